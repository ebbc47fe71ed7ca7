// G-buffer and depth-only (shadow map) rendering of the scene's meshes.

@group(0) @binding(0) var<uniform> view: View;
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

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) material: u32,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    let world = object.model * vec4<f32>(v.position, 1.0);
    out.world = world.xyz;
    out.clip = view.view_proj * world;
    out.normal = (object.normal_matrix * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = v.uv;
    out.material = v.material;
    return out;
}

@vertex
fn vs_depth(v: VertexIn) -> @builtin(position) vec4<f32> {
    return view.view_proj * (object.model * vec4<f32>(v.position, 1.0));
}

struct GBufferOut {
    @location(0) normal: vec4<f32>,
    @location(1) albedo: vec4<f32>,
};

@fragment
fn fs_gbuffer(in: VertexOut) -> GBufferOut {
    var n = normalize(in.normal);
    // Shade both sides: the normal faces the camera.
    if (dot(n, view.eye.xyz - in.world) < 0.0) {
        n = -n;
    }
    let m = materials[in.material];
    // Sampled unconditionally: implicit-derivative sampling must stay in uniform control flow.
    let texel = textureSample(textures, texture_sampler, in.uv, max(i32(m.w), 0)).rgb;
    let albedo = select(m.rgb, m.rgb * texel, m.w >= 0.0);
    var out: GBufferOut;
    out.normal = vec4<f32>(n, 1.0);
    out.albedo = vec4<f32>(albedo, 1.0);
    return out;
}
