// The shared direct-light pass: direct irradiance per G-buffer pixel (DIRECT_LIGHT_WGSL, with
// its bindings at group 1, is prepended).

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var gbuffer_depth: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_albedo: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}

@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pix = vec2<i32>(frag.xy);
    let depth = textureLoad(gbuffer_depth, pix, 0).r;
    let nrm = textureLoad(gbuffer_normal, pix, 0);
    if (nrm.w == 0.0) {
        return vec4<f32>(0.0);
    }
    let p = world_from_depth(view, frag.xy, depth);
    return vec4<f32>(direct_irradiance(p, nrm.xyz), 1.0);
}
