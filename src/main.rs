//! `gibench`: run real-time indirect-illumination techniques side by side on the same scenes,
//! frames and timing harness, and render their per-stage timing tables.

mod export;
mod rays;
mod registry;
mod reproduce;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use gibench_harness::assets::AssetPaths;
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::output::OutputSet;
use gibench_harness::quality::{IndirectComponent, QualityConfig, ReferenceCache};
use gibench_harness::reference::ReferenceSettings;
use gibench_harness::report;
use gibench_harness::results::RunResult;
use gibench_harness::runner::{RunConfig, TimingMode};
use gibench_harness::scene::{descriptor, Scene, SceneDescriptor};
use gibench_harness::session::{self, Progress, RunSpec, TechniqueRun};
use gibench_harness::technique::{Params, TechniqueInfo};
use gibench_harness::{Error, Result};

#[derive(Parser)]
#[command(
    name = "gibench",
    version,
    about = "Benchmark suite for real-time indirect illumination"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Run techniques on a scene and write results, images and tables.
    Run(RunArgs),
    /// List the scenes and techniques (with their parameters and defaults).
    List,
    /// Render tables (Markdown, CSV, LaTeX) and a stacked-bar SVG from results files.
    Report(ReportArgs),
    /// Render the CPU reference (direct, one-bounce, multi-bounce) for one frame.
    Reference(ReferenceArgs),
    /// Run one technique over a list of values of one parameter (e.g. vpls=64,128,256 or
    /// tiles=1x1,2x2,4x4,8x8) and tabulate and plot per-stage times against it.
    Sweep(SweepArgs),
    /// Regenerate paper tables, figures and sweeps: `all`, or one target (`reproduce all --list`).
    Reproduce(reproduce::ReproduceArgs),
    /// Plot per-frame error against the reference from results files made with
    /// `run --quality --quality-all` (e.g. the lag of keller-incremental).
    PlotQuality(PlotQualityArgs),
    /// Compare CURRENT runs with BASE runs stage by stage: ratios, a noise band from at least
    /// three repeats on each side, and a verdict (faster / slower / unchanged).
    Compare(CompareArgs),
    /// Count the CPU kernels' instructions under callgrind (deterministic, unlike time) and
    /// compare them with a baseline; fails on a regression beyond the threshold.
    Instructions(InstructionsArgs),
    /// Write one frame of a scene as PLY meshes per material and a JSON of its camera, light
    /// and albedos, for another renderer (`scripts/compare_mitsuba.py`).
    ExportScene(export::ExportArgs),
    /// Time the reference's BVH on the rays of `export-scene --rays N` (closest hit and shadow
    /// rays, wall and CPU time), for `scripts/compare_mitsuba.py --rays`.
    Raycast(rays::RaycastArgs),
}

#[derive(Args)]
struct InstructionsArgs {
    /// The baseline counts (JSON).
    #[arg(long, default_value = "results/baseline/instructions.json")]
    baseline: PathBuf,
    /// Write the counts as the new baseline instead of comparing.
    #[arg(long)]
    write: bool,
    /// Relative increase counted as a regression.
    #[arg(long, default_value_t = 0.02)]
    threshold: f64,
    /// Only these kernels, comma-separated (default: all; `gibench-kernels list`).
    #[arg(long, value_delimiter = ',')]
    kernels: Vec<String>,
}

#[derive(Args)]
struct CompareArgs {
    /// Folder of the BASE runs (searched recursively for results files; one subfolder per repeat).
    base: PathBuf,
    /// Folder of the CURRENT runs, likewise.
    current: PathBuf,
    /// Relative change a verdict needs beyond the band: slower when every pairing is above
    /// 1 + tolerance (0.25 keeps a shared CPU's run-to-run noise from deciding).
    #[arg(long, default_value_t = 0.25)]
    tolerance: f64,
    /// Output directory for the comparison (Markdown, CSV, LaTeX, JSON).
    #[arg(long, default_value = "results/local")]
    out: PathBuf,
    /// File name stem of the outputs.
    #[arg(long, default_value = "compare")]
    stem: String,
}

#[derive(Args)]
struct SweepArgs {
    /// The swept parameter and its values: name=v1,v2,...
    #[arg(long)]
    sweep: String,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Args)]
struct PlotQualityArgs {
    /// Results JSON files (or directories holding them).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// rmse, rel_mse, mae, bias, flip or flicker.
    #[arg(long, default_value = "rmse")]
    metric: String,
    /// Output SVG.
    #[arg(long, default_value = "results/local/quality-per-frame.svg")]
    out: PathBuf,
}

#[derive(Args, Clone)]
struct ReferenceOpts {
    /// Reference samples per pixel (cosine-weighted hemisphere paths at each visible point).
    #[arg(long = "spp", default_value_t = ReferenceSettings::default().spp)]
    spp: u32,
    /// Reference bounce limit for the multi-bounce image.
    #[arg(long = "bounces", default_value_t = ReferenceSettings::default().bounces)]
    bounces: u32,
    /// Reference seed.
    #[arg(long = "reference-seed", default_value_t = ReferenceSettings::default().seed)]
    reference_seed: u64,
    /// Directory of the reference cache.
    #[arg(long, default_value = "results/cache")]
    cache: PathBuf,
    /// Do not read or write the reference cache.
    #[arg(long)]
    no_cache: bool,
}

/// The most reference samples per pixel a command takes (at 256x192 and 8 bounces, hours on
/// two cores already).
const MAX_SPP: u32 = 1 << 16;
/// The most reference bounces a command takes.
const MAX_BOUNCES: u32 = 64;

impl ReferenceOpts {
    fn settings(&self) -> Result<ReferenceSettings> {
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
    fn cache(&self) -> ReferenceCache {
        ReferenceCache {
            dir: (!self.no_cache).then(|| self.cache.clone()),
        }
    }
}

#[derive(Args)]
struct ReferenceArgs {
    /// Scene: a built-in name or a descriptor JSON.
    #[arg(long, default_value = "cornell")]
    scene: String,
    /// Animation frame.
    #[arg(long, default_value_t = 0)]
    frame: u32,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "256x192")]
    resolution: String,
    /// Output directory.
    #[arg(long, default_value = "results/local")]
    out: PathBuf,
    /// Extra directory searched first for scene assets.
    #[arg(long)]
    assets: Option<PathBuf>,
    /// Also render with the next seed and report the relative MSE between the two (an
    /// estimate of the reference's own noise).
    #[arg(long)]
    error_estimate: bool,
    #[command(flatten)]
    reference: ReferenceOpts,
}

#[derive(Args, Clone)]
struct GpuArgs {
    /// Restrict the adapter to one backend: vulkan, gl, metal or dx12.
    #[arg(long, env = "GIBENCH_BACKEND")]
    backend: Option<String>,
    /// Use the adapter whose name contains this (case-insensitive).
    #[arg(long, env = "GIBENCH_ADAPTER")]
    adapter: Option<String>,
    /// Fail when the GPU takes longer than this many seconds over one submission (default:
    /// wait as long as the work takes; a note is printed after 30 s).
    #[arg(long, env = "GIBENCH_GPU_TIMEOUT", value_name = "SECONDS")]
    gpu_timeout: Option<f64>,
}

