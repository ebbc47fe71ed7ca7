// Barczak 2006 §4.3.3: the low-resolution pass's two full-screen draws. `fs_mask` turns the edge
// mask into depth (reversed Z: 0 at edge pixels, 1 elsewhere), so that the full-resolution light
// draws, tested Greater, run only at edges; `fs_composite` (drawn at depth 0.5, tested Less: only
// off the edges) interpolates the low-resolution image bilinearly between its samples, each of
// which shows the full-resolution pixel factor * p + factor / 2 (rounded down).

struct LowResParams {
    // x: factor, y: the sample's pixel within its block, z, w: low-resolution width, height
    counts: vec4<u32>,
    // x, y: full-resolution width, height
    full: vec4<u32>,
};

@group(0) @binding(0) var<storage, read> lowres: LowResParams;
@group(0) @binding(1) var<storage, read> edge_mask: array<u32>;
@group(0) @binding(2) var low_image: texture_2d<f32>;
@group(1) @binding(0) var<uniform> view: View;
@group(1) @binding(1) var gbuffer_depth: texture_2d<f32>;
@group(1) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(1) @binding(3) var gbuffer_albedo: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let p = fullscreen_position(i);
    return vec4<f32>(p.xy, 0.5, 1.0);
}

@fragment
fn fs_mask(@builtin(position) pos: vec4<f32>) -> @builtin(frag_depth) f32 {
    let pix = vec2<u32>(pos.xy);
    if (edge_mask[pix.y * lowres.full.x + pix.x] != 0u) {
        return 0.0;
    }
    return 1.0;
}

fn low(x: u32, y: u32) -> vec3<f32> {
    return textureLoad(low_image, vec2<i32>(vec2<u32>(x, y)), 0).rgb;
}

@fragment
fn fs_composite(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let pix = vec2<i32>(pos.xy);
    // Only where a surface is shown (background stays zero).
    if (textureLoad(gbuffer_normal, pix, 0).w == 0.0) {
        discard;
    }
    let f = f32(lowres.counts.x);
    let h = f32(lowres.counts.y);
    let last = vec2<f32>(f32(lowres.counts.z - 1u), f32(lowres.counts.w - 1u));
    let u = clamp((vec2<f32>(pix) - h) / f, vec2<f32>(0.0), last);
    let p0 = vec2<u32>(floor(u));
    let p1 = min(p0 + 1u, vec2<u32>(lowres.counts.zw - 1u));
    let t = u - floor(u);
    let e = mix(mix(low(p0.x, p0.y), low(p1.x, p0.y), t.x),
                mix(low(p0.x, p1.y), low(p1.x, p1.y), t.x), t.y);
    return vec4<f32>(e, 0.0);
}
