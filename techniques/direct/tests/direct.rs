//! `direct`, the baseline, through the harness on every portable backend present: it takes no
//! parameters and adds no stages; its indirect irradiance is exactly zero at every pixel, at
//! the run's resolution; and the direct light it leaves to the harness lights a diffuse floor
//! under an omni light as the light model's closed form says, E = Φ/(4π) · cos θ / r².

use gibench_harness::glam::Vec3;
use gibench_harness::run::runner::{
    Harness, STAGE_COMPOSE, STAGE_DIRECT_LIGHT, STAGE_DIRECT_SHADOW_MAP, STAGE_GBUFFER,
};
use gibench_harness::scene::{Material, Mesh, Scene};
use gibench_test_support::{each_backend, kv, quad, read_rgb, run_config, Rendered};

const SIZE: [u32; 2] = [64, 48];
/// The omni light's flux per channel and its height above the floor's centre.
const POWER: [f32; 3] = [12.0, 8.0, 4.0];
const HEIGHT: f32 = 1.0;

/// A 4 × 4 grey floor at y = 0 under an omni light `HEIGHT` above its centre, seen from above
/// at an angle.
fn lit_floor() -> Scene {
    let json = r#"{
        "name": "lit-floor",
        "mesh": { "generated": "cornell-box" },
        "camera": { "fov_y_deg": 60, "near": 0.1,
                    "path": { "keys": [ { "time": 0, "position": [0, 2.5, 2.5], "target": [0, 0, 0] } ] } },
        "light": { "kind": "omni", "power": [12, 8, 4],
                   "path": { "keys": [ { "time": 0, "position": [0, 1, 0] } ] } },
        "settings": { "filter_distance": 1 }
    }"#;
    let mut mesh = Mesh::default();
    quad(
        &mut mesh,
        [
            Vec3::new(-2.0, 0.0, -2.0),
            Vec3::new(-2.0, 0.0, 2.0),
            Vec3::new(2.0, 0.0, 2.0),
            Vec3::new(2.0, 0.0, -2.0),
        ],
        Vec3::Y,
        0,
    );
    let grey = Material::plain("grey", Vec3::splat(0.5));
    gibench_test_support::scene_from_json(json, mesh, vec![grey])
}

fn render(harness: &Harness, pairs: &[(&str, &str)]) -> Rendered {
    Rendered::run(
        harness,
        &gibench_direct::INFO,
        pairs,
        &run_config(SIZE, 256),
        2,
    )
    .unwrap()
}

/// Every pixel of the output is +0.0 (bit for bit) and there is one per pixel of the run; the
/// output is not the direct light's texture either (the floor is lit). Caught by: an output
/// cleared to anything else or written, the direct irradiance returned as the indirect, a
/// texture of another size.
#[test]
fn the_indirect_irradiance_is_zero_at_every_pixel() {
    let scene = lit_floor();
    each_backend("direct", &scene, SIZE, 256, |backend, _, harness| {
        let out = render(harness, &[]);
        assert_eq!(
            out.indirect.len(),
            (SIZE[0] * SIZE[1]) as usize,
            "{backend}"
        );
        for (i, e) in out.indirect.iter().enumerate() {
            assert!(
                e.to_array().iter().all(|c| c.to_bits() == 0),
                "{backend}: pixel {i} holds {e}"
            );
        }
    });
}

/// Per floor pixel (the G-buffer's position), the direct irradiance is the omni light's
/// Φ/(4π) · cos θ / r² per channel: within 1 % everywhere, 0.2 % on average (measured on
/// llvmpipe: 0.05 % on average, 0.1 % worst; the irradiance is a half float). Nothing
/// stands between the light and the floor, so the shadow map must not darken a pixel. Caught
/// by: the omni light's intensity taken as a spot's Φ/π, the cosine dropped, the falloff as
/// 1/r.
#[test]
fn a_diffuse_floor_under_an_omni_light_gets_the_closed_form_irradiance() {
    let scene = lit_floor();
    let power = Vec3::from(POWER);
    let light = Vec3::new(0.0, HEIGHT, 0.0);
    each_backend("direct", &scene, SIZE, 256, |backend, gpu, harness| {
        render(harness, &[]);
        let direct = read_rgb(gpu, &harness.direct.irradiance);
        let texels = harness.gbuffer.export(gpu).unwrap();
        let (mut n, mut sum, mut worst) = (0usize, 0f64, 0f32);
        for (i, p) in texels.positions.iter().enumerate() {
            let Some(p) = p else { continue };
            let to_light = light - *p;
            let r2 = to_light.length_squared();
            let cos = to_light.y / r2.sqrt();
            let want = power / (4.0 * std::f32::consts::PI) * cos / r2;
            let rel = ((direct[i] - want).abs() / want).max_element();
            worst = worst.max(rel);
            sum += rel as f64;
            n += 1;
        }
        let mean = sum / n as f64;
        eprintln!("{backend}: {n} floor pixels, relative error mean {mean:.5}, worst {worst:.5}");
        assert!(
            n > SIZE[0] as usize * SIZE[1] as usize / 2,
            "{backend}: {n} floor pixels"
        );
        assert!(
            worst < 0.01 && mean < 0.002,
            "{backend}: mean {mean}, worst {worst}"
        );
    });
}

/// The baseline declares no parameters, so any given is refused naming it; and a run records
/// only the harness's stages and counter: nothing of its own.
#[test]
fn no_parameters_and_no_stages_of_its_own() {
    let info = &gibench_direct::INFO;
    assert_eq!(info.param_specs().count(), 0);
    assert!(info.parse_params(&[]).is_ok());
    let e = info.parse_params(&kv(&[("vpls", "4")])).unwrap_err();
    assert!(e.to_string().contains("vpls"), "{e}");
    let scene = lit_floor();
    each_backend("direct", &scene, SIZE, 256, |backend, _, harness| {
        let out = render(harness, &[]);
        let want = [
            STAGE_GBUFFER,
            STAGE_DIRECT_SHADOW_MAP,
            STAGE_DIRECT_LIGHT,
            STAGE_COMPOSE,
        ];
        assert_eq!(out.stages, want, "{backend}");
        let counters: Vec<&str> = out.counters.keys().map(String::as_str).collect();
        assert_eq!(counters, ["direct-shadow-faces"], "{backend}");
    });
}
