// The VPL store (VplStore): one item per slot; a zero flux marks an empty slot.

struct GpuVpl {
    // xyz: position; w: slot (shadow-map slot)
    position: vec4<f32>,
    // xyz: unit normal
    normal: vec4<f32>,
    // rgb: flux leaving the surface (emits flux / pi * cos)
    flux: vec4<f32>,
    // the VPL's frame about its normal (xyz), for paraboloid maps
    tangent: vec4<f32>,
    bitangent: vec4<f32>,
};

struct VplStoreData {
    // x: slots in use (highest used slot + 1);
    // yzw: bits of three f32s, the VPLs' summed flux (r, g, b)
    header: vec4<u32>,
    items: array<GpuVpl>,
};

// The unoccluded geometric term between a VPL at `position` (unit normal `normal`) and a
// receiver at `p` (unit normal `n`): the cosine at the VPL times the cosine at the receiver
// over their squared distance; 0 when either lies behind the other's surface. A VPL's
// irradiance there is flux / pi * this * visibility.
fn geometric_term(position: vec3<f32>, normal: vec3<f32>, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let d = p - position;
    let r2 = dot(d, d);
    let dir = d * inverseSqrt(max(r2, 1e-30));
    let cos_v = dot(normal, dir);
    let cos_r = -dot(n, dir);
    if (cos_v <= 0.0 || cos_r <= 0.0) {
        return 0.0;
    }
    return cos_v * cos_r / max(r2, 1e-30);
}

// geometric_term between VPL `v` and a receiver at `p` (unit normal `n`).
fn vpl_geometry(v: GpuVpl, p: vec3<f32>, n: vec3<f32>) -> f32 {
    return geometric_term(v.position.xyz, v.normal.xyz, p, n);
}
