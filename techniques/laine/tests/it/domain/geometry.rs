//! The domain's geometry against brute force — empty circumcircles, the largest empty
//! circle, Voronoi areas — through inserts and removals, small and degenerate sets and
//! refused points.

use std::f64::consts::PI;

use gibench_harness::rng::SplitMix64 as Rng;
use gibench_laine::domain::{DomainKind, SamplingDomain};
use glam::{DVec2, DVec3};

use super::{build, point_set};

const SIZES: [usize; 3] = [16, 256, 1024];

fn nearest_distance(pts: &[DVec3], x: DVec3) -> f64 {
    pts.iter()
        .map(|p| (*p - x).length_squared())
        .fold(f64::INFINITY, f64::min)
        .sqrt()
}

fn all_cases() -> Vec<(DomainKind, usize, bool)> {
    let mut cases = Vec::new();
    for kind in [DomainKind::Disc, DomainKind::Sphere] {
        for n in SIZES {
            for random in [false, true] {
                cases.push((kind, n, random));
            }
        }
    }
    cases
}

/// Every Delaunay triangle's circumcircle (disc) / circumcap on the empty side (sphere) holds
/// no other site.
fn check_empty_circumcircles(d: &SamplingDomain) {
    let pts = d.points();
    let get = |id: u64| d.point(id).unwrap();
    let tris = d.triangles();
    match d.kind() {
        DomainKind::Disc => {
            // Euler: a planar triangulation of n points with h on the hull has 2n − 2 − h
            // triangles.
            for t in &tris {
                let [a, b, c] = t.map(|id| get(id).truncate());
                let area2 = (b - a).perp_dot(c - a);
                assert!(area2 > 0.0, "triangle {t:?} not counter-clockwise");
                let (ba, ca) = (b - a, c - a);
                let dd = 2.0 * ba.perp_dot(ca);
                let cx = (ca.y * ba.length_squared() - ba.y * ca.length_squared()) / dd;
                let cy = (ba.x * ca.length_squared() - ca.x * ba.length_squared()) / dd;
                let centre = a + DVec2::new(cx, cy);
                let r = (a - centre).length();
                for &(id, p) in &pts {
                    if t.contains(&id) {
                        continue;
                    }
                    let dist = (p.truncate() - centre).length();
                    assert!(
                        dist >= r * (1.0 - 1e-9) - 1e-12,
                        "site {id} inside circumcircle of {t:?}: {dist} < {r}"
                    );
                }
            }
        }
        DomainKind::Sphere => {
            // A triangulation of the sphere: 2n − 4 triangles.
            if pts.len() >= 3 {
                assert_eq!(tris.len(), 2 * pts.len() - 4, "Euler characteristic");
            }
            for t in &tris {
                let [a, b, c] = t.map(get);
                let m = (b - a).cross(c - a).normalize();
                let h = m.dot(a);
                for &(id, p) in &pts {
                    if t.contains(&id) {
                        continue;
                    }
                    assert!(
                        m.dot(p) <= h + 1e-12,
                        "site {id} beyond the plane of {t:?} (cap not empty or orientation wrong)"
                    );
                }
                // Seen from the circumcentre m, the vertices are equidistant and nearest.
                let r = (m - a).length();
                assert!(
                    nearest_distance(&pts.iter().map(|p| p.1).collect::<Vec<_>>(), m) >= r - 1e-9
                );
            }
        }
    }
}

/// The largest empty circle agrees with a brute-force search over a fine sampling of the
/// domain.
fn check_largest_empty_circle(d: &SamplingDomain) {
    let pts: Vec<DVec3> = d.points().into_iter().map(|p| p.1).collect();
    let (centre, radius) = d.largest_empty_circle().unwrap();
    assert_eq!(d.dispersion(), radius);
    assert!(
        (nearest_distance(&pts, centre) - radius).abs() < 1e-9,
        "radius is not the distance to the nearest site"
    );
    let (brute, tol) = match d.kind() {
        DomainKind::Disc => {
            assert!(centre.truncate().length() <= 1.0 + 1e-12 && centre.z == 0.0);
            let g = 400;
            let mut best = 0.0f64;
            for i in 0..g {
                for j in 0..g {
                    let x = DVec3::new(
                        -1.0 + 2.0 * (i as f64 + 0.5) / g as f64,
                        -1.0 + 2.0 * (j as f64 + 0.5) / g as f64,
                        0.0,
                    );
                    if x.truncate().length_squared() <= 1.0 {
                        best = best.max(nearest_distance(&pts, x));
                    }
                }
            }
            for k in 0..4096 {
                let phi = 2.0 * PI * k as f64 / 4096.0;
                let x = DVec3::new(phi.cos(), phi.sin(), 0.0);
                best = best.max(nearest_distance(&pts, x));
            }
            // Any point of the disc is within half a grid diagonal of a sample.
            (best, 2.0 / g as f64)
        }
        DomainKind::Sphere => {
            assert!((centre.length() - 1.0).abs() < 1e-12);
            let n = 200_000;
            let golden = PI * (3.0 - 5f64.sqrt());
            let mut best = 0.0f64;
            for k in 0..n {
                let z = 1.0 - (2.0 * k as f64 + 1.0) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let phi = golden * k as f64;
                let x = DVec3::new(r * phi.cos(), r * phi.sin(), z);
                best = best.max(nearest_distance(&pts, x));
            }
            (best, 0.01)
        }
    };
    assert!(
        brute <= radius + 1e-9,
        "a sampled point is farther from all sites ({brute}) than the largest empty circle ({radius})"
    );
    assert!(
        radius <= brute + tol,
        "largest empty circle {radius} exceeds brute force {brute} + {tol}"
    );
}

