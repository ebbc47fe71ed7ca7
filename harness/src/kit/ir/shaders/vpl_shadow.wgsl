// Depth maps of virtual point lights: paraboloid (Brabec et al. 2002, as Laine et al. 2007 use),
// cube faces or octahedral faces (Barczak 2006), all in one depth atlas. Reversed depth
// everywhere: 1 near, 0 far/empty.

struct VplView {
    // Cube faces: view-projection of the face (reversed-Z); unused for paraboloids.
    view_proj: mat4x4<f32>,
    // xyz: VPL position; w: far distance (paraboloid depth = 1 - distance / far)
    position: vec4<f32>,
    // The VPL's frame: tangent, bitangent, normal (xyz). Octahedral faces: tangent.w and
    // bitangent.w are the signs (sx, sy) of the face's quadrant, normal.w the near distance.
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

struct OctahedralOut {
    @builtin(position) clip: vec4<f32>,
    // The point in the VPL's frame (z along the normal), interpolated exactly: it is linear on
    // the triangle and the face's projection is a perspective one.
    @location(0) local: vec3<f32>,
};

// One face of an octahedral map (Barczak 2006 §4.2.1): the projection from the VPL onto the
// face's plane sx*x + sy*y + z = 1, unfolded, (u, v) = (x + y, x - y) / (sx*x + sy*y + z), is
// projective, so the triangle is rasterised exactly. The clip depth w - near keeps only points
// at least `near` in front of the face's plane (as the cube faces' near plane does; clipping at
// w = 0 itself would make vertices at infinity); the fragment writes the depth and keeps its
// quadrant (the face's triangle of the square).
@vertex
fn vs_octahedral(@location(0) position: vec3<f32>) -> OctahedralOut {
    let world = (object.model * vec4<f32>(position, 1.0)).xyz;
    let d = world - vpl_view.position.xyz;
    let local = vec3<f32>(dot(d, vpl_view.tangent.xyz), dot(d, vpl_view.bitangent.xyz), dot(d, vpl_view.normal.xyz));
    let w = vpl_view.tangent.w * local.x + vpl_view.bitangent.w * local.y + local.z;
    var out: OctahedralOut;
    out.clip = vec4<f32>(local.x + local.y, local.x - local.y, w - vpl_view.normal.w, w);
    out.local = local;
    return out;
}

// Keeps the face's quadrant of the upper hemisphere, widened by 1e-3 of the distance, and stores
// the exact distance (Barczak: the pixel shader writes the light-space distance as depth). The
// margin makes neighbouring faces overlap by a sliver: with exact quadrants, texel centres on a
// face boundary (the square's diagonals) were discarded by both faces' interpolation rounding,
// leaving cracks of empty texels that directions near a face boundary looked up (a floor seen
// from just above it lies along one: 40 % of a wall's shadow leaked, tests/vpl_maps.rs). A
// sliver point drawn by the neighbouring face lands within 2e-3 of its true place in the map.
@fragment
fn fs_octahedral(in: OctahedralOut) -> @builtin(frag_depth) f32 {
    let sx = vpl_view.tangent.w;
    let sy = vpl_view.bitangent.w;
    let margin = 1e-3 * length(in.local);
    if (in.local.z < -margin || sx * in.local.x < -margin || sy * in.local.y < -margin) {
        discard;
    }
    return clamp(1.0 - length(in.local) / vpl_view.position.w, 0.0, 1.0);
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
