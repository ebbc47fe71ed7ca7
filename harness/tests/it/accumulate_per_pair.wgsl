// The accumulation as it was before its per-VPL terms moved to a dispatch of their own (issue
// 55): the direct per-pair formulation, every term recomputed for each (texel, VPL) pair. Kept
// as the reference the kit's lean accumulation is compared with (tests/it/accumulate.rs): the
// paper's formula, read straight.
// Prepended: INTERLEAVE_WGSL (group 0), the store (group 1, binding 0), the atlas (group 2).

struct AccumulateParams {
    // x: the clamp factor over the scene's surface area, k / A (0: no clamp): each channel of
    // a VPL's irradiance is bounded at k / A times that channel of the store's summed flux,
    // the whole colour scaled by the tightest channel's ratio
    clamp: vec4<f32>,
};

@group(1) @binding(1) var<storage, read> accumulate_params: AccumulateParams;

// Irradiance at `p` (unit normal `n`) from VPL `v`, including visibility, bounded per channel
// by `e_max` (no bound when `clamped` is false).
fn vpl_irradiance(v: GpuVpl, p: vec3<f32>, n: vec3<f32>, e_max: vec3<f32>, clamped: bool) -> vec3<f32> {
    // Empty slots carry no flux: skip them before any lookup.
    if (all(v.flux.rgb == vec3<f32>(0.0))) {
        return vec3<f32>(0.0);
    }
    let g = vpl_geometry(v, p, n);
    if (g <= 0.0) {
        return vec3<f32>(0.0);
    }
    // Irradiance = base * g. The bound is compared as g against the largest g any channel
    // allows, so a tiny r2 cannot overflow into inf * 0.
    let base = v.flux.rgb * (vpl_visibility(v, p, n) / 3.14159265358979);
    if (clamped) {
        var g_max = 3.4e38;
        for (var c = 0; c < 3; c++) {
            if (base[c] > 0.0) {
                g_max = min(g_max, e_max[c] / base[c]);
            }
        }
        if (g > g_max) {
            return base * g_max;
        }
    }
    return base * g;
}

@compute @workgroup_size(8, 8)
fn accumulate(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= interleave.split.x || id.y >= interleave.split.y) {
        return;
    }
    let i = id.y * interleave.split.x + id.x;
    let pos = split_position[i];
    if (pos.w == 0.0) {
        split_irradiance[i] = vec4<f32>(0.0);
        return;
    }
    let n = split_normal[i].xyz;
    let tiles = interleave.tiles.x * interleave.tiles.y;
    let count = min(vpl_store.header.x, arrayLength(&vpl_store.items));
    let h = vpl_store.header;
    let e_max = accumulate_params.clamp.x * vec3<f32>(bitcast<f32>(h.y), bitcast<f32>(h.z), bitcast<f32>(h.w));
    let clamped = accumulate_params.clamp.x > 0.0;
    var e = vec3<f32>(0.0);
    for (var k = split_tile(id.x, id.y); k < count; k += tiles) {
        e += vpl_irradiance(vpl_store.items[k], pos.xyz, n, e_max, clamped);
    }
    split_irradiance[i] = vec4<f32>(e * f32(tiles), 1.0);
}