fn check_voronoi_areas(d: &SamplingDomain) {
    let areas = d.voronoi_areas();
    assert_eq!(areas.len(), d.len());
    let mut ids: Vec<u64> = areas.iter().map(|a| a.0).collect();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), d.len());
    let total: f64 = areas.iter().map(|a| a.1).sum();
    let expected = match d.kind() {
        DomainKind::Disc => PI,
        DomainKind::Sphere => 4.0 * PI,
    };
    assert!(
        ((total - expected) / expected).abs() < 1e-9,
        "Voronoi areas sum to {total}, expected {expected}"
    );
    for (k, &(id, a)) in areas.iter().enumerate() {
        assert!(a > 0.0 && a.is_finite(), "area of {id} = {a}");
        // The management reads a site's area at its index.
        assert_eq!(d.site_index(id), Some(k), "area of {id} listed at {k}");
    }
}

fn check_all(d: &SamplingDomain) {
    check_empty_circumcircles(d);
    check_largest_empty_circle(d);
    check_voronoi_areas(d);
}

#[test]
fn delaunay_circumcircles_are_empty() {
    for (kind, n, random) in all_cases() {
        let d = build(kind, &point_set(kind, n, random));
        check_empty_circumcircles(&d);
    }
}

#[test]
fn largest_empty_circle_matches_brute_force() {
    for (kind, n, random) in all_cases() {
        let d = build(kind, &point_set(kind, n, random));
        check_largest_empty_circle(&d);
    }
}

#[test]
fn voronoi_areas_partition_the_domain() {
    for (kind, n, random) in all_cases() {
        let d = build(kind, &point_set(kind, n, random));
        check_voronoi_areas(&d);
    }
}

/// Each site's Voronoi area (§4.7's intensity share) against a dense count of the domain's
/// points nearest to it: a stratified grid over the disc, a Fibonacci lattice over the sphere.
/// Every cell agrees within 5 % of the mean cell area (the counting's own error is about 1 %).
#[test]
fn voronoi_areas_match_nearest_site_counts() {
    for kind in [DomainKind::Disc, DomainKind::Sphere] {
        let n = 64;
        let pts = point_set(kind, n, true);
        let d = build(kind, &pts);
        let areas: std::collections::HashMap<u64, f64> = d.voronoi_areas().into_iter().collect();
        let mut counts = vec![0usize; n];
        let mut nearest = |x: DVec3| {
            let i = (0..n)
                .min_by(|&a, &b| {
                    (pts[a] - x)
                        .length_squared()
                        .total_cmp(&(pts[b] - x).length_squared())
                })
                .unwrap();
            counts[i] += 1;
        };
        let sample_area = match kind {
            DomainKind::Disc => {
                let g = 900;
                let h = 2.0 / g as f64;
                for y in 0..g {
                    for x in 0..g {
                        let p = DVec3::new(
                            -1.0 + (x as f64 + 0.5) * h,
                            -1.0 + (y as f64 + 0.5) * h,
                            0.0,
                        );
                        if p.length_squared() <= 1.0 {
                            nearest(p);
                        }
                    }
                }
                h * h
            }
            DomainKind::Sphere => {
                let m = 600_000;
                let golden = PI * (3.0 - 5f64.sqrt());
                for k in 0..m {
                    let z = 1.0 - (2.0 * k as f64 + 1.0) / m as f64;
                    let r = (1.0 - z * z).sqrt();
                    let phi = golden * k as f64;
                    nearest(DVec3::new(r * phi.cos(), r * phi.sin(), z));
                }
                4.0 * PI / m as f64
            }
        };
        let mean = match kind {
            DomainKind::Disc => PI,
            DomainKind::Sphere => 4.0 * PI,
        } / n as f64;
        for i in 0..n {
            let counted = counts[i] as f64 * sample_area;
            let a = areas[&(i as u64 * 7 + 3)];
            assert!(
                (a - counted).abs() < 0.05 * mean,
                "{kind:?} site {i}: Voronoi area {a:.5} vs {counted:.5} counted (mean {mean:.5})"
            );
        }
    }
}

