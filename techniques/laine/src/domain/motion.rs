//! Moving a [`SamplingDomain`] to new points (the management's per-frame update): last
//! frame's triangulation kept, the sites whose motion breaks it taken out and put back.

use glam::DVec3;
use spade::handles::VertexHandle;
use spade::Triangulation;

use super::sites::{stored_site, Site, Slot};
use super::sphere::Pole;
use super::SamplingDomain;

/// What [`SamplingDomain::update_sites`] did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SiteUpdate {
    /// Per site, whether it is in the domain (`from_sites`'s acceptance).
    pub accepted: Vec<bool>,
    /// Whether the domain was rebuilt from the sites (a bulk load) instead of moved.
    pub rebuilt: bool,
    /// Moved: the sites taken out before the motion and inserted again after it.
    pub reinserted: usize,
}

impl SamplingDomain {
    /// Moves the domain to `sites` (id, point), the same sites as now at new points (the
    /// management's sampling points after the light moved; sites absent from `sites` are
    /// removed): afterwards the domain holds the Delaunay triangulation of the new points, the
    /// one [`from_sites`](Self::from_sites) would build (up to the internal numbering and the
    /// diagonal of four cocircular points: candidates of exactly equal radius are told apart
    /// by the numbering, and circumcentres of near-degenerate triangles by the order of their
    /// corners), and the result is `from_sites`'s acceptance per site.
    ///
    /// Kinetic, not rebuilt: the points move a little per frame, so almost every triangle of
    /// last frame's triangulation is still a Delaunay triangle of the new points. The sites
    /// whose motion breaks it are found first — corners of triangles that would turn over or
    /// flatten, convex-hull corners that would stop being strictly convex, and for each edge
    /// whose quadrilateral would stop being locally Delaunay the vertex opposite it — and
    /// removed while the points are still where they were (a Delaunay triangulation, so
    /// spade's removal applies); the check repeats around what the removals changed until
    /// nothing is broken. Every remaining triangle then keeps its orientation, the hull stays
    /// convex and every edge locally Delaunay, so moving the points leaves a Delaunay
    /// triangulation (Delaunay's lemma), into which the removed sites are inserted at their
    /// new points. Measured on Sibenik's animation at 1024 sites: about four such edges per
    /// frame, and a triangle turning over in one frame of 40 (disc) to 150 (sphere). Anything else — a new or repeated id, an invalid
    /// point, a sphere whose first site is not its projection pole (`from_sites` makes the first
    /// site the pole: after the pole's site is deleted, one rebuild), more than a quarter of the sites to move this way, a
    /// refused re-insertion — rebuilds from the sites instead (`from_sites`), so the result
    /// never depends on which path ran.
    pub fn update_sites(&mut self, sites: &[(u64, DVec3)]) -> SiteUpdate {
        if let Some(reinserted) = self.move_sites(sites) {
            return SiteUpdate {
                accepted: vec![true; sites.len()],
                rebuilt: false,
                reinserted,
            };
        }
        let (d, accepted) = Self::from_sites(self.kind, sites);
        *self = d;
        SiteUpdate {
            accepted,
            rebuilt: true,
            reinserted: 0,
        }
    }

    /// The kinetic path of [`update_sites`](Self::update_sites): the number of sites taken
    /// out and put back, or `None` when it does not apply (the domain is then rebuilt,
    /// whatever state this left it in).
    fn move_sites(&mut self, sites: &[(u64, DVec3)]) -> Option<usize> {
        if sites.len() < 8 || self.tri.num_inner_faces() == 0 {
            return None;
        }
        // The new pole (it must stay, and be the first site: `from_sites` makes the first
        // site the pole, and the sphere's duplicate rule is relative to it), then per vertex
        // (spade's index) its site at the new point; a site the domain does not hold, or a
        // repeated one, rebuilds.
        let pole = match self.pole {
            Some(p) => {
                let &(id, x) = sites.first()?;
                if id != p.id {
                    return None;
                }
                let len = x.length();
                if !(len > 0.0 && len.is_finite()) {
                    return None;
                }
                Some(Pole::new(p.id, x / len))
            }
            None => None,
        };
        let n = self.tri.num_vertices();
        let mut target = vec![None; n];
        let mut pole_seen = false;
        for &(id, point) in sites {
            match *self.slots.get(&id)? {
                Slot::Planar(h) => {
                    let slot = &mut target[h.index()];
                    if slot.is_some() {
                        return None;
                    }
                    let (pos, point) = stored_site(self.kind, pole.as_ref(), point).ok()??;
                    *slot = Some(Site { pos, point, id });
                }
                Slot::Pole if !pole_seen => pole_seen = true,
                Slot::Pole => return None,
            }
        }
        // Remove the sites that are gone (spade swap-removes a vertex; so does `target`).
        let gone: Vec<u64> = (self.tri.vertices())
            .zip(&target)
            .filter(|(_, t)| t.is_none())
            .map(|(v, _)| v.data().id)
            .collect();
        for id in gone {
            let Some(Slot::Planar(h)) = self.slots.get(&id) else {
                return None;
            };
            target.swap_remove(h.index());
            self.remove(id)?;
        }
        let mut target: Vec<Site> = target.into_iter().collect::<Option<_>>()?;
        // Remove (at the old points) what the motion would break, until nothing is.
        let limit = sites.len() / 4;
        let mut pending: Vec<Site> = Vec::new();
        let mut dirty: Option<Vec<u64>> = None;
        loop {
            let broken = self.broken_by_motion(&target, dirty.as_deref());
            if broken.is_empty() {
                break;
            }
            if pending.len() + broken.len() > limit {
                return None;
            }
            let mut around = Vec::new();
            for &id in &broken {
                if let Some(Slot::Planar(h)) = self.slots.get(&id) {
                    around.extend(self.tri.vertex(*h).out_edges().map(|e| e.to().data().id));
                }
            }
            for id in broken {
                let Some(Slot::Planar(h)) = self.slots.get(&id) else {
                    return None;
                };
                // spade swap-removes the vertex; so does `target`.
                pending.push(target.swap_remove(h.index()));
                self.remove(id)?;
            }
            around.retain(|id| self.slots.contains_key(id));
            dirty = Some(around);
        }
        // Move, then insert the removed sites where they now are.
        for (h, site) in self.tri.fixed_vertices().zip(target) {
            *self.tri.vertex_data_mut(h) = site;
        }
        self.pole = pole;
        // The location grids keep last frame's sites: a moved site is still a good place to
        // start a walk from, and a hint never changes the result.
        self.lec_mut().valid = false;
        let reinserted = pending.len();
        for site in pending {
            self.insert_site(site, None).ok()?;
        }
        Some(reinserted)
    }

