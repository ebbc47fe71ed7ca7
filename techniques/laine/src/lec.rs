//! The largest-empty-circle candidates of a [`SamplingDomain`](crate::domain::SamplingDomain),
//! kept between queries and updated where an insertion changed the triangulation.
//!
//! Reads: the domain's triangulation (faces, edges, vertices by spade index). Writes: one
//! candidate (centre, radius) per slot — per inner face (its circumcentre), per undirected edge
//! two (its Voronoi edge crossing the disc's rim), per vertex one (the rim point opposite it),
//! and on the sphere per outer directed edge one (the wrap-around triangle at the pole) — with
//! a max tree over the faces and, for the other kinds (whose few candidates lie near the hull),
//! a short list of the slots that hold one, so the largest empty circle is a lookup, not a
//! pass over the triangulation.
//!
//! The answer is the one of the plain scan (faces, then edges, then vertices, each in index
//! order, the first strictly largest radius winning): each kind breaks ties towards the lower
//! index and kinds are compared in scan order. Every slot is computed by the same function the
//! scan would apply to the same triangulation, so results are bit-identical
//! (`lec_cache_equals_the_scan` in the tests checks it over random insert/remove sequences).
//!
//! Incremental update: spade inserts a vertex v by splitting a face (or edge, or fanning to
//! the hull) and flipping edges opposite v; every face it creates or changes is incident to v
//! afterwards, and no face is deleted. So after inserting v the changed slots are: the faces
//! around v; the edges of those faces (their Voronoi edges join those faces' circumcentres);
//! v and its neighbours (their cells changed); on the sphere the wrap slots of those faces'
//! edges and of their reverses. A removal or a rebuild invalidates the cache; the next query
//! recomputes every slot (one pass, the cost of one scan).

use glam::DVec3;

/// A candidate: centre, radius and the spade index of a site on its circle.
pub(crate) type Candidate = Option<(DVec3, f64, u32)>;

/// A max tree over slots `0..len`: the slot with the largest radius, ties to the lower index.
/// Slots without a candidate hold −∞.
#[derive(Clone, Debug, Default)]
pub(crate) struct MaxTree {
    radius: Vec<f64>,
    centre: Vec<DVec3>,
    site: Vec<u32>,
    /// Heap-ordered internal nodes (1 is the root; leaves at `cap + i`), each the best slot
    /// below it.
    node: Vec<u32>,
    cap: usize,
}

const NONE: u32 = u32::MAX;

impl MaxTree {
    fn better(&self, a: u32, b: u32) -> u32 {
        if a == NONE {
            return b;
        }
        if b == NONE {
            return a;
        }
        let (ra, rb) = (self.radius[a as usize], self.radius[b as usize]);
        if rb > ra || (rb == ra && b < a) {
            b
        } else {
            a
        }
    }

    /// Empties the tree and sizes it for `len` slots, all without a candidate.
    pub(crate) fn reset(&mut self, len: usize) {
        self.radius.clear();
        self.radius.resize(len, f64::NEG_INFINITY);
        self.centre.clear();
        self.centre.resize(len, DVec3::ZERO);
        self.site.clear();
        self.site.resize(len, 0);
        // Room for an eighth more slots: the insertions after a recompute (a frame's new
        // sampling points) then grow the slots without rebuilding the tree. The winner does
        // not depend on the tree's shape (largest radius, then lowest slot: a total order).
        self.cap = (len + len / 8).next_power_of_two().max(1);
        self.node.clear();
        self.node.resize(2 * self.cap, NONE);
        for i in 0..len {
            self.node[self.cap + i] = i as u32;
        }
    }

    /// Recomputes every internal node (after [`reset`](Self::reset) and [`set_leaf`]s).
    pub(crate) fn build(&mut self) {
        for n in (1..self.cap).rev() {
            self.node[n] = self.better(self.node[2 * n], self.node[2 * n + 1]);
        }
    }

    /// Sets slot `i` without updating the internal nodes (then [`build`](Self::build)).
    pub(crate) fn set_leaf(&mut self, i: usize, candidate: Candidate) {
        let (c, r, site) = candidate.unwrap_or((DVec3::ZERO, f64::NEG_INFINITY, 0));
        self.centre[i] = c;
        self.radius[i] = r;
        self.site[i] = site;
    }

