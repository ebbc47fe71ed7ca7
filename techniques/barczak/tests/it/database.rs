//! The movers' visibility database: after every step of two movers along their paths, the
//! incrementally updated database equals one rebuilt from scratch on the moved scene, the
//! light-map changes it reports are exactly the leaves whose lights changed between lit and
//! unlit, and it makes fewer tests than the rebuild.

use gibench_barczak::database::{ReceiverShape, VisibilityDatabase};
use gibench_barczak::visibility::LightState;
use glam::{Mat3, Vec3};

use crate::support;
use support::{lights, room};

fn leaf_lit(db: &VisibilityDatabase) -> Vec<bool> {
    let mut v = Vec::new();
    for (r, rec) in db.receivers.iter().enumerate() {
        for n in 0..rec.node_count() {
            let leaf = match &rec.shape {
                ReceiverShape::Patch(t) => t.nodes[n].children.is_none(),
                ReceiverShape::Object { .. } => true,
            };
            if leaf {
                for l in 0..db.lights.len() {
                    v.push(matches!(
                        db.state(r, n, l),
                        LightState::Unblocked | LightState::Partial
                    ));
                }
            }
        }
    }
    v
}

#[test]
fn mover_updates_equal_a_full_recomputation() {
    updates_equal_rebuilds(false);
}

/// The same with the static blockers folded away (`keep_movers_only` on the first database;
/// `build_keeping_movers`, what `setup::prepare` uses, for each rebuild): the updated entries
/// equal the folded rebuild's, and every state equals the unfolded rebuild's.
#[test]
fn updates_keeping_movers_only_equal_a_full_recomputation() {
    updates_equal_rebuilds(true);
}

fn updates_equal_rebuilds(keep_movers_only: bool) {
    const MOVERS: [u32; 2] = [7, 8];
    let (receivers, blockers) = room();
    let (mut db, _) = VisibilityDatabase::build(lights(), receivers, blockers);
    if keep_movers_only {
        // (all listed, the movers' listed)
        let listed = |db: &VisibilityDatabase| -> (usize, usize) {
            let all = db
                .entries()
                .iter()
                .flatten()
                .flatten()
                .flat_map(|e| &e.blockers);
            all.fold((0, 0), |(n, m), (b, _)| {
                let mover = MOVERS.contains(&db.blockers[*b as usize].object);
                (n + 1, m + usize::from(mover))
            })
        };
        let (all, movers) = listed(&db);
        db.keep_movers_only(&MOVERS);
        assert!(movers < all, "the room has static blockers");
        assert_eq!(listed(&db), (movers, movers));
    }
    let (mut incremental, mut rebuilt, mut changes, mut maps) = (0, 0, 0, 0);
    for step in 1..=24 {
        // The box slides across the floor under the table; the sphere circles and rises.
        let before = leaf_lit(&db);
        let update = if step % 2 == 0 {
            db.move_object(7, |p| p + Vec3::new(0.21, 0.0, 0.17))
        } else {
            let centre = Vec3::new(3.0, 0.0, 3.0);
            let turn = Mat3::from_rotation_y(0.31);
            db.move_object(8, move |p| {
                centre + turn * (p - centre) + Vec3::new(0.0, 0.04, 0.0)
            })
        };
        let (mut fresh, tests) =
            VisibilityDatabase::build(db.lights.clone(), db.receivers.clone(), db.blockers.clone());
        if keep_movers_only {
            assert_eq!(leaf_lit(&db), leaf_lit(&fresh), "step {step}");
            let states = |db: &VisibilityDatabase| -> Vec<Option<LightState>> {
                db.entries()
                    .iter()
                    .flatten()
                    .flatten()
                    .map(|e| e.state)
                    .collect()
            };
            let unfolded = states(&fresh);
            (fresh, _) = VisibilityDatabase::build_keeping_movers(
                db.lights.clone(),
                db.receivers.clone(),
                db.blockers.clone(),
                &MOVERS,
            );
            assert_eq!(
                states(&fresh),
                unfolded,
                "step {step}: folding changed a state"
            );
        }
        if db.entries() != fresh.entries() {
            for (r, (a, b)) in db.entries().iter().zip(fresh.entries()).enumerate() {
                for (n, (x, y)) in a.iter().zip(b).enumerate() {
                    for (l, (e, f)) in x.iter().zip(y).enumerate() {
                        if e != f {
                            panic!("step {step}: receiver {r} (object {}) node {n} light {l}: {e:?} vs rebuilt {f:?}", db.receivers[r].object);
                        }
                    }
                }
            }
        }
        // The light-map changes are exactly the leaves that changed between lit and unlit.
        let after = leaf_lit(&db);
        let flipped = before.iter().zip(&after).filter(|(a, b)| a != b).count();
        assert_eq!(update.light_map.len(), flipped, "step {step}");
        for c in &update.light_map {
            assert_eq!(
                c.add,
                matches!(
                    db.state(c.receiver as usize, c.node as usize, c.light as usize),
                    LightState::Unblocked | LightState::Partial
                )
            );
        }
        incremental += update.tests;
        rebuilt += tests;
        changes += update.light_map.len();
        maps += update.shadow_maps.len();
    }
    eprintln!("tests: {incremental} updating, {rebuilt} rebuilding; {changes} light-map changes; {maps} shadow maps to update");
    assert!(
        changes > 20,
        "the movers hardly changed anything ({changes} light-map changes)"
    );
    assert!(maps > 0 && maps < 24 * lights().len(), "{maps}");
    assert!(
        incremental * 2 < rebuilt,
        "updates made {incremental} tests, rebuilds {rebuilt}"
    );
}

