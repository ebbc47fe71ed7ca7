//! The largest-empty-circle candidates of a [`SamplingDomain`](crate::domain::SamplingDomain),
//! kept between queries and updated where an insertion changed the triangulation.
//!
//! Reads: the domain's triangulation (faces, edges, vertices by spade index). Writes: one
//! candidate (centre, radius) per slot — per inner face (its circumcentre), per undirected edge
//! two (its Voronoi edge crossing the disc's rim), per vertex one (the rim point opposite it),
//! and on the sphere per outer directed edge one (the wrap-around triangle at the pole) — with
//! blocks of slots over the faces and, for the other kinds (whose few candidates lie near the hull),
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

/// Slots `0..len` in blocks of [`BLOCK`], each block knowing its best slot: the slot with the
/// largest radius, ties to the lower index (slots without a candidate hold −∞). A change
/// rescans its block; the answer scans the blocks' best — both short, branch-light loops over
/// contiguous radii, and a full recomputation is one pass.
#[derive(Clone, Debug, Default)]
pub(crate) struct BlockMax {
    radius: Vec<f64>,
    centre: Vec<DVec3>,
    site: Vec<u32>,
    /// Per block, its best slot (`NONE`: no candidate in it).
    block: Vec<u32>,
}

const NONE: u32 = u32::MAX;

/// Slots per block of a [`BlockMax`].
const BLOCK: usize = 64;

impl BlockMax {
    /// Empties the slots and sizes them for `len`, all without a candidate.
    pub(crate) fn reset(&mut self, len: usize) {
        self.radius.clear();
        self.radius.resize(len, f64::NEG_INFINITY);
        self.centre.clear();
        self.centre.resize(len, DVec3::ZERO);
        self.site.clear();
        self.site.resize(len, 0);
        self.block.clear();
        self.block.resize(len.div_ceil(BLOCK), NONE);
    }

    /// The best slot of block `b`.
    fn scan_block(&self, b: usize) -> u32 {
        let end = ((b + 1) * BLOCK).min(self.radius.len());
        let (mut best, mut r) = (NONE, f64::NEG_INFINITY);
        for i in b * BLOCK..end {
            if self.radius[i] > r {
                (best, r) = (i as u32, self.radius[i]);
            }
        }
        best
    }

    /// Recomputes every block (after [`reset`](Self::reset) and [`set_leaf`]s).
    pub(crate) fn build(&mut self) {
        for b in 0..self.block.len() {
            self.block[b] = self.scan_block(b);
        }
    }

    /// Sets slot `i` without updating its block (then [`build`](Self::build)).
    pub(crate) fn set_leaf(&mut self, i: usize, candidate: Candidate) {
        let (c, r, site) = candidate.unwrap_or((DVec3::ZERO, f64::NEG_INFINITY, 0));
        self.centre[i] = c;
        self.radius[i] = r;
        self.site[i] = site;
    }

    /// Sets slot `i` (growing the slots if needed) and rescans its block.
    pub(crate) fn set(&mut self, i: usize, candidate: Candidate) {
        if i >= self.radius.len() {
            self.radius.resize(i + 1, f64::NEG_INFINITY);
            self.centre.resize(i + 1, DVec3::ZERO);
            self.site.resize(i + 1, 0);
            self.block.resize((i + 1).div_ceil(BLOCK), NONE);
        }
        self.set_leaf(i, candidate);
        self.block[i / BLOCK] = self.scan_block(i / BLOCK);
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
        let (mut best, mut r) = (NONE, f64::NEG_INFINITY);
        for &k in &self.block {
            if k != NONE && self.radius[k as usize] > r {
                (best, r) = (k, self.radius[k as usize]);
            }
        }
        let b = best as usize;
        (best != NONE).then(|| (self.centre[b], self.radius[b], self.site[b]))
    }
}

/// Slots of which few hold a candidate (the disc's rim crossings and rim points, the
/// sphere's wrap-around triangles: only near the hull): the candidates in a short list, found
/// by slot. Same answers as a [`BlockMax`] (the largest radius, ties to the lower slot) without
/// a pass over every slot each time the candidates are recomputed.
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
    pub(crate) faces: BlockMax,
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
