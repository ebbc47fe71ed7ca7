//! The shadow-mapped subtraction on the GPU (pillar room, octahedral maps, Vulkan and GL):
//! light maps minus the occluded partial lights equal the kit's brute-force gather of every
//! light with the same shadow maps (Barczak's "Naive") on the patches' pixels, once the light
//! maps' interpolation error (computed on the CPU) is accounted for; merging elements by the
//! optimiser changes the image by rounding only and never adds draws; the Naive level equals
//! the gather, and VD equals Naive but where a shadow map contradicts the classification. At
//! every level the passes submitted as one draw give the very image of one draw per pass.

use std::sync::Arc;

use gibench_barczak::light_draws::{Level, LightDraws, Submission};
use gibench_barczak::lightmap::contribution;
use gibench_barczak::lightmap_pass::{Leaves, LightMapPass};
use gibench_barczak::samples::SampleSettings;
use gibench_barczak::visibility::LightState;
use gibench_harness::glam::Vec3;
use gibench_harness::kit::ir::accumulate::{Accumulation, IrradianceClamp};
use gibench_harness::kit::ir::atlas::{AtlasFormat, AtlasSettings, MapKind, ShadowAtlas};
use gibench_harness::kit::ir::interleave::{FilterSettings, Interleave};
use gibench_harness::kit::ir::raster::{AtlasClear, AtlasRasteriser};
use gibench_harness::kit::ir::store::VplStore;
use gibench_harness::kit::passes::{render_target, DrawSet, HDR_FORMAT};

use crate::support;

const W: u32 = 96;
const H: u32 = 72;

#[test]
fn light_maps_minus_occluded_partials_equal_the_brute_force_gather() {
    let scene = gibench_test_support::load("barczak-pillars");
    gibench_test_support::each_backend("barczak", &scene, [W, H], 64, |backend, gpu, harness| {
        let frame = harness.clock.frame(0);
        harness.uniforms.write(&gpu.queue, &frame);
        let settings = SampleSettings {
            direct: 8,
            indirect: 40,
            bounces: 2,
        };
        let bz = support::prepared(&scene, &harness.bvh, &frame, settings, 4);
        let lights = bz.samples.slotted();
        let n = lights.len() as u32;
        let store = VplStore::new(gpu, n).unwrap();
        store.write(&gpu.queue, &lights);
        let atlas = ShadowAtlas::new(
            gpu,
            &scene.extent,
            AtlasSettings {
                kind: MapKind::Octahedral,
                format: AtlasFormat::Depth16,
                size: 128,
                capacity: n,
                bias: 0.01,
            },
        )
        .unwrap();
        let raster =
            AtlasRasteriser::new(gpu, &atlas, &harness.uniforms, DrawSet::CastersAndMovers)
                .unwrap();
        let leaves = Arc::new(Leaves::new(gpu, &bz.db));
        let maps = LightMapPass::new(
            gpu,
            &harness.uniforms,
            &harness.gbuffer,
            leaves.clone(),
            &bz.light_maps,
        )
        .unwrap();
        let mut subtract = LightDraws::new(
            gpu,
            &harness.uniforms,
            &harness.gbuffer,
            leaves,
            n,
            7,
            Submission::Merged,
            &store,
            &atlas,
            None,
        )
        .unwrap();
        // Draws the planned passes (after the light maps, at Full) into a new target.
        let draw = |subtract: &LightDraws, level: Level| {
            let t = render_target(&gpu.device, "test irradiance", [W, H], HDR_FORMAT);
            let view = t.create_view(&Default::default());
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            harness
                .gbuffer
                .encode(&mut enc, &harness.gpu_scene, &harness.uniforms);
            raster.render(
                gpu,
                &mut enc,
                &atlas,
                &harness.gpu_scene,
                &harness.uniforms,
                &lights,
                AtlasClear::Whole,
            );
            if level == Level::Full {
                maps.encode(&mut enc, &harness.uniforms, &view);
            }
            subtract.encode(&mut enc, &harness.uniforms, &atlas, &view);
            gpu.queue.submit([enc.finish()]);
            gibench_harness::gpu::image_io::read_rgb_f32(gpu, &t).unwrap()
        };
        // Barczak Full with and without the pass optimiser, then VD and Naive (which, as the
        // thesis' levels, draw each leaf on its own).
        let mut images = Vec::new();
        let mut draws = Vec::new();
        let runs = [
            (Level::Full, true),
            (Level::Full, false),
            (Level::VisibilityDetermination, false),
            (Level::Naive, false),
        ];
        for (level, optimise) in runs {
            draws.push(subtract.plan(gpu, &bz.db, level, optimise).unwrap());
            let [passes, merged] = [Submission::Passes, Submission::Merged].map(|submission| {
                subtract.set_submission(submission);
                draw(&subtract, level)
            });
            let what = format!("{backend}: {level:?} (optimiser {optimise})");
            images.push(assert_bit_identical(&what, passes, merged));
        }
        let naive = brute_force_gather(gpu, harness, &store, &atlas);

        let (opt, plain) = (&images[0], &images[1]);
        assert_the_optimiser_only_rounds(backend, opt, plain, &draws);
        let close = |a: [f32; 3], b: [f32; 3], rel: f32| {
            (0..3).all(|c| (a[c] - b[c]).abs() <= rel * a[c].abs().max(b[c].abs()) + 1e-5)
        };
        // Barczak = light map − occluded partial lights; the gather = every light with its
        // visibility. They differ by the light maps' interpolation (bilinear between texel
        // centres, against the exact sum of the leaf's lit lights at the pixel) and wherever a
        // shadow map disagrees with the geometric classification; the first is computed here.
        let g = harness.gbuffer.export(gpu).unwrap();
        let (mut compared, mut agree) = (0, 0);
        for (i, p) in g.positions.iter().enumerate() {
            let Some(p) = p else { continue };
            let Some((r, node, s, t)) =
                support::leaf_at(&bz.db, *p, g.normals[i], 1e-3 * scene.extent.diagonal, 0.02)
            else {
                continue;
            };
            let gibench_barczak::database::ReceiverShape::Patch(tree) = &bz.db.receivers[r].shape
            else {
                unreachable!()
            };
            let interpolated = support::bilinear(bz.light_maps.texels(r, node), 4, s, t);
            let exact: Vec3 = (0..n as usize)
                .filter(|&l| {
                    matches!(
                        bz.db.state(r, node, l),
                        LightState::Unblocked | LightState::Partial
                    )
                })
                .map(|l| contribution(&bz.db.lights[l], bz.flux[l], *p, tree.normal))
                .sum();
            let expected = Vec3::from(naive[i]) + interpolated - exact;
            compared += 1;
            agree += close(opt[i], expected.to_array(), 0.03) as usize;
        }
        eprintln!("{backend}: draws {draws:?}, elements {}; {agree} of {compared} patch pixels within 3 % of the brute-force gather (interpolation accounted for)", subtract.elements());
        assert!(compared > 3000, "{backend}: {compared} pixels compared");
        assert!(
            agree * 100 >= compared * 97,
            "{backend}: {agree} of {compared} pixels agree with the brute-force gather"
        );
        // Naive is the kit's gather drawn as Barczak draws it: the same lights and lookups.
        // VD differs from Naive only where a shadow map disagrees with the geometric
        // classification (an unblocked light taken as visible, a blocked one skipped).
        let (vd, naive_draws) = (&images[2], &images[3]);
        let (mut patch, mut same_naive, mut same_vd) = (0, 0, 0);
        for ((a, b), c) in naive_draws.iter().zip(&naive).zip(vd) {
            if b.iter().all(|x| *x == 0.0) || a.iter().all(|x| *x == 0.0) {
                continue;
            }
            patch += 1;
            same_naive += close(*a, *b, 0.01) as usize;
            same_vd += close(*c, *a, 0.03) as usize;
        }
        eprintln!("{backend}: draws Full {} (unmerged {}), VD {}, Naive {}; Naive = gather on {same_naive} of {patch}, VD = Naive on {same_vd}", draws[0], draws[1], draws[2], draws[3]);
        assert!(
            same_naive * 1000 >= patch * 995,
            "{backend}: Naive matches the gather on {same_naive} of {patch} pixels"
        );
        assert!(
            same_vd * 100 >= patch * 98,
            "{backend}: VD matches Naive on {same_vd} of {patch} pixels"
        );
    });
}

