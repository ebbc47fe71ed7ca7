//! Visibility determination against brute force: segments from points sampled on each
//! receiver to the light, tested against every blocker.

use gibench_barczak::visibility::{
    classify_object, classify_patch, determine, segment_hits, Blocker, LightState, PatchTree,
    PointLight, Pyramid, Shape,
};
use glam::Vec3;

use gibench_harness::rng::SplitMix64 as Rng;

/// A uniform unit vector (rejection from the cube, away from its centre).
fn unit(rng: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        if v.length_squared() > 0.01 && v.length_squared() <= 1.0 {
            return v.normalize();
        }
    }
}

/// A rectangle: centre, unit normal, half sizes; corners in order (front side along `n`).
fn rectangle(c: Vec3, n: Vec3, hu: f32, hv: f32, turn: f32) -> [Vec3; 4] {
    let u0 = n.any_orthonormal_vector();
    let v0 = n.cross(u0);
    let (u, v) = (
        u0 * turn.cos() + v0 * turn.sin(),
        v0 * turn.cos() - u0 * turn.sin(),
    );
    [
        c - u * hu - v * hv,
        c + u * hu - v * hv,
        c + u * hu + v * hv,
        c - u * hu + v * hv,
    ]
}

struct Case {
    tree: PatchTree,
    light: PointLight,
    blockers: Vec<Blocker>,
}

/// A random patch (object 0, split twice), a light in front of it and a few blockers around
/// the space between: rectangles, triangles and spheres of other objects, plus the patch's own
/// polygon (which must never count).
fn case(rng: &mut Rng) -> Case {
    let n = unit(rng);
    let c = Vec3::new(
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
    );
    let corners = rectangle(
        c,
        n,
        rng.range(0.5, 2.0),
        rng.range(0.5, 2.0),
        rng.range(0.0, 6.3),
    );
    let tree = PatchTree::new(0, corners, n, 2);
    let light_pos = c + (n + 0.8 * unit(rng)).normalize_or(n) * rng.range(1.0, 5.0);
    let light_pos = if n.dot(light_pos - c) < 0.3 {
        c + n * rng.range(1.0, 4.0)
    } else {
        light_pos
    };
    let normal = match (rng.next_f32() * 3.0) as u32 {
        0 => None,
        // Mostly facing the patch, sometimes away.
        _ => Some((c - light_pos).normalize().lerp(unit(rng), 0.7).normalize()),
    };
    let mut blockers = vec![Blocker {
        object: 0,
        shape: Shape::Polygon(corners.to_vec()),
    }];
    for i in 0..rng.range(1.0, 5.0) as u32 {
        let t = rng.range(0.1, 0.9);
        let at = c.lerp(light_pos, t) + unit(rng) * rng.range(0.0, 2.0);
        let shape = match (rng.next_f32() * 3.0) as u32 {
            0 => Shape::Sphere {
                center: at,
                radius: rng.range(0.05, 0.8),
            },
            1 => {
                let r = rectangle(at, unit(rng), rng.range(0.1, 3.0), rng.range(0.1, 3.0), 0.0);
                Shape::Polygon(r.to_vec())
            }
            _ => {
                let s = rng.range(0.2, 3.0);
                Shape::Polygon(vec![
                    at + unit(rng) * s,
                    at + unit(rng) * s,
                    at + unit(rng) * s,
                ])
            }
        };
        blockers.push(Blocker {
            object: 1 + i,
            shape,
        });
    }
    Case {
        tree,
        light: PointLight {
            position: light_pos,
            normal,
        },
        blockers,
    }
}

/// Points on the patch (a 12 × 12 grid kept 1 % off its edges).
fn samples(corners: [Vec3; 4]) -> Vec<Vec3> {
    let [a, b, c, d] = corners;
    let mut out = Vec::new();
    for i in 0..12 {
        for j in 0..12 {
            let (s, t) = (0.01 + 0.98 * i as f32 / 11.0, 0.01 + 0.98 * j as f32 / 11.0);
            out.push(a.lerp(b, s).lerp(d.lerp(c, s), t));
        }
    }
    out
}

fn blocked(p: Vec3, light: Vec3, blockers: &[Blocker], own: u32) -> bool {
    blockers
        .iter()
        .filter(|b| b.object != own)
        .any(|b| segment_hits(p, light, &b.shape, 1e-6))
}

