//! Sampling-point domains of Laine et al. 2007's VPL management (§4.1, Figure 3).
//!
//! A [`SamplingDomain`] holds the sampling points of the current VPLs, each under a caller-given
//! `u64` id (e.g. the VPL's id), together with their Delaunay triangulation, maintained
//! incrementally with [`spade`] (`insert` and `remove` update it; nothing is rebuilt per
//! query), built at once from a list of sites ([`SamplingDomain::from_sites`], a bulk load), or
//! moved to new points ([`SamplingDomain::update_sites`]: what the management does each frame,
//! when every point has moved with the light). Points use
//! the convention of [`gibench_harness::vpl::Vpl::sample`]:
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

use std::collections::HashMap;
use std::f64::consts::PI;
use std::fmt;
use std::sync::Mutex;

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use spade::handles::{
    FixedDirectedEdgeHandle, FixedFaceHandle, FixedUndirectedEdgeHandle, FixedVertexHandle,
    InnerTag, VertexHandle,
};
use spade::{
    DelaunayTriangulation, HasPosition, HintGenerator, Point2, PositionInTriangulation,
    Triangulation,
};

use crate::lec::{Candidate, LecCache};

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

/// The angular distance (radians) on the unit sphere of chordal distance `chord`.
pub fn chord_to_angle(chord: f64) -> f64 {
    2.0 * (0.5 * chord).clamp(-1.0, 1.0).asin()
}

/// A site as stored in spade: its planar position (the disc point, or the stereographic
/// projection of the sphere point), its domain point and its id.
#[derive(Clone, Copy, Debug)]
struct Site {
    pos: Point2<f64>,
    point: DVec3,
    id: u64,
}

impl HasPosition for Site {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.pos
    }
}

/// A hasher for sequential ids (a multiplicative mix; the ids are the caller's, not
/// adversarial): the domain looks ids up several times per site and frame.
#[derive(Clone, Copy, Default)]
struct IdHasher(u64);

impl std::hash::Hasher for IdHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ b as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_u64(&mut self, n: u64) {
        self.0 = (n ^ (n >> 32)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
}

type IdMap<V> = HashMap<u64, V, std::hash::BuildHasherDefault<IdHasher>>;

/// Cells per axis of the location grids: grids over the domain's points ([−1, 1]² or ³)
/// remembering, per cell, the id of the last site inserted there — where spade's point
/// location for the next point in that cell starts (the fine grid's cell, or if it is empty
/// the coarse one's). The sphere's points fill only its surface cells, hence fewer per axis.
const GRIDS: [(usize, usize); 2] = [(8, 4), (2, 2)];

/// Index of point `p`'s cell in grid `level` of [`GRIDS`] (the disc's grids have one layer).
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
enum Slot {
    Planar(FixedVertexHandle),
    Pole,
}

/// The sphere's projection pole: a site kept out of spade, with a right-handed frame
/// (t, b, n = point).
#[derive(Clone, Copy, Debug)]
struct Pole {
    id: u64,
    point: DVec3,
    t: DVec3,
    b: DVec3,
}

impl Pole {
    fn new(id: u64, point: DVec3) -> Self {
        let t = point.any_orthonormal_vector();
        let b = point.cross(t);
        Pole { id, point, t, b }
    }

    /// The stereographic projection from the pole: x ↦ (x·t, −x·b) / (1 − x·n), with
    /// 1 − x·n = |x − n|²/2. The sign flip on the second coordinate makes the map
    /// orientation-consistent: a counter-clockwise planar triangle is counter-clockwise seen
    /// from outside the sphere (near the antipode −n, where x' ≈ (x·t, −x·b)/2, a planar ccw
    /// triangle has (b − a) × (c − a) along −n, the outward normal there).
    fn project(&self, x: DVec3) -> Point2<f64> {
        let denom = 0.5 * (x - self.point).length_squared();
        spade::mitigate_underflow(Point2::new(x.dot(self.t) / denom, -x.dot(self.b) / denom))
    }
}

/// A Delaunay edge as a queue key: its squared length, then its two ids (smaller first), so
/// that equal lengths are ordered by the sites, not by the triangulation's numbering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct EdgeKey {
    /// The squared length's bits (a non-negative float orders as its bits).
    bits: u64,
    ids: [u64; 2],
}

