//! Light samples: the direct set is the area light point-sampled; the indirect set's walks run
//! to the bounce limit and are normalised by the walks started.

use gibench_barczak::samples::{generate, SampleSettings};
use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::glam::Vec3;
use gibench_harness::scene::anim::LightPose;
use gibench_harness::scene::descriptor::LightKind;
use gibench_harness::scene::Scene;

use gibench_test_support::{closed_box_mesh, material, scene};

const ALBEDO: Vec3 = Vec3::new(0.5, 0.6, 0.7);
const BOX: Vec3 = Vec3::new(4.0, 3.0, 5.0);

/// A closed 4 × 3 × 5 box of inward-facing quads of albedo [`ALBEDO`].
fn closed_box() -> Scene {
    scene(closed_box_mesh(BOX, 0), vec![material("box", ALBEDO)])
}

/// A 1.2 × 0.8 area light just under the ceiling, facing down.
fn area_light() -> LightPose {
    LightPose {
        kind: LightKind::Area,
        position: Vec3::new(1.9, 2.95, 2.3),
        direction: Vec3::NEG_Y,
        power: Vec3::new(100.0, 200.0, 50.0),
        size: [1.2, 0.8],
    }
}

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    ((a - b).abs() / b.abs()).max_element() <= tol
}

#[test]
fn direct_samples_are_the_area_light_point_sampled() {
    let scene = closed_box();
    let bvh = SceneBvh::new(&scene.mesh);
    let light = area_light();
    let s = generate(
        &scene,
        &bvh,
        &light,
        SampleSettings {
            direct: 25,
            indirect: 0,
            bounces: 5,
        },
    )
    .unwrap();
    assert_eq!(s.direct.len(), 25);
    let total: Vec3 = s.direct.iter().map(|v| v.flux).sum();
    assert!(close(total, light.power, 1e-5), "{total}");
    let (hu, hv) = light.area_half_extents().unwrap();
    let mut spread = Vec3::ZERO;
    for v in &s.direct {
        let d = v.position - light.position;
        assert!(d.dot(hu).abs() <= hu.length_squared() * 1.0001);
        assert!(d.dot(hv).abs() <= hv.length_squared() * 1.0001);
        assert!(d.dot(Vec3::Y).abs() < 1e-5 && v.normal == Vec3::NEG_Y);
        spread = spread.max(d.abs());
    }
    // Spread over the rectangle, not bunched at its centre.
    assert!(spread.x > 0.5 && spread.z > 0.3, "{spread}");
}

/// In a closed box every walk reaches the bounce limit, so bounce j carries Φ ρ^j × (walks
/// reaching j) / (walks started): exactly Φ ρ^j when the count is a multiple of the limit, and
/// 33/34 of it for bounces 2 and 3 when 100 samples need 34 walks of 3.
#[test]
fn indirect_walks_run_to_the_limit_and_are_normalised_by_walks_started() {
    let scene = closed_box();
    let bvh = SceneBvh::new(&scene.mesh);
    let light = area_light();
    for (count, walks) in [(192u32, 64u32), (100, 34)] {
        let s = generate(
            &scene,
            &bvh,
            &light,
            SampleSettings {
                direct: 0,
                indirect: count,
                bounces: 3,
            },
        )
        .unwrap();
        assert_eq!(s.indirect.len(), count as usize);
        assert_eq!(s.walks, walks);
        for j in 1..=3u32 {
            let flux: Vec3 = s
                .indirect
                .iter()
                .filter(|v| v.bounce == j)
                .map(|v| v.flux)
                .sum();
            let reaching = s.indirect.iter().filter(|v| v.bounce == j).count() as f32;
            let expected = light.power * ALBEDO.powf(j as f32) * reaching / walks as f32;
            assert!(
                close(flux, expected, 1e-4),
                "{count} samples, bounce {j}: {flux} vs {expected}"
            );
        }
        if count == 100 {
            assert_eq!(s.indirect.iter().filter(|v| v.bounce == 1).count(), 34);
            assert_eq!(s.indirect.iter().filter(|v| v.bounce == 3).count(), 33);
        }
    }
}

#[test]
fn bad_settings_name_the_parameter() {
    let scene = closed_box();
    let bvh = SceneBvh::new(&scene.mesh);
    let spot = LightPose {
        kind: LightKind::Spot,
        size: [0.0, 0.0],
        ..area_light()
    };
    let err = generate(
        &scene,
        &bvh,
        &spot,
        SampleSettings {
            direct: 4,
            indirect: 10,
            bounces: 2,
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("set=direct") && err.contains("area light"),
        "{err}"
    );
    let err = generate(
        &scene,
        &bvh,
        &area_light(),
        SampleSettings {
            direct: 0,
            indirect: 0,
            bounces: 2,
        },
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("vpls"), "{err}");
    let err = generate(
        &scene,
        &bvh,
        &area_light(),
        SampleSettings {
            direct: 0,
            indirect: 5,
            bounces: 0,
        },
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("bounces"), "{err}");
    // A spot light with only indirect samples is fine.
    assert_eq!(
        generate(
            &scene,
            &bvh,
            &spot,
            SampleSettings {
                direct: 0,
                indirect: 10,
                bounces: 2
            }
        )
        .unwrap()
        .indirect
        .len(),
        10
    );
}
