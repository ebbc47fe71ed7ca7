//! How the management keeps a domain: §4.5 deletions (one at a time and from a queue), the
//! kept largest-empty-circle candidates, hinted inserts, the bulk build and moving the sites.

use std::f64::consts::PI;

use gibench_harness::rng::SplitMix64 as Rng;
use gibench_laine::domain::{DomainKind, SamplingDomain};
use glam::{DVec2, DVec3};

use super::{build, point_set, to_disc, to_sphere};

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
