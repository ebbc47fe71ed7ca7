//! Option groups several commands flatten into their arguments: the CPU reference's settings
//! and cache ([`ReferenceOpts`]) and the adapter choice ([`GpuArgs`]).

use std::path::PathBuf;

use clap::Args;
use gibench_harness::cpu::reference::ReferenceSettings;
use gibench_harness::run::quality::ReferenceCache;
use gibench_harness::{Error, Result};

#[derive(Args, Clone)]
pub struct ReferenceOpts {
    /// Reference samples per pixel (cosine-weighted hemisphere paths at each visible point).
    #[arg(long = "spp", default_value_t = ReferenceSettings::default().spp)]
    pub spp: u32,
    /// Reference bounce limit for the multi-bounce image.
    #[arg(long = "bounces", default_value_t = ReferenceSettings::default().bounces)]
    pub bounces: u32,
    /// Reference seed.
    #[arg(long = "reference-seed", default_value_t = ReferenceSettings::default().seed)]
    pub reference_seed: u64,
    /// Directory of the reference cache.
    #[arg(long, default_value = DEFAULT_CACHE_DIR)]
    pub cache: PathBuf,
    /// Do not read or write the reference cache.
    #[arg(long)]
    pub no_cache: bool,
}

/// Where references are cached unless `--cache` or `--no-cache` says otherwise.
const DEFAULT_CACHE_DIR: &str = "results/cache";

/// The reference cache of a command without cache options (the paper targets of
/// `gibench reproduce`): the folder `gibench run --quality` uses by default, so that their
/// references are rendered once and reused by every run, target and later invocation.
pub fn default_reference_cache() -> ReferenceCache {
    ReferenceCache {
        dir: Some(PathBuf::from(DEFAULT_CACHE_DIR)),
    }
}

/// The most reference samples per pixel a command takes (at 256x192 and 8 bounces, hours on
/// two cores already).
const MAX_SPP: u32 = 1 << 16;
/// The most reference bounces a command takes.
const MAX_BOUNCES: u32 = 64;

impl ReferenceOpts {
    pub fn settings(&self) -> Result<ReferenceSettings> {
        if !(1..=MAX_SPP).contains(&self.spp) {
            return Err(Error::param(
                "spp",
                format!(
                    "expected 1..={MAX_SPP} samples per pixel (got {})",
                    self.spp
                ),
            ));
        }
        if !(1..=MAX_BOUNCES).contains(&self.bounces) {
            return Err(Error::param(
                "bounces",
                format!("expected 1..={MAX_BOUNCES} bounces (got {})", self.bounces),
            ));
        }
        Ok(ReferenceSettings {
            spp: self.spp,
            bounces: self.bounces,
            seed: self.reference_seed,
        })
    }
    pub fn cache(&self) -> ReferenceCache {
        ReferenceCache {
            dir: (!self.no_cache).then(|| self.cache.clone()),
        }
    }
}

#[derive(Args, Clone)]
pub struct GpuArgs {
    /// Restrict the adapter to one backend: vulkan, gl, metal or dx12.
    #[arg(long, env = "GIBENCH_BACKEND")]
    pub backend: Option<String>,
    /// Use the adapter whose name contains this (case-insensitive).
    #[arg(long, env = "GIBENCH_ADAPTER")]
    pub adapter: Option<String>,
    /// Fail when the GPU takes longer than this many seconds over one submission (default:
    /// wait as long as the work takes; a note is printed after 30 s).
    #[arg(long, env = "GIBENCH_GPU_TIMEOUT", value_name = "SECONDS")]
    pub gpu_timeout: Option<f64>,
}
