//! The profiler: every stage is timed by name without the stage asking how.
//!
//! Two modes, run one after the other over the same frames (`TimingMode::Both`):
//!
//! * [`ProfileMode::Stages`]: each GPU stage is recorded into its own command buffer and
//!   submitted alone, with the queue flushed before and after it. The CPU wall time between the
//!   two flushes is Laine et al.'s per-task time; where the adapter has timestamp queries a
//!   timestamp is also written at the start and end of the stage's commands (GPU time). CPU
//!   stages are timed by wall time.
//! * [`ProfileMode::Frame`]: stages add their commands to the frame's list, the whole frame is
//!   submitted at once and nothing waits except the swap-chain-like throttle that keeps at most
//!   [`FRAMES_IN_FLIGHT`] frames queued. The time between consecutive frame starts is the frame
//!   time (Laine's FPS column).
//!
//! Warm-up frames are run the same way and then dropped from the statistics.

use std::collections::{BTreeMap, VecDeque};
use std::time::Instant;

use crate::gpu::GpuContext;
use crate::results::{FrameResult, StageKind, StageResult};
use crate::roofline::{CostSum, StageCost};
use crate::stats::Stats;
use crate::Result;

/// Frames that may be queued on the GPU in [`ProfileMode::Frame`], as with a double-buffered
/// swap chain.
pub const FRAMES_IN_FLIGHT: usize = 2;

/// Most GPU stages per frame that get timestamps.
const MAX_TIMED_STAGES: u32 = 64;

/// How the frames are being timed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProfileMode {
    Stages,
    Frame,
}

struct StageSeries {
    name: String,
    kind: StageKind,
    wall: Vec<f64>,
    gpu: Vec<f64>,
    /// Thread CPU time (CPU stages).
    cpu: Vec<f64>,
    /// The costs the stage declared in measured frames ([`Profiler::stage_cost`]).
    cost: CostSum,
}

/// A deliberate slowdown for testing `gibench compare`: `GIBENCH_TEST_SLOW_STAGE=NAME:MS` adds
/// MS milliseconds to the stage NAME. In stages mode the milliseconds are added to the stage's
/// recorded wall time and nothing waits, so the other stages run exactly as without the hook (a
/// real busy-wait between two flushed stages let lavapipe's worker threads fall asleep and made
/// the *next* stage slower too); in frame mode the stage busy-waits on the CPU, since only a
/// real delay reaches the frame time. Read once per profiler; a run with it set says so in its
/// results' warnings ([`Profiler::test_hook_warning`]); never set in benchmark runs.
fn slow_stage_hook() -> Option<(String, f64)> {
    let v = std::env::var("GIBENCH_TEST_SLOW_STAGE").ok()?;
    let (name, ms) = v.split_once(':')?;
    Some((name.to_string(), ms.parse().ok()?))
}

fn busy_wait(ms: f64) {
    let t0 = Instant::now();
    while t0.elapsed().as_secs_f64() * 1e3 < ms {
        std::hint::spin_loop();
    }
}

struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    period_ns: f64,
}

/// Collects per-stage and per-frame timings.
pub struct Profiler {
    mode: ProfileMode,
    recording: bool,
    series: Vec<StageSeries>,
    counters: BTreeMap<String, Vec<f64>>,
    timestamps: Option<Timestamps>,
    /// [`slow_stage_hook`].
    slow: Option<(String, f64)>,
    /// (series index, query index) of stages timed this frame.
    frame_queries: Vec<(usize, u32)>,
    frame_commands: Vec<wgpu::CommandBuffer>,
    in_flight: VecDeque<wgpu::SubmissionIndex>,
    frame_start: Option<Instant>,
    /// When the last frame's `end_frame` returned (the next frame could have started).
    frame_end: Option<Instant>,
    frame_times: Vec<f64>,
    /// Frames begun so far.
    frames_begun: u64,
    /// Sum of the first frame's stage times (stages mode): the fill frame.
    first_frame_ms: f64,
}

