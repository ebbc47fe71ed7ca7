//! The backend loop: a context on every portable backend present (Vulkan, GL), and a harness on
//! each for a scene; the run settings tests use.

use gibench_harness::gpu::{backend_context, backends_for, GpuContext};
use gibench_harness::run::runner::{Harness, RunConfig, TimingMode};
use gibench_harness::scene::Scene;

/// A context on each portable backend present, with its name; `check` names the test in the
/// note printed when only one backend is present.
pub fn gpus(check: &str) -> impl Iterator<Item = (&'static str, GpuContext)> {
    backends_for(check)
        .into_iter()
        .map(|backend| (backend, backend_context(backend)))
}

/// One frame at `resolution`, no warm-up, starting at frame 0, stage timing, seed 1, direct
/// shadow maps of `shadow_size`.
pub fn run_config(resolution: [u32; 2], shadow_size: u32) -> RunConfig {
    RunConfig {
        resolution,
        frames: 1,
        warmup: 0,
        first_frame: 0,
        timing: TimingMode::Stages,
        seed: 1,
        shadow_size,
    }
}

/// Runs `body` on every portable backend present with a harness for `scene` at `size`
/// pixels (direct shadow maps of `shadow_size`).
pub fn each_backend(
    check: &str,
    scene: &Scene,
    size: [u32; 2],
    shadow_size: u32,
    mut body: impl FnMut(&str, &GpuContext, &Harness),
) {
    for (backend, gpu) in gpus(check) {
        let harness = Harness::new(&gpu, scene, &run_config(size, shadow_size)).unwrap();
        body(backend, &gpu, &harness);
    }
}
