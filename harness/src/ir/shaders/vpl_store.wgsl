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
