//! A four-wide BVH for single-ray CPU traversal: each node holds its four children's boxes as
//! lanes (x/y/z minima and maxima, one `Vec4` each), and each leaf is a group of up to four
//! triangles stored the same way (first corner and edges, one `Vec4` per coordinate), so one
//! SIMD step tests four boxes or four triangles. Built by collapsing `obvhs`'s binary PLOC tree:
//! every subtree of at most four triangles becomes one leaf group, and a node takes in its
//! largest children's children until it has four.
//!
//! The triangle test is Möller–Trumbore with the scalar test's operations in the scalar test's
//! order (`super::intersect`), so each lane gives bit for bit the scalar answer; box tests widen
//! the exit distance by a few ulps (Ize 2013) so rounding never culls a triangle the ray hits.

use glam::{Vec3, Vec4};
use obvhs::bvh2::Bvh2;
use obvhs::triangle::Triangle;

/// A child code: an inner node's index, `LEAF | group`, or `EMPTY`.
const LEAF: u32 = 1 << 31;
const EMPTY: u32 = u32::MAX;

/// Stack entries a traversal keeps on the call stack (enough for a tree 31 levels deep);
/// deeper trees get a heap stack per ray.
pub(super) const FIXED_STACK: usize = 94;

/// Exit distances are scaled by `1 + 2γ₃` (γₙ = nε/(1 − nε), ε = 2⁻²⁴) to bound the slab test's
/// rounding.
const ROBUST: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// Four children: their boxes as lanes (min x, y, z, max x, y, z) and their codes. An absent
/// child has an empty box (min +∞, max −∞), which no ray enters.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Node {
    planes: [Vec4; 6],
    child: [u32; 4],
}

/// Up to four triangles as lanes: first corner, edge to corner 1, edge to corner 2. An unused
/// lane has zero edges (determinant 0: never hit).
#[derive(Clone, Copy)]
#[repr(C, align(16))]
struct Group {
    v0: [Vec4; 3],
    e1: [Vec4; 3],
    e2: [Vec4; 3],
}

/// The tree: nodes, leaf groups and each group lane's mesh triangle.
pub(super) struct WideBvh {
    /// The root's code (a leaf group when the whole mesh fits in one).
    root: u32,
    nodes: Vec<Node>,
    groups: Vec<Group>,
    /// Mesh triangle of each group lane (`u32::MAX` for unused lanes).
    ids: Vec<[u32; 4]>,
    /// Stack entries a traversal can need: three per level below the root, plus one.
    stack_len: usize,
}

/// A ray prepared for box tests: origin and reciprocal direction splatted across lanes, and
/// which plane (min or max) each axis enters through.
struct BoxRay {
    origin: [Vec4; 3],
    inv_dir: [Vec4; 3],
    near: [usize; 3],
    far: [usize; 3],
}

impl BoxRay {
    fn new(origin: Vec3, dir: Vec3) -> BoxRay {
        // A zero component becomes a tiny one of the same sign, so its reciprocal is large and
        // finite (no 0·∞ in the slab test) and the ray enters through the plane that sign says.
        let safe = |d: f32| {
            if d.abs() < 1e-30 {
                1e-30f32.copysign(d)
            } else {
                d
            }
        };
        let inv = Vec3::new(1.0 / safe(dir.x), 1.0 / safe(dir.y), 1.0 / safe(dir.z));
        let planes = |k: usize, neg: bool| if neg { (k + 3, k) } else { (k, k + 3) };
        let (nx, fx) = planes(0, inv.x < 0.0);
        let (ny, fy) = planes(1, inv.y < 0.0);
        let (nz, fz) = planes(2, inv.z < 0.0);
        BoxRay {
            origin: [
                Vec4::splat(origin.x),
                Vec4::splat(origin.y),
                Vec4::splat(origin.z),
            ],
            inv_dir: [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)],
            near: [nx, ny, nz],
            far: [fx, fy, fz],
        }
    }

    /// Entry distances of the four children and the mask of those the ray enters within
    /// `[t_min, t_max]`, the exit (or `t_max`) widened by `ROBUST`: a triangle at `t < t_max`
    /// inside a box is never culled by the entry distance's rounding.
    #[inline(always)]
    fn enter(&self, node: &Node, t_min: Vec4, t_max: Vec4) -> (Vec4, u32) {
        let p = &node.planes;
        let slab = |k: usize, plane: usize| (p[plane] - self.origin[k]) * self.inv_dir[k];
        let near = slab(0, self.near[0])
            .max(slab(1, self.near[1]))
            .max(slab(2, self.near[2]).max(t_min));
        let far = slab(0, self.far[0])
            .min(slab(1, self.far[1]))
            .min(slab(2, self.far[2]).min(t_max))
            * ROBUST;
        (near, near.cmple(far).bitmask())
    }
}

