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
//!   time (Laine's FPS column). Where the adapter has timestamp queries each GPU stage's
//!   commands are also bracketed by timestamps, and the frame's **GPU span** is recorded: from
//!   the first stage's start to the last stage's end, all on one queue (summing the stages'
//!   own intervals instead would count twice the work a GPU overlaps, as tiled GPUs do). Each
//!   frame's timestamps are read back when the throttle has waited for that frame anyway, from
//!   one of [`FRAMES_IN_FLIGHT`] + 1 buffers made once, so nothing more waits.
//!
//! Warm-up frames are run the same way and then dropped from the statistics.

use std::collections::{BTreeMap, VecDeque};
use std::time::Instant;

use crate::gpu::GpuContext;
use crate::measure::results::{FrameResult, GpuFrameSpan, StageKind, StageResult};
use crate::measure::roofline::{CostSum, StageCost};
use crate::measure::stats::Stats;
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

/// How much [`slow_stage_hook`] slows its stage.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Slowdown {
    /// Milliseconds added.
    Ms(f64),
    /// Percent of the stage's own time added.
    Percent(f64),
}

impl Slowdown {
    /// The milliseconds added to a stage that took `ms`.
    fn added(self, ms: f64) -> f64 {
        match self {
            Slowdown::Ms(add) => add,
            Slowdown::Percent(p) => ms * p / 100.0,
        }
    }
}

impl std::fmt::Display for Slowdown {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Slowdown::Ms(ms) => write!(f, "{ms} ms"),
            Slowdown::Percent(p) => write!(f, "{p} %"),
        }
    }
}

/// A deliberate slowdown for testing `gibench compare`: `GIBENCH_TEST_SLOW_STAGE=NAME:MS` adds
/// MS milliseconds to the stage NAME, `NAME:P%` adds P percent of the stage's own time (a
/// slowdown of known size whatever the machine's speed). In stages mode the milliseconds are
/// added to the stage's recorded wall time and nothing waits, so the other stages run exactly
/// as without the hook (a real busy-wait between two flushed stages let lavapipe's worker
/// threads fall asleep and made the *next* stage slower too); in frame mode the stage
/// busy-waits on the CPU (P percent of the time it took to record or run), since only a real
/// delay reaches the frame time. Read once per profiler; a run with it set says so in its
/// results' warnings ([`Profiler::test_hook_warning`]); never set in benchmark runs.
fn slow_stage_hook() -> Option<(String, Slowdown)> {
    let v = std::env::var("GIBENCH_TEST_SLOW_STAGE").ok()?;
    let (name, amount) = v.split_once(':')?;
    let slowdown = match amount.strip_suffix('%') {
        Some(p) => Slowdown::Percent(p.trim().parse().ok()?),
        None => Slowdown::Ms(amount.parse().ok()?),
    };
    Some((name.to_string(), slowdown))
}

fn busy_wait(ms: f64) {
    let t0 = Instant::now();
    while t0.elapsed().as_secs_f64() * 1e3 < ms {
        std::hint::spin_loop();
    }
}

/// Timestamp queries: `slots` ranges of 2 × [`MAX_TIMED_STAGES`] queries, one per frame that
/// may be in flight (1 in stages mode, which reads each frame back before the next).
struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    /// One per slot: a buffer being mapped cannot be written by a later frame's copy.
    readback: Vec<wgpu::Buffer>,
    period_ns: f64,
}

/// Queries per slot.
const SLOT_QUERIES: u32 = 2 * MAX_TIMED_STAGES;

/// A frame whose timestamps are on their way back (frame mode).
struct PendingSpan {
    /// Its readback slot; its stages' queries are the profiler's `slot_queries[slot]`.
    slot: usize,
    /// Whether the frame is measured (not warm-up).
    measured: bool,
}

