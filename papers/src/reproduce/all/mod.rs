//! `gibench reproduce all`: every paper table, figure and sweep in one command.
//!
//! The targets are listed once, in [`TARGETS`]: the paper modules' typed reproductions and the
//! sweeps and runs that are plain gibench commands (each with its arguments at quick and at
//! paper sizes). `all` checks every selected target before any runs (scenes load, parameters
//! parse, folders are writable), prints a time estimate, runs them one after another on one
//! adapter under one progress bar, and publishes everything as one output set: each target's
//! folder under `--out` is replaced (files its target did not write are removed), so the folder
//! never mixes the files of two runs of a target. It then lists every table and figure it
//! wrote and records them in `reproduce-all.json` / `.md` (per target: the command, the work,
//! the estimate and the time taken) and `reproduce-all.html` (one page with every target's
//! figures and links to its tables and pages).
//!
//! **The estimate** scales the time each target took in the last `reproduce all` recorded in
//! the output folder (or in the committed `results/`) by the work it does now (frames ×
//! pixels; frames × VPLs for CPU-only targets); it says which adapter and mode those times were
//! measured on. A target never timed before has no estimate, and the printout says so.
//!
//! This file runs the command (one target, or all of them) and prints the plan; [`targets`]
//! lists the targets, [`planned`] checks and runs one, [`Overall`] (in `cli::progress`) is the shared progress bar
//! and [`manifest`] the record of what ran.

mod manifest;
mod merge;
mod planned;
mod resume;
mod targets;

use std::path::{Path, PathBuf};
use std::time::Instant;

use gibench_harness::gpu::GpuContext;
use gibench_harness::output::OutputSet;
use gibench_harness::{Error, Result};

use super::{out_dir, ReproduceArgs};
use crate::files::writable_dir;
use crate::progress::{Bars, Overall};
use manifest::{duration, Manifest, Record, MANIFEST};
pub use merge::merge;
use planned::Planned;
use resume::Checkpoint;
pub use targets::{find, Kind, Target, TARGETS};

