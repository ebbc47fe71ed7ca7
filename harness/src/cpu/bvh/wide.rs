//! An eight-wide BVH for single-ray CPU traversal: each node holds its eight children's boxes
//! as lanes (x/y/z minima and maxima, one row of eight each), and each leaf is a group of up to
//! eight triangles stored the same way (first corner and edges), so one step tests eight boxes
//! or eight triangles: one AVX instruction per operation where the CPU has AVX2 (checked at
//! run time), two four-lane ones (SSE2, NEON) elsewhere. Built by collapsing `obvhs`'s binary
//! PLOC tree: every subtree of at most eight triangles becomes one leaf group, and a node takes
//! in its largest children's children until it has eight.
//!
//! The triangle test is Möller–Trumbore with the scalar test's operations in the scalar test's
//! order (`super::intersect`), so each lane gives bit for bit the scalar answer; box tests widen
//! the exit distance by a few ulps (Ize 2013) so rounding never culls a triangle the ray hits.

use std::mem::MaybeUninit;

use glam::{Vec3, Vec4};
use obvhs::bvh2::Bvh2;
use obvhs::triangle::Triangle;

/// A child code: an inner node's index, `LEAF | group`, or `EMPTY`.
const LEAF: u32 = 1 << 31;
const EMPTY: u32 = u32::MAX;

/// Stack entries a traversal keeps on the call stack (enough for a tree 9 levels deep, as
/// Sibenik's 80k triangles make); deeper trees use a per-thread stack on the heap.
pub(super) const FIXED_STACK: usize = 64;

/// Exit distances are scaled by `1 + 2γ₃` (γₙ = nε/(1 − nε), ε = 2⁻²⁴) to bound the slab test's
/// rounding: through the reciprocal direction the exit planes use (`(p − o) · (1/d · R)` has
/// the four roundings of `((p − o) · 1/d) · R`, so the same bound holds) and `t_max`. Scaling
/// the reciprocal once per ray instead of each exit distance took a multiply off every box
/// test's longest chain: Sibenik's closest-hit rays 1.8 % faster (medians of 40 passes each,
/// alternating).
const ROBUST: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// Children per node.
const W: usize = 8;
/// Triangles per leaf group.
const G: usize = 8;

/// Up to eight children: their boxes as lanes (min x, y, z, max x, y, z) and their codes. An
/// absent child has an empty box (min +∞, max −∞), which no ray enters.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
struct Node {
    planes: [[f32; W]; 6],
    child: [u32; W],
}

/// Up to eight triangles as lanes: first corner, edge to corner 1, edge to corner 2, and each
/// lane's mesh triangle (`u32::MAX` for an unused lane, which has zero edges: determinant 0,
/// never hit). 320 bytes on a cache-line boundary: five whole lines, the ids in the line the
/// test has just read (with the ids in an array of their own, and 288-byte groups straddling
/// lines, closest-hit rays on Sibenik were 4 % slower).
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Group {
    v0: [[f32; G]; 3],
    e1: [[f32; G]; 3],
    e2: [[f32; G]; 3],
    ids: [u32; G],
}

/// The tree: nodes and leaf groups.
pub(super) struct WideBvh {
    /// The root's code (a leaf group when the whole mesh fits in one).
    root: u32,
    nodes: Vec<Node>,
    groups: Vec<Group>,
    /// Stack entries a traversal can need: `W − 1` per level below the root, plus one.
    stack_len: usize,
    /// Whether the CPU has AVX2 (x86-64): box and triangle tests then take eight lanes in one
    /// step.
    avx2: bool,
}

/// A ray prepared for a node's box tests and a leaf's triangle tests: origin, direction and
/// reciprocal direction splatted across lanes, and which plane (min or max) each axis enters
/// through. One implementation per instruction set; the traversal is written once over this.
trait BoxRay {
    fn new(origin: Vec3, dir: Vec3) -> Self;

