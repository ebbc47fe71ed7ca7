// VPL data and visibility lookups shared by every VPL technique's accumulation shader.
// Prepended after INTERLEAVE_WGSL; binds group 1.

struct GpuVpl {
    // xyz: position; w: shadow-map slot
    position: vec4<f32>,
    // xyz: unit normal
    normal: vec4<f32>,
    // rgb: flux leaving the surface (emits flux / pi * cos)
    flux: vec4<f32>,
    // the VPL's paraboloid frame (xyz); tangent.w: how far the map's centre is lifted off the
    // surface along the normal
    tangent: vec4<f32>,
    bitangent: vec4<f32>,
};

struct VplParams {
    // x: VPL count; y: atlas columns (in slots); z: map size (texels); w: parameterisation (0 paraboloid, 1 cube)
    counts: vec4<u32>,
    // x: far distance; y: minimum distance (clamp of the 1/r^2 singularity); z: depth bias (fraction of distance); w: cube near plane
    distances: vec4<f32>,
    // Cube faces: projection * rotation, for a VPL at the origin.
    cube_faces: array<mat4x4<f32>, 6>,
};

@group(1) @binding(0) var<uniform> vpl_params: VplParams;
@group(1) @binding(1) var<storage, read> vpls: array<GpuVpl>;
@group(1) @binding(2) var vpl_atlas: texture_2d<f32>;

// Top-left texel of the tile of `slot` (cube: of face 0 of its 3x2 block) in the atlas.
fn vpl_tile_origin(slot: u32, tile_w: u32, tile_h: u32) -> vec2<i32> {
    let cols = vpl_params.counts.y;
    return vec2<i32>(i32((slot % cols) * tile_w), i32((slot / cols) * tile_h));
}

// 1 if receiver `p` (unit normal `n`) is visible from VPL `v` according to its depth map,
// else 0. The receiver is first moved off its surface by about two map texels (normal offset),
// so that surfaces tilted away from the VPL do not shadow themselves.
fn vpl_visibility(v: GpuVpl, p_surface: vec3<f32>, n: vec3<f32>) -> f32 {
    let size = vpl_params.counts.z;
    let slot = u32(v.position.w);
    let eye = v.position.xyz + v.normal.xyz * v.tangent.w;
    let p = p_surface + n * (4.0 * length(p_surface - eye) / f32(size));
    let d = p - eye;
    let len = length(d);
    let far = vpl_params.distances.x;
    let bias = vpl_params.distances.z;
    if (vpl_params.counts.w == 0u) {
        let local = vec3<f32>(dot(d, v.tangent.xyz), dot(d, v.bitangent.xyz), dot(d, v.normal.xyz)) / max(len, 1e-20);
        if (local.z <= 0.0) {
            return 0.0;
        }
        let uv = local.xy / (1.0 + local.z);
        let st = vec2<i32>(floor(vec2<f32>(uv.x * 0.5 + 0.5, 0.5 - uv.y * 0.5) * f32(size)));
        let t = clamp(st, vec2<i32>(0), vec2<i32>(i32(size) - 1));
        let stored = textureLoad(vpl_atlas, vpl_tile_origin(slot, size, size) + t, 0).r;
        let receiver = 1.0 - len * (1.0 - bias) / far;
        return select(0.0, 1.0, receiver >= stored);
    }
    let face = cube_face(d);
    let clip = vpl_params.cube_faces[face] * vec4<f32>(d * (1.0 - bias), 1.0);
    let ndc = clip.xyz / clip.w;
    let st = vec2<i32>(floor(vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * f32(size)));
    let t = clamp(st, vec2<i32>(0), vec2<i32>(i32(size) - 1));
    let origin = vpl_tile_origin(slot, 3u * size, 2u * size) + vec2<i32>(i32((face % 3u) * size), i32((face / 3u) * size));
    let stored = textureLoad(vpl_atlas, origin + t, 0).r;
    return select(0.0, 1.0, ndc.z >= stored);
}

// Irradiance at `p` (unit normal `n`) from VPL `v`, including visibility. The 1/r^2
// singularity is clamped by a minimum distance.
fn vpl_irradiance(v: GpuVpl, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    // Empty slots carry no flux: skip them before any lookup.
    if (all(v.flux.rgb == vec3<f32>(0.0))) {
        return vec3<f32>(0.0);
    }
    let d = p - v.position.xyz;
    let r2 = dot(d, d);
    let dir = d * inverseSqrt(max(r2, 1e-30));
    let cos_v = dot(v.normal.xyz, dir);
    let cos_r = -dot(n, dir);
    if (cos_v <= 0.0 || cos_r <= 0.0) {
        return vec3<f32>(0.0);
    }
    let min_d = vpl_params.distances.y;
    let g = cos_v * cos_r / max(r2, min_d * min_d);
    return v.flux.rgb * (g / 3.14159265358979) * vpl_visibility(v, p, n);
}
