//! The backend loop: the portable backends present (Vulkan, GL), a context on each, and a
//! harness on each for a scene; a note past the test harness's capture for what a machine
//! could not check.

use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::run::runner::Harness;
use gibench_harness::scene::Scene;

/// The portable backends (`vulkan`, `gl`) that offer an adapter on this machine, in that order:
/// tests that compare backends run on the ones present and say which are absent.
pub fn available_backends() -> Vec<&'static str> {
    ["vulkan", "gl"]
        .into_iter()
        .filter(|b| {
            GpuContext::new(&GpuOptions {
                backend: Some(b.to_string()),
                ..Default::default()
            })
            .is_ok()
        })
        .collect()
}

/// The portable backends present ([`available_backends`]) for a check that must hold on each
/// (the tests' backend loop): at least one, else it panics; when only one is, `check` says so
/// past the test harness's capture, so that a machine without the other is never silent.
pub fn backends_for(check: &str) -> Vec<&'static str> {
    let present = available_backends();
    assert!(!present.is_empty(), "{check}: no Vulkan or GL adapter");
    if present.len() < 2 {
        say_uncaptured(&format!(
            "{check}: only {present:?} present on this machine"
        ));
    }
    present
}

/// A context on `backend`, one of [`available_backends`].
pub fn backend_context(backend: &str) -> GpuContext {
    GpuContext::new(&GpuOptions {
        backend: Some(backend.into()),
        ..Default::default()
    })
    .unwrap_or_else(|e| panic!("a {backend} adapter: {e}"))
}

/// Writes `message` to the process's standard error directly, past the test harness's output
/// capture: for a test that must say plainly what it could not check on this machine.
pub fn say_uncaptured(message: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "note: {message}");
}

/// A context on each portable backend present, with its name; `check` names the test in the
/// note printed when only one backend is present.
pub fn gpus(check: &str) -> impl Iterator<Item = (&'static str, GpuContext)> {
    backends_for(check)
        .into_iter()
        .map(|backend| (backend, backend_context(backend)))
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
        let config = crate::config::run_config(size, shadow_size);
        let harness = Harness::new(&gpu, scene, &config).unwrap();
        body(backend, &gpu, &harness);
    }
}