#[derive(Args, Clone)]
pub(crate) struct RunArgs {
    /// Scene: a built-in name (see `gibench list`) or a path to a descriptor JSON.
    #[arg(long, default_value = "cornell")]
    scene: String,
    /// Techniques, comma-separated (default: every registered technique).
    #[arg(long, value_delimiter = ',')]
    technique: Vec<String>,
    /// Technique parameter `name=value` (applies to every selected technique that declares it)
    /// or `technique.name=value`. Repeatable.
    #[arg(long = "param", short = 'p')]
    params: Vec<String>,
    /// Measured frames.
    #[arg(long, default_value_t = 60)]
    frames: u32,
    /// Warm-up frames run first and dropped from the statistics.
    #[arg(long, default_value_t = 5)]
    warmup: u32,
    /// Animation frame to start at.
    #[arg(long, default_value_t = 0)]
    first_frame: u32,
    /// Image size WIDTHxHEIGHT (the papers used 1024x768 and 1600x1200).
    #[arg(long, default_value = "256x192")]
    resolution: String,
    /// Edge length of each face of the primary light's cube shadow map (Laine: 1024).
    #[arg(long, default_value_t = 256)]
    shadow_size: u32,
    /// `stages` (per-stage, flushed), `frame` (whole frames, no added sync) or `both`.
    #[arg(long, default_value = "both")]
    timing: String,
    /// Seed for every random choice a technique makes.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Directory for results JSON, images and tables.
    #[arg(long, default_value = "results/local")]
    out: PathBuf,
    /// Extra directory searched first for scene assets (glTF files).
    #[arg(long)]
    assets: Option<PathBuf>,
    /// Do not write images.
    #[arg(long)]
    no_images: bool,
    /// Do not show a progress bar.
    #[arg(long)]
    quiet: bool,
    /// Also measure image error against the CPU reference (RMSE, relative MSE, MAE, FLIP,
    /// flicker) on consecutive frame pairs spread over the measured frames.
    #[arg(long)]
    quality: bool,
    /// Frame pairs compared with the reference when --quality is given [default: 2].
    #[arg(long)]
    quality_pairs: Option<u32>,
    /// With --quality, compare every measured frame (per-frame error and lag plots).
    #[arg(long)]
    quality_all: bool,
    /// The reference component the indirect irradiance is compared with: one-bounce,
    /// multi-bounce, or direct (for a technique's direct light samples: `barczak set=direct`)
    /// (default: each technique's declared component, see `gibench list`).
    #[arg(long)]
    quality_reference: Option<String>,
    /// Also write an HTML page of the run (`{scene}-report.html`, or `{stem}.html` for a
    /// sweep): tables, images beside the reference, error maps, time versus error.
    #[arg(long)]
    html: bool,
    #[command(flatten)]
    reference: ReferenceOpts,
    #[command(flatten)]
    gpu: GpuArgs,
}

#[derive(Args)]
struct ReportArgs {
    /// Results JSON files (or directories holding them).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Output directory for the tables and the plot.
    #[arg(long, default_value = "results/local")]
    out: PathBuf,
    /// File name stem of the outputs.
    #[arg(long, default_value = "report")]
    stem: String,
    /// Also print full statistics (median, mean, p5, p95, min, max) per stage.
    #[arg(long)]
    detailed: bool,
    /// Also write an HTML page (`{stem}.html`): the table, the runs' images beside the
    /// reference (from their folders), error maps, time versus error.
    #[arg(long)]
    html: bool,
}

