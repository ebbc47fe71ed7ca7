//! Tests of the sampling-point domains (Laine et al. 2007, §4.5–§4.7).

use std::f64::consts::PI;

use gibench_laine::domain::{DomainKind, SamplingDomain};
use glam::{DVec2, DVec3};

const SIZES: [usize; 3] = [16, 256, 1024];

use gibench_harness::rng::SplitMix64 as Rng;
use gibench_harness::vpl::radical_inverse;

/// Uniform disc point from the unit square (polar mapping).
fn to_disc(u: f64, v: f64) -> DVec3 {
    let r = u.sqrt();
    let phi = 2.0 * PI * v;
    DVec3::new(r * phi.cos(), r * phi.sin(), 0.0)
}

/// Uniform sphere point from the unit square.
fn to_sphere(u: f64, v: f64) -> DVec3 {
    let z = 1.0 - 2.0 * u;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * v;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

fn point_set(kind: DomainKind, n: usize, random: bool) -> Vec<DVec3> {
    let mut rng = Rng::from_state(0x1234_5678 + n as u64);
    (0..n)
        .map(|i| {
            let (u, v) = if random {
                (rng.next_f64(), rng.next_f64())
            } else {
                (
                    radical_inverse(2, i as u64 + 1),
                    radical_inverse(3, i as u64 + 1),
                )
            };
            match kind {
                DomainKind::Disc => to_disc(u, v),
                DomainKind::Sphere => to_sphere(u, v),
            }
        })
        .collect()
}

fn build(kind: DomainKind, pts: &[DVec3]) -> SamplingDomain {
    let mut d = SamplingDomain::new(kind);
    for (i, &p) in pts.iter().enumerate() {
        d.insert(i as u64 * 7 + 3, p).unwrap();
    }
    assert_eq!(d.len(), pts.len());
    d
}

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

/// Disc points of the deletion test around `origin`, scaled: A–B is the shortest edge; B's
/// second-closest neighbour (E, 0.15 away) is closer than A's (C, 0.30 away), so §4.5 deletes
/// B. Mirrored, the roles swap.
fn deletion_configuration(mirror: bool) -> Vec<(u64, DVec2)> {
    let s = if mirror { -1.0 } else { 1.0 };
    let mut pts = vec![
        (10, DVec2::new(0.0, 0.0)),        // A
        (20, DVec2::new(0.05 * s, 0.0)),   // B
        (30, DVec2::new(-0.30 * s, 0.0)),  // C: A's second-closest
        (40, DVec2::new(0.20 * s, 0.0)),   // E: B's second-closest
        (50, DVec2::new(0.025 * s, 0.6)),  // above
        (60, DVec2::new(0.025 * s, -0.6)), // below
    ];
    for k in 0..8 {
        let phi = 2.0 * PI * (k as f64 + 0.5) / 8.0;
        pts.push((100 + k, 0.9 * DVec2::new(phi.cos(), phi.sin())));
    }
    pts
}

#[test]
fn deletion_removes_the_endpoint_with_the_closer_second_neighbour() {
    for mirror in [false, true] {
        let config = deletion_configuration(mirror);
        // Disc.
        let mut d = SamplingDomain::new(DomainKind::Disc);
        for &(id, p) in &config {
            d.insert(id, p.extend(0.0)).unwrap();
        }
        let (a, b, len) = d.shortest_edge().unwrap();
        assert_eq!((a.min(b), a.max(b)), (10, 20));
        assert!((len - 0.05).abs() < 1e-12);
        assert!((d.second_closest_neighbour_distance(10).unwrap() - 0.30).abs() < 1e-12);
        assert!((d.second_closest_neighbour_distance(20).unwrap() - 0.15).abs() < 1e-12);
        assert_eq!(d.deletion_candidate(), Some(20));
        // Insert B's partner last and A's first, so insertion order cannot decide.
        let mut d = SamplingDomain::new(DomainKind::Disc);
        for &(id, p) in config.iter().rev() {
            d.insert(id, p.extend(0.0)).unwrap();
        }
        assert_eq!(d.deletion_candidate(), Some(20));
        // Sphere: the same configuration on the tangent plane at +Z, gnomonically (distances
        // change a little but not their order); plus a site at the south pole.
        let mut d = SamplingDomain::new(DomainKind::Sphere);
        d.insert(999, DVec3::NEG_Z).unwrap();
        for &(id, p) in &config {
            d.insert(id, (p * 0.5).extend(1.0)).unwrap();
        }
        let (a, b, _) = d.shortest_edge().unwrap();
        assert_eq!((a.min(b), a.max(b)), (10, 20));
        assert_eq!(d.deletion_candidate(), Some(20));
        // Deleting repeatedly always removes an endpoint of the shortest edge and never
        // decreases the shortest edge length (§4.5: "always increases the smallest distance").
        let mut last = 0.0;
        while d.len() > 4 {
            let (a, b, len) = d.shortest_edge().unwrap();
            assert!(len >= last - 1e-12);
            last = len;
            let victim = d.deletion_candidate().unwrap();
            assert!(victim == a || victim == b);
            d.remove(victim).unwrap();
        }
    }
}

/// The largest empty circle answered from the kept candidates equals a full scan bit for bit
/// (centre and radius) after every step of a mixed sequence — inserts at the largest empty
/// circle (as the management does), random inserts, rim points (disc) and removals including
/// the sphere's pole — on both domains.
#[test]
fn lec_cache_equals_the_scan() {
    // Many short sequences (few sites: where the rim candidates of case (3) win) and one long.
    let runs = (0..400u64).map(|seed| (seed, 20)).chain([(77, 1500)]);
    for ((seed, steps), kind) in runs.flat_map(|r| [(r, DomainKind::Disc), (r, DomainKind::Sphere)])
    {
        let mut rng = Rng::from_state(seed);
        let mut d = SamplingDomain::new(kind);
        let mut live: Vec<u64> = Vec::new();
        let mut next = 0u64;
        for step in 0..steps {
            let r = rng.next_f64();
            if r < 0.15 && live.len() > 3 {
                let k = (rng.next_f64() * live.len() as f64) as usize;
                let id = live.swap_remove(k.min(live.len() - 1));
                d.remove(id);
            } else {
                let p = if r < 0.6 {
                    d.largest_empty_circle().unwrap().0
                } else if r < 0.7 && kind == DomainKind::Disc {
                    let phi = 2.0 * PI * rng.next_f64();
                    DVec3::new(phi.cos(), phi.sin(), 0.0)
                } else {
                    match kind {
                        DomainKind::Disc => to_disc(rng.next_f64(), rng.next_f64()),
                        DomainKind::Sphere => to_sphere(rng.next_f64(), rng.next_f64()),
                    }
                };
                if d.insert(next, p).is_ok() {
                    live.push(next);
                }
                next += 1;
            }
            let cached = d
                .largest_empty_circle()
                .map(|(c, r)| (c.to_array().map(f64::to_bits), r.to_bits()));
            let scan = d
                .largest_empty_circle_by_scan()
                .map(|(c, r)| (c.to_array().map(f64::to_bits), r.to_bits()));
            assert_eq!(
                cached,
                scan,
                "{kind:?}, seed {seed}, step {step}, {} sites",
                d.len()
            );
        }
    }
}

/// Inserting with a hint (any site, near or far) gives the triangulation a plain insert gives,
/// triangle for triangle in the same order, and the same largest empty circle.
#[test]
fn hinted_inserts_build_the_same_triangulation() {
    for kind in [DomainKind::Disc, DomainKind::Sphere] {
        for random in [true, false] {
            let mut pts = point_set(kind, 400, random);
            let mut rng = Rng::from_state(5);
            // Every third disc point on the rim: outside the hull of the points before it.
            if kind == DomainKind::Disc {
                for p in pts.iter_mut().step_by(3) {
                    *p = p.normalize();
                }
            }
            let mut plain = SamplingDomain::new(kind);
            let mut hinted = SamplingDomain::new(kind);
            for (i, p) in pts.iter().enumerate() {
                let a = plain.insert(i as u64, *p);
                let hint = (i > 0).then(|| (rng.next_f64() * i as f64) as u64);
                let b = hinted.insert_near(i as u64, *p, hint);
                assert_eq!(a, b, "{kind:?} point {i}");
                assert_eq!(plain.triangles(), hinted.triangles(), "{kind:?} point {i}");
            }
            // Then fill at the largest empty circle, hinted by the circle's site.
            for k in 0..200u64 {
                let (c, _) = plain.largest_empty_circle().unwrap();
                let (ch, _, site) = hinted.largest_empty_circle_near().unwrap();
                assert_eq!(
                    c.to_array().map(f64::to_bits),
                    ch.to_array().map(f64::to_bits)
                );
                plain.insert(10_000 + k, c).unwrap();
                hinted.insert_near(10_000 + k, ch, site).unwrap();
            }
            assert_eq!(
                plain.triangles(),
                hinted.triangles(),
                "{kind:?} random {random}"
            );
        }
    }
}

/// Triangles as id triples, each rotated to start at its smallest id, sorted: the same set
/// whatever order the triangulation numbers faces and corners in.
fn canonical_triangles(d: &SamplingDomain) -> Vec<[u64; 3]> {
    let mut t = d.triangles();
    for tri in &mut t {
        let k = (0..3).min_by_key(|&k| tri[k]).unwrap();
        tri.rotate_left(k);
    }
    t.sort_unstable();
    t
}

/// `from_sites` (the per-frame bulk load of the management) accepts and refuses exactly the
/// sites that inserting them in order does — repeated ids, non-finite and (sphere) zero
/// points, points equal to an earlier one (sphere: to the pole site, or projecting onto a
/// projected site) — and builds the same Delaunay triangulation, largest empty circle,
/// deletion candidate and Voronoi areas.
#[test]
fn bulk_built_domain_equals_the_inserted_one() {
    for kind in [DomainKind::Disc, DomainKind::Sphere] {
        for random in [true, false] {
            let pts = point_set(kind, 300, random);
            let mut sites: Vec<(u64, DVec3)> = pts
                .iter()
                .enumerate()
                .map(|(i, p)| (i as u64 * 3 + 1, *p))
                .collect();
            // Every fifth disc point pushed outside the disc (moved onto the rim).
            if kind == DomainKind::Disc {
                for s in sites.iter_mut().step_by(5) {
                    s.1 *= 2.0;
                }
            }
            let first = sites[0];
            sites.push((4, sites[7].1)); // an earlier site's point (the pole's on the sphere: 0)
                                         // The first site's point again (on the sphere scaled: the pole, normalised).
            let again = match kind {
                DomainKind::Disc => first.1,
                DomainKind::Sphere => first.1 * 3.0,
            };
            sites.push((5, again));
            sites.push((sites[9].0, DVec3::new(0.01, 0.02, 0.5))); // a repeated id
            sites.push((8, DVec3::new(f64::NAN, 0.0, 0.0)));
            sites.push((11, DVec3::new(0.0, f64::INFINITY, 0.0)));
            sites.push((14, DVec3::ZERO)); // the disc's centre; no point on the sphere
            sites.push((17, DVec3::new(0.02, -0.03, 0.9)));
            sites.insert(40, (2, sites[12].1)); // a duplicate before later sites
            let mut inserted = SamplingDomain::new(kind);
            let want: Vec<bool> = sites
                .iter()
                .map(|&(id, p)| inserted.insert(id, p).is_ok())
                .collect();
            assert!(want.iter().filter(|a| !**a).count() >= 6, "{kind:?}");
            let (bulk, got) = SamplingDomain::from_sites(kind, &sites);
            assert_eq!(got, want, "{kind:?} random {random}");
            assert_eq!(bulk.len(), inserted.len());
            let mut a = bulk.points();
            let mut b = inserted.points();
            a.sort_by_key(|p| p.0);
            b.sort_by_key(|p| p.0);
            assert_eq!(a, b);
            assert_eq!(canonical_triangles(&bulk), canonical_triangles(&inserted));
            let (cb, rb) = bulk.largest_empty_circle().unwrap();
            let (ci, ri) = inserted.largest_empty_circle().unwrap();
            assert!((cb - ci).length() < 1e-12 && (rb - ri).abs() < 1e-12);
            assert_eq!(bulk.deletion_candidate(), inserted.deletion_candidate());
            let mut va = bulk.voronoi_areas();
            let mut vb = inserted.voronoi_areas();
            va.sort_by_key(|p| p.0);
            vb.sort_by_key(|p| p.0);
            for ((ia, x), (ib, y)) in va.iter().zip(&vb) {
                assert_eq!(ia, ib);
                assert!((x - y).abs() < 1e-12, "{kind:?} site {ia}: {x} vs {y}");
            }
        }
    }
}

/// `update_sites` (the management's per-frame kinetic update: last frame's triangulation moved
/// with its points, the sites whose motion breaks it taken out and put back) ends where
/// `from_sites` would: the same accepted sites, Delaunay triangles, largest empty circle,
/// deletion candidate and Voronoi areas — over 40 frames of a coherent motion (a rotation and
/// a varying shear, like the sampling points of a moving light) with jitter that turns
/// triangles over and pushes disc points past the rim, a few sites leaving each frame; then
/// a new id and an invalid point, which must rebuild. The motion is large enough that the
/// repair path runs, and small enough that the kinetic path is the one that ran.
#[test]
fn moved_domain_equals_the_bulk_built_one() {
    for kind in [DomainKind::Disc, DomainKind::Sphere] {
        let pts = point_set(kind, 600, true);
        let mut sites: Vec<(u64, DVec3)> = (pts.iter().enumerate())
            .map(|(i, p)| (i as u64 * 5 + 2, *p))
            .collect();
        let (mut d, _) = SamplingDomain::from_sites(kind, &sites);
        let mut rng = Rng::from_state(0x5eed + kind as u64);
        let (mut rebuilt, mut reinserted) = (0, 0);
        let check = |d: &SamplingDomain, sites: &[(u64, DVec3)], got: &[bool], frame: usize| {
            let (want_d, want) = SamplingDomain::from_sites(kind, sites);
            assert_eq!(got, want, "{kind:?} frame {frame}");
            assert_eq!(
                canonical_triangles(d),
                canonical_triangles(&want_d),
                "{kind:?} frame {frame}"
            );
            let (c, r) = d.largest_empty_circle().unwrap();
            let (wc, wr) = want_d.largest_empty_circle().unwrap();
            assert!(
                (c - wc).length() < 1e-12 && (r - wr).abs() < 1e-12,
                "{kind:?} frame {frame}"
            );
            assert_eq!(d.deletion_candidate(), want_d.deletion_candidate());
            let mut va = d.voronoi_areas();
            let mut vb = want_d.voronoi_areas();
            va.sort_by_key(|p| p.0);
            vb.sort_by_key(|p| p.0);
            assert_eq!(va.len(), vb.len());
            for ((ia, x), (ib, y)) in va.iter().zip(&vb) {
                assert_eq!(ia, ib);
                assert!(
                    (x - y).abs() < 1e-12,
                    "{kind:?} frame {frame} site {ia}: {x} vs {y}"
                );
            }
        };
        for frame in 0..40 {
            let (angle, shear) = (0.01, 0.004 * (frame % 3) as f64);
            let (sin, cos) = f64::sin_cos(angle);
            for s in &mut sites {
                let p = s.1;
                let mut jitter = DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) - 0.5;
                let q = match kind {
                    DomainKind::Disc => {
                        jitter.z = 0.0;
                        DVec3::new(
                            cos * p.x - sin * p.y + shear * p.y,
                            sin * p.x + cos * p.y,
                            0.0,
                        )
                    }
                    DomainKind::Sphere => DVec3::new(
                        cos * p.x - sin * p.z + shear * p.y,
                        p.y,
                        sin * p.x + cos * p.z,
                    )
                    .normalize(),
                };
                s.1 = q + 0.003 * jitter;
            }
            for _ in 0..3 {
                let k = (rng.next_f64() * sites.len() as f64) as usize;
                sites.swap_remove(k);
            }
            let u = d.update_sites(&sites);
            rebuilt += u.rebuilt as usize;
            reinserted += u.reinserted;
            check(&d, &sites, &u.accepted, frame);
        }
        assert_eq!(rebuilt, 0, "{kind:?}: rebuilt {rebuilt} of 40 frames");
        assert!(
            reinserted >= 40,
            "{kind:?}: only {reinserted} sites reinserted in 40 frames"
        );
        // A site the domain does not hold, and an invalid point: rebuilt, refused as
        // `from_sites` refuses it.
        sites.push((1, DVec3::new(0.1, 0.2, 0.3)));
        sites.push((sites[3].0 + 1, DVec3::new(f64::NAN, 0.0, 0.0)));
        let u = d.update_sites(&sites);
        assert!(u.rebuilt);
        check(&d, &sites, &u.accepted, 40);
    }
}