/// `gibench reproduce TARGET` (one target) or `gibench reproduce all`.
pub fn reproduce(args: &ReproduceArgs) -> Result<()> {
    let began = Instant::now();
    if args.target != "all" {
        return reproduce_one(args);
    }
    if !args.scenes.is_empty() {
        return Err(Error::param(
            "scenes",
            "applies to single Laine targets; `all` runs every target on its own scenes",
        ));
    }
    let root = args.out.clone().unwrap_or_else(|| PathBuf::from("results"));
    let selected = selected_targets(args)?;
    let shard = args.shard.resolve()?;
    if let Some(s) = &shard {
        eprintln!(
            "gibench reproduce all: shard {s} (0-based), from {}",
            s.source
        );
    }
    // Every target is checked before any runs.
    eprintln!("gibench reproduce all: checking {} targets", selected.len());
    let planned: Vec<Planned> = selected
        .iter()
        .map(|t| Planned::new(t, args, root.join(t.dir)))
        .collect::<Result<_>>()?;
    let selected_names: Vec<String> = planned.iter().map(|p| p.target.name.to_string()).collect();
    let planned = match &shard {
        Some(s) => own_part(planned, s),
        None => planned,
    };
    let mode = args.mode();
    let gpu = if planned.iter().any(Planned::needs_gpu) {
        Some(super::open_gpu(args)?)
    } else {
        None
    };
    let adapter = gpu
        .as_ref()
        .map(|g| g.info.label())
        .unwrap_or_else(|| "CPU only".into());
    let previous = Manifest::previous(&root);
    let (measured, sources) = estimates(&planned, previous.as_ref());
    let estimates: Vec<Option<f64>> = measured.iter().map(|m| m.as_ref().map(|e| e.0)).collect();
    let sources: Vec<&str> = sources.iter().map(String::as_str).collect();
    print_plan(
        &planned,
        &estimates,
        previous.as_ref(),
        &sources,
        &mode,
        &adapter,
        &root,
    );
    if args.budget.is_some() || args.list {
        eprintln!(
            "with --budget, targets run in this order (the papers' headline tables first): {}",
            targets::PRIORITY.join(", ")
        );
    }
    if args.list {
        return Ok(());
    }
    writable_dir("out", &root)?;
    let checkpoint = Checkpoint::new(
        &root,
        &planned,
        &mode,
        &adapter,
        shard.as_ref().map(ToString::to_string),
        std::env::args().collect::<Vec<_>>().join(" "),
    );
    let mut resumed: Vec<Option<Record>> = planned.iter().map(|_| None).collect();
    let set = OutputSet::resume("out", &root, &mut |present| {
        let (keep, taken) = checkpoint.take_over(present);
        resumed = taken;
        keep
    })?;
    for (p, r) in planned.iter().zip(&resumed) {
        if r.is_some() {
            claim_folders(&set, p.target)?;
        }
    }
    let budget = args.budget.map(|b| Budget {
        ends: began + b,
        total: b.as_secs_f64(),
        adapter: adapter.clone(),
        measured,
    });
    let (records, seconds) = match run_targets(
        &planned,
        &estimates,
        budget.as_ref(),
        gpu.as_ref(),
        &adapter,
        (&set, &checkpoint, resumed),
        args.quiet,
    ) {
        // Stopped by a signal or a lost device, or failed: the completed targets stay staged
        // for a resume (the same command again).
        Err(e) => {
            set.suspend();
            if !e.stops_everything() {
                eprintln!(
                    "gibench reproduce all: the targets completed before this error are kept \
                     (staged); run the same command again to resume"
                );
            }
            return Err(e);
        }
        Ok(r) => r,
    };
    let estimate: Option<f64> = estimates.iter().copied().sum();
    let mut manifest = Manifest::new(
        &mode,
        &adapter,
        gpu.as_ref(),
        seconds,
        estimate,
        records,
        // Entries are carried over only from this folder's own manifest: one found elsewhere
        // (the committed results/) only gives estimates; its files are not here. A shard's
        // manifest holds its own targets only (what `gibench merge` pools).
        previous
            .as_ref()
            .filter(|p| p.source == root.join(format!("{MANIFEST}.json")) && shard.is_none()),
    );
    manifest.budget_s = args.budget.map(|b| b.as_secs_f64());
    if let Some(s) = &shard {
        manifest.shard = Some(s.to_string());
        manifest.shard_source = Some(s.source.clone());
        manifest.selected = selected_names;
    }
    let manifest = manifest.dated_by_their_files(&root);
    manifest.write(&root)?;
    manifest.write_index(&root)?;
    set.publish()?;
    checkpoint.finish();
    println!("{}", manifest.listing(&root));
    let failed: Vec<&str> = manifest
        .targets
        .iter()
        .filter(|t| t.left_out.as_deref().is_some_and(|w| w.starts_with(FAILED)))
        .map(|t| t.name.as_str())
        .collect();
    if !failed.is_empty() {
        return Err(Error::Invalid(format!(
            "{} target(s) failed and were left out: {} (reproduce-all.json says why); the \
             others are published in {}",
            failed.len(),
            failed.join(", "),
            root.display()
        )));
    }
    Ok(())
}

/// How a target that failed within a budget is recorded as left out.
const FAILED: &str = "failed: ";

/// The targets of shard `s`: the selection split by [`crate::shard::assign`] on the
/// estimates of the committed manifest (the same file on every machine of a checkout), a
/// target never timed there weighing the mean of those timed (1 s where none is).
fn own_part(planned: Vec<Planned>, s: &crate::shard::Shard) -> Vec<Planned> {
    let committed = Manifest::committed();
    let timed: Vec<Option<f64>> = planned
        .iter()
        .map(|p| {
            committed
                .as_ref()
                .and_then(|m| m.estimate(p.target.name, p.work.units))
                .map(|e| e.0)
        })
        .collect();
    let known: Vec<f64> = timed.iter().flatten().copied().collect();
    let fallback = if known.is_empty() {
        1.0
    } else {
        known.iter().sum::<f64>() / known.len() as f64
    };
    let units: Vec<(&str, f64)> = planned
        .iter()
        .zip(&timed)
        .map(|(p, t)| (p.target.name, t.unwrap_or(fallback)))
        .collect();
    let basis = format!(
        "the estimates of {}{}",
        committed
            .as_ref()
            .map(|m| m.source.display().to_string())
            .unwrap_or_else(|| "nothing: no results/reproduce-all.json here".into()),
        if known.len() < timed.len() {
            "; a target never timed there weighs their mean"
        } else {
            ""
        }
    );
    let mine = crate::shard::own_units(&units, s, &|e| duration(e), &basis);
    planned
        .into_iter()
        .zip(mine)
        .filter(|(_, m)| *m)
        .map(|(p, _)| p)
        .collect()
}

