//! `barczak` as a registered technique: its direct light samples (`set=direct`) reproduce the
//! reference's direct light of the area light (soft shadows) on the Cornell box; bad parameters
//! are refused by name before any preparation.

use gibench_harness::cpu::reference::{render_reference, ReferenceSettings};
use gibench_harness::gpu::profiler::{ProfileMode, Profiler};
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::run::runner::Harness;
use gibench_test_support::kv;

const SIZE: [u32; 2] = [96, 72];

/// 256 points on the Cornell box's area light against the reference's direct irradiance: the
/// mean within 3 %, the relative L1 error below 0.12 (measured: ratio 0.996, L1 0.026 on lavapipe;
/// point-sampled soft shadows and 16-bit octahedral maps). Caught by: the direct set's flux
/// not divided by its count (ratio 256), its emission about the wrong normal (dark).
#[test]
fn direct_samples_match_the_reference_direct_light() {
    let info = &gibench_barczak::INFO;
    let scene = gibench_test_support::load("cornell-area");
    let gpu = GpuContext::new(&GpuOptions::default()).unwrap();
    let config = gibench_test_support::one_frame(SIZE).build();
    let h = Harness::new(&gpu, &scene, &config).unwrap();
    let params = info
        .parse_params(&kv(&[("set", "direct"), ("vpls", "256")]))
        .unwrap();
    let prepared = h.prepare(info, &params, &config).unwrap();
    let (mut t, compose) = h.build(info, &params, &config, &prepared).unwrap();
    let mut profiler = Profiler::new(&gpu, ProfileMode::Frame);
    let frame = h.clock.frame(0);
    h.render_frame(t.as_mut(), &compose, &mut profiler, &frame, false)
        .unwrap();
    profiler.finish(&gpu).unwrap();
    let out = gibench_test_support::read_rgb(&gpu, t.output().texture());
    let reference = render_reference(
        &scene,
        &frame,
        SIZE,
        &ReferenceSettings {
            spp: 64,
            bounces: 1,
            seed: 0,
        },
    );
    let (mut sum_t, mut sum_r, mut l1) = (0f64, 0f64, 0f64);
    for ((t, r), hit) in out.iter().zip(&reference.direct).zip(&reference.hit) {
        if *hit {
            sum_t += t.element_sum() as f64;
            sum_r += r.element_sum() as f64;
            l1 += (*t - *r).abs().element_sum() as f64;
        }
    }
    let (ratio, rel_l1) = (sum_t / sum_r, l1 / sum_r);
    eprintln!("set=direct on cornell-area: mean ratio {ratio:.4}, relative L1 {rel_l1:.4}");
    assert!((0.97..=1.03).contains(&ratio), "mean ratio {ratio}");
    assert!(rel_l1 < 0.12, "relative L1 {rel_l1}");
}

/// Parameters that cannot work are refused, naming the parameter, by `prepare` (the first
/// thing a run does with a technique).
#[test]
fn bad_parameters_are_refused_by_name() {
    let info = &gibench_barczak::INFO;
    let gpu = GpuContext::new(&GpuOptions::default()).unwrap();
    let err = |scene: &str, resolution: [u32; 2], pairs: &[(&str, &str)]| -> String {
        let scene = gibench_test_support::load(scene);
        let config = gibench_test_support::one_frame(resolution).build();
        let h = Harness::new(&gpu, &scene, &config).unwrap();
        let params = info.parse_params(&kv(pairs)).unwrap();
        match h.prepare(info, &params, &config) {
            Ok(_) => panic!("{pairs:?} at {resolution:?} was accepted"),
            Err(e) => e.to_string(),
        }
    };
    let e = err("cornell", SIZE, &[("set", "direct")]);
    assert!(e.contains("set") && e.contains("area light"), "{e}");
    let e = err("cornell-area", [97, 72], &[("level", "vd-lp")]);
    assert!(e.contains("lowres") && e.contains("97x72"), "{e}");
    // An edge step below the factor leaves pixels the interpolation reads unmasked.
    let e = err("cornell-area", SIZE, &[("edge-step", "1")]);
    assert!(e.contains("edge-step") && e.contains("factor 2"), "{e}");
    // Light maps bigger than the device binds: refused while preparing (before the visibility
    // database, which takes most of a minute on a scene of this size), not when the pass is
    // made.
    let e = err("sibenik", SIZE, &[("light-map-res", "64")]);
    assert!(e.contains("light-map-res") && e.contains("MB"), "{e}");
    // VD has no low-resolution pass: any resolution.
    let scene = gibench_test_support::load("cornell-area");
    let config = gibench_test_support::one_frame([97, 72]).build();
    let h = Harness::new(&gpu, &scene, &config).unwrap();
    let params = info.parse_params(&kv(&[("level", "vd")])).unwrap();
    assert!(h.prepare(info, &params, &config).is_ok());
}