    /// Entry distances of the node's children and the mask of those the ray enters within
    /// `[t_min, t_max]`, the exit (or `t_max`) widened by `ROBUST`: a triangle at `t < t_max`
    /// inside a box is never culled by the entry distance's rounding.
    fn enter(&self, node: &Node, t_min: f32, t_max: f32) -> ([f32; W], u32);

    /// The lanes of `group` that the ray hits for `t` in `(t_min, t_max)`, and each lane's
    /// `(t, u, v)`: the arithmetic of `super::intersect`, lane by lane.
    fn hit(&self, group: &Group, t_min: f32, t_max: f32) -> (u32, [[f32; G]; 3]);
}

/// Reciprocal direction with zero components made tiny ones of the same sign (large, finite
/// reciprocals: no 0·∞ in the slab test), and the entry and exit planes per axis (min is
/// plane `k`, max `k + 3`).
fn slab_setup(dir: Vec3) -> (Vec3, [usize; 3], [usize; 3]) {
    let safe = |d: f32| {
        if d.abs() < 1e-30 {
            1e-30f32.copysign(d)
        } else {
            d
        }
    };
    let inv = Vec3::new(1.0 / safe(dir.x), 1.0 / safe(dir.y), 1.0 / safe(dir.z));
    // Written out per axis: as array `map`s this was a function call per ray.
    let (nx, ny, nz) = (inv.x < 0.0, inv.y < 0.0, inv.z < 0.0);
    let near = [
        if nx { 3 } else { 0 },
        if ny { 4 } else { 1 },
        if nz { 5 } else { 2 },
    ];
    let far = [
        if nx { 0 } else { 3 },
        if ny { 1 } else { 4 },
        if nz { 2 } else { 5 },
    ];
    (inv, near, far)
}

/// Two four-lane halves (SSE2 on x86-64, NEON on ARM, scalar elsewhere).
struct Halves {
    o: Vec3,
    d: Vec3,
    origin: [Vec4; 3],
    inv_dir: [Vec4; 3],
    /// `inv_dir` × `ROBUST`, for the exit planes.
    inv_far: [Vec4; 3],
    near: [usize; 3],
    far: [usize; 3],
}

impl BoxRay for Halves {
    fn new(origin: Vec3, dir: Vec3) -> Self {
        let (inv, near, far) = slab_setup(dir);
        Halves {
            o: origin,
            d: dir,
            origin: [0, 1, 2].map(|k| Vec4::splat(origin[k])),
            inv_dir: [0, 1, 2].map(|k| Vec4::splat(inv[k])),
            inv_far: [0, 1, 2].map(|k| Vec4::splat(inv[k] * ROBUST)),
            near,
            far,
        }
    }

    #[inline(always)]
    fn enter(&self, node: &Node, t_min: f32, t_max: f32) -> ([f32; W], u32) {
        let mut out = [0.0; W];
        let mut mask = 0;
        for half in 0..2 {
            let slab = |k: usize, plane: usize, inv: &[Vec4; 3]| {
                let p = Vec4::from_slice(&node.planes[plane][4 * half..]);
                (p - self.origin[k]) * inv[k]
            };
            let (i, f) = (&self.inv_dir, &self.inv_far);
            let near = slab(0, self.near[0], i)
                .max(slab(1, self.near[1], i))
                .max(slab(2, self.near[2], i).max(Vec4::splat(t_min)));
            let far = slab(0, self.far[0], f)
                .min(slab(1, self.far[1], f))
                .min(slab(2, self.far[2], f).min(Vec4::splat(t_max * ROBUST)));
            near.write_to_slice(&mut out[4 * half..]);
            mask |= near.cmple(far).bitmask() << (4 * half);
        }
        (out, mask)
    }

