//! `gibench run` (and `gibench` with no arguments): its arguments, the plan checked before
//! anything runs or is written, and the run itself with its tables, plots and page.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use clap::{Args, Parser};
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::kit::technique::{Params, TechniqueInfo};
use gibench_harness::measure::results::RunResult;
use gibench_harness::output::OutputSet;
use gibench_harness::report;
use gibench_harness::run::quality::{IndirectComponent, QualityConfig};
use gibench_harness::run::runner::{Harness, RunConfig, TimingMode};
use gibench_harness::run::session::{RunSpec, TechniqueRun};
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::{Scene, SceneDescriptor};
use gibench_harness::{Error, Result};

use crate::files::{cache_dir, file_name, writable_dir};
use crate::options::{GpuArgs, ReferenceOpts};
use crate::page::{page_line, with_folder, write_page};
use crate::params::{assign_params, parse_resolution};
use crate::progress::{execute_skipping_with_bar, Bars};
use crate::registry;
use crate::shard::{own_units, ShardArgs, ShardRecord};

#[derive(Args, Clone)]
pub struct RunArgs {
    /// Scene: a built-in name (see `gibench list`) or a path to a descriptor JSON; `run` takes
    /// several, comma-separated (one summary table each).
    #[arg(long, default_value = "cornell")]
    pub scene: String,
    /// Techniques, comma-separated (default: every registered technique).
    #[arg(long, value_delimiter = ',')]
    pub technique: Vec<String>,
    /// Technique parameter `name=value` (applies to every selected technique that declares it)
    /// or `technique.name=value`. Repeatable.
    #[arg(long = "param", short = 'p')]
    pub params: Vec<String>,
    /// Measured frames.
    #[arg(long, default_value_t = 60)]
    pub frames: u32,
    /// Warm-up frames run first and dropped from the statistics.
    #[arg(long, default_value_t = 5)]
    pub warmup: u32,
    /// Animation frame to start at.
    #[arg(long, default_value_t = 0)]
    pub first_frame: u32,
    /// Image size WIDTHxHEIGHT (the papers used 1024x768 and 1600x1200).
    #[arg(long, default_value = "256x192")]
    pub resolution: String,
    /// Edge length of each face of the primary light's cube shadow map (Laine: 1024).
    #[arg(long, default_value_t = 256)]
    pub shadow_size: u32,
    /// `stages` (per-stage, flushed), `frame` (whole frames, no added sync) or `both`.
    #[arg(long, default_value = "both")]
    pub timing: String,
    /// Seed for every random choice a technique makes.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Directory for results JSON, images and tables.
    #[arg(long, default_value = "results/local")]
    pub out: PathBuf,
    /// Extra directory searched first for scene assets (glTF files).
    #[arg(long)]
    pub assets: Option<PathBuf>,
    /// Do not write images.
    #[arg(long)]
    pub no_images: bool,
    /// Do not show a progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Also measure image error against the CPU reference (RMSE, relative MSE, MAE, FLIP,
    /// flicker) on consecutive frame pairs spread over the measured frames.
    #[arg(long)]
    pub quality: bool,
    /// Frame pairs compared with the reference when --quality is given [default: 2].
    #[arg(long)]
    pub quality_pairs: Option<u32>,
    /// With --quality, compare every measured frame (per-frame error and lag plots).
    #[arg(long)]
    pub quality_all: bool,
    /// The reference component the indirect irradiance is compared with: one-bounce,
    /// multi-bounce, or direct (for a technique's direct light samples: `barczak set=direct`)
    /// (default: each technique's declared component, see `gibench list`).
    #[arg(long)]
    pub quality_reference: Option<String>,
    /// Compare at equal time: set each technique's quality knob (VPLs, propagation
    /// iterations: `gibench list`) to the largest value whose frame fits this budget on this
    /// device (e.g. 33ms), found by a short timed search, then run at those settings; an
    /// equal-time table beside the summary.
    #[arg(long, value_name = "MS")]
    pub equal_time: Option<String>,
    /// Also write an HTML page of the run (`{scene}-report.html`, or `{stem}.html` for a
    /// sweep): tables, images beside the reference, error maps, time versus error.
    #[arg(long)]
    pub html: bool,
    /// Not an option: set by `reproduce all` for a smoke run (`--test-size tiny`, `--frames`),
    /// the note its tables carry ([`gibench_harness::report::Table::mark_smoke`]).
    #[arg(skip)]
    pub smoke: Option<String>,
    #[command(flatten)]
    pub reference: ReferenceOpts,
    #[command(flatten)]
    pub gpu: GpuArgs,
    #[command(flatten)]
    pub shard: ShardArgs,
}