/// Collects per-stage and per-frame timings.
pub struct Profiler {
    mode: ProfileMode,
    recording: bool,
    series: Vec<StageSeries>,
    counters: BTreeMap<String, Vec<f64>>,
    timestamps: Option<Timestamps>,
    /// [`slow_stage_hook`].
    slow: Option<(String, Slowdown)>,
    /// (series index, query index) of stages timed this frame.
    frame_queries: Vec<(usize, u32)>,
    /// Per readback slot, the queries of the frame whose timestamps it holds (swapped with
    /// `frame_queries` at the frame's end, so that no frame allocates a list).
    slot_queries: Vec<Vec<(usize, u32)>>,
    frame_commands: Vec<wgpu::CommandBuffer>,
    /// The series of the GPU stage recorded last (where a lost device is reported).
    last_stage: Option<usize>,
    in_flight: VecDeque<(wgpu::SubmissionIndex, Option<PendingSpan>)>,
    /// The GPU span of each measured frame (frame mode with timestamps).
    gpu_spans: Vec<GpuFrameSpan>,
    frame_start: Option<Instant>,
    /// When the last frame's `end_frame` returned (the next frame could have started).
    frame_end: Option<Instant>,
    frame_times: Vec<f64>,
    /// Frames begun so far.
    frames_begun: u64,
    /// Sum of the first frame's stage times (stages mode): the fill frame.
    first_frame_ms: f64,
    /// The stages that may be timed ([`Profiler::declare_stages`]); `None`: any.
    declared: Option<Vec<(&'static str, StageKind)>>,
    /// Stages timed that were not declared, or declared of the other kind, as "name (kind)".
    undeclared: Vec<String>,
}

impl Profiler {
    pub fn new(gpu: &GpuContext, mode: ProfileMode) -> Profiler {
        let timestamps = gpu.timestamps.then(|| {
            let slots = match mode {
                ProfileMode::Stages => 1,
                ProfileMode::Frame => FRAMES_IN_FLIGHT + 1,
            };
            let slot_size = SLOT_QUERIES as u64 * 8;
            Timestamps {
                set: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("profiler timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: SLOT_QUERIES * slots as u32,
                }),
                resolve: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("profiler resolve"),
                    size: slot_size * slots as u64,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                readback: (0..slots)
                    .map(|_| {
                        gpu.device.create_buffer(&wgpu::BufferDescriptor {
                            label: Some("profiler readback"),
                            size: slot_size,
                            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                            mapped_at_creation: false,
                        })
                    })
                    .collect(),
                period_ns: gpu.queue.get_timestamp_period() as f64,
            }
        });
        Profiler {
            mode,
            recording: false,
            series: Vec::new(),
            last_stage: None,
            counters: BTreeMap::new(),
            timestamps,
            slow: slow_stage_hook(),
            frame_queries: Vec::new(),
            slot_queries: Vec::new(),
            frame_commands: Vec::new(),
            in_flight: VecDeque::new(),
            gpu_spans: Vec::new(),
            frame_start: None,
            frame_end: None,
            frame_times: Vec::new(),
            frames_begun: 0,
            first_frame_ms: 0.0,
            declared: None,
            undeclared: Vec::new(),
        }
    }

    pub fn mode(&self) -> ProfileMode {
        self.mode
    }

