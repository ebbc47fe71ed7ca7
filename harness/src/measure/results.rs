//! The results schema: one JSON file per (scene, technique) run, versioned, written atomically.
//! Tables and plots are rendered from these files only ([`crate::report`]).

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::measure::metrics::ComponentErrors;
use crate::measure::stats::Stats;
use crate::{Error, Result};

/// Bumped whenever a field changes meaning or is removed.
pub const SCHEMA_VERSION: u32 = 1;

/// How a stage was run and timed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StageKind {
    /// GPU work, timed by timestamps and by flushed CPU wall time.
    Gpu,
    /// CPU work, timed by wall time.
    Cpu,
}

/// Timings of one named stage over the measured frames (milliseconds).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StageResult {
    pub name: String,
    pub kind: StageKind,
    /// GPU timestamps (end − start) per frame; absent when the adapter has no timestamp queries
    /// or the run did not time stages.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gpu_ms: Option<Stats>,
    /// CPU wall time with the queue flushed before and after the stage (Laine et al. 2007's
    /// per-task method); for CPU stages, plain wall time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_ms: Option<Stats>,
    /// CPU stages: CPU time beside wall time — of the calling thread and rayon's pool's workers
    /// (the stage's work across cores; not the GPU driver's threads), in both timing modes
    /// ([`crate::cpu::threads::pool_cpu_ms`]). Below wall time when the work waits or is
    /// descheduled on a busy machine, above it when it runs on several cores.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu_ms: Option<Stats>,
}

/// Whole-frame timings with no added synchronisation (Laine's FPS column).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameResult {
    /// Time between consecutive frame starts, with at most `frames_in_flight` frames queued.
    pub frame_ms: Stats,
    /// 1000 / mean frame time.
    pub fps: f64,
    pub frames_in_flight: u32,
    /// Every measured frame's time, in order (for spotting spikes and their frames).
    #[serde(default)]
    pub samples_ms: Vec<f64>,
    /// The GPU frame time: per measured frame, GPU timestamps from the first stage's start to
    /// the last stage's end (where the adapter has timestamp queries).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gpu_span_ms: Option<Stats>,
    /// Per measured frame, in order: its GPU span and its stages' own timestamp intervals,
    /// summed and the longest.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub gpu_spans: Vec<GpuFrameSpan>,
}

/// One frame's GPU timestamps in frame timing (every stage's commands submitted together,
/// on one queue), milliseconds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GpuFrameSpan {
    /// From the first stage's start to the last stage's end.
    pub span_ms: f64,
    /// The stages' own intervals (end − start) summed: more than the span where the GPU
    /// overlaps stages (tiled GPUs), less where it idles between them.
    pub stage_sum_ms: f64,
    /// The longest stage's interval: never more than the span on one in-order queue.
    pub longest_stage_ms: f64,
}

impl GpuFrameSpan {
    /// The span of one frame's stage intervals `(start, end)` in ticks, in submission order,
    /// `period_ns` nanoseconds a tick.
    pub fn of(intervals: impl IntoIterator<Item = (u64, u64)>, period_ns: f64) -> GpuFrameSpan {
        let ms = |ticks: u64| ticks as f64 * period_ns * 1e-6;
        let (mut first, mut last, mut sum, mut longest) = (None, 0, 0.0, 0.0f64);
        for (a, b) in intervals {
            first.get_or_insert(a);
            last = b;
            let own = ms(b.saturating_sub(a));
            sum += own;
            longest = longest.max(own);
        }
        GpuFrameSpan {
            span_ms: first.map_or(0.0, |f| ms(last.saturating_sub(f))),
            stage_sum_ms: sum,
            longest_stage_ms: longest,
        }
    }
}

/// What the run was run on.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DeviceInfo {
    pub adapter: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    pub driver_info: String,
    pub timestamp_queries: bool,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period_ns: f32,
    /// The environment variables that set how a software rasteriser runs, as they were set
    /// ([`SOFTWARE_ENV`]; empty on a GPU, or where none was set): a CPU device's thread count
    /// changes its speed, so runs made with other settings are another device's.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub driver_env: std::collections::BTreeMap<String, String>,
}

/// Environment variables read by software rasterisers that change their speed: Mesa llvmpipe's
/// and lavapipe's thread count (`LP_NUM_THREADS`; 0 runs everything on the submitting thread).
pub const SOFTWARE_ENV: [&str; 1] = ["LP_NUM_THREADS"];

