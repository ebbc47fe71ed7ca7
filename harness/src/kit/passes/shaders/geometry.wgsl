// G-buffer and depth-only (shadow map) rendering of the scene's meshes.
#import gibench::mesh

@group(0) @binding(0) var<uniform> view: View;
@vertex
fn vs_main(v: VertexIn) -> MeshOut {
    return mesh_vertex(v, view.view_proj);
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
fn fs_gbuffer(in: MeshOut) -> GBufferOut {
    var n = normalize(in.normal);
    // Shade both sides: the normal faces the camera.
    if (dot(n, view.eye.xyz - in.world) < 0.0) {
        n = -n;
    }
    let albedo = mesh_albedo(in);
    var out: GBufferOut;
    out.normal = vec4<f32>(n, 1.0);
    out.albedo = vec4<f32>(albedo, 1.0);
    return out;
}
