//! `keller-full` against the CPU reference: one-bounce indirect irradiance on the Cornell box.
//! Stated in the README: with 256 VPLs and `clamp=3`, relative MSE below 0.1 without
//! interleaving (1x1 tiles) and below 0.25 with 4x4 tiles, mean irradiance within 0.90–1.00 of
//! the reference's (VPL clamping and shadow-map bias only darken). Also: colour bleeds from the
//! red wall.

use gibench_harness::cpu::reference::{render_reference, ReferenceSettings};
use gibench_harness::glam::Vec3;
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::run::runner::Harness;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::Scene;

#[test]
fn keller_full_matches_the_reference_one_bounce() {
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let gpu = GpuContext::new(&GpuOptions::default()).expect("a GPU adapter (Vulkan or GL)");
    let size = [128u32, 96];
    let config = gibench_test_support::one_frame(size).build();
    let h = Harness::new(&gpu, &scene, &config).unwrap();
    let frame = h.clock.frame(0);
    let r = render_reference(
        &scene,
        &frame,
        size,
        &ReferenceSettings {
            spp: 256,
            bounces: 1,
            seed: 0,
        },
    );
    let info = &gibench_keller::FULL;
    for (tiles, bound) in [("1x1", 0.1), ("4x4", 0.25)] {
        let kv = |k: &str, v: &str| (k.to_string(), v.to_string());
        let params = info
            .parse_params(&[
                kv("vpls", "256"),
                kv("clamp", "3"),
                kv("tiles", tiles),
                kv("vpl-map-size", "256"),
            ])
            .unwrap();
        let prepared = h.prepare(info, &params, &config).unwrap();
        let (mut t, compose) = h.build(info, &params, &config, &prepared).unwrap();
        let mut profiler = gibench_harness::gpu::profiler::Profiler::new(
            &gpu,
            gibench_harness::gpu::profiler::ProfileMode::Stages,
        );
        h.render_frame(t.as_mut(), &compose, &mut profiler, &frame, false)
            .unwrap();
        let e: Vec<Vec3> = gibench_harness::gpu::image_io::read_rgb_f32(&gpu, t.output().texture())
            .unwrap()
            .into_iter()
            .map(Vec3::from)
            .collect();
        let rel = gibench_harness::measure::metrics::relative_mse(&e, &r.one_bounce, &r.hit);
        let (mut a, mut b) = (0.0f64, 0.0f64);
        for ((t, x), hit) in e.iter().zip(&r.one_bounce).zip(&r.hit) {
            if *hit {
                a += t.element_sum() as f64;
                b += x.element_sum() as f64;
            }
        }
        eprintln!(
            "keller-full 256 VPLs, tiles {tiles}: relMSE {rel:.4}, mean ratio {:.4}",
            a / b
        );
        assert!(rel < bound, "tiles {tiles}: relative MSE {rel}");
        assert!(
            (0.90..=1.0).contains(&(a / b)),
            "tiles {tiles}: mean ratio {}",
            a / b
        );
        // Colour bleeding: where the reference's bounce light is clearly red, so is keller's.
        let reddish: Vec<usize> = (0..e.len())
            .filter(|&i| r.hit[i] && r.one_bounce[i].x > 2.0 * r.one_bounce[i].y)
            .collect();
        assert!(reddish.len() > 100, "the reference shows red bleeding");
        let red = reddish.iter().filter(|&&i| e[i].x > 1.5 * e[i].y).count();
        assert!(
            red * 10 >= reddish.len() * 9,
            "tiles {tiles}: only {red} of {} red-bleed pixels are red",
            reddish.len()
        );
    }
}
