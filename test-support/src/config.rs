//! Run settings for tests: one frame, changed where a test needs more (the only place a
//! test, bench or test helper spells out a `RunConfig`).

use gibench_harness::run::runner::{RunConfig, TimingMode};

/// A [`RunConfig`] built up from one frame ([`one_frame`]).
#[derive(Clone, Debug)]
pub struct Config(RunConfig);

/// One measured frame at `resolution`: no warm-up, starting at frame 0, stage timing, seed 1,
/// direct shadow maps of 256 texels a side; each setting can be changed before
/// [`Config::build`].
pub fn one_frame(resolution: [u32; 2]) -> Config {
    Config(RunConfig {
        resolution,
        frames: 1,
        warmup: 0,
        first_frame: 0,
        timing: TimingMode::Stages,
        seed: 1,
        shadow_size: 256,
    })
}

/// [`one_frame`] with direct shadow maps of `shadow_size`.
pub fn run_config(resolution: [u32; 2], shadow_size: u32) -> RunConfig {
    one_frame(resolution).shadow_size(shadow_size).build()
}

impl Config {
    /// Measured frames.
    pub fn frames(mut self, frames: u32) -> Config {
        self.0.frames = frames;
        self
    }

    /// Warm-up frames before the measured ones.
    pub fn warmup(mut self, warmup: u32) -> Config {
        self.0.warmup = warmup;
        self
    }

    /// The animation frame of the first (warm-up) frame.
    pub fn first_frame(mut self, first_frame: u32) -> Config {
        self.0.first_frame = first_frame;
        self
    }

    /// What is timed.
    pub fn timing(mut self, timing: TimingMode) -> Config {
        self.0.timing = timing;
        self
    }

    /// The run's random seed.
    pub fn seed(mut self, seed: u64) -> Config {
        self.0.seed = seed;
        self
    }

    /// Edge length of each face of the direct light's shadow map.
    pub fn shadow_size(mut self, shadow_size: u32) -> Config {
        self.0.shadow_size = shadow_size;
        self
    }

    /// The settings.
    pub fn build(self) -> RunConfig {
        self.0
    }
}
