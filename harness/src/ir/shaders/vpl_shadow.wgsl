// Depth maps of virtual point lights: paraboloid (Brabec et al. 2002, as Laine et al. 2007 use)
// or cube faces, all in one depth atlas. Reversed depth everywhere: 1 near, 0 far/empty.

struct VplView {
    // Cube faces: view-projection of the face (reversed-Z); unused for paraboloids.
    view_proj: mat4x4<f32>,
    // xyz: VPL position; w: far distance (paraboloid depth = 1 - distance / far)
    position: vec4<f32>,
    // The VPL's frame: tangent, bitangent, normal (xyz).
    tangent: vec4<f32>,
    bitangent: vec4<f32>,
    normal: vec4<f32>,
};

@group(0) @binding(0) var<uniform> vpl_view: VplView;
@group(1) @binding(0) var<uniform> object: Object;

struct ParaboloidOut {
    @builtin(position) clip: vec4<f32>,
    // z of the unit direction in the VPL's frame: < 0 behind the VPL.
    @location(0) side: f32,
};

@vertex
fn vs_paraboloid(@location(0) position: vec3<f32>) -> ParaboloidOut {
    let world = (object.model * vec4<f32>(position, 1.0)).xyz;
    let d = world - vpl_view.position.xyz;
    let local = vec3<f32>(dot(d, vpl_view.tangent.xyz), dot(d, vpl_view.bitangent.xyz), dot(d, vpl_view.normal.xyz));
    let len = max(length(local), 1e-20);
    let dn = local / len;
    var out: ParaboloidOut;
    out.clip = vec4<f32>(dn.xy / (1.0 + max(dn.z, -0.999)), clamp(1.0 - len / vpl_view.position.w, 0.0, 1.0), 1.0);
    out.side = dn.z;
    return out;
}

@fragment
fn fs_paraboloid(in: ParaboloidOut) {
    if (in.side < 0.0) {
        discard;
    }
}

@vertex
fn vs_cube(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return vpl_view.view_proj * (object.model * vec4<f32>(position, 1.0));
}

// A triangle covering the viewport at depth 0 (empty), drawn with compare Always to clear one
// tile of the atlas.
@vertex
fn vs_clear(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}