/// `remove_redundant` (the management's run of §4.5 deletions from one queue of edges) deletes
/// the sites that `deletion_candidate` and `remove` called in turn delete, in the same order —
/// down to two sites, on the disc and on the sphere (whose projection pole is deleted along
/// the way) — and leaves the same domain.
#[test]
fn queued_deletions_equal_repeated_candidates() {
    for kind in [DomainKind::Disc, DomainKind::Sphere] {
        for random in [true, false] {
            let pts = point_set(kind, 200, random);
            let mut a = build(kind, &pts);
            let mut b = a.clone();
            let mut q = b.redundancy_queue();
            for step in 0..198 {
                let want = a.deletion_candidate().unwrap();
                a.remove(want).unwrap();
                let got = b.remove_redundant(&mut q);
                assert_eq!(got, Some(want), "{kind:?} random {random} deletion {step}");
            }
            assert_eq!(canonical_triangles(&a), canonical_triangles(&b));
            assert_eq!(a.len(), 2);
        }
    }
}

/// `update_sites` accepts and refuses as `from_sites` also when the sites come in another
/// order: `from_sites` makes the first site the sphere's projection pole and refuses points
/// within 10⁻¹² of it, so a list whose first site is not the domain's pole must rebuild — here
/// a site moves to 5·10⁻¹³ from the new first site (kept by a move from the old pole, refused
/// by `from_sites`).
#[test]
fn update_sites_refuses_as_from_sites_whatever_the_order() {
    let kind = DomainKind::Sphere;
    let mut sites: Vec<(u64, DVec3)> = (point_set(kind, 16, true).into_iter().enumerate())
        .map(|(i, p)| (i as u64 + 1, p))
        .collect();
    let a = sites[3].1;
    sites[7].1 = a + DVec3::new(1e-7, 0.0, 0.0);
    let (mut d, _) = SamplingDomain::from_sites(kind, &sites);
    sites.swap(0, 3);
    sites[7].1 = a + DVec3::new(5e-13, 0.0, 0.0);
    let u = d.update_sites(&sites);
    let (want_d, want) = SamplingDomain::from_sites(kind, &sites);
    assert_eq!(u.accepted, want);
    assert!(want.iter().any(|a| !a), "the near duplicate is refused");
    assert_eq!(canonical_triangles(&d), canonical_triangles(&want_d));
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
