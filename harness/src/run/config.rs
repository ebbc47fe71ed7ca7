//! A run's settings ([`RunConfig`]): resolution, frames, warm-up, timing mode, seed, shadow-map
//! size, checked before any work ([`RunConfig::validate`]); re-exported by [`super::runner`].

use std::collections::BTreeMap;

use serde_json::Value;

use crate::gpu::profiler::ProfileMode;
use crate::{Error, Result};

/// Which timings a run takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingMode {
    /// Per-stage times only (GPU timestamps and flushed wall time).
    Stages,
    /// Whole-frame times only (no added synchronisation).
    Frame,
    /// Both, in two passes over the same frames.
    Both,
}

impl TimingMode {
    pub fn parse(s: &str) -> Result<TimingMode> {
        match s {
            "stages" => Ok(TimingMode::Stages),
            "frame" => Ok(TimingMode::Frame),
            "both" => Ok(TimingMode::Both),
            _ => Err(Error::param(
                "timing",
                format!("expected stages, frame or both (got '{s}')"),
            )),
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            TimingMode::Stages => "stages",
            TimingMode::Frame => "frame",
            TimingMode::Both => "both",
        }
    }
    pub(super) fn passes(self) -> &'static [ProfileMode] {
        match self {
            TimingMode::Stages => &[ProfileMode::Stages],
            TimingMode::Frame => &[ProfileMode::Frame],
            TimingMode::Both => &[ProfileMode::Stages, ProfileMode::Frame],
        }
    }
}

/// Largest width or height accepted before asking the device.
pub const MAX_RESOLUTION: u32 = 16384;

/// Settings of one run.
#[derive(Clone, Debug)]
pub struct RunConfig {
    pub resolution: [u32; 2],
    /// Measured frames.
    pub frames: u32,
    /// Warm-up frames run before the measured ones and dropped.
    pub warmup: u32,
    /// Animation frame of the first warm-up frame.
    pub first_frame: u32,
    pub timing: TimingMode,
    pub seed: u64,
    /// Edge length of each face of the direct light's cube shadow map.
    pub shadow_size: u32,
}

/// The largest frame count or frame number a command takes (frame numbers stay representable:
/// a run's last frame is first_frame + warmup + frames − 1).
pub const MAX_FRAMES: u32 = 10_000_000;

/// Checks an image size given as option `resolution`: both sides at least 1 and at most
/// [`MAX_RESOLUTION`].
pub fn check_resolution([w, h]: [u32; 2]) -> Result<()> {
    if w == 0 || h == 0 {
        return Err(Error::param(
            "resolution",
            format!("width and height must be at least 1 (got {w}x{h})"),
        ));
    }
    if w > MAX_RESOLUTION || h > MAX_RESOLUTION {
        return Err(Error::param(
            "resolution",
            format!("{w}x{h} exceeds the limit of {MAX_RESOLUTION} per side"),
        ));
    }
    Ok(())
}

impl RunConfig {
    /// Checks the settings that need no GPU.
    pub fn validate(&self) -> Result<()> {
        check_resolution(self.resolution)?;
        if self.frames == 0 {
            return Err(Error::param(
                "frames",
                "at least one measured frame is needed (got 0)",
            ));
        }
        // Frame numbers must stay representable: the last animation frame rendered is
        // first_frame + warmup + frames - 1.
        for (name, v) in [
            ("frames", self.frames),
            ("warmup", self.warmup),
            ("first-frame", self.first_frame),
        ] {
            if v > MAX_FRAMES {
                return Err(Error::param(
                    name,
                    format!("{v} exceeds the limit of {MAX_FRAMES}"),
                ));
            }
        }
        let min_warmup = crate::gpu::profiler::FRAMES_IN_FLIGHT as u32 + 1;
        if self.timing != TimingMode::Stages && self.warmup < min_warmup {
            return Err(Error::param(
                "warmup",
                format!(
                    "timing whole frames needs at least {min_warmup} warm-up frames (got {}): with \
                     {} frames in flight, frame i waits for frame i - {}, so the first (fill) frame's \
                     work would land in a measured interval; it is recorded on its own as the fill \
                     frame. Use --warmup {min_warmup} or more, or --timing stages",
                    self.warmup,
                    crate::gpu::profiler::FRAMES_IN_FLIGHT,
                    crate::gpu::profiler::FRAMES_IN_FLIGHT
                ),
            ));
        }
        if !(16..=MAX_RESOLUTION).contains(&self.shadow_size) {
            return Err(Error::param(
                "shadow-size",
                format!("expected 16..={MAX_RESOLUTION} (got {})", self.shadow_size),
            ));
        }
        Ok(())
    }

    /// Harness settings recorded in every result.
    pub fn settings(&self) -> BTreeMap<String, Value> {
        let mut m = BTreeMap::new();
        m.insert(
            "direct_shadow_map".into(),
            Value::from(format!("cube {0}x{0} Depth32Float", self.shadow_size)),
        );
        m.insert("direct_pcf_taps".into(), Value::from(16));
        m.insert(
            "frames_in_flight".into(),
            Value::from(crate::gpu::profiler::FRAMES_IN_FLIGHT),
        );
        m
    }
}
