//! Sphere geometry: the stereographic projection pole, spherical triangle and polygon areas,
//! circumcentres, the lunes of sites on one circle, and chordal to angular distance.

use std::f64::consts::PI;

use glam::DVec3;
use spade::Point2;

use crate::lec::Candidate;

/// The angular distance (radians) on the unit sphere of chordal distance `chord`.
#[inline]
pub fn chord_to_angle(chord: f64) -> f64 {
    2.0 * (0.5 * chord).clamp(-1.0, 1.0).asin()
}

/// The sphere's projection pole: a site kept out of spade, with a right-handed frame
/// (t, b, n = point).
#[derive(Clone, Copy, Debug)]
pub(super) struct Pole {
    pub(super) id: u64,
    pub(super) point: DVec3,
    t: DVec3,
    b: DVec3,
}

impl Pole {
    #[inline]
    pub(super) fn new(id: u64, point: DVec3) -> Self {
        let t = point.any_orthonormal_vector();
        let b = point.cross(t);
        Pole { id, point, t, b }
    }

    /// The stereographic projection from the pole: x ↦ (x·t, −x·b) / (1 − x·n), with
    /// 1 − x·n = |x − n|²/2. The sign flip on the second coordinate makes the map
    /// orientation-consistent: a counter-clockwise planar triangle is counter-clockwise seen
    /// from outside the sphere (near the antipode −n, where x' ≈ (x·t, −x·b)/2, a planar ccw
    /// triangle has (b − a) × (c − a) along −n, the outward normal there).
    #[inline]
    pub(super) fn project(&self, x: DVec3) -> Point2<f64> {
        let denom = 0.5 * (x - self.point).length_squared();
        spade::mitigate_underflow(Point2::new(x.dot(self.t) / denom, -x.dot(self.b) / denom))
    }
}

/// Signed area of the spherical triangle (a, b, c) of unit vectors (Van Oosterom–Strackee,
/// the stable form of l'Huilier's theorem): positive when counter-clockwise seen from outside.
#[inline]
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
pub(super) fn spherical_fan_area(s: DVec3, ring: &[DVec3]) -> f64 {
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
#[inline]
pub(super) fn sphere_triangle_slot([a, b, c]: [DVec3; 3], site: usize) -> Candidate {
    let m = spherical_circumcentre(a, b, c);
    let r = (m - a).length();
    (m != DVec3::ZERO && r.is_finite()).then_some((m, r, site as u32))
}

/// Unit circumcentre of the spherical triangle (a, b, c) (counter-clockwise seen from outside):
/// the outward normal of its plane, i.e. the centre of the circumcap on the empty side.
#[inline]
pub(super) fn spherical_circumcentre(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    (a.cross(b) + b.cross(c) + c.cross(a)).normalize_or_zero()
}

/// Voronoi areas of sites all on one circle with axis `m`: lunes between the bisectors of
/// consecutive sites around the axis; area = 2 × dihedral angle. In the order of `pts`.
pub(super) fn lune_areas(pts: &[(u64, DVec3)], m: DVec3) -> Vec<(u64, f64)> {
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
