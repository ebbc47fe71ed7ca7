//! A bounding-volume hierarchy over the blockers' boxes, so that a receiver's occlusion pyramid
//! is tested only against the blockers that may reach into it (what makes §4.3.1's visibility
//! determination affordable on scenes of tens of thousands of patches; the thesis' rooms had a
//! few dozen).
//!
//! Reads: the blockers' shapes (their axis-aligned boxes).
//! Writes: for a query (a test "is this box certainly outside?"), the blockers whose boxes it
//! does not rule out (each blocker's own box, not only its leaf's), ascending: exactly those
//! testing every box would keep (tested). A box outside one of a pyramid's bounding planes is
//! outside the pyramid, so the exact test would have rejected every blocker left out: the
//! database is the same with the index as without (tested). A plane a box lies wholly inside
//! is not tested again below it.
//!
//! [`clusters`] groups receivers that are near one another, so that they share one search
//! (see `database`).
//!
//! Built once (median splits on the longest axis, up to [`LEAF_SIZE`] blockers a leaf); when
//! an object moves, its blockers' leaves are refitted and then their ancestors, in place
//! (nothing is allocated).

use glam::Vec3;

use crate::visibility::{Blocker, Shape};

/// Blockers per leaf at most.
pub const LEAF_SIZE: usize = 4;

#[derive(Clone, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// Inner: the two children; leaf: `first..first + count` of `order`.
    left: u32,
    right: u32,
    first: u32,
    count: u32,
    parent: u32,
}

/// See the module docs.
#[derive(Clone, Debug, Default)]
pub struct BlockerIndex {
    nodes: Vec<Node>,
    /// Blocker indices, leaves' ranges into it.
    order: Vec<u32>,
    /// Each blocker's leaf.
    leaf_of: Vec<u32>,
    /// Each blocker's box (a leaf's blockers are tested one by one).
    boxes: Vec<(Vec3, Vec3)>,
}

/// The axis-aligned box of a shape.
pub fn bounds(shape: &Shape) -> (Vec3, Vec3) {
    let of = |points: &mut dyn Iterator<Item = Vec3>| {
        points.fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        )
    };
    match shape {
        Shape::Polygon(v) => of(&mut v.iter().copied()),
        Shape::Chart { hull, .. } => of(&mut hull.iter().copied()),
        Shape::Sphere { center, radius } => (*center - *radius, *center + *radius),
    }
}

const NONE: u32 = u32::MAX;

/// Groups of at most `size` of the points `centres` (indices), near one another: the points
/// split at the median of their longest axis until a part holds `size` or fewer.
pub fn clusters(centres: &[Vec3], size: usize) -> Vec<Vec<u32>> {
    fn split(centres: &[Vec3], part: &mut [u32], size: usize, out: &mut Vec<Vec<u32>>) {
        if part.len() <= size.max(1) {
            out.push(part.to_vec());
            return;
        }
        let (lo, hi) = part.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &i| (lo.min(centres[i as usize]), hi.max(centres[i as usize])),
        );
        let axis = (hi - lo).max_position();
        let mid = part.len() / 2;
        part.select_nth_unstable_by(mid, |a, b| {
            centres[*a as usize][axis].total_cmp(&centres[*b as usize][axis])
        });
        let (left, right) = part.split_at_mut(mid);
        split(centres, left, size, out);
        split(centres, right, size, out);
    }
    let mut all: Vec<u32> = (0..centres.len() as u32).collect();
    let mut out = Vec::new();
    if !all.is_empty() {
        split(centres, &mut all, size, &mut out);
    }
    out
}

impl BlockerIndex {
    /// The index of `blockers`.
    pub fn new(blockers: &[Blocker]) -> BlockerIndex {
        let boxes: Vec<(Vec3, Vec3)> = blockers.iter().map(|b| bounds(&b.shape)).collect();
        let mut index = BlockerIndex {
            nodes: Vec::new(),
            order: (0..blockers.len() as u32).collect(),
            leaf_of: vec![NONE; blockers.len()],
            boxes: Vec::new(),
        };
        if !blockers.is_empty() {
            index.build(&boxes, 0, blockers.len(), NONE);
        }
        index.boxes = boxes;
        index
    }

