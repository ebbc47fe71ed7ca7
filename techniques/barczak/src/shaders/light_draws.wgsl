// Barczak 2006 §4.3.2–4.3.5: lights drawn over patch leaves, up to K per draw. Each draw covers
// the leaves of one element and up to K lights. `fs_subtract` (after the light-map pass, blended
// with ReverseSubtract) sums the contributions of the lights its shadow maps find occluded;
// `fs_add` (blended with Add) sums every light's contribution, times its shadow-map visibility
// where the light's entry asks for a lookup (high bit set). Needs GpuVpl / vpl_store (group 2,
// binding 0) and the atlas lookup (group 3) declared before it.

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
@group(2) @binding(1) var<storage, read> draw_lights: DrawLights;

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

struct LeafOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
};

@vertex
fn vs_leaf(@location(0) position: vec3<f32>, @location(2) normal: vec3<f32>) -> LeafOut {
    var out: LeafOut;
    out.clip = camera.view_proj * vec4<f32>(position, 1.0);
    out.clip = vec4<f32>(out.clip.xy + raster.ndc.xy * out.clip.w, out.clip.zw);
    out.world = position;
    out.normal = normal;
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
    var occluded = vec3<f32>(0.0);
    let count = min(draw_lights.count.x, 16u);
    for (var k = 0u; k < count; k++) {
        let slot = draw_lights.lights[k / 4u][k % 4u] & ~LOOKUP;
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
    var sum = vec3<f32>(0.0);
    let count = min(draw_lights.count.x, 16u);
    for (var k = 0u; k < count; k++) {
        let entry = draw_lights.lights[k / 4u][k % 4u];
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
