//! Sampling-point domains of Laine et al. 2007's VPL management (§4.1, Figure 3).
//!
//! A [`SamplingDomain`] holds the sampling points of the current VPLs, each under a caller-given
//! `u64` id (e.g. the VPL's id), together with their Delaunay triangulation, maintained
//! incrementally with [`spade`] (`insert` and `remove` update it; nothing is rebuilt per
//! query), built at once from a list of sites ([`SamplingDomain::from_sites`], a bulk load), or
//! moved to new points ([`SamplingDomain::update_sites`]: what the management does each frame,
//! when every point has moved with the light). Points use
//! the convention of [`gibench_harness::cpu::vpl::Vpl::sample`]:
//!
//! * [`DomainKind::Disc`] (spot lights, Figure 3a/b): `(x, y, 0)` on the unit disc;
//! * [`DomainKind::Sphere`] (omni lights, Figure 3c): a unit direction.
//!
//! ## Metric
//!
//! Every distance (edge lengths, empty-circle radii, second-closest-neighbour distances) is the
//! Euclidean distance in the embedding space: in ℝ² for the disc and the *chordal* distance in
//! ℝ³ for the sphere, as the paper allows in §4.3 ("we may equally well use Euclidean distance
//! in ℝ³"). Chordal distance c and angular distance θ are related monotonically by
//! c = 2 sin(θ/2), so every arg-min/arg-max (largest empty circle, shortest edge, deletion
//! candidate) is the same in either metric; convert a sphere radius with
//! [`chord_to_angle`].
//!
//! ## The sphere without a tetrahedralisation
//!
//! The paper builds the spherical Delaunay triangulation from a 3D tetrahedralisation, its
//! bottleneck (§6: "the tetrahedralization should be replaced with a triangulation on the
//! surface of the sphere"). Here one of the sites, the *pole* N, is kept outside spade and all
//! the others are mapped into the plane by the stereographic projection from N. The spherical
//! Delaunay triangulation (= the convex hull of the points) is then exactly
//!
//! * the planar Delaunay triangles of the projected points (spade's inner faces), plus
//! * one *wrap-around* triangle (a, b, N) for every convex-hull edge a→b of the projection.
//!
//! Why: the stereographic projection from N maps circles on the sphere not through N to circles
//! in the plane and circles through N to lines; the open cap bounded by a circle not through N
//! that does *not* contain N maps to the inside of the image circle. A spherical triangle
//! (a, b, c) not incident to N is Delaunay iff one of the two caps of its circumcircle is empty
//! of sites; N is a site, so that cap does not contain N, so it maps to the inside of the planar
//! circumcircle of a', b', c', which is therefore empty: (a', b', c') is planar Delaunay, and
//! conversely. A triangle (a, b, N) is Delaunay iff some circle through a, b and N bounds an
//! empty cap; its image is a line through a' and b' with every projected site on one side, i.e.
//! a'b' is a convex-hull edge. The projection is orientation-consistent (see `project`), so
//! spade's counter-clockwise faces are counter-clockwise seen from outside the sphere. This is
//! exact in exact arithmetic and needs no "pole region" heuristics: N is a site, so no
//! triangle's circumcap can contain it unnoticed. Points very close to N project far out
//! (|x'| ≈ 2/|x − N|), which spade's robust predicates handle; 1 − x·N is computed as
//! |x − N|²/2 to avoid cancellation. Removing the pole site re-projects the remaining points
//! from another site and bulk-loads them into a new triangulation (O(n log n), ~0.15 ms for
//! 256 and ~0.6 ms for 1024 points): the only non-incremental update, hit with probability
//! 1/n per removal.
//!
//! Costs for n sites: the largest empty circle is kept between queries (the crate's `lec`
//! module): O(n) after a removal, O(d log n) after inserting a site of degree d, O(1)
//! otherwise; the
//! shortest edge and the Voronoi areas are one pass (a run of deletions shares one pass:
//! [`SamplingDomain::redundancy_queue`]; the areas across cores from 4096 sites); moving every
//! site is one pass plus O(d²) per site whose motion broke the triangulation. Point location
//! starts from a coarse grid of recently inserted sites.

// One file per job; each adds its part of `impl SamplingDomain`.
mod access;
mod empty_circle;
mod motion;
mod plane;
mod redundancy;
mod sites;
mod sphere;
mod voronoi;

pub use motion::SiteUpdate;
pub use redundancy::RedundancyQueue;
pub use sphere::chord_to_angle;

use std::fmt;
use std::sync::Mutex;

use spade::DelaunayTriangulation;

use crate::lec::LecCache;
use sites::{IdMap, Site, Slot};
use sphere::Pole;

/// Which 2D domain the sampling points live in (Laine et al. 2007, §4.1, Figure 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DomainKind {
    /// The unit disc: 180° cosine spot lights, via the Nusselt analog (Figure 3a/b).
    Disc,
    /// The unit sphere: omnidirectional point lights (Figure 3c).
    Sphere,
}

/// Why [`SamplingDomain::insert`] refused a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DomainError {
    /// The id is already in the domain.
    DuplicateId(u64),
    /// The point coincides with the point of the site with this id.
    DuplicatePoint(u64),
    /// The point is not finite, or (sphere) zero.
    InvalidPoint,
}

impl fmt::Display for DomainError {
    #[inline]
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DomainError::DuplicateId(id) => write!(f, "sampling point id {id} already present"),
            DomainError::DuplicatePoint(id) => {
                write!(f, "sampling point coincides with the point of id {id}")
            }
            DomainError::InvalidPoint => write!(f, "sampling point is not finite (or zero)"),
        }
    }
}

impl std::error::Error for DomainError {}

/// A set of sampling points with stable ids in the unit disc or on the unit sphere, and its
/// incrementally maintained Delaunay triangulation (Laine et al. 2007, §4.1). See the module
/// docs for the metric and for how the sphere is triangulated.
pub struct SamplingDomain {
    kind: DomainKind,
    tri: DelaunayTriangulation<Site>,
    slots: IdMap<Slot>,
    /// The location grids (see [`GRIDS`](sites::GRIDS)): per cell the id of a site inserted there, or
    /// `u64::MAX`; entries of removed sites are skipped when read.
    grids: [Vec<u64>; 2],
    /// Sphere only: the projection pole (`None` for the disc and for an empty sphere).
    pole: Option<Pole>,
    /// The largest-empty-circle candidates ([`crate::lec`]), filled by the first query and
    /// updated by insertions.
    lec: Mutex<LecCache>,
}

impl Clone for SamplingDomain {
    #[inline]
    fn clone(&self) -> Self {
        SamplingDomain {
            kind: self.kind,
            tri: self.tri.clone(),
            slots: self.slots.clone(),
            grids: self.grids.clone(),
            pole: self.pole,
            lec: Mutex::new(self.lec_cache().clone()),
        }
    }
}

impl fmt::Debug for SamplingDomain {
    #[inline]
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SamplingDomain")
            .field("kind", &self.kind)
            .field("len", &self.len())
            .finish()
    }
}
