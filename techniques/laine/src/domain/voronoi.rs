//! Voronoi areas (§4.7): each site's region clipped to the disc, or its spherical cell, the
//! per-site pass run across cores for large domains.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use spade::handles::{FixedDirectedEdgeHandle, FixedFaceHandle, FixedVertexHandle, InnerTag};
use spade::Triangulation;

use super::plane::{circumcentre, clip_half_plane, disc_triangle_area};
use super::sphere::{lune_areas, spherical_circumcentre, spherical_fan_area};
use super::{DomainKind, SamplingDomain};

/// Sites from which per-site passes (the Voronoi areas) run across cores. Below it one thread
/// is faster: measured in the management at 1024 sites on 2 cores (frames alternating between
/// the two ways in one run), handing the pass to the pool cost more than it saved — its
/// workers sleep between a frame's passes, and waking them and the caller costs tens of
/// microseconds.
const PARALLEL_SITES: usize = 4096;

/// `f(scratch, i)` for every site index `i < n`, in order: across cores (one `init()` scratch
/// per worker) from [`PARALLEL_SITES`] sites on, on the calling thread below.
#[inline]
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

impl SamplingDomain {
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
}
