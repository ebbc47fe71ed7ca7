//! Plane geometry of the disc: circumcentres, half-plane clipping and the area of a triangle
//! fan cut by the unit circle.

use glam::DVec2;

/// Signed area of the intersection of the unit disc (centred at the origin) with the triangle
/// (0, a, b): positive when (0, a, b) is counter-clockwise. Exact: the segment a→b is split
/// where it crosses the circle; pieces inside contribute triangles, pieces outside the
/// circular sector they subtend.
#[inline]
pub(super) fn disc_triangle_area(a: DVec2, b: DVec2) -> f64 {
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
#[inline]
pub(super) fn circumcentre(a: DVec2, b: DVec2, c: DVec2) -> Option<DVec2> {
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
#[inline]
pub(super) fn clip_half_plane(poly: &[DVec2], m: DVec2, d: DVec2, out: &mut Vec<DVec2>) {
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