fn main() -> ExitCode {
    gibench_harness::threads::join_global_pool();
    let cli = Cli::parse();
    let outcome = match cli.command {
        None => run(&RunArgs::parse_default()),
        Some(Command::Run(args)) => run(&args),
        Some(Command::List) => list(),
        Some(Command::Report(args)) => report_cmd(&args),
        Some(Command::Reference(args)) => reference_cmd(&args),
        Some(Command::Sweep(args)) => sweep(&args),
        Some(Command::PlotQuality(args)) => plot_quality(&args),
        Some(Command::Compare(args)) => compare_cmd(&args),
        Some(Command::Instructions(args)) => instructions_cmd(&args),
        Some(Command::ExportScene(args)) => export::export_scene(&args),
        Some(Command::Raycast(args)) => rays::raycast(&args),
        Some(Command::Reproduce(args)) => reproduce::reproduce(&args),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

impl RunArgs {
    /// `gibench` with no arguments: `gibench run`'s defaults, compared with the CPU reference
    /// (cached after the first run) and written up as an HTML page.
    fn parse_default() -> RunArgs {
        RunArgs::parse_args(["gibench", "--quality", "--html"])
    }

    /// `gibench run` options from an argument list (the first item is the program name).
    fn parse_args<I: IntoIterator<Item = T>, T: Into<std::ffi::OsString> + Clone>(
        args: I,
    ) -> RunArgs {
        #[derive(Parser)]
        struct Only {
            #[command(flatten)]
            run: RunArgs,
        }
        Only::parse_from(args).run
    }
}

fn parse_resolution(s: &str) -> Result<[u32; 2]> {
    let bad = || {
        Error::param(
            "resolution",
            format!("expected WIDTHxHEIGHT, e.g. 256x192 (got '{s}')"),
        )
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok([
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    ])
}

/// Splits `--param` values among the selected techniques. A bare `name=value` goes to every
/// technique that declares `name`; it is an error if none does, and an error if a technique
/// would get the same parameter twice (`vpls=8` and `laine.vpls=16`: which one holds would
/// depend on their order).
fn assign_params(techniques: &[&TechniqueInfo], raw: &[String]) -> Result<Vec<Params>> {
    // Per technique: (parameter, value, the `--param` it came from).
    let mut given: Vec<Vec<(String, String, &str)>> = vec![Vec::new(); techniques.len()];
    for p in raw {
        let (key, value) = p.split_once('=').ok_or_else(|| {
            Error::param(p.clone(), "expected name=value or technique.name=value")
        })?;
        let targets: Vec<(usize, &str)> = match key.split_once('.') {
            Some((t, name)) => {
                let i = techniques
                    .iter()
                    .position(|info| info.name == t)
                    .ok_or_else(|| {
                        Error::param(
                            key,
                            format!("technique '{t}' is not among the selected techniques"),
                        )
                    })?;
                vec![(i, name)]
            }
            None => techniques
                .iter()
                .enumerate()
                .filter(|(_, info)| info.has_param(key))
                .map(|(i, _)| (i, key))
                .collect(),
        };
        if targets.is_empty() {
            let known: Vec<String> = techniques
                .iter()
                .map(|t| {
                    let names: Vec<&str> = t.param_specs().map(|s| s.name).collect();
                    format!(
                        "{}: {}",
                        t.name,
                        if names.is_empty() {
                            "none".into()
                        } else {
                            names.join(", ")
                        }
                    )
                })
                .collect();
            return Err(Error::param(
                key,
                format!(
                    "no selected technique has this parameter ({})",
                    known.join("; ")
                ),
            ));
        }
        for (i, name) in targets {
            if let Some((.., first)) = given[i].iter().find(|(n, ..)| n == name) {
                return Err(Error::param(
                    format!("{}.{name}", techniques[i].name),
                    format!("given twice ('{first}' and '{p}'); give each parameter once"),
                ));
            }
            given[i].push((name.to_string(), value.to_string(), p));
        }
    }
    techniques
        .iter()
        .zip(given)
        .map(|(t, g)| {
            let pairs: Vec<(String, String)> = g.into_iter().map(|(n, v, _)| (n, v)).collect();
            t.parse_params(&pairs)
        })
        .collect()
}

/// Everything a run needs, checked before anything runs or is written.
pub(crate) struct Plan {
    config: RunConfig,
    quality: Option<QualityConfig>,
    techniques: Vec<&'static TechniqueInfo>,
    params: Vec<Params>,
    desc: SceneDescriptor,
    scene: Scene,
}

pub(crate) fn plan(args: &RunArgs, extra_params: &[String]) -> Result<Plan> {
    let config = RunConfig {
        resolution: parse_resolution(&args.resolution)?,
        frames: args.frames,
        warmup: args.warmup,
        first_frame: args.first_frame,
        timing: TimingMode::parse(&args.timing)?,
        seed: args.seed,
        shadow_size: args.shadow_size,
    };
    config.validate()?;
    gpu_options(args).validate()?;
    let quality_options = [
        ("quality-pairs", args.quality_pairs.is_some()),
        ("quality-all", args.quality_all),
        ("quality-reference", args.quality_reference.is_some()),
    ];
    if let Some((name, _)) = quality_options
        .iter()
        .find(|(_, given)| *given && !args.quality)
    {
        return Err(Error::param(
            *name,
            "applies to the error measurement: add --quality (without it nothing is compared)",
        ));
    }
    let pairs = args.quality_pairs.unwrap_or(2);
    if args.quality && pairs == 0 {
        return Err(Error::param(
            "quality-pairs",
            "at least one frame pair is needed (got 0)",
        ));
    }
    let quality = if args.quality {
        Some(QualityConfig {
            pairs,
            all: args.quality_all,
            reference: args.reference.settings()?,
            component: args
                .quality_reference
                .as_deref()
                .map(IndirectComponent::parse)
                .transpose()?,
        })
    } else {
        None
    };
    let registry = registry::all();
    let names: Vec<String> = if args.technique.is_empty() {
        registry.iter().map(|t| t.name.to_string()).collect()
    } else {
        args.technique.clone()
    };
    let techniques: Vec<&'static TechniqueInfo> = names
        .iter()
        .map(|n| TechniqueInfo::find(registry, n.trim()))
        .collect::<Result<_>>()?;
    for (i, t) in techniques.iter().enumerate() {
        if techniques[..i].iter().any(|o| o.name == t.name) {
            return Err(Error::param(
                "technique",
                format!(
                    "'{}' is listed twice; its second run would overwrite the first's files",
                    t.name
                ),
            ));
        }
    }
    if let Some(dir) = &args.assets {
        if !dir.is_dir() {
            return Err(Error::param(
                "assets",
                format!("{} is not a folder", dir.display()),
            ));
        }
    }
    let mut raw = args.params.clone();
    raw.extend_from_slice(extra_params);
    let params = assign_params(&techniques, &raw)?;
    if let Some(given) = quality.as_ref().and_then(|q| q.component) {
        for line in other_components(&techniques, &params, given) {
            eprintln!("warning: {line}");
        }
    }
    let desc = SceneDescriptor::resolve(&args.scene)?;
    let scene = Scene::load(&desc, &AssetPaths::standard(args.assets.as_deref()))?;
    // Where files will go must be usable before any GPU work.
    writable_dir("out", &args.out)?;
    if args.quality && !args.reference.no_cache {
        writable_dir("cache", &args.reference.cache)?;
    }
    Ok(Plan {
        config,
        quality,
        techniques,
        params,
        desc,
        scene,
    })
}

/// A line for each technique whose parameters compute another component than `given`
/// (`--quality-reference`): its error column is then against light it does not compute.
fn other_components(
    techniques: &[&TechniqueInfo],
    params: &[Params],
    given: IndirectComponent,
) -> Vec<String> {
    techniques
        .iter()
        .zip(params)
        .filter_map(|(t, p)| {
            let computed = (t.reference)(p);
            (computed != given).then(|| {
                format!(
                    "--quality-reference {}: {} computes the {} component with these parameters; its error is measured against light it does not compute",
                    given.name(),
                    t.name,
                    computed.name()
                )
            })
        })
        .collect()
}

impl Plan {
    /// The typed run of these techniques, files named `{scene}-{technique}`.
    fn spec(&self, args: &RunArgs) -> RunSpec<'_> {
        let runs = self
            .techniques
            .iter()
            .zip(&self.params)
            .map(|(info, params)| TechniqueRun {
                info,
                params: params.clone(),
                stem: format!("{}-{}", self.desc.name, info.name),
            })
            .collect();
        RunSpec {
            scene: &self.scene,
            runs,
            config: self.config.clone(),
            quality: self.quality.clone(),
            cache: args.reference.cache(),
            out: args.out.clone(),
            images: !args.no_images,
        }
    }
}

/// Runs `spec` with a progress bar (hidden when `quiet`).
pub(crate) fn execute_with_bar(
    bars: &Bars,
    gpu: &GpuContext,
    spec: &RunSpec,
) -> Result<Vec<RunResult>> {
    execute_skipping_with_bar(bars, gpu, spec, false).map(|(results, _)| results)
}

/// [`execute_with_bar`] leaving out, with `skip_unfit`, the techniques that cannot take the
/// scene or the device ([`session::execute_skipping`]); each is named with its reason.
pub(crate) fn execute_skipping_with_bar(
    bars: &Bars,
    gpu: &GpuContext,
    spec: &RunSpec,
    skip_unfit: bool,
) -> Result<(Vec<RunResult>, Vec<session::Skipped>)> {
    let executed = match bars {
        Bars::Own(quiet) => {
            let bar = progress_bar(*quiet, spec.total_frames());
            let executed = session::execute_skipping(gpu, spec, skip_unfit, &mut |p| match p {
                Progress::Technique(name) => bar.set_message(name.to_string()),
                Progress::Frame => bar.inc(1),
            });
            bar.finish_and_clear();
            executed
        }
        Bars::Shared(all) => session::execute_skipping(gpu, spec, skip_unfit, &mut |p| match p {
            Progress::Technique(name) => all.technique(name),
            Progress::Frame => all.frame(),
        }),
    };
    if let Ok((results, skipped)) = &executed {
        for s in skipped {
            bars.note(&format!(
                "skipped {} on {}: {}",
                s.technique, spec.scene.descriptor.name, s.reason
            ));
        }
        for r in results {
            for w in &r.warnings {
                bars.note(&format!("warning: {} on {}: {w}", r.technique, r.scene));
            }
        }
    }
    executed
}

/// Where a command reports its progress: a bar of its own (hidden when quiet), or its share of
/// `gibench reproduce all`'s bar.
pub(crate) enum Bars<'a> {
    Own(bool),
    Shared(&'a reproduce::all::Overall),
}

impl Bars<'_> {
    /// A line for the terminal (above the shared bar, not through it).
    pub(crate) fn note(&self, line: &str) {
        match self {
            Bars::Own(_) => eprintln!("{line}"),
            Bars::Shared(all) => all.note(line),
        }
    }

    /// A result table for the terminal: printed by a command of its own; under `reproduce all`
    /// it is in the files only.
    pub(crate) fn table(&self, table: &report::Table) {
        if let Bars::Own(_) = self {
            println!("{}", table.to_terminal());
        }
    }
}

/// Creates `dir` if needed and checks a file can be written there; the error names `option`.
pub(crate) fn writable_dir(option: &str, dir: &Path) -> Result<()> {
    let fail = |e: std::io::Error| {
        Error::param(
            option,
            format!("{} is not a writable folder: {e}", dir.display()),
        )
    };
    let dir = gibench_harness::output::without_cur_dirs(dir);
    // The topmost folder this check creates is removed again: a command that fails later
    // leaves no empty folder behind (the output set creates it for real).
    let mut first_missing = None;
    for a in dir.ancestors() {
        if a.as_os_str().is_empty() || a.exists() {
            break;
        }
        first_missing = Some(a.to_path_buf());
    }
    std::fs::create_dir_all(&dir).map_err(fail)?;
    // The probe file is deleted as soon as it is made.
    let probe = tempfile::NamedTempFile::new_in(&dir)
        .map(|_| ())
        .map_err(fail);
    if let Some(top) = first_missing {
        let _ = std::fs::remove_dir_all(top);
    }
    probe
}

/// Checks `path` can be written as a file: not a folder, in a folder that can be created and
/// written ([`writable_dir`]); the error names `option` and suggests `example` inside a folder.
pub(crate) fn writable_file(option: &str, path: &Path, example: &str) -> Result<()> {
    if path.is_dir() {
        return Err(Error::param(
            option,
            format!(
                "{} is a folder; expected the path of a file to write, e.g. {}",
                path.display(),
                path.join(example).display()
            ),
        ));
    }
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if let Some(file) = dir.ancestors().find(|a| a.is_file()) {
        return Err(Error::param(
            option,
            format!(
                "{} is a file, not a folder; expected the path of a file to write in a folder",
                file.display()
            ),
        ));
    }
    writable_dir(option, dir)
}

pub(crate) fn progress_bar(quiet: bool, total: u64) -> indicatif::ProgressBar {
    let bar = if quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(total)
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg:>24} [{bar:30}] {pos}/{len} frames ({elapsed})",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

pub(crate) fn announcement(plan: &Plan, gpu: &GpuContext) -> String {
    let c = &plan.config;
    format!(
        "gibench: scene '{}' ({} triangles) at {}x{} on {} ({}), {} measured + {} warm-up frames, timing '{}'",
        plan.desc.name,
        plan.scene.mesh.triangle_count(),
        c.resolution[0],
        c.resolution[1],
        gpu.info.adapter,
        gpu.info.backend,
        c.frames,
        c.warmup,
        c.timing.name()
    )
}

/// The adapter choice `args` ask for.
fn gpu_options(args: &RunArgs) -> GpuOptions {
    GpuOptions {
        backend: args.gpu.backend.clone(),
        adapter: args.gpu.adapter.clone(),
        gpu_timeout: args.gpu.gpu_timeout,
    }
}

pub(crate) fn open_gpu(args: &RunArgs) -> Result<GpuContext> {
    GpuContext::new(&gpu_options(args))
}

fn run(args: &RunArgs) -> Result<()> {
    // Everything that can be checked without running is checked before anything is written.
    let plan = plan(args, &[])?;
    plan.spec(args).validate()?;
    let set = OutputSet::begin("out", &args.out)?;
    if args.technique.is_empty() {
        // A run over every technique says which it skipped; one that skipped none leaves no
        // earlier run's list behind.
        set.replace_files(&skipped_file(&plan.desc.name))?;
    }
    let gpu = open_gpu(args)?;
    let done = run_planned(args, &plan, &gpu, &Bars::Own(args.quiet))?;
    set.publish()?;
    eprintln!("{done}");
    Ok(())
}

/// The file in which a run over every technique on `scene` lists those it skipped and why.
fn skipped_file(scene: &str) -> String {
    format!("{scene}-skipped.json")
}

/// The work of `gibench run` once planned and its output set is open: runs, tables, plots.
/// Returns what it wrote, as a line for the terminal.
pub(crate) fn run_planned(
    args: &RunArgs,
    plan: &Plan,
    gpu: &GpuContext,
    bars: &Bars,
) -> Result<String> {
    let spec = plan.spec(args);
    bars.note(&announcement(plan, gpu));
    // A run over every technique leaves out one that cannot take the scene or the device; one
    // named with --technique is an error.
    let (results, skipped) =
        execute_skipping_with_bar(bars, gpu, &spec, args.technique.is_empty())?;
    let name = &plan.desc.name;
    if results.is_empty() {
        let reasons: Vec<String> = skipped
            .iter()
            .map(|s| format!("{}: {}", s.technique, s.reason))
            .collect();
        return Err(Error::Invalid(format!(
            "no technique could run on scene '{name}': {}",
            reasons.join("; ")
        )));
    }
    let mut table = report::stage_table(&results);
    for s in &skipped {
        table
            .notes
            .push(format!("Skipped {}: {}", s.technique, s.reason));
    }
    bars.table(&table);
    let stem = format!("{name}-summary");
    let mut written: Vec<String> = report::write_tables(&table, &args.out, &stem)?
        .iter()
        .map(|p| file_name(p))
        .collect();
    if !skipped.is_empty() {
        let list: Vec<serde_json::Value> = (skipped.iter())
            .map(|s| serde_json::json!({ "technique": s.technique, "reason": s.reason }))
            .collect();
        let record = serde_json::json!({
            "scene": name,
            "note": "techniques a run over every technique left out, each with its reason (not a results file)",
            "skipped": list,
        });
        let path = args.out.join(skipped_file(name));
        let bytes =
            serde_json::to_vec_pretty(&record).map_err(|e| Error::Invalid(e.to_string()))?;
        gibench_harness::error::write_atomic(&path, &bytes)?;
        written.push(file_name(&path));
    }
    report::stacked_bar_svg(
        &results,
        &args.out.join(format!("{stem}.svg")),
        &format!("Per-stage times on {name}"),
    )?;
    written.push(format!("{stem}.svg"));
    if plan.quality.is_some() {
        // Per compared frame (every measured frame with --quality-all); flicker where a frame
        // pair was compared.
        let flicker = results.iter().any(|r| {
            r.quality
                .as_ref()
                .is_some_and(|q| q.frames.iter().any(|f| f.temporal.is_some()))
        });
        for metric in ["rmse", "flicker"]
            .into_iter()
            .filter(|m| *m == "rmse" || flicker)
        {
            let svg = args.out.join(format!("{name}-{metric}-per-frame.svg"));
            if report::per_frame_lines(&results, metric)?.is_empty() {
                // Every value is not a number (each run's warnings say why): what is valid
                // is still written.
                eprintln!(
                    "note: no {metric} value is a number; {} not drawn",
                    file_name(&svg)
                );
                continue;
            }
            report::quality_over_frames_svg(
                &results,
                metric,
                &svg,
                &format!("{metric} against the reference on {name}"),
            )?;
            written.push(file_name(&svg));
        }
    }
    if plan.quality.is_some() {
        let svg = args.out.join(format!("{name}-time-vs-error.svg"));
        if report::time_error_points(&results).is_empty() {
            eprintln!(
                "note: no run has an error that is a number; {} not drawn",
                file_name(&svg)
            );
        } else {
            report::time_vs_error_svg(&results, &svg, &format!("Time versus error on {name}"))?;
            written.push(file_name(&svg));
        }
    }
    let mut done = format!(
        "wrote {} results, images and {} to {}",
        results.len(),
        written.join(", "),
        args.out.display()
    );
    if args.html {
        let page = args.out.join(format!("{name}-report.html"));
        write_page(
            &page,
            format!("gibench run on {name}"),
            vec![table],
            written
                .iter()
                .filter(|w| w.ends_with(".svg"))
                .map(|w| args.out.join(w))
                .collect(),
            with_folder(&args.out, results),
        )?;
        done.push_str(&page_line(&page));
    }
    Ok(done)
}

/// The runs paired with the folder they were written to.
pub(crate) fn with_folder(dir: &Path, results: Vec<RunResult>) -> Vec<(PathBuf, RunResult)> {
    results
        .into_iter()
        .map(|r| (dir.to_path_buf(), r))
        .collect()
}

/// This command as a user would type it: `gibench` and its arguments (not the executable's
/// path on this machine, which names a user's folders and means nothing elsewhere).
pub(crate) fn command_line() -> String {
    std::iter::once("gibench".to_string())
        .chain(std::env::args().skip(1))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Writes an HTML page ([`gibench_harness::html`]) with this process's command line.
pub(crate) fn write_page(
    path: &Path,
    title: String,
    tables: Vec<report::Table>,
    figures: Vec<PathBuf>,
    runs: Vec<(PathBuf, RunResult)>,
) -> Result<()> {
    gibench_harness::html::Page {
        title,
        command: command_line(),
        tables,
        figures,
        runs,
    }
    .write(path)
}

/// "\nreport: PATH (open it in a browser)", the page's path made absolute.
pub(crate) fn page_line(page: &Path) -> String {
    let shown = std::env::current_dir()
        .map(|d| d.join(page))
        .unwrap_or_else(|_| page.to_path_buf());
    format!("\nreport: {} (open it in a browser)", shown.display())
}

/// `gibench sweep`: one technique, one parameter over a list of values.
fn sweep(args: &SweepArgs) -> Result<()> {
    let planned = sweep_plan(args)?;
    let set = OutputSet::begin("out", &args.run.out)?;
    // The folder's points of this scene, technique and parameter are this sweep's alone: an
    // earlier sweep's points at values this one does not run are removed when it publishes
    // (they would otherwise sit beside its table as if part of it).
    for stale in planned.earlier_points(&args.run.out) {
        gibench_harness::output::replace_in_open_set(&stale)?;
    }
    let gpu = open_gpu(&args.run)?;
    let done = sweep_planned(args, &planned, &gpu, &Bars::Own(args.run.quiet))?;
    set.publish()?;
    eprintln!("{done}");
    Ok(())
}

/// A sweep checked before it runs: the parameter, its values and one plan per value.
pub(crate) struct SweepPlan {
    name: String,
    values: Vec<String>,
    plans: Vec<Plan>,
}

impl SweepPlan {
    /// The typed run of every point.
    fn spec(&self, args: &SweepArgs) -> RunSpec<'_> {
        let first = &self.plans[0];
        let info = first.techniques[0];
        let mut spec = first.spec(&args.run);
        spec.runs = self
            .values
            .iter()
            .zip(&self.plans)
            .map(|(v, p)| TechniqueRun {
                info,
                params: p.params[0].clone(),
                stem: format!("{}{v}", self.point_prefix()),
            })
            .collect();
        spec
    }

    /// What every point's files are named after: `SCENE-TECHNIQUE-PARAMETER-` (the value
    /// follows).
    fn point_prefix(&self) -> String {
        let first = &self.plans[0];
        let info = first.techniques[0];
        format!("{}-{}-{}-", first.desc.name, info.name, self.name)
    }

    /// The files in `dir` named as points of a sweep of this scene, technique and parameter
    /// (any value) — not those of a parameter whose name extends this one's (`vpl-map-size`
    /// beside `vpl-map`).
    fn earlier_points(&self, dir: &Path) -> Vec<PathBuf> {
        let prefix = self.point_prefix();
        let first = &self.plans[0];
        let info = first.techniques[0];
        let bare = self.name.rsplit('.').next().unwrap_or(&self.name);
        let longer: Vec<String> = (info.params.iter().flat_map(|g| g.iter()))
            .filter(|p| p.name.starts_with(&format!("{bare}-")))
            .map(|p| format!("{}-{}-{}-", first.desc.name, info.name, p.name))
            .collect();
        let Ok(entries) = std::fs::read_dir(dir) else {
            return Vec::new();
        };
        entries
            .flatten()
            .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
            .filter(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                name.starts_with(&prefix) && !longer.iter().any(|l| name.starts_with(l))
            })
            .map(|e| e.path())
            .collect()
    }
}

