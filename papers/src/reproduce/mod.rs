//! `gibench reproduce TARGET`: regenerate a paper's tables, one module per paper over the typed
//! run API ([`gibench_harness::run::session`]), with the paper's published figures read from
//! `results/papers/<paper>.json` and printed beside ours, each labelled with its source.
//!
//! * [`laine2007`]: Laine et al. 2007, Tables 1 and 2, VPL management, dispersion.
//! * [`gaitatzes2010`]: Gaitatzes et al. 2010, Table 1, the Figure 6 comparison with plain
//!   light propagation volumes, and the Cornell bias taken apart effect by effect.
//! * [`ism2008`]: the imperfect-shadow-map breakdown of the Kautz course slides (Ritschel et
//!   al. 2008), ISM against classic maps on the same VPLs.
//! * [`barczak2006`]: Barczak 2006, Figures 5-2 to 5-6 (frame rate against lights and
//!   optimisation levels, and against shadow-map updates with moving objects), plots and tables.
//! * [`all`]: every paper table, figure and sweep (`gibench reproduce all`), and the sweeps
//!   that are gibench commands (Keller's and Laine's tile, VPL and clamp sweeps, the lag and
//!   quality runs, the reference) as targets of their own.
//! * [`job`]: a run, sweep or reference command checked and run as a target of `reproduce`.

pub mod all;
pub mod barczak2006;
pub mod gaitatzes2010;
pub mod ism2008;
pub mod job;
pub mod laine2007;

use std::path::PathBuf;

use clap::Args;
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::measure::results::RunResult;
use gibench_harness::report::{Cell, Table};
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::{Scene, SceneDescriptor};
use gibench_harness::{Error, Result};

use crate::progress::{execute_with_bar, Bars};

#[derive(Args, Clone)]
pub struct ReproduceArgs {
    /// What to regenerate: `all` (every target below), or one target: laine-table1,
    /// laine-table2, laine-tables (both from one set of runs), laine-management,
    /// laine-dispersion, ism-breakdown, gaitatzes-table1, gaitatzes-quality, gaitatzes-cornell, barczak2006, or a sweep or run target (`gibench reproduce all --list` lists them).
    pub target: String,
    /// Small sizes for machines without a GPU (each target says which).
    #[arg(long)]
    pub quick: bool,
    /// Scenes (default: the paper's; paper targets only: Laine's, ism-breakdown and gaitatzes-*).
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    /// Output directory (default: results/<the target's folder>; for `all`, results, with
    /// each target in its folder under it).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Override the measured frame count (e.g. for a smoke test).
    #[arg(long)]
    pub frames: Option<u32>,
    /// With `all`: only these targets, comma-separated.
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// Print the targets, their commands, folders and the time estimate; run nothing.
    #[arg(long)]
    pub list: bool,
    /// Also write an HTML page per target (its tables, a paper's rows beside ours, and the
    /// runs' images and plots where it has them).
    #[arg(long)]
    pub html: bool,
    /// Extra directory searched first for scene assets (glTF files).
    #[arg(long)]
    pub assets: Option<PathBuf>,
    /// Do not show a progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// With `all`: run the targets in priority order (`--list` prints it) and start none whose
    /// estimate does not fit what is left of this time, e.g. 90s, 2m, 9m (docs/fleet.md).
    #[arg(long, value_name = "DURATION", value_parser = crate::params::parse_budget)]
    pub budget: Option<std::time::Duration>,
    #[command(flatten)]
    pub shard: crate::shard::ShardArgs,
    /// For the test suite only: `tiny` cuts every target to a few frames at tiny sizes. Printed,
    /// and recorded in reproduce-all.json as the mode (e.g. `quick-tiny`): never benchmark results.
    #[arg(long, env = "GIBENCH_TEST_SIZE", value_enum, value_name = "SIZE")]
    pub test_size: Option<TestSize>,
    /// Restrict the adapter to one backend.
    #[arg(long, env = "GIBENCH_BACKEND")]
    pub backend: Option<String>,
    /// Use the adapter whose name contains this.
    #[arg(long, env = "GIBENCH_ADAPTER")]
    pub adapter: Option<String>,
    /// Fail when the GPU takes longer than this many seconds over one submission (default:
    /// wait as long as the work takes).
    #[arg(long, env = "GIBENCH_GPU_TIMEOUT", value_name = "SECONDS")]
    pub gpu_timeout: Option<f64>,
}

