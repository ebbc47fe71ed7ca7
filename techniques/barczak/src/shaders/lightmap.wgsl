// Barczak 2006 §4.3.2: the light-map pass. Every leaf sub-patch is drawn with the camera; where
// it is the surface the G-buffer shows, the pixel gets the leaf's light map, bilinearly
// interpolated between texel centres and clamped inside the leaf (one map per sub-patch, so no
// interpolation across sub-patches with different lights).

@group(0) @binding(0) var<uniform> camera: View;
@group(1) @binding(0) var<uniform> view: View;
@group(1) @binding(1) var gbuffer_depth: texture_2d<f32>;
@group(1) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(1) @binding(3) var gbuffer_albedo: texture_2d<f32>;

struct LightMapParams {
    // x: texels along a leaf's edge
    counts: vec4<u32>,
};
@group(2) @binding(0) var<storage, read> lm_params: LightMapParams;
// Leaf l's texels: texel t = l * res * res + j * res + i (i along the leaf's first edge) is
// lm_texels[3t .. 3t + 3], its red, green and blue (12 bytes a texel, not a vec4's 16: the
// conference room's 131,000 leaves fit the buffers a device binds).
@group(2) @binding(1) var<storage, read> lm_texels: array<f32>;

struct LeafOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) leaf: u32,
    // The point's coordinates in the leaf, [0, 1]² from its first corner.
    @location(1) st: vec2<f32>,
};

@vertex
fn vs_leaf(@location(0) position: vec3<f32>, @location(1) leaf: u32, @location(3) st: vec2<f32>) -> LeafOut {
    var out: LeafOut;
    out.clip = camera.view_proj * vec4<f32>(position, 1.0);
    out.leaf = leaf;
    out.st = st;
    return out;
}

fn texel(leaf: u32, i: u32, j: u32) -> vec3<f32> {
    let res = lm_params.counts.x;
    let t = 3u * (leaf * res * res + j * res + i);
    return vec3<f32>(lm_texels[t], lm_texels[t + 1u], lm_texels[t + 2u]);
}

@fragment
fn fs_leaf(in: LeafOut) -> @location(0) vec4<f32> {
    // Only where this leaf is what the camera sees (the leaves are not the G-buffer's
    // triangles, so their depths agree to rounding, not bit for bit).
    let shown = textureLoad(gbuffer_depth, vec2<i32>(in.clip.xy), 0).r;
    if (abs(in.clip.z - shown) > 1e-4 * shown) {
        discard;
    }
    let res = lm_params.counts.x;
    let last = f32(res - 1u);
    let x = clamp(in.st.x * f32(res) - 0.5, 0.0, last);
    let y = clamp(in.st.y * f32(res) - 0.5, 0.0, last);
    let i0 = u32(floor(x));
    let j0 = u32(floor(y));
    let i1 = min(i0 + 1u, res - 1u);
    let j1 = min(j0 + 1u, res - 1u);
    let fx = x - f32(i0);
    let fy = y - f32(j0);
    let e = mix(mix(texel(in.leaf, i0, j0), texel(in.leaf, i1, j0), fx),
                mix(texel(in.leaf, i0, j1), texel(in.leaf, i1, j1), fx), fy);
    return vec4<f32>(e, 1.0);
}