    #[inline(always)]
    fn hit(&self, g: &Group, t_min: f32, t_max: f32) -> (u32, [[f32; G]; 3]) {
        let mut out = [[0.0; G]; 3];
        let mut mask = 0;
        for half in 0..G / 4 {
            let lanes = |rows: &[[f32; G]; 3]| rows.map(|r| Vec4::from_slice(&r[4 * half..]));
            let (m, t, u, v) = intersect4(
                [lanes(&g.v0), lanes(&g.e1), lanes(&g.e2)],
                self.o,
                self.d,
                t_min,
                t_max,
            );
            for (o, x) in out.iter_mut().zip([t, u, v]) {
                x.write_to_slice(&mut o[4 * half..]);
            }
            mask |= m << (4 * half);
        }
        (mask, out)
    }
}

/// Eight lanes at once with AVX (used when the CPU has AVX2).
#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{slab_setup, BoxRay, Group, Node, G, ROBUST, W};
    use glam::Vec3;
    use std::arch::x86_64::*;

    pub(super) struct Avx {
        origin: [__m256; 3],
        dir: [__m256; 3],
        inv_dir: [__m256; 3],
        /// `inv_dir` × `ROBUST`, for the exit planes.
        inv_far: [__m256; 3],
        near: [usize; 3],
        far: [usize; 3],
    }

    impl BoxRay for Avx {
        #[inline(always)]
        fn new(origin: Vec3, dir: Vec3) -> Self {
            let (inv, near, far) = slab_setup(dir);
            // SAFETY: `Avx` is only made inside `WideBvh`'s AVX2 entry points, which run
            // after the CPU was checked for AVX2.
            unsafe {
                Avx {
                    origin: [
                        _mm256_set1_ps(origin.x),
                        _mm256_set1_ps(origin.y),
                        _mm256_set1_ps(origin.z),
                    ],
                    dir: [
                        _mm256_set1_ps(dir.x),
                        _mm256_set1_ps(dir.y),
                        _mm256_set1_ps(dir.z),
                    ],
                    inv_dir: [
                        _mm256_set1_ps(inv.x),
                        _mm256_set1_ps(inv.y),
                        _mm256_set1_ps(inv.z),
                    ],
                    inv_far: [
                        _mm256_set1_ps(inv.x * ROBUST),
                        _mm256_set1_ps(inv.y * ROBUST),
                        _mm256_set1_ps(inv.z * ROBUST),
                    ],
                    near,
                    far,
                }
            }
        }

        #[inline(always)]
        fn enter(&self, node: &Node, t_min: f32, t_max: f32) -> ([f32; W], u32) {
            // SAFETY: as in `new`; the loads read whole `[f32; 8]` rows of the node.
            unsafe {
                let slab = |k: usize, plane: usize, inv: &[__m256; 3]| {
                    let p = _mm256_loadu_ps(node.planes[plane].as_ptr());
                    _mm256_mul_ps(_mm256_sub_ps(p, self.origin[k]), inv[k])
                };
                let (i, f) = (&self.inv_dir, &self.inv_far);
                let near = _mm256_max_ps(
                    _mm256_max_ps(slab(0, self.near[0], i), slab(1, self.near[1], i)),
                    _mm256_max_ps(slab(2, self.near[2], i), _mm256_set1_ps(t_min)),
                );
                let far = _mm256_min_ps(
                    _mm256_min_ps(slab(0, self.far[0], f), slab(1, self.far[1], f)),
                    _mm256_min_ps(slab(2, self.far[2], f), _mm256_set1_ps(t_max * ROBUST)),
                );
                let mut out = [0.0; W];
                _mm256_storeu_ps(out.as_mut_ptr(), near);
                let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32;
                (out, mask)
            }
        }

        #[inline(always)]
        fn hit(&self, g: &Group, t_min: f32, t_max: f32) -> (u32, [[f32; G]; 3]) {
            // SAFETY: as in `new`; the loads read whole `[f32; 8]` rows of the group.
            unsafe {
                let load = |row: &[f32; G]| _mm256_loadu_ps(row.as_ptr());
                let (add, sub, mul) = (_mm256_add_ps, _mm256_sub_ps, _mm256_mul_ps);
                let [dx, dy, dz] = self.dir;
                let [e1x, e1y, e1z] = [load(&g.e1[0]), load(&g.e1[1]), load(&g.e1[2])];
                let [e2x, e2y, e2z] = [load(&g.e2[0]), load(&g.e2[1]), load(&g.e2[2])];
                // The operations of `super::intersect`, in its order.
                let px = sub(mul(dy, e2z), mul(e2y, dz));
                let py = sub(mul(dz, e2x), mul(e2z, dx));
                let pz = sub(mul(dx, e2y), mul(e2x, dy));
                let det = add(add(mul(e1x, px), mul(e1y, py)), mul(e1z, pz));
                let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
                let sx = sub(self.origin[0], load(&g.v0[0]));
                let sy = sub(self.origin[1], load(&g.v0[1]));
                let sz = sub(self.origin[2], load(&g.v0[2]));
                let u = mul(add(add(mul(sx, px), mul(sy, py)), mul(sz, pz)), inv_det);
                let qx = sub(mul(sy, e1z), mul(e1y, sz));
                let qy = sub(mul(sz, e1x), mul(e1z, sx));
                let qz = sub(mul(sx, e1y), mul(e1x, sy));
                let v = mul(add(add(mul(dx, qx), mul(dy, qy)), mul(dz, qz)), inv_det);
                let t = mul(add(add(mul(e2x, qx), mul(e2y, qy)), mul(e2z, qz)), inv_det);
                let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
                let abs_det = _mm256_andnot_ps(_mm256_set1_ps(-0.0), det);
                let and = _mm256_and_ps;
                let ok = and(
                    and(
                        and(
                            _mm256_cmp_ps::<_CMP_NEQ_UQ>(det, zero),
                            _mm256_cmp_ps::<_CMP_LT_OQ>(abs_det, _mm256_set1_ps(f32::INFINITY)),
                        ),
                        and(
                            _mm256_cmp_ps::<_CMP_GE_OQ>(u, zero),
                            _mm256_cmp_ps::<_CMP_LE_OQ>(u, one),
                        ),
                    ),
                    and(
                        and(
                            _mm256_cmp_ps::<_CMP_GE_OQ>(v, zero),
                            _mm256_cmp_ps::<_CMP_LE_OQ>(add(u, v), one),
                        ),
                        and(
                            _mm256_cmp_ps::<_CMP_GT_OQ>(t, _mm256_set1_ps(t_min)),
                            _mm256_cmp_ps::<_CMP_LT_OQ>(t, _mm256_set1_ps(t_max)),
                        ),
                    ),
                );
                let mask = _mm256_movemask_ps(ok) as u32;
                let mut out = [[0.0; G]; 3];
                if mask != 0 {
                    _mm256_storeu_ps(out[0].as_mut_ptr(), t);
                    _mm256_storeu_ps(out[1].as_mut_ptr(), u);
                    _mm256_storeu_ps(out[2].as_mut_ptr(), v);
                }
                (mask, out)
            }
        }
    }
}

