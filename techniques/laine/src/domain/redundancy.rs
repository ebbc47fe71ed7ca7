//! Redundant sites (§4.5): the shortest Delaunay edge, second-closest neighbours, and the
//! queue of short edges a run of deletions shares.

use spade::Triangulation;

use super::SamplingDomain;

/// A Delaunay edge as a queue key: its squared length, then its two ids (smaller first), so
/// that equal lengths are ordered by the sites, not by the triangulation's numbering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct EdgeKey {
    /// The squared length's bits (a non-negative float orders as its bits).
    bits: u64,
    ids: [u64; 2],
}

impl EdgeKey {
    #[inline]
    fn new(l2: f64, a: u64, b: u64) -> Self {
        EdgeKey {
            bits: l2.to_bits(),
            ids: [a.min(b), a.max(b)],
        }
    }

    #[inline]
    fn length(&self) -> f64 {
        f64::from_bits(self.bits).sqrt()
    }
}

/// The Delaunay edges of a [`SamplingDomain`] by length (see
/// [`SamplingDomain::remove_redundant`]).
#[derive(Debug)]
pub struct RedundancyQueue {
    heap: std::collections::BinaryHeap<std::cmp::Reverse<EdgeKey>>,
    /// The longest edge queued by the last pass, if it left edges out (all longer).
    bound: Option<EdgeKey>,
    scratch: Vec<usize>,
}

/// Edges [`SamplingDomain::redundancy_queue`] keeps from one pass (a frame deletes a few
/// sites, each taking its shortest edge and a handful of its neighbours' with it).
const QUEUED_EDGES: usize = 32;

impl SamplingDomain {
    /// The shortest Delaunay edge (§4.5) as `(id, id, length)`; `None` with fewer than two
    /// sites.
    #[inline]
    pub fn shortest_edge(&self) -> Option<(u64, u64, f64)> {
        self.shortest_edge_indices()
            .map(|(a, b, l)| (self.site_id(a), self.site_id(b), l))
    }

    fn shortest_edge_indices(&self) -> Option<(usize, usize, f64)> {
        let mut best: Option<(EdgeKey, usize, usize)> = None;
        let mut consider = |a: usize, b: usize, l2: f64| {
            let key = EdgeKey::new(l2, self.site_id(a), self.site_id(b));
            if best.is_none_or(|(k, _, _)| key < k) {
                best = Some((key, a, b));
            }
        };
        for e in self.tri.undirected_edges() {
            let [a, b] = e.vertices();
            let l2 = (a.data().point - b.data().point).length_squared();
            consider(a.fix().index(), b.fix().index(), l2);
        }
        if self.pole.is_some() {
            let np = self.pole_index();
            let mut nb = Vec::new();
            self.neighbours(np, &mut nb);
            let pp = self.site_point(np);
            for i in nb {
                consider(np, i, (self.site_point(i) - pp).length_squared());
            }
        }
        best.map(|(k, a, b)| (a, b, k.length()))
    }

    /// The distance from site `index` to its second-closest Delaunay neighbour (+∞ with fewer
    /// than two neighbours).
    fn second_closest_distance(&self, index: usize, scratch: &mut Vec<usize>) -> f64 {
        self.neighbours(index, scratch);
        let p = self.site_point(index);
        let (mut d1, mut d2) = (f64::INFINITY, f64::INFINITY);
        for &i in scratch.iter() {
            let d = (self.site_point(i) - p).length_squared();
            if d < d1 {
                d2 = d1;
                d1 = d;
            } else if d < d2 {
                d2 = d;
            }
        }
        d2.sqrt()
    }

    /// The distance from `id` to its second-closest Delaunay neighbour (§4.5), `None` if `id`
    /// is absent, +∞ with fewer than two neighbours.
    #[inline]
    pub fn second_closest_neighbour_distance(&self, id: u64) -> Option<f64> {
        let i = self.index_of(id)?;
        Some(self.second_closest_distance(i, &mut Vec::new()))
    }

    /// The site §4.5 deletes next: of the two endpoints of the [shortest Delaunay
    /// edge](Self::shortest_edge), "the vertex that has smaller distance to second-closest
    /// neighbor" (second-closest among its Delaunay neighbours, as the paper examines "the
    /// neighbors of the two vertices"). Ties (e.g. two sites) delete the larger id. `None` with
    /// fewer than two sites.
    #[inline]
    pub fn deletion_candidate(&self) -> Option<u64> {
        let (a, b, _) = self.shortest_edge_indices()?;
        Some(self.redundant_endpoint(a, b))
    }

