// Barczak 2006 §4.4: complex meshes by precomputed radiance transfer. The vertex shader dots the
// vertex's 25 transfer coefficients with the object's lighting environment (5th-order SH, RGB);
// the fragment writes the interpolated irradiance where the mover is what the camera sees.

@group(0) @binding(0) var<uniform> camera: View;
@group(1) @binding(0) var<uniform> object: Object;
@group(2) @binding(0) var<uniform> view: View;
@group(2) @binding(1) var gbuffer_depth: texture_2d<f32>;
@group(2) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(2) @binding(3) var gbuffer_albedo: texture_2d<f32>;
// 25 coefficients per vertex.
@group(3) @binding(0) var<storage, read> transfer: array<f32>;
// The lighting environment: 25 RGB coefficients (w unused).
@group(3) @binding(1) var<storage, read> lighting: array<vec4<f32>, 25>;

struct PrtOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) irradiance: vec3<f32>,
};

@vertex
fn vs_prt(@builtin(vertex_index) index: u32, @location(0) position: vec3<f32>) -> PrtOut {
    var out: PrtOut;
    out.clip = camera.view_proj * (object.model * vec4<f32>(position, 1.0));
    var e = vec3<f32>(0.0);
    for (var k = 0u; k < 25u; k++) {
        e += transfer[index * 25u + k] * lighting[k].xyz;
    }
    out.irradiance = max(e, vec3<f32>(0.0));
    return out;
}

@fragment
fn fs_prt(in: PrtOut) -> @location(0) vec4<f32> {
    let shown = textureLoad(gbuffer_depth, vec2<i32>(in.clip.xy), 0).r;
    if (abs(in.clip.z - shown) > 1e-4 * shown) {
        discard;
    }
    return vec4<f32>(in.irradiance, 1.0);
}