impl DeviceInfo {
    /// Whether the adapter is a CPU rasteriser rather than a GPU: wgpu's CPU device type, or a
    /// name of the software drivers (Mesa's llvmpipe, lavapipe and softpipe, SwiftShader,
    /// Microsoft's WARP, "Basic Render Driver"), which some backends report as another type.
    pub fn is_software(&self) -> bool {
        let name = format!("{} {}", self.adapter, self.driver).to_lowercase();
        self.device_type == "Cpu"
            || [
                "llvmpipe",
                "lavapipe",
                "softpipe",
                "swiftshader",
                "basic render driver",
                "warp",
            ]
            .iter()
            .any(|s| name.contains(s))
    }

    /// [`SOFTWARE_ENV`]'s variables as `get` reads them, where the adapter is a software
    /// rasteriser (a GPU's runs record none).
    pub fn software_env(
        &self,
        get: impl Fn(&str) -> Option<String>,
    ) -> std::collections::BTreeMap<String, String> {
        if !self.is_software() {
            return Default::default();
        }
        (SOFTWARE_ENV.iter())
            .filter_map(|k| Some((k.to_string(), get(k)?)))
            .collect()
    }

    /// "adapter (backend)", with any [`SOFTWARE_ENV`] setting after the backend
    /// ("llvmpipe (LLVM 15.0.6, 256 bits) (vulkan, LP_NUM_THREADS=0)"): what a run ran on.
    pub fn label(&self) -> String {
        format!("{} ({}{})", self.adapter, self.backend, self.env_text())
    }

    /// The recorded [`SOFTWARE_ENV`] settings as ", LP_NUM_THREADS=0" (empty where none): for
    /// every description of the device.
    pub fn env_text(&self) -> String {
        (self.driver_env.iter())
            .map(|(k, v)| format!(", {k}={v}"))
            .collect()
    }
}

/// Frames: how many were measured, how many warm-up frames were dropped before them.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FrameRange {
    pub warmup: u32,
    pub measured: u32,
    /// Frame index of the first measured frame in the animation.
    pub first: u32,
}

/// One run of one technique on one scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunResult {
    pub schema_version: u32,
    pub gibench_version: String,
    /// `git describe --always --dirty` of the checkout, if known.
    pub git_commit: String,
    /// Seconds since the Unix epoch when the run finished.
    pub timestamp: u64,
    pub scene: String,
    pub technique: String,
    /// The technique's parameters after defaults were applied.
    pub parameters: BTreeMap<String, serde_json::Value>,
    /// Harness settings shared by all techniques (shadow-map size, PCF taps, ...).
    pub settings: BTreeMap<String, serde_json::Value>,
    pub resolution: [u32; 2],
    pub frames: FrameRange,
    pub seed: u64,
    /// `stages`, `frame` or `both`.
    pub timing_mode: String,
    pub device: DeviceInfo,
    /// In execution order.
    pub stages: Vec<StageResult>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<FrameResult>,
    /// Per-stage counters averaged over measured frames (e.g. shadow maps rendered).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub counters: BTreeMap<String, Stats>,
    /// Wall time of the technique's once-per-scene preparation (`TechniqueInfo::prepare`),
    /// milliseconds; shared by the timing passes and the quality pass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prepare_ms: Option<f64>,
    /// The first frame rendered (warm-up included), in the stages pass: the sum of its stage
    /// times, milliseconds. For `laine` it is the fill frame that renders every map (the
    /// paper's "stutter").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_frame_ms: Option<f64>,
    /// Error against the CPU reference (`gibench run --quality`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quality: Option<crate::measure::metrics::QualitySummary>,
    /// Images written next to the results file (relative paths).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub images: Vec<String>,
    /// What the run found wrong with its own output (e.g. irradiance past the half-float
    /// limit), also printed after the run.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Wall time of the calibration workload timed in the same session
    /// ([`crate::measure::calibrate::calibration_ms`]): `gibench compare` divides by it so that drift of
    /// a shared machine between sessions cancels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration_ms: Option<f64>,
    /// The process's peak resident memory when the run ended (`VmHWM`, MB; Linux): the
    /// technique's own peak when it was the only one run in the process (one `--technique`),
    /// else the largest of those run so far.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_memory_mb: Option<f64>,
    /// The device's copy bandwidth and arithmetic rate, measured once per process before the
    /// frames of its first run that times stages ([`crate::measure::roofline`]); absent in older files
    /// and frame-only runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device_bounds: Option<crate::measure::roofline::DeviceBounds>,
    /// Each GPU stage's declared minimum cost per frame (mean over the measured frames), by
    /// stage name; a stage that declares none is absent.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub stage_costs: BTreeMap<String, crate::measure::roofline::StageCost>,
}