/// The lanes of four triangles (first corners, edges 1 and 2) that the ray hits for `t` in
/// `(t_min, t_max)`, and each lane's `(t, u, v)`; the arithmetic of `super::intersect`, four
/// lanes at once.
#[inline(always)]
fn intersect4(
    [v0, e1, e2]: [[Vec4; 3]; 3],
    origin: Vec3,
    dir: Vec3,
    t_min: f32,
    t_max: f32,
) -> (u32, Vec4, Vec4, Vec4) {
    let [dx, dy, dz] = [dir.x, dir.y, dir.z].map(Vec4::splat);
    let [e1x, e1y, e1z] = e1;
    let [e2x, e2y, e2z] = e2;
    // p = dir × e2
    let px = dy * e2z - e2y * dz;
    let py = dz * e2x - e2z * dx;
    let pz = dx * e2y - e2x * dy;
    let det = e1x * px + e1y * py + e1z * pz;
    let inv_det = Vec4::ONE / det;
    let sx = Vec4::splat(origin.x) - v0[0];
    let sy = Vec4::splat(origin.y) - v0[1];
    let sz = Vec4::splat(origin.z) - v0[2];
    let u = (sx * px + sy * py + sz * pz) * inv_det;
    // q = s × e1
    let qx = sy * e1z - e1y * sz;
    let qy = sz * e1x - e1z * sx;
    let qz = sx * e1y - e1x * sy;
    let v = (dx * qx + dy * qy + dz * qz) * inv_det;
    let t = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
    let ok = det.cmpne(Vec4::ZERO)
        & det.is_finite_mask()
        & u.cmpge(Vec4::ZERO)
        & u.cmple(Vec4::ONE)
        & v.cmpge(Vec4::ZERO)
        & (u + v).cmple(Vec4::ONE)
        & t.cmpgt(Vec4::splat(t_min))
        & t.cmplt(Vec4::splat(t_max));
    (ok.bitmask(), t, u, v)
}

