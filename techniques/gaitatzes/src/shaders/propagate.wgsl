// One propagation iteration (Gaitatzes et al. 2010 §4.2, Eq. 8), in two passes so that what
// depends only on the sending cell is computed once per cell and iteration, not once for each
// of its six receivers: `faces`, per cell, the flux it sends through each of its six faces;
// then `propagate`, per cell, the gather of what its six neighbours send it.
//
// Every cell gathers from its six neighbours the radiance each sends through the shared face —
// the neighbour's SH integrated over the face's 90-degree pyramid (SH dot product with the
// pyramid's coefficients; see face_shares) — and takes it as a clamped-cosine lobe of that flux
// along the direction of travel (TRANSPORT 1: into void cells, with the neighbour's own angular
// distribution instead, so a lobe keeps its direction; 2: with the distribution of the
// neighbour's light within the face's pyramid). Void cells pass the gathered radiance on.
// Occupied cells add it to the accumulation as incident radiance and reflect it for
// the next bounce: mirrored along the dominant axis of their normal (the paper's
// simplification of the rotation to the normal), times the albedo (0.5, the paper's constant,
// or the voxel's), and send it on through the faces on their lit side only (the side their
// normal's dominant axis points to: radiance moves through void space, not through walls).
// (Plain LPV, `mode=lpv`, propagates with lpv.wgsl instead.)

// What `faces` writes per cell and `propagate` reads, in two buffers (each the size of an SH
// buffer, so that the grid's largest fits the same limit): per face k (see face_axis), in
// rgb, the flux the cell sends through it per channel (0 through a face it does not pass light
// through); faces 0, 2, 4 (+x, +y, +z) in `senders_pos`, 1, 3, 5 in `senders_neg`. The w
// components, in face order: face 0, 0 for a void cell and 1 + the
// dominant axis of its normal for an occupied one; faces 1-3, the voxel's albedo (written only
// with STORED_ALBEDO).
struct Sender {
    face: array<vec4<f32>, 3>,
};

// `faces`' bindings.
@group(0) @binding(0) var<storage, read> voxels: array<Voxel>;
@group(0) @binding(1) var<storage, read> face_source: array<Sh3>;
@group(0) @binding(2) var<storage, read_write> senders_pos_out: array<Sender>;
@group(0) @binding(3) var<storage, read_write> senders_neg_out: array<Sender>;

// `propagate`'s bindings (the same group, other slots: each pipeline's layout has its own;
// with TRANSPORT 1 and 2 also `source`, binding 8, prepended by the pass with sender_sh).
@group(0) @binding(4) var<storage, read> senders_pos: array<Sender>;
@group(0) @binding(5) var<storage, read> senders_neg: array<Sender>;
@group(0) @binding(6) var<storage, read_write> destination: array<Sh3>;
@group(0) @binding(7) var<storage, read_write> accumulation: array<Sh3>;

// Writes the flux through face k of cell i (the w component is left as it is).
fn send(i: u32, k: u32, v: vec3<f32>) {
    if ((k & 1u) == 0u) {
        senders_pos_out[i].face[k / 2u].x = v.x;
        senders_pos_out[i].face[k / 2u].y = v.y;
        senders_pos_out[i].face[k / 2u].z = v.z;
    } else {
        senders_neg_out[i].face[k / 2u].x = v.x;
        senders_neg_out[i].face[k / 2u].y = v.y;
        senders_neg_out[i].face[k / 2u].z = v.z;
    }
}

// Writes the w component of face k of cell i.
fn send_w(i: u32, k: u32, w: f32) {
    if ((k & 1u) == 0u) {
        senders_pos_out[i].face[k / 2u].w = w;
    } else {
        senders_neg_out[i].face[k / 2u].w = w;
    }
}

// Face k's vec4 of cell i.
fn sent(i: u32, k: u32) -> vec4<f32> {
    if ((k & 1u) == 0u) {
        return senders_pos[i].face[k / 2u];
    }
    return senders_neg[i].face[k / 2u];
}

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

fn dominant_axis(n: vec3<f32>) -> u32 {
    let a = abs(n);
    if (a.x >= a.y && a.x >= a.z) {
        return 0u;
    }
    return select(2u, 1u, a.y >= a.z);
}

