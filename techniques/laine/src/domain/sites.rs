//! The spade wrapper: how a [`SamplingDomain`]'s sites are stored (ids, planar positions,
//! the sphere's pole, location grids), built, inserted and removed.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::Mutex;

use glam::DVec3;
use spade::handles::FixedVertexHandle;
use spade::{
    DelaunayTriangulation, HasPosition, HintGenerator, Point2, PositionInTriangulation,
    Triangulation,
};

use super::sphere::Pole;
use super::{DomainError, DomainKind, SamplingDomain};
use crate::lec::LecCache;

/// A site as stored in spade: its planar position (the disc point, or the stereographic
/// projection of the sphere point), its domain point and its id.
#[derive(Clone, Copy, Debug)]
pub(super) struct Site {
    pub(super) pos: Point2<f64>,
    pub(super) point: DVec3,
    pub(super) id: u64,
}

impl HasPosition for Site {
    type Scalar = f64;
    #[inline]
    fn position(&self) -> Point2<f64> {
        self.pos
    }
}

/// A hasher for sequential ids (a multiplicative mix; the ids are the caller's, not
/// adversarial): the domain looks ids up several times per site and frame.
#[derive(Clone, Copy, Default)]
pub(super) struct IdHasher(u64);

impl std::hash::Hasher for IdHasher {
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ b as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    #[inline]
    fn write_u64(&mut self, n: u64) {
        self.0 = (n ^ (n >> 32)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
}

pub(super) type IdMap<V> = HashMap<u64, V, std::hash::BuildHasherDefault<IdHasher>>;

/// Cells per axis of the location grids: grids over the domain's points ([−1, 1]² or ³)
/// remembering, per cell, the id of the last site inserted there — where spade's point
/// location for the next point in that cell starts (the fine grid's cell, or if it is empty
/// the coarse one's). The sphere's points fill only its surface cells, hence fewer per axis.
pub(super) const GRIDS: [(usize, usize); 2] = [(8, 4), (2, 2)];

/// Index of point `p`'s cell in grid `level` of [`GRIDS`] (the disc's grids have one layer).
#[inline]
fn grid_cell(kind: DomainKind, level: usize, p: DVec3) -> usize {
    let n = match kind {
        DomainKind::Disc => GRIDS[level].0,
        DomainKind::Sphere => GRIDS[level].1,
    };
    let c = |x: f64| (((x + 1.0) * 0.5 * n as f64) as isize).clamp(0, n as isize - 1) as usize;
    let z = if kind == DomainKind::Disc { 0 } else { c(p.z) };
    (z * n + c(p.y)) * n + c(p.x)
}

/// Where a site lives.
#[derive(Clone, Copy, Debug)]
pub(super) enum Slot {
    Planar(FixedVertexHandle),
    Pole,
}

/// How a point enters a domain of `kind` whose sphere pole is `pole`
/// ([`SamplingDomain::insert`]'s rules, shared with [`SamplingDomain::from_sites`]):
/// `Ok(Some((spade position, stored point)))` for a planar site — disc: `point.z` dropped and a
/// point outside the unit disc moved radially onto its circle; sphere: normalised and projected
/// from the pole —, `Ok(None)` for the first sphere point (it becomes the pole, stored
/// normalised: `point / point.length()`), or why it is refused (not finite; on the sphere zero, or
/// the pole's point).
pub(super) fn stored_site(
    kind: DomainKind,
    pole: Option<&Pole>,
    point: DVec3,
) -> Result<Option<(Point2<f64>, DVec3)>, DomainError> {
    if !point.is_finite() {
        return Err(DomainError::InvalidPoint);
    }
    match kind {
        DomainKind::Disc => {
            let mut p = point.truncate();
            let len2 = p.length_squared();
            if len2 > 1.0 {
                if len2.is_finite() {
                    p /= len2.sqrt();
                } else {
                    // |p|² overflowed: scaled down first.
                    let q = p / p.abs().max_element();
                    p = q / q.length();
                }
            }
            let pos = spade::mitigate_underflow(Point2::new(p.x, p.y));
            Ok(Some((pos, DVec3::new(pos.x, pos.y, 0.0))))
        }
        DomainKind::Sphere => {
            let len = point.length();
            if len == 0.0 || !len.is_finite() {
                return Err(DomainError::InvalidPoint);
            }
            let x = point / len;
            let Some(pole) = pole else {
                return Ok(None);
            };
            if (x - pole.point).length_squared() < 1e-24 {
                return Err(DomainError::DuplicatePoint(pole.id));
            }
            Ok(Some((pole.project(x), x)))
        }
    }
}

impl SamplingDomain {
    /// A domain holding `n` points on a Fibonacci spiral (ids 0..n): evenly spread, the same
    /// every time — the filled domain of benchmarks and instruction counts.
    pub fn spiral(kind: DomainKind, n: u64) -> Self {
        let mut d = Self::new(kind);
        let golden = PI * (3.0 - 5f64.sqrt());
        for i in 0..n {
            let t = (i as f64 + 0.5) / n as f64;
            let phi = i as f64 * golden;
            let p = match kind {
                DomainKind::Disc => {
                    let r = t.sqrt() * 0.999;
                    DVec3::new(r * phi.cos(), r * phi.sin(), 0.0)
                }
                DomainKind::Sphere => {
                    let z = 1.0 - 2.0 * t;
                    let r = (1.0 - z * z).sqrt();
                    DVec3::new(r * phi.cos(), r * phi.sin(), z)
                }
            };
            d.insert(i, p)
                .expect("spiral points are distinct and inside the domain");
        }
        d
    }

    /// An empty domain of `kind`.
    #[inline]
    pub fn new(kind: DomainKind) -> Self {
        Self::with_capacity(kind, 0)
    }

    /// An empty domain of `kind` with room for `n` sites (no reallocation while it is filled
    /// up to that).
    pub fn with_capacity(kind: DomainKind, n: usize) -> Self {
        SamplingDomain {
            kind,
            tri: DelaunayTriangulation::with_capacity(n, 3 * n, 2 * n + 1),
            slots: IdMap::with_capacity_and_hasher(n, Default::default()),
            grids: [0, 1].map(|level| {
                let n = match kind {
                    DomainKind::Disc => GRIDS[level].0.pow(2),
                    DomainKind::Sphere => GRIDS[level].1.pow(3),
                };
                vec![u64::MAX; n]
            }),
            pole: None,
            lec: Mutex::new(LecCache::default()),
        }
    }

    /// A domain of `kind` holding `sites` (id, point), built at once: each site is accepted or
    /// refused exactly as [`insert`](Self::insert) would, called on the sites in order (a
    /// repeated id, an invalid point or a point equal to an earlier accepted one is refused),
    /// and the accepted ones are triangulated by spade's bulk load (a sweep over the points
    /// sorted by distance from their centroid; measured about 0.6 ms for 1024 points here
    /// against about 0.8 ms inserting them one by one). The Delaunay triangulation of points in general position is unique, so the
    /// triangles, empty circles and Voronoi cells are the ones the insertions give; only the
    /// internal numbering differs. Returns the domain and, per site, whether it was accepted.
    pub fn from_sites(kind: DomainKind, sites: &[(u64, DVec3)]) -> (Self, Vec<bool>) {
        let mut d = Self::with_capacity(kind, 0);
        let mut accepted = vec![false; sites.len()];
        let mut planar: Vec<Site> = Vec::with_capacity(sites.len());
        let mut ids: IdMap<()> = IdMap::with_capacity_and_hasher(sites.len(), Default::default());
        let mut positions: HashMap<[u64; 2], ()> = HashMap::with_capacity(sites.len());
        for (k, &(id, point)) in sites.iter().enumerate() {
            if ids.contains_key(&id) {
                continue;
            }
            let (pos, point) = match stored_site(kind, d.pole.as_ref(), point) {
                Ok(Some(site)) => site,
                Ok(None) => {
                    d.pole = Some(Pole::new(id, point / point.length()));
                    ids.insert(id, ());
                    accepted[k] = true;
                    continue;
                }
                Err(_) => continue,
            };
            // Equal positions are what spade's `locate_vertex` calls a duplicate.
            let key = [pos.x, pos.y].map(|c| if c == 0.0 { 0 } else { c.to_bits() });
            if positions.insert(key, ()).is_some() {
                continue;
            }
            ids.insert(id, ());
            accepted[k] = true;
            planar.push(Site { pos, point, id });
        }
        let n = planar.len();
        d.tri = match DelaunayTriangulation::bulk_load(planar) {
            Ok(t) => t,
            Err(_) => {
                // Positions are finite and distinct, so spade accepts them; should it not,
                // the insertions give the same domain.
                let mut d = Self::with_capacity(kind, sites.len());
                let accepted = sites.iter().map(|&(id, p)| d.insert(id, p).is_ok());
                let accepted = accepted.collect();
                return (d, accepted);
            }
        };
        d.slots = IdMap::with_capacity_and_hasher(n + 1, Default::default());
        if let Some(p) = d.pole {
            d.slots.insert(p.id, Slot::Pole);
        }
        for h in d.tri.fixed_vertices() {
            let s = *d.tri.vertex(h).data();
            d.slots.insert(s.id, Slot::Planar(h));
            for level in 0..2 {
                d.grids[level][grid_cell(kind, level, s.point)] = s.id;
            }
        }
        (d, accepted)
    }

    /// Adds the sampling point `point` under `id` and updates the Delaunay triangulation
    /// incrementally (§4.6: "we add it to the distribution and update the Delaunay
    /// triangulation"). Disc: `point.z` is ignored and a point outside the unit disc is moved
    /// radially onto its circle. Sphere: `point` is normalised. Fails, leaving the domain
    /// unchanged, on a repeated id, a non-finite (or, on the sphere, zero) point, or a point
    /// equal to an existing one (on the sphere: within 10⁻¹² of the pole site, or projecting
    /// onto an existing projected point).
    #[inline]
    pub fn insert(&mut self, id: u64, point: DVec3) -> Result<(), DomainError> {
        self.insert_near(id, point, None)
    }

    /// [`insert`](Self::insert), with the id of a site near `point` (e.g. the site of the
    /// largest empty circle it fills) to start spade's point location from; without one (or
    /// if it is gone) the location grid's site in `point`'s cell. The triangulation afterwards
    /// is the one spade's plain `insert` makes, index for index: a hint is used only when the
    /// point lies strictly inside a face (then the face is unique, whatever the walk);
    /// otherwise the point is located from where a plain `insert` would start.
    pub fn insert_near(
        &mut self,
        id: u64,
        point: DVec3,
        near: Option<u64>,
    ) -> Result<(), DomainError> {
        if self.slots.contains_key(&id) {
            return Err(DomainError::DuplicateId(id));
        }
        let Some((pos, point)) = stored_site(self.kind, self.pole.as_ref(), point)? else {
            self.pole = Some(Pole::new(id, point / point.length()));
            self.slots.insert(id, Slot::Pole);
            self.lec_mut().valid = false;
            return Ok(());
        };
        self.insert_site(Site { pos, point, id }, near)
    }

    /// [`insert_near`](Self::insert_near) of a planar site already mapped by [`stored_site`].
    pub(super) fn insert_site(&mut self, site: Site, near: Option<u64>) -> Result<(), DomainError> {
        let (pos, point, id) = (site.pos, site.point, site.id);
        let incremental = self.tri.num_inner_faces() > 0;
        let cells = [0, 1].map(|level| grid_cell(self.kind, level, point));
        let planar = |n: u64| match self.slots.get(&n) {
            Some(Slot::Planar(h)) => Some(*h),
            _ => None,
        };
        let hint = near
            .and_then(planar)
            .or_else(|| planar(self.grids[0][cells[0]]))
            .or_else(|| planar(self.grids[1][cells[1]]))
            .filter(|_| incremental);
        let mut handle = None;
        if let Some(h) = hint {
            // Where an unhinted call would start: restored unless the hinted walk found the
            // (unique) face containing the point.
            let start = self.tri.hint_generator().get_hint(pos);
            if let PositionInTriangulation::OnFace(f) = self.tri.locate_with_hint(pos, h) {
                // Located again from a corner of the face found: a walk of one step.
                let corner = self.tri.face(f).vertices()[0].fix();
                handle = Some(
                    self.tri
                        .insert_with_hint(site, corner)
                        .map_err(|_| DomainError::InvalidPoint)?,
                );
            } else {
                HintGenerator::<f64>::notify_vertex_lookup(self.tri.hint_generator(), start);
            }
        }
        let handle = match handle {
            Some(h) => h,
            None => {
                if let Some(v) = self.tri.locate_vertex(pos) {
                    return Err(DomainError::DuplicatePoint(v.data().id));
                }
                self.tri
                    .insert(site)
                    .map_err(|_| DomainError::InvalidPoint)?
            }
        };
        self.slots.insert(id, Slot::Planar(handle));
        self.grids[0][cells[0]] = id;
        self.grids[1][cells[1]] = id;
        let lec = self.lec_mut();
        if lec.valid && incremental {
            let mut lec = std::mem::take(lec);
            self.update_lec(&mut lec, handle);
            *self.lec_mut() = lec;
        } else {
            lec.valid = false;
        }
        Ok(())
    }

    /// Removes `id` and updates the triangulation incrementally (spade's removal, O(d²) for a
    /// site of degree d); returns its point, or `None` if absent. On the sphere, removing the
    /// projection pole re-projects the other sites from a new pole (see the module docs).
    pub fn remove(&mut self, id: u64) -> Option<DVec3> {
        self.lec_mut().valid = false;
        match self.slots.remove(&id)? {
            Slot::Planar(h) => {
                let removed = self.tri.remove(h);
                // spade swap-removes: the last vertex now has the removed vertex's index.
                if h.index() < self.tri.num_vertices() {
                    let moved = self.tri.vertex(h).data().id;
                    self.slots.insert(moved, Slot::Planar(h));
                }
                Some(removed.point)
            }
            Slot::Pole => {
                let old = self.pole.take()?;
                self.rebuild_sphere();
                Some(old.point)
            }
        }
    }

    /// Sphere: picks a new pole among the planar sites and re-projects the rest.
    fn rebuild_sphere(&mut self) {
        let mut sites: Vec<Site> = self.tri.vertices().map(|v| *v.data()).collect();
        self.tri = DelaunayTriangulation::new();
        self.slots.clear();
        self.lec_mut().valid = false;
        let Some(first) = sites.pop() else {
            return;
        };
        let pole = Pole::new(first.id, first.point);
        self.pole = Some(pole);
        self.slots.insert(first.id, Slot::Pole);
        for s in &mut sites {
            s.pos = pole.project(s.point);
        }
        match DelaunayTriangulation::bulk_load(sites.clone()) {
            Ok(t) => self.tri = t,
            Err(_) => {
                for s in sites {
                    // Coordinates are finite and were accepted before; ignore the impossible.
                    let _ = self.tri.insert(s);
                }
            }
        }
        for h in self.tri.fixed_vertices() {
            self.slots
                .insert(self.tri.vertex(h).data().id, Slot::Planar(h));
        }
    }
}