/// The same states as testing every node against every blocker without the blocker index
/// (`visibility::determine`, `classify_object`): on the room after its movers moved (the
/// index refitted), and on the charts of a scene that records no patches.
#[test]
fn the_blocker_index_leaves_every_state_unchanged() {
    use gibench_barczak::visibility::{classify_object, determine};
    let check = |db: &VisibilityDatabase, what: &str| {
        let mut partial = 0;
        for (r, rec) in db.receivers.iter().enumerate() {
            for (l, light) in db.lights.iter().enumerate() {
                let want: Vec<LightState> = match &rec.shape {
                    ReceiverShape::Patch(tree) => determine(tree, light, &db.blockers)
                        .into_iter()
                        .map(|v| v.state)
                        .collect(),
                    ReceiverShape::Object { center, radius } => {
                        vec![
                            classify_object(*center, *radius, rec.object, light, &db.blockers)
                                .state,
                        ]
                    }
                };
                for (n, w) in want.iter().enumerate() {
                    partial += (*w == LightState::Partial) as usize;
                    // Below a fully blocked node, `determine` keeps "blocked" where the
                    // database says "behind": both leave the light out.
                    let unlit =
                        |s: LightState| matches!(s, LightState::Blocked | LightState::Behind);
                    let got = db.state(r, n, l);
                    assert!(
                        got == *w || (unlit(got) && unlit(*w)),
                        "{what}: receiver {r} node {n} light {l}: {got:?}, without the index {w:?}"
                    );
                }
            }
        }
        assert!(partial > 0, "{what}: no partial light to check");
    };
    let (receivers, blockers) = room();
    let (mut db, _) = VisibilityDatabase::build(lights(), receivers, blockers);
    check(&db, "room");
    for step in 0..6 {
        db.move_object(7, |p| p + Vec3::new(0.35, 0.0, 0.25));
        db.move_object(8, |p| p + Vec3::new(-0.2, 0.05, 0.3));
        check(&db, &format!("room after move {step}"));
    }
    let scene = gibench_test_support::load("cornell-gltf");
    let bvh = gibench_harness::cpu::bvh::SceneBvh::new(&scene.mesh);
    let frame = gibench_harness::scene::anim::FrameClock::new(&scene.descriptor).frame(0);
    let settings = gibench_barczak::samples::SampleSettings {
        direct: 0,
        indirect: 32,
        bounces: 2,
    };
    let prepared = support::prepared(&scene, &bvh, &frame, settings, 2);
    check(&prepared.db, "cornell-gltf charts");
}

/// The blocker index's search finds exactly the blockers whose boxes a reach does not rule
/// out, as testing every box would (no more: a plane dropped below a box it does not wholly
/// hold would let more through; no fewer), for patch, object and group reaches over a few
/// thousand scattered blockers.
#[test]
fn the_blocker_index_finds_exactly_the_boxes_a_reach_keeps() {
    use gibench_barczak::blocker_index::BlockerIndex;
    use gibench_barczak::visibility::{Blocker, Reach, Shape, Tolerance};
    let mut rng = gibench_test_support::Lcg::new(7);
    let mut at = |scale: f32| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * scale;
    let blockers: Vec<Blocker> = (0..3000)
        .map(|i| {
            let (o, u, v) = (at(10.0), at(0.6), at(0.6));
            Blocker {
                object: i,
                shape: Shape::Polygon(vec![o, o + u, o + u + v, o + v]),
            }
        })
        .collect();
    let index = BlockerIndex::new(&blockers);
    let (mut found, mut kept_some) = (Vec::new(), 0);
    for light in lights() {
        let corners = [at(10.0), at(10.0), at(10.0), at(10.0)];
        let (o, u, v) = (corners[0], Vec3::X * 2.0, Vec3::Z * 2.0);
        let patch = [o, o + u, o + u + v, o + v];
        let tolerance = Tolerance::of_patch(light.position, &patch);
        let reaches = [
            Reach::patch(&light, patch, Vec3::NEG_Y, tolerance),
            Reach::patch(&light, patch, Vec3::Y, tolerance),
            Reach::object(&light, corners[1], 1.5),
            Reach::around(&light, corners[2], 3.0),
        ];
        for reach in &reaches {
            index.query(|lo, hi, mask| reach.cull(lo, hi, mask), &mut found);
            let want: Vec<u32> = (0..blockers.len() as u32)
                .filter(|&b| {
                    let (lo, hi) = index.bounds_of(b);
                    !reach.rules_out(lo, hi)
                })
                .collect();
            assert_eq!(found, want, "{reach:?}");
            kept_some += (!want.is_empty() && want.len() < blockers.len()) as usize;
        }
    }
    assert!(kept_some > 50, "only {kept_some} searches kept some boxes");
}
