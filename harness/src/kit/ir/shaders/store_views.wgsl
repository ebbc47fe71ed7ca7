// Paraboloid views of the VPLs a GPU pass wrote into the VPL store, for the atlas rasteriser:
// one 256-byte `VplView` (vpl_shadow.wgsl) per slot, written where the rasteriser's dynamic
// offsets read it. Expects VplStore::wgsl at group 0 binding 0, and the constants LIFT and FAR
// (the atlas's) prepended.

struct ViewSlot {
    view_proj: mat4x4<f32>,
    position: vec4<f32>,
    tangent: vec4<f32>,
    bitangent: vec4<f32>,
    normal: vec4<f32>,
    // Pads the slot to the 256-byte stride of the rasteriser's dynamic offsets.
    pad: array<vec4<f32>, 8>,
};

@group(0) @binding(1) var<storage, read_write> views: array<ViewSlot>;

@compute @workgroup_size(64)
fn write_views(@builtin(global_invocation_id) id: vec3<u32>) {
    let slot = id.x;
    if (slot >= vpl_store.header.x || slot >= arrayLength(&views)) {
        return;
    }
    let v = vpl_store.items[slot];
    var out: ViewSlot;
    out.view_proj = mat4x4<f32>(vec4<f32>(1.0, 0.0, 0.0, 0.0), vec4<f32>(0.0, 1.0, 0.0, 0.0), vec4<f32>(0.0, 0.0, 1.0, 0.0), vec4<f32>(0.0, 0.0, 0.0, 1.0));
    out.position = vec4<f32>(v.position.xyz + v.normal.xyz * LIFT, FAR);
    out.tangent = vec4<f32>(v.tangent.xyz, 0.0);
    out.bitangent = vec4<f32>(v.bitangent.xyz, 0.0);
    out.normal = vec4<f32>(v.normal.xyz, 0.0);
    views[slot] = out;
}