/// Unblocked: no sampled segment is blocked; fully blocked: every one is; behind: the light
/// lights none of the samples; partial: conservative, but on 90 % of the partial leaves with one
/// polygon reaching in the samples see both light and shadow (the rest: the polygon cuts only
/// a sliver near the patch's edges, between samples). Every state occurs often enough to matter.
#[test]
fn classification_agrees_with_ray_sampling() {
    let mut rng = Rng::from_state(7);
    let mut count = std::collections::HashMap::new();
    let (mut partial, mut mixed) = (0, 0);
    for k in 0..600 {
        let case = case(&mut rng);
        let states = determine(&case.tree, &case.light, &case.blockers);
        for leaf in case.tree.leaves() {
            let corners = case.tree.nodes[leaf].corners;
            let hits: Vec<bool> = samples(corners)
                .iter()
                .map(|p| blocked(*p, case.light.position, &case.blockers, 0))
                .collect();
            let n_hit = hits.iter().filter(|h| **h).count();
            let state = states[leaf].state;
            *count.entry(state).or_insert(0) += 1;
            match state {
                LightState::Unblocked => assert_eq!(
                    n_hit, 0,
                    "case {k} leaf {leaf}: unblocked but {n_hit} segments blocked"
                ),
                LightState::Blocked => assert_eq!(
                    n_hit,
                    hits.len(),
                    "case {k} leaf {leaf}: blocked but {} segments free",
                    hits.len() - n_hit
                ),
                LightState::Behind => {
                    let lit = samples(corners).iter().any(|p| {
                        case.tree.normal.dot(case.light.position - *p) > 0.0
                            && case
                                .light
                                .normal
                                .is_none_or(|ln| ln.dot(*p - case.light.position) > 0.0)
                    });
                    assert!(
                        !lit,
                        "case {k} leaf {leaf}: behind, but the light reaches a sample"
                    );
                }
                LightState::Partial => {
                    // Tightness where it can be expected: one polygon reaching in.
                    let list = &states[leaf].blockers;
                    let one_polygon = states[leaf].tested
                        && list.len() == 1
                        && matches!(case.blockers[list[0].0 as usize].shape, Shape::Polygon(_));
                    if one_polygon {
                        partial += 1;
                        mixed += (n_hit > 0 && n_hit < hits.len()) as usize;
                    }
                }
            }
        }
    }
    eprintln!("states {count:?}; single-polygon partial leaves with light and shadow: {mixed} of {partial}");
    for s in [
        LightState::Unblocked,
        LightState::Partial,
        LightState::Blocked,
        LightState::Behind,
    ] {
        assert!(
            count.get(&s).copied().unwrap_or(0) >= 100,
            "too few {s:?} leaves: {count:?}"
        );
    }
    assert!(
        mixed * 10 >= partial * 9,
        "partial leaves that see light and shadow: {mixed} of {partial}"
    );
}

/// The hierarchy's early termination changes nothing: every leaf's state is what testing the
/// leaf against every blocker gives.
#[test]
fn hierarchy_equals_testing_every_leaf() {
    let mut rng = Rng::from_state(11);
    let mut tested_below_root = 0;
    for _ in 0..600 {
        let case = case(&mut rng);
        let states = determine(&case.tree, &case.light, &case.blockers);
        for leaf in case.tree.leaves() {
            let node = &case.tree.nodes[leaf];
            let flat = classify_patch(
                node.corners,
                case.tree.normal,
                0,
                &case.light,
                &case.blockers,
                0..case.blockers.len() as u32,
                case.tree.tolerance(&case.light),
            );
            // A leaf under a fully blocked node says Blocked even where the light is also
            // behind it; both mean it adds nothing.
            let nothing = |s: LightState| matches!(s, LightState::Blocked | LightState::Behind);
            assert!(
                states[leaf].state == flat.state
                    || (nothing(states[leaf].state) && nothing(flat.state)),
                "{:?} vs {:?}",
                states[leaf].state,
                flat.state
            );
            tested_below_root += states[leaf].tested as usize;
        }
    }
    assert!(
        tested_below_root > 500,
        "the descent was hardly exercised ({tested_below_root} leaves tested)"
    );
}

