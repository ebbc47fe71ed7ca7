//! Headless wgpu context: adapter choice, device creation with optional features, and an error
//! sink so that GPU validation errors become [`Error::Gpu`] instead of panics.
//!
//! Adapter choice: `--backend` (vulkan, gl, metal, dx12) restricts the backends;
//! `--adapter NAME` keeps adapters whose name contains NAME (case-insensitive). Among what is
//! left the harness prefers a hardware adapter (discrete, integrated, virtual), then a CPU Vulkan
//! adapter (Mesa lavapipe), then GL (Mesa llvmpipe), then anything else.

pub mod image_io;
pub mod profiler;

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::measure::results::DeviceInfo;
use crate::{Error, Result};

/// How to choose the adapter.
#[derive(Clone, Debug, Default)]
pub struct GpuOptions {
    /// `vulkan`, `gl`, `metal`, `dx12`, or `None` for all.
    pub backend: Option<String>,
    /// Case-insensitive substring of the adapter name.
    pub adapter: Option<String>,
    /// The longest one wait for the GPU may last before it fails, seconds (`--gpu-timeout`);
    /// `None` waits as long as the work takes.
    pub gpu_timeout: Option<f64>,
    /// Limits to ask the device for instead of the adapter's own (each at most the adapter's):
    /// tests make a smaller adapter's device this way, to check a technique's error for a
    /// limit it needs beyond what the adapter offers.
    pub limits: Option<wgpu::Limits>,
}

/// One blocking wait is at most this long and is then renewed: wgpu's GL backend caps a fence
/// wait at `u32::MAX` nanoseconds (about 4.3 s) and reports a timeout past it even when asked to
/// wait indefinitely, while one submission on a CPU driver (llvmpipe) can take longer than that.
const WAIT_SLICE: Duration = Duration::from_secs(1);

/// After this long waiting for one submission, a line on standard error says so (once).
const WAIT_NOTICE: Duration = Duration::from_secs(30);

/// Optional features the harness uses when the adapter has them.
const OPTIONAL_FEATURES: wgpu::Features =
    wgpu::Features::TIMESTAMP_QUERY.union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS);

/// The device and what it can do.
pub struct GpuContext {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: DeviceInfo,
    /// Timestamp queries can be written between passes (`write_timestamp` on encoders).
    pub timestamps: bool,
    errors: Arc<Mutex<Vec<String>>>,
    /// Set by the device-lost callback: the reason and the driver's message.
    lost: Arc<Mutex<Option<String>>>,
    wait_limit: Option<Duration>,
    /// `GIBENCH_TEST_LOSE_DEVICE`, parsed once ([`GpuContext::test_lose_device`]): technique,
    /// frame, which occurrence, and the occurrences seen.
    lose_hook: Option<(String, u32, u32, std::sync::atomic::AtomicU32)>,
}

/// The environment variable the command line reads `--backend` from when it is not given.
pub const BACKEND_ENV: &str = "GIBENCH_BACKEND";

impl GpuOptions {
    /// Checks what needs no adapter (the backend's name), so that a bad one is refused before
    /// any work.
    pub fn validate(&self) -> Result<()> {
        if let Some(b) = &self.backend {
            parse_backend(b)?;
        }
        self.wait_limit()?;
        Ok(())
    }

    /// `gpu_timeout` as a duration; refused unless a number of seconds in (0, 1e6].
    fn wait_limit(&self) -> Result<Option<Duration>> {
        match self.gpu_timeout {
            None => Ok(None),
            Some(s) if s.is_finite() && s > 0.0 && s <= 1e6 => Ok(Some(Duration::from_secs_f64(s))),
            Some(s) => Err(Error::param(
                "gpu-timeout",
                format!("expected a number of seconds above 0 and at most 1e6 (got {s})"),
            )),
        }
    }
}