/// One draw and one draw per pass give the very same image: the passes' order and lights kept.
/// Returns the image.
fn assert_bit_identical(what: &str, passes: Vec<[f32; 3]>, merged: Vec<[f32; 3]>) -> Vec<[f32; 3]> {
    let differ = passes
        .iter()
        .zip(&merged)
        .filter(|(a, b)| a.map(f32::to_bits) != b.map(f32::to_bits))
        .count();
    assert_eq!(
        differ, 0,
        "{what}: one draw and one draw per pass differ on {differ} pixels"
    );
    merged
}

/// The kit's gather of every light with the same maps (1x1 tiles, no filtering, no clamp):
/// Barczak's "Naive" as the VPL techniques compute it.
fn brute_force_gather(
    gpu: &gibench_harness::gpu::GpuContext,
    harness: &gibench_harness::run::runner::Harness,
    store: &VplStore,
    atlas: &ShadowAtlas,
) -> Vec<[f32; 3]> {
    let output = gibench_harness::kit::passes::indirect_target(&gpu.device, [W, H], true);
    let interleave = Interleave::new(
        gpu,
        &harness.gbuffer,
        (1, 1),
        FilterSettings {
            alpha: 0.0,
            beta: 2.0,
        },
        &output,
    )
    .unwrap();
    let accumulation =
        Accumulation::new(gpu, &interleave, store, atlas, IrradianceClamp::OFF).unwrap();
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    interleave.encode_split(&mut enc);
    accumulation.encode(&mut enc, &interleave, atlas);
    interleave.encode_combine(&mut enc);
    interleave.encode_filter(&mut enc);
    gpu.queue.submit([enc.finish()]);
    gibench_harness::gpu::image_io::read_rgb_f32(gpu, &output).unwrap()
}

/// Merging elements by the pass optimiser never adds draws and changes the image by blending's
/// rounding only.
fn assert_the_optimiser_only_rounds(
    backend: &str,
    opt: &[[f32; 3]],
    plain: &[[f32; 3]],
    draws: &[u32],
) {
    assert!(
        draws[0] <= draws[1] && draws[0] > 0,
        "{backend}: draws {draws:?}"
    );
    let top = opt
        .iter()
        .flat_map(|p| p.iter().copied())
        .fold(0f32, f32::max);
    let worst = opt
        .iter()
        .zip(plain)
        .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).abs()).fold(0f32, f32::max))
        .fold(0f32, f32::max);
    eprintln!("{backend}: optimised vs not: largest difference {worst} (image maximum {top})");
    // Blending rounds to half floats after every draw, and the optimiser changes the order
    // of the subtractions: a few half-float steps of the largest value at most.
    assert!(
        worst <= 4e-3 * top,
        "{backend}: the optimiser changed the image by {worst}"
    );
}
