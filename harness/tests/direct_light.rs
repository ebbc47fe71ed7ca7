//! The shared direct-light pass against the radiometric convention: per pixel, the GPU's
//! direct irradiance equals I(ω) cos θ / r² with CPU ray-cast visibility, away from shadow
//! boundaries; and Vulkan and GL agree. Needs a GPU adapter (lavapipe and llvmpipe are enough).

use gibench_harness::assets::AssetPaths;
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::passes::light_axis_intensity;
use gibench_harness::runner::{Harness, RunConfig, TimingMode};
use gibench_harness::scene::descriptor::LightKind;
use gibench_harness::scene::Scene;

/// Direct irradiance (red channel) from the GPU and from the CPU, per pixel (None: background).
fn direct_irradiance(backend: &str, frame_index: u32) -> Vec<Option<(f32, f32)>> {
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let gpu = GpuContext::new(&GpuOptions {
        backend: Some(backend.into()),
        adapter: None,
    })
    .expect("a GPU adapter (install mesa-vulkan-drivers)");
    let config = RunConfig {
        resolution: [96, 72],
        frames: 1,
        warmup: 0,
        first_frame: 0,
        timing: TimingMode::Stages,
        seed: 1,
        shadow_size: 256,
    };
    let h = Harness::new(&gpu, &scene, &config).unwrap();
    let frame = h.clock.frame(frame_index);
    h.uniforms.write(&gpu.queue, &frame);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    h.gbuffer.encode(&mut enc, &h.gpu_scene, &h.uniforms);
    h.direct
        .encode_shadow_map(&mut enc, &h.gpu_scene, &h.uniforms, &frame.light);
    h.direct.encode_lighting(&mut enc, &h.gbuffer);
    gpu.queue.submit([enc.finish()]);
    let gpu_e = gibench_harness::image_io::read_rgb_f32(&gpu, &h.direct.irradiance).unwrap();
    let g = h.gbuffer.export(&gpu).unwrap();
    let light = frame.light;
    assert_eq!(light.kind, LightKind::Spot);
    let i0 = light_axis_intensity(&light).x;
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

#[test]
fn direct_pass_matches_closed_form_with_ray_cast_visibility() {
    for frame in [0, 40] {
        let px = direct_irradiance("vulkan", frame);
        let max = px.iter().flatten().map(|(_, c)| *c).fold(0.0f32, f32::max);
        let (mut lit, mut agree, mut shadow_ok, mut shadowed) = (0, 0, 0, 0);
        for (g, c) in px.iter().flatten() {
            if *c > 0.02 * max {
                lit += 1;
                // Half-float storage and the 16-tap kernel at the edges of shadows: 3%.
                if (g - c).abs() <= 0.03 * c {
                    agree += 1;
                }
            } else if *c == 0.0 {
                shadowed += 1;
                if *g <= 0.02 * max {
                    shadow_ok += 1;
                }
            }
        }
        assert!(lit > 500, "frame {frame}: only {lit} lit pixels");
        // Pixels near shadow boundaries (PCF penumbra vs. a single ray) may differ.
        assert!(
            agree * 100 >= lit * 95,
            "frame {frame}: {agree} of {lit} lit pixels agree within 3%"
        );
        assert!(
            shadow_ok * 100 >= shadowed * 95,
            "frame {frame}: {shadow_ok} of {shadowed} shadowed pixels dark"
        );
    }
}

#[test]
fn vulkan_and_gl_agree() {
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