/// The backends `name` selects. An unknown name is refused naming `--backend`, or
/// [`BACKEND_ENV`] when that is where the name came from.
fn parse_backend(name: &str) -> Result<wgpu::Backends> {
    Ok(match name.to_ascii_lowercase().as_str() {
        "vulkan" | "vk" => wgpu::Backends::VULKAN,
        "gl" | "gles" | "opengl" => wgpu::Backends::GL,
        "metal" => wgpu::Backends::METAL,
        "dx12" | "d3d12" => wgpu::Backends::DX12,
        "all" | "" => wgpu::Backends::all(),
        other => {
            let expected = "expected one of vulkan, gl, metal, dx12";
            if std::env::var(BACKEND_ENV).is_ok_and(|v| v == name) {
                return Err(Error::Invalid(format!(
                    "environment variable {BACKEND_ENV}: unknown backend '{other}'; {expected} \
                     (or unset it; --backend overrides it)"
                )));
            }
            return Err(Error::param(
                "backend",
                format!("unknown backend '{other}'; {expected}"),
            ));
        }
    })
}

/// Lower is better: hardware, then CPU Vulkan, then GL, then the rest.
fn preference(info: &wgpu::AdapterInfo) -> u32 {
    use wgpu::{Backend, DeviceType};
    match (info.backend, info.device_type) {
        (Backend::Gl, _) => 2,
        (_, DeviceType::DiscreteGpu) => 0,
        (_, DeviceType::IntegratedGpu | DeviceType::VirtualGpu) => 0,
        (Backend::Vulkan, DeviceType::Cpu) => 1,
        _ => 3,
    }
}

const NO_ADAPTER_HELP: &str = "no GPU adapter found. gibench needs a Vulkan driver or OpenGL; \
on a machine without a GPU install Mesa's CPU drivers (Debian/Ubuntu: \
`apt-get install mesa-vulkan-drivers` for lavapipe; llvmpipe GL comes with libgl1-mesa-dri)";

