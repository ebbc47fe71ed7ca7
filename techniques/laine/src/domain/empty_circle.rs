//! The largest empty circle (§4.6) and the dispersion (§4.3): the candidate slots of faces,
//! edges and vertices, kept in the crate's `lec` cache or found by a full scan.

use glam::{DVec2, DVec3};
use spade::handles::{
    FixedDirectedEdgeHandle, FixedFaceHandle, FixedUndirectedEdgeHandle, FixedVertexHandle,
    InnerTag,
};
use spade::Triangulation;

use super::plane::circumcentre;
use super::sites::Site;
use super::sphere::{sphere_triangle_slot, spherical_circumcentre};
use super::{DomainKind, SamplingDomain};
use crate::lec::{Candidate, LecCache};

/// Relative tolerance of the "antipodal boundary point lies in the cell" test (§4.6 case 3).
const CELL_EPS: f64 = 1e-12;

impl SamplingDomain {
    /// The centre and radius of the largest empty circle (§4.6), whose centre is where the
    /// paper inserts the next sampling point; its radius is the dispersion (§4.3, Eq. 1).
    /// The radius equals the distance from the centre to its nearest site.
    ///
    /// * Disc (centre constrained to the disc): the maximum over the three candidate kinds of
    ///   §4.6 ([SH75, AK00]): (1) Voronoi vertices inside the disc, (2) intersections of
    ///   Voronoi edges with the bounding circle, (3) the boundary point −p/|p| when the Voronoi
    ///   cell of site p contains the whole segment from p through the origin to the circle
    ///   (the paper's only possible "vertex of the bounding polygon" case for a circle; for a
    ///   site at the origin, any boundary point of its cell, e.g. (1, 0)). Case (1) takes the
    ///   circumcentres of the Delaunay triangles, case (2) intersects each Delaunay edge's dual
    ///   Voronoi edge (a segment between the circumcentres of its two faces, a ray for convex
    ///   hull edges, the whole bisector for collinear sites) with the circle, and case (3) tests
    ///   −p/|p| against the bisectors of p's Delaunay neighbours. These are all the extreme
    ///   points of the regions (Voronoi cell ∩ disc), over each of which the distance to the
    ///   cell's site is convex, so the maximum is among them. With
    ///   no sites: the origin, radius 1.
    /// * Sphere: only case (1) exists (no boundary): the maximum over the spherical Delaunay
    ///   triangles of their circumcentres ([`triangles`](Self::triangles)); chordal radius.
    ///   Fewer than three sites are solved directly: none → (+Z, 2); one site p → (−p, 2);
    ///   two → the point of their bisecting great circle farthest from both.
    ///
    /// Always `Some` for a valid domain; `None` only if no candidate had a finite radius.
    ///
    /// Answered from candidates kept between calls (the crate's `lec` module): after an
    /// insertion only the slots it changed are recomputed; after a removal the next call
    /// recomputes all.
    #[inline]
    pub fn largest_empty_circle(&self) -> Option<(DVec3, f64)> {
        self.largest_empty_circle_near().map(|(c, r, _)| (c, r))
    }

    /// [`largest_empty_circle`](Self::largest_empty_circle) with the id of a site on its
    /// circle (a hint for [`insert_near`](Self::insert_near)), `None` where there is none.
    pub fn largest_empty_circle_near(&self) -> Option<(DVec3, f64, Option<u64>)> {
        match self.kind {
            DomainKind::Disc if self.tri.num_vertices() == 0 => {
                return Some((DVec3::ZERO, 1.0, None));
            }
            DomainKind::Sphere if self.len() < 3 => {
                return self
                    .sphere_largest_empty_circle()
                    .map(|(c, r)| (c, r, None));
            }
            _ => {}
        }
        let mut lec = self.lec_cache();
        if !lec.valid {
            self.recompute_lec(&mut lec);
        }
        let (centre, radius, site) = lec.best()?;
        Some((centre, radius, Some(self.site_id(site as usize))))
    }

