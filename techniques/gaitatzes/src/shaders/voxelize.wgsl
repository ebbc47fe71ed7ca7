// Slice-by-slice voxelization (Gaitatzes et al. 2010, Algorithm 1; Chen and Fang 1998 without
// the XOR): one draw of the scene per slice of the grid along one axis, into that slice's tile
// of the axis's atlas, depth-clipped to the slice; the fragments that land are the slice's
// voxels. Additive blending sums, per voxel, the direct radiosity, the normal and the albedo of
// every fragment, and counts them (alpha). The combine pass averages them and merges the three
// axes. Expects DirectLight::wgsl(3) prepended.

struct Slice {
    // World -> clip for this slice: x, y over the slice's N x N tile; z = the position along
    // the slicing axis minus the slice index (clipped to [0, 1]: the slice's depth range).
    clip_from_world: mat4x4<f32>,
};

@group(0) @binding(0) var<uniform> slice: Slice;
@group(1) @binding(0) var<uniform> object: Object;
@group(2) @binding(0) var<uniform> materials: array<vec4<f32>, 1024>;
@group(2) @binding(1) var textures: texture_2d_array<f32>;
@group(2) @binding(2) var texture_sampler: sampler;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) material: u32,
};

struct VoxelIn {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) material: u32,
};

@vertex
fn vs_voxel(v: VertexIn) -> VoxelIn {
    var out: VoxelIn;
    let world = object.model * vec4<f32>(v.position, 1.0);
    out.world = world.xyz;
    out.clip = slice.clip_from_world * world;
    out.normal = (object.normal_matrix * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = v.uv;
    out.material = v.material;
    return out;
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
fn fs_voxel(in: VoxelIn) -> VoxelOut {
    // A voxel emits and reflects on the side its surface's normal points to (inside a room,
    // into the room); light reaching the back of a surface (the sun on a roof) stays outside.
    let n = normalize(in.normal);
    var e = vec3<f32>(0.0);
    if (dot(n, light_incidence(light, in.world).xyz) > 0.0) {
        e = direct_irradiance(in.world, n);
    }
    let m = materials[in.material];
    // Sampled unconditionally: implicit-derivative sampling must stay in uniform control flow.
    let texel = textureSample(textures, texture_sampler, in.uv, max(i32(m.w), 0)).rgb;
    let albedo = select(m.rgb, m.rgb * texel, m.w >= 0.0);
    var out: VoxelOut;
    out.radiosity = vec4<f32>(albedo * e, 1.0);
    out.normal = vec4<f32>(n, 1.0);
    out.albedo = vec4<f32>(albedo, 1.0);
    return out;
}