impl GpuContext {
    /// The largest buffer this device can create and bind whole as storage, bytes (the
    /// smaller of the two limits): what every storage buffer sized by a parameter is checked
    /// against before it is made.
    pub fn max_storage_buffer(&self) -> u64 {
        let limits = self.device.limits();
        limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size)
    }

    /// Picks an adapter and creates the device.
    pub fn new(opts: &GpuOptions) -> Result<GpuContext> {
        let wait_limit = opts.wait_limit()?;
        let backends = match &opts.backend {
            Some(b) => parse_backend(b)?,
            None => wgpu::Backends::all(),
        };
        let wants_named = |a: &wgpu::Adapter| match &opts.adapter {
            Some(sub) => a
                .get_info()
                .name
                .to_lowercase()
                .contains(&sub.to_lowercase()),
            None => true,
        };
        let open = |b: wgpu::Backends| {
            let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
            desc.backends = b;
            let instance = wgpu::Instance::new(desc);
            let adapters = pollster::block_on(instance.enumerate_adapters(b));
            (instance, adapters)
        };
        // GL is initialised only when no other backend offers a matching adapter (or when it is
        // the backend asked for): probing EGL prints noise on headless machines.
        let others = backends - wgpu::Backends::GL;
        let (mut instance, mut adapters) = if others.is_empty() {
            open(backends)
        } else {
            open(others)
        };
        if backends.contains(wgpu::Backends::GL)
            && !others.is_empty()
            && !adapters.iter().any(wants_named)
        {
            (instance, adapters) = open(backends);
        }
        if adapters.is_empty() {
            let which = opts
                .backend
                .as_deref()
                .map(|b| format!(" for backend '{b}'"))
                .unwrap_or_default();
            return Err(Error::Gpu(format!("{NO_ADAPTER_HELP}{which}")));
        }
        let names: Vec<String> = adapters
            .iter()
            .map(|a| format!("{} ({:?})", a.get_info().name, a.get_info().backend))
            .collect();
        let mut candidates: Vec<wgpu::Adapter> = adapters.into_iter().filter(wants_named).collect();
        if candidates.is_empty() {
            return Err(Error::param(
                "adapter",
                format!(
                    "no adapter name contains '{}'; available: {}",
                    opts.adapter.as_deref().unwrap_or(""),
                    names.join(", ")
                ),
            ));
        }
        candidates.sort_by_key(|a| preference(&a.get_info()));
        let adapter = candidates.remove(0);
        let ai = adapter.get_info();
        let features = adapter.features() & OPTIONAL_FEATURES;
        let timestamps = features.contains(OPTIONAL_FEATURES);
        let features = if timestamps {
            features
        } else {
            wgpu::Features::empty()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("gibench"),
            required_features: features,
            required_limits: opts.limits.clone().unwrap_or_else(|| adapter.limits()),
            ..Default::default()
        }))
        .map_err(|e| Error::Gpu(format!("could not create a device on '{}': {e}", ai.name)))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut v) = sink.lock() {
                v.push(e.to_string());
            }
        }));
        let lost = Arc::new(Mutex::new(None));
        let lost_sink = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            if let Ok(mut l) = lost_sink.lock() {
                *l = Some(match message.is_empty() {
                    true => format!("{reason:?}"),
                    false => format!("{reason:?}: {message}"),
                });
            }
        });
        let period = if timestamps {
            queue.get_timestamp_period()
        } else {
            0.0
        };
        let mut info = DeviceInfo {
            adapter: ai.name.clone(),
            backend: format!("{:?}", ai.backend).to_lowercase(),
            device_type: format!("{:?}", ai.device_type),
            driver: ai.driver.clone(),
            driver_info: ai.driver_info.clone(),
            timestamp_queries: timestamps,
            timestamp_period_ns: period,
            driver_env: Default::default(),
        };
        info.driver_env = info.software_env(|k| std::env::var(k).ok());
        Ok(GpuContext {
            instance,
            adapter,
            device,
            queue,
            info,
            timestamps,
            errors,
            lost,
            wait_limit,
            lose_hook: std::env::var("GIBENCH_TEST_LOSE_DEVICE")
                .ok()
                .and_then(|v| {
                    let mut parts = v.split(':');
                    let technique = parts.next()?.to_string();
                    let frame = parts.next()?.parse().ok()?;
                    let nth = parts.next().and_then(|n| n.parse().ok()).unwrap_or(1);
                    Some((technique, frame, nth, Default::default()))
                }),
        })
    }

    /// Blocks until all submitted GPU work has finished. Only the profiler and explicit
    /// readbacks call this.
    pub fn flush(&self) -> Result<()> {
        self.wait(None)?;
        self.check_errors()
    }

    /// Blocks until the given submission has finished.
    pub fn wait_for(&self, index: wgpu::SubmissionIndex) -> Result<()> {
        self.wait(Some(index))
    }

    /// Waits for `index` (the latest submission when `None`) in slices of [`WAIT_SLICE`], as
    /// long as the work takes or up to the user's `--gpu-timeout`; a long wait is announced
    /// once on standard error.
    fn wait(&self, index: Option<wgpu::SubmissionIndex>) -> Result<()> {
        let start = Instant::now();
        let mut announced = false;
        loop {
            let poll = wgpu::PollType::Wait {
                submission_index: index.clone(),
                timeout: Some(WAIT_SLICE),
            };
            self.check_lost()?;
            // wgpu 30 panics in `poll` on a device lost while waiting (an error it cannot map
            // to a PollError); the lost callback has run by then, so that panic is the loss.
            let polled =
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| self.device.poll(poll)));
            self.check_lost()?;
            let polled = match polled {
                Ok(p) => p,
                Err(panic) => std::panic::resume_unwind(panic),
            };
            match polled {
                Ok(_) => return Ok(()),
                Err(wgpu::PollError::Timeout) => {
                    let waited = start.elapsed();
                    if let Some(limit) = self.wait_limit.filter(|l| waited >= *l) {
                        return Err(Error::param(
                            "gpu-timeout",
                            format!(
                                "the GPU ({}) did not finish one submission within {:.1} s",
                                self.info.adapter,
                                limit.as_secs_f64()
                            ),
                        ));
                    }
                    if !announced && waited >= WAIT_NOTICE {
                        announced = true;
                        eprintln!(
                            "note: still waiting for the GPU ({}) after {:.0} s on one submission; \
                             gibench waits as long as it takes (--gpu-timeout sets a limit)",
                            self.info.adapter,
                            waited.as_secs_f64()
                        );
                    }
                }
                Err(e) => return Err(Error::Gpu(format!("waiting for the GPU failed: {e}"))),
            }
        }
    }

    /// [`Error::DeviceLost`] once the device is lost (its callback ran), without where.
    pub fn check_lost(&self) -> Result<()> {
        match self.lost.lock().ok().and_then(|l| l.clone()) {
            Some(what) => Err(Error::DeviceLost {
                what,
                at: String::new(),
            }),
            None => Ok(()),
        }
    }

    /// A test hook: `GIBENCH_TEST_LOSE_DEVICE=TECHNIQUE:FRAME[:NTH]` destroys the device before
    /// TECHNIQUE's frame FRAME (the NTH time it comes, 1 by default: a sweep's second point),
    /// as a driver reset would lose it (tests/it/device_loss.rs).
    pub fn test_lose_device(&self, technique: &str, frame: u32) {
        let Some((t, f, nth, seen)) = &self.lose_hook else {
            return;
        };
        if t == technique
            && *f == frame
            && seen.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1 == *nth
        {
            eprintln!("GIBENCH_TEST_LOSE_DEVICE: destroying the device before {technique}'s frame {frame} (a test hook)");
            self.device.destroy();
        }
    }

    /// The mapped contents of `slice` (mapped with `map_async` and waited for); a failure is
    /// the lost device's error where the device is lost (its callback runs on a poll), else
    /// one naming `what` was read back.
    pub fn mapped(&self, slice: &wgpu::BufferSlice<'_>, what: &str) -> Result<wgpu::BufferView> {
        slice.get_mapped_range().map_err(|e| {
            // A destroyed device says so once its queue has drained: wait for that (bounded).
            let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                self.device.poll(wgpu::PollType::Wait {
                    submission_index: None,
                    timeout: Some(WAIT_SLICE),
                })
            }));
            match self.check_errors() {
                Err(first) => first,
                Ok(()) => Error::Gpu(format!("mapping {what} failed: {e}")),
            }
        })
    }

    /// Turns a lost device, or GPU validation errors collected so far, into an error.
    pub fn check_errors(&self) -> Result<()> {
        self.check_lost()?;
        if self.errors.lock().is_ok_and(|v| !v.is_empty()) {
            // Errors from a device just lost ("device is invalid") come before its lost
            // callback, which runs on the next poll: give it the chance to say so.
            let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                self.device.poll(wgpu::PollType::Poll)
            }));
            self.check_lost()?;
        }
        let mut v = self
            .errors
            .lock()
            .map_err(|_| Error::Gpu("error sink poisoned".into()))?;
        if v.is_empty() {
            Ok(())
        } else {
            let msg = v.join("; ");
            v.clear();
            Err(Error::Gpu(msg))
        }
    }

    /// Whether the device has `features` and at least `limits`; the error names what is missing.
    pub fn check_requirements(
        &self,
        who: &str,
        features: wgpu::Features,
        limits: &wgpu::Limits,
    ) -> Result<()> {
        let missing = features - self.device.features();
        if !missing.is_empty() {
            return Err(Error::Gpu(format!(
                "{who} needs GPU features {missing:?} which '{}' lacks",
                self.info.adapter
            )));
        }
        let mut failed = Vec::new();
        limits.check_limits_with_fail_fn(&self.device.limits(), false, |name, want, have| {
            failed.push(format!("{name} (needs {want}, has {have})"))
        });
        if !failed.is_empty() {
            return Err(Error::Gpu(format!(
                "{who} needs limits that '{}' lacks: {}",
                self.info.adapter,
                failed.join(", ")
            )));
        }
        Ok(())
    }

    /// The largest square 2D texture the device supports.
    pub fn max_texture_2d(&self) -> u32 {
        self.device.limits().max_texture_dimension_2d
    }
}
