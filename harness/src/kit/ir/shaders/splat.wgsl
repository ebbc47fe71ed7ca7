// Point splats of imperfect shadow maps (Ritschel et al. 2008): each VPL's own subset of the
// point pool, projected into its paraboloid map and kept nearest-first (reversed depth, so the
// largest value wins) with a storage-buffer atomic: one thread per (point, VPL).
// Expects VplStore::wgsl at group 0 binding 0 and ShadowAtlas::wgsl at group 1.

struct SplatParams {
    // x: points per VPL; y: points in the pool; z, w: unused
    counts: vec4<u32>,
};

@group(0) @binding(1) var<storage, read> splat_params: SplatParams;
@group(0) @binding(2) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> ism_depth: array<atomic<u32>>;
// Object -> world per object: 0 the static mesh (identity), k + 1 mover k.
@group(0) @binding(4) var<storage, read> objects: array<mat4x4<f32>>;

// Where VPL `slot`'s subset starts in the pool: a multiplicative hash, so neighbouring slots
// take unrelated runs of the (shuffled) pool.
fn subset_start(slot: u32, pool: u32) -> u32 {
    return (slot * 2654435761u + 40503u) % pool;
}

@compute @workgroup_size(64)
fn splat(@builtin(global_invocation_id) id: vec3<u32>) {
    let slot = id.y;
    let j = id.x;
    let per_vpl = splat_params.counts.x;
    let pool = splat_params.counts.y;
    if (slot >= vpl_store.header.x || j >= per_vpl || pool == 0u) {
        return;
    }
    let v = vpl_store.items[slot];
    if (max(v.flux.x, max(v.flux.y, v.flux.z)) <= 0.0) {
        return;
    }
    let point = points[(subset_start(slot, pool) + j) % pool];
    let p = (objects[u32(point.w)] * vec4<f32>(point.xyz, 1.0)).xyz;
    let eye = v.position.xyz + v.normal.xyz * atlas_params.distances.w;
    let d = p - eye;
    let len = length(d);
    if (len <= 0.0) {
        return;
    }
    let local = vec3<f32>(dot(d, v.tangent.xyz), dot(d, v.bitangent.xyz), dot(d, v.normal.xyz)) / len;
    if (local.z <= 0.0) {
        return;
    }
    let size = atlas_params.counts.y;
    let t = paraboloid_texel(local, size);
    let depth = clamp(1.0 - len / atlas_params.distances.x, 0.0, 1.0);
    // Non-negative floats order like their bits as u32.
    atomicMax(&ism_depth[slot * size * size + u32(t.y) * size + u32(t.x)], bitcast<u32>(depth));
}
