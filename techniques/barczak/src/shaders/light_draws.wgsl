// Barczak 2006 §4.3.2–4.3.5: lights drawn over patch leaves, up to K per pass. Each pass covers
// the leaves of one element and up to K lights; every triangle the draws emit names its leaf
// triangle's first vertex and its pass's light record (`emitted`), so that one draw can hold
// many passes (each triangle shaded with its own pass's lights, blended in the order of the
// passes).
// `fs_subtract` (after the light-map pass, blended with ReverseSubtract) sums the contributions
// of the lights its shadow maps find occluded; `fs_add` (blended with Add) sums every light's
// contribution, times its shadow-map visibility where the light's entry asks for a lookup (high
// bit set). Needs GpuVpl / vpl_store (group 2, binding 0) and the atlas lookup (group 3)
// declared before it.

@group(0) @binding(0) var<uniform> camera: View;
@group(1) @binding(0) var<uniform> view: View;
@group(1) @binding(1) var gbuffer_depth: texture_2d<f32>;
@group(1) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(1) @binding(3) var gbuffer_albedo: texture_2d<f32>;

struct DrawLights {
    // x: lights in this draw (at most 16)
    count: vec4<u32>,
    // The lights' store slots, four per vector; the high bit asks for a shadow-map lookup.
    lights: array<vec4<u32>, 4>,
};
@group(2) @binding(1) var<storage, read> records: array<DrawLights>;

// Where the draw rasterises: full resolution (factor 1) or the low-resolution pass's (its
// pixel p shows the G-buffer's pixel factor * p + sample, the projection shifted by ndc so that
// the pixel centres fall on those pixels' centres; lowres.rs).
struct Raster {
    // x: factor, y: sample
    counts: vec4<u32>,
    // xy: NDC shift
    ndc: vec4<f32>,
};
@group(2) @binding(2) var<storage, read> raster: Raster;

// Per emitted triangle: x its leaf triangle's first vertex, y its pass's record.
@group(2) @binding(3) var<storage, read> emitted: array<vec2<u32>>;
// The leaves' vertices (lightmap_pass.rs `LeafVertex`, nine words each): position, tile,
// normal, (s, t).
@group(2) @binding(4) var<storage, read> leaf_words: array<u32>;
const LEAF_WORDS: u32 = 9u;

struct LeafOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) record: u32,
};

fn leaf_vec3(vertex: u32, word: u32) -> vec3<f32> {
    let i = vertex * LEAF_WORDS + word;
    return bitcast<vec3<f32>>(vec3<u32>(leaf_words[i], leaf_words[i + 1u], leaf_words[i + 2u]));
}

@vertex
fn vs_leaf(@builtin(vertex_index) index: u32) -> LeafOut {
    let e = emitted[index / 3u];
    let vertex = e.x + index % 3u;
    let position = leaf_vec3(vertex, 0u);
    var out: LeafOut;
    out.clip = camera.view_proj * vec4<f32>(position, 1.0);
    out.clip = vec4<f32>(out.clip.xy + raster.ndc.xy * out.clip.w, out.clip.zw);
    out.world = position;
    out.normal = leaf_vec3(vertex, 4u);
    out.record = e.y;
    return out;
}

// A light sample's irradiance at p (normal n) without visibility: flux/pi times the store's
// geometric term, cos at the light times cos at the receiver over the squared distance
// (lightmap.rs `contribution`).
fn contribution(v: GpuVpl, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return v.flux.rgb / 3.14159265358979 * vpl_geometry(v, p, n);
}

const LOOKUP: u32 = 0x80000000u;

// Whether this leaf fragment is what the camera sees at its G-buffer pixel (leaves are not the
// G-buffer's triangles, so depths agree to rounding only).
fn shown(in: LeafOut) -> bool {
    let pixel = vec2<u32>(in.clip.xy) * raster.counts.x + raster.counts.y;
    let depth = textureLoad(gbuffer_depth, vec2<i32>(pixel), 0).r;
    return abs(in.clip.z - depth) <= 1e-4 * depth;
}

@fragment
fn fs_subtract(in: LeafOut) -> @location(0) vec4<f32> {
    if (!shown(in)) {
        discard;
    }
    let n = normalize(in.normal);
    let record = in.record;
    var occluded = vec3<f32>(0.0);
    let count = min(records[record].count.x, 16u);
    for (var k = 0u; k < count; k++) {
        let slot = records[record].lights[k / 4u][k % 4u] & ~LOOKUP;
        let v = vpl_store.items[slot];
        let c = contribution(v, in.world, n);
        if (any(c > vec3<f32>(0.0))) {
            occluded += c * (1.0 - vpl_visibility(v, in.world, n));
        }
    }
    return vec4<f32>(occluded, 0.0);
}

@fragment
fn fs_add(in: LeafOut) -> @location(0) vec4<f32> {
    if (!shown(in)) {
        discard;
    }
    let n = normalize(in.normal);
    let record = in.record;
    var sum = vec3<f32>(0.0);
    let count = min(records[record].count.x, 16u);
    for (var k = 0u; k < count; k++) {
        let entry = records[record].lights[k / 4u][k % 4u];
        let v = vpl_store.items[entry & ~LOOKUP];
        let c = contribution(v, in.world, n);
        if (any(c > vec3<f32>(0.0))) {
            if ((entry & LOOKUP) != 0u) {
                sum += c * vpl_visibility(v, in.world, n);
            } else {
                sum += c;
            }
        }
    }
    return vec4<f32>(sum, 0.0);
}
