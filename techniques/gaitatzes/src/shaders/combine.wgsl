// Combines the three axes' voxelizations by MAX (Gaitatzes et al. 2010 §4.1) into the voxel
// buffer, and injects each occupied voxel's direct radiosity B as the initial radiance of the
// propagation: a VPL's clamped-cosine lobe about the voxel's normal, L(w) = B / pi max(0, n.w).
// Clears the accumulation. (Plain LPV, `mode=lpv`, injects with lpv.wgsl instead.)

@group(0) @binding(0) var rad_x: texture_2d<f32>;
@group(0) @binding(1) var nrm_x: texture_2d<f32>;
@group(0) @binding(2) var alb_x: texture_2d<f32>;
@group(0) @binding(3) var rad_y: texture_2d<f32>;
@group(0) @binding(4) var nrm_y: texture_2d<f32>;
@group(0) @binding(5) var alb_y: texture_2d<f32>;
@group(0) @binding(6) var rad_z: texture_2d<f32>;
@group(0) @binding(7) var nrm_z: texture_2d<f32>;
@group(0) @binding(8) var alb_z: texture_2d<f32>;
@group(0) @binding(9) var<storage, read_write> voxels: array<Voxel>;
@group(0) @binding(10) var<storage, read_write> propagation: array<Sh3>;
@group(0) @binding(11) var<storage, read_write> accumulation: array<Sh3>;

// The texel of cell `c` in the atlas of slicing axis `axis`: (u, v) within the tile of slice w.
fn atlas_texel(c: vec3<u32>, axis: u32) -> vec2<i32> {
    var p = c;
    if (axis == 0u) {
        p = vec3<u32>(c.y, c.z, c.x);
    } else if (axis == 1u) {
        p = vec3<u32>(c.z, c.x, c.y);
    }
    let tile = vec2<u32>(p.z % COLS, p.z / COLS);
    return vec2<i32>(tile * N + p.xy);
}

@compute @workgroup_size(4, 4, 4)
fn combine(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= vec3<u32>(N))) {
        return;
    }
    var radiosity = vec3<f32>(0.0);
    var normal = vec3<f32>(0.0);
    var albedo = vec3<f32>(0.0);
    var count = 0.0;
    for (var axis = 0u; axis < 3u; axis++) {
        let t = atlas_texel(id, axis);
        var r: vec4<f32>;
        var n: vec4<f32>;
        var a: vec4<f32>;
        if (axis == 0u) {
            r = textureLoad(rad_x, t, 0);
            n = textureLoad(nrm_x, t, 0);
            a = textureLoad(alb_x, t, 0);
        } else if (axis == 1u) {
            r = textureLoad(rad_y, t, 0);
            n = textureLoad(nrm_y, t, 0);
            a = textureLoad(alb_y, t, 0);
        } else {
            r = textureLoad(rad_z, t, 0);
            n = textureLoad(nrm_z, t, 0);
            a = textureLoad(alb_z, t, 0);
        }
        if (r.a > 0.0) {
            radiosity = max(radiosity, r.rgb / r.a);
            normal += n.xyz;
            albedo += a.rgb;
            count += r.a;
        }
    }
    let i = cell_index(vec3<i32>(id));
    var v: Voxel;
    var injected: Sh3;
    if (count > 0.0) {
        let nl = length(normal);
        let unit = select(vec3<f32>(0.0, 1.0, 0.0), normal / nl, nl > 1e-6);
        v.normal = vec4<f32>(unit, 1.0);
        v.albedo = vec4<f32>(albedo / count, 0.0);
        v.radiosity = vec4<f32>(radiosity, 0.0);
        let lobe = sh_cosine_unit(unit);
        injected = Sh3(radiosity.r * lobe, radiosity.g * lobe, radiosity.b * lobe);
    }
    voxels[i] = v;
    propagation[i] = injected;
    accumulation[i] = Sh3(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
}
