// Slice-by-slice voxelization (Gaitatzes et al. 2010, Algorithm 1; Chen and Fang 1998 without
// the XOR): one draw of the scene per slice of the grid along one axis, into that slice's tile
// of the axis's atlas, depth-clipped to the slice; the fragments that land are the slice's
// voxels. Additive blending sums, per voxel, the direct radiosity, the normal and the albedo of
// every fragment, and counts them (alpha). The combine pass averages them and merges the three
// axes. Imports the harness's mesh module; DirectLight::wgsl(3) is composed beside it.
#import gibench::mesh

struct Slice {
    // World -> clip for this slice: x, y over the slice's N x N tile; z = the position along
    // the slicing axis minus the slice index (clipped to [0, 1]: the slice's depth range).
    clip_from_world: mat4x4<f32>,
};

@group(0) @binding(0) var<uniform> slice: Slice;
@vertex
fn vs_voxel(v: VertexIn) -> MeshOut {
    return mesh_vertex(v, slice.clip_from_world);
}

struct VoxelOut {
    // rgb: direct radiosity (albedo x direct irradiance); a: 1 (the fragment count)
    @location(0) radiosity: vec4<f32>,
    // xyz: the surface's unit normal (the side the voxel emits and reflects on); a: 1
    @location(1) normal: vec4<f32>,
    // rgb: albedo; a: 1
    @location(2) albedo: vec4<f32>,
};

@fragment
fn fs_voxel(in: MeshOut) -> VoxelOut {
    // A voxel emits and reflects on the side its surface's normal points to (inside a room,
    // into the room); light reaching the back of a surface (the sun on a roof) stays outside.
    let n = normalize(in.normal);
    var e = vec3<f32>(0.0);
    if (dot(n, light_incidence(light, in.world).xyz) > 0.0) {
        e = direct_irradiance(in.world, n);
    }
    let albedo = mesh_albedo(in);
    var out: VoxelOut;
    out.radiosity = vec4<f32>(albedo * e, 1.0);
    out.normal = vec4<f32>(n, 1.0);
    out.albedo = vec4<f32>(albedo, 1.0);
    return out;
}
