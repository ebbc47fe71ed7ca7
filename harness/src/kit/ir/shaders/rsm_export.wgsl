// The reflective shadow map's texels as the VPL sampler reads them: per texel of the 3x2 atlas
// of faces (the sun: face 0 only), the surface position (w = 1 where a surface was seen), its
// normal (facing the light) and the flux it reflects: albedo × the light's flux through the
// texel — I(ω) · Ω_texel for a light at a point (cube faces at unit distance: Ω = (2/R)² /
// (1 + u² + v²)^{3/2}), E⊥ · A_texel for the sun (its map spans the disc of radius r: A =
// (2r/R)²).

struct RsmParams {
    // x: face edge R; y: faces rendered (6, or 1 for the sun); z, w: unused
    counts: vec4<u32>,
};

@group(0) @binding(0) var<storage, read> rsm_params: RsmParams;
@group(0) @binding(1) var<storage, read> light: Light;
@group(0) @binding(2) var rsm_depth: texture_2d<f32>;
@group(0) @binding(3) var rsm_normal: texture_2d<f32>;
@group(0) @binding(4) var rsm_albedo: texture_2d<f32>;
@group(0) @binding(5) var<storage, read_write> out_position: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> out_normal: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> out_flux: array<vec4<f32>>;
@group(1) @binding(0) var<uniform> face0: View;
@group(1) @binding(1) var<uniform> face1: View;
@group(1) @binding(2) var<uniform> face2: View;
@group(1) @binding(3) var<uniform> face3: View;
@group(1) @binding(4) var<uniform> face4: View;
@group(1) @binding(5) var<uniform> face5: View;

fn face_view(f: u32) -> View {
    switch f {
        case 0u: { return face0; }
        case 1u: { return face1; }
        case 2u: { return face2; }
        case 3u: { return face3; }
        case 4u: { return face4; }
        default: { return face5; }
    }
}

@compute @workgroup_size(64)
fn export_texels(@builtin(global_invocation_id) id: vec3<u32>) {
    let r = rsm_params.counts.x;
    let face = id.y;
    if (id.x >= r * r || face >= 6u) {
        return;
    }
    let x = id.x % r;
    let y = id.x / r;
    let i = (face * r + y) * r + x;
    out_position[i] = vec4<f32>(0.0);
    out_normal[i] = vec4<f32>(0.0, 0.0, 1.0, 0.0);
    out_flux[i] = vec4<f32>(0.0);
    if (face >= rsm_params.counts.y) {
        return;
    }
    let texel = vec2<i32>(i32((face % 3u) * r + x), i32((face / 3u) * r + y));
    let depth = textureLoad(rsm_depth, texel, 0).r;
    if (depth <= 0.0) {
        return;
    }
    let ndc = vec2<f32>((f32(x) + 0.5) / f32(r) * 2.0 - 1.0, 1.0 - (f32(y) + 0.5) / f32(r) * 2.0);
    let h = face_view(face).inv_view_proj * vec4<f32>(ndc, depth, 1.0);
    let p = h.xyz / h.w;
    let n = normalize(textureLoad(rsm_normal, texel, 0).xyz);
    let albedo = textureLoad(rsm_albedo, texel, 0).rgb;
    var through: vec3<f32>;
    if (light.position.w == 3.0) {
        let side = 2.0 * light.direction.w / f32(r);
        through = light.intensity.rgb * side * side;
    } else {
        let w = normalize(p - light.position.xyz);
        let t = 2.0 / f32(r);
        let solid_angle = t * t / pow(1.0 + dot(ndc, ndc), 1.5);
        through = light_intensity(light, w) * solid_angle;
    }
    out_position[i] = vec4<f32>(p, 1.0);
    out_normal[i] = vec4<f32>(n, 0.0);
    out_flux[i] = vec4<f32>(albedo * through, 0.0);
}