    /// The ids of planar sites whose move to `target` would break the triangulation (see
    /// [`update_sites`](Self::update_sites)): checked everywhere, or (`dirty`) only in the
    /// triangles and edges around these sites — the neighbours of the sites just removed: the
    /// holes they left are retriangulated between them, so every changed triangle has all its
    /// corners among them and every edge whose quadrilateral changed both ends —, and always
    /// along the convex hull.
    fn broken_by_motion(&self, target: &[Site], dirty: Option<&[u64]>) -> Vec<u64> {
        let at = |v: VertexHandle<'_, Site, (), (), ()>| {
            let p = target[v.fix().index()].pos;
            robust::Coord { x: p.x, y: p.y }
        };
        type V<'a> = VertexHandle<'a, Site, (), (), ()>;
        let mut broken = Vec::new();
        // A triangle of the old triangulation (corners counter-clockwise) turned over or flat.
        let check_face = |corners: [V<'_>; 3], broken: &mut Vec<u64>| {
            let [a, b, c] = corners.map(at);
            if robust::orient2d(a, b, c) <= 0.0 {
                broken.extend(corners.map(|v| v.data().id));
            }
        };
        // The edge p → q between two triangles (r opposite it on its left, d on its right), no
        // longer locally Delaunay: d is inside the left triangle's circumcircle.
        let check_edge = |[p, q, r, d]: [V<'_>; 4], broken: &mut Vec<u64>| {
            if robust::incircle(at(p), at(q), at(r), at(d)) > 0.0 {
                broken.push(d.data().id);
            }
        };
        match dirty {
            None => {
                // Face by face: its orientation, then each of its edges once, in the edge's own
                // direction, the face's third corner opposite on the left.
                for f in self.tri.inner_faces() {
                    let edges = f.adjacent_edges();
                    let corners = edges.map(|e| e.from());
                    check_face(corners, &mut broken);
                    for (k, e) in edges.into_iter().enumerate() {
                        if e.fix().as_undirected().as_directed() != e.fix() {
                            continue;
                        }
                        if let Some(d) = e.rev().opposite_vertex() {
                            let [p, q, r] = [k, k + 1, k + 2].map(|i| corners[i % 3]);
                            check_edge([p, q, r, d], &mut broken);
                        }
                    }
                }
            }
            Some(ids) => {
                for id in ids {
                    let Some(Slot::Planar(h)) = self.slots.get(id) else {
                        continue;
                    };
                    for e in self.tri.vertex(*h).out_edges() {
                        if e.face().as_inner().is_some() {
                            check_face([e.from(), e.to(), e.next().to()], &mut broken);
                        }
                        if let (Some(r), Some(d)) = (e.opposite_vertex(), e.rev().opposite_vertex())
                        {
                            check_edge([e.from(), e.to(), r, d], &mut broken);
                        }
                    }
                }
            }
        }
        // The convex hull (clockwise along the outer face) must turn strictly right.
        for e in self.tri.convex_hull() {
            let n = e.next();
            if robust::orient2d(at(e.from()), at(e.to()), at(n.to())) >= 0.0 {
                broken.push(e.to().data().id);
            }
        }
        broken.sort_unstable();
        broken.dedup();
        broken
    }
}
