// Direct irradiance from the primary light with a cube shadow map and 16-tap PCF
// (Laine et al. 2007, Section 6).

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var gbuffer_depth: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_albedo: texture_2d<f32>;

@group(1) @binding(0) var<uniform> light: Light;
// The six cube faces side by side in one 3x2 atlas, read with textureLoad as plain floats
// (GLSL cannot texelFetch a depth sampler, and depth texture arrays read back as zero on GL).
@group(1) @binding(1) var shadow_map: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}

// Fraction of the 4x4 PCF kernel around `p` (unit normal `n`) that sees the light.
fn shadow_visibility(p: vec3<f32>, n: vec3<f32>) -> f32 {
    let dist = length(p - light.position.xyz);
    // Normal offset: move the receiver off its surface by the footprint of the PCF kernel
    // (2 texels of a 90-degree face at this distance), so tilted receivers do not shadow
    // themselves; then towards the light by the constant bias (a fraction of the distance).
    let texel_world = 2.0 * dist / light.shadow.x;
    let offset_p = p + n * (2.0 * texel_world);
    let to_p = offset_p - light.position.xyz;
    let face = cube_face(to_p);
    let biased = light.position.xyz + to_p * (1.0 - light.shadow.y);
    let clip = light.faces[face] * vec4<f32>(biased, 1.0);
    let ndc = clip.xyz / clip.w;
    let size = i32(light.shadow.x);
    let tile = vec2<i32>(i32(face % 3u), i32(face / 3u)) * size;
    // Texel coordinates of the receiver; the 4x4 kernel's taps are the texels at offsets
    // -1.5, -0.5, 0.5, 1.5 from it (percentage-closer filtering, Reeves et al. 1987).
    let st = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * light.shadow.x;
    var lit = 0.0;
    for (var y = 0; y < 4; y++) {
        for (var x = 0; x < 4; x++) {
            let t = clamp(vec2<i32>(floor(st + vec2<f32>(f32(x) - 1.5, f32(y) - 1.5))), vec2<i32>(0), vec2<i32>(size - 1));
            let occluder = textureLoad(shadow_map, tile + t, 0).r;
            // Reversed Z: the receiver is lit when it is at least as close as the occluder.
            lit += select(0.0, 1.0, ndc.z >= occluder);
        }
    }
    return lit / 16.0;
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
    let to_light = light.position.xyz - p;
    let r2 = dot(to_light, to_light);
    let l = to_light * inverseSqrt(r2);
    let cos_r = max(dot(nrm.xyz, l), 0.0);
    if (cos_r <= 0.0) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let e = light_intensity(light, -l) * cos_r / r2 * shadow_visibility(p, nrm.xyz);
    return vec4<f32>(e, 1.0);
}