#[derive(Clone, Copy, Default)]
struct Entry {
    code: u32,
    t: f32,
}

impl WideBvh {
    /// Collapses `bvh2` (built over `tris`, whose index `k` is mesh triangle `mesh_ids[k]`).
    pub(super) fn from_bvh2(bvh2: &Bvh2, tris: &[Triangle], mesh_ids: &[u32]) -> WideBvh {
        let mut tree = WideBvh {
            root: EMPTY,
            nodes: Vec::new(),
            groups: Vec::new(),
            stack_len: 1,
            avx2: has_avx2(),
        };
        if bvh2.nodes.is_empty() {
            return tree;
        }
        // Triangles under each BVH2 node (children come after parents in PLOC's layout, but
        // this does not rely on it).
        let counts = subtree_counts(bvh2);
        let leaf_of = |tree: &mut WideBvh, n: usize| {
            let mut prims = Vec::new();
            collect_prims(bvh2, n, &mut prims);
            tree.leaf_tree(&prims, tris, mesh_ids)
        };
        if counts[0] <= G || bvh2.nodes[0].is_leaf() {
            tree.root = leaf_of(&mut tree, 0);
            tree.stack_len = (W - 1) * tree.depth() + 1;
            return tree;
        }
        tree.root = 0;
        tree.nodes.push(empty_node());
        // (BVH2 node, wide node slot)
        let mut work = vec![(0usize, 0usize)];
        while let Some((n2, slot)) = work.pop() {
            // Open the largest inner child until W children.
            let first = bvh2.nodes[n2].first_index as usize;
            let mut kids = vec![first, first + 1];
            while kids.len() < W {
                let open = kids
                    .iter()
                    .enumerate()
                    .filter(|&(_, &k)| !bvh2.nodes[k].is_leaf() && counts[k] > G)
                    .max_by(|a, b| {
                        let area = |k: usize| bvh2.nodes[k].aabb().half_area();
                        area(*a.1).total_cmp(&area(*b.1))
                    })
                    .map(|(i, _)| i);
                let Some(i) = open else { break };
                let k = kids.swap_remove(i);
                let f = bvh2.nodes[k].first_index as usize;
                kids.extend([f, f + 1]);
            }
            let mut node = empty_node();
            for (lane, &k) in kids.iter().enumerate() {
                let aabb = bvh2.nodes[k].aabb();
                set_lane(&mut node, lane, aabb.min.into(), aabb.max.into());
                node.child[lane] = if bvh2.nodes[k].is_leaf() || counts[k] <= G {
                    leaf_of(&mut tree, k)
                } else {
                    let s = tree.nodes.len();
                    tree.nodes.push(empty_node());
                    work.push((k, s));
                    s as u32
                };
            }
            tree.nodes[slot] = node;
        }
        tree.stack_len = (W - 1) * tree.depth() + 1;
        tree
    }

    /// Inner levels on the longest path from the root (0 when the root is a leaf).
    fn depth(&self) -> usize {
        let mut deepest = 0;
        let mut stack = vec![(self.root, 0)];
        while let Some((code, depth)) = stack.pop() {
            if code & LEAF == 0 {
                deepest = deepest.max(depth + 1);
                let node = &self.nodes[code as usize];
                stack.extend(
                    node.child
                        .iter()
                        .filter(|&&c| c != EMPTY)
                        .map(|&c| (c, depth + 1)),
                );
            }
        }
        deepest
    }