impl Profiler {
    pub fn new(gpu: &GpuContext, mode: ProfileMode) -> Profiler {
        let timestamps = (gpu.timestamps && mode == ProfileMode::Stages).then(|| {
            let n = 2 * MAX_TIMED_STAGES;
            let size = n as u64 * 8;
            Timestamps {
                set: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("profiler timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: n,
                }),
                resolve: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("profiler resolve"),
                    size,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                readback: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("profiler readback"),
                    size,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                period_ns: gpu.queue.get_timestamp_period() as f64,
            }
        });
        Profiler {
            mode,
            recording: false,
            series: Vec::new(),
            counters: BTreeMap::new(),
            timestamps,
            slow: slow_stage_hook(),
            frame_queries: Vec::new(),
            frame_commands: Vec::new(),
            in_flight: VecDeque::new(),
            frame_start: None,
            frame_end: None,
            frame_times: Vec::new(),
            frames_begun: 0,
            first_frame_ms: 0.0,
        }
    }

    pub fn mode(&self) -> ProfileMode {
        self.mode
    }

    fn series_index(&mut self, name: &str, kind: StageKind) -> usize {
        if let Some(i) = self.series.iter().position(|s| s.name == name) {
            return i;
        }
        self.series.push(StageSeries {
            name: name.to_string(),
            kind,
            wall: Vec::new(),
            gpu: Vec::new(),
            cpu: Vec::new(),
            cost: CostSum::default(),
        });
        self.series.len() - 1
    }

    /// Starts a frame. `measured` false marks a warm-up frame: it runs the same way but its
    /// timings are dropped.
    pub fn begin_frame(&mut self, measured: bool) {
        let now = Instant::now();
        if self.mode == ProfileMode::Frame {
            if let Some(prev) = self.frame_start {
                if self.recording {
                    self.frame_times
                        .push(now.duration_since(prev).as_secs_f64() * 1e3);
                }
            }
        }
        self.frames_begun += 1;
        self.frame_start = Some(now);
        self.recording = measured;
        self.frame_queries.clear();
    }

    /// Runs a GPU stage: `record` encodes its commands into the encoder it is given.
    pub fn gpu_stage<R>(
        &mut self,
        gpu: &GpuContext,
        name: &str,
        record: impl FnOnce(&mut wgpu::CommandEncoder) -> R,
    ) -> Result<R> {
        let idx = self.series_index(name, StageKind::Gpu);
        let mut enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(name) });
        match self.mode {
            ProfileMode::Frame => {
                let r = record(&mut enc);
                self.slow_down(name);
                self.frame_commands.push(enc.finish());
                Ok(r)
            }
            ProfileMode::Stages => {
                let q = self.frame_queries.len() as u32;
                let ts = self.timestamps.as_ref().filter(|_| q < MAX_TIMED_STAGES);
                gpu.flush()?;
                let t0 = Instant::now();
                if let Some(ts) = ts {
                    enc.write_timestamp(&ts.set, 2 * q);
                }
                let r = record(&mut enc);
                if let Some(ts) = ts {
                    enc.write_timestamp(&ts.set, 2 * q + 1);
                    self.frame_queries.push((idx, q));
                }
                gpu.queue.submit([enc.finish()]);
                gpu.flush()?;
                let ms = t0.elapsed().as_secs_f64() * 1e3 + self.added_ms(name);
                self.record_wall(idx, ms);
                Ok(r)
            }
        }
    }

    /// Runs a CPU stage and times it by wall clock, and by CPU time: that of the calling thread
    /// and of rayon's pool, where the stage's work runs across cores
    /// ([`crate::threads::pool_cpu_ms`]), in both modes; never the GPU driver's threads, which
    /// on a CPU driver run earlier frames' GPU work beside it in frame mode.
    pub fn cpu_stage<R>(&mut self, name: &str, work: impl FnOnce() -> R) -> R {
        let idx = self.series_index(name, StageKind::Cpu);
        let clock = crate::threads::pool_cpu_ms;
        let c0 = clock();
        let t0 = Instant::now();
        let r = work();
        if self.mode == ProfileMode::Frame {
            self.slow_down(name);
        }
        let ms = t0.elapsed().as_secs_f64() * 1e3 + self.added_ms(name);
        if let (Some(c0), Some(c1), true) = (c0, clock(), self.recording) {
            self.series[idx].cpu.push(c1 - c0);
        }
        self.record_wall(idx, ms);
        r
    }

    /// The [`slow_stage_hook`]'s milliseconds added to this stage's recorded time (stages mode).
    fn added_ms(&self, name: &str) -> f64 {
        match &self.slow {
            Some((stage, ms)) if self.mode == ProfileMode::Stages && stage == name => *ms,
            _ => 0.0,
        }
    }

    /// A warning for the results when the `slow_stage_hook` is set.
    pub fn test_hook_warning(&self) -> Option<String> {
        self.slow.as_ref().map(|(stage, ms)| {
            format!(
                "GIBENCH_TEST_SLOW_STAGE was set: stage {stage} was slowed by {ms} ms on purpose (a test hook); these timings are not a benchmark"
            )
        })
    }

    /// The [`slow_stage_hook`] in frame mode: a real busy-wait, if it names this stage.
    fn slow_down(&self, name: &str) {
        if let Some((stage, ms)) = &self.slow {
            if stage == name {
                busy_wait(*ms);
            }
        }
    }

    fn record_wall(&mut self, series: usize, ms: f64) {
        if self.frames_begun == 1 {
            self.first_frame_ms += ms;
        }
        if self.recording {
            self.series[series].wall.push(ms);
        }
    }

    /// The first frame's time in stages mode: the sum of its stages' wall times (GPU stages
    /// flushed; the fill frame, Laine et al.'s "stutter", when a technique fills all its maps
    /// then). `None` in frame mode or before any frame.
    pub fn first_frame_ms(&self) -> Option<f64> {
        (self.mode == ProfileMode::Stages && self.frames_begun > 0).then_some(self.first_frame_ms)
    }

    /// Declares the GPU stage `name`'s minimum cost this frame ([`crate::roofline`]): what it
    /// must read, write and compute for its inputs. Called beside the stage, with a cost the
    /// technique computed once; the results hold its mean over the measured frames.
    pub fn stage_cost(&mut self, name: &str, cost: StageCost) {
        let idx = self.series_index(name, StageKind::Gpu);
        if self.recording {
            self.series[idx].cost.add(&cost);
        }
    }

    /// The declared costs by stage name (means over the measured frames).
    pub fn stage_costs(&self) -> BTreeMap<String, StageCost> {
        self.series
            .iter()
            .filter_map(|s| Some((s.name.clone(), s.cost.mean()?)))
            .collect()
    }

    /// Records a per-frame counter (e.g. shadow maps rendered this frame).
    pub fn count(&mut self, name: &str, value: f64) {
        if self.recording {
            self.counters
                .entry(name.to_string())
                .or_default()
                .push(value);
        }
    }

    /// Ends the frame: in frame mode submits it (waiting only for the frame
    /// [`FRAMES_IN_FLIGHT`] back); in stage mode reads back this frame's timestamps.
    pub fn end_frame(&mut self, gpu: &GpuContext) -> Result<()> {
        match self.mode {
            ProfileMode::Frame => {
                let idx = gpu.queue.submit(self.frame_commands.drain(..));
                self.in_flight.push_back(idx);
                while self.in_flight.len() > FRAMES_IN_FLIGHT {
                    let oldest = self.in_flight.pop_front().expect("non-empty");
                    gpu.wait_for(oldest)?;
                }
                self.frame_end = Some(Instant::now());
                gpu.check_errors()
            }
            ProfileMode::Stages => {
                let (Some(ts), false) = (&self.timestamps, self.frame_queries.is_empty()) else {
                    return gpu.check_errors();
                };
                let n = 2 * self.frame_queries.len() as u32;
                let mut enc = gpu.device.create_command_encoder(&Default::default());
                enc.resolve_query_set(&ts.set, 0..n, &ts.resolve, 0);
                enc.copy_buffer_to_buffer(&ts.resolve, 0, &ts.readback, 0, n as u64 * 8);
                gpu.queue.submit([enc.finish()]);
                let slice = ts.readback.slice(..n as u64 * 8);
                slice.map_async(wgpu::MapMode::Read, |_| {});
                gpu.flush()?;
                let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(
                    &slice.get_mapped_range().map_err(|e| {
                        crate::Error::Gpu(format!("mapping a readback buffer failed: {e}"))
                    })?[..],
                );
                ts.readback.unmap();
                if self.recording {
                    for &(series, q) in &self.frame_queries {
                        let (a, b) = (ticks[2 * q as usize], ticks[2 * q as usize + 1]);
                        let ms = b.saturating_sub(a) as f64 * ts.period_ns * 1e-6;
                        self.series[series].gpu.push(ms);
                    }
                }
                Ok(())
            }
        }
    }

    /// Waits for everything queued (end of a frame-mode sequence). The last frame's duration is
    /// the time from its start to the end of all queued work.
    pub fn finish(&mut self, gpu: &GpuContext) -> Result<()> {
        // The last frame's interval ends where the next frame could have begun (when its
        // `end_frame` returned), not when all queued work is done: only complete intervals.
        if self.mode == ProfileMode::Frame && self.recording {
            if let (Some(start), Some(end)) = (self.frame_start.take(), self.frame_end) {
                if end >= start {
                    self.frame_times
                        .push(end.duration_since(start).as_secs_f64() * 1e3);
                }
            }
        }
        self.recording = false;
        gpu.flush()?;
        self.in_flight.clear();
        Ok(())
    }

    pub fn stage_results(&self) -> Vec<StageResult> {
        self.series
            .iter()
            .map(|s| StageResult {
                name: s.name.clone(),
                kind: s.kind,
                gpu_ms: (!s.gpu.is_empty()).then(|| Stats::of(&s.gpu)),
                wall_ms: (!s.wall.is_empty()).then(|| Stats::of(&s.wall)),
                cpu_ms: (!s.cpu.is_empty()).then(|| Stats::of(&s.cpu)),
            })
            .collect()
    }

    /// Whole-frame statistics (frame mode only).
    pub fn frame_result(&self) -> Option<FrameResult> {
        if self.frame_times.is_empty() {
            return None;
        }
        let frame_ms = Stats::of(&self.frame_times);
        Some(FrameResult {
            fps: 1000.0 / frame_ms.mean,
            frame_ms,
            frames_in_flight: FRAMES_IN_FLIGHT as u32,
            samples_ms: self.frame_times.clone(),
        })
    }

    /// Counter statistics.
    pub fn counter_results(&self) -> BTreeMap<String, Stats> {
        self.counters
            .iter()
            .map(|(k, v)| (k.clone(), Stats::of(v)))
            .collect()
    }
}
