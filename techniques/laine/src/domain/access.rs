//! Reading a [`SamplingDomain`]: its ids and points, the internal site indices (the sphere's
//! pole last), Delaunay neighbours and triangles.

use glam::DVec3;
use spade::handles::FixedVertexHandle;
use spade::Triangulation;

use super::{DomainKind, SamplingDomain, Slot};

impl SamplingDomain {
    /// The domain's kind.
    #[inline]
    pub fn kind(&self) -> DomainKind {
        self.kind
    }

    /// The number of sampling points.
    #[inline]
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Whether the domain holds no sampling point.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Whether `id` is in the domain.
    #[inline]
    pub fn contains(&self, id: u64) -> bool {
        self.slots.contains_key(&id)
    }

    /// The stored point of `id` (after the normalisation [`insert`](Self::insert) applies).
    #[inline]
    pub fn point(&self, id: u64) -> Option<DVec3> {
        match *self.slots.get(&id)? {
            Slot::Planar(h) => Some(self.tri.vertex(h).data().point),
            Slot::Pole => self.pole.map(|p| p.point),
        }
    }

    /// The position of site `id` in the domain's internal order, which [`points`] and
    /// [`voronoi_areas`] list the sites in (it changes as sites come and go).
    ///
    /// [`points`]: Self::points
    /// [`voronoi_areas`]: Self::voronoi_areas
    #[inline]
    pub fn site_index(&self, id: u64) -> Option<usize> {
        self.index_of(id)
    }

    /// All `(id, point)` pairs, in the domain's internal order (see [`site_index`]).
    ///
    /// [`site_index`]: Self::site_index
    #[inline]
    pub fn points(&self) -> Vec<(u64, DVec3)> {
        let mut out: Vec<(u64, DVec3)> = self
            .tri
            .vertices()
            .map(|v| (v.data().id, v.data().point))
            .collect();
        if let Some(p) = self.pole {
            out.push((p.id, p.point));
        }
        out
    }

    /// The number of sites, with the sphere's pole at index `tri.num_vertices()`.
    #[inline]
    pub(super) fn pole_index(&self) -> usize {
        self.tri.num_vertices()
    }

    #[inline]
    pub(super) fn site_point(&self, index: usize) -> DVec3 {
        if index < self.tri.num_vertices() {
            self.tri
                .vertex(FixedVertexHandle::from_index(index))
                .data()
                .point
        } else {
            self.pole.map_or(DVec3::ZERO, |p| p.point)
        }
    }

    #[inline]
    pub(super) fn site_id(&self, index: usize) -> u64 {
        if index < self.tri.num_vertices() {
            self.tri
                .vertex(FixedVertexHandle::from_index(index))
                .data()
                .id
        } else {
            self.pole.map_or(u64::MAX, |p| p.id)
        }
    }

    #[inline]
    pub(super) fn index_of(&self, id: u64) -> Option<usize> {
        match *self.slots.get(&id)? {
            Slot::Planar(h) => Some(h.index()),
            Slot::Pole => Some(self.pole_index()),
        }
    }

    /// Delaunay neighbours of site `index` (internal indices; the sphere's pole included).
    pub(super) fn neighbours(&self, index: usize, out: &mut Vec<usize>) {
        out.clear();
        let np = self.tri.num_vertices();
        if index < np {
            let v = self.tri.vertex(FixedVertexHandle::from_index(index));
            let mut on_hull = false;
            for e in v.out_edges() {
                out.push(e.to().fix().index());
                on_hull |= e.is_outer_edge();
            }
            if self.pole.is_some() && (on_hull || np == 1) {
                out.push(np);
            }
        } else if self.pole.is_some() {
            if np == 1 {
                out.push(0);
            } else {
                out.extend(self.tri.convex_hull().map(|e| e.from().fix().index()));
            }
        }
        out.sort_unstable();
        out.dedup();
    }

    /// The Delaunay triangles as id triples, counter-clockwise (on the sphere: seen from
    /// outside, so (b − a) × (c − a) is the outward normal of the triangle's plane and its
    /// normalisation the Voronoi vertex). On the sphere these include the wrap-around
    /// triangles at the pole (see the module docs). Fewer than three sites (or, on the disc,
    /// collinear sites) give none.
    #[inline]
    pub fn triangles(&self) -> Vec<[u64; 3]> {
        self.triangle_indices()
            .into_iter()
            .map(|t| t.map(|i| self.site_id(i as usize)))
            .collect()
    }

    /// Triangles as internal indices: spade's inner faces (face index f ↦ f − 1), then on the
    /// sphere one wrap-around triangle per outer directed edge; also returns, per directed
    /// edge, its wrap-around triangle (`u32::MAX` if none).
    fn triangles_and_wraps(&self) -> (Vec<[u32; 3]>, Vec<u32>) {
        let mut tris = vec![[0u32; 3]; self.tri.num_inner_faces()];
        for f in self.tri.inner_faces() {
            let v = f.vertices();
            tris[f.fix().index() - 1] = v.map(|v| v.fix().index() as u32);
        }
        let mut wraps = Vec::new();
        if self.pole.is_some() && self.tri.num_vertices() >= 2 {
            let np = self.pole_index() as u32;
            wraps = vec![u32::MAX; self.tri.num_directed_edges()];
            for e in self.tri.directed_edges() {
                if e.is_outer_edge() {
                    wraps[e.fix().index()] = tris.len() as u32;
                    tris.push([
                        e.from().fix().index() as u32,
                        e.to().fix().index() as u32,
                        np,
                    ]);
                }
            }
        }
        (tris, wraps)
    }

    #[inline]
    pub(super) fn triangle_indices(&self) -> Vec<[u32; 3]> {
        self.triangles_and_wraps().0
    }
}