pub(crate) fn sweep_plan(args: &SweepArgs) -> Result<SweepPlan> {
    let (name, values) = args
        .sweep
        .split_once('=')
        .map(|(n, v)| {
            (
                n.trim().to_string(),
                v.split(',')
                    .map(|x| x.trim().to_string())
                    .collect::<Vec<_>>(),
            )
        })
        .filter(|(n, v)| !n.is_empty() && !v.is_empty() && v.iter().all(|x| !x.is_empty()))
        .ok_or_else(|| {
            Error::param(
                "sweep",
                format!("expected name=v1,v2,... (got '{}')", args.sweep),
            )
        })?;
    if args.run.technique.len() != 1 {
        return Err(Error::param(
            "technique",
            "a sweep runs exactly one technique",
        ));
    }
    check_swept_not_given(&args.sweep, &name, &args.run.params)?;
    let info = TechniqueInfo::find(registry::all(), args.run.technique[0].trim())?;
    check_distinct_values(info, &name, &values)?;
    // Check every point before running any.
    let plans: Vec<Plan> = values
        .iter()
        .map(|v| plan(&args.run, &[format!("{name}={v}")]))
        .collect::<Result<_>>()?;
    let planned = SweepPlan {
        name,
        values,
        plans,
    };
    planned.spec(args).validate()?;
    Ok(planned)
}

