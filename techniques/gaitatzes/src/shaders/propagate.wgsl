// One propagation iteration (Gaitatzes et al. 2010 §4.2, Eq. 8): every cell gathers from its six
// neighbours the radiance each sends through the shared face — the neighbour's SH integrated
// over the face's 90-degree pyramid (SH dot product with the pyramid's coefficients; see
// face_share) — and takes it as a clamped-cosine lobe of that flux along the direction of
// travel (TRANSPORT 1: into void cells, with the neighbour's own angular distribution instead,
// so a lobe keeps its direction; 2: with the distribution of the neighbour's light within the
// face's pyramid). Void cells pass the gathered radiance on. Occupied cells
// (MODE 0) add it to the accumulation as incident radiance and reflect it for the next bounce:
// mirrored along the dominant axis of their normal (the paper's simplification of the rotation
// to the normal), times the albedo (0.5, the paper's constant, or the voxel's), and send it on
// through the faces on their lit side only (the side their normal's dominant axis points to:
// radiance moves through void space, not through walls). Plain LPV
// (MODE 1): no occupancy, no reflection; every cell accumulates what passes.

@group(0) @binding(0) var<storage, read> voxels: array<Voxel>;
@group(0) @binding(1) var<storage, read> source: array<Sh3>;
@group(0) @binding(2) var<storage, read_write> destination: array<Sh3>;
@group(0) @binding(3) var<storage, read_write> accumulation: array<Sh3>;

// The SH with the l = 1 coefficient of axis `axis` (0 x, 1 y, 2 z) negated.
fn mirror(c: vec4<f32>, axis: u32) -> vec4<f32> {
    if (axis == 0u) {
        return vec4<f32>(c.x, c.y, c.z, -c.w);
    }
    if (axis == 1u) {
        return vec4<f32>(c.x, -c.y, c.z, c.w);
    }
    return vec4<f32>(c.x, c.y, -c.z, c.w);
}

// The unit axis of face k (0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z).
fn face_axis(k: u32) -> vec3<i32> {
    var d = vec3<i32>(0);
    d[k / 2u] = select(1, -1, (k & 1u) == 1u);
    return d;
}

// Whether cell `j` passes light on through its face towards `d`. Void cells pass through
// every face. Occupied cells (MODE 0) only into void neighbours (radiance moves through void
// space, not along the inside of a wall) on the side their normal points to (a wall's back
// passes nothing on). Faces at the grid's edge let light out.
fn passes(j: vec3<i32>, d: vec3<i32>) -> bool {
    if (MODE != 0u) {
        return true;
    }
    let v = voxels[cell_index(j)];
    if (v.normal.w <= 0.0) {
        return true;
    }
    let axis = dominant_axis(v.normal.xyz);
    if (f32(d[axis]) * v.normal[axis] < 0.0) {
        return false;
    }
    let k = j + d;
    return !in_grid(k) || voxels[cell_index(k)].normal.w <= 0.0;
}

// What a cell with radiance `c` (one channel) and open faces `open` sends through its face towards unit axis `d`:
// the integral of c over that face's 90-degree pyramid. Negative integrals (SH ringing) and
// faces the cell does not pass light through are dropped, and the rest rescaled so that the
// faces together pass on exactly the cell's radiance integral (the six pyramids tile the
// sphere): a void cell keeps its light, an occupied one sends all it emits or reflects into
// the void in front of it.
fn face_share(c: vec4<f32>, d: vec3<i32>, open: array<bool, 6>) -> f32 {
    var positive = 0.0;
    for (var k = 0u; k < 6u; k++) {
        if (open[k]) {
            positive += max(dot(c, sh_face(vec3<f32>(face_axis(k)))), 0.0);
        }
    }
    // The whole integral: c0 times 4 pi Y00.
    let whole = c.x * 4.0 * 3.14159265 * SH_C0;
    if (positive <= 0.0 || whole <= 0.0) {
        return 0.0;
    }
    return max(dot(c, sh_face(vec3<f32>(d))), 0.0) * whole / positive;
}

// `c` rescaled to a radiance integral of 1 (0 when its integral is not positive).
fn unit_integral(c: vec4<f32>) -> vec4<f32> {
    let whole = c.x * 4.0 * 3.14159265 * SH_C0;
    if (whole <= 0.0) {
        return vec4<f32>(0.0);
    }
    return c / whole;
}

// The SH of `c` restricted to the pyramid of the face towards `d` (its integral and first
// moment), rescaled to an integral of 1 (0 when the face's integral is not positive).
fn through_face(c: vec4<f32>, d: vec3<f32>) -> vec4<f32> {
    let flux = dot(c, sh_face(d));
    if (flux <= 0.0) {
        return vec4<f32>(0.0);
    }
    let m = sh_face_moment(c, d);
    return vec4<f32>(SH_C0 * flux, SH_C1 * m.y, SH_C1 * m.z, SH_C1 * m.x) / flux;
}

fn dominant_axis(n: vec3<f32>) -> u32 {
    let a = abs(n);
    if (a.x >= a.y && a.x >= a.z) {
        return 0u;
    }
    return select(2u, 1u, a.y >= a.z);
}

@compute @workgroup_size(4, 4, 4)
fn propagate(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= vec3<u32>(N))) {
        return;
    }
    let c = vec3<i32>(id);
    let here = voxels[cell_index(c)];
    var g = Sh3(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    var carried = g;
    for (var k = 0u; k < 6u; k++) {
        // The direction the light travels from the neighbour into this cell.
        let d = face_axis(k);
        let j = c - d;
        if (!in_grid(j) || !passes(j, d)) {
            continue;
        }
        var open: array<bool, 6>;
        for (var f = 0u; f < 6u; f++) {
            open[f] = passes(j, face_axis(f));
        }
        let s = source[cell_index(j)];
        let share = vec3<f32>(face_share(s.r, d, open), face_share(s.g, d, open), face_share(s.b, d, open));
        let lobe = sh_cosine_unit(vec3<f32>(d));
        g.r += share.r * lobe;
        g.g += share.g * lobe;
        g.b += share.b * lobe;
        if (TRANSPORT == 1u) {
            // The flux with the sender's angular distribution (its SH over its integral).
            carried.r += share.r * unit_integral(s.r);
            carried.g += share.g * unit_integral(s.g);
            carried.b += share.b * unit_integral(s.b);
        } else if (TRANSPORT == 2u) {
            // The flux with the distribution of what crossed the face (the sender's SH over
            // the face's pyramid, re-projected).
            let df = vec3<f32>(d);
            carried.r += share.r * through_face(s.r, df);
            carried.g += share.g * through_face(s.g, df);
            carried.b += share.b * through_face(s.b, df);
        }
    }
    let i = cell_index(c);
    let v = here;
    if (TRANSPORT != 0u && !(MODE == 0u && v.normal.w > 0.0)) {
        g = carried;
    }
    if (MODE == 0u && v.normal.w > 0.0) {
        let a = accumulation[i];
        accumulation[i] = Sh3(a.r + g.r, a.g + g.g, a.b + g.b);
        let axis = dominant_axis(v.normal.xyz);
        var rho = vec3<f32>(0.5);
        if (STORED_ALBEDO == 1u) {
            rho = v.albedo.rgb;
        }
        destination[i] = Sh3(rho.r * mirror(g.r, axis), rho.g * mirror(g.g, axis), rho.b * mirror(g.b, axis));
    } else {
        if (MODE == 1u) {
            let a = accumulation[i];
            accumulation[i] = Sh3(a.r + g.r, a.g + g.g, a.b + g.b);
        }
        destination[i] = g;
    }
}