/// The lanes of `group` that the ray hits for `t` in `(t_min, t_max)`, and each lane's
/// `(t, u, v)`; the arithmetic of `super::intersect`, four lanes at once.
#[inline(always)]
fn intersect4(
    g: &Group,
    origin: Vec3,
    dir: Vec3,
    t_min: f32,
    t_max: f32,
) -> (u32, Vec4, Vec4, Vec4) {
    let [dx, dy, dz] = [dir.x, dir.y, dir.z].map(Vec4::splat);
    let [e1x, e1y, e1z] = g.e1;
    let [e2x, e2y, e2z] = g.e2;
    // p = dir × e2
    let px = dy * e2z - e2y * dz;
    let py = dz * e2x - e2z * dx;
    let pz = dx * e2y - e2x * dy;
    let det = e1x * px + e1y * py + e1z * pz;
    let inv_det = Vec4::ONE / det;
    let sx = Vec4::splat(origin.x) - g.v0[0];
    let sy = Vec4::splat(origin.y) - g.v0[1];
    let sz = Vec4::splat(origin.z) - g.v0[2];
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
            ids: Vec::new(),
            stack_len: 1,
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
        if counts[0] <= 4 || bvh2.nodes[0].is_leaf() {
            tree.root = leaf_of(&mut tree, 0);
            tree.stack_len = 3 * tree.depth() + 1;
            return tree;
        }
        tree.root = 0;
        tree.nodes.push(empty_node());
        // (BVH2 node, wide node slot)
        let mut work = vec![(0usize, 0usize)];
        while let Some((n2, slot)) = work.pop() {
            // Open the largest inner child until four children.
            let first = bvh2.nodes[n2].first_index as usize;
            let mut kids = vec![first, first + 1];
            while kids.len() < 4 {
                let open = kids
                    .iter()
                    .enumerate()
                    .filter(|&(_, &k)| !bvh2.nodes[k].is_leaf() && counts[k] > 4)
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
                node.child[lane] = if bvh2.nodes[k].is_leaf() || counts[k] <= 4 {
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
        tree.stack_len = 3 * tree.depth() + 1;
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

    /// A leaf group for at most four triangles, else a node over up to four leaf trees of
    /// consecutive parts (only for BVH2 leaves larger than four, which the build avoids).
    fn leaf_tree(&mut self, prims: &[u32], tris: &[Triangle], mesh_ids: &[u32]) -> u32 {
        if prims.len() <= 4 {
            let mut g = Group {
                v0: [Vec4::ZERO; 3],
                e1: [Vec4::ZERO; 3],
                e2: [Vec4::ZERO; 3],
            };
            let mut ids = [u32::MAX; 4];
            for (lane, &p) in prims.iter().enumerate() {
                let t = &tris[p as usize];
                let (v0, v1, v2) = (Vec3::from(t.v0), Vec3::from(t.v1), Vec3::from(t.v2));
                let (e1, e2) = (v1 - v0, v2 - v0);
                for k in 0..3 {
                    g.v0[k][lane] = v0[k];
                    g.e1[k][lane] = e1[k];
                    g.e2[k][lane] = e2[k];
                }
                ids[lane] = mesh_ids[p as usize];
            }
            self.groups.push(g);
            self.ids.push(ids);
            return LEAF | (self.groups.len() - 1) as u32;
        }
        let slot = self.nodes.len();
        self.nodes.push(empty_node());
        let mut node = empty_node();
        for (lane, part) in prims.chunks(prims.len().div_ceil(4)).enumerate() {
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

    /// Closest hit for `t` in `(t_min, t_max)`: `(mesh triangle, t, u, v)`.
    #[inline]
    pub(super) fn closest(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
    ) -> Option<(u32, f32, f32, f32)> {
        if self.root == EMPTY {
            return None;
        }
        let mut buf = [Entry::default(); FIXED_STACK];
        let mut heap = Vec::new();
        let stack: &mut [Entry] = if self.stack_len <= buf.len() {
            &mut buf
        } else {
            heap.resize(self.stack_len, Entry::default());
            &mut heap
        };
        let ray = BoxRay::new(origin, dir);
        let t_min4 = Vec4::splat(t_min);
        let mut t_max = t_max;
        let mut best = None;
        let mut sp = 0;
        let mut code = self.root;
        'walk: loop {
            if code & LEAF == 0 {
                let node = &self.nodes[code as usize];
                let (near, mut mask) = ray.enter(node, t_min4, Vec4::splat(t_max));
                if mask != 0 {
                    let near = near.to_array();
                    if mask & (mask - 1) == 0 {
                        code = node.child[mask.trailing_zeros() as usize];
                        continue;
                    }
                    // Sort the entered children by entry distance; walk the nearest, push the
                    // rest farthest first.
                    let mut hits = [Entry::default(); 4];
                    let mut n = 0;
                    while mask != 0 {
                        let lane = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        let e = Entry {
                            code: node.child[lane],
                            t: near[lane],
                        };
                        let mut i = n;
                        while i > 0 && hits[i - 1].t > e.t {
                            hits[i] = hits[i - 1];
                            i -= 1;
                        }
                        hits[i] = e;
                        n += 1;
                    }
                    for e in hits[1..n].iter().rev() {
                        stack[sp] = *e;
                        sp += 1;
                    }
                    code = hits[0].code;
                    continue;
                }
            } else {
                let g = (code & !LEAF) as usize;
                let (mut mask, t, u, v) = intersect4(&self.groups[g], origin, dir, t_min, t_max);
                if mask != 0 {
                    let (t, u, v) = (t.to_array(), u.to_array(), v.to_array());
                    while mask != 0 {
                        let lane = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        if t[lane] < t_max {
                            t_max = t[lane];
                            best = Some((self.ids[g][lane], t[lane], u[lane], v[lane]));
                        }
                    }
                }
            }
            loop {
                if sp == 0 {
                    break 'walk;
                }
                sp -= 1;
                if stack[sp].t <= t_max * ROBUST {
                    code = stack[sp].code;
                    break;
                }
            }
        }
        best
    }

    /// Whether any triangle is hit for `t` in `(t_min, t_max)`.
    #[inline]
    pub(super) fn any(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> bool {
        if self.root == EMPTY {
            return false;
        }
        let mut buf = [0u32; FIXED_STACK];
        let mut heap = Vec::new();
        let stack: &mut [u32] = if self.stack_len <= buf.len() {
            &mut buf
        } else {
            heap.resize(self.stack_len, 0);
            &mut heap
        };
        let ray = BoxRay::new(origin, dir);
        let (t_min4, t_max4) = (Vec4::splat(t_min), Vec4::splat(t_max));
        let mut sp = 0;
        let mut code = self.root;
        loop {
            if code & LEAF == 0 {
                let node = &self.nodes[code as usize];
                let (_, mut mask) = ray.enter(node, t_min4, t_max4);
                if mask != 0 {
                    code = node.child[mask.trailing_zeros() as usize];
                    mask &= mask - 1;
                    while mask != 0 {
                        stack[sp] = node.child[mask.trailing_zeros() as usize];
                        sp += 1;
                        mask &= mask - 1;
                    }
                    continue;
                }
            } else {
                let g = &self.groups[(code & !LEAF) as usize];
                if intersect4(g, origin, dir, t_min, t_max).0 != 0 {
                    return true;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            code = stack[sp];
        }
    }
}

fn empty_node() -> Node {
    Node {
        planes: [
            Vec4::INFINITY,
            Vec4::INFINITY,
            Vec4::INFINITY,
            Vec4::NEG_INFINITY,
            Vec4::NEG_INFINITY,
            Vec4::NEG_INFINITY,
        ],
        child: [EMPTY; 4],
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