/// Refuses a `--param` that sets the swept parameter `name` (with or without a `technique.`
/// prefix): every point would silently override it.
fn check_swept_not_given(sweep: &str, name: &str, params: &[String]) -> Result<()> {
    let bare = |key: &str| key.split_once('.').map_or(key, |(_, n)| n).to_string();
    let swept = bare(name);
    let given = params
        .iter()
        .find(|p| p.split_once('=').is_some_and(|(k, _)| bare(k) == swept));
    if let Some(p) = given {
        return Err(Error::param(
            swept,
            format!(
                "given both as --param ('{p}') and as the swept parameter (--sweep {sweep}); \
                 give it once"
            ),
        ));
    }
    Ok(())
}

/// Refuses a sweep value listed twice, compared as the technique reads them (`08` and `8`, `1`
/// and `1.0` are one setting): the second point would repeat the first's run, or overwrite its
/// files.
fn check_distinct_values(info: &TechniqueInfo, name: &str, values: &[String]) -> Result<()> {
    let parsed: Vec<Params> = values
        .iter()
        .map(|v| assign_params(&[info], &[format!("{name}={v}")]).map(|mut p| p.remove(0)))
        .collect::<Result<_>>()?;
    for (i, p) in parsed.iter().enumerate() {
        if let Some(j) = parsed[..i].iter().position(|q| q == p) {
            let (a, b) = (&values[j], &values[i]);
            let message = if a == b {
                format!("the value '{b}' is listed twice; its second run would overwrite the first's files")
            } else {
                format!(
                    "the values '{a}' and '{b}' are listed twice: {} reads both as the same \
                     {name}, so the second run would only repeat the first",
                    info.name
                )
            };
            return Err(Error::param("sweep", message));
        }
    }
    Ok(())
}

/// The work of `gibench sweep` once planned and its output set is open. Returns what it
/// wrote, as a line for the terminal.
pub(crate) fn sweep_planned(
    args: &SweepArgs,
    planned: &SweepPlan,
    gpu: &GpuContext,
    bars: &Bars,
) -> Result<String> {
    let SweepPlan {
        name,
        values,
        plans,
    } = planned;
    let (name, values) = (name.clone(), values.clone());
    let first = &plans[0];
    let info = first.techniques[0];
    let spec = planned.spec(args);
    bars.note(&announcement(first, gpu));
    let runs = execute_with_bar(bars, gpu, &spec)?;
    let points: Vec<(String, RunResult)> = values.iter().cloned().zip(runs).collect();
    let results: Vec<RunResult> = points.iter().map(|(_, r)| r.clone()).collect();
    let mut table = report::stage_table(&results);
    table.title = format!(
        "{} on {}: per-stage time (median ms) against {name}",
        info.name, first.desc.name
    );
    table.columns.insert(0, name.clone());
    for (row, v) in table.rows.iter_mut().zip(&values) {
        row.insert(0, report::Cell::text(v));
    }
    bars.table(&table);
    let stem = format!("{}-{}-sweep-{name}", first.desc.name, info.name);
    report::write_tables(&table, &args.run.out, &stem)?;
    report::sweep_plot_svg(
        &points,
        &args.run.out.join(format!("{stem}.svg")),
        &format!(
            "{} on {}: stage times against {name}",
            info.name, first.desc.name
        ),
        &name,
    )?;
    let mut figures = vec![args.run.out.join(format!("{stem}.svg"))];
    if first.quality.is_some() {
        let svg = args.run.out.join(format!("{stem}-time-vs-error.svg"));
        report::time_vs_error_svg(
            &results,
            &svg,
            &format!(
                "{} on {}: time versus error over {name}",
                info.name, first.desc.name
            ),
        )?;
        figures.push(svg);
    }
    let mut done = format!(
        "wrote {} points and {stem}.md/.csv/.tex/.svg{} to {}",
        points.len(),
        if figures.len() > 1 {
            ", -time-vs-error.svg"
        } else {
            ""
        },
        args.run.out.display()
    );
    if args.run.html {
        let page = args.run.out.join(format!("{stem}.html"));
        write_page(
            &page,
            table.title.clone(),
            vec![table],
            figures,
            with_folder(&args.run.out, results),
        )?;
        done.push_str(&page_line(&page));
    }
    Ok(done)
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn list() -> Result<()> {
    println!("Scenes (built-in descriptors; any descriptor JSON path also works):");
    for name in descriptor::builtin_names() {
        let d = SceneDescriptor::resolve(name)?;
        let mesh = d
            .mesh
            .file
            .clone()
            .or(d.mesh.generated.clone().map(|g| format!("generated {g}")))
            .unwrap_or_default();
        println!(
            "  {name:<16} {mesh:<28} {:?} light. {}",
            d.light.kind, d.description
        );
    }
    println!("\nTechniques:");
    for t in registry::all() {
        println!("  {:<16} {}", t.name, t.description);
        println!(
            "      compared with the {} reference by default; conformance: relative L1 error <= {}, mean ratio {}-{}",
            t.default_reference().name(),
            t.conformance.max_relative_l1,
            t.conformance.mean_ratio.0,
            t.conformance.mean_ratio.1
        );
        if t.param_specs().next().is_none() {
            println!("      (no parameters)");
        }
        for p in t.param_specs() {
            println!("      {:<14} default {:<8} {}", p.name, p.default, p.doc);
        }
    }
    Ok(())
}

fn read_results(inputs: &[PathBuf]) -> Result<Vec<RunResult>> {
    Ok(read_results_with_folders(inputs)?
        .into_iter()
        .map(|(_, r)| r)
        .collect())
}

/// The results files given (or found in the given folders: JSON files that are not results are
/// passed over there), each with its folder.
fn read_results_with_folders(inputs: &[PathBuf]) -> Result<Vec<(PathBuf, RunResult)>> {
    let mut files = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(input)
                .map_err(|e| Error::io(input, e))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "json"))
                // Other JSON files in a results folder (a run's list of skipped techniques, a
                // comparison) are passed over; a damaged results file is still read, and named.
                .filter(|p| results_like(p).is_some())
                .collect();
            found.sort();
            files.extend(found);
        } else {
            files.push(input.clone());
        }
    }
    check_each_file_once(&files)?;
    let results: Vec<(PathBuf, RunResult)> = files
        .iter()
        .map(|f| {
            let folder = f
                .parent()
                .filter(|p| !p.as_os_str().is_empty())
                .unwrap_or(Path::new("."))
                .to_path_buf();
            RunResult::read(f).map(|r| (folder, r))
        })
        .collect::<Result<_>>()?;
    if results.is_empty() {
        return Err(Error::Invalid(format!(
            "no results files (*.json) in {} (folders are not searched recursively)",
            shown_list(inputs)
        )));
    }
    Ok(results)
}