/// `--test-size` / `GIBENCH_TEST_SIZE`: sizes for the test suite, not for results.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestSize {
    /// Two frames at 64x48; Laine's tables on the Cornell box only, at 64x48 and 96x72.
    Tiny,
}

impl ReproduceArgs {
    /// Parses the words after `gibench reproduce` as the command line does (its checks and
    /// environment variables included): how a library user or a test states a reproduction.
    pub fn parse_words(words: &[&str]) -> Result<ReproduceArgs> {
        #[derive(clap::Parser)]
        #[command(name = "gibench reproduce")]
        struct Words {
            #[command(flatten)]
            args: ReproduceArgs,
        }
        <Words as clap::Parser>::try_parse_from(
            std::iter::once("reproduce").chain(words.iter().copied()),
        )
        .map(|w| w.args)
        .map_err(|e| Error::Invalid(e.to_string().trim().to_string()))
    }

    /// Whether `--test-size tiny` (or `GIBENCH_TEST_SIZE=tiny`) is on.
    pub fn tiny(&self) -> bool {
        self.test_size == Some(TestSize::Tiny)
    }

    /// The mode recorded and compared: `quick` or `paper`, with `-tiny` at the test size.
    pub fn mode(&self) -> String {
        let base = if self.quick { "quick" } else { "paper" };
        if self.tiny() {
            format!("{base}-tiny")
        } else {
            base.to_string()
        }
    }
}

/// A table and the file stem it is written under.
pub type Reproduction = (Table, &'static str);

/// A paper target's tables and the runs behind them.
pub type Reproduced = Result<(Vec<Reproduction>, Vec<RunResult>)>;

/// What a paper module offers `reproduce all` for its targets (each function takes the
/// target's name).
pub struct PaperModule {
    /// What the target regenerates, one line.
    pub describe: fn(&str) -> &'static str,
    /// Subfolders of its output folder the target owns entirely (replaced by `all`).
    pub owned_folders: fn(&str) -> &'static [&'static str],
    /// Checks everything that can be checked before any work.
    pub check: fn(&str, &ReproduceArgs) -> Result<()>,
    /// (frames rendered or stepped, work units) for the time estimate.
    pub work: fn(&str, &ReproduceArgs) -> (u64, u64),
    /// Whether the target needs an adapter (CPU-only targets do not).
    pub needs_gpu: fn(&str) -> bool,
    /// Regenerates the target on `gpu` (opened by the module if `None`): its tables and the
    /// runs behind them.
    pub reproduce: fn(&str, &ReproduceArgs, Option<&GpuContext>, &Bars) -> Reproduced,
    /// The folder of the runs behind the tables.
    pub runs_folder: fn(&ReproduceArgs) -> PathBuf,
    /// The figures (SVG) the target writes beside its tables into the output folder.
    pub figures: fn(&std::path::Path, &str) -> Vec<PathBuf>,
}

/// A paper's published figures (`results/papers/{name}.json`, embedded at build time).
pub fn paper(name: &str, text: &str) -> Result<serde_json::Value> {
    serde_json::from_str(text)
        .map_err(|e| Error::Invalid(format!("results/papers/{name}.json: {e}")))
}

/// A built-in scene or descriptor file, loaded with the asset search path (`--assets` first).
pub fn load_scene(name: &str, args: &ReproduceArgs) -> Result<Scene> {
    Scene::load(
        &SceneDescriptor::resolve(name)?,
        &AssetPaths::standard(args.assets.as_deref()),
    )
}

/// The adapter `args` asks for.
pub fn open_gpu(args: &ReproduceArgs) -> Result<GpuContext> {
    GpuContext::new(&GpuOptions {
        backend: args.backend.clone(),
        adapter: args.adapter.clone(),
        gpu_timeout: args.gpu_timeout,
        limits: None,
    })
}

/// `gpu`, or else the adapter `args` asks for, opened here and kept in `opened`.
pub fn gpu_or_open<'a>(
    gpu: Option<&'a GpuContext>,
    args: &ReproduceArgs,
    opened: &'a mut Option<GpuContext>,
) -> Result<&'a GpuContext> {
    match gpu {
        Some(g) => Ok(g),
        None => Ok(opened.insert(open_gpu(args)?)),
    }
}

