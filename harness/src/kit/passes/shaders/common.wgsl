// Shared declarations: the module `gibench::common`, the prelude of every harness and technique
// shader (kit::wgsl).

struct View {
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    // xyz: eye position
    eye: vec4<f32>,
    // x, y: target size in pixels; z: near plane; w: unused
    params: vec4<f32>,
};

struct Object {
    model: mat4x4<f32>,
    normal_matrix: mat4x4<f32>,
};

struct Light {
    // xyz: position (the sun: the centre of its disc); w: kind (0 spot, 1 omni, 2 area, 3 sun)
    position: vec4<f32>,
    // xyz: unit direction (spot axis / area normal / sun direction); w: the sun's disc radius
    direction: vec4<f32>,
    // rgb: on-axis radiant intensity (spot/area: Φ/π; omni: Φ/4π); the sun: irradiance E⊥
    intensity: vec4<f32>,
    // x: shadow map size; y: depth bias (fraction of distance); z: shadow near plane; w: PCF taps per side
    shadow: vec4<f32>,
    faces: array<mat4x4<f32>, 6>,
};

// Radiant intensity of the primary light towards unit direction `dir_from_light` (the sun:
// its irradiance E⊥).
fn light_intensity(light: Light, dir_from_light: vec3<f32>) -> vec3<f32> {
    if (light.position.w == 1.0 || light.position.w == 3.0) {
        return light.intensity.rgb;
    }
    return light.intensity.rgb * max(dot(dir_from_light, light.direction.xyz), 0.0);
}

// Unit direction from `p` to the primary light (xyz) and its 1/r² factor (w; 1 for the sun).
fn light_incidence(light: Light, p: vec3<f32>) -> vec4<f32> {
    if (light.position.w == 3.0) {
        return vec4<f32>(-light.direction.xyz, 1.0);
    }
    let d = light.position.xyz - p;
    let r2 = max(dot(d, d), 1e-30);
    return vec4<f32>(d * inverseSqrt(r2), 1.0 / r2);
}

// Cube-map face whose frustum contains direction `v` (+X, -X, +Y, -Y, +Z, -Z).
fn cube_face(v: vec3<f32>) -> u32 {
    let a = abs(v);
    if (a.x >= a.y && a.x >= a.z) {
        return select(1u, 0u, v.x > 0.0);
    }
    if (a.y >= a.z) {
        return select(3u, 2u, v.y > 0.0);
    }
    return select(5u, 4u, v.z > 0.0);
}

// World position of a G-buffer pixel (centre) from its reversed-Z depth.
fn world_from_depth(view: View, pixel: vec2<f32>, depth: f32) -> vec3<f32> {
    let ndc = vec2<f32>(pixel.x / view.params.x * 2.0 - 1.0, 1.0 - pixel.y / view.params.y * 2.0);
    let p = view.inv_view_proj * vec4<f32>(ndc, depth, 1.0);
    return p.xyz / p.w;
}

// A triangle covering the whole target.
fn fullscreen_position(vertex_index: u32) -> vec4<f32> {
    let uv = vec2<f32>(f32((vertex_index << 1u) & 2u), f32(vertex_index & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}