/// The paths, comma-separated, for a message.
fn shown_list(paths: &[PathBuf]) -> String {
    let shown: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    shown.join(", ")
}

/// Refuses a file reached twice among the inputs (`F F`, or `DIR DIR/F`; compared by canonical
/// path): its run would be counted twice.
fn check_each_file_once(files: &[PathBuf]) -> Result<()> {
    let mut seen: Vec<(PathBuf, &PathBuf)> = Vec::new();
    for f in files {
        let canonical = f.canonicalize().map_err(|e| Error::io(f, e))?;
        if let Some((_, first)) = seen.iter().find(|(c, _)| *c == canonical) {
            let also = if *first == f {
                String::new()
            } else {
                format!(" (also as {})", first.display())
            };
            return Err(Error::bad_file(
                f,
                format!(
                    "given twice among the inputs{also}; its run would be counted twice, so give \
                     each results file once"
                ),
            ));
        }
        seen.push((canonical, f));
    }
    Ok(())
}

fn plot_quality(args: &PlotQualityArgs) -> Result<()> {
    report::check_per_frame_metric(&args.metric)?;
    writable_file("out", &args.out, "quality-per-frame.svg")?;
    let results = read_results(&args.inputs)?;
    if report::per_frame_lines(&results, &args.metric)?.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no results hold per-frame quality values ('{}'); `gibench run --quality \
             --quality-all` makes them",
            shown_list(&args.inputs),
            args.metric
        )));
    }
    report::quality_over_frames_svg(
        &results,
        &args.metric,
        &args.out,
        &format!("{} against the reference per frame", args.metric),
    )?;
    eprintln!("wrote {}", args.out.display());
    Ok(())
}

/// Every results file under `dir`, recursively, with its path. JSON files that are not results
/// (no `schema_version` and `technique`) are passed over; a results file that cannot be read
/// (truncated, newer schema, invalid values) is named on standard error, and is an error when
/// its scene and technique are in no file read from `dir` (the side would lose that run).
fn results_under(option: &str, dir: &Path) -> Result<Vec<(PathBuf, RunResult)>> {
    if !dir.is_dir() {
        return Err(Error::param(
            option,
            format!("{} is not a folder of results", dir.display()),
        ));
    }
    let mut found = Vec::new();
    let mut unreadable: Vec<(PathBuf, String, Option<String>)> = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(&d)
            .map_err(|e| Error::io(&d, e))?
            .flatten()
            .map(|e| e.path())
            .collect();
        entries.sort();
        for p in entries {
            let hidden = p
                .file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with('.'));
            if hidden {
                continue;
            }
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "json") {
                match RunResult::read(&p) {
                    Ok(r) => found.push((p, r)),
                    Err(e) => {
                        if let Some(run) = results_like(&p) {
                            unreadable.push((p, e.to_string(), run));
                        }
                    }
                }
            }
        }
    }
    for (p, why, _) in &unreadable {
        eprintln!("warning: {option}: skipped {}: {why}", p.display());
    }
    let lost: Vec<String> = unreadable
        .iter()
        .filter(|(_, _, run)| {
            run.as_ref().is_none_or(|run| {
                !found
                    .iter()
                    .any(|(_, r)| &format!("{}/{}", r.scene, r.technique) == run)
            })
        })
        .map(|(p, _, run)| {
            format!(
                "{} ({})",
                p.display(),
                run.as_deref().unwrap_or("its run unknown")
            )
        })
        .collect();
    if !lost.is_empty() {
        return Err(Error::param(
            option,
            format!(
                "results files that cannot be read hold runs no other file under {} has: {} \
                 (their errors are above; fix or remove them)",
                dir.display(),
                lost.join(", ")
            ),
        ));
    }
    if found.is_empty() {
        return Err(Error::param(
            option,
            format!("no gibench results files under {}", dir.display()),
        ));
    }
    Ok(found)
}

/// `Some("scene/technique")` (its run, `None` inside where unknown) when `path` looks like a
/// gibench results file — a truncated or damaged one included — and `None` when it is another
/// JSON file (a comparison, a reproduction's summary).
fn results_like(path: &Path) -> Option<Option<String>> {
    let bytes = gibench_harness::error::read_bounded(path, 1 << 30).ok()?;
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]).into_owned();
    let v: Option<serde_json::Value> = serde_json::from_slice(&bytes).ok();
    match v {
        Some(v) => {
            let o = v.as_object()?;
            if !(o.contains_key("schema_version") && o.contains_key("technique")) {
                return None;
            }
            let run = o
                .get("scene")
                .and_then(|s| s.as_str())
                .zip(o.get("technique").and_then(|t| t.as_str()))
                .map(|(s, t)| format!("{s}/{t}"));
            Some(run)
        }
        // Not JSON (truncated): a results file if it begins like one, its run read from the
        // fields near its start where they are there.
        None => {
            if !head.contains("\"schema_version\"") {
                return None;
            }
            let field = |name: &str| {
                let key = format!("\"{name}\": \"");
                let start = head.find(&key)? + key.len();
                let len = head[start..].find('"')?;
                Some(head[start..start + len].to_string())
            };
            Some(
                field("scene")
                    .zip(field("technique"))
                    .map(|(s, t)| format!("{s}/{t}")),
            )
        }
    }
}

fn compare_cmd(args: &CompareArgs) -> Result<()> {
    check_stem(&args.stem)?;
    let base = results_under("base", &args.base)?;
    let current = results_under("current", &args.current)?;
    check_distinct_runs(args, &base, &current)?;
    let (base, current): (Vec<RunResult>, Vec<RunResult>) = (
        base.into_iter().map(|(_, r)| r).collect(),
        current.into_iter().map(|(_, r)| r).collect(),
    );
    let rows = gibench_harness::compare::compare(&base, &current, args.tolerance)?;
    let table = gibench_harness::compare::compare_table(&rows, args.tolerance);
    println!("{}", table.to_terminal());
    let set = OutputSet::begin("out", &args.out)?;
    report::write_tables(&table, &args.out, &args.stem)?;
    let json = serde_json::to_vec_pretty(&rows).map_err(|e| Error::Invalid(e.to_string()))?;
    gibench_harness::error::write_atomic(&args.out.join(format!("{}.json", args.stem)), &json)?;
    set.publish()?;
    eprintln!(
        "wrote {stem}.md, .csv, .tex and .json to {}",
        args.out.display(),
        stem = args.stem
    );
    Ok(())
}

/// Refuses a comparison of runs with themselves: BASE and CURRENT the same folder, a results
/// file reached from both sides or twice from one (through a link), or two byte-identical
/// copies of one run (counted as two repeats, a copy would narrow the noise band falsely).
fn check_distinct_runs(
    args: &CompareArgs,
    base: &[(PathBuf, RunResult)],
    current: &[(PathBuf, RunResult)],
) -> Result<()> {
    let folder = |p: &Path| p.canonicalize().map_err(|e| Error::io(p, e));
    if folder(&args.base)? == folder(&args.current)? {
        return Err(Error::param(
            "current",
            format!(
                "{} is the same folder as BASE ({}); compare needs two different sets of runs",
                args.current.display(),
                args.base.display()
            ),
        ));
    }
    let side = |i: usize| if i < base.len() { "BASE" } else { "CURRENT" };
    // Each file's canonical path and a hash of its bytes; equal hashes are confirmed on the bytes.
    let mut seen: Vec<(PathBuf, u64, &Path)> = Vec::new();
    for (i, (path, _)) in base.iter().chain(current).enumerate() {
        let canonical = folder(path)?;
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let hash = {
            use std::hash::{Hash, Hasher};
            let mut h = std::hash::DefaultHasher::new();
            bytes.hash(&mut h);
            h.finish()
        };
        for (j, (c, other_hash, other)) in seen.iter().enumerate() {
            let same_file = *c == canonical;
            let same_bytes = !same_file
                && *other_hash == hash
                && std::fs::read(other).map_err(|e| Error::io(*other, e))? == bytes;
            if same_file || same_bytes {
                return Err(Error::bad_file(
                    path,
                    format!(
                        "in {}, {} {} in {}; compare needs distinct runs (every repeat run anew, \
                         BASE and CURRENT different folders)",
                        side(i),
                        if same_file {
                            "the same file as"
                        } else {
                            "a byte-identical copy of"
                        },
                        other.display(),
                        side(j)
                    ),
                ));
            }
        }
        seen.push((canonical, hash, path));
    }
    Ok(())
}

