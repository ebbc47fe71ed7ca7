//! The light-map pass on the GPU: at every pixel of the pillar room the irradiance equals the
//! CPU light map of the leaf the pixel lies in, bilinear between texel centres inside the leaf
//! (Vulkan and GL); pixels on the torus mover (no patch) stay zero.

use gibench_barczak::lightmap_pass::{Leaves, LightMapPass};
use gibench_barczak::samples::SampleSettings;
use gibench_harness::glam::Vec3;
use gibench_harness::kit::passes::{render_target, HDR_FORMAT};

use crate::support;

const W: u32 = 96;
const H: u32 = 72;
const RES: u32 = 4;

#[test]
fn light_map_pass_draws_the_cpu_light_maps() {
    let scene = gibench_test_support::load("barczak-pillars");
    gibench_test_support::each_backend("barczak", &scene, [W, H], 64, |backend, gpu, harness| {
        let frame = harness.clock.frame(0);
        harness.uniforms.write(&gpu.queue, &frame);
        let settings = SampleSettings {
            direct: 8,
            indirect: 24,
            bounces: 2,
        };
        let bz = support::prepared(&scene, &harness.bvh, &frame, settings, RES);
        let leaves = std::sync::Arc::new(Leaves::new(gpu, &bz.db));
        let pass = LightMapPass::new(
            gpu,
            &harness.uniforms,
            &harness.gbuffer,
            leaves,
            &bz.light_maps,
        )
        .unwrap();
        let target = render_target(&gpu.device, "test irradiance", [W, H], HDR_FORMAT);
        let view = target.create_view(&Default::default());
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        harness
            .gbuffer
            .encode(&mut enc, &harness.gpu_scene, &harness.uniforms);
        assert_eq!(pass.encode(&mut enc, &harness.uniforms, &view), 1);
        gpu.queue.submit([enc.finish()]);
        let gpu_e = gibench_harness::gpu::image_io::read_rgb_f32(gpu, &target).unwrap();
        let g = harness.gbuffer.export(gpu).unwrap();
        let (mut checked, mut agree, mut mover, mut mover_zero) = (0, 0, 0, 0);
        for (i, p) in g.positions.iter().enumerate() {
            let Some(p) = p else { continue };
            let e = Vec3::from(gpu_e[i]);
            let found =
                support::leaf_at(&bz.db, *p, g.normals[i], 1e-3 * scene.extent.diagonal, 0.02);
            let Some((r, n, s, t)) = found else {
                // Not a patch: the torus (or a leaf's border, left out).
                let on_torus = scene.patches.iter().all(|pa| {
                    pa.normal.dot(*p - pa.corners[0]).abs() > 1e-3 * scene.extent.diagonal
                });
                if on_torus {
                    mover += 1;
                    mover_zero += (e == Vec3::ZERO) as usize;
                }
                continue;
            };
            let want = support::bilinear(bz.light_maps.texels(r, n), RES, s, t);
            checked += 1;
            // Rgba16Float output: 3 significant digits; the pixel centre's (s, t) on the GPU comes
            // from interpolation, on the CPU from the reconstructed position.
            agree += ((e - want).abs().max_element() <= 0.01 * want.max_element() + 1e-6) as usize;
        }
        eprintln!("{backend}: {agree} of {checked} agree; torus {mover_zero} zero of {mover}");
        assert!(checked > 2000, "{backend}: only {checked} pixels checked");
        assert!(
            agree * 100 >= checked * 99,
            "{backend}: {agree} of {checked} pixels agree with the CPU light maps"
        );
        assert!(
            mover > 20 && mover_zero == mover,
            "{backend}: torus pixels {mover_zero} zero of {mover}"
        );
    });
}
