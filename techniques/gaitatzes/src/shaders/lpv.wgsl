// Light propagation volumes (Kaplanyan 2009; Kaplanyan and Dachsbacher 2010), `mode=lpv`: the
// contrast of Gaitatzes et al.'s Figure 6. Expects grid.wgsl and sh::wgsl() prepended, and
// TEXELS (the reflective shadow map's texels), LPV_FRONT and LPV_SIDE (the solid angles, in
// steradians, of a neighbour's far face and of one of its side faces seen from a cell's
// centre: slab::kaplanyan_weights) and FIXED (the fixed-point range of the injection).
//
// Injection, per frame: every texel of the reflective shadow map is a VPL of flux Φ at its
// surface point, moved half a cell along its normal (against self-illumination; and 1/64 of a
// cell more, so that a surface at a cell's centre, where the grid puts the walls on the
// scene's bounds, lands in the next cell whatever the last bits of its position) and added to
// the cell it then lies in as a clamped-cosine intensity lobe about its normal, Φ/π max(0, n.ω),
// divided by the cell's face area to stand for radiance. The sums are taken in fixed point with
// integer atomics (deterministic whatever the order; GL has no float atomics): `clear` resets
// the largest texel flux, `largest` finds it, `inject` adds each texel in units of
// largest × TEXELS / FIXED (no cell can exceed the range), `resolve` turns the sums into the
// first propagation field and the accumulation's start (the injected light is lit with too,
// as in the published accumulation of every step) and clears them for the next frame.
//
// Propagation, per iteration and cell (`lpv_propagate`): from each of its six neighbours, the
// flux through each of this cell's five faces other than the shared one: the neighbour's
// intensity towards the face's centre times the face's solid angle; each re-emitted from the
// cell's centre as a clamped-cosine lobe along the face's outward normal. No occlusion, no
// reflection; every step is added to the accumulation.

// The injection's sums: 12 per cell (r, g, b × 4 coefficients), then the largest texel flux's
// bits (a positive float's bits order as the float does).
@group(0) @binding(0) var<storage, read> rsm_position: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> rsm_normal: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> rsm_flux: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> sums: array<atomic<i32>>;

@group(0) @binding(4) var<storage, read_write> injected: array<Sh3>;
@group(0) @binding(5) var<storage, read_write> accumulation: array<Sh3>;

// The largest texel flux's slot in `sums`.
fn largest_slot() -> u32 {
    return 12u * N * N * N;
}

// What one unit of the fixed-point sums stands for (0 before any flux).
fn unit() -> f32 {
    let largest = bitcast<f32>(atomicLoad(&sums[largest_slot()]));
    let lobe = max(SH_COS0, SH_COS1) / 3.14159265 / (CELL * CELL);
    return largest * f32(TEXELS) * lobe / FIXED;
}

@compute @workgroup_size(1)
fn clear() {
    atomicStore(&sums[largest_slot()], 0);
}

@compute @workgroup_size(64)
fn largest(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= TEXELS || rsm_position[id.x].w <= 0.0) {
        return;
    }
    let f = rsm_flux[id.x].rgb;
    atomicMax(&sums[largest_slot()], bitcast<i32>(max(f.r, max(f.g, f.b))));
}

@compute @workgroup_size(64)
fn inject(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= TEXELS || rsm_position[id.x].w <= 0.0) {
        return;
    }
    let u = unit();
    if (u <= 0.0) {
        return;
    }
    let n = normalize(rsm_normal[id.x].xyz);
    let p = rsm_position[id.x].xyz + (0.5 + 1.0 / 64.0) * CELL * n;
    let c = vec3<i32>(floor((p - ORIGIN) / CELL));
    if (!in_grid(c)) {
        return;
    }
    let lobe = sh_cosine_unit(n) / (CELL * CELL);
    let f = rsm_flux[id.x].rgb;
    let base = 12u * cell_index(c);
    for (var ch = 0u; ch < 3u; ch++) {
        for (var k = 0u; k < 4u; k++) {
            let q = i32(round(f[ch] * lobe[k] / u));
            if (q != 0) {
                atomicAdd(&sums[base + 4u * ch + k], q);
            }
        }
    }
}

@compute @workgroup_size(4, 4, 4)
fn resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= vec3<u32>(N))) {
        return;
    }
    let i = cell_index(vec3<i32>(id));
    let u = unit();
    var v: array<vec4<f32>, 3>;
    for (var ch = 0u; ch < 3u; ch++) {
        for (var k = 0u; k < 4u; k++) {
            v[ch][k] = f32(atomicExchange(&sums[12u * i + 4u * ch + k], 0)) * u;
        }
    }
    let s = Sh3(v[0], v[1], v[2]);
    injected[i] = s;
    accumulation[i] = s;
}

// Propagation's bindings (the same group, other slots).
@group(0) @binding(6) var<storage, read> source: array<Sh3>;
@group(0) @binding(7) var<storage, read_write> destination: array<Sh3>;
@group(0) @binding(8) var<storage, read_write> accumulated: array<Sh3>;

// The flux through a face of solid angle `solid` seen towards unit `w` from a cell holding `c`
// (one channel): its intensity that way times the solid angle (none where the SH rings
// negative).
fn face_flux(c: vec4<f32>, w: vec3<f32>, solid: f32) -> f32 {
    return solid * max(dot(c, sh_lobe(SH_C0, SH_C1, w)), 0.0);
}

@compute @workgroup_size(8, 8, 4)
fn lpv_propagate(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= vec3<u32>(N))) {
        return;
    }
    let c = vec3<i32>(id);
    var g = Sh3(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    for (var k = 0u; k < 6u; k++) {
        // The direction from the neighbour to this cell.
        let d = face_axis(k);
        let j = c - d;
        if (!in_grid(j)) {
            continue;
        }
        let s = source[cell_index(j)];
        for (var f = 0u; f < 6u; f++) {
            let a = face_axis(f);
            if (all(a == -d)) {
                continue;
            }
            // From the neighbour's centre to this face's centre: d + a/2.
            var w = vec3<f32>(d);
            var solid = LPV_FRONT;
            if (!all(a == d)) {
                w = (vec3<f32>(d) + 0.5 * vec3<f32>(a)) / sqrt(1.25);
                solid = LPV_SIDE;
            }
            let lobe = sh_cosine_unit(vec3<f32>(a));
            g.r += face_flux(s.r, w, solid) * lobe;
            g.g += face_flux(s.g, w, solid) * lobe;
            g.b += face_flux(s.b, w, solid) * lobe;
        }
    }
    let i = cell_index(c);
    destination[i] = g;
    let acc = accumulated[i];
    accumulated[i] = Sh3(acc.r + g.r, acc.g + g.g, acc.b + g.b);
}
