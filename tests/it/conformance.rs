//! The conformance entry every registered technique gets by registering (like wgpu's example
//! tests): on the generated Cornell box at 96x72, lit by each kind of light there is a scene for
//! (`cornell` spot, `cornell-area` area light, `cornell-omni`, `cornell-sun`), after three
//! animation frames,
//!
//! 1. its indirect irradiance is finite everywhere;
//! 2. it is exactly zero where no geometry is hit;
//! 3. two builds with the same seed (each from its own preparation) give bit-identical output;
//! 4. against the reference component it declares (`TechniqueInfo::reference`), its relative
//!    L1 error (Σ|t − r| / Σr over pixels that hit geometry, RGB summed: 1 for an all-zero
//!    output) and its mean relative to the reference's lie within the band around the known
//!    bias it declares for the scene (`TechniqueInfo::conformance`, `KnownBias`), and the
//!    output scaled by 1.15 or by 0.87 fails that band (a band that admits them cannot tell a
//!    technique that lost or gained that much light). The mean ratio is the energy check:
//!    halving a technique's VPL intensities moves it to about half its known bias. On the
//!    Cornell boxes, the same at the technique's converged setting (`Conformance::converged`):
//!    within ×1.05 of its stated residual, which lies within ±10 % of the reference, and the
//!    output ×1.1 or ×0.9 fails;
//!
//! 5. every stage it times is declared in `TechniqueInfo::stages` (name and GPU or CPU), and
//!    every GPU stage declares its minimum cost (`Profiler::stage_cost`, the roofline's input,
//!    docs/roofline.md), so `gibench report --detailed` has a fraction for each.
//!
//! Runs on the best adapter there is (Vulkan, else GL).

use gibench_papers::registry;

use gibench_harness::cpu::reference::{render_reference, ReferenceImages, ReferenceSettings};
use gibench_harness::glam::Vec3;
use gibench_harness::gpu::profiler::ProfileMode;
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::kit::technique::{Converged, KnownBias, Params, TechniqueInfo};
use gibench_harness::measure::results::StageKind;
use gibench_harness::run::quality::IndirectComponent;
use gibench_harness::run::runner::{Harness, RunConfig};
use gibench_harness::scene::anim::FrameState;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::Scene;

const SIZE: [u32; 2] = [96, 72];
const FRAMES: u32 = 3;

/// The technique's indirect irradiance after frames 0..FRAMES, from a fresh build, and the GPU
/// stages it timed without declaring a cost (the frames are recorded, so the profiler keeps
/// the costs declared).
fn render(
    gpu: &GpuContext,
    h: &Harness,
    info: &TechniqueInfo,
    params: &Params,
    config: &RunConfig,
) -> (Vec<Vec3>, Vec<String>) {
    let prepared = h.prepare(info, params, config).expect("prepare");
    let (mut t, compose) = h
        .build(info, params, config, &prepared)
        .expect("technique builds");
    let mut profiler = h.profiler(info, ProfileMode::Frame);
    for f in 0..FRAMES {
        let frame = h.clock.frame(f);
        h.render_frame(t.as_mut(), &compose, &mut profiler, &frame, true)
            .expect("frame renders");
    }
    profiler.finish(gpu).expect("frames finish");
    let costs = profiler.stage_costs();
    let undeclared = profiler
        .stage_results()
        .into_iter()
        .filter(|s| s.kind == StageKind::Gpu && !costs.contains_key(&s.name))
        .map(|s| format!("{} without a declared cost", s.name))
        .chain(
            profiler
                .undeclared()
                .iter()
                .map(|s| format!("{s} not in TechniqueInfo.stages")),
        )
        .collect();
    let output = gibench_harness::gpu::image_io::read_rgb_f32(gpu, t.output().texture())
        .expect("output reads back")
        .into_iter()
        .map(Vec3::from)
        .collect();
    (output, undeclared)
}