    /// Declares the stages (name and kind) that may be timed: any other is recorded as
    /// undeclared ([`Profiler::undeclared`]), for the runner to refuse.
    pub fn declare_stages(&mut self, stages: Vec<(&'static str, StageKind)>) {
        self.declared = Some(stages);
    }

    /// The stages timed that were not declared (or declared as the other kind), as
    /// "name (GPU)" / "name (CPU)".
    pub fn undeclared(&self) -> &[String] {
        &self.undeclared
    }

    fn series_index(&mut self, name: &str, kind: StageKind) -> usize {
        if let Some(i) = self.series.iter().position(|s| s.name == name) {
            return i;
        }
        if let Some(declared) = &self.declared {
            if !declared.iter().any(|&(n, k)| n == name && k == kind) {
                let which = if kind == StageKind::Gpu { "GPU" } else { "CPU" };
                self.undeclared.push(format!("{name} ({which})"));
            }
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
        self.last_stage = Some(idx);
        let mut enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(name) });
        match self.mode {
            ProfileMode::Frame => {
                let t0 = Instant::now();
                let q = self.frame_queries.len() as u32;
                let base = self.slot() as u32 * SLOT_QUERIES;
                let ts = self.timestamps.as_ref().filter(|_| q < MAX_TIMED_STAGES);
                if let Some(ts) = ts {
                    enc.write_timestamp(&ts.set, base + 2 * q);
                }
                let r = record(&mut enc);
                if let Some(ts) = ts {
                    enc.write_timestamp(&ts.set, base + 2 * q + 1);
                    self.frame_queries.push((idx, q));
                }
                self.slow_down(name, t0);
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
                let ms = t0.elapsed().as_secs_f64() * 1e3;
                self.record_wall(idx, ms + self.added_ms(name, ms));
                Ok(r)
            }
        }
    }

    /// Runs a CPU stage and times it by wall clock, and by CPU time: that of the calling thread
    /// and of rayon's pool, where the stage's work runs across cores
    /// ([`crate::cpu::threads::pool_cpu_ms`]), in both modes; never the GPU driver's threads, which
    /// on a CPU driver run earlier frames' GPU work beside it in frame mode.
    pub fn cpu_stage<R>(&mut self, name: &str, work: impl FnOnce() -> R) -> R {
        let idx = self.series_index(name, StageKind::Cpu);
        let clock = crate::cpu::threads::pool_cpu_ms;
        let c0 = clock();
        let t0 = Instant::now();
        let r = work();
        if self.mode == ProfileMode::Frame {
            self.slow_down(name, t0);
        }
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        let ms = ms + self.added_ms(name, ms);
        if let (Some(c0), Some(c1), true) = (c0, clock(), self.recording) {
            self.series[idx].cpu.push(c1 - c0);
        }
        self.record_wall(idx, ms);
        r
    }

    /// The [`slow_stage_hook`]'s milliseconds added to this stage's recorded time `ms` (stages
    /// mode).
    fn added_ms(&self, name: &str, ms: f64) -> f64 {
        match &self.slow {
            Some((stage, slow)) if self.mode == ProfileMode::Stages && stage == name => {
                slow.added(ms)
            }
            _ => 0.0,
        }
    }

    /// A warning for the results when the `slow_stage_hook` is set.
    /// The GPU stage recorded last, if any.
    pub fn last_stage(&self) -> Option<&str> {
        self.last_stage.map(|i| self.series[i].name.as_str())
    }

    pub fn test_hook_warning(&self) -> Option<String> {
        self.slow.as_ref().map(|(stage, slow)| {
            format!(
                "GIBENCH_TEST_SLOW_STAGE was set: stage {stage} was slowed by {slow} on purpose (a test hook); these timings are not a benchmark"
            )
        })
    }

