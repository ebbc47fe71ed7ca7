// Direct irradiance from the primary light with its shadow map and 16-tap PCF (Laine et al.
// 2007, Section 6): the cube map of a point light (3x2 faces in one atlas) or the sun's one
// orthographic map (in face 0's place). Any shader may prepend this after declaring
//   var<uniform> light: Light;              (binding 0 of DirectLight::light_group)
//   var direct_shadow_map: texture_2d<f32>; (binding 1)
// as DirectLight::wgsl(group) does. The atlas is read with textureLoad as plain floats (GLSL
// cannot texelFetch a depth sampler, and depth texture arrays read back as zero on GL).

// Fraction of the 4x4 PCF kernel around `p` (unit normal `n`) that sees the light.
fn direct_shadow(p: vec3<f32>, n: vec3<f32>) -> f32 {
    let sun = light.position.w == 3.0;
    // Normal offset: move the receiver off its surface by the footprint of the PCF kernel
    // (2 texels: of a 90-degree face at this distance, or of the sun's map), so tilted
    // receivers do not shadow themselves; then towards the light by the constant bias (a
    // fraction of the distance; for the sun, of its disc radius).
    var texel_world = 2.0 * length(p - light.position.xyz) / light.shadow.x;
    if (sun) {
        texel_world = 2.0 * light.direction.w / light.shadow.x;
    }
    let offset_p = p + n * (2.0 * texel_world);
    var face = 0u;
    var biased = offset_p - light.direction.xyz * (light.shadow.y * light.direction.w);
    if (!sun) {
        let to_p = offset_p - light.position.xyz;
        face = cube_face(to_p);
        biased = light.position.xyz + to_p * (1.0 - light.shadow.y);
    }
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
            let occluder = textureLoad(direct_shadow_map, tile + t, 0).r;
            // Reversed Z: the receiver is lit when it is at least as close as the occluder.
            lit += select(0.0, 1.0, ndc.z >= occluder);
        }
    }
    return lit / 16.0;
}

// Direct irradiance at surface point `p` with unit normal `n`: I(ω) cos θ / r² × visibility
// (the sun: E⊥ cos θ × visibility).
fn direct_irradiance(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let inc = light_incidence(light, p);
    let cos_r = dot(n, inc.xyz);
    if (cos_r <= 0.0) {
        return vec3<f32>(0.0);
    }
    return light_intensity(light, -inc.xyz) * cos_r * inc.w * direct_shadow(p, n);
}
