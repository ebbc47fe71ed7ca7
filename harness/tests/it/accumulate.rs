//! The accumulation's lean form (each VPL's receiver-independent terms computed once, by a
//! dispatch of their own) against the direct per-pair formulation it replaced
//! (`accumulate_per_pair.wgsl`, the kit's shader before): on the Cornell box with 4x4
//! tiles, every map kind, the clamp on and off (and biting), empty slots between VPLs, and an
//! atlas of more than one row of maps, the split irradiance of both agrees within 1e-5
//! relative at every texel. Runs on Vulkan and GL.

use gibench_harness::cpu::vpl::{self, Vpl, VplSettings};
use gibench_harness::gpu::GpuContext;
use gibench_harness::kit::ir::accumulate::{Accumulation, IrradianceClamp};
use gibench_harness::kit::ir::atlas::{AtlasFormat, AtlasSettings, MapKind, ShadowAtlas};
use gibench_harness::kit::ir::interleave::{FilterSettings, Interleave, INTERLEAVE_WGSL};
use gibench_harness::kit::ir::raster::{AtlasClear, AtlasRasteriser};
use gibench_harness::kit::ir::store::VplStore;
use gibench_harness::kit::passes::{compute_pipeline, Bindings, DrawSet};
use gibench_harness::run::runner::Harness;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::Scene;
use gibench_harness::wgpu;
use gibench_test_support::{backend_context, backends_for};

/// The split irradiance of the kit's accumulation and of the per-pair reference, over the same
/// split G-buffer, store and atlas.
fn both(
    gpu: &GpuContext,
    scene: &Scene,
    kind: MapKind,
    clamp: IrradianceClamp,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let [w, h] = [96u32, 72];
    let config = gibench_test_support::one_frame([w, h]).build();
    let harness = Harness::new(gpu, scene, &config).unwrap();
    let frame = harness.clock.frame(0);
    harness.uniforms.write(&gpu.queue, &frame);
    let output = gibench_harness::kit::passes::indirect_target(&gpu.device, [w, h], true);
    let filter = FilterSettings {
        alpha: 0.0,
        beta: 2.0,
    };
    let interleave = Interleave::new(gpu, &harness.gbuffer, (4, 4), filter, &output).unwrap();
    // First-bounce VPLs, every third slot left empty (as an incremental technique's ring):
    // more slots than an atlas row of 128² maps holds under a 16384-texel limit, so that
    // tile origins below the first row are looked up too (asserted below).
    let vpls: Vec<Vpl> = vpl::generate(scene, &harness.bvh, &frame.light, &VplSettings::new(160));
    let stored: Vec<(u32, Vpl)> = (vpls.iter().enumerate())
        .map(|(i, v)| ((i + i / 2) as u32, *v))
        .collect();
    let capacity = stored.iter().map(|(s, _)| s + 1).max().unwrap();
    let atlas = ShadowAtlas::new(
        gpu,
        &scene.extent,
        AtlasSettings {
            kind,
            format: AtlasFormat::Depth16,
            size: 128,
            capacity,
            bias: 0.01,
        },
    )
    .unwrap();
    let ([_, last_row], _) = atlas.block(capacity - 1);
    assert!(
        last_row > 0,
        "the atlas holds {capacity} maps in one row: widen the test"
    );
    let store = VplStore::new(gpu, capacity).unwrap();
    store.write(&gpu.queue, &stored);
    let lean = Accumulation::new(gpu, &interleave, &store, &atlas, clamp).unwrap();
    // The reference: the per-pair shader over the same bindings.
    let per_flux = if clamp.factor > 0.0 {
        clamp.factor / clamp.surface_area
    } else {
        0.0
    };
    let params = gibench_harness::kit::passes::params_buffer(
        gpu,
        "per-pair params",
        &[per_flux, 0.0, 0.0, 0.0],
    );
    let group = Bindings::new("per-pair accumulate", wgpu::ShaderStages::COMPUTE)
        .read(store.buffer())
        .params(&params)
        .build(&gpu.device);
    let source = format!(
        "{INTERLEAVE_WGSL}\n{}\n{}\n{}",
        VplStore::wgsl(1, 0, false),
        ShadowAtlas::wgsl(2),
        include_str!("accumulate_per_pair.wgsl")
    );
    let per_pair = compute_pipeline(
        &gpu.device,
        "per-pair accumulate",
        &source,
        &[interleave.split_layout(), &group.layout, atlas.layout()],
        "accumulate",
    );
    let raster =
        AtlasRasteriser::new(gpu, &atlas, &harness.uniforms, DrawSet::StaticCasters).unwrap();
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
        &stored,
        AtlasClear::Whole,
    );
    interleave.encode_split(&mut enc);
    lean.encode(&mut enc, &interleave, &atlas);
    gpu.queue.submit([enc.finish()]);
    let a = read_vec4(gpu, &interleave.split_irradiance);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&per_pair);
        pass.set_bind_group(0, interleave.split_group(), &[]);
        pass.set_bind_group(1, &group.group, &[]);
        pass.set_bind_group(2, atlas.group(), &[]);
        interleave.dispatch_split_size(&mut pass);
    }
    gpu.queue.submit([enc.finish()]);
    let b = read_vec4(gpu, &interleave.split_irradiance);
    (a, b)
}

/// Reads a buffer of `vec4<f32>` back to the CPU.
fn read_vec4(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Vec<[f32; 4]> {
    let bytes = gibench_harness::gpu::image_io::read_buffer(gpu, buffer).unwrap();
    bytemuck::cast_slice(&bytes).to_vec()
}

#[test]
fn the_lean_accumulation_equals_the_per_pair_one() {
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let clamped = IrradianceClamp {
        factor: 2.0,
        surface_area: scene.extent.surface_area,
    };
    for backend in backends_for("accumulate") {
        let gpu = backend_context(backend);
        for kind in [MapKind::Paraboloid, MapKind::Cube, MapKind::Octahedral] {
            let mut references = Vec::new();
            for clamp in [IrradianceClamp::OFF, clamped] {
                let (lean, per_pair) = both(&gpu, &scene, kind, clamp);
                assert_eq!(lean.len(), per_pair.len());
                let (mut lit, mut worst) = (0, 0f32);
                for (a, b) in lean.iter().zip(&per_pair) {
                    for c in 0..4 {
                        if a[c] != b[c] {
                            let rel = (a[c] - b[c]).abs() / b[c].abs().max(1e-30);
                            // A NaN on either side is a difference, not a pass.
                            worst = if rel.is_nan() {
                                f32::INFINITY
                            } else {
                                worst.max(rel)
                            };
                        }
                    }
                    lit += (b[0] > 0.0) as usize;
                }
                // The comparison means something only where VPLs light texels.
                assert!(
                    lit > lean.len() / 4,
                    "{backend} {kind:?}: {lit} of {} texels lit",
                    lean.len()
                );
                assert!(
                    worst <= 1e-5,
                    "{backend} {kind:?} {clamp:?}: a texel differs by {worst:e} relative"
                );
                references.push(per_pair);
            }
            // The clamp bites somewhere (else its branch went untested).
            assert_ne!(
                references[0], references[1],
                "{backend} {kind:?}: the clamp changed nothing"
            );
        }
    }
}
