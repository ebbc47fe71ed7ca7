// The scene's meshes as every rasterising pass draws them: the object and material bindings
// (groups 1 and 2, the shared layouts of `FrameUniforms` and `GpuScene`), the vertex layout of
// `GpuScene::vertex_layout`, the vertex transform to any clip space, and a fragment's albedo.
// The module `gibench::mesh`: imported by the G-buffer and shadow-map passes and by Gaitatzes'
// voxelization; each declares its own group 0 (the view or the slice).

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

struct MeshOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) material: u32,
};

// `v` placed by the object's model matrix, projected by `clip_from_world`.
fn mesh_vertex(v: VertexIn, clip_from_world: mat4x4<f32>) -> MeshOut {
    var out: MeshOut;
    let world = object.model * vec4<f32>(v.position, 1.0);
    out.world = world.xyz;
    out.clip = clip_from_world * world;
    out.normal = (object.normal_matrix * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = v.uv;
    out.material = v.material;
    return out;
}

// The fragment's albedo: its material's colour, times its texture where it has one (w >= 0
// names the texture layer). Sampled unconditionally: implicit-derivative sampling must stay in
// uniform control flow.
fn mesh_albedo(in: MeshOut) -> vec3<f32> {
    let m = materials[in.material];
    let texel = textureSample(textures, texture_sampler, in.uv, max(i32(m.w), 0)).rgb;
    return select(m.rgb, m.rgb * texel, m.w >= 0.0);
}
