//! Light maps: the map of a leaf minus the contributions of its partial lights that a ray cast
//! finds occluded equals summing every light with its visibility, at every texel of every leaf,
//! before and after the movers move; and maps updated by single lights equal maps baked anew.

use gibench_barczak::database::{ReceiverShape, VisibilityDatabase};
use gibench_barczak::lightmap::{contribution, texel_position, LightMaps};
use gibench_barczak::visibility::{segment_hits, LightState};
use glam::{Mat3, Vec3};

use crate::support;
use support::{lights, room};

const RES: u32 = 4;

fn fluxes(n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|i| {
            Vec3::new(
                1.0 + (i % 3) as f32,
                2.0 + (i % 5) as f32,
                1.5 + (i % 7) as f32,
            )
        })
        .collect()
}

/// The largest difference, relative to the largest irradiance, between light map − occluded
/// partial lights and the sum of all lights with visibility, over every texel.
fn worst_error(db: &VisibilityDatabase, maps: &LightMaps, flux: &[Vec3]) -> (f32, usize) {
    let (mut worst, mut top, mut subtracted) = (0f32, 0f32, 0usize);
    for (r, receiver) in db.receivers.iter().enumerate() {
        let ReceiverShape::Patch(tree) = &receiver.shape else {
            continue;
        };
        for n in tree.leaves() {
            for j in 0..RES {
                for i in 0..RES {
                    let x = texel_position(tree, n, RES, i, j);
                    let visible = |l: usize| {
                        !db.blockers
                            .iter()
                            .filter(|b| b.object != receiver.object)
                            .any(|b| segment_hits(x, db.lights[l].position, &b.shape, 1e-6))
                    };
                    let mut truth = Vec3::ZERO;
                    let mut shown = maps.texels(r, n)[(j * RES + i) as usize];
                    for (l, (light, f)) in db.lights.iter().zip(flux).enumerate() {
                        let c = contribution(light, *f, x, tree.normal);
                        let v = visible(l);
                        if v {
                            truth += c;
                        }
                        if db.state(r, n, l) == LightState::Partial && !v {
                            shown -= c;
                            subtracted += 1;
                        }
                    }
                    worst = worst.max((shown - truth).abs().max_element());
                    top = top.max(truth.max_element());
                }
            }
        }
    }
    (worst / top, subtracted)
}

#[test]
fn light_map_minus_occluded_partial_lights_equals_summing_with_visibility() {
    let (receivers, blockers) = room();
    let flux = fluxes(lights().len());
    let (mut db, _) = VisibilityDatabase::build(lights(), receivers, blockers);
    let mut maps = LightMaps::bake(&db, &flux, RES);
    let (error, subtracted) = worst_error(&db, &maps, &flux);
    assert!(error < 1e-5, "static: error {error}");
    assert!(
        subtracted > 100,
        "hardly any occlusion to subtract ({subtracted})"
    );
    for step in 1..=10 {
        let (object, update) = if step % 2 == 0 {
            (7, db.move_object(7, |p| p + Vec3::new(0.3, 0.0, 0.25)))
        } else {
            let centre = Vec3::new(3.0, 0.0, 3.0);
            let turn = Mat3::from_rotation_y(0.4);
            (8, db.move_object(8, move |p| centre + turn * (p - centre)))
        };
        maps.apply(&db, &flux, &update.light_map, object);
        let (error, _) = worst_error(&db, &maps, &flux);
        assert!(error < 1e-5, "step {step}: error {error}");
        let fresh = LightMaps::bake(&db, &flux, RES);
        for (r, receiver) in db.receivers.iter().enumerate() {
            for n in 0..receiver.node_count() {
                for (a, b) in maps.texels(r, n).iter().zip(fresh.texels(r, n)) {
                    assert!(
                        (*a - *b).abs().max_element() <= 1e-5 * b.max_element().max(1e-3),
                        "step {step}: {a} vs {b}"
                    );
                }
            }
        }
    }
}