    /// Sets slot `i` (growing the tree if needed) and updates its path to the root.
    pub(crate) fn set(&mut self, i: usize, candidate: Candidate) {
        if i >= self.radius.len() {
            let len = i + 1;
            if len > self.cap {
                let radius = std::mem::take(&mut self.radius);
                let centre = std::mem::take(&mut self.centre);
                let site = std::mem::take(&mut self.site);
                self.reset(len);
                self.radius[..radius.len()].copy_from_slice(&radius);
                self.centre[..centre.len()].copy_from_slice(&centre);
                self.site[..site.len()].copy_from_slice(&site);
                self.set_leaf(i, candidate);
                self.build();
                return;
            }
            let old = self.radius.len();
            self.radius.resize(len, f64::NEG_INFINITY);
            self.centre.resize(len, DVec3::ZERO);
            self.site.resize(len, 0);
            for k in old..len {
                self.node[self.cap + k] = k as u32;
            }
        }
        self.set_leaf(i, candidate);
        let mut n = (self.cap + i) / 2;
        while n >= 1 {
            self.node[n] = self.better(self.node[2 * n], self.node[2 * n + 1]);
            n /= 2;
        }
    }

    /// The number of slots.
    pub(crate) fn len(&self) -> usize {
        self.radius.len()
    }

    /// Slot `i`'s centre (zero where it holds no candidate).
    pub(crate) fn centre(&self, i: usize) -> DVec3 {
        self.centre[i]
    }

    /// The best slot's candidate, `None` if no slot has one.
    pub(crate) fn best(&self) -> Candidate {
        let b = *self.node.get(1)? as usize;
        if b == NONE as usize || self.radius[b] == f64::NEG_INFINITY {
            return None;
        }
        Some((self.centre[b], self.radius[b], self.site[b]))
    }
}

/// Slots of which few hold a candidate (the disc's rim crossings and rim points, the
/// sphere's wrap-around triangles: only near the hull): the candidates in a short list, found
/// by slot. Same answers as a [`MaxTree`] (the largest radius, ties to the lower slot) without
/// a tree over every slot to clear and rebuild each time the candidates are recomputed.
#[derive(Clone, Debug, Default)]
pub(crate) struct SparseMax {
    /// Per slot, its entry in `items` (`NONE`: no candidate).
    at: Vec<u32>,
    /// (slot, centre, radius, site).
    items: Vec<(u32, DVec3, f64, u32)>,
}

impl SparseMax {
    /// Empties the list and sizes it for `len` slots, all without a candidate.
    pub(crate) fn reset(&mut self, len: usize) {
        self.at.clear();
        self.at.resize(len, NONE);
        self.items.clear();
    }

    /// Sets slot `i` (growing the slots if needed).
    pub(crate) fn set(&mut self, i: usize, candidate: Candidate) {
        if i >= self.at.len() {
            self.at.resize(i + 1, NONE);
        }
        let k = self.at[i];
        match (k, candidate) {
            (NONE, None) => {}
            (NONE, Some((c, r, site))) => {
                self.at[i] = self.items.len() as u32;
                self.items.push((i as u32, c, r, site));
            }
            (k, Some((c, r, site))) => self.items[k as usize] = (i as u32, c, r, site),
            (k, None) => {
                self.items.swap_remove(k as usize);
                if let Some(moved) = self.items.get(k as usize) {
                    self.at[moved.0 as usize] = k;
                }
                self.at[i] = NONE;
            }
        }
    }

    /// The number of slots.
    pub(crate) fn len(&self) -> usize {
        self.at.len()
    }

    /// Slot `i`'s centre (zero where it holds no candidate).
    pub(crate) fn centre(&self, i: usize) -> DVec3 {
        match self.at.get(i) {
            Some(&k) if k != NONE => self.items[k as usize].1,
            _ => DVec3::ZERO,
        }
    }

    /// The candidate of the largest radius (ties to the lower slot), `None` if none.
    pub(crate) fn best(&self) -> Candidate {
        let mut best: Option<&(u32, DVec3, f64, u32)> = None;
        for item in &self.items {
            if best.is_none_or(|b| item.2 > b.2 || (item.2 == b.2 && item.0 < b.0)) {
                best = Some(item);
            }
        }
        best.map(|&(_, c, r, site)| (c, r, site))
    }
}

/// The cached candidates; `valid` is false until the next query recomputes them.
#[derive(Clone, Debug, Default)]
pub(crate) struct LecCache {
    pub(crate) valid: bool,
    pub(crate) faces: MaxTree,
    pub(crate) edges: SparseMax,
    pub(crate) vertices: SparseMax,
    pub(crate) wraps: SparseMax,
    /// Disc: each face's circumcentre (`None`: degenerate or the outer face), which the edge
    /// slots read.
    pub(crate) centres: Vec<Option<glam::DVec2>>,
}

impl LecCache {
    /// The largest empty circle over every kind, in the scan's order (faces, wrap-around
    /// triangles, edges, vertices; a later kind wins only with a strictly larger radius).
    pub(crate) fn best(&self) -> Candidate {
        let mut best: Candidate = None;
        let kinds = [
            self.faces.best(),
            self.wraps.best(),
            self.edges.best(),
            self.vertices.best(),
        ];
        for c in kinds.into_iter().flatten() {
            if best.is_none_or(|b| c.1 > b.1) {
                best = Some(c);
            }
        }
        best
    }
}
