//! The backend loop: the portable backends present (Vulkan, GL), a context on each, and a
//! harness on each for a scene; a note past the test harness's capture for what a machine
//! could not check.

use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::run::runner::Harness;
use gibench_harness::scene::Scene;
use gibench_harness::wgpu;

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

/// A GPU test's needs, declared beside it as wgpu's own tests declare theirs
/// (`tests/src/params.rs` there): the backends it may run on, the device features it needs and
/// the limits below which it cannot run. [`GpuTest::run`] runs the body on each portable backend
/// present that meets them and prints, past the capture, why each other one was skipped; with
/// no portable backend at all it fails (a machine that runs no GPU test is a broken set-up).
///
/// ```text
/// GpuTest::new("kernel_time_within_its_submission")
///     .features(wgpu::Features::TIMESTAMP_QUERY)
///     .run(|backend, gpu| { /* ... */ });
/// ```
pub struct GpuTest {
    name: &'static str,
    backends: &'static [&'static str],
    features: wgpu::Features,
    limits: Vec<Limit>,
}

/// A limit a test needs: its name, the least value, and how to read it.
type Limit = (&'static str, u64, fn(&wgpu::Limits) -> u64);

impl GpuTest {
    /// A test named `name` with no needs, on every portable backend (Vulkan, GL).
    pub fn new(name: &'static str) -> GpuTest {
        GpuTest {
            name,
            backends: &["vulkan", "gl"],
            features: wgpu::Features::empty(),
            limits: Vec::new(),
        }
    }

    /// Only these backends (a test of one backend's behaviour).
    pub fn backends(mut self, backends: &'static [&'static str]) -> GpuTest {
        self.backends = backends;
        self
    }

    /// Needs the device to have `features`.
    pub fn features(mut self, features: wgpu::Features) -> GpuTest {
        self.features |= features;
        self
    }

    /// Needs the device's limit `name`, read by `of`, to be at least `least`.
    pub fn limit(
        mut self,
        name: &'static str,
        least: u64,
        of: fn(&wgpu::Limits) -> u64,
    ) -> GpuTest {
        self.limits.push((name, least, of));
        self
    }

    /// Why `gpu` cannot run the test (`None`: it can).
    pub fn unmet(&self, gpu: &GpuContext) -> Option<String> {
        let missing = self.features - gpu.device.features();
        if !missing.is_empty() {
            return Some(format!("no {missing:?}"));
        }
        let limits = gpu.device.limits();
        self.limits.iter().find_map(|(name, least, of)| {
            let has = of(&limits);
            (has < *least).then(|| format!("{name} is {has}, the test needs {least}"))
        })
    }

    /// Runs `body` on each declared backend present that meets the needs, in order; says why
    /// each other one was skipped. Returns how many backends ran it.
    pub fn run(&self, mut body: impl FnMut(&str, &GpuContext)) -> usize {
        let present = available_backends();
        assert!(
            !present.is_empty(),
            "{}: no Vulkan or GL adapter",
            self.name
        );
        let mut ran = 0;
        for backend in self.backends {
            if !present.contains(backend) {
                say_uncaptured(&format!("{}: skipped on {backend}: not present", self.name));
                continue;
            }
            let gpu = backend_context(backend);
            match self.unmet(&gpu) {
                Some(why) => say_uncaptured(&format!("{}: skipped on {backend}: {why}", self.name)),
                None => {
                    body(backend, &gpu);
                    ran += 1;
                }
            }
        }
        ran
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A need no device meets skips every backend and says why; no needs runs on each one
    /// present. Catches `unmet` ignoring limits or features, and `run` ignoring `unmet`.
    #[test]
    fn a_need_the_device_lacks_skips_and_says_why() {
        let present = available_backends();
        let gpu = backend_context(present[0]);
        let huge =
            GpuTest::new("huge").limit("max_bind_groups", u64::MAX, |l| l.max_bind_groups as u64);
        assert!(huge.unmet(&gpu).unwrap().contains("max_bind_groups"));
        assert_eq!(huge.run(|_, _| panic!("ran despite an unmet need")), 0);
        let all = GpuTest::new("all").features(wgpu::Features::all());
        assert!(all.unmet(&gpu).unwrap().starts_with("no "));
        let none = GpuTest::new("none");
        assert!(none.unmet(&gpu).is_none());
        assert_eq!(none.run(|_, _| {}), present.len());
    }
}
