//! The G-buffer read back from the GPU agrees with CPU ray casts through the same pixel centres
//! (hit position and normal) on the Cornell box. Needs a GPU adapter (lavapipe is enough).

use gibench_harness::glam::{Vec3, Vec4};
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::run::runner::Harness;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::Scene;

fn check_backend(backend: Option<&str>) {
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let gpu = GpuContext::new(&GpuOptions {
        backend: backend.map(String::from),
        ..Default::default()
    })
    .expect("a GPU adapter (install mesa-vulkan-drivers)");
    let config = gibench_test_support::one_frame([96, 72])
        .shadow_size(64)
        .build();
    let h = Harness::new(&gpu, &scene, &config).unwrap();
    // Frame 17: camera and light away from their first keys.
    let frame = h.clock.frame(17);
    h.uniforms.write(&gpu.queue, &frame);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    h.gbuffer.encode(&mut enc, &h.gpu_scene, &h.uniforms);
    gpu.queue.submit([enc.finish()]);
    let g = h.gbuffer.export(&gpu).unwrap();

    let inv = h.uniforms.camera_view_proj(&frame).inverse();
    let [w, hgt] = config.resolution;
    let (mut compared, mut disagree, mut worst_normal) = (0, 0, 1.0f32);
    for y in 0..hgt {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let ndc = Vec4::new(
                (x as f32 + 0.5) / w as f32 * 2.0 - 1.0,
                1.0 - (y as f32 + 0.5) / hgt as f32 * 2.0,
                1.0,
                1.0,
            );
            let near = inv * ndc;
            let near = near.truncate() / near.w;
            let dir = (near - frame.camera.position).normalize();
            let hit = h
                .bvh
                .closest_hit(frame.camera.position, dir, 0.0, f32::INFINITY);
            match (hit, g.positions[i]) {
                (Some(hit), Some(p)) => {
                    compared += 1;
                    let tol = 2e-3 * hit.t;
                    if (hit.position - p).length() > tol {
                        disagree += 1;
                    } else {
                        worst_normal = worst_normal.min(hit.shading_normal.dot(g.normals[i]));
                    }
                }
                (None, None) => {}
                _ => disagree += 1,
            }
        }
    }
    let total = (w * hgt) as usize;
    // The box fills most of the view; only pixels exactly on an edge may disagree.
    assert!(
        compared > total / 2,
        "only {compared} of {total} pixels hit geometry"
    );
    assert!(
        disagree * 100 <= total,
        "{disagree} of {total} pixels disagree (more than 1%)"
    );
    assert!(
        worst_normal > 0.999,
        "normals disagree: worst cosine {worst_normal}"
    );
    // Albedo is the material colour (sRGB-encoded 8-bit storage: a few 1/255 steps).
    let red = Vec3::new(0.63, 0.065, 0.05);
    assert!(
        g.albedo
            .iter()
            .any(|a| (*a - red).abs().max_element() < 0.01),
        "no red-wall pixel"
    );
}

/// On each portable backend present (Vulkan, GL); an absent one is named, not failed.
#[test]
fn gbuffer_matches_ray_casts_on_every_backend() {
    let present = gibench_test_support::available_backends();
    assert!(!present.is_empty(), "no Vulkan or GL adapter");
    for backend in ["vulkan", "gl"] {
        if present.contains(&backend) {
            check_backend(Some(backend));
        } else {
            gibench_test_support::say_uncaptured(&format!(
                "gbuffer_matches_ray_casts: {backend} is absent on this machine; not checked"
            ));
        }
    }
}