#[test]
fn insert_and_remove_keep_everything_consistent() {
    for (kind, n, random) in all_cases() {
        let pts = point_set(kind, n, random);
        let mut d = build(kind, &pts);
        let ids: Vec<u64> = (0..n as u64).map(|i| i * 7 + 3).collect();
        // Remove every other point, in a scrambled order, and the first inserted (the sphere's
        // projection pole) among them.
        let mut removed = Vec::new();
        for (k, &id) in ids.iter().enumerate() {
            if k % 2 == 0 {
                removed.push(id);
            }
        }
        removed.reverse();
        let third = removed.len() / 3;
        removed.rotate_left(third);
        for &id in &removed {
            assert!(d.remove(id).is_some());
            assert!(!d.contains(id));
        }
        assert_eq!(d.len(), n - removed.len());
        for (k, &id) in ids.iter().enumerate() {
            assert_eq!(d.contains(id), k % 2 == 1);
            if k % 2 == 1 {
                let p = d.point(id).unwrap();
                assert!((p - pts[k]).length() < 1e-12);
            }
        }
        check_all(&d);
        // Grow it back at the largest empty circles (§4.6), as the management does.
        for k in 0..removed.len().min(64) {
            let (c, r) = d.largest_empty_circle().unwrap();
            assert!(r > 0.0);
            d.insert(1_000_000 + k as u64, c).unwrap();
        }
        check_all(&d);
    }
}

#[test]
fn inserting_at_the_largest_empty_circle_reduces_dispersion() {
    for kind in [DomainKind::Disc, DomainKind::Sphere] {
        let mut d = SamplingDomain::new(kind);
        let mut last = f64::INFINITY;
        for id in 0..300u64 {
            let (c, r) = d.largest_empty_circle().unwrap();
            assert!(r <= last + 1e-12, "{kind:?}: dispersion grew {last} → {r}");
            last = r;
            d.insert(id, c).unwrap();
            if id % 50 == 49 {
                check_all(&d);
            }
        }
        // 300 well-spread points: the dispersion is about that of a regular lattice.
        let area = match kind {
            DomainKind::Disc => PI,
            DomainKind::Sphere => 4.0 * PI,
        };
        let hex = (2.0 * area / (3.0 * 3f64.sqrt() * 300.0)).sqrt();
        assert!(
            last < 2.0 * hex,
            "{kind:?}: dispersion {last} vs lattice {hex}"
        );
    }
}

#[test]
fn small_sets() {
    for kind in [DomainKind::Disc, DomainKind::Sphere] {
        let mut d = SamplingDomain::new(kind);
        let (c, r) = d.largest_empty_circle().unwrap();
        match kind {
            DomainKind::Disc => assert_eq!((c, r), (DVec3::ZERO, 1.0)),
            DomainKind::Sphere => assert_eq!(r, 2.0),
        }
        assert!(d.voronoi_areas().is_empty());
        assert_eq!(d.shortest_edge(), None);
        assert_eq!(d.deletion_candidate(), None);
        let pts = [
            DVec3::new(0.3, 0.1, 0.2),
            DVec3::new(-0.5, 0.4, -0.6),
            DVec3::new(0.1, -0.7, 0.3),
            DVec3::new(0.6, 0.5, -0.4),
            DVec3::new(-0.2, -0.2, 0.9),
        ];
        for (i, &p) in pts.iter().enumerate() {
            d.insert(i as u64, p).unwrap();
            check_all(&d);
            assert!(d.shortest_edge().is_some() == (i >= 1));
        }
        for i in 0..pts.len() as u64 {
            d.remove(i).unwrap();
            if !d.is_empty() {
                check_all(&d);
            }
        }
        assert!(d.is_empty());
        // A site at the disc's centre: every boundary point is at distance 1.
        if kind == DomainKind::Disc {
            d.insert(9, DVec3::ZERO).unwrap();
            let (c, r) = d.largest_empty_circle().unwrap();
            assert!((r - 1.0).abs() < 1e-12 && (c.length() - 1.0).abs() < 1e-12);
            assert!((d.voronoi_areas()[0].1 - PI).abs() < 1e-12);
        }
    }
}