impl RunArgs {
    /// `gibench` with no arguments: `gibench run`'s defaults, compared with the CPU reference
    /// (cached after the first run) and written up as an HTML page.
    pub fn parse_default() -> RunArgs {
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

/// Everything a run needs, checked before anything runs or is written.
pub struct Plan {
    pub config: RunConfig,
    pub quality: Option<QualityConfig>,
    pub techniques: Vec<&'static TechniqueInfo>,
    pub params: Vec<Params>,
    pub desc: SceneDescriptor,
    pub scene: Scene,
    /// `--equal-time`'s budget (ms), if given: each technique's knob is tuned to it when the
    /// plan runs ([`crate::equal_time::apply`]).
    pub equal_time: Option<f64>,
}

/// Checks `args` (with `extra_params` after its `--param`s) and loads the scene: everything a
/// run needs, before any GPU work or file.
pub fn plan(args: &RunArgs, extra_params: &[String]) -> Result<Plan> {
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
        cache_dir("cache", &args.reference.cache)?;
    }
    let equal_time = (args.equal_time.as_deref())
        .map(crate::equal_time::parse_budget)
        .transpose()?;
    Ok(Plan {
        config,
        quality,
        techniques,
        params,
        desc,
        scene,
        equal_time,
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
    pub fn spec(&self, args: &RunArgs) -> RunSpec<'_> {
        self.spec_with(args, &self.params, &[])
    }

    /// [`Plan::spec`] with each technique's parameters from `params` and, where `recorded` has
    /// an entry, what its results record beside the run's settings.
    fn spec_with(
        &self,
        args: &RunArgs,
        params: &[Params],
        recorded: &[BTreeMap<String, serde_json::Value>],
    ) -> RunSpec<'_> {
        let runs = (self.techniques.iter().zip(params).enumerate())
            .map(|(i, (info, params))| TechniqueRun {
                info,
                params: params.clone(),
                stem: format!("{}-{}", self.desc.name, info.name),
                settings: recorded.get(i).cloned().unwrap_or_default(),
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

/// The line a run starts with: scene, size, adapter, frames and timing mode.
pub fn announcement(plan: &Plan, gpu: &GpuContext) -> String {
    let c = &plan.config;
    format!(
        "gibench: scene '{}' ({} triangles) at {}x{} on {}, {} measured + {} warm-up frames, timing '{}'",
        plan.desc.name,
        plan.scene.mesh.triangle_count(),
        c.resolution[0],
        c.resolution[1],
        gpu.info.label(),
        c.frames,
        c.warmup,
        c.timing.name()
    )
}

/// One plan per scene of `--scene a,b` (each with `args` for that scene alone), checked.
pub fn plan_scenes(args: &RunArgs) -> Result<Vec<(RunArgs, Plan)>> {
    let names: Vec<&str> = args.scene.split(',').map(str::trim).collect();
    for (i, n) in names.iter().enumerate() {
        if n.is_empty() || names[..i].contains(n) {
            return Err(Error::param(
                "scene",
                format!(
                    "expected distinct scene names or descriptor files, comma-separated (got '{}')",
                    args.scene
                ),
            ));
        }
    }
    let mut plans: Vec<(RunArgs, Plan)> = Vec::new();
    for n in &names {
        let mut one = args.clone();
        one.scene = n.to_string();
        let p = plan(&one, &[])?;
        p.spec(&one).validate()?;
        plans.push((one, p));
    }
    Ok(plans)
}

/// The adapter choice `args` ask for.
fn gpu_options(args: &RunArgs) -> GpuOptions {
    GpuOptions {
        backend: args.gpu.backend.clone(),
        adapter: args.gpu.adapter.clone(),
        gpu_timeout: args.gpu.gpu_timeout,
        limits: None,
    }
}

/// The adapter `args` ask for, opened.
pub fn open_gpu(args: &RunArgs) -> Result<GpuContext> {
    GpuContext::new(&gpu_options(args))
}

/// `gibench run`: plan (every scene of `--scene a,b`), open the output set and the adapter,
/// run, publish. With a shard (`--shard`, or a job array's environment) only its part of the
/// (scene, technique) units runs, and a [`ShardRecord`] beside the results says which, for
/// `gibench merge`.
pub fn exec(args: &RunArgs) -> Result<()> {
    // Everything that can be checked without running is checked before anything is written.
    let mut plans = plan_scenes(args)?;
    let shard = args.shard.resolve()?;
    if shard.is_some() && args.equal_time.is_some() {
        // Each shard would tune its techniques on its own device: a merged table would compare
        // settings found on different machines.
        return Err(Error::param(
            "equal-time",
            "cannot be sharded: every technique must be tuned on one device (run it unsharded)",
        ));
    }
    let unit = |p: &Plan, t: &TechniqueInfo| format!("{}-{}", p.desc.name, t.name);
    let record = match &shard {
        Some(s) => {
            eprintln!("gibench run: shard {s} (0-based), from {}", s.source);
            let units: Vec<String> = (plans.iter())
                .flat_map(|(_, p)| p.techniques.iter().map(|t| unit(p, t)))
                .collect();
            let mine = own_units(
                &weigh_equally(&units),
                s,
                &|_| "1 unit".into(),
                "equal weights (every unit runs the same size and frames), ties by name",
            );
            let mut settings = settings(args, &plans[0].1);
            let scenes: Vec<&str> = plans.iter().map(|(_, p)| p.desc.name.as_str()).collect();
            settings.insert("scene".into(), scenes.join(","));
            let mut k = mine.iter();
            for (_, p) in plans.iter_mut() {
                let keep: Vec<bool> = (p.techniques.iter())
                    .map(|_| *k.next().unwrap_or(&false))
                    .collect();
                let mut it = keep.iter();
                p.techniques.retain(|_| *it.next().unwrap_or(&false));
                let mut it = keep.iter();
                p.params.retain(|_| *it.next().unwrap_or(&false));
            }
            Some(ShardRecord::new("run", s, units, settings))
        }
        None => None,
    };
    let set = OutputSet::begin("out", &args.out)?;
    let mut stale = Vec::new();
    for (_, p) in &plans {
        stale.extend(replace_scene_files(&set, &args.out, &p.desc.name, true)?);
    }
    let mut ran: Vec<(String, String)> = Vec::new();
    let mut lines: Vec<String> = Vec::new();
    let mut gpu = None;
    // A lost device ends the runs: those completed are published, the rest listed, and the
    // command fails after publishing.
    let mut lost = None;
    for (one, p) in &plans {
        if p.techniques.is_empty() {
            continue;
        }
        if lost.is_some() {
            for t in &p.techniques {
                ran.push((
                    unit(p, t),
                    "skipped: not run: the GPU device was lost before it".into(),
                ));
            }
            continue;
        }
        if gpu.is_none() {
            gpu = Some(open_gpu(args)?);
        }
        let g = gpu.as_ref().expect("opened above");
        let (line, skipped) = match run_planned_skipping(one, p, g, &Bars::Own(args.quiet)) {
            Ok(r) => r,
            // Lost before any run of this scene completed: the earlier scenes' runs are
            // still published, this scene's listed as not completed.
            Err(e @ Error::DeviceLost { .. }) => {
                for t in &p.techniques {
                    ran.push((unit(p, t), format!("skipped: not completed: {e}")));
                }
                lines.push(format!("{}: not completed: {e}", p.desc.name));
                lost = Some(e);
                continue;
            }
            Err(e) => return Err(e),
        };
        lines.push(line);
        lost = lost.or(gibench_harness::run::session::device_lost(&skipped));
        for t in &p.techniques {
            let why = skipped.iter().find(|s| s.technique == t.name);
            let file = match why {
                Some(s) => format!("skipped: {}", s.reason),
                None => format!("{}.json", unit(p, t)),
            };
            ran.push((unit(p, t), file));
        }
    }
    if let Some(mut record) = record {
        record.ran = ran;
        record.write(&args.out)?;
        if lines.is_empty() {
            lines.push("this shard has no techniques to run".into());
        }
    }
    set.publish()?;
    lines.extend(removed_note(&stale));
    eprintln!("{}", lines.join("\n"));
    match lost {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// The files about scene `name` as a whole that a run or a merge writes only with some options
/// (`--html`, `--quality`, a technique skipped), declared replaced in `set`: at publication
/// those this command did not write are removed, so that no page, plot or list of an earlier
/// command into `out` is left beside tables of other runs (a page kept the old numbers over
/// the new images). The run's own results files are not among them: runs of other techniques
/// made into the same folder stay; the skipped list only where `skipped_list` (a merge writes
/// none, so it leaves the folder's). Returns those of the files present now.
pub fn replace_scene_files(
    set: &OutputSet,
    out: &Path,
    name: &str,
    skipped_list: bool,
) -> Result<Vec<PathBuf>> {
    let mut files = vec![
        format!("{name}-report.html"),
        format!("{name}-rmse-per-frame.svg"),
        format!("{name}-flicker-per-frame.svg"),
        format!("{name}-time-vs-error.svg"),
        format!("{name}-equal-time.md"),
        format!("{name}-equal-time.csv"),
        format!("{name}-equal-time.tex"),
    ];
    if skipped_list {
        files.push(skipped_file(name));
    }
    replace_listing_present(set, out, &files)
}

/// Declares the files `names` of `out` replaced in `set` ([`OutputSet::replace_files`]);
/// returns the paths of those present now, for [`removed_note`] after publication.
pub(crate) fn replace_listing_present(
    set: &OutputSet,
    out: &Path,
    names: &[String],
) -> Result<Vec<PathBuf>> {
    let mut present = Vec::new();
    // A figure's PDF beside its SVG (`report::pdf_path`) goes with it.
    let pdfs = (names.iter())
        .filter_map(|f| f.strip_suffix(".svg"))
        .map(|stem| format!("{stem}.pdf"));
    for f in names.iter().cloned().chain(pdfs) {
        set.replace_files(&f)?;
        let path = out.join(f);
        if path.is_file() {
            present.push(path);
        }
    }
    Ok(present)
}

/// A note naming the files of [`replace_scene_files`] an earlier command had left that this
/// one removed (`None` if none).
pub fn removed_note(before: &[PathBuf]) -> Option<String> {
    let gone: Vec<String> = before
        .iter()
        .filter(|p| !p.exists())
        .map(|p| file_name(p))
        .collect();
    (!gone.is_empty()).then(|| {
        format!(
            "note: removed {} of an earlier command into this folder (they described other runs than this one's tables)",
            gone.join(", ")
        )
    })
}

/// Units of equal weight (a run's or a sweep's units share one size and frame count).
pub fn weigh_equally(units: &[String]) -> Vec<(&str, f64)> {
    units.iter().map(|u| (u.as_str(), 1.0)).collect()
}

/// The settings every shard of one run must share, by name (`gibench merge` compares them).
pub fn settings(args: &RunArgs, plan: &Plan) -> BTreeMap<String, String> {
    let c = &plan.config;
    let q = plan.quality.as_ref();
    [
        ("scene", plan.desc.name.clone()),
        (
            "resolution",
            format!("{}x{}", c.resolution[0], c.resolution[1]),
        ),
        ("frames", c.frames.to_string()),
        ("warmup", c.warmup.to_string()),
        ("first-frame", c.first_frame.to_string()),
        ("timing", c.timing.name().to_string()),
        ("seed", c.seed.to_string()),
        ("shadow-size", c.shadow_size.to_string()),
        ("param", args.params.join(" ")),
        ("images", (!args.no_images).to_string()),
        ("html", args.html.to_string()),
        ("quality", q.is_some().to_string()),
        (
            "quality-pairs",
            q.map(|q| q.pairs.to_string()).unwrap_or_default(),
        ),
        ("quality-all", q.is_some_and(|q| q.all).to_string()),
        (
            "quality-reference",
            args.quality_reference.clone().unwrap_or_default(),
        ),
        (
            "equal-time",
            plan.equal_time
                .map(|ms| format!("{ms}ms"))
                .unwrap_or_default(),
        ),
        ("commit", gibench_harness::run::runner::git_commit()),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect()
}

/// The file in which a run over every technique on `scene` lists those it skipped and why.
fn skipped_file(scene: &str) -> String {
    format!("{scene}-skipped.json")
}

/// The work of `gibench run` once planned and its output set is open: runs, tables, plots.
/// Returns what it wrote, as a line for the terminal.
pub fn run_planned(args: &RunArgs, plan: &Plan, gpu: &GpuContext, bars: &Bars) -> Result<String> {
    let (done, skipped) = run_planned_skipping(args, plan, gpu, bars)?;
    // A target of `reproduce all` is complete only with every run: a lost device fails it.
    match gibench_harness::run::session::device_lost(&skipped) {
        Some(e) => Err(e),
        None => Ok(done),
    }
}

/// With `--equal-time`: a technique whose run measured its frame off the mark
/// ([`crate::equal_time::off_the_mark`]: over the budget, or under 85 % of it) is tuned again
/// with that measurement as one more timing of its value and run again, at most
/// [`crate::equal_time::MAX_RETUNES`] times; `results` get the new runs (their files replace
/// the earlier ones), and each record lists the measurements that sent it back (`runs`).
#[allow(clippy::too_many_arguments)]
fn retune_off_the_mark(
    args: &RunArgs,
    plan: &Plan,
    gpu: &GpuContext,
    bars: &Bars,
    budget: f64,
    params: &mut [Params],
    recorded: &mut [BTreeMap<String, serde_json::Value>],
    results: &mut [RunResult],
) -> Result<()> {
    for _ in 0..crate::equal_time::MAX_RETUNES {
        let off: Vec<(usize, f64)> = (plan.techniques.iter().enumerate())
            .filter_map(|(i, info)| {
                let r = results.iter().find(|r| r.technique == info.name)?;
                let ms = report::frame_time_ms(r)?;
                crate::equal_time::off_the_mark(&recorded[i]["equal_time"], ms).then_some((i, ms))
            })
            .collect();
        if off.is_empty() {
            return Ok(());
        }
        let h = Harness::new(gpu, &plan.scene, &plan.config)?;
        for &(i, ms) in &off {
            let info = plan.techniques[i];
            bars.note(&format!(
                "equal time {budget} ms: {}'s run measured {ms:.2} ms a frame, off the mark (85-100 % of the budget): tuning it again",
                info.name
            ));
            let (p, record) = crate::equal_time::retune(
                info,
                &params[i],
                &plan.config,
                &h,
                &recorded[i]["equal_time"],
                ms,
                bars,
            )?;
            params[i] = p;
            recorded[i].insert("equal_time".to_string(), record);
        }
        drop(h);
        let mut spec = plan.spec_with(args, params, recorded);
        spec.runs.retain(|r| {
            off.iter()
                .any(|&(i, _)| plan.techniques[i].name == r.info.name)
        });
        let (again, lost) = execute_skipping_with_bar(bars, gpu, &spec, false)?;
        if let Some(e) = gibench_harness::run::session::device_lost(&lost) {
            return Err(e);
        }
        for r in again {
            if let Some(old) = results.iter_mut().find(|o| o.technique == r.technique) {
                *old = r;
            }
        }
    }
    Ok(())
}

/// Said before an equal-time search on a software rasteriser left to its default threads.
/// Measured on a shared 2-core machine (lavapipe, `gaitatzes` on Cornell at one setting, 30
/// frames a run): five runs' medians 79.1-126.3 ms with the default threads, in two modes a
/// whole run long; with `LP_NUM_THREADS=0` 126.1-133.3 ms over four runs of 10 frames. One
/// thread is steadier, not steady: `barczak` at 126 VPLs (10 frames) measured 88.6-129.6 ms in
/// 22 of 28 processes on one thread and 141-169 ms in the other 6, each steady within its
/// process (neither glibc's malloc thresholds fixed nor address randomisation off changed
/// that; not explained).
const UNSTEADY_SOFTWARE: &str = "equal time: this device is a software rasteriser on its default threads, whose frame time can move by tens of percent from one run to the next (on a shared machine); a run may then land off the budget however the search went. LP_NUM_THREADS=0 (one thread: slower, and steadier) gives settings that hold more often";

/// [`run_planned`], also returning the techniques a run over every technique left out.
fn run_planned_skipping(
    args: &RunArgs,
    plan: &Plan,
    gpu: &GpuContext,
    bars: &Bars,
) -> Result<(String, Vec<gibench_harness::run::session::Skipped>)> {
    bars.note(&announcement(plan, gpu));
    // With --equal-time, each technique's knob tuned to the budget first.
    let (mut params, mut recorded) = (plan.params.clone(), Vec::new());
    if let Some(budget) = plan.equal_time {
        if gpu.info.is_software() && gpu.info.driver_env.is_empty() {
            bars.note(UNSTEADY_SOFTWARE);
        }
        let h = Harness::new(gpu, &plan.scene, &plan.config)?;
        let records = crate::equal_time::apply(
            &plan.techniques,
            &mut params,
            &plan.config,
            &h,
            budget,
            bars,
        )?;
        recorded = (records.into_iter())
            .map(|r| BTreeMap::from([("equal_time".to_string(), r)]))
            .collect();
    }
    let spec = plan.spec_with(args, &params, &recorded);
    // A run over every technique leaves out one that cannot take the scene or the device; one
    // named with --technique is an error.
    let (mut results, skipped) =
        execute_skipping_with_bar(bars, gpu, &spec, args.technique.is_empty())?;
    if let Some(budget) = plan.equal_time {
        retune_off_the_mark(
            args,
            plan,
            gpu,
            bars,
            budget,
            &mut params,
            &mut recorded,
            &mut results,
        )?;
    }
    let name = &plan.desc.name;
    if let Some(e) = (results.is_empty())
        .then(|| gibench_harness::run::session::device_lost(&skipped))
        .flatten()
    {
        return Err(e);
    }
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
    let notes: Vec<(String, String)> = (skipped.iter())
        .map(|s| (s.technique.clone(), s.reason.clone()))
        .collect();
    let (tables, mut written) = write_summary(
        &results,
        &notes,
        &args.out,
        name,
        plan.quality.is_some(),
        args.smoke.as_deref(),
    )?;
    for t in &tables {
        bars.table(t);
    }
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
        gibench_harness::output::write_atomic(&path, &bytes)?;
        written.push(file_name(&path));
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
            tables,
            written
                .iter()
                .filter(|w| w.ends_with(".svg"))
                .map(|w| args.out.join(w))
                .collect(),
            with_folder(&args.out, results),
        )?;
        done.push_str(&page_line(&page));
    }
    Ok((done, skipped))
}

/// The tables and plots of a run on scene `name` from its `results` (and the techniques it
/// `skipped`, with why): `{name}-summary.md/.csv/.tex/.svg`, with `quality` the error plots,
/// and where runs record an `--equal-time` search `{name}-equal-time.md/.csv/.tex`, into
/// `out`, the tables marked with `smoke`'s note for a smoke run. `gibench run` and `gibench
/// merge` (pooling shards) both write them here. Returns the tables (the summary first) and
/// the files written.
pub fn write_summary(
    results: &[RunResult],
    skipped: &[(String, String)],
    out: &Path,
    name: &str,
    quality: bool,
    smoke: Option<&str>,
) -> Result<(Vec<report::Table>, Vec<String>)> {
    let mut table = report::stage_table(results);
    // Before the Pareto front's line, which ends the notes.
    let at = (table.notes.iter())
        .position(|n| n.starts_with("Pareto front"))
        .unwrap_or(table.notes.len());
    for (k, (technique, reason)) in skipped.iter().enumerate() {
        table
            .notes
            .insert(at + k, format!("Skipped {technique}: {reason}"));
    }
    if let Some(note) = smoke {
        table.mark_smoke(note);
    }
    let stem = format!("{name}-summary");
    let mut written: Vec<String> = report::write_tables(&table, out, &stem)?
        .iter()
        .map(|p| file_name(p))
        .collect();
    report::stacked_bar_svg(
        results,
        &out.join(format!("{stem}.svg")),
        &format!("Per-stage times on {name}"),
    )?;
    written.push(format!("{stem}.svg"));
    if quality {
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
            let svg = out.join(format!("{name}-{metric}-per-frame.svg"));
            if report::per_frame_lines(results, metric)?.is_empty() {
                // Every value is not a number (each run's warnings say why): what is valid
                // is still written.
                eprintln!(
                    "note: no {metric} value is a number; {} not drawn",
                    file_name(&svg)
                );
                continue;
            }
            report::quality_over_frames_svg(
                results,
                metric,
                &svg,
                &format!("{metric} against the reference on {name}"),
            )?;
            written.push(file_name(&svg));
        }
    }
    if quality {
        let svg = out.join(format!("{name}-time-vs-error.svg"));
        if report::time_error_points(results).is_empty() {
            eprintln!(
                "note: no run has an error that is a number; {} not drawn",
                file_name(&svg)
            );
        } else {
            report::time_vs_error_svg(results, &svg, &format!("Time versus error on {name}"))?;
            written.push(file_name(&svg));
        }
    }
    let mut tables = vec![table];
    if let Some(mut equal) = report::equal_time_table(results) {
        if let Some(note) = smoke {
            equal.mark_smoke(note);
        }
        let files = report::write_tables(&equal, out, &format!("{name}-equal-time"))?;
        written.extend(files.iter().map(|p| file_name(p)));
        tables.push(equal);
    }
    Ok((tables, written))
}