/// A floor patch with walls standing on its edges and the light inside the room: the walls
/// touch the pyramid only along the floor's edges and block nothing; a box on the floor
/// in the middle does.
#[test]
fn walls_meeting_the_patch_are_not_blockers() {
    let floor = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 4.0),
        Vec3::new(4.0, 0.0, 4.0),
        Vec3::new(4.0, 0.0, 0.0),
    ];
    let wall = |a: Vec3, b: Vec3| Shape::Polygon(vec![a, b, b + Vec3::Y * 3.0, a + Vec3::Y * 3.0]);
    let mut blockers: Vec<Blocker> = (0..4)
        .map(|i| Blocker {
            object: 1 + i as u32,
            shape: wall(floor[i], floor[(i + 1) % 4]),
        })
        .collect();
    let light = PointLight {
        position: Vec3::new(1.0, 2.5, 3.0),
        normal: Some(Vec3::NEG_Y),
    };
    let tree = PatchTree::new(0, floor, Vec3::Y, 1);
    let v = determine(&tree, &light, &blockers);
    assert_eq!(v[0].state, LightState::Unblocked, "{:?}", v[0]);
    blockers.push(Blocker {
        object: 9,
        shape: Shape::Polygon(vec![
            Vec3::new(1.5, 1.0, 1.5),
            Vec3::new(2.5, 1.0, 1.5),
            Vec3::new(2.5, 1.0, 2.5),
            Vec3::new(1.5, 1.0, 2.5),
        ]),
    });
    let v = determine(&tree, &light, &blockers);
    assert_eq!(v[0].state, LightState::Partial);
    assert_eq!(
        v[0].blockers,
        vec![(4, gibench_barczak::visibility::Occlusion::Partial)]
    );
}

/// The widened pyramid of a complex receiver holds its bounding sphere, and its classification
/// agrees with segments from the light to points of the sphere.
#[test]
fn object_pyramids_hold_the_sphere_and_agree_with_ray_sampling() {
    let mut rng = Rng::from_state(5);
    let mut count = std::collections::HashMap::new();
    for k in 0..400 {
        let center = Vec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let radius = rng.range(0.2, 1.0);
        let light = center + unit(&mut rng) * rng.range(radius * 1.5, 6.0);
        let pyramid = Pyramid::to_sphere(light, center, radius).unwrap();
        // Points of the sphere: none is blocked by a polygon the pyramid misses.
        let pts: Vec<Vec3> = (0..200)
            .map(|_| center + unit(&mut rng) * radius * rng.next_f32().sqrt())
            .collect();
        for _ in 0..4 {
            let at =
                center.lerp(light, rng.range(0.1, 0.95)) + unit(&mut rng) * rng.range(0.0, 1.5);
            let shape = if rng.next_f32() < 0.5 {
                Shape::Polygon(
                    rectangle(
                        at,
                        unit(&mut rng),
                        rng.range(0.1, 3.0),
                        rng.range(0.1, 3.0),
                        0.0,
                    )
                    .to_vec(),
                )
            } else {
                Shape::Sphere {
                    center: at,
                    radius: rng.range(0.05, 0.5),
                }
            };
            let result = pyramid.test(&shape);
            let n_hit = pts
                .iter()
                .filter(|p| segment_hits(**p, light, &shape, 1e-6))
                .count();
            *count.entry(format!("{result:?}")).or_insert(0) += 1;
            match result {
                None => assert_eq!(n_hit, 0, "case {k}: outside the pyramid but blocks {n_hit}"),
                Some(gibench_barczak::visibility::Occlusion::Full) => {
                    assert_eq!(
                        n_hit,
                        pts.len(),
                        "case {k}: full but {} free",
                        pts.len() - n_hit
                    )
                }
                Some(_) => {}
            }
        }
        let blockers = vec![Blocker {
            object: 3,
            shape: Shape::Sphere { center, radius },
        }];
        // The object never blocks itself.
        let own = classify_object(
            center,
            radius,
            3,
            &PointLight {
                position: light,
                normal: None,
            },
            &blockers,
        );
        assert_eq!(own.state, LightState::Unblocked);
    }
    eprintln!("{count:?}");
    for key in ["None", "Some(Partial)", "Some(Full)"] {
        assert!(
            count.get(key).copied().unwrap_or(0) >= 50,
            "too few {key}: {count:?}"
        );
    }
}
