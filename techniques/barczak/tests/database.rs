//! The movers' visibility database: after every step of two movers along their paths, the
//! incrementally updated database equals one rebuilt from scratch on the moved scene, the
//! light-map changes it reports are exactly the leaves whose lights changed between lit and
//! unlit, and it makes fewer tests than the rebuild.

use gibench_barczak::database::{Receiver, ReceiverShape, VisibilityDatabase};
use gibench_barczak::visibility::{Blocker, LightState, PatchTree, PointLight, Shape};
use glam::{Mat3, Vec3};

/// A 6 × 3 × 6 room: floor (split three times), walls and ceiling (split once), a table top
/// (both a receiver and a blocker), a box mover (six faces, each a receiver and a blocker)
/// and a sphere mover (a complex object: its bounding sphere).
fn room() -> (Vec<Receiver>, Vec<Blocker>) {
    let mut receivers = Vec::new();
    let mut blockers = Vec::new();
    let mut add = |object: u32, c: [Vec3; 4], n: Vec3, levels: u32, blocks: bool| {
        receivers.push(Receiver {
            object,
            shape: ReceiverShape::Patch(PatchTree::new(object, c, n, levels)),
        });
        if blocks {
            blockers.push(Blocker {
                object,
                shape: Shape::Polygon(c.to_vec()),
            });
        }
    };
    let v = Vec3::new;
    let (w, h) = (6.0, 3.0);
    add(
        0,
        [v(0., 0., 0.), v(0., 0., w), v(w, 0., w), v(w, 0., 0.)],
        Vec3::Y,
        3,
        false,
    );
    add(
        1,
        [v(0., h, 0.), v(w, h, 0.), v(w, h, w), v(0., h, w)],
        Vec3::NEG_Y,
        1,
        false,
    );
    add(
        2,
        [v(0., 0., 0.), v(w, 0., 0.), v(w, h, 0.), v(0., h, 0.)],
        Vec3::Z,
        1,
        true,
    );
    add(
        3,
        [v(0., 0., w), v(0., h, w), v(w, h, w), v(w, 0., w)],
        Vec3::NEG_Z,
        1,
        true,
    );
    add(
        4,
        [v(0., 0., 0.), v(0., h, 0.), v(0., h, w), v(0., 0., w)],
        Vec3::X,
        1,
        true,
    );
    add(
        5,
        [v(w, 0., 0.), v(w, 0., w), v(w, h, w), v(w, h, 0.)],
        Vec3::NEG_X,
        1,
        true,
    );
    // Table top at 1 m, both sides.
    let top = [
        v(2., 1., 2.),
        v(2., 1., 3.5),
        v(3.5, 1., 3.5),
        v(3.5, 1., 2.),
    ];
    add(6, top, Vec3::Y, 1, true);
    let mut under = top;
    under.reverse();
    add(6, under, Vec3::NEG_Y, 1, false);
    // The box mover, object 7: 0.6 m cube at (1, 0.3..0.9, 1).
    let cube = |x: f32, y: f32, z: f32| v(0.7 + 0.6 * x, 0.3 + 0.6 * y, 0.7 + 0.6 * z);
    let faces = [
        (
            [(0., 0., 0.), (1., 0., 0.), (1., 0., 1.), (0., 0., 1.)],
            Vec3::NEG_Y,
        ),
        (
            [(0., 1., 0.), (0., 1., 1.), (1., 1., 1.), (1., 1., 0.)],
            Vec3::Y,
        ),
        (
            [(0., 0., 0.), (0., 0., 1.), (0., 1., 1.), (0., 1., 0.)],
            Vec3::NEG_X,
        ),
        (
            [(1., 0., 0.), (1., 1., 0.), (1., 1., 1.), (1., 0., 1.)],
            Vec3::X,
        ),
        (
            [(0., 0., 0.), (0., 1., 0.), (1., 1., 0.), (1., 0., 0.)],
            Vec3::NEG_Z,
        ),
        (
            [(0., 0., 1.), (1., 0., 1.), (1., 1., 1.), (0., 1., 1.)],
            Vec3::Z,
        ),
    ];
    for (c, n) in faces {
        add(7, c.map(|(x, y, z)| cube(x, y, z)), n, 0, true);
    }
    // The sphere mover, object 8 (the bunny's stand-in).
    receivers.push(Receiver {
        object: 8,
        shape: ReceiverShape::Object {
            center: v(4.5, 0.5, 4.5),
            radius: 0.45,
        },
    });
    blockers.push(Blocker {
        object: 8,
        shape: Shape::Sphere {
            center: v(4.5, 0.5, 4.5),
            radius: 0.45,
        },
    });
    (receivers, blockers)
}

/// Lights on the room's surfaces facing in (as light samples are), one omni near the ceiling.
fn lights() -> Vec<PointLight> {
    let mut out = vec![PointLight {
        position: Vec3::new(3.1, 2.7, 2.9),
        normal: None,
    }];
    let mut k = 1u32;
    let mut next = || {
        k = k.wrapping_mul(1_103_515_245).wrapping_add(12345);
        (k >> 8) as f32 / (1u32 << 24) as f32
    };
    for i in 0..48 {
        let (a, b) = (0.2 + 5.6 * next(), 0.2 + 5.6 * next());
        let (position, normal) = match i % 4 {
            0 => (Vec3::new(a, 0.001, b), Vec3::Y),
            1 => (Vec3::new(a, 2.999, b), Vec3::NEG_Y),
            2 => (Vec3::new(0.001, 0.2 + 2.6 * next(), b), Vec3::X),
            _ => (Vec3::new(a, 0.2 + 2.6 * next(), 5.999), Vec3::NEG_Z),
        };
        out.push(PointLight {
            position,
            normal: Some(normal),
        });
    }
    out
}

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
    let (receivers, blockers) = room();
    let (mut db, _) = VisibilityDatabase::build(lights(), receivers, blockers);
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
        let (fresh, tests) =
            VisibilityDatabase::build(db.lights.clone(), db.receivers.clone(), db.blockers.clone());
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
