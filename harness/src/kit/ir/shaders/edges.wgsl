// Edge detection for a low-resolution illumination pass (Barczak 2006 §4.3.3): a pixel is an
// edge where the plane of the surface it shows differs from the plane a neighbour `step`
// pixels away shows (or the neighbour shows nothing), so that interpolating a low-resolution
// image there would leak across the edge. Reads the G-buffer (group 0); writes one u32 per
// pixel: 1 edge, 0 not (background: 0).

struct EdgeParams {
    // x: step in pixels
    counts: vec4<u32>,
    // x: cosine below which two normals differ; y: largest distance of a neighbour from the
    // pixel's plane, as a fraction of their distance
    limits: vec4<f32>,
};

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var gbuffer_depth: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_albedo: texture_2d<f32>;
@group(1) @binding(0) var<storage, read> edge_params: EdgeParams;
@group(1) @binding(1) var<storage, read_write> edge_mask: array<u32>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(view.params.x);
    let h = u32(view.params.y);
    if (id.x >= w || id.y >= h) {
        return;
    }
    let pix = vec2<i32>(id.xy);
    let n = textureLoad(gbuffer_normal, pix, 0);
    if (n.w == 0.0) {
        edge_mask[id.y * w + id.x] = 0u;
        return;
    }
    let p = world_from_depth(view, vec2<f32>(id.xy) + 0.5, textureLoad(gbuffer_depth, pix, 0).r);
    let s = i32(edge_params.counts.x);
    var edge = 0u;
    for (var k = 0; k < 8; k++) {
        let offsets = array<vec2<i32>, 8>(
            vec2<i32>(s, 0), vec2<i32>(-s, 0), vec2<i32>(0, s), vec2<i32>(0, -s),
            vec2<i32>(s, s), vec2<i32>(-s, s), vec2<i32>(s, -s), vec2<i32>(-s, -s));
        let q = clamp(pix + offsets[k], vec2<i32>(0), vec2<i32>(i32(w) - 1, i32(h) - 1));
        let nq = textureLoad(gbuffer_normal, q, 0);
        if (nq.w == 0.0) {
            edge = 1u;
            break;
        }
        let pq = world_from_depth(view, vec2<f32>(q) + 0.5, textureLoad(gbuffer_depth, q, 0).r);
        let off = abs(dot(n.xyz, pq - p));
        if (dot(n.xyz, nq.xyz) < edge_params.limits.x || off > edge_params.limits.y * length(pq - p)) {
            edge = 1u;
            break;
        }
    }
    edge_mask[id.y * w + id.x] = edge;
}