/// The first line `program --version` prints, if it runs.
fn tool_version(program: &str) -> Option<String> {
    let o = std::process::Command::new(program)
        .arg("--version")
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    o.status
        .success()
        .then(|| text.lines().next().unwrap_or("").trim().to_string())
}

/// Instructions callgrind counts inside `gibench_kernel_body` for one kernel.
fn count_instructions(kernels: &Path, name: &str) -> Result<u64> {
    let o = std::process::Command::new("valgrind")
        .args([
            "--tool=callgrind",
            "--toggle-collect=gibench_kernel_body",
            "--callgrind-out-file=/dev/null",
        ])
        .arg(kernels)
        .args(["run", name])
        .output()
        .map_err(|e| Error::Invalid(format!("could not run valgrind: {e}")))?;
    let stderr = String::from_utf8_lossy(&o.stderr);
    if !o.status.success() {
        return Err(Error::Invalid(format!(
            "valgrind on kernel '{name}' failed: {stderr}"
        )));
    }
    stderr
        .lines()
        .find_map(|l| l.split("Collected :").nth(1))
        .and_then(|n| n.trim().parse().ok())
        .ok_or_else(|| Error::Invalid(format!("no instruction count for '{name}' in: {stderr}")))
}

fn instructions_cmd(args: &InstructionsArgs) -> Result<()> {
    if !(args.threshold.is_finite() && args.threshold >= 0.0) {
        return Err(Error::param("threshold", "must be a number >= 0"));
    }
    let valgrind = tool_version("valgrind").ok_or_else(|| {
        Error::Invalid(
            "valgrind was not found; install it (Debian: apt-get install valgrind)".into(),
        )
    })?;
    let kernels = std::env::current_exe()
        .map_err(|e| Error::Invalid(e.to_string()))?
        .with_file_name("gibench-kernels");
    if !kernels.is_file() {
        return Err(Error::Invalid(format!(
            "{} not found beside gibench; build it with `cargo build --release --bins`",
            kernels.display()
        )));
    }
    let listed = std::process::Command::new(&kernels)
        .arg("list")
        .output()
        .map_err(|e| Error::io(&kernels, e))?;
    let all: Vec<String> = String::from_utf8_lossy(&listed.stdout)
        .lines()
        .map(str::to_string)
        .collect();
    let names: Vec<String> = if args.kernels.is_empty() {
        all.clone()
    } else {
        for k in &args.kernels {
            if !all.contains(k) {
                return Err(Error::param(
                    "kernels",
                    format!("unknown kernel '{k}'; known: {}", all.join(", ")),
                ));
            }
        }
        args.kernels.clone()
    };
    let rustc = tool_version("rustc").unwrap_or_default();
    let baseline = if args.write {
        None
    } else {
        let bytes = gibench_harness::error::read_bounded(&args.baseline, 1 << 20)?;
        let v: serde_json::Value = serde_json::from_slice(&bytes).map_err(|e| {
            Error::bad_file(&args.baseline, format!("not an instruction baseline: {e}"))
        })?;
        Some(v)
    };
    let mut counts = serde_json::Map::new();
    let mut rows = Vec::new();
    let mut regressions = Vec::new();
    for name in &names {
        let n = count_instructions(&kernels, name)?;
        counts.insert(name.clone(), serde_json::json!(n));
        if let Some(b) = &baseline {
            let base = b["kernels"][name].as_u64();
            let (ratio, verdict) = match base {
                Some(base) if base > 0 => {
                    let r = n as f64 / base as f64;
                    let v = if r > 1.0 + args.threshold {
                        regressions.push(format!("{name} (+{:.1} %)", (r - 1.0) * 100.0));
                        "regression"
                    } else if r < 1.0 - args.threshold {
                        "fewer"
                    } else {
                        "unchanged"
                    };
                    (Some(r), v)
                }
                _ => (None, "not in the baseline"),
            };
            rows.push(vec![
                report::Cell::text(name),
                report::Cell::Num(base.map(|b| b as f64), 0),
                report::Cell::Num(Some(n as f64), 0),
                report::Cell::Num(ratio, 4),
                report::Cell::text(verdict),
            ]);
        }
    }
    if args.write {
        let json = serde_json::json!({
            "valgrind": valgrind,
            "rustc": rustc,
            "git_commit": gibench_harness::runner::git_commit(),
            "kernels": counts,
        });
        let bytes = serde_json::to_vec_pretty(&json).map_err(|e| Error::Invalid(e.to_string()))?;
        gibench_harness::error::write_atomic(&args.baseline, &bytes)?;
        eprintln!(
            "wrote the instruction counts of {} kernels to {}",
            names.len(),
            args.baseline.display()
        );
        return Ok(());
    }
    let b = baseline.expect("compared");
    let same_tools = b["valgrind"].as_str() == Some(valgrind.as_str())
        && b["rustc"].as_str() == Some(rustc.as_str());
    let table = report::Table {
        title: format!(
            "Instructions per kernel (callgrind), against {}",
            args.baseline.display()
        ),
        columns: ["kernel", "baseline", "now", "ratio", "verdict"]
            .map(String::from)
            .to_vec(),
        rows,
        notes: vec![format!(
            "Instructions collected inside gibench_kernel_body (gibench-kernels run NAME) under {valgrind}; \
             a regression is a count more than {:.1} % above the baseline's.",
            args.threshold * 100.0
        )],
    };
    println!("{}", table.to_terminal());
    if regressions.is_empty() {
        return Ok(());
    }
    if !same_tools {
        eprintln!(
            "warning: instruction counts above the baseline ({}), but the baseline was made with {} and {}, this run with {valgrind} and {rustc}: regenerate it (gibench instructions --write) rather than trust the comparison",
            regressions.join(", "),
            b["valgrind"].as_str().unwrap_or("?"),
            b["rustc"].as_str().unwrap_or("?")
        );
        return Ok(());
    }
    Err(Error::Invalid(format!(
        "instruction-count regression beyond {:.1} %: {}",
        args.threshold * 100.0,
        regressions.join(", ")
    )))
}

/// A `--stem` must be a plain file name (checked before any work).
fn check_stem(stem: &str) -> Result<()> {
    if stem.is_empty() || stem.contains(['/', '\\']) || stem.starts_with('.') {
        return Err(Error::param(
            "stem",
            format!("'{stem}' must be a file name without folders, not starting with '.'"),
        ));
    }
    Ok(())
}

fn report_cmd(args: &ReportArgs) -> Result<()> {
    check_stem(&args.stem)?;
    let runs = read_results_with_folders(&args.inputs)?;
    let results: Vec<RunResult> = runs.iter().map(|(_, r)| r.clone()).collect();
    let set = OutputSet::begin("out", &args.out)?;
    let table = report::stage_table(&results);
    println!("{}", table.to_terminal());
    if args.detailed {
        for r in &results {
            println!("{}", report::stage_table_detailed(r).to_terminal());
        }
    }
    report::write_tables(&table, &args.out, &args.stem)?;
    let mut figures = vec![args.out.join(format!("{}.svg", args.stem))];
    report::stacked_bar_svg(&results, &figures[0], "Per-stage times")?;
    if !report::time_error_points(&results).is_empty() {
        let svg = args.out.join(format!("{}-time-vs-error.svg", args.stem));
        report::time_vs_error_svg(&results, &svg, "Time versus error")?;
        figures.push(svg);
    }
    let page = args.out.join(format!("{}.html", args.stem));
    if args.html {
        write_page(&page, table.title.clone(), vec![table], figures, runs)?;
    }
    set.publish()?;
    if args.html {
        eprintln!("{}", page_line(&page).trim_start());
    }
    Ok(())
}

fn reference_cmd(args: &ReferenceArgs) -> Result<()> {
    let planned = reference_plan(args)?;
    let set = OutputSet::begin("out", &args.out)?;
    let done = reference_planned(args, &planned, &Bars::Own(false))?;
    set.publish()?;
    eprintln!("{done}");
    Ok(())
}