    /// A leaf group for at most `G` triangles, else a node over up to `W` leaf trees of
    /// consecutive parts (only for BVH2 leaves larger than `G`, which the build avoids).
    fn leaf_tree(&mut self, prims: &[u32], tris: &[Triangle], mesh_ids: &[u32]) -> u32 {
        if prims.len() <= G {
            let mut g = Group {
                v0: [[0.0; G]; 3],
                e1: [[0.0; G]; 3],
                e2: [[0.0; G]; 3],
                ids: [u32::MAX; G],
            };
            for (lane, &p) in prims.iter().enumerate() {
                let t = &tris[p as usize];
                let (v0, v1, v2) = (Vec3::from(t.v0), Vec3::from(t.v1), Vec3::from(t.v2));
                let (e1, e2) = (v1 - v0, v2 - v0);
                for k in 0..3 {
                    g.v0[k][lane] = v0[k];
                    g.e1[k][lane] = e1[k];
                    g.e2[k][lane] = e2[k];
                }
                g.ids[lane] = mesh_ids[p as usize];
            }
            self.groups.push(g);
            return LEAF | (self.groups.len() - 1) as u32;
        }
        let slot = self.nodes.len();
        self.nodes.push(empty_node());
        let mut node = empty_node();
        for (lane, part) in prims.chunks(prims.len().div_ceil(W)).enumerate() {
            let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            for &p in part {
                let t = &tris[p as usize];
                for v in [t.v0, t.v1, t.v2] {
                    lo = lo.min(v.into());
                    hi = hi.max(v.into());
                }
            }
            set_lane(&mut node, lane, lo, hi);
            node.child[lane] = self.leaf_tree(part, tris, mesh_ids);
        }
        self.nodes[slot] = node;
        slot as u32
    }

    /// Stack entries a traversal reserves (tests check the heap fallback for deep trees).
    #[cfg(test)]
    pub(super) fn stack_len(&self) -> usize {
        self.stack_len
    }

    /// Box and triangle tests without AVX2 even where the CPU has it (tests compare both).
    #[cfg(test)]
    pub(super) fn without_avx2(mut self) -> Self {
        self.avx2 = false;
        self
    }