impl EdgeKey {
    fn new(l2: f64, a: u64, b: u64) -> Self {
        EdgeKey {
            bits: l2.to_bits(),
            ids: [a.min(b), a.max(b)],
        }
    }

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

/// A set of sampling points with stable ids in the unit disc or on the unit sphere, and its
/// incrementally maintained Delaunay triangulation (Laine et al. 2007, §4.1). See the module
/// docs for the metric and for how the sphere is triangulated.
pub struct SamplingDomain {
    kind: DomainKind,
    tri: DelaunayTriangulation<Site>,
    slots: IdMap<Slot>,
    /// The location grids (see [`GRIDS`]): per cell the id of a site inserted there, or
    /// `u64::MAX`; entries of removed sites are skipped when read.
    grids: [Vec<u64>; 2],
    /// Sphere only: the projection pole (`None` for the disc and for an empty sphere).
    pole: Option<Pole>,
    /// The largest-empty-circle candidates ([`crate::lec`]), filled by the first query and
    /// updated by insertions.
    lec: Mutex<LecCache>,
}

impl Clone for SamplingDomain {
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
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SamplingDomain")
            .field("kind", &self.kind)
            .field("len", &self.len())
            .finish()
    }
}

/// Signed area of the spherical triangle (a, b, c) of unit vectors (Van Oosterom–Strackee,
/// the stable form of l'Huilier's theorem): positive when counter-clockwise seen from outside.
fn spherical_triangle_area(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let det = a.dot(b.cross(c));
    let den = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    2.0 * det.atan2(den)
}

/// The area of the spherical polygon `ring` (in order around `s`, star-shaped from it): the
/// fan of signed triangles (s, ring[k], ring[k + 1]), |Σ spherical_triangle_area|. Each term is
/// 2 atan2(det, den); when every corner lies within 60° of `s` (s · corner > 1/2, i.e. chord
/// < 1) the polygon lies in a cap of area π, so every term's angle and their sum stay inside
/// (−π/2, π/2) and the sum is the argument of the product of the (den + i det): one atan2 per
/// polygon instead of one per corner. The terms' den ≥ 1.5 there and their modulus is below
/// 4.2, so up to 64 corners the product neither vanishes nor overflows (past about 500 it
/// would); larger rings, or rings reaching farther, sum the terms. One pass: the product is
/// taken from the closing pair (ring[n − 1], ring[0]) on, each corner's s · corner serving
/// both its pairs and the 60° test.
fn spherical_fan_area(s: DVec3, ring: &[DVec3]) -> f64 {
    let n = ring.len();
    if (1..=64).contains(&n) {
        let (mut re, mut im) = (1.0, 0.0);
        let mut near = true;
        let mut a = ring[n - 1];
        let mut sa = s.dot(a);
        for &b in ring {
            let sb = s.dot(b);
            let det = s.dot(a.cross(b));
            let den = 1.0 + sa + a.dot(b) + sb;
            (re, im) = (re * den - im * det, re * det + im * den);
            near &= sb > 0.5;
            (a, sa) = (b, sb);
        }
        if near {
            return (2.0 * atan_right_half(im, re)).abs();
        }
    }
    (0..n)
        .map(|k| spherical_triangle_area(s, ring[k], ring[(k + 1) % n]))
        .sum::<f64>()
        .abs()
}

/// atan2(y, x): in the right half-plane x > 0, where it is atan(t) with t = y / x, and for
/// |t| ≤ 1/16 — a Voronoi cell's fan at a few hundred sites and more, whose angle is half its
/// area — the Taylor series of atan to the t¹³ term (the first omitted one, t¹⁵/15, is below
/// 2⁻⁵⁹ of the result), within about an ulp of libm's at a fraction of its cost; libm's atan2
/// everywhere else.
fn atan_right_half(y: f64, x: f64) -> f64 {
    let t = y / x;
    if !(x > 0.0 && t.abs() <= 1.0 / 16.0) {
        return y.atan2(x);
    }
    let t2 = t * t;
    // 1 − t²/3 + t⁴/5 − … + t¹²/13, by Horner's rule in t².
    let mut p = 1.0 / 13.0;
    for k in (0..6).rev() {
        let c = 1.0 / (2 * k + 1) as f64;
        p = if k % 2 == 0 { c } else { -c } + t2 * p;
    }
    t * p
}