    /// Of the endpoints (internal indices) of a shortest edge, the one §4.5 deletes.
    fn redundant_endpoint(&self, a: usize, b: usize) -> u64 {
        let mut scratch = Vec::new();
        let da = self.second_closest_distance(a, &mut scratch);
        let db = self.second_closest_distance(b, &mut scratch);
        let (ia, ib) = (self.site_id(a), self.site_id(b));
        if da < db {
            ia
        } else if db < da {
            ib
        } else {
            ia.max(ib)
        }
    }

    /// The shortest Delaunay edges, for a run of §4.5 deletions with
    /// [`remove_redundant`](Self::remove_redundant): one pass over the edges keeps the
    /// 32 shortest (and the longest of them as a bound: every edge left out is
    /// longer), instead of one pass per deletion.
    pub fn redundancy_queue(&self) -> RedundancyQueue {
        let mut best: std::collections::BinaryHeap<EdgeKey> =
            std::collections::BinaryHeap::with_capacity(QUEUED_EDGES + 1);
        let mut total = 0;
        let mut keep = |key: EdgeKey| {
            total += 1;
            if best.len() < QUEUED_EDGES {
                best.push(key);
            } else if best.peek().is_some_and(|m| key < *m) {
                best.pop();
                best.push(key);
            }
        };
        for e in self.tri.undirected_edges() {
            let [a, b] = e.vertices();
            let l2 = (a.data().point - b.data().point).length_squared();
            keep(EdgeKey::new(l2, a.data().id, b.data().id));
        }
        let mut scratch = Vec::new();
        if self.pole.is_some() {
            self.edge_keys_of(self.pole_index(), &mut scratch, keep);
        }
        let bound = (total > best.len()).then(|| best.peek().copied()).flatten();
        RedundancyQueue {
            heap: best.into_iter().map(std::cmp::Reverse).collect(),
            bound,
            scratch,
        }
    }

    /// `f` of the queue key of every Delaunay edge of site `index` (`nb`: scratch).
    #[inline]
    fn edge_keys_of(&self, index: usize, nb: &mut Vec<usize>, mut f: impl FnMut(EdgeKey)) {
        self.neighbours(index, nb);
        let (p, id) = (self.site_point(index), self.site_id(index));
        for &n in nb.iter() {
            let l2 = (self.site_point(n) - p).length_squared();
            f(EdgeKey::new(l2, id, self.site_id(n)));
        }
    }

    /// Pushes the edges of site `index` onto `q`.
    #[inline]
    fn queue_edges_of(&self, index: usize, q: &mut RedundancyQueue) {
        let mut nb = std::mem::take(&mut q.scratch);
        self.edge_keys_of(index, &mut nb, |k| q.heap.push(std::cmp::Reverse(k)));
        q.scratch = nb;
    }

    /// Deletes the site [`deletion_candidate`](Self::deletion_candidate) names, taking the
    /// shortest edge from `q` (built by [`redundancy_queue`](Self::redundancy_queue) on this
    /// domain, and changed since only by this method): entries whose edge is gone are skipped
    /// (a site of theirs was removed — or, with cocircular sites, a removal chose the other
    /// diagonal), and the edges around the hole are queued after the removal. Returns the id removed,
    /// `None` with fewer than two sites.
    pub fn remove_redundant(&mut self, q: &mut RedundancyQueue) -> Option<u64> {
        let (a, b) = loop {
            // The shortest queued edge is the shortest edge if it is within the bound;
            // otherwise the queue is refilled.
            let k = match q.heap.peek() {
                Some(&std::cmp::Reverse(k)) if q.bound.is_none_or(|b| k <= b) => k,
                _ if q.bound.is_some() => {
                    *q = self.redundancy_queue();
                    continue;
                }
                _ => return None,
            };
            q.heap.pop();
            let (Some(a), Some(b)) = (self.index_of(k.ids[0]), self.index_of(k.ids[1])) else {
                continue;
            };
            self.neighbours(a, &mut q.scratch);
            if q.scratch.contains(&b) {
                break (a, b);
            }
        };
        let victim = self.redundant_endpoint(a, b);
        let index = self.index_of(victim)?;
        self.neighbours(index, &mut q.scratch);
        let around: Vec<u64> = q.scratch.iter().map(|&n| self.site_id(n)).collect();
        self.remove(victim)?;
        for id in around {
            if let Some(n) = self.index_of(id) {
                self.queue_edges_of(n, q);
            }
        }
        Some(victim)
    }
}
