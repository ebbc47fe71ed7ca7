// Outgoing radiance L = albedo / pi * (E_direct + E_indirect), and its display encoding.

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var gbuffer_depth: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_albedo: texture_2d<f32>;

struct ComposeParams {
    // x: exposure
    params: vec4<f32>,
};

@group(1) @binding(0) var direct_irradiance: texture_2d<f32>;
@group(1) @binding(1) var indirect_irradiance: texture_2d<f32>;
@group(1) @binding(2) var<storage, read> compose: ComposeParams;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}

struct ComposeOut {
    @location(0) radiance: vec4<f32>,
    @location(1) display: vec4<f32>,
};

@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> ComposeOut {
    let pix = vec2<i32>(frag.xy);
    let albedo = textureLoad(gbuffer_albedo, pix, 0).rgb;
    // A technique's estimate can undershoot below 0 (the runner counts and warns); no irradiance is.
    let e = textureLoad(direct_irradiance, pix, 0).rgb
        + max(textureLoad(indirect_irradiance, pix, 0).rgb, vec3<f32>(0.0));
    let radiance = albedo * e / 3.14159265358979;
    var out: ComposeOut;
    out.radiance = vec4<f32>(radiance, 1.0);
    // The display target is sRGB: the hardware encodes on write.
    out.display = vec4<f32>(clamp(radiance * compose.params.x, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
    return out;
}