    /// The largest empty circle by a pass over the whole triangulation, without the kept
    /// candidates: what [`largest_empty_circle`](Self::largest_empty_circle) must equal bit
    /// for bit (the tests compare them: it checks the keeping and updating, while the slot
    /// functions both use are pinned by the management's layout test).
    #[inline]
    pub fn largest_empty_circle_by_scan(&self) -> Option<(DVec3, f64)> {
        match self.kind {
            DomainKind::Disc => self.disc_largest_empty_circle(),
            DomainKind::Sphere => self.sphere_largest_empty_circle(),
        }
    }

    /// The dispersion δ (§4.3, Eq. 1): the radius of the [largest empty
    /// circle](Self::largest_empty_circle) (chordal on the sphere).
    #[inline]
    pub fn dispersion(&self) -> f64 {
        self.largest_empty_circle().map_or(0.0, |(_, r)| r)
    }

    /// The largest-empty-circle cache (a poisoned lock only means a panic elsewhere mid-query;
    /// the cache is then recomputed).
    #[inline]
    pub(super) fn lec_cache(&self) -> std::sync::MutexGuard<'_, LecCache> {
        self.lec.lock().unwrap_or_else(|e| {
            let mut guard = e.into_inner();
            guard.valid = false;
            guard
        })
    }

    #[inline]
    pub(super) fn lec_mut(&mut self) -> &mut LecCache {
        match self.lec.get_mut() {
            Ok(lec) => lec,
            Err(e) => {
                let lec = e.into_inner();
                lec.valid = false;
                lec
            }
        }
    }

    /// Disc: inner face `f`'s corners, counter-clockwise, and the index of the first.
    #[inline]
    pub(super) fn disc_face_corners(&self, f: FixedFaceHandle<InnerTag>) -> ([DVec2; 3], usize) {
        let [a, b, c] = self.tri.face(f).vertices();
        (
            [a, b, c].map(|v| v.data().point.truncate()),
            a.fix().index(),
        )
    }

    /// Disc: inner face `f`'s circumcentre and its case (1) slot (the circumcentre, if inside
    /// the disc), from one walk round the face.
    #[inline]
    fn disc_face(&self, f: FixedFaceHandle<InnerTag>) -> (Option<DVec2>, Candidate) {
        let ([a, b, c], site) = self.disc_face_corners(f);
        let m = circumcentre(a, b, c);
        let slot = m.and_then(|m| {
            let r = (m - a).length();
            (m.length_squared() <= 1.0 && r.is_finite()).then(|| (m.extend(0.0), r, site as u32))
        });
        (m, slot)
    }

    /// Disc, case (2): where the Voronoi edge of undirected edge `u` crosses the rim (its two
    /// roots, in the scan's order), from the faces' circumcentres `centres`. The Voronoi edge
    /// dual to p→q runs along their bisector between the circumcentres of the faces on either
    /// side; an outer face makes it a ray leaving the triangulation on that side, two make it
    /// the whole bisector (collinear sites); a degenerate face (circumcentre at infinity) gives
    /// none.
    fn disc_edge_slots(
        &self,
        u: FixedUndirectedEdgeHandle,
        centres: &[Option<DVec2>],
    ) -> [Candidate; 2] {
        let mut out = [None, None];
        let e = self.tri.directed_edge(u.as_directed());
        let left = e.face().as_inner().map(|f| centres[f.fix().index()]);
        let right = e.rev().face().as_inner().map(|f| centres[f.fix().index()]);
        // Both ends inside the disc (with a margin far above rounding): the Voronoi edge, a
        // segment between them, cannot reach the rim.
        let inside =
            |c: Option<Option<DVec2>>| c.flatten().is_some_and(|c| c.length_squared() < 1.0 - 1e-9);
        if inside(left) && inside(right) {
            return out;
        }
        let site = e.from().fix().index() as u32;
        let pos = |v: spade::handles::VertexHandle<Site>| v.data().point.truncate();
        let (p, q) = (pos(e.from()), pos(e.to()));
        let normal = (q - p).perp().normalize_or_zero();
        let (origin, t_range) = match (left, right) {
            (Some(Some(l)), Some(Some(r))) => (r, (0.0, (l - r).dot(normal))),
            (None, Some(Some(r))) => (r, (0.0, f64::INFINITY)),
            (Some(Some(l)), None) => (l, (f64::NEG_INFINITY, 0.0)),
            (None, None) => (0.5 * (p + q), (f64::NEG_INFINITY, f64::INFINITY)),
            _ => return out,
        };
        let half_b = origin.dot(normal);
        let disc = half_b * half_b - (origin.length_squared() - 1.0);
        if disc >= 0.0 {
            let s = disc.sqrt();
            for (k, t) in [-half_b - s, -half_b + s].into_iter().enumerate() {
                if t >= t_range.0.min(t_range.1) && t <= t_range.0.max(t_range.1) {
                    let c = origin + normal * t;
                    let c = c / c.length();
                    let r = (c - p).length();
                    if r.is_finite() {
                        out[k] = Some((c.extend(0.0), r, site));
                    }
                }
            }
        }
        out
    }

    /// Disc, case (3): the rim point opposite vertex `v` if its cell reaches it (then it holds
    /// the whole segment from the site through the origin, the cell being convex).
    fn disc_vertex_slot(&self, v: FixedVertexHandle) -> Candidate {
        let v = self.tri.vertex(v);
        let p = v.data().point.truncate();
        let len = p.length();
        let c = if len > 0.0 { -p / len } else { DVec2::X };
        let rp = (c - p).length_squared();
        let inside = v.out_edges().all(|e| {
            let q = e.to().data().point.truncate();
            rp <= (c - q).length_squared() * (1.0 + CELL_EPS) + CELL_EPS
        });
        let r = rp.sqrt();
        (inside && r.is_finite()).then(|| (c.extend(0.0), r, v.fix().index() as u32))
    }

    /// Sphere: inner face `f`'s triangle.
    #[inline]
    fn sphere_face_slot(&self, f: FixedFaceHandle<InnerTag>) -> Candidate {
        let [a, b, c] = self.tri.face(f).vertices();
        sphere_triangle_slot([a, b, c].map(|v| v.data().point), a.fix().index())
    }

    /// Sphere: the wrap-around triangle (from, to, pole) of directed edge `d` if it is a
    /// convex-hull edge seen from outside.
    fn sphere_wrap_slot(&self, d: FixedDirectedEdgeHandle) -> Candidate {
        let e = self.tri.directed_edge(d);
        if self.pole.is_none() || self.tri.num_vertices() < 2 || !e.is_outer_edge() {
            return None;
        }
        // The pole has no spade index: a wrap-around triangle's hint is its first site.
        sphere_triangle_slot(
            [
                e.from().data().point,
                e.to().data().point,
                self.site_point(self.pole_index()),
            ],
            e.from().fix().index(),
        )
    }

    /// Fills every slot of `lec` from the current triangulation.
    fn recompute_lec(&self, lec: &mut LecCache) {
        let t = &self.tri;
        lec.faces.reset(t.num_all_faces());
        match self.kind {
            DomainKind::Disc => {
                lec.centres.clear();
                lec.centres.resize(t.num_all_faces(), None);
                for f in t.inner_faces() {
                    let i = f.fix().index();
                    let (centre, slot) = self.disc_face(f.fix());
                    lec.centres[i] = centre;
                    lec.faces.set_leaf(i, slot);
                }
                // After a reset every slot is empty: only candidates are set (most edges and
                // vertices have none).
                lec.edges.reset(2 * t.num_undirected_edges());
                for u in t.fixed_undirected_edges() {
                    let [a, b] = self.disc_edge_slots(u, &lec.centres);
                    for (k, c) in [(0, a), (1, b)] {
                        if c.is_some() {
                            lec.edges.set(2 * u.index() + k, c);
                        }
                    }
                }
                lec.vertices.reset(t.num_vertices());
                for v in t.fixed_vertices() {
                    let c = self.disc_vertex_slot(v);
                    if c.is_some() {
                        lec.vertices.set(v.index(), c);
                    }
                }
                lec.wraps.reset(0);
            }
            DomainKind::Sphere => {
                for f in t.inner_faces() {
                    lec.faces
                        .set_leaf(f.fix().index(), self.sphere_face_slot(f.fix()));
                }
                // Only the convex hull's edges (the outer face's) have a wrap-around triangle.
                lec.wraps.reset(t.num_directed_edges());
                for d in t.convex_hull() {
                    lec.wraps
                        .set(d.fix().index(), self.sphere_wrap_slot(d.fix()));
                }
                lec.edges.reset(0);
                lec.vertices.reset(0);
            }
        }
        lec.faces.build();
        lec.valid = true;
    }

    /// Updates the slots of `lec` that inserting vertex `v` changed (see [`crate::lec`]).
    pub(super) fn update_lec(&self, lec: &mut LecCache, v: FixedVertexHandle) {
        let t = &self.tri;
        let vh = t.vertex(v);
        let faces: Vec<FixedFaceHandle<InnerTag>> = vh
            .out_edges()
            .filter_map(|e| e.face().as_inner().map(|f| f.fix()))
            .collect();
        match self.kind {
            DomainKind::Disc => {
                lec.centres.resize(t.num_all_faces(), None);
                for &f in &faces {
                    let (centre, slot) = self.disc_face(f);
                    lec.centres[f.index()] = centre;
                    lec.faces.set(f.index(), slot);
                }
                for &f in &faces {
                    for d in t.face(f).adjacent_edges() {
                        let u = d.fix().as_undirected();
                        let [a, b] = self.disc_edge_slots(u, &lec.centres);
                        lec.edges.set(2 * u.index(), a);
                        lec.edges.set(2 * u.index() + 1, b);
                    }
                }
                lec.vertices.set(v.index(), self.disc_vertex_slot(v));
                for e in vh.out_edges() {
                    let w = e.to().fix();
                    lec.vertices.set(w.index(), self.disc_vertex_slot(w));
                }
            }
            DomainKind::Sphere => {
                for &f in &faces {
                    lec.faces.set(f.index(), self.sphere_face_slot(f));
                }
                for &f in &faces {
                    for d in t.face(f).adjacent_edges() {
                        for d in [d.fix(), d.fix().rev()] {
                            lec.wraps.set(d.index(), self.sphere_wrap_slot(d));
                        }
                    }
                }
            }
        }
    }

    /// Disc: one pass over every slot — (1) faces, (2) edges, (3) vertices, each in index
    /// order, the first strictly largest radius winning — with the slot functions the kept
    /// candidates use.
    fn disc_largest_empty_circle(&self) -> Option<(DVec3, f64)> {
        if self.tri.num_vertices() == 0 {
            return Some((DVec3::ZERO, 1.0));
        }
        let mut best: Candidate = None;
        let mut consider = |c: Candidate| {
            if let Some(c) = c {
                if best.is_none_or(|b| c.1 > b.1) {
                    best = Some(c);
                }
            }
        };
        let mut centres = vec![None; self.tri.num_all_faces()];
        for f in self.tri.inner_faces() {
            let (centre, slot) = self.disc_face(f.fix());
            centres[f.fix().index()] = centre;
            consider(slot);
        }
        for u in self.tri.fixed_undirected_edges() {
            for c in self.disc_edge_slots(u, &centres) {
                consider(c);
            }
        }
        for v in self.tri.fixed_vertices() {
            consider(self.disc_vertex_slot(v));
        }
        best.map(|(c, r, _)| (c, r))
    }

    fn sphere_largest_empty_circle(&self) -> Option<(DVec3, f64)> {
        let pts = self.points();
        match pts.len() {
            0 => return Some((DVec3::Z, 2.0)),
            1 => return Some((-pts[0].1, 2.0)),
            2 => {
                let (a, b) = (pts[0].1, pts[1].1);
                let s = a + b;
                let c = if s.length_squared() > 1e-24 {
                    -s.normalize()
                } else {
                    a.any_orthonormal_vector()
                };
                return Some((c, (c - a).length()));
            }
            _ => {}
        }
        let mut best: Option<(DVec3, f64)> = None;
        for t in self.triangle_indices() {
            let [a, b, c] = t.map(|i| self.site_point(i as usize));
            let m = spherical_circumcentre(a, b, c);
            if m == DVec3::ZERO {
                continue;
            }
            let r = (m - a).length();
            if best.is_none_or(|(_, br)| r > br) {
                best = Some((m, r));
            }
        }
        best
    }
}
