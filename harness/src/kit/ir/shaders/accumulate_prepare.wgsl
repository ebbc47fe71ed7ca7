#import gibench::prepared_vpl

// The accumulation's per-VPL terms (Accumulation, the first dispatch of its pass): for every
// slot in use, what the pair loop of accumulate.wgsl would otherwise recompute for each
// (texel, VPL) pair — the map's eye point and tile origin in the atlas, the flux over pi, and
// the largest geometric term the irradiance clamp lets through — into `prepared`.
// Prepended: the store (group 0, binding 0), the atlas (group 1).

struct AccumulateParams {
    // x: the clamp factor over the scene's surface area, k / A (0: no clamp): each channel of
    // a VPL's irradiance is bounded at k / A times that channel of the store's summed flux,
    // the whole colour scaled by the tightest channel's ratio
    clamp: vec4<f32>,
};

@group(0) @binding(1) var<storage, read> accumulate_params: AccumulateParams;
@group(0) @binding(2) var<storage, read_write> prepared: array<PreparedVpl>;

@compute @workgroup_size(64)
fn prepare(@builtin(global_invocation_id) id: vec3<u32>) {
    let k = id.x;
    if (k >= min(vpl_store.header.x, min(arrayLength(&vpl_store.items), arrayLength(&prepared)))) {
        return;
    }
    let v = vpl_store.items[k];
    let h = vpl_store.header;
    let e_max = accumulate_params.clamp.x * vec3<f32>(bitcast<f32>(h.y), bitcast<f32>(h.z), bitcast<f32>(h.w));
    // A receiver's irradiance is base * g where it sees the VPL, base = flux / pi. The clamp
    // compares g against the largest g any channel allows, so a tiny r2 cannot overflow into
    // inf * 0.
    let base = v.flux.rgb * (1.0f / 3.14159265358979);
    var g_max = 3.4e38;
    if (accumulate_params.clamp.x > 0.0) {
        for (var c = 0; c < 3; c++) {
            if (base[c] > 0.0) {
                g_max = min(g_max, e_max[c] / base[c]);
            }
        }
    }
    // An empty slot carries no flux: the pair loop skips it before any lookup.
    if (all(v.flux.rgb == vec3<f32>(0.0))) {
        g_max = -1.0;
    }
    prepared[k] = PreparedVpl(
        vec4<f32>(v.position.xyz, g_max),
        v.normal.xyz,
        pack_origin(vpl_map_origin(u32(v.position.w))),
        vec4<f32>(vpl_eye(v), base.r),
        vec4<f32>(v.tangent.xyz, base.g),
        vec4<f32>(v.bitangent.xyz, base.b),
    );
}