/// Checks a frame number or count given as option `option` against the limit every command
/// shares ([`gibench_harness::runner::MAX_FRAMES`]).
pub(crate) fn check_frame_number(option: &str, frame: u32) -> Result<()> {
    let max = gibench_harness::runner::MAX_FRAMES;
    if frame > max {
        return Err(Error::param(
            option,
            format!("{frame} exceeds the limit of {max}"),
        ));
    }
    Ok(())
}

/// A reference render checked before it runs.
pub(crate) struct ReferencePlan {
    resolution: [u32; 2],
    settings: ReferenceSettings,
    desc: SceneDescriptor,
    scene: Scene,
}

pub(crate) fn reference_plan(args: &ReferenceArgs) -> Result<ReferencePlan> {
    let resolution = parse_resolution(&args.resolution)?;
    gibench_harness::runner::check_resolution(resolution)?;
    check_frame_number("frame", args.frame)?;
    let settings = args.reference.settings()?;
    let desc = SceneDescriptor::resolve(&args.scene)?;
    let scene = Scene::load(&desc, &AssetPaths::standard(args.assets.as_deref()))?;
    if !args.reference.no_cache {
        writable_dir("cache", &args.reference.cache)?;
    }
    writable_dir("out", &args.out)?;
    Ok(ReferencePlan {
        resolution,
        settings,
        desc,
        scene,
    })
}

/// The work of `gibench reference` once planned and its output set is open. Returns what it
/// wrote, as a line for the terminal.
pub(crate) fn reference_planned(
    args: &ReferenceArgs,
    planned: &ReferencePlan,
    bars: &Bars,
) -> Result<String> {
    let ReferencePlan {
        resolution,
        settings,
        desc,
        scene,
    } = planned;
    let (resolution, settings) = (*resolution, *settings);
    let frame = gibench_harness::anim::FrameClock::new(desc).frame(args.frame);
    let cache = args.reference.cache();
    bars.note(&format!(
        "gibench: reference for '{}' frame {} at {}x{}: {} spp, {} bounces, seed {}",
        desc.name,
        args.frame,
        resolution[0],
        resolution[1],
        settings.spp,
        settings.bounces,
        settings.seed
    ));
    // Wall and all-thread CPU of the call (BVH build included; `setup` has its share).
    let (r, seconds, cpu_seconds) =
        gibench_harness::calibrate::timed(|| cache.get_timed(scene, &frame, resolution, &settings));
    let (r, setup) = r?;
    let mut estimate = None;
    if args.error_estimate {
        let other = ReferenceSettings {
            seed: settings.seed + 1,
            ..settings
        };
        let r2 = cache.get(scene, &frame, resolution, &other)?;
        let one = gibench_harness::metrics::relative_mse(&r.one_bounce, &r2.one_bounce, &r.hit);
        let multi =
            gibench_harness::metrics::relative_mse(&r.multi_bounce, &r2.multi_bounce, &r.hit);
        bars.note(&format!(
            "relative MSE between seeds {} and {}: one-bounce {one:.5}, multi-bounce {multi:.5}",
            settings.seed, other.seed
        ));
        estimate = Some(
            serde_json::json!({"seeds": [settings.seed, other.seed], "one_bounce_rel_mse": one, "multi_bounce_rel_mse": multi}),
        );
    }
    let stem = format!("{}-f{}-reference", desc.name, args.frame);
    let out = |suffix: &str| args.out.join(format!("{stem}{suffix}"));
    let arr =
        |v: &[gibench_harness::glam::Vec3]| v.iter().map(|c| c.to_array()).collect::<Vec<_>>();
    gibench_harness::image_io::write_exr(&out("-direct.exr"), resolution, &arr(&r.direct))?;
    gibench_harness::image_io::write_exr(&out("-one-bounce.exr"), resolution, &arr(&r.one_bounce))?;
    gibench_harness::image_io::write_exr(
        &out("-multi-bounce.exr"),
        resolution,
        &arr(&r.multi_bounce),
    )?;
    gibench_harness::image_io::write_exr(&out("-radiance.exr"), resolution, &arr(&r.radiance))?;
    let exposure = desc.settings.exposure;
    let png = |radiance: &[gibench_harness::glam::Vec3]| -> Vec<u8> {
        gibench_harness::metrics::tonemap_srgb8(radiance, exposure)
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect()
    };
    gibench_harness::image_io::write_png(&out(".png"), resolution, &png(&r.radiance))?;
    gibench_harness::image_io::write_png(
        &out("-one-bounce.png"),
        resolution,
        &png(&r.radiance_with(&r.one_bounce)),
    )?;
    gibench_harness::image_io::write_png(
        &out("-direct.png"),
        resolution,
        &png(&r.radiance_with(&vec![Default::default(); r.direct.len()])),
    )?;
    let info = serde_json::json!({
        "scene": desc.name, "frame": args.frame, "resolution": resolution, "spp": settings.spp,
        "bounces": settings.bounces, "seed": settings.seed, "seconds": seconds,
        "cpu_seconds": cpu_seconds,
        "bvh_build_seconds": setup.map(|t| t.seconds),
        "bvh_build_cpu_seconds": setup.and_then(|t| t.cpu_seconds),
        "reference_version": gibench_harness::reference::REFERENCE_VERSION,
        "git_commit": gibench_harness::runner::git_commit(), "error_estimate": estimate,
    });
    let json = serde_json::to_vec_pretty(&info).map_err(|e| Error::Invalid(e.to_string()))?;
    gibench_harness::error::write_atomic(&out(".json"), &json)?;
    Ok(format!("wrote {stem}.png, .json and -direct/-one-bounce/-multi-bounce/-radiance.exr to {} ({seconds:.1} s)", args.out.display()))
}

/// A gibench command run as a target of `gibench reproduce`, checked before anything runs.
pub(crate) enum Job {
    Run(Box<RunArgs>, Box<Plan>),
    Sweep(Box<SweepArgs>, Box<SweepPlan>),
    Reference(Box<ReferenceArgs>, Box<ReferencePlan>),
}

impl Job {
    /// Parses and checks `gibench ARGV...` (run, sweep or reference).
    pub(crate) fn plan(argv: &[String]) -> Result<Job> {
        let cli =
            Cli::try_parse_from(std::iter::once("gibench").chain(argv.iter().map(String::as_str)))
                .map_err(|e| Error::Invalid(e.to_string().trim().to_string()))?;
        match cli.command {
            Some(Command::Run(a)) => {
                let p = plan(&a, &[])?;
                p.spec(&a).validate()?;
                Ok(Job::Run(Box::new(a), Box::new(p)))
            }
            Some(Command::Sweep(a)) => {
                let p = sweep_plan(&a)?;
                Ok(Job::Sweep(Box::new(a), Box::new(p)))
            }
            Some(Command::Reference(a)) => {
                let p = reference_plan(&a)?;
                Ok(Job::Reference(Box::new(a), Box::new(p)))
            }
            _ => Err(Error::Invalid(format!(
                "`gibench {}` is not a run, sweep or reference command",
                argv.join(" ")
            ))),
        }
    }

    pub(crate) fn needs_gpu(&self) -> bool {
        !matches!(self, Job::Reference(..))
    }

    /// (frames rendered, frames × pixels; reference: samples × pixels).
    pub(crate) fn work(&self) -> (u64, u64) {
        let of = |spec: &RunSpec| {
            let frames = spec.total_frames();
            let [w, h] = spec.config.resolution;
            (frames, frames * w as u64 * h as u64)
        };
        match self {
            Job::Run(a, p) => of(&p.spec(a)),
            Job::Sweep(a, p) => of(&p.spec(a)),
            Job::Reference(a, p) => {
                let seeds = 1 + a.error_estimate as u64;
                let [w, h] = p.resolution;
                (0, seeds * p.settings.spp as u64 * w as u64 * h as u64)
            }
        }
    }

    /// Runs it into its `--out` (inside an open output set) on `gpu`; returns what it wrote.
    pub(crate) fn execute(&self, gpu: Option<&GpuContext>, bars: &Bars) -> Result<String> {
        let gpu =
            || gpu.ok_or_else(|| Error::Invalid("no adapter was opened for a GPU run".into()));
        match self {
            Job::Run(a, p) => run_planned(a, p, gpu()?, bars),
            Job::Sweep(a, p) => sweep_planned(a, p, gpu()?, bars),
            Job::Reference(a, p) => reference_planned(a, p, bars),
        }
    }
}
