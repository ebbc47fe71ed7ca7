//! The shared direct-light pass against the radiometric convention: per pixel, the GPU's
//! direct irradiance equals I(ω) cos θ / r² with CPU ray-cast visibility, away from shadow
//! boundaries; and Vulkan and GL agree. Needs a GPU adapter (lavapipe and llvmpipe are enough).

use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::scene::assets::AssetPaths;

use gibench_harness::run::runner::Harness;
use gibench_harness::scene::descriptor::LightKind;
use gibench_harness::scene::Scene;

/// Direct irradiance (red channel) from the GPU and from the CPU, per pixel (None: background).
fn direct_irradiance(backend: &str, frame_index: u32) -> Vec<Option<(f32, f32)>> {
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let gpu = GpuContext::new(&GpuOptions {
        backend: Some(backend.into()),
        ..Default::default()
    })
    .expect("a GPU adapter (install mesa-vulkan-drivers)");
    let config = gibench_test_support::one_frame([96, 72]).build();
    let h = Harness::new(&gpu, &scene, &config).unwrap();
    let frame = h.clock.frame(frame_index);
    h.uniforms.write(&gpu.queue, &frame);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    h.gbuffer.encode(&mut enc, &h.gpu_scene, &h.uniforms);
    h.direct
        .encode_shadow_map(&mut enc, &h.gpu_scene, &h.uniforms, &frame.light);
    h.direct.encode_lighting(&mut enc, &h.gbuffer);
    gpu.queue.submit([enc.finish()]);
    let gpu_e = gibench_harness::gpu::image_io::read_rgb_f32(&gpu, &h.direct.irradiance).unwrap();
    let g = h.gbuffer.export(&gpu).unwrap();
    let light = frame.light;
    assert_eq!(light.kind, LightKind::Spot);
    let i0 = light.axis_intensity().x;
    (0..g.positions.len())
        .map(|i| {
            let p = g.positions[i]?;
            let n = g.normals[i];
            let to_light = light.position - p;
            let r2 = to_light.length_squared();
            let l = to_light / r2.sqrt();
            let cos_r = n.dot(l).max(0.0);
            let cos_l = (-l).dot(light.direction).max(0.0);
            let visible = !h.bvh.occluded(p + n * 0.5, light.position, 1e-4);
            let cpu = if visible {
                i0 * cos_l * cos_r / r2
            } else {
                0.0
            };
            Some((gpu_e[i][0], cpu))
        })
        .collect()
}

/// The GPU `direct` technique's direct irradiance against the CPU reference's direct
/// component on the Cornell box (this pins light units, falloff and shadows across GPU and
/// CPU). Bound: mean relative error under 2 % over lit pixels at least two pixels away from a
/// shadow boundary of the reference (the 16-tap PCF penumbra is 4 shadow-map texels wide).
#[test]
fn direct_pass_matches_reference_direct() {
    direct_pass_matches_reference_direct_on("cornell");
}

/// The same bound for the sun (directional light, orthographic shadow map fitted to the scene).
#[test]
fn direct_pass_matches_reference_direct_sun() {
    direct_pass_matches_reference_direct_on("cornell-sun");
}

fn direct_pass_matches_reference_direct_on(scene_name: &str) {
    use gibench_harness::cpu::reference::{render_reference, ReferenceSettings};
    let scene = Scene::load_named(scene_name, &AssetPaths::standard(None)).unwrap();
    let gpu = GpuContext::new(&GpuOptions::default()).expect("a GPU adapter (Vulkan or GL)");
    let [w, h] = [128u32, 96];
    let config = gibench_test_support::one_frame([w, h])
        .shadow_size(512)
        .build();
    let harness = Harness::new(&gpu, &scene, &config).unwrap();
    let info = gibench_direct_info();
    let params = info.parse_params(&[]).unwrap();
    for frame_index in [0, 40] {
        let prepared = harness.prepare(&info, &params, &config).unwrap();
        let (mut technique, compose) = harness.build(&info, &params, &config, &prepared).unwrap();
        let mut profiler = gibench_harness::gpu::profiler::Profiler::new(
            &gpu,
            gibench_harness::gpu::profiler::ProfileMode::Stages,
        );
        let frame = harness.clock.frame(frame_index);
        harness
            .render_frame(technique.as_mut(), &compose, &mut profiler, &frame, false)
            .unwrap();
        let gpu_e =
            gibench_harness::gpu::image_io::read_rgb_f32(&gpu, &harness.direct.irradiance).unwrap();
        let settings = ReferenceSettings {
            spp: 1,
            bounces: 1,
            seed: 1,
        };
        let r = render_reference(&scene, &frame, [w, h], &settings);
        let lit = |x: i64, y: i64| {
            let (x, y) = (x.clamp(0, w as i64 - 1), y.clamp(0, h as i64 - 1));
            let i = (y * w as i64 + x) as usize;
            r.hit[i] && r.direct[i].x > 0.0
        };
        let (mut n, mut sum_rel) = (0usize, 0.0f64);
        for y in 0..h as i64 {
            for x in 0..w as i64 {
                let i = (y * w as i64 + x) as usize;
                if !lit(x, y)
                    || r.direct[i].x < 1e-3 * r.direct.iter().map(|d| d.x).fold(0.0, f32::max)
                {
                    continue;
                }
                let boundary = (-2..=2).any(|dy| (-2..=2).any(|dx| !lit(x + dx, y + dy)));
                if boundary {
                    continue;
                }
                n += 1;
                sum_rel += ((gpu_e[i][0] - r.direct[i].x).abs() / r.direct[i].x) as f64;
            }
        }
        let mean_rel = sum_rel / n as f64;
        eprintln!(
            "{scene_name} frame {frame_index}: mean relative error {mean_rel:.5} over {n} pixels"
        );
        assert!(
            n > 2000,
            "frame {frame_index}: only {n} lit interior pixels"
        );
        assert!(
            mean_rel < 0.02,
            "frame {frame_index}: mean relative error {mean_rel:.4} over {n} pixels"
        );
    }
}

/// The `direct` technique's registry entry, built here without the root crate.
fn gibench_direct_info() -> gibench_harness::kit::technique::TechniqueInfo {
    gibench_direct::INFO
}

#[test]
fn vulkan_and_gl_agree() {
    let present = gibench_test_support::available_backends();
    if present.len() < 2 {
        gibench_test_support::say_uncaptured(&format!("vulkan_and_gl_agree: only {present:?} present on this machine; the backends are not compared"));
        return;
    }
    let a = direct_irradiance("vulkan", 25);
    let b = direct_irradiance("gl", 25);
    assert_eq!(a.len(), b.len());
    let max = a.iter().flatten().map(|(g, _)| *g).fold(0.0f32, f32::max);
    let (mut n, mut close) = (0, 0);
    for (x, y) in a.iter().zip(&b) {
        match (x, y) {
            (Some((ga, _)), Some((gb, _))) => {
                n += 1;
                if (ga - gb).abs() <= 0.01 * max {
                    close += 1;
                }
            }
            (None, None) => {}
            _ => panic!("the backends disagree on which pixels hold geometry"),
        }
    }
    assert!(
        close * 100 >= n * 99,
        "{close} of {n} pixels agree within 1% of the maximum"
    );
}