#[test]
fn every_registered_technique_conforms() {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("a GPU adapter (Vulkan or GL)");
    let mut failures = Vec::new();
    for scene_name in CORNELL_BOXES {
        conform_on(
            &gpu,
            scene_name,
            registry::all().iter(),
            true,
            &mut failures,
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The entries techniques declare beyond the Cornell boxes, each on its scene, with one build
/// each (the Cornell entries check determinism): `barczak` on the papers' large scenes (its
/// receivers there are generated charts, issue 37; each build is most of this test's time).
#[test]
fn techniques_conform_on_the_other_scenes_they_declare() {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("a GPU adapter (Vulkan or GL)");
    let mut scenes: Vec<&str> = (registry::all().iter())
        .flat_map(|t| t.conformance.defaults.iter().map(|k| k.scene))
        .filter(|s| !CORNELL_BOXES.contains(s))
        .collect();
    scenes.sort_unstable();
    scenes.dedup();
    assert!(
        scenes.contains(&"sibenik"),
        "{scenes:?}: barczak's large scenes"
    );
    let mut failures = Vec::new();
    for scene_name in scenes {
        let declared = (registry::all().iter()).filter(|t| t.conformance.on(scene_name).is_some());
        conform_on(&gpu, scene_name, declared, false, &mut failures);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The scenes every technique is held to.
const CORNELL_BOXES: [&str; 4] = ["cornell", "cornell-area", "cornell-omni", "cornell-sun"];

fn conform_on<'a>(
    gpu: &GpuContext,
    scene_name: &str,
    techniques: impl Iterator<Item = &'a TechniqueInfo>,
    twice: bool,
    failures: &mut Vec<String>,
) {
    let scene = Scene::load_named(scene_name, &AssetPaths::standard(None)).unwrap();
    let config = gibench_test_support::one_frame(SIZE).frames(FRAMES).build();
    let h = Harness::new(gpu, &scene, &config).unwrap();
    let frame = h.clock.frame(FRAMES - 1);
    let mut references = References::default();
    for info in techniques {
        let defaults = info.parse_params(&[]).expect("defaults parse");
        let component = info.default_reference();
        let reference = references.get(&scene, &frame, component);
        let (a, undeclared) = render(gpu, &h, info, &defaults, &config);
        let b = if twice {
            render(gpu, &h, info, &defaults, &config).0
        } else {
            a.clone()
        };
        let name = format!("{} on {scene_name}", info.name);
        // 5. Every GPU stage declares its cost. Catches a GPU stage added (or a declaration
        // dropped) without a `stage_cost` beside its `gpu_stage`: the roofline would show "–".
        if !undeclared.is_empty() {
            failures.push(format!(
                "{name}: stages not declared: {}",
                undeclared.join(", ")
            ));
        }
        // 1. Finite.
        if let Some(i) = a.iter().position(|e| !e.is_finite()) {
            failures.push(format!("{name}: non-finite output {} at pixel {i}", a[i]));
        }
        // 2. Zero where the camera sees no geometry (the reference's hit mask, the same camera).
        let misses: Vec<usize> = (0..a.len()).filter(|&i| !reference.hit[i]).collect();
        assert!(
            !misses.is_empty() || !scene_name.starts_with("cornell"),
            "the Cornell view shows background"
        );
        if let Some(&i) = misses.iter().find(|&&i| a[i] != Vec3::ZERO) {
            failures.push(format!(
                "{name}: {} where no geometry is hit (pixel {i})",
                a[i]
            ));
        }
        // 3. Deterministic across builds (where built twice).
        if a != b {
            let n = a.iter().zip(&b).filter(|(x, y)| x != y).count();
            failures.push(format!("{name}: two builds differ in {n} pixels"));
        }
        // 4. Against the declared reference component, within the band around its known bias
        // on this scene; and the band tells a ×1.15 or ×0.87 of the output from it.
        let Some(known) = info.conformance.on(scene_name) else {
            failures.push(format!("{name}: no known bias declared for this scene"));
            continue;
        };
        let held = Held {
            name: &name,
            known,
            factor: KnownBias::FACTOR,
            slack: KnownBias::L1_SLACK,
            scales: SCALES,
        };
        held.check(&a, component.of(reference), &reference.hit, failures);
        // 4b. At the converged setting (on the Cornell boxes), once; `direct` has none but its
        // defaults.
        let converged = &info.conformance.converged;
        if let Some(known) = (twice && !converged.params.is_empty())
            .then(|| converged.on(scene_name))
            .flatten()
        {
            let params = info
                .parse_params(&converged.given())
                .expect("the converged setting parses");
            let component = (info.reference)(&params);
            let reference = references.get(&scene, &frame, component);
            let name = format!("{name} at {}", converged.params.join(" "));
            let (c, _) = render(gpu, &h, info, &params, &config);
            let held = Held {
                name: &name,
                known,
                factor: Converged::FACTOR,
                slack: Converged::L1_SLACK,
                scales: CONVERGED_SCALES,
            };
            held.check(&c, component.of(reference), &reference.hit, failures);
        }
    }
}

/// The references of one scene's last frame, one per component, rendered when first asked.
#[derive(Default)]
struct References(Vec<(IndirectComponent, ReferenceImages)>);

impl References {
    fn get(
        &mut self,
        scene: &Scene,
        frame: &FrameState,
        component: IndirectComponent,
    ) -> &ReferenceImages {
        let i = match self.0.iter().position(|(c, _)| *c == component) {
            Some(i) => i,
            None => {
                let bounces = match component {
                    IndirectComponent::OneBounce => 1,
                    IndirectComponent::MultiBounce | IndirectComponent::Direct => 8,
                };
                let settings = ReferenceSettings {
                    spp: 256,
                    bounces,
                    seed: 0,
                };
                let r = render_reference(scene, frame, SIZE, &settings);
                self.0.push((component, r));
                self.0.len() - 1
            }
        };
        &self.0[i].1
    }
}

/// One entry and the band it is held within.
struct Held<'a> {
    name: &'a str,
    known: &'a KnownBias,
    factor: f64,
    slack: f64,
    /// Uniform scales of the output the band must not admit.
    scales: [f32; 2],
}

impl Held<'_> {
    /// Checks `output` against `want` over the pixels that `hit` geometry, and that each of the
    /// scales of it fails.
    fn check(&self, output: &[Vec3], want: &[Vec3], hit: &[bool], failures: &mut Vec<String>) {
        let name = self.name;
        let known = self.known;
        let (ratio, rel_l1) = against(output, want, hit);
        let (lo, hi) = known.bounds_within(self.factor);
        eprintln!(
            "{name}: relative L1 error {rel_l1:.4} (at most {:.4}), mean ratio {ratio:.4} ({lo:.4}-{hi:.4})",
            known.relative_l1 + self.slack,
        );
        let check = |ratio, rel_l1| known.check_within(self.factor, self.slack, ratio, rel_l1);
        if let Some(why) = check(ratio, rel_l1) {
            failures.push(format!("{name}: {why}"));
        }
        // A band around zero cannot tell a scale (`direct`: no indirect light at all).
        if known.mean_ratio > 0.0 {
            for scale in self.scales {
                let scaled: Vec<Vec3> = output.iter().map(|v| *v * scale).collect();
                let (ratio, rel_l1) = against(&scaled, want, hit);
                if check(ratio, rel_l1).is_none() {
                    failures.push(format!(
                        "{name}: the output ×{scale} passes its entry too (mean ratio {ratio:.4})"
                    ));
                }
            }
        }
    }
}

/// Uniform changes of the output every defaults entry must fail: a band that admits them cannot
/// tell a technique that lost or gained that much light from its known bias.
const SCALES: [f32; 2] = [1.15, 0.87];
/// The same for every converged entry.
const CONVERGED_SCALES: [f32; 2] = [1.1, 0.9];

/// Catches: a converged entry whose setting is not converged (a residual beyond ±10 % of the
/// reference stated as the method's), or one that names a parameter the technique does not
/// take, or a box missing. Cheap: reads the declarations only.
#[test]
fn every_converged_entry_is_within_ten_percent_and_parses() {
    let mut failures = Vec::new();
    for info in registry::all() {
        let converged = &info.conformance.converged;
        if let Err(e) = info.parse_params(&converged.given()) {
            failures.push(format!("{}: {e}", info.name));
        }
        for scene in CORNELL_BOXES {
            match converged.on(scene) {
                None => failures.push(format!("{}: no converged entry on {scene}", info.name)),
                // `direct` computes no indirect light: nothing to converge.
                Some(k) if k.mean_ratio == 0.0 && converged.params.is_empty() => {}
                Some(k) if (k.mean_ratio - 1.0).abs() > Converged::MAX_RESIDUAL => {
                    failures.push(format!(
                        "{}: converged mean ratio {} on {scene}",
                        info.name, k.mean_ratio
                    ))
                }
                Some(_) => {}
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The mean ratio (Σt / Σr) and relative L1 error (Σ|t − r| / Σr) of `output` against `want`
/// over the pixels that `hit` geometry, RGB summed.
fn against(output: &[Vec3], want: &[Vec3], hit: &[bool]) -> (f64, f64) {
    let (mut sum_t, mut sum_r, mut l1) = (0.0f64, 0.0f64, 0.0f64);
    for ((t, r), hit) in output.iter().zip(want).zip(hit) {
        if *hit {
            sum_t += t.element_sum() as f64;
            sum_r += r.element_sum() as f64;
            l1 += (*t - *r).abs().element_sum() as f64;
        }
    }
    (sum_t / sum_r, l1 / sum_r)
}

/// Catches: a technique timing a stage its `TechniqueInfo::stages` does not declare (or
/// declares as the other kind) without an error: keller-full declared without its own CPU
/// stage and its maps' stage is refused by name when run.
#[test]
fn a_stage_the_technique_does_not_declare_is_refused() {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("a GPU adapter (Vulkan or GL)");
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let config = gibench_test_support::one_frame([64, 48])
        .warmup(3)
        .shadow_size(128)
        .build();
    let h = Harness::new(&gpu, &scene, &config).unwrap();
    let keller = TechniqueInfo::find(registry::all(), "keller-full").unwrap();
    let partial = TechniqueInfo {
        stages: &[gibench_harness::kit::ir::gather::GATHER_STAGES],
        ..*keller
    };
    let params = partial.parse_params(&[]).unwrap();
    let prepared = h.prepare(&partial, &params, &config).unwrap();
    let e = h
        .run(&partial, &params, &config, &prepared, &mut || {})
        .err()
        .expect("an undeclared stage is refused");
    let e = e.to_string();
    assert!(
        e.contains("'keller-full'")
            && e.contains("vpl-generation (CPU)")
            && e.contains("vpl-shadow-maps (GPU)"),
        "{e}"
    );
    // Declared in full, the same run goes through.
    h.run(keller, &params, &config, &prepared, &mut || {})
        .expect("declared stages run");
}