impl RunResult {
    /// Writes the result as pretty JSON, atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let json =
            serde_json::to_vec_pretty(self).map_err(|e| Error::bad_file(path, e.to_string()))?;
        crate::output::write_atomic(path, &json)
    }

    /// Reads and checks a results file.
    pub fn read(path: &Path) -> Result<RunResult> {
        let bytes = crate::error::read_bounded(path, 1 << 30)?;
        let r: RunResult = crate::error::from_json(&bytes)
            .map_err(|e| Error::bad_file(path, format!("not a gibench results file: {e}")))?;
        if r.schema_version != SCHEMA_VERSION {
            return Err(Error::bad_file(
                path,
                format!(
                    "results schema version {} (this gibench reads version {SCHEMA_VERSION})",
                    r.schema_version
                ),
            ));
        }
        r.check().map_err(|e| Error::bad_file(path, e))?;
        Ok(r)
    }

    /// What tables would print wrong from a file that parses: an empty scene or technique
    /// name, an unnamed or repeated stage (its time would count twice), a negative time.
    fn check(&self) -> std::result::Result<(), String> {
        for (field, value) in [("scene", &self.scene), ("technique", &self.technique)] {
            if value.trim().is_empty() {
                return Err(format!("'{field}' is empty"));
            }
        }
        let mut seen = std::collections::HashSet::new();
        for (i, st) in self.stages.iter().enumerate() {
            if st.name.trim().is_empty() {
                return Err(format!("stages[{i}] has no name"));
            }
            if !seen.insert(st.name.as_str()) {
                return Err(format!("stage '{}' is listed twice", st.name));
            }
            for (field, stats) in [
                ("gpu_ms", &st.gpu_ms),
                ("wall_ms", &st.wall_ms),
                ("cpu_ms", &st.cpu_ms),
            ] {
                if let Some(s) = stats {
                    non_negative(s).map_err(|v| {
                        format!("stage '{}': {field}.{v} (times are not negative)", st.name)
                    })?;
                }
            }
        }
        if let Some(f) = &self.frame {
            non_negative(&f.frame_ms)
                .map_err(|v| format!("frame.frame_ms.{v} (times are not negative)"))?;
            if let Some(s) = &f.gpu_span_ms {
                non_negative(s)
                    .map_err(|v| format!("frame.gpu_span_ms.{v} (times are not negative)"))?;
            }
        }
        if let Some(c) = self.calibration_ms {
            if !(CALIBRATION_MS.0..=CALIBRATION_MS.1).contains(&c) {
                return Err(format!(
                    "calibration_ms is {}; the calibration workload takes between {:e} and {:e} \
                     ms on any machine gibench runs on",
                    shown(c),
                    CALIBRATION_MS.0,
                    CALIBRATION_MS.1
                ));
            }
        }
        if let Some(b) = &self.device_bounds {
            for (field, v) in [
                ("copy_bytes", b.copy_bytes),
                ("copy_ms", b.copy_ms),
                ("fma_ops", b.fma_ops),
                ("fma_ms", b.fma_ms),
            ] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(format!(
                        "device_bounds.{field} is {} (expected a finite number above 0)",
                        shown(v)
                    ));
                }
            }
        }
        for (stage, c) in &self.stage_costs {
            for (field, v) in [
                ("bytes_read", c.bytes_read),
                ("bytes_written", c.bytes_written),
                ("ops", c.ops),
            ] {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(format!(
                        "stage_costs.{stage}.{field} is {} (expected a finite number, not negative)",
                        shown(v)
                    ));
                }
            }
        }
        if let Some(q) = &self.quality {
            // Errors are not negative (the bias is signed).
            for (field, stats) in [
                ("rmse", &q.rmse),
                ("rel_mse", &q.rel_mse),
                ("mae", &q.mae),
                ("flip_mean", &q.flip_mean),
            ] {
                non_negative(stats)
                    .map_err(|v| format!("quality.{field}.{v} (errors are not negative)"))?;
            }
            for (i, c) in q.components.iter().enumerate() {
                if !ComponentErrors::NAMES.contains(&c.component.as_str()) {
                    return Err(format!(
                        "quality.components[{i}].component is '{}' (expected {})",
                        c.component,
                        ComponentErrors::NAMES.join(" or ")
                    ));
                }
                for (field, stats) in [("rel_mse", &c.rel_mse), ("flip_mean", &c.flip_mean)] {
                    non_negative(stats).map_err(|v| {
                        format!("quality.components[{i}].{field}.{v} (errors are not negative)")
                    })?;
                }
            }
            for (i, f) in q.frames.iter().enumerate() {
                for (field, v) in [
                    ("rmse", Some(f.rmse)),
                    ("rel_mse", Some(f.rel_mse)),
                    ("mae", Some(f.mae)),
                    ("flip_mean", Some(f.flip_mean)),
                    ("temporal", f.temporal),
                ] {
                    if v.is_some_and(|v| v < 0.0) {
                        return Err(format!(
                            "quality.frames[{i}].{field} is {} (errors are not negative)",
                            shown(v.unwrap_or_default())
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// The stage named `name`, if any.
    pub fn stage(&self, name: &str) -> Option<&StageResult> {
        self.stages.iter().find(|s| s.name == name)
    }
}

/// `v` for a message: with an exponent when very large or small (`1e-300`, not 300 digits).
fn shown(v: f64) -> String {
    if v != 0.0 && !(1e-3..1e9).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// The range a valid `calibration_ms` lies in, milliseconds: the workload takes about 10 ms on
/// the CI machine; these bounds are a thousand times either way and more.
pub const CALIBRATION_MS: (f64, f64) = (1e-3, 1e5);

/// `Err("NAME is V")` for the first statistic of `s` below zero
/// (missing ones, read as NaN, pass).
fn non_negative(s: &Stats) -> std::result::Result<(), String> {
    let named = [
        ("mean", s.mean),
        ("median", s.median),
        ("p5", s.p5),
        ("p95", s.p95),
        ("p99", s.p99),
        ("min", s.min),
        ("max", s.max),
    ];
    match named.into_iter().find(|(_, v)| *v < 0.0) {
        Some((name, v)) => Err(format!("{name} is {}", shown(v))),
        None => Ok(()),
    }
}

impl StageResult {
    /// The per-stage time tables show: the median flushed wall time (Laine et al. 2007's
    /// per-task method, and the one that is right on every adapter: lavapipe's timestamps around
    /// some compute passes were seen to miss most of their work), else the median GPU timestamp
    /// time.
    pub fn best_ms(&self) -> Option<f64> {
        self.best_stats().map(|s| s.median)
    }

    /// The per-frame statistics [`StageResult::best_ms`] takes its median of.
    pub fn best_stats(&self) -> Option<&Stats> {
        self.wall_ms.as_ref().or(self.gpu_ms.as_ref())
    }
}

#[cfg(test)]
mod span_tests {
    use super::GpuFrameSpan;

    /// The span runs from the first stage's start to the last stage's end: overlapping stages
    /// (a tiled GPU) give a span below their sum, stages with gaps between them one above it.
    /// Catches a span taken as the sum, or from the wrong ends.
    #[test]
    fn the_span_is_first_start_to_last_end() {
        // Ticks of 1 µs: stages 0–4, 2–7 and 6–9 ms, overlapping.
        let overlapping = GpuFrameSpan::of([(0, 4000), (2000, 7000), (6000, 9000)], 1000.0);
        assert_eq!(overlapping.span_ms, 9.0);
        assert_eq!(overlapping.stage_sum_ms, 12.0);
        assert_eq!(overlapping.longest_stage_ms, 5.0);
        let gaps = GpuFrameSpan::of([(100, 200), (500, 600)], 1e6);
        assert_eq!((gaps.span_ms, gaps.stage_sum_ms), (500.0, 200.0));
        assert_eq!(GpuFrameSpan::of(std::iter::empty(), 1.0).span_ms, 0.0);
    }
}

#[cfg(test)]
mod device_tests {
    use super::DeviceInfo;

    /// A software rasteriser records its thread setting where one is set, and shows it in its
    /// label; a GPU records none whatever the environment holds. Catches a GPU run labelled
    /// with llvmpipe's variable and a CPU run whose setting is lost.
    #[test]
    fn a_software_rasterisers_thread_setting_is_recorded_and_labelled() {
        let set = |k: &str| (k == "LP_NUM_THREADS").then(|| "0".to_string());
        let mut cpu = DeviceInfo {
            adapter: "llvmpipe (LLVM 15.0.6, 256 bits)".into(),
            backend: "vulkan".into(),
            device_type: "Cpu".into(),
            ..Default::default()
        };
        assert!(cpu.software_env(|_| None).is_empty());
        cpu.driver_env = cpu.software_env(set);
        assert_eq!(
            cpu.label(),
            "llvmpipe (LLVM 15.0.6, 256 bits) (vulkan, LP_NUM_THREADS=0)"
        );
        let gpu = DeviceInfo {
            adapter: "NVIDIA H100".into(),
            backend: "vulkan".into(),
            device_type: "DiscreteGpu".into(),
            ..Default::default()
        };
        assert!(gpu.software_env(set).is_empty());
        assert_eq!(gpu.label(), "NVIDIA H100 (vulkan)");
    }
}
