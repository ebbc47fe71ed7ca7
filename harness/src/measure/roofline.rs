//! Stage efficiency against the device's bounds (a roofline).
//!
//! A stage's time alone does not say how good its implementation is. Each GPU stage may declare
//! a [`StageCost`]: the fewest bytes it must read and write and the arithmetic operations it must
//! do for its inputs (a derivation beside each declaration says why it is the minimum). Once per
//! process, before the frames of its first stage-timed run, [`crate::run::bounds::measure_bounds`]
//! times two kernels of its own on the device: a copy ([`DeviceBounds::bandwidth`], bytes read
//! plus written per second) and independent FMA chains
//! ([`DeviceBounds::ops_per_s`], an FMA counting as two operations, as a stage's `ops` do). The
//! roofline ([`roofline`]) is then
//!
//! ```text
//! time_min   = max(bytes / bandwidth, ops / rate)
//! efficiency = time_min / measured time
//! ```
//!
//! with the measured time the one the tables show (the median flushed wall time), and the
//! binding bound the larger of the two terms. `gibench report --detailed` prints it.
//!
//! Timing: both kernels are timed by GPU timestamps around their compute pass where the adapter
//! has timestamp queries, else by the CPU wall time of their submission with the queue flushed
//! before and after (the profiler's own method; it includes the submission's fixed overhead, so
//! the kernels are sized to run for milliseconds). Each is run once untimed, then
//! [`crate::run::bounds::REPEATS`] times, and the fastest run is the bound.

use serde::{Deserialize, Serialize};

/// The fewest bytes a stage must move and the operations it must do per frame (see the module
/// docs). Bytes and operations are counted for the stage's inputs as they are in the run
/// (resolution, VPL count, grid size), computed once when the technique is built.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StageCost {
    /// Bytes the stage must read from memory (each input element once).
    pub bytes_read: f64,
    /// Bytes the stage must write (each output element once).
    pub bytes_written: f64,
    /// Arithmetic operations (floating point; an FMA counts two).
    pub ops: f64,
}

impl StageCost {
    /// Bytes read and written.
    pub fn bytes(&self) -> f64 {
        self.bytes_read + self.bytes_written
    }

    /// `count` elements each reading `read`, writing `written` bytes and doing `ops`
    /// operations.
    pub fn per_element(count: u64, read: u64, written: u64, ops: u64) -> StageCost {
        let n = count as f64;
        StageCost {
            bytes_read: n * read as f64,
            bytes_written: n * written as f64,
            ops: n * ops as f64,
        }
    }

    /// The sum of two costs.
    pub fn plus(mut self, other: StageCost) -> StageCost {
        self.add(&other);
        self
    }

    fn add(&mut self, other: &StageCost) {
        self.bytes_read += other.bytes_read;
        self.bytes_written += other.bytes_written;
        self.ops += other.ops;
    }

    /// This cost `factor` times over (a per-map or per-face cost times the maps or faces a
    /// frame draws; a sum over frames divided by their number).
    pub fn scaled(&self, factor: f64) -> StageCost {
        StageCost {
            bytes_read: self.bytes_read * factor,
            bytes_written: self.bytes_written * factor,
            ops: self.ops * factor,
        }
    }
}

/// The sum of costs declared over frames (the profiler keeps one per stage).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CostSum {
    sum: StageCost,
    frames: u32,
}

impl CostSum {
    pub(crate) fn add(&mut self, cost: &StageCost) {
        self.sum.add(cost);
        self.frames += 1;
    }

    /// The mean cost per frame, `None` when none was declared.
    pub(crate) fn mean(&self) -> Option<StageCost> {
        (self.frames > 0).then(|| self.sum.scaled(1.0 / self.frames as f64))
    }
}

/// How a bound kernel was timed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BoundTimer {
    /// GPU timestamps written at the start and end of the kernel's compute pass.
    Timestamps,
    /// CPU wall time of the kernel's submission, the queue flushed before and after (adapters
    /// without timestamp queries).
    Wall,
}

/// The device's copy bandwidth and arithmetic rate, measured once per run by
/// [`crate::run::bounds::measure_bounds`] (stored in the results file).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeviceBounds {
    /// Bytes the copy kernel read plus wrote in one run (twice the buffer's size).
    pub copy_bytes: f64,
    /// The fastest copy, milliseconds.
    pub copy_ms: f64,
    /// Operations of the FMA kernel in one run (an FMA counts two).
    pub fma_ops: f64,
    /// The fastest FMA run, milliseconds.
    pub fma_ms: f64,
    /// How both kernels were timed.
    pub timer: BoundTimer,
    /// Wall time of the whole measurement (both kernels, their warm-up and sizing runs), ms.
    pub measure_ms: f64,
}

impl DeviceBounds {
    /// Bytes per second: `copy_bytes / copy_ms`.
    pub fn bandwidth(&self) -> f64 {
        self.copy_bytes / (self.copy_ms * 1e-3)
    }

    /// Operations per second: `fma_ops / fma_ms`.
    pub fn ops_per_s(&self) -> f64 {
        self.fma_ops / (self.fma_ms * 1e-3)
    }
}

/// Which bound limits a stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binding {
    Memory,
    Arithmetic,
}

/// A stage's place under the roofline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roofline {
    /// Achieved bytes per second ÷ the bandwidth bound.
    pub bandwidth_fraction: f64,
    /// Achieved operations per second ÷ the arithmetic bound.
    pub ops_fraction: f64,
    /// max(bytes / bandwidth, ops / rate), milliseconds.
    pub time_min_ms: f64,
    /// The larger term of `time_min_ms`.
    pub binding: Binding,
    /// `time_min_ms / measured_ms` (the larger of the two fractions).
    pub efficiency: f64,
}

/// The roofline of a stage of `cost` measured at `measured_ms` on a device of `bounds`; `None`
/// when the time is not positive and finite.
pub fn roofline(cost: &StageCost, bounds: &DeviceBounds, measured_ms: f64) -> Option<Roofline> {
    if !(measured_ms.is_finite() && measured_ms > 0.0) {
        return None;
    }
    let memory_ms = cost.bytes() / bounds.bandwidth() * 1e3;
    let arithmetic_ms = cost.ops / bounds.ops_per_s() * 1e3;
    let (time_min_ms, binding) = if memory_ms >= arithmetic_ms {
        (memory_ms, Binding::Memory)
    } else {
        (arithmetic_ms, Binding::Arithmetic)
    };
    Some(Roofline {
        bandwidth_fraction: memory_ms / measured_ms,
        ops_fraction: arithmetic_ms / measured_ms,
        time_min_ms,
        binding,
        efficiency: time_min_ms / measured_ms,
    })
}
