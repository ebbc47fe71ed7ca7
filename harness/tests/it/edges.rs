//! The edge mask for low-resolution passes (Barczak 2006 §4.3.3) on the Cornell box: the GPU
//! mask equals the rule applied on the CPU to the exported G-buffer, marks the boundaries
//! (blocks against walls, the open front) but not the interiors of flat walls, and widens with
//! the step. Runs on Vulkan and GL.

use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::kit::ir::edges::{EdgeMask, EdgeSettings};
use gibench_harness::kit::passes::GBufferTexels;
use gibench_harness::run::runner::Harness;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::Scene;

const W: u32 = 160;
const H: u32 = 120;

/// The rule of `edges.wgsl`, on the CPU.
fn cpu_mask(g: &GBufferTexels, s: EdgeSettings) -> Vec<u32> {
    let (w, h) = (W as i32, H as i32);
    let step = s.step as i32;
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let Some(p) = g.positions[i as usize] else {
                return 0;
            };
            let n = g.normals[i as usize];
            let offsets = [
                (1, 0),
                (-1, 0),
                (0, 1),
                (0, -1),
                (1, 1),
                (-1, 1),
                (1, -1),
                (-1, -1),
            ];
            offsets.iter().any(|(dx, dy)| {
                let (qx, qy) = (
                    (x + dx * step).clamp(0, w - 1),
                    (y + dy * step).clamp(0, h - 1),
                );
                let q = (qy * w + qx) as usize;
                match g.positions[q] {
                    None => true,
                    Some(pq) => {
                        n.dot(g.normals[q]) < s.normal_cos
                            || n.dot(pq - p).abs() > s.plane_distance * (pq - p).length()
                    }
                }
            }) as u32
        })
        .collect()
}

#[test]
fn edge_mask_matches_the_rule_and_finds_the_boundaries() {
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    for backend in gibench_test_support::backends_for("edges") {
        let gpu = gibench_test_support::backend_context(backend);
        let config = gibench_test_support::one_frame([W, H])
            .shadow_size(64)
            .build();
        let harness = Harness::new(&gpu, &scene, &config).unwrap();
        harness.uniforms.write(&gpu.queue, &harness.clock.frame(0));
        let mut counts = Vec::new();
        for step in [1, 3, 6] {
            let settings = EdgeSettings {
                step,
                ..EdgeSettings::default()
            };
            let edges = EdgeMask::new(&gpu, &harness.gbuffer, settings).unwrap();
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            harness
                .gbuffer
                .encode(&mut enc, &harness.gpu_scene, &harness.uniforms);
            edges.encode(&mut enc);
            gpu.queue.submit([enc.finish()]);
            let gpu_mask = edges.read(&gpu).unwrap();
            let g = harness.gbuffer.export(&gpu).unwrap();
            let cpu = cpu_mask(&g, settings);
            let geometry = g.positions.iter().filter(|p| p.is_some()).count();
            let same = gpu_mask.iter().zip(&cpu).filter(|(a, b)| a == b).count();
            assert!(
                same * 1000 >= gpu_mask.len() * 998,
                "{backend} step {step}: GPU and CPU masks agree on {same} of {} pixels",
                gpu_mask.len()
            );
            let n_edges = gpu_mask.iter().filter(|m| **m == 1).count();
            eprintln!("{backend} step {step}: {n_edges} edges of {geometry} geometry pixels");
            counts.push((n_edges, geometry));
        }
        // Step 1: a thin outline (the box's edges), most of each wall interior; wider steps mask
        // more around the same boundaries.
        let (first, geometry) = counts[0];
        assert!(
            first * 50 > geometry && first * 5 < geometry,
            "{backend}: {counts:?}"
        );
        assert!(
            counts[0].0 < counts[1].0 && counts[1].0 < counts[2].0,
            "{backend}: {counts:?}"
        );
    }
}

#[test]
fn bad_edge_settings_name_the_setting() {
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let gpu = GpuContext::new(&GpuOptions::default()).unwrap();
    let config = gibench_test_support::one_frame([W, H])
        .shadow_size(64)
        .build();
    let harness = Harness::new(&gpu, &scene, &config).unwrap();
    let err = EdgeMask::new(
        &gpu,
        &harness.gbuffer,
        EdgeSettings {
            step: 0,
            ..EdgeSettings::default()
        },
    )
    .err()
    .unwrap()
    .to_string();
    assert!(err.contains("edge-step"), "{err}");
}