/// Sphere: the circumcentre of the spherical triangle of sites `[a, b, c]`, with its radius and
/// `site` (the index of `a`, where a walk to the circumcentre starts).
fn sphere_triangle_slot([a, b, c]: [DVec3; 3], site: usize) -> Candidate {
    let m = spherical_circumcentre(a, b, c);
    let r = (m - a).length();
    (m != DVec3::ZERO && r.is_finite()).then_some((m, r, site as u32))
}

/// Unit circumcentre of the spherical triangle (a, b, c) (counter-clockwise seen from outside):
/// the outward normal of its plane, i.e. the centre of the circumcap on the empty side.
fn spherical_circumcentre(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    (a.cross(b) + b.cross(c) + c.cross(a)).normalize_or_zero()
}

/// Signed area of the intersection of the unit disc (centred at the origin) with the triangle
/// (0, a, b): positive when (0, a, b) is counter-clockwise. Exact: the segment a→b is split
/// where it crosses the circle; pieces inside contribute triangles, pieces outside the
/// circular sector they subtend.
fn disc_triangle_area(a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let dd = d.length_squared();
    let mut ts = [0.0, 1.0, 1.0, 1.0];
    let mut count = 1;
    if dd > 0.0 {
        // |a + t d|² = 1  ⇔  dd t² + 2 (a·d) t + (|a|² − 1) = 0
        let half_b = a.dot(d);
        let c = a.length_squared() - 1.0;
        let disc = half_b * half_b - dd * c;
        if disc > 0.0 {
            let s = disc.sqrt();
            for t in [(-half_b - s) / dd, (-half_b + s) / dd] {
                if t > 0.0 && t < 1.0 {
                    ts[count] = t;
                    count += 1;
                }
            }
        }
    }
    ts[count] = 1.0;
    let mut area = 0.0;
    for w in ts[..=count].windows(2) {
        let p = a + d * w[0];
        let q = a + d * w[1];
        let mid = a + d * (0.5 * (w[0] + w[1]));
        let cross = p.perp_dot(q);
        if mid.length_squared() <= 1.0 {
            area += 0.5 * cross;
        } else {
            area += 0.5 * cross.atan2(p.dot(q));
        }
    }
    area
}

/// The circumcentre of the planar triangle (a, b, c), `None` if it is degenerate.
fn circumcentre(a: DVec2, b: DVec2, c: DVec2) -> Option<DVec2> {
    let (ba, ca) = (b - a, c - a);
    let d = 2.0 * ba.perp_dot(ca);
    if d == 0.0 {
        return None;
    }
    let (lb, lc) = (ba.length_squared(), ca.length_squared());
    let m = a + DVec2::new(ca.y * lb - ba.y * lc, ba.x * lc - ca.x * lb) / d;
    m.is_finite().then_some(m)
}

/// Clips the convex polygon `poly` by the half-plane {x : (x − m)·d ≤ 0} into `out`.
fn clip_half_plane(poly: &[DVec2], m: DVec2, d: DVec2, out: &mut Vec<DVec2>) {
    out.clear();
    let n = poly.len();
    for i in 0..n {
        let a = poly[i];
        let b = poly[(i + 1) % n];
        let da = (a - m).dot(d);
        let db = (b - m).dot(d);
        if da <= 0.0 {
            out.push(a);
        }
        if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
            let t = da / (da - db);
            out.push(a + (b - a) * t);
        }
    }
}

/// Sites from which per-site passes (the Voronoi areas) run across cores. Below it one thread
/// is faster: measured in the management at 1024 sites on 2 cores (frames alternating between
/// the two ways in one run), handing the pass to the pool cost more than it saved — its
/// workers sleep between a frame's passes, and waking them and the caller costs tens of
/// microseconds.
const PARALLEL_SITES: usize = 4096;