    fn build(&mut self, boxes: &[(Vec3, Vec3)], first: usize, end: usize, parent: u32) -> u32 {
        let (lo, hi) = self.order[first..end].iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &b| (lo.min(boxes[b as usize].0), hi.max(boxes[b as usize].1)),
        );
        let me = self.nodes.len() as u32;
        self.nodes.push(Node {
            lo,
            hi,
            left: NONE,
            right: NONE,
            first: first as u32,
            count: (end - first) as u32,
            parent,
        });
        if end - first <= LEAF_SIZE {
            for &b in &self.order[first..end] {
                self.leaf_of[b as usize] = me;
            }
            return me;
        }
        let axis = (hi - lo).max_position();
        let mid = (first + end) / 2;
        let centre = |b: u32| (boxes[b as usize].0 + boxes[b as usize].1)[axis];
        self.order[first..end]
            .select_nth_unstable_by(mid - first, |a, b| centre(*a).total_cmp(&centre(*b)));
        let left = self.build(boxes, first, mid, me);
        let right = self.build(boxes, mid, end, me);
        let node = &mut self.nodes[me as usize];
        node.left = left;
        node.right = right;
        node.count = 0;
        me
    }

    /// Appends to `out` (cleared first) the blockers whose boxes `cull` does not rule out,
    /// ascending. `cull(lo, hi, mask)` is asked about a box with the tests still needed
    /// (`mask`, all ones at the root) and says `None` when the box is certainly outside, else
    /// the tests its contents still need: a test a box passes wholly (a box inside one of a
    /// pyramid's half-spaces) is passed by every box inside it, so it is dropped below.
    pub fn query(&self, cull: impl Fn(Vec3, Vec3, u32) -> Option<u32>, out: &mut Vec<u32>) {
        out.clear();
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = [(0u32, u32::MAX); 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (n, mask) = stack[top];
            let node = &self.nodes[n as usize];
            let Some(mask) = cull(node.lo, node.hi, mask) else {
                continue;
            };
            if node.left == NONE {
                let (f, c) = (node.first as usize, node.count as usize);
                out.extend(self.order[f..f + c].iter().filter(|&&b| {
                    let (lo, hi) = self.boxes[b as usize];
                    cull(lo, hi, mask).is_some()
                }));
            } else {
                stack[top] = (node.left, mask);
                stack[top + 1] = (node.right, mask);
                top += 2;
            }
        }
        out.sort_unstable();
    }

    /// Blocker `b`'s box.
    pub fn bounds_of(&self, b: u32) -> (Vec3, Vec3) {
        self.boxes[b as usize]
    }

    /// Refits after blocker `b` of `blockers` moved: its leaf's box is recomputed from its
    /// blockers and every ancestor's from its children.
    pub fn moved(&mut self, b: u32, blockers: &[Blocker]) {
        self.boxes[b as usize] = bounds(&blockers[b as usize].shape);
        let mut n = self.leaf_of[b as usize];
        let mut first = true;
        while n != NONE {
            let node = &self.nodes[n as usize];
            let (lo, hi) = if first {
                let (f, c) = (node.first as usize, node.count as usize);
                self.order[f..f + c].iter().fold(
                    (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                    |(lo, hi), &k| {
                        let (a, b) = self.boxes[k as usize];
                        (lo.min(a), hi.max(b))
                    },
                )
            } else {
                let (l, r) = (
                    &self.nodes[node.left as usize],
                    &self.nodes[node.right as usize],
                );
                (l.lo.min(r.lo), l.hi.max(r.hi))
            };
            let node = &mut self.nodes[n as usize];
            node.lo = lo;
            node.hi = hi;
            n = node.parent;
            first = false;
        }
    }
}
