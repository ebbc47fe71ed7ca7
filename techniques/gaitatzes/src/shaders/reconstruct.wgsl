// Final reconstruction (Gaitatzes et al. 2010 §4.3, Eq. 11-12): per pixel, the accumulated
// incident radiance interpolated trilinearly from the eight nearest grid points, using only
// occupied ones (plain LPV: all), and the irradiance as its SH dot product with the clamped
// cosine about the surface normal, E = integral of L(w) max(0, -n.w) dw, times the
// flux-to-irradiance constant 12/7 (sh_irradiance; sh::flux_to_irradiance derives it): the
// propagation delivers flux as unit-integral cosine lobes, whose band-limited dot product with
// the cosine is 7/12 of the flux they carry head-on. Plain LPV (MODE 1) takes the dot product
// as it is, as light propagation volumes do: its grid holds radiance, not flux through faces.
// Expects the G-buffer's read group at 0.

@group(0) @binding(0) var<uniform> camera: View;
@group(0) @binding(1) var gbuffer_depth: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_albedo: texture_2d<f32>;
@group(1) @binding(0) var<storage, read> voxels: array<Voxel>;
@group(1) @binding(1) var<storage, read> accumulation: array<Sh3>;
@group(1) @binding(2) var output: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn reconstruct(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(output);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let px = vec2<i32>(id.xy);
    let depth = textureLoad(gbuffer_depth, px, 0).x;
    let nrm = textureLoad(gbuffer_normal, px, 0);
    if (depth <= 0.0 || nrm.w <= 0.0) {
        textureStore(output, px, vec4<f32>(0.0, 0.0, 0.0, 1.0));
        return;
    }
    let p = world_from_depth(camera, vec2<f32>(id.xy) + 0.5, depth);
    let n = normalize(nrm.xyz);
    let g = (p - ORIGIN) / CELL - 0.5;
    let base = vec3<i32>(floor(g));
    let f = g - floor(g);
    var sum = Sh3(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    var weight = 0.0;
    for (var k = 0u; k < 8u; k++) {
        let o = vec3<i32>(i32(k & 1u), i32((k >> 1u) & 1u), i32((k >> 2u) & 1u));
        let c = base + o;
        if (!in_grid(c)) {
            continue;
        }
        let i = cell_index(c);
        if (MODE == 0u && voxels[i].normal.w <= 0.0) {
            continue;
        }
        let t = mix(1.0 - f, f, vec3<f32>(o));
        let w = t.x * t.y * t.z;
        let a = accumulation[i];
        sum = Sh3(sum.r + w * a.r, sum.g + w * a.g, sum.b + w * a.b);
        weight += w;
    }
    var e = vec3<f32>(0.0);
    if (weight > 0.0) {
        e = vec3<f32>(sh_irradiance(sum.r, n), sh_irradiance(sum.g, n), sh_irradiance(sum.b, n)) / weight;
        if (MODE == 1u) {
            e /= SH_FLUX_TO_IRRADIANCE;
        }
    }
    textureStore(output, px, vec4<f32>(e, 1.0));
}