/// `--budget`: when it ends, and what the estimates were measured on.
struct Budget {
    ends: Instant,
    total: f64,
    adapter: String,
    /// Per planned target: its estimate and the adapter that estimate was measured on.
    measured: Vec<Option<(f64, String)>>,
}

/// `gibench reproduce TARGET`: one target into its folder.
fn reproduce_one(args: &ReproduceArgs) -> Result<()> {
    if !args.only.is_empty() {
        return Err(Error::param(
            "only",
            "applies to `gibench reproduce all` only",
        ));
    }
    let target = find(&args.target)?;
    let out = out_dir(args, target.dir);
    let planned = Planned::new(target, args, out.clone())?;
    if args.list {
        println!(
            "{}  {}\n  {}",
            target.name,
            planned.target.description(),
            planned.command
        );
        return Ok(());
    }
    writable_dir("out", &out)?;
    let set = OutputSet::begin("out", &out)?;
    let gpu = if planned.needs_gpu() && planned.job.is_some() {
        Some(super::open_gpu(args)?)
    } else {
        None
    };
    let done = planned.run(gpu.as_ref(), &Bars::Own(args.quiet))?;
    set.publish()?;
    eprintln!("{done}");
    Ok(())
}

/// The targets `all` runs: every one, or those `--only` names (in the order of [`TARGETS`]).
fn selected_targets(args: &ReproduceArgs) -> Result<Vec<&'static Target>> {
    if args.only.is_empty() {
        return Ok(TARGETS.iter().collect());
    }
    let mut picked = Vec::new();
    for name in &args.only {
        let t = TARGETS
            .iter()
            .find(|t| t.name == name.trim())
            .ok_or_else(|| {
                Error::param(
                    "only",
                    format!(
                        "'{name}' is not a target of `all`; expected some of: {}",
                        TARGETS
                            .iter()
                            .map(|t| t.name)
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })?;
        if picked.iter().any(|p: &&Target| p.name == t.name) {
            return Err(Error::param("only", format!("'{name}' is listed twice")));
        }
        picked.push(t);
    }
    // In the order of TARGETS, whatever the order given.
    Ok(TARGETS
        .iter()
        .filter(|t| picked.iter().any(|p| p.name == t.name))
        .collect())
}

/// Each target's estimate (seconds) from the earlier manifest, and the adapters those
/// estimates were measured on (a CPU-only target's on any), sorted, each once.
fn estimates(
    planned: &[Planned],
    previous: Option<&Manifest>,
) -> (Vec<Option<(f64, String)>>, Vec<String>) {
    let measured: Vec<Option<(f64, String)>> = planned
        .iter()
        .map(|p| previous.and_then(|m| m.estimate(p.target.name, p.work.units)))
        .collect();
    let mut sources: Vec<String> = measured
        .iter()
        .zip(planned)
        .filter(|(_, p)| p.needs_gpu())
        .filter_map(|(m, _)| m.as_ref().map(|e| e.1.clone()))
        .collect();
    sources.sort();
    sources.dedup();
    (measured, sources)
}

/// Claims for the output set the folders `target` owns entirely: a command target's folder,
/// a paper target's owned subfolders (files there that the run does not write are removed).
/// Claimed just before the target runs: a target the budget leaves out keeps its folder.
pub(super) fn claim_folders(set: &OutputSet, target: &Target) -> Result<()> {
    if matches!(target.kind, Kind::Command { .. }) {
        set.replace(Path::new(target.dir))?;
    }
    if let Kind::Paper(m) = target.kind {
        for sub in (m.owned_folders)(target.name) {
            set.replace(&Path::new(target.dir).join(sub))?;
        }
    }
    Ok(())
}

/// Runs the planned targets one after another under one bar (with a budget: in priority
/// order, each the first not yet run whose estimate fits what is left), except those an
/// interrupted run completed (`resumed`: their entries); returns each one's record (its files:
/// what it staged in `set`; a target left out says why) and the seconds they took together.
/// After each target `checkpoint` records the progress; a signal stops the run before the
/// next target or frame (the target it stopped is dropped, the completed ones stay staged).
fn run_targets(
    planned: &[Planned],
    estimates: &[Option<f64>],
    budget: Option<&Budget>,
    gpu: Option<&GpuContext>,
    adapter: &str,
    (set, checkpoint, resumed): (&OutputSet, &Checkpoint, Vec<Option<Record>>),
    quiet: bool,
) -> Result<(Vec<Record>, f64)> {
    // The bar advances in estimated milliseconds (work units where there is no estimate).
    let spans: Vec<u64> = if estimates.iter().all(Option::is_some) {
        estimates
            .iter()
            .map(|e| (e.unwrap_or(0.0) * 1e3).max(1.0) as u64)
            .collect()
    } else {
        planned.iter().map(|p| p.work.units.max(1)).collect()
    };
    let overall = Overall::new(
        quiet,
        (spans.iter().zip(&resumed))
            .filter(|(_, r)| r.is_none())
            .map(|(s, _)| s)
            .sum(),
    );
    let started = Instant::now();
    let mut order: Vec<usize> = (0..planned.len())
        .filter(|&i| resumed[i].is_none())
        .collect();
    let to_run = order.len();
    let mut records = resumed;
    let mut before = set.staged().len();
    if budget.is_some() {
        order.sort_by_key(|&i| targets::priority(planned[i].target.name));
    }
    // Measured ÷ estimated over the GPU targets run so far whose estimates came from another
    // adapter: scales the rest of those estimates (1 until one has run).
    let (mut took, mut guessed) = (0.0f64, 0.0f64);
    let mut n = 0;
    while let Some(pos) = match budget {
        None => (!order.is_empty()).then_some(0),
        Some(b) => {
            let left = b
                .ends
                .saturating_duration_since(Instant::now())
                .as_secs_f64();
            order
                .iter()
                .position(|&i| fits(b, i, planned[i].needs_gpu(), took, guessed, left))
        }
    } {
        let i = order.remove(pos);
        let p = &planned[i];
        if let Err(e) =
            gibench_harness::interrupt::check(|| format!("the start of {}", p.target.name))
        {
            return Err(stopped(e, checkpoint, &records));
        }
        n += 1;
        overall.start(
            &format!("{}/{} {}", n, to_run, p.target.name),
            spans[i],
            p.work.frames,
        );
        let mark = set.mark();
        claim_folders(set, p.target)?;
        let t = Instant::now();
        let done = match p.run(gpu, &Bars::Shared(&overall)) {
            Ok(done) => done,
            // A signal, or a lost device (no later target could run either): the completed
            // targets stay staged for a resume.
            Err(e) if e.stops_everything() => {
                overall.finish();
                set.rollback(mark)?;
                return Err(stopped(e, checkpoint, &records));
            }
            // Within a budget (a short GPU slot) one target's failure does not cost the
            // others: it is left out with its error, nothing of it is published, the rest go on,
            // and the command fails after publishing.
            Err(e) if budget.is_some() => {
                set.rollback(mark)?;
                before = set.staged().len();
                let why = format!("{FAILED}{e}");
                overall.note(&format!("{} {why}", p.target.name));
                records[i] = Some(record(
                    p,
                    estimates[i],
                    adapter,
                    None,
                    Vec::new(),
                    Some(why),
                ));
                continue;
            }
            Err(e) => return Err(e),
        };
        let seconds = t.elapsed().as_secs_f64();
        if let Some(Some((e, from))) = budget.map(|b| &b.measured[i]) {
            if p.needs_gpu() && *from != adapter {
                took += seconds;
                guessed += e;
            }
        }
        let staged = set.staged();
        let files: Vec<PathBuf> = staged[before..].to_vec();
        before = staged.len();
        overall.note(&format!(
            "{} done in {}: {done}",
            p.target.name,
            duration(seconds)
        ));
        records[i] = Some(record(p, estimates[i], adapter, Some(seconds), files, None));
        checkpoint.save(&records, None)?;
    }
    overall.finish();
    // What the budget left out, and why.
    if let Some(b) = budget {
        let left = b
            .ends
            .saturating_duration_since(Instant::now())
            .as_secs_f64();
        for i in order {
            let p = &planned[i];
            let why = match &b.measured[i] {
                None => format!(
                    "no estimate: never timed in the manifest the estimates come from, so it cannot be known to fit the {} budget",
                    duration(b.total)
                ),
                Some(_) => format!(
                    "its estimate {} did not fit the {} left of the {} budget",
                    duration(scaled(b, i, p.needs_gpu(), took, guessed)),
                    duration(left),
                    duration(b.total)
                ),
            };
            eprintln!("left out: {} ({why})", p.target.name);
            records[i] = Some(record(
                p,
                estimates[i],
                adapter,
                None,
                Vec::new(),
                Some(why),
            ));
        }
    }
    Ok((
        records.into_iter().flatten().collect(),
        started.elapsed().as_secs_f64(),
    ))
}

/// A run stopped by a signal or a lost device (`e`): records what is complete and what is
/// missing, and says so; returns `e` (or the error recording failed with).
fn stopped(e: Error, checkpoint: &Checkpoint, records: &[Option<Record>]) -> Error {
    if let Err(w) = checkpoint.save(records, Some(&e.to_string())) {
        return w;
    }
    eprintln!(
        "gibench reproduce all: {e}; {} target(s) complete are kept (staged, not published); \
         missing: {}. Run the same command again to resume (docs/fleet.md).",
        records
            .iter()
            .flatten()
            .filter(|r| r.left_out.is_none())
            .count(),
        checkpoint.missing(records).join(", ")
    );
    e
}

/// Target `i`'s estimate for the budget: as measured, or for a GPU target measured on another
/// adapter, scaled by `took / guessed` (this run's measured ÷ estimated) once that is known.
fn scaled(b: &Budget, i: usize, needs_gpu: bool, took: f64, guessed: f64) -> f64 {
    match &b.measured[i] {
        None => f64::INFINITY,
        Some((e, from)) if needs_gpu && *from != b.adapter && guessed > 0.0 => e * took / guessed,
        Some((e, _)) => *e,
    }
}

/// Whether target `i` may start with `left` seconds of the budget left: its (scaled) estimate
/// plus a tenth for the estimate's noise fits. A target without an estimate never does.
fn fits(b: &Budget, i: usize, needs_gpu: bool, took: f64, guessed: f64, left: f64) -> bool {
    scaled(b, i, needs_gpu, took, guessed) * 1.1 <= left
}

/// A target's manifest entry.
fn record(
    p: &Planned,
    estimate_s: Option<f64>,
    adapter: &str,
    seconds: Option<f64>,
    files: Vec<PathBuf>,
    left_out: Option<String>,
) -> Record {
    Record {
        name: p.target.name.to_string(),
        dir: p.target.dir.to_string(),
        what: p.target.description(),
        command: p.command.clone(),
        frames: p.work.frames,
        units: p.work.units,
        estimate_s,
        seconds,
        files: files
            .iter()
            .map(|f| f.to_string_lossy().into_owned())
            .collect(),
        carried_from: None,
        adapter: if p.needs_gpu() {
            adapter.to_string()
        } else {
            "CPU only".into()
        },
        left_out,
    }
}

#[allow(clippy::too_many_arguments)]
fn print_plan(
    planned: &[Planned],
    estimates: &[Option<f64>],
    previous: Option<&Manifest>,
    sources: &[&str],
    mode: &str,
    adapter: &str,
    root: &Path,
) {
    eprintln!(
        "gibench reproduce all ({mode} sizes) on {adapter}: {} targets into {}",
        planned.len(),
        root.display()
    );
    for (p, e) in planned.iter().zip(estimates) {
        eprintln!(
            "  {:<26} {:>9}  {:<22} {}",
            p.target.name,
            e.map(duration).unwrap_or_else(|| "?".into()),
            p.target.dir,
            p.command
        );
    }
    let known: f64 = estimates.iter().flatten().sum::<f64>().max(0.0);
    let unknown = estimates.iter().filter(|e| e.is_none()).count();
    match previous {
        Some(_) if unknown == estimates.len() => eprintln!(
            "estimate: none — the run recorded in {} timed none of these targets",
            Manifest::places(root)
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(" or ")
        ),
        Some(m) => eprintln!(
            "estimate: {}{} — the times of the {} run recorded in {} (on {}), scaled by the work each target does now{}",
            duration(known),
            if unknown > 0 { format!(" + {unknown} targets never timed") } else { String::new() },
            m.mode,
            m.source.display(),
            if sources.is_empty() { "the CPU".to_string() } else { sources.join("; ") },
            if sources.iter().any(|s| *s != adapter) { "; a different adapter, so only a rough guide" } else { "" }
        ),
        None => eprintln!(
            "estimate: none — no earlier `reproduce all` is recorded in {} (the bar shows the work done instead)",
            Manifest::places(root)
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(" or ")
        ),
    }
}