// Whether cell `j`, whose voxel is `v`, passes light on through its face towards `d`. Void
// cells pass through every face. Occupied cells only into void neighbours (radiance
// moves through void space, not along the inside of a wall) on the side their normal points
// to (a wall's back passes nothing on). Faces at the grid's edge let light out.
fn passes(j: vec3<i32>, v: Voxel, d: vec3<i32>) -> bool {
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

// The radiance integral of `c` (one channel): c0 times 4 pi Y00.
fn whole_integral(c: vec4<f32>) -> f32 {
    return c.x * 4.0 * 3.14159265 * SH_C0;
}

// What a cell with radiance `c` (one channel) and open faces `open` sends through each face:
// the integral of c over that face's 90-degree pyramid (SH dot product with the pyramid's
// coefficients). Negative integrals (SH ringing) and faces the cell does not pass light
// through are dropped, and the rest rescaled so that the faces together pass on exactly the
// cell's radiance integral (the six pyramids tile the sphere): a void cell keeps its light,
// an occupied one sends all it emits or reflects into the void in front of it.
fn face_shares(c: vec4<f32>, open: array<bool, 6>) -> array<f32, 6> {
    var integral: array<f32, 6>;
    var positive = 0.0;
    for (var k = 0u; k < 6u; k++) {
        integral[k] = max(dot(c, sh_face(vec3<f32>(face_axis(k)))), 0.0);
        if (open[k]) {
            positive += integral[k];
        }
    }
    let whole = whole_integral(c);
    var share = array<f32, 6>(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    if (positive <= 0.0 || whole <= 0.0) {
        return share;
    }
    for (var k = 0u; k < 6u; k++) {
        if (open[k]) {
            share[k] = integral[k] * whole / positive;
        }
    }
    return share;
}

// `c` rescaled to a radiance integral of 1 (0 when its integral is not positive).
fn unit_integral(c: vec4<f32>) -> vec4<f32> {
    let whole = whole_integral(c);
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

// Per cell: the flux it sends through each face. Workgroups of 8x8x4 cells: Propagation::WORKGROUP.
@compute @workgroup_size(8, 8, 4)
fn faces(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= vec3<u32>(N))) {
        return;
    }
    let j = vec3<i32>(id);
    let i = cell_index(j);
    let v = voxels[i];
    var open: array<bool, 6>;
    for (var f = 0u; f < 6u; f++) {
        open[f] = passes(j, v, face_axis(f));
    }
    let s = face_source[i];
    let r = face_shares(s.r, open);
    let g = face_shares(s.g, open);
    let b = face_shares(s.b, open);
    for (var k = 0u; k < 6u; k++) {
        send(i, k, vec3<f32>(r[k], g[k], b[k]));
    }
    if (v.normal.w > 0.0) {
        send_w(i, 0u, 1.0 + f32(dominant_axis(v.normal.xyz)));
    } else {
        send_w(i, 0u, 0.0);
    }
    if (STORED_ALBEDO == 1u) {
        send_w(i, 1u, v.albedo.r);
        send_w(i, 2u, v.albedo.g);
        send_w(i, 3u, v.albedo.b);
    }
}

// Per cell: the gather from its six neighbours, the accumulation and the reflection.
@compute @workgroup_size(8, 8, 4)
fn propagate(@builtin(global_invocation_id) id: vec3<u32>) {
    if (any(id >= vec3<u32>(N))) {
        return;
    }
    let c = vec3<i32>(id);
    var g = Sh3(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    var carried = g;
    for (var k = 0u; k < 6u; k++) {
        // The direction the light travels from the neighbour into this cell.
        let d = face_axis(k);
        let j = c - d;
        if (!in_grid(j)) {
            continue;
        }
        // 0 where the neighbour does not pass light through this face: adding it changes
        // nothing.
        let share = sent(cell_index(j), k).xyz;
        let lobe = sh_cosine_unit(vec3<f32>(d));
        g.r += share.r * lobe;
        g.g += share.g * lobe;
        g.b += share.b * lobe;
        if (TRANSPORT != 0u && any(share != vec3<f32>(0.0))) {
            let s = sender_sh(cell_index(j));
            if (TRANSPORT == 1u) {
                // The flux with the sender's angular distribution (its SH over its integral).
                carried.r += share.r * unit_integral(s.r);
                carried.g += share.g * unit_integral(s.g);
                carried.b += share.b * unit_integral(s.b);
            } else {
                // The flux with the distribution of what crossed the face (the sender's SH
                // over the face's pyramid, re-projected).
                let df = vec3<f32>(d);
                carried.r += share.r * through_face(s.r, df);
                carried.g += share.g * through_face(s.g, df);
                carried.b += share.b * through_face(s.b, df);
            }
        }
    }
    let i = cell_index(c);
    let code = sent(i, 0u).w;
    let occupied = code > 0.0;
    if (TRANSPORT != 0u && !occupied) {
        g = carried;
    }
    if (occupied) {
        let a = accumulation[i];
        accumulation[i] = Sh3(a.r + g.r, a.g + g.g, a.b + g.b);
        let axis = u32(code) - 1u;
        var rho = vec3<f32>(0.5);
        if (STORED_ALBEDO == 1u) {
            rho = vec3<f32>(sent(i, 1u).w, sent(i, 2u).w, sent(i, 3u).w);
        }
        destination[i] = Sh3(rho.r * mirror(g.r, axis), rho.g * mirror(g.g, axis), rho.b * mirror(g.b, axis));
    } else {
        destination[i] = g;
    }
}