/// How a point enters a domain of `kind` whose sphere pole is `pole`
/// ([`SamplingDomain::insert`]'s rules, shared with [`SamplingDomain::from_sites`]):
/// `Ok(Some((spade position, stored point)))` for a planar site — disc: `point.z` dropped and a
/// point outside the unit disc moved radially onto its circle; sphere: normalised and projected
/// from the pole —, `Ok(None)` for the first sphere point (it becomes the pole, stored
/// normalised: `point / point.length()`), or why it is refused (not finite; on the sphere zero, or
/// the pole's point).
fn stored_site(
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

/// `f(scratch, i)` for every site index `i < n`, in order: across cores (one `init()` scratch
/// per worker) from [`PARALLEL_SITES`] sites on, on the calling thread below.
fn map_sites<T: Send, S>(
    n: usize,
    init: impl Fn() -> S + Sync + Send,
    f: impl Fn(&mut S, usize) -> T + Sync + Send,
) -> Vec<T> {
    if n >= PARALLEL_SITES {
        (0..n).into_par_iter().map_init(init, f).collect()
    } else {
        let mut scratch = init();
        (0..n).map(|i| f(&mut scratch, i)).collect()
    }
}

/// Buffers for [`SamplingDomain::disc_cell`], one set per worker.
#[derive(Default)]
struct DiscCellScratch {
    poly: Vec<DVec2>,
    tmp: Vec<DVec2>,
}

/// Half the side of the square the disc's Voronoi cells are first clipped to (it contains the
/// unit disc with margin, so the clipped cells ∩ disc are exact).
const BOX: f64 = 2.0;

/// Relative tolerance of the "antipodal boundary point lies in the cell" test (§4.6 case 3).
const CELL_EPS: f64 = 1e-12;

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

    /// The domain's kind.
    pub fn kind(&self) -> DomainKind {
        self.kind
    }

    /// The number of sampling points.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Whether the domain holds no sampling point.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Whether `id` is in the domain.
    pub fn contains(&self, id: u64) -> bool {
        self.slots.contains_key(&id)
    }

    /// The stored point of `id` (after the normalisation [`insert`](Self::insert) applies).
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
    pub fn site_index(&self, id: u64) -> Option<usize> {
        self.index_of(id)
    }

    /// All `(id, point)` pairs, in the domain's internal order (see [`site_index`]).
    ///
    /// [`site_index`]: Self::site_index
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

    /// Adds the sampling point `point` under `id` and updates the Delaunay triangulation
    /// incrementally (§4.6: "we add it to the distribution and update the Delaunay
    /// triangulation"). Disc: `point.z` is ignored and a point outside the unit disc is moved
    /// radially onto its circle. Sphere: `point` is normalised. Fails, leaving the domain
    /// unchanged, on a repeated id, a non-finite (or, on the sphere, zero) point, or a point
    /// equal to an existing one (on the sphere: within 10⁻¹² of the pole site, or projecting
    /// onto an existing projected point).
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
    fn insert_site(&mut self, site: Site, near: Option<u64>) -> Result<(), DomainError> {
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

    /// The largest-empty-circle cache (a poisoned lock only means a panic elsewhere mid-query;
    /// the cache is then recomputed).
    fn lec_cache(&self) -> std::sync::MutexGuard<'_, LecCache> {
        self.lec.lock().unwrap_or_else(|e| {
            let mut guard = e.into_inner();
            guard.valid = false;
            guard
        })
    }

    fn lec_mut(&mut self) -> &mut LecCache {
        match self.lec.get_mut() {
            Ok(lec) => lec,
            Err(e) => {
                let lec = e.into_inner();
                lec.valid = false;
                lec
            }
        }
    }

    /// The number of sites, with the sphere's pole at index `tri.num_vertices()`.
    fn pole_index(&self) -> usize {
        self.tri.num_vertices()
    }

    fn site_point(&self, index: usize) -> DVec3 {
        if index < self.tri.num_vertices() {
            self.tri
                .vertex(FixedVertexHandle::from_index(index))
                .data()
                .point
        } else {
            self.pole.map_or(DVec3::ZERO, |p| p.point)
        }
    }

    fn site_id(&self, index: usize) -> u64 {
        if index < self.tri.num_vertices() {
            self.tri
                .vertex(FixedVertexHandle::from_index(index))
                .data()
                .id
        } else {
            self.pole.map_or(u64::MAX, |p| p.id)
        }
    }

    fn index_of(&self, id: u64) -> Option<usize> {
        match *self.slots.get(&id)? {
            Slot::Planar(h) => Some(h.index()),
            Slot::Pole => Some(self.pole_index()),
        }
    }

    /// Delaunay neighbours of site `index` (internal indices; the sphere's pole included).
    fn neighbours(&self, index: usize, out: &mut Vec<usize>) {
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

    fn triangle_indices(&self) -> Vec<[u32; 3]> {
        self.triangles_and_wraps().0
    }

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
    pub fn largest_empty_circle_by_scan(&self) -> Option<(DVec3, f64)> {
        match self.kind {
            DomainKind::Disc => self.disc_largest_empty_circle(),
            DomainKind::Sphere => self.sphere_largest_empty_circle(),
        }
    }

    /// Disc: inner face `f`'s corners, counter-clockwise, and the index of the first.
    fn disc_face_corners(&self, f: FixedFaceHandle<InnerTag>) -> ([DVec2; 3], usize) {
        let [a, b, c] = self.tri.face(f).vertices();
        (
            [a, b, c].map(|v| v.data().point.truncate()),
            a.fix().index(),
        )
    }

    /// Disc: inner face `f`'s circumcentre and its case (1) slot (the circumcentre, if inside
    /// the disc), from one walk round the face.
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
    fn update_lec(&self, lec: &mut LecCache, v: FixedVertexHandle) {
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

    /// The dispersion δ (§4.3, Eq. 1): the radius of the [largest empty
    /// circle](Self::largest_empty_circle) (chordal on the sphere).
    pub fn dispersion(&self) -> f64 {
        self.largest_empty_circle().map_or(0.0, |(_, r)| r)
    }

    /// The area of disc site `v`'s Voronoi region when it lies inside the unit disc: the
    /// polygon of the circumcentres (`centres`, per face index) of the faces around `v`, each
    /// in the disc (the region is convex, so then all of it is). `None` for a site on the
    /// triangulation's hull (an unbounded region) or one whose region reaches the rim.
    fn disc_inner_cell_area(&self, v: FixedVertexHandle, centres: &[Option<DVec2>]) -> Option<f64> {
        let mut first = None;
        let mut prev = DVec2::ZERO;
        let mut twice = 0.0;
        for e in self.tri.vertex(v).out_edges() {
            let face = e.face();
            face.as_inner()?;
            let c = centres[face.fix().index()]?;
            if c.length_squared() > 1.0 {
                return None;
            }
            match first {
                None => first = Some(c),
                Some(_) => twice += prev.perp_dot(c),
            }
            prev = c;
        }
        twice += prev.perp_dot(first?);
        Some(0.5 * twice.abs())
    }

    /// The Voronoi region of disc site `v` ∩ the square [−2, 2]², counter-clockwise: the
    /// square clipped by the bisector of each Delaunay neighbour in turn.
    fn disc_cell<'s>(&self, v: FixedVertexHandle, scratch: &'s mut DiscCellScratch) -> &'s [DVec2] {
        let v = self.tri.vertex(v);
        let p = v.data().point.truncate();
        let DiscCellScratch { poly, tmp } = scratch;
        poly.clear();
        poly.extend_from_slice(&[
            DVec2::new(-BOX, -BOX),
            DVec2::new(BOX, -BOX),
            DVec2::new(BOX, BOX),
            DVec2::new(-BOX, BOX),
        ]);
        for e in v.out_edges() {
            let q = e.to().data().point.truncate();
            clip_half_plane(poly, 0.5 * (p + q), q - p, tmp);
            std::mem::swap(poly, tmp);
        }
        poly
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

    /// The shortest Delaunay edge (§4.5) as `(id, id, length)`; `None` with fewer than two
    /// sites.
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
    pub fn second_closest_neighbour_distance(&self, id: u64) -> Option<f64> {
        let i = self.index_of(id)?;
        Some(self.second_closest_distance(i, &mut Vec::new()))
    }

    /// The site §4.5 deletes next: of the two endpoints of the [shortest Delaunay
    /// edge](Self::shortest_edge), "the vertex that has smaller distance to second-closest
    /// neighbor" (second-closest among its Delaunay neighbours, as the paper examines "the
    /// neighbors of the two vertices"). Ties (e.g. two sites) delete the larger id. `None` with
    /// fewer than two sites.
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
    fn edge_keys_of(&self, index: usize, nb: &mut Vec<usize>, mut f: impl FnMut(EdgeKey)) {
        self.neighbours(index, nb);
        let (p, id) = (self.site_point(index), self.site_id(index));
        for &n in nb.iter() {
            let l2 = (self.site_point(n) - p).length_squared();
            f(EdgeKey::new(l2, id, self.site_id(n)));
        }
    }

    /// Pushes the edges of site `index` onto `q`.
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

    /// The area of every site's Voronoi region (§4.7, after Yakowitz et al.), to which the
    /// paper sets the VPL intensities before scaling them to the light's power.
    ///
    /// * Disc: the region clipped to the unit disc; the areas sum to π. Exact up to rounding:
    ///   a site off the hull whose faces' circumcentres all lie in the disc has the polygon of
    ///   those circumcentres as its cell (shoelace area); any other cell is the square
    ///   [−2, 2]² clipped by the bisectors of the site's Delaunay neighbours, its intersection
    ///   with the disc summed analytically over its edges (triangle (0, a, b) ∩ disc: triangle
    ///   pieces inside, circular sectors outside).
    /// * Sphere: the spherical area on the unit sphere; the areas sum to 4π. Each cell is the
    ///   spherical polygon of the circumcentres of the site's triangles in order, summed as a
    ///   fan of signed spherical triangles from the site (Van Oosterom–Strackee / l'Huilier);
    ///   the cell is an intersection of hemispheres containing its site, hence star-shaped from
    ///   it, and for sites not all on one plane its Voronoi edges are shorter than π. Sites all
    ///   on one plane (always the case for three) have lune-shaped cells between the bisectors
    ///   of their neighbours along the common circle: area = 2 × the lune's dihedral angle.
    ///
    /// In the sites' internal order: the entry of site `id` is at [`site_index`]`(id)`.
    ///
    /// [`site_index`]: Self::site_index
    pub fn voronoi_areas(&self) -> Vec<(u64, f64)> {
        match self.kind {
            // One cell per site, in site order: from the circumcentres of its faces where the
            // cell lies inside the disc, by clipping otherwise.
            DomainKind::Disc => {
                // The circumcentres the largest-empty-circle candidates keep (the same
                // function's values), or computed here.
                let lec = self.lec_cache();
                let computed: Vec<Option<DVec2>>;
                let centres = if lec.valid && lec.centres.len() == self.tri.num_all_faces() {
                    &lec.centres[..]
                } else {
                    computed = (self.tri.all_faces())
                        .map(|f| {
                            let [a, b, c] = self.disc_face_corners(f.as_inner()?.fix()).0;
                            circumcentre(a, b, c)
                        })
                        .collect();
                    &computed[..]
                };
                map_sites(
                    self.tri.num_vertices(),
                    DiscCellScratch::default,
                    |scratch, i| {
                        let v = FixedVertexHandle::from_index(i);
                        if let Some(area) = self.disc_inner_cell_area(v, centres) {
                            return (self.site_id(i), area);
                        }
                        let poly = self.disc_cell(v, scratch);
                        let n = poly.len();
                        let area: f64 = (0..n)
                            .map(|k| disc_triangle_area(poly[k], poly[(k + 1) % n]))
                            .sum();
                        (self.site_id(i), area)
                    },
                )
            }
            DomainKind::Sphere => self.sphere_voronoi_areas(),
        }
    }

    fn sphere_voronoi_areas(&self) -> Vec<(u64, f64)> {
        let n = self.len();
        if n < 3 {
            let pts = self.points();
            return match n {
                0 => Vec::new(),
                1 => vec![(pts[0].0, 4.0 * PI)],
                _ => vec![(pts[0].0, 2.0 * PI), (pts[1].0, 2.0 * PI)],
            };
        }
        // Coplanar sites (all on one circle): lunes.
        let [a, b, c] = [0, 1, 2].map(|i| self.site_point(i));
        let m = spherical_circumcentre(a, b, c);
        if m != DVec3::ZERO && (0..n).all(|i| m.dot(self.site_point(i) - a).abs() <= 1e-10) {
            return lune_areas(&self.points(), m);
        }
        // The circumcentres of the triangles around each site: those the largest-empty-circle
        // candidates keep (the same function's values: `sphere_triangle_slot`), or computed.
        let lec = self.lec_cache();
        let kept = lec.valid
            && lec.faces.len() == self.tri.num_all_faces()
            && lec.wraps.len() == self.tri.num_directed_edges();
        let lec = &*lec;
        let face_centre = |f: FixedFaceHandle<InnerTag>| {
            if kept {
                return lec.faces.centre(f.index());
            }
            let [a, b, c] = self.tri.face(f).vertices().map(|v| v.data().point);
            spherical_circumcentre(a, b, c)
        };
        // The wrap-around triangle (from, to, pole) of outer edge `e`.
        let wrap_centre = |e: FixedDirectedEdgeHandle| {
            if kept {
                return lec.wraps.centre(e.index());
            }
            let e = self.tri.directed_edge(e);
            let [a, b] = [e.from(), e.to()].map(|v| v.data().point);
            spherical_circumcentre(a, b, self.site_point(self.pole_index()))
        };
        // One cell per planar site, in site order; then the pole's.
        let mut out: Vec<(u64, f64)> = map_sites(
            self.tri.num_vertices(),
            || Vec::with_capacity(16),
            |ring: &mut Vec<DVec3>, i| {
                let v = self.tri.vertex(FixedVertexHandle::from_index(i));
                ring.clear();
                for e in v.out_edges() {
                    match e.face().as_inner() {
                        Some(f) => ring.push(face_centre(f.fix())),
                        None => {
                            ring.push(wrap_centre(e.fix()));
                            ring.push(wrap_centre(e.prev().fix()));
                        }
                    }
                }
                (v.data().id, spherical_fan_area(v.data().point, ring))
            },
        );
        if let Some(pole) = self.pole {
            let ring: Vec<DVec3> = (self.tri.convex_hull())
                .map(|e| wrap_centre(e.fix()))
                .collect();
            out.push((pole.id, spherical_fan_area(pole.point, &ring)));
        }
        out
    }
}

/// Voronoi areas of sites all on one circle with axis `m`: lunes between the bisectors of
/// consecutive sites around the axis; area = 2 × dihedral angle. In the order of `pts`.
fn lune_areas(pts: &[(u64, DVec3)], m: DVec3) -> Vec<(u64, f64)> {
    let u = m.any_orthonormal_vector();
    let w = m.cross(u);
    let mut angles: Vec<(f64, usize)> = pts
        .iter()
        .enumerate()
        .map(|(k, &(_, x))| (x.dot(w).atan2(x.dot(u)), k))
        .collect();
    angles.sort_by(|a, b| a.0.total_cmp(&b.0));
    let n = angles.len();
    let gap = |i: usize| {
        let (a, b) = (angles[i].0, angles[(i + 1) % n].0);
        let g = b - a;
        if g <= 0.0 {
            g + 2.0 * PI
        } else {
            g
        }
    };
    let mut out: Vec<(u64, f64)> = pts.iter().map(|&(id, _)| (id, 0.0)).collect();
    for i in 0..n {
        out[angles[i].1].1 = gap(i) + gap((i + n - 1) % n);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The series agrees with libm's atan2 to within an ulp across its range (and is libm's
    /// beyond it), for both signs of x and y and across magnitudes of x.
    #[test]
    fn atan_right_half_matches_libm() {
        for x in [1e-3, 0.5, 1.0, 3.0, 1e6, -1.0, -1e-3] {
            for k in -2000..=2000 {
                let t = k as f64 / 2000.0 * 0.07;
                let y = t * x;
                let (got, want) = (atan_right_half(y, x), y.atan2(x));
                assert!(
                    (got - want).abs() <= f64::EPSILON * want.abs(),
                    "atan2({y}, {x}): {got} vs {want}"
                );
            }
        }
    }
}