#[test]
fn degenerate_configurations() {
    // Disc: collinear sites and a regular polygon (co-circular).
    let mut d = SamplingDomain::new(DomainKind::Disc);
    for i in 0..5 {
        d.insert(i, DVec3::new(-0.8 + 0.4 * i as f64, 0.0, 0.0))
            .unwrap();
    }
    check_all(&d);
    let mut d = SamplingDomain::new(DomainKind::Disc);
    for i in 0..8 {
        let phi = 2.0 * PI * i as f64 / 8.0;
        d.insert(i, DVec3::new(0.5 * phi.cos(), 0.5 * phi.sin(), 0.0))
            .unwrap();
    }
    check_all(&d);
    // Sphere: sites on one small circle, on a great circle, and an octahedron.
    for z in [0.0f64, 0.6] {
        let mut d = SamplingDomain::new(DomainKind::Sphere);
        let r = (1.0 - z * z).sqrt();
        for i in 0..7 {
            let phi = 2.0 * PI * i as f64 / 7.0 + 0.1;
            d.insert(i, DVec3::new(r * phi.cos(), r * phi.sin(), z))
                .unwrap();
        }
        check_largest_empty_circle(&d);
        check_voronoi_areas(&d);
    }
    let mut d = SamplingDomain::new(DomainKind::Sphere);
    for (i, p) in [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ]
    .into_iter()
    .enumerate()
    {
        d.insert(i as u64, p).unwrap();
    }
    check_largest_empty_circle(&d);
    check_voronoi_areas(&d);
    for (_, a) in d.voronoi_areas() {
        assert!((a - 4.0 * PI / 6.0).abs() < 1e-9);
    }
    let (c, r) = d.largest_empty_circle().unwrap();
    assert!((c.abs() - DVec3::splat(1.0 / 3f64.sqrt())).length() < 1e-9);
    assert!((r - (2.0 - 2.0 / 3f64.sqrt()).sqrt()).abs() < 1e-9);
}

#[test]
fn insert_rejects_duplicates_and_invalid_points() {
    for kind in [DomainKind::Disc, DomainKind::Sphere] {
        let mut d = SamplingDomain::new(kind);
        let p = DVec3::new(0.3, 0.4, 0.0);
        d.insert(1, p).unwrap();
        d.insert(2, DVec3::new(-0.3, 0.2, 0.5)).unwrap();
        assert!(d.insert(1, DVec3::new(0.1, 0.1, 0.1)).is_err());
        assert!(d.insert(3, p).is_err());
        assert!(d.insert(4, DVec3::new(f64::NAN, 0.0, 0.0)).is_err());
        assert_eq!(d.len(), 2);
        assert_eq!(d.remove(7), None);
    }
    // Outside the disc: moved onto the circle. Sphere: normalised.
    let mut d = SamplingDomain::new(DomainKind::Disc);
    d.insert(1, DVec3::new(3.0, 4.0, 9.0)).unwrap();
    assert!((d.point(1).unwrap() - DVec3::new(0.6, 0.8, 0.0)).length() < 1e-15);
    let mut d = SamplingDomain::new(DomainKind::Sphere);
    d.insert(1, DVec3::new(0.0, 0.0, 2.0)).unwrap();
    assert_eq!(d.point(1), Some(DVec3::Z));
    assert!(d.insert(2, DVec3::ZERO).is_err());
}

/// A sphere site of high degree (a ring of m sites around +Z): its Voronoi area is the cap
/// inside the ring and all areas sum to 4π — past degree 500 a product of the fan's terms would
/// overflow (it gave NaN at 600).
#[test]
fn sphere_voronoi_area_of_a_site_of_high_degree() {
    let theta = 0.2f64;
    for m in [100usize, 600] {
        let mut sites = vec![(0u64, -DVec3::Z), (1, DVec3::Z)];
        let mut rng = Rng::from_state(3);
        for k in 0..m {
            let phi = 2.0 * PI * (k as f64 + 0.1 * rng.next_f64()) / m as f64;
            let p = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            sites.push((k as u64 + 2, p));
        }
        let (d, _) = SamplingDomain::from_sites(DomainKind::Sphere, &sites);
        let areas = d.voronoi_areas();
        let total: f64 = areas.iter().map(|a| a.1).sum();
        let top = areas.iter().find(|a| a.0 == 1).unwrap().1;
        let cap = 2.0 * PI * (1.0 - (theta / 2.0).cos());
        assert!(
            (total - 4.0 * PI).abs() < 1e-9,
            "ring of {m}: total {total}"
        );
        assert!(
            (top - cap).abs() < 0.01 * cap,
            "ring of {m}: {top} vs the cap's {cap}"
        );
    }
}

/// A disc point so far out that its squared length overflows is still moved onto the rim
/// along its direction (it was stored at the centre).
#[test]
fn a_huge_disc_point_lands_on_the_rim() {
    let mut d = SamplingDomain::new(DomainKind::Disc);
    d.insert(1, DVec3::new(1e300, 1e300, 0.0)).unwrap();
    let p = d.point(1).unwrap();
    let want = DVec3::new(1.0, 1.0, 0.0).normalize();
    assert!((p - want).length() < 1e-15, "stored {p}");
}
