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
//! lists the targets, [`planned`] checks and runs one, [`overall`] is the shared progress bar
//! and [`manifest`] the record of what ran.

mod manifest;
mod overall;
mod planned;
mod targets;

use std::path::{Path, PathBuf};
use std::time::Instant;

use gibench_harness::gpu::GpuContext;
use gibench_harness::output::OutputSet;
use gibench_harness::{Error, Result};

use super::{out_dir, ReproduceArgs};
use crate::cli::files::writable_dir;
use crate::cli::progress::Bars;
use manifest::{duration, Manifest, Record, MANIFEST};
pub use overall::Overall;
use planned::Planned;
pub use targets::{find, Kind, Target, TARGETS};

/// `gibench reproduce TARGET` (one target) or `gibench reproduce all`.
pub fn reproduce(args: &ReproduceArgs) -> Result<()> {
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
    // Every target is checked before any runs.
    eprintln!("gibench reproduce all: checking {} targets", selected.len());
    let planned: Vec<Planned> = selected
        .iter()
        .map(|t| Planned::new(t, args, root.join(t.dir)))
        .collect::<Result<_>>()?;
    let mode = if args.quick { "quick" } else { "paper" };
    let gpu = if planned.iter().any(Planned::needs_gpu) {
        Some(super::open_gpu(args)?)
    } else {
        None
    };
    let adapter = gpu
        .as_ref()
        .map(|g| format!("{} ({})", g.info.adapter, g.info.backend))
        .unwrap_or_else(|| "CPU only".into());
    let previous = Manifest::previous(&root);
    let (estimates, sources) = estimates(&planned, previous.as_ref());
    let sources: Vec<&str> = sources.iter().map(String::as_str).collect();
    print_plan(
        &planned,
        &estimates,
        previous.as_ref(),
        &sources,
        mode,
        &adapter,
        &root,
    );
    if args.list {
        return Ok(());
    }
    writable_dir("out", &root)?;
    let set = OutputSet::begin("out", &root)?;
    claim_folders(&set, &planned)?;
    let (records, seconds) = run_targets(
        &planned,
        &estimates,
        gpu.as_ref(),
        &adapter,
        &set,
        args.quiet,
    )?;
    let estimate: Option<f64> = estimates.iter().copied().sum();
    let manifest = Manifest::new(
        mode,
        &adapter,
        gpu.as_ref(),
        seconds,
        estimate,
        records,
        // Entries are carried over only from this folder's own manifest: one found elsewhere
        // (the committed results/) only gives estimates; its files are not here.
        previous
            .as_ref()
            .filter(|p| p.source == root.join(format!("{MANIFEST}.json"))),
    );
    let manifest = manifest.dated_by_their_files(&root);
    manifest.write(&root)?;
    manifest.write_index(&root)?;
    set.publish()?;
    println!("{}", manifest.listing(&root));
    Ok(())
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
fn estimates(planned: &[Planned], previous: Option<&Manifest>) -> (Vec<Option<f64>>, Vec<String>) {
    let measured: Vec<Option<(f64, String)>> = planned
        .iter()
        .map(|p| previous.and_then(|m| m.estimate(p.target.name, p.work.units)))
        .collect();
    let estimates: Vec<Option<f64>> = measured.iter().map(|m| m.as_ref().map(|e| e.0)).collect();
    let mut sources: Vec<String> = measured
        .iter()
        .zip(planned)
        .filter(|(_, p)| p.needs_gpu())
        .filter_map(|(m, _)| m.as_ref().map(|e| e.1.clone()))
        .collect();
    sources.sort();
    sources.dedup();
    (estimates, sources)
}

/// Claims for the output set the folders the targets own entirely: a command target's folder,
/// a paper target's owned subfolders (files there that the run does not write are removed).
fn claim_folders(set: &OutputSet, planned: &[Planned]) -> Result<()> {
    for p in planned {
        if matches!(p.target.kind, Kind::Command { .. }) {
            set.replace(Path::new(p.target.dir))?;
        }
        if let Kind::Paper(m) = p.target.kind {
            for sub in (m.owned_folders)(p.target.name) {
                set.replace(&Path::new(p.target.dir).join(sub))?;
            }
        }
    }
    Ok(())
}

/// Runs the planned targets one after another under one bar; returns each one's record (its
/// files: what it staged in `set`) and the seconds they took together.
fn run_targets(
    planned: &[Planned],
    estimates: &[Option<f64>],
    gpu: Option<&GpuContext>,
    adapter: &str,
    set: &OutputSet,
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
    let overall = Overall::new(quiet, spans.iter().sum());
    let started = Instant::now();
    let mut records = Vec::new();
    let mut before = set.staged().len();
    for (i, p) in planned.iter().enumerate() {
        overall.start(
            &format!("{}/{} {}", i + 1, planned.len(), p.target.name),
            spans[i],
            p.work.frames,
        );
        let t = Instant::now();
        let done = p.run(gpu, &Bars::Shared(&overall))?;
        let seconds = t.elapsed().as_secs_f64();
        let staged = set.staged();
        let files: Vec<PathBuf> = staged[before..].to_vec();
        before = staged.len();
        overall.note(&format!(
            "{} done in {}: {done}",
            p.target.name,
            duration(seconds)
        ));
        records.push(Record {
            name: p.target.name.to_string(),
            dir: p.target.dir.to_string(),
            what: p.target.description(),
            command: p.command.clone(),
            frames: p.work.frames,
            units: p.work.units,
            estimate_s: estimates[i],
            seconds: Some(seconds),
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
        });
    }
    overall.finish();
    Ok((records, started.elapsed().as_secs_f64()))
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
