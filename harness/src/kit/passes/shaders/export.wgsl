// Copies the G-buffer into a storage buffer (world position, normal) for CPU-side checks and
// the reference comparisons.

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var gbuffer_depth: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_albedo: texture_2d<f32>;

struct Texel {
    // w: 1 where geometry was hit, 0 for background
    position: vec4<f32>,
    normal: vec4<f32>,
    albedo: vec4<f32>,
};

@group(1) @binding(0) var<storage, read_write> texels: array<Texel>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(view.params.x);
    let h = u32(view.params.y);
    if (id.x >= w || id.y >= h) {
        return;
    }
    let pix = vec2<i32>(id.xy);
    let depth = textureLoad(gbuffer_depth, pix, 0).r;
    let nrm = textureLoad(gbuffer_normal, pix, 0);
    var t: Texel;
    if (nrm.w != 0.0) {
        t.position = vec4<f32>(world_from_depth(view, vec2<f32>(id.xy) + 0.5, depth), 1.0);
    }
    t.normal = nrm;
    t.albedo = textureLoad(gbuffer_albedo, pix, 0);
    texels[id.y * w + id.x] = t;
}
