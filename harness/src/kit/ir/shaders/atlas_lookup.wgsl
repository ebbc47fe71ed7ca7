#import gibench::vpl_store
// Visibility lookups in a VPL shadow atlas (ShadowAtlas): one map per slot, paraboloid
// (Brabec et al. 2002, as Laine et al. 2007 use), cube (3x2 faces) or octahedral (Barczak 2006:
// four octahedron faces unfolded to a square). Stored values are reversed depth: 1 near,
// 0 far/empty (paraboloid, octahedral: 1 - distance / far; cube: reversed-Z NDC depth).
// The module `gibench::atlas_lookup`: uses the bindings `atlas_params` and `vpl_atlas` that
// ShadowAtlas::wgsl declares beside its import.

struct AtlasParams {
    // x: slots per atlas row; y: map size (texels); z: parameterisation (0 paraboloid, 1 cube,
    // 2 octahedral)
    counts: vec4<u32>,
    // x: far distance; y: depth bias (fraction of distance); z: cube near plane; w: lift (the
    // map's centre sits this far off the VPL's surface along its normal)
    distances: vec4<f32>,
    // Cube faces: projection * rotation, for a VPL at the origin.
    cube_faces: array<mat4x4<f32>, 6>,
};

// Top-left texel of the tile of `slot` (cube: of face 0 of its 3x2 block) in the atlas.
fn vpl_tile_origin(slot: u32, tile_w: u32, tile_h: u32) -> vec2<i32> {
    let cols = atlas_params.counts.x;
    return vec2<i32>(i32((slot % cols) * tile_w), i32((slot / cols) * tile_h));
}

// The texel of a `size`² paraboloid map that the unit direction `local` (in the map's frame, z
// along the VPL's normal, z > 0) falls in: uv = local.xy / (1 + local.z) on [-1, 1]², row 0 at
// the top. Shared by the lookup below and the point splats of imperfect shadow maps.
fn paraboloid_texel(local: vec3<f32>, size: u32) -> vec2<i32> {
    let uv = local.xy / (1.0 + local.z);
    let st = vec2<i32>(floor(vec2<f32>(uv.x * 0.5 + 0.5, 0.5 - uv.y * 0.5) * f32(size)));
    return clamp(st, vec2<i32>(0), vec2<i32>(i32(size) - 1));
}

// The texel of a `size`² octahedral map that the unit direction `local` (the map's frame, z
// along the VPL's normal, z >= 0) falls in: o = local / (|x| + |y| + z) on the octahedron, the
// diamond turned onto the square, uv = (o.x + o.y, o.x - o.y), row 0 at the top (atlas.rs
// `octahedral_uv`).
fn octahedral_texel(local: vec3<f32>, size: u32) -> vec2<i32> {
    let o = local.xy / max(abs(local.x) + abs(local.y) + max(local.z, 0.0), 1e-30);
    let uv = vec2<f32>(o.x + o.y, o.x - o.y);
    let st = vec2<i32>(floor(vec2<f32>(uv.x * 0.5 + 0.5, 0.5 - uv.y * 0.5) * f32(size)));
    return clamp(st, vec2<i32>(0), vec2<i32>(i32(size) - 1));
}

// The eye point of VPL `v`'s map: its position lifted off its surface along its normal.
fn vpl_eye(v: GpuVpl) -> vec3<f32> {
    return v.position.xyz + v.normal.xyz * atlas_params.distances.w;
}

// Top-left texel of the map of `slot` in the atlas (cube: of face 0 of its 3x2 block).
fn vpl_map_origin(slot: u32) -> vec2<i32> {
    let size = atlas_params.counts.y;
    if (atlas_params.counts.z == 1u) {
        return vpl_tile_origin(slot, 3u * size, 2u * size);
    }
    return vpl_tile_origin(slot, size, size);
}

// 1 if receiver `p_surface` (unit normal `n`) is visible from the map with eye point `eye`,
// frame (`tangent`, `bitangent`, `normal`: z along the VPL's normal) and top-left texel
// `origin` in the atlas (vpl_eye, vpl_map_origin), else 0. The receiver is first moved off its
// surface by about two map texels (normal offset), so that surfaces tilted away from the VPL
// do not shadow themselves.
fn atlas_visibility(eye: vec3<f32>, tangent: vec3<f32>, bitangent: vec3<f32>, normal: vec3<f32>, origin: vec2<i32>, p_surface: vec3<f32>, n: vec3<f32>) -> f32 {
    let size = atlas_params.counts.y;
    let p = p_surface + n * (4.0 * length(p_surface - eye) / f32(size));
    let d = p - eye;
    let len = length(d);
    let far = atlas_params.distances.x;
    let bias = atlas_params.distances.y;
    if (atlas_params.counts.z != 1u) {
        let local = vec3<f32>(dot(d, tangent), dot(d, bitangent), dot(d, normal)) / max(len, 1e-20);
        if (local.z <= 0.0) {
            return 0.0;
        }
        var t: vec2<i32>;
        if (atlas_params.counts.z == 0u) {
            t = paraboloid_texel(local, size);
        } else {
            t = octahedral_texel(local, size);
        }
        let stored = textureLoad(vpl_atlas, origin + t, 0).r;
        let receiver = 1.0 - len * (1.0 - bias) / far;
        return select(0.0, 1.0, receiver >= stored);
    }
    let face = cube_face(d);
    let clip = atlas_params.cube_faces[face] * vec4<f32>(d * (1.0 - bias), 1.0);
    let ndc = clip.xyz / clip.w;
    let st = vec2<i32>(floor(vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * f32(size)));
    let t = clamp(st, vec2<i32>(0), vec2<i32>(i32(size) - 1));
    let face_origin = origin + vec2<i32>(i32((face % 3u) * size), i32((face / 3u) * size));
    let stored = textureLoad(vpl_atlas, face_origin + t, 0).r;
    return select(0.0, 1.0, ndc.z >= stored);
}

// 1 if receiver `p_surface` (unit normal `n`) is visible from VPL `v` according to its map,
// else 0 (atlas_visibility for v's own map).
fn vpl_visibility(v: GpuVpl, p_surface: vec3<f32>, n: vec3<f32>) -> f32 {
    return atlas_visibility(vpl_eye(v), v.tangent.xyz, v.bitangent.xyz, v.normal.xyz, vpl_map_origin(u32(v.position.w)), p_surface, n);
}
