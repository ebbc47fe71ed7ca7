// Interleaved accumulation of VPL irradiance (Laine et al. 2007, Section 5.1): every texel of
// the split G-buffer gathers from the VPLs assigned to its tile (the VPL in slot k goes to tile
// k mod T; the list is indexed by slot) with a visibility lookup each. Each tile sees 1/T of the VPLs,
// so its sum is scaled by T: after the n x m filter averages the T tiles, every pixel has the
// full estimate.

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
    var e = vec3<f32>(0.0);
    for (var k = split_tile(id.x, id.y); k < vpl_params.counts.x; k += tiles) {
        e += vpl_irradiance(vpls[k], pos.xyz, n);
    }
    split_irradiance[i] = vec4<f32>(e * f32(tiles), 1.0);
}