    /// Closest hit for `t` in `(t_min, t_max)`: `(mesh triangle, t, u, v)`.
    #[inline]
    pub(super) fn closest(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
    ) -> Option<(u32, f32, f32, f32)> {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only when the CPU reports AVX2.
            return unsafe { self.closest_avx2(origin, dir, t_min, t_max) };
        }
        self.closest_with::<Halves>(origin, dir, t_min, t_max)
    }

    /// Whether any triangle is hit for `t` in `(t_min, t_max)`.
    #[inline]
    pub(super) fn any(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> bool {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: as in `closest`.
            return unsafe { self.any_avx2(origin, dir, t_min, t_max) };
        }
        self.any_with::<Halves>(origin, dir, t_min, t_max)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    unsafe fn closest_avx2(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
    ) -> Option<(u32, f32, f32, f32)> {
        self.closest_with::<avx::Avx>(origin, dir, t_min, t_max)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    unsafe fn any_avx2(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> bool {
        self.any_with::<avx::Avx>(origin, dir, t_min, t_max)
    }

    #[inline(always)]
    fn closest_with<R: BoxRay>(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
    ) -> Option<(u32, f32, f32, f32)> {
        if self.root == EMPTY {
            return None;
        }
        let mut buf = [const { MaybeUninit::uninit() }; FIXED_STACK];
        let mut deep = Vec::new();
        let mut stack = self.stack(&mut buf, &mut deep);
        let ray = R::new(origin, dir);
        let mut t_max = t_max;
        let mut best = None;
        let mut code = self.root;
        'walk: loop {
            if code & LEAF == 0 {
                let node = &self.nodes[code as usize];
                let (near, mut mask) = ray.enter(node, t_min, t_max);
                if mask != 0 {
                    // One entered child: walk it. Two (a third of the nodes with any on
                    // Sibenik): walk the nearer, push the other, the lower lane first on a tie
                    // as the sort below orders them. More: sort.
                    let first = mask.trailing_zeros() as usize & (W - 1);
                    let rest = mask & (mask - 1);
                    if rest == 0 {
                        code = node.child[first];
                        continue;
                    }
                    if rest & (rest - 1) == 0 {
                        let second = rest.trailing_zeros() as usize & (W - 1);
                        let (near_lane, far_lane) = if near[second] < near[first] {
                            (second, first)
                        } else {
                            (first, second)
                        };
                        stack.push(Entry {
                            code: node.child[far_lane],
                            t: near[far_lane],
                        });
                        code = node.child[near_lane];
                        continue;
                    }
                    // Sort the entered children by entry distance (ties: the lower lane first);
                    // walk the nearest, push the rest farthest first. Each child goes straight
                    // to its rank, counted without branches (an insertion sort's data-dependent
                    // branches made closest-hit rays on Sibenik 1-4 % slower). Entered lanes'
                    // distances are never NaN (`near <= far` held), so the ranks are distinct.
                    let mut codes = [0u32; W];
                    let mut ts = [0f32; W];
                    let mut n = 0;
                    while mask != 0 {
                        let lane = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        codes[n] = node.child[lane];
                        ts[n] = near[lane];
                        n += 1;
                    }
                    let mut hits = [Entry::default(); W];
                    for i in 0..n {
                        let mut rank = 0;
                        for j in 0..n {
                            rank += ((ts[j] < ts[i]) | ((ts[j] == ts[i]) & (j < i))) as usize;
                        }
                        // (`& (W - 1)`: rank < n ≤ W; lets the compiler drop the bounds check.)
                        hits[rank & (W - 1)] = Entry {
                            code: codes[i],
                            t: ts[i],
                        };
                    }
                    for e in hits[1..n].iter().rev() {
                        stack.push(*e);
                    }
                    code = hits[0].code;
                    continue;
                }
            } else {
                let g = (code & !LEAF) as usize;
                let (mut mask, [t, u, v]) = ray.hit(&self.groups[g], t_min, t_max);
                if mask != 0 {
                    while mask != 0 {
                        let lane = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        if t[lane] < t_max {
                            t_max = t[lane];
                            best = Some((self.groups[g].ids[lane], t[lane], u[lane], v[lane]));
                        }
                    }
                }
            }
            loop {
                let Some(e) = stack.pop() else {
                    break 'walk;
                };
                if e.t <= t_max * ROBUST {
                    code = e.code;
                    break;
                }
            }
        }
        give_back(deep);
        best
    }

    // The set-up above is repeated rather than shared through a closure: a closure does not
    // inherit `closest_avx2`'s target features, so its AVX intrinsics became calls (measured
    // six times slower).
    #[inline(always)]
    fn any_with<R: BoxRay>(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> bool {
        if self.root == EMPTY {
            return false;
        }
        let mut buf = [const { MaybeUninit::uninit() }; FIXED_STACK];
        let mut deep = Vec::new();
        let mut stack = self.stack(&mut buf, &mut deep);
        let ray = R::new(origin, dir);
        let mut code = self.root;
        let hit = loop {
            if code & LEAF == 0 {
                let node = &self.nodes[code as usize];
                let (_, mut mask) = ray.enter(node, t_min, t_max);
                if mask != 0 {
                    code = node.child[mask.trailing_zeros() as usize];
                    mask &= mask - 1;
                    while mask != 0 {
                        stack.push(Entry {
                            code: node.child[mask.trailing_zeros() as usize],
                            t: 0.0,
                        });
                        mask &= mask - 1;
                    }
                    continue;
                }
            } else {
                let g = &self.groups[(code & !LEAF) as usize];
                if ray.hit(g, t_min, t_max).0 != 0 {
                    break true;
                }
            }
            let Some(e) = stack.pop() else {
                break false;
            };
            code = e.code;
        };
        give_back(deep);
        hit
    }

    /// The traversal stack: `buf` when the tree is shallow enough, else this thread's deep
    /// stack (taken into `deep`; `give_back` returns it), grown to the tree's need once.
    #[inline(always)]
    fn stack<'a>(
        &self,
        buf: &'a mut [MaybeUninit<Entry>; FIXED_STACK],
        deep: &'a mut Vec<MaybeUninit<Entry>>,
    ) -> Stack<'a> {
        if self.stack_len <= FIXED_STACK {
            return Stack { slots: buf, len: 0 };
        }
        *deep = DEEP_STACK.take();
        if deep.len() < self.stack_len {
            deep.resize(self.stack_len, MaybeUninit::uninit());
        }
        Stack {
            slots: deep,
            len: 0,
        }
    }
}