    /// The [`slow_stage_hook`] in frame mode: a real busy-wait, if it names this stage (begun
    /// at `t0`).
    fn slow_down(&self, name: &str, t0: Instant) {
        if let Some((stage, slow)) = &self.slow {
            if stage == name {
                busy_wait(slow.added(t0.elapsed().as_secs_f64() * 1e3));
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

    /// Declares the GPU stage `name`'s minimum cost this frame ([`crate::measure::roofline`]): what it
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
                // The frame's timestamps are resolved and copied in its own submission.
                let pending = match (&self.timestamps, self.frame_queries.is_empty()) {
                    (Some(ts), false) => {
                        let slot = self.slot();
                        let n = 2 * self.frame_queries.len() as u32;
                        let base = slot as u32 * SLOT_QUERIES;
                        let mut enc = gpu.device.create_command_encoder(&Default::default());
                        enc.resolve_query_set(
                            &ts.set,
                            base..base + n,
                            &ts.resolve,
                            base as u64 * 8,
                        );
                        enc.copy_buffer_to_buffer(
                            &ts.resolve,
                            base as u64 * 8,
                            &ts.readback[slot],
                            0,
                            n as u64 * 8,
                        );
                        self.frame_commands.push(enc.finish());
                        if self.slot_queries.len() <= slot {
                            self.slot_queries.resize_with(slot + 1, Vec::new);
                        }
                        std::mem::swap(&mut self.frame_queries, &mut self.slot_queries[slot]);
                        Some(PendingSpan {
                            slot,
                            measured: self.recording,
                        })
                    }
                    _ => None,
                };
                let idx = gpu.queue.submit(self.frame_commands.drain(..));
                self.in_flight.push_back((idx, pending));
                while self.in_flight.len() > FRAMES_IN_FLIGHT {
                    let (oldest, pending) = self.in_flight.pop_front().expect("non-empty");
                    gpu.wait_for(oldest.clone())?;
                    if let Some(p) = pending {
                        self.read_span(gpu, oldest, p)?;
                    }
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
                enc.copy_buffer_to_buffer(&ts.resolve, 0, &ts.readback[0], 0, n as u64 * 8);
                gpu.queue.submit([enc.finish()]);
                let slice = ts.readback[0].slice(..n as u64 * 8);
                slice.map_async(wgpu::MapMode::Read, |_| {});
                gpu.flush()?;
                let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(
                    &gpu.mapped(&slice, "a timestamp readback buffer")?[..],
                );
                ts.readback[0].unmap();
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
        while let Some((idx, pending)) = self.in_flight.pop_front() {
            if let Some(p) = pending {
                self.read_span(gpu, idx, p)?;
            }
        }
        Ok(())
    }

    /// The timestamp slot of the current frame (frame mode: one per frame that may be in
    /// flight, reused once that frame has been read back).
    fn slot(&self) -> usize {
        match (&self.timestamps, self.mode) {
            (Some(ts), ProfileMode::Frame) => {
                self.frames_begun.saturating_sub(1) as usize % ts.readback.len()
            }
            _ => 0,
        }
    }

    /// Reads back a finished frame's timestamps (its submission `done` has completed, so the
    /// mapping waits for nothing) and records its GPU span if it was measured.
    fn read_span(
        &mut self,
        gpu: &GpuContext,
        done: wgpu::SubmissionIndex,
        p: PendingSpan,
    ) -> Result<()> {
        let Some(ts) = &self.timestamps else {
            return Ok(());
        };
        let queries = &self.slot_queries[p.slot];
        let n = 2 * queries.len() as u64;
        let buffer = &ts.readback[p.slot];
        let slice = buffer.slice(..n * 8);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        gpu.wait_for(done)?;
        let span = {
            let mapped = gpu.mapped(&slice, "a timestamp readback buffer")?;
            let ticks: &[u64] = bytemuck::cast_slice(&mapped[..]);
            GpuFrameSpan::of(
                queries
                    .iter()
                    .map(|&(_, q)| (ticks[2 * q as usize], ticks[2 * q as usize + 1])),
                ts.period_ns,
            )
        };
        buffer.unmap();
        if p.measured {
            self.gpu_spans.push(span);
        }
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
        let spans: Vec<f64> = self.gpu_spans.iter().map(|s| s.span_ms).collect();
        Some(FrameResult {
            fps: 1000.0 / frame_ms.mean,
            frame_ms,
            frames_in_flight: FRAMES_IN_FLIGHT as u32,
            samples_ms: self.frame_times.clone(),
            gpu_span_ms: (!spans.is_empty()).then(|| Stats::of(&spans)),
            gpu_spans: self.gpu_spans.clone(),
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
