#import gibench::prepared_vpl

// Interleaved accumulation of VPL irradiance (Laine et al. 2007, Section 5.1): every texel of
// the split G-buffer gathers from the VPLs assigned to its tile (the VPL in slot k goes to tile
// k mod T) with a visibility lookup each. Each tile sees 1/T of the VPLs, so its sum is scaled
// by T: after the n x m filter averages the T tiles, every pixel has the full estimate.
// Reads each VPL's terms that do not depend on the receiver from `prepared`
// (accumulate_prepare.wgsl, the dispatch before this one), so the pair loop holds only what
// does: the geometric term, the normal offset and the map lookup.
// Prepended: INTERLEAVE_WGSL (group 0), the store (group 1, binding 1: its header's count of
// slots in use), the atlas (group 2).

@group(1) @binding(0) var<storage, read> prepared: array<PreparedVpl>;

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
    let p = pos.xyz;
    let n = split_normal[i].xyz;
    let tiles = interleave.tiles.x * interleave.tiles.y;
    let count = min(vpl_store.header.x, arrayLength(&prepared));
    var e = vec3<f32>(0.0);
    for (var k = split_tile(id.x, id.y); k < count; k += tiles) {
        let v = prepared[k];
        if (v.position.w < 0.0) {
            continue;
        }
        let g = geometric_term(v.position.xyz, v.normal, p, n);
        if (g <= 0.0) {
            continue;
        }
        if (atlas_visibility(v.eye.xyz, v.tangent.xyz, v.bitangent.xyz, v.normal, prepared_origin(v), p, n) == 0.0) {
            continue;
        }
        e += vec3<f32>(v.eye.w, v.tangent.w, v.bitangent.w) * min(g, v.position.w);
    }
    split_irradiance[i] = vec4<f32>(e * f32(tiles), 1.0);
}