/// A traversal's stack over slots left uninitialised (zeroing the 64 fixed entries was about
/// 13 instructions per ray: 3 % of a Cornell shadow ray's): `push` writes the slot at `len`,
/// `pop` reads below it.
struct Stack<'a> {
    slots: &'a mut [MaybeUninit<Entry>],
    len: usize,
}

impl Stack<'_> {
    #[inline(always)]
    fn push(&mut self, e: Entry) {
        self.slots[self.len].write(e);
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<Entry> {
        self.len = self.len.checked_sub(1)?;
        // SAFETY: every slot below the old `len` was written by `push` in this walk (`len`
        // starts at 0 and only `push` raises it, after writing).
        Some(unsafe { self.slots[self.len].assume_init() })
    }
}

thread_local! {
    /// Per thread, the stack of traversals of trees deeper than `FIXED_STACK` allows.
    static DEEP_STACK: std::cell::Cell<Vec<MaybeUninit<Entry>>> =
        const { std::cell::Cell::new(Vec::new()) };
}

/// Returns a deep stack taken by `WideBvh::stack` (an empty one is left alone).
#[inline(always)]
fn give_back(deep: Vec<MaybeUninit<Entry>>) {
    if !deep.is_empty() {
        DEEP_STACK.set(deep);
    }
}

fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    false
}

fn empty_node() -> Node {
    Node {
        planes: [
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
        ],
        child: [EMPTY; W],
    }
}

fn set_lane(node: &mut Node, lane: usize, lo: Vec3, hi: Vec3) {
    for k in 0..3 {
        node.planes[k][lane] = lo[k];
        node.planes[k + 3][lane] = hi[k];
    }
}

/// Number of primitives under each BVH2 node.
fn subtree_counts(bvh2: &Bvh2) -> Vec<usize> {
    let mut counts = vec![0usize; bvh2.nodes.len()];
    // Post-order without recursion: visit, then fold children once both are done.
    let mut stack = vec![(0usize, false)];
    while let Some((n, done)) = stack.pop() {
        let node = &bvh2.nodes[n];
        if node.is_leaf() {
            counts[n] = node.prim_count as usize;
        } else if done {
            let f = node.first_index as usize;
            counts[n] = counts[f] + counts[f + 1];
        } else {
            let f = node.first_index as usize;
            stack.extend([(n, true), (f, false), (f + 1, false)]);
        }
    }
    counts
}

/// The primitives (indices into the triangles the BVH2 was built over) under node `n`.
fn collect_prims(bvh2: &Bvh2, n: usize, out: &mut Vec<u32>) {
    let mut stack = vec![n];
    while let Some(n) = stack.pop() {
        let node = &bvh2.nodes[n];
        if node.is_leaf() {
            let f = node.first_index as usize;
            out.extend_from_slice(&bvh2.primitive_indices[f..f + node.prim_count as usize]);
        } else {
            let f = node.first_index as usize;
            stack.extend([f + 1, f]);
        }
    }
}
