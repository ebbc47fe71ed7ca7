//! Barczak's scene set-up on a generated room: the light maps minus the occluded partial lights
//! equal summing every light sample with visibility ray-cast against the real geometry (the
//! static mesh and the posed torus mover, whose bounding sphere stands in for it as a blocker).

use gibench_barczak::database::ReceiverShape;
use gibench_barczak::lightmap::{contribution, texel_position};
use gibench_barczak::samples::SampleSettings;
use gibench_barczak::setup::{prepare, LightMapSize, CHART_LEVELS, MAX_CHARTS};
use gibench_barczak::visibility::LightState;
use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::glam::Vec3;
use gibench_harness::scene::anim::FrameClock;

const RES: u32 = 3;

#[test]
fn light_maps_of_the_pillar_room_agree_with_ray_casts() {
    light_maps_agree_with_ray_casts("barczak-pillars", 16);
}

/// The Cornell box records no patches: one per triangle (its measured quads are not planar).
#[test]
fn light_maps_of_the_cornell_box_agree_with_ray_casts() {
    light_maps_agree_with_ray_casts("cornell-area", 16);
}

fn light_maps_agree_with_ray_casts(name: &str, direct: u32) {
    let scene = gibench_test_support::load(name);
    let bvh = SceneBvh::new(&scene.mesh);
    let frame = FrameClock::new(&scene.descriptor).frame(0);
    let settings = SampleSettings {
        direct,
        indirect: 48,
        bounces: 3,
    };
    let bz = prepare(
        &scene,
        &bvh,
        &frame,
        &frame.light,
        settings,
        LightMapSize {
            res: RES,
            max_bytes: u64::MAX,
        },
        MAX_CHARTS,
    )
    .unwrap();
    assert_eq!(bz.db.lights.len(), 64);
    // The database's size as a run reports it (counters `patches` and `leaves`): every
    // receiver patch once, and the 4^levels leaves of its quadtree.
    let expected = scene.receiver_patches(CHART_LEVELS, MAX_CHARTS).unwrap();
    let leaves: usize = expected.iter().map(|p| 4usize.pow(p.levels)).sum();
    assert_eq!(bz.patches_and_leaves(), (expected.len(), leaves));
    // The real occluders: the static mesh and the torus where frame 0 puts it.
    let mut world = scene.mesh.clone();
    for (k, mover) in scene.movers.iter().enumerate() {
        let mut posed = mover.mesh.clone();
        for p in &mut posed.positions {
            *p = frame.movers[k].transform_point3(*p);
        }
        world.append(&posed, 0);
    }
    let real = SceneBvh::new(&world);
    let eps = 1e-4 * scene.extent.diagonal;
    let (mut worst, mut top, mut subtracted) = (0f32, 0f32, 0);
    for (r, receiver) in bz.db.receivers.iter().enumerate() {
        let ReceiverShape::Patch(tree) = &receiver.shape else {
            continue;
        };
        for n in tree.leaves() {
            for j in 0..RES {
                for i in 0..RES {
                    let x = texel_position(tree, n, RES, i, j);
                    let mut shown = bz.light_maps.texels(r, n)[(j * RES + i) as usize];
                    let mut truth = Vec3::ZERO;
                    for (l, light) in bz.db.lights.iter().enumerate() {
                        let c = contribution(light, bz.flux[l], x, tree.normal);
                        if c == Vec3::ZERO {
                            continue;
                        }
                        let ln = light.normal.unwrap();
                        let visible =
                            !real.occluded(x + tree.normal * eps, light.position + ln * eps, 0.0);
                        if visible {
                            truth += c;
                        }
                        if bz.db.state(r, n, l) == LightState::Partial && !visible {
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
    assert!(subtracted > 50, "hardly any occlusion ({subtracted})");
    assert!(
        worst <= 1e-4 * top,
        "light map − occluded partial lights is {worst} off the ray-cast sum (largest {top})"
    );
}

/// A scene that records no patches gets its planar charts as patches (cornell-gltf: 34
/// triangles, its walls' quads and the boxes' faces, 18 charts, each holding its triangles);
/// more charts than allowed is an error naming the scene and the counts.
#[test]
fn scenes_without_patches_get_charts_up_to_a_limit() {
    let scene = gibench_test_support::load("cornell-gltf");
    assert!(scene.patches.is_empty());
    let patches = scene.receiver_patches(2, 1000).unwrap();
    assert_eq!(patches.len(), 18);
    let held: usize = patches
        .iter()
        .map(|p| p.chart.as_ref().unwrap().triangles.len())
        .sum();
    assert_eq!(held, scene.mesh.triangle_count());
    let err = scene.receiver_patches(2, 17).unwrap_err().to_string();
    assert!(
        err.contains("'cornell-gltf'") && err.contains("18 planar charts") && err.contains("17"),
        "{err}"
    );
}