/// Validates every spec, then runs them one after another on `gpu` (or the adapter `args` asks
/// for) under `bars`: a paper target's runs, all checked before any starts.
pub fn run_specs(
    specs: &[gibench_harness::run::session::RunSpec],
    args: &ReproduceArgs,
    gpu: Option<&GpuContext>,
    bars: &Bars,
) -> Result<Vec<RunResult>> {
    for s in specs {
        s.validate()?;
    }
    let mut opened = None;
    let gpu = gpu_or_open(gpu, args, &mut opened)?;
    let mut runs = Vec::new();
    for s in specs {
        runs.extend(execute_with_bar(bars, gpu, s)?);
    }
    Ok(runs)
}

/// A paper target's run configuration: per-stage timing only for runs compared with the
/// reference (stage and frame timing otherwise), seed 1, the direct light's map 256² with
/// `--quick` and 1024² (Laine's) without.
pub fn paper_config(
    args: &ReproduceArgs,
    resolution: [u32; 2],
    frames: u32,
    warmup: u32,
    compared: bool,
) -> gibench_harness::run::runner::RunConfig {
    use gibench_harness::run::runner::{RunConfig, TimingMode};
    RunConfig {
        resolution,
        frames,
        warmup,
        first_frame: 0,
        timing: if compared {
            TimingMode::Stages
        } else {
            TimingMode::Both
        },
        seed: 1,
        shadow_size: if args.quick { 256 } else { 1024 },
    }
}

/// A stage's table figure in `r` (flushed wall time, else GPU timestamps), if it has it.
pub fn ms(r: &RunResult, stage: &str) -> Option<f64> {
    r.stage(stage).and_then(|s| s.best_ms())
}

/// The sum of `stages`' figures in `r` (`None` if one is missing).
pub fn sum_ms(r: &RunResult, stages: &[&str]) -> Option<f64> {
    stages.iter().map(|s| ms(r, s)).sum()
}

/// "Ours: adapter (backend, driver); git commit." for a table's notes.
pub fn device_note(runs: &[&RunResult]) -> String {
    let mut devices: Vec<String> = runs
        .iter()
        .map(|r| {
            format!(
                "{} ({}, driver {}{})",
                r.device.adapter,
                r.device.backend,
                r.device.driver,
                r.device.env_text()
            )
        })
        .collect();
    devices.dedup();
    format!(
        "Ours: {}; git {}.",
        devices.join("; "),
        runs.first().map(|r| r.git_commit.as_str()).unwrap_or("?")
    )
}

/// A paper's row of numbers as one-decimal cells.
pub fn paper_cells(values: &serde_json::Value) -> Vec<Cell> {
    values
        .as_array()
        .map(|a| a.iter().map(|v| Cell::Num(v.as_f64(), 1)).collect())
        .unwrap_or_default()
}

/// The folder a target writes into: `--out`, else `results/<dir>`.
pub fn out_dir(args: &ReproduceArgs, dir: &str) -> PathBuf {
    args.out
        .clone()
        .unwrap_or_else(|| PathBuf::from("results").join(dir))
}

/// Runs `args.target` (one target, or `all`) and writes its files.
pub fn exec(args: &ReproduceArgs) -> Result<()> {
    if args.frames == Some(0) {
        // Statistics of no samples are not a table.
        return Err(Error::param(
            "frames",
            "at least one frame is needed (got 0)",
        ));
    }
    if let Some(frames) = args.frames {
        crate::params::check_frame_number("frames", frames)?;
    }
    // A smoke run's tables must not replace the committed results by default.
    if args.out.is_none() && !args.list && (args.tiny() || args.frames.is_some()) {
        let what = if args.tiny() {
            "--test-size tiny (or GIBENCH_TEST_SIZE=tiny)"
        } else {
            "--frames"
        };
        return Err(Error::param(
            "out",
            format!(
                "{what} makes a smoke run, and without --out it would write into results/, replacing the committed results and their times in results/reproduce-all.json; name a folder (e.g. --out /tmp/smoke), or --out results to replace them on purpose"
            ),
        ));
    }
    if args.tiny() {
        eprintln!(
            "gibench reproduce: TEST SIZE tiny (--test-size / GIBENCH_TEST_SIZE): every target cut to \
             a few frames at tiny sizes, recorded as such; not benchmark results"
        );
        if args.frames.is_none() {
            let mut args = args.clone();
            args.frames = Some(2);
            return all::reproduce(&args);
        }
    }
    all::reproduce(args)
}
