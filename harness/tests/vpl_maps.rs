//! VPL depth maps, paraboloid and cube: rendering a VPL's map and looking receivers up in it is
//! a round trip through the projection; its visibility must agree with CPU ray casts. Runs on
//! Vulkan and GL.

use gibench_harness::assets::AssetPaths;
use gibench_harness::glam::Vec3;
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::passes::{
    FilterSettings, Interleave, VplLighting, VplMapKind, VplShadowSettings,
};
use gibench_harness::runner::{Harness, RunConfig, TimingMode};
use gibench_harness::scene::Scene;
use gibench_harness::vpl::Vpl;

/// Per pixel: (GPU irradiance from one VPL with visibility, CPU unoccluded irradiance, CPU visible).
fn one_vpl(backend: &str, kind: VplMapKind, vpl: Vpl) -> Vec<Option<(f32, f32, bool)>> {
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let gpu = GpuContext::new(&GpuOptions {
        backend: Some(backend.into()),
        adapter: None,
    })
    .expect("a GPU adapter");
    let [w, h] = [96u32, 72];
    let config = RunConfig {
        resolution: [w, h],
        frames: 1,
        warmup: 0,
        first_frame: 0,
        timing: TimingMode::Stages,
        seed: 1,
        shadow_size: 64,
    };
    let harness = Harness::new(&gpu, &scene, &config).unwrap();
    let frame = harness.clock.frame(0);
    harness.uniforms.write(&gpu.queue, &frame);
    let output = gibench_harness::passes::indirect_target(&gpu.device, [w, h], true);
    // 1x1 tiles and a filter that never averages: the output is the raw accumulation.
    let interleave = Interleave::new(
        &gpu,
        &harness.gbuffer,
        (1, 1),
        FilterSettings {
            alpha: 0.0,
            beta: 2.0,
        },
        &output,
    )
    .unwrap();
    let lighting = VplLighting::new(
        &gpu,
        &harness.gpu_scene,
        &harness.uniforms,
        &interleave,
        VplShadowSettings {
            kind,
            size: 512,
            depth_bits: 32,
            capacity: 4,
            clamp_distance: 0.0,
            bias: 0.01,
        },
    )
    .unwrap();
    lighting.write_view(&gpu.queue, 2, &vpl);
    lighting.write_vpls(&gpu.queue, &[(2, vpl)]);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    harness
        .gbuffer
        .encode(&mut enc, &harness.gpu_scene, &harness.uniforms);
    lighting.encode_shadow_maps(&mut enc, &harness.gpu_scene, &harness.uniforms, &[2], true);
    interleave.encode_split(&mut enc);
    lighting.encode_accumulate(&mut enc, &interleave);
    interleave.encode_combine(&mut enc);
    interleave.encode_filter(&mut enc);
    gpu.queue.submit([enc.finish()]);
    let e = gibench_harness::image_io::read_rgb_f32(&gpu, &output).unwrap();
    let g = harness.gbuffer.export(&gpu).unwrap();
    (0..e.len())
        .map(|i| {
            let p = g.positions[i]?;
            let n = g.normals[i];
            let d = p - vpl.position;
            let r2 = d.length_squared();
            let dir = d / r2.sqrt();
            let g_term = vpl.normal.dot(dir).max(0.0) * (-n.dot(dir)).max(0.0) / r2;
            let unoccluded = vpl.flux.x / std::f32::consts::PI * g_term;
            let visible = !harness
                .bvh
                .occluded(vpl.position + vpl.normal * 0.5, p + n * 0.5, 1e-4);
            Some((e[i][0], unoccluded, visible))
        })
        .collect()
}

fn check(kind: VplMapKind) {
    // A VPL on the floor between the blocks, and one on the red wall, facing into the box.
    let vpls = [
        Vpl {
            position: Vec3::new(150.0, 0.0, 420.0),
            normal: Vec3::Y,
            ..test_vpl()
        },
        Vpl {
            position: Vec3::new(553.0, 300.0, 250.0),
            normal: Vec3::NEG_X,
            ..test_vpl()
        },
    ];
    for backend in ["vulkan", "gl"] {
        for vpl in vpls {
            let px = one_vpl(backend, kind, vpl);
            let (mut n, mut agree, mut shadowed, mut lit) = (0, 0, 0, 0);
            for (gpu_e, unoccluded, visible) in px.iter().flatten() {
                // Receivers facing the VPL clearly.
                if *unoccluded < 1e-6 {
                    continue;
                }
                n += 1;
                let gpu_visible = *gpu_e > 0.5 * unoccluded;
                if gpu_visible == *visible {
                    agree += 1;
                }
                shadowed += (!visible) as usize;
                lit += *visible as usize;
                if *visible && gpu_visible {
                    // Unclamped, visible: the GPU computes the same irradiance.
                    assert!(
                        (gpu_e - unoccluded).abs() <= 0.01 * unoccluded + 1e-9,
                        "{backend} {kind:?}: {gpu_e} vs {unoccluded}"
                    );
                }
            }
            assert!(
                n > 1000 && shadowed > 50 && lit > 500,
                "{backend} {kind:?}: too few pixels ({n}, {shadowed} shadowed, {lit} lit)"
            );
            // Texel-sized disagreements at shadow boundaries only.
            assert!(
                agree * 100 >= n * 97,
                "{backend} {kind:?} at {:?}: visibility agrees on {agree} of {n} pixels",
                vpl.position
            );
        }
    }
}

fn test_vpl() -> Vpl {
    Vpl {
        position: Vec3::ZERO,
        normal: Vec3::Y,
        flux: Vec3::splat(1.0e9),
        color: Vec3::ONE,
        bounce: 1,
        path: 0,
        sample: Vec3::ZERO,
    }
}

#[test]
fn paraboloid_maps_agree_with_ray_casts() {
    check(VplMapKind::Paraboloid);
}

#[test]
fn cube_maps_agree_with_ray_casts() {
    check(VplMapKind::Cube);
}
