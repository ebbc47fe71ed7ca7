//! `gibench merge DIR… --out DIR`: one output set from the folders of many machines (the
//! shards of a Slurm array, Kubernetes Indexed Job or Buildkite parallel step). What the
//! folders hold decides: `reproduce all` folders (a `reproduce-all.json` each) are pooled by
//! [`crate::reproduce::all::merge`]; the shards of one `gibench run` or `gibench sweep`
//! (a [`ShardRecord`] each) are pooled here: every results file (and its images) copied, and
//! the run's or sweep's tables and plots drawn again from the pooled results by the code
//! `run` and `sweep` write them with. A mix is refused, naming the folders.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use clap::Args;
use gibench_harness::measure::results::RunResult;
use gibench_harness::output::{write_atomic, OutputSet};
use gibench_harness::{Error, Result};

use crate::files::writable_dir;
use crate::page::{page_line, with_folder, write_page};
use crate::shard::{ShardRecord, RECORD};

#[derive(Args)]
pub struct MergeArgs {
    /// The folders to pool: each written by `gibench reproduce all`, or each a shard of one
    /// `gibench run` / `gibench sweep` (e.g. one per shard).
    #[arg(required = true, value_name = "DIR")]
    pub dirs: Vec<PathBuf>,
    /// The folder the pooled files and the combined tables go to.
    #[arg(long)]
    pub out: PathBuf,
}

pub fn exec(args: &MergeArgs) -> Result<()> {
    let manifest = |d: &PathBuf| d.join("reproduce-all.json").is_file();
    let record = |d: &PathBuf| d.join(RECORD).is_file();
    if args.dirs.iter().all(manifest) {
        let listing = crate::reproduce::all::merge(&args.dirs, &args.out)?;
        println!("{listing}");
        return Ok(());
    }
    if !args.dirs.is_empty() && args.dirs.iter().all(record) {
        return merge_shards(&args.dirs, &args.out);
    }
    let what = |d: &PathBuf| {
        if manifest(d) {
            "a `reproduce all` folder"
        } else if record(d) {
            "a `run`/`sweep` shard"
        } else {
            "neither (no reproduce-all.json, no gibench-shard.json)"
        }
    };
    let list: Vec<String> = (args.dirs.iter())
        .map(|d| format!("{} is {}", d.display(), what(d)))
        .collect();
    Err(Error::param(
        "DIR",
        format!(
            "expected the folders of `reproduce all` runs, or the shards of one `run` / `sweep`, all of one kind: {}",
            list.join("; ")
        ),
    ))
}

/// Refuses shards of different commands, settings or selections, naming the folders.
fn check_one_run(dirs: &[PathBuf], records: &[ShardRecord]) -> Result<()> {
    let name = |i: usize| dirs[i].display().to_string();
    let first = &records[0];
    // One command, one selection, the same settings everywhere.
    for (i, r) in records.iter().enumerate().skip(1) {
        if r.command != first.command {
            return Err(Error::Invalid(format!(
                "merge: {} is a shard of `{}` but {} of `{}`; expected shards of one command",
                name(0),
                first.command,
                name(i),
                r.command
            )));
        }
        let keys: std::collections::BTreeSet<&String> =
            first.settings.keys().chain(r.settings.keys()).collect();
        for k in keys {
            let (a, b) = (first.settings.get(k), r.settings.get(k));
            if a != b {
                return Err(Error::Invalid(format!(
                    "merge: {k} differs: '{}' in {} but '{}' in {}; expected shards of one run",
                    a.map_or("(none)", |s| s.as_str()),
                    name(0),
                    b.map_or("(none)", |s| s.as_str()),
                    name(i)
                )));
            }
        }
        if r.units != first.units {
            return Err(Error::Invalid(format!(
                "merge: {} and {} were split from different selections ({} and {})",
                name(0),
                name(i),
                first.units.join(","),
                r.units.join(",")
            )));
        }
    }
    Ok(())
}

/// The shard count: one for all, each index once, none missing (else an error naming them).
fn check_shard_set(dirs: &[PathBuf], records: &[ShardRecord]) -> Result<usize> {
    let name = |i: usize| dirs[i].display().to_string();
    // One shard count, each index once, all present.
    let parse = |i: usize| -> Result<(usize, usize)> {
        let s = &records[i].shard;
        s.split_once('/')
            .and_then(|(a, b)| Some((a.parse().ok()?, b.parse().ok()?)))
            .ok_or_else(|| Error::bad_file(dirs[i].join(RECORD), format!("shard '{s}' is not I/N")))
    };
    let (_, count) = parse(0)?;
    let mut seen: Vec<Option<usize>> = vec![None; count];
    for i in 0..records.len() {
        let (k, n) = parse(i)?;
        if n != count || k >= count {
            return Err(Error::Invalid(format!(
                "merge: {} is shard {k}/{n} but {} is of {count} shards; expected one shard count",
                name(i),
                name(0)
            )));
        }
        if let Some(j) = seen[k] {
            return Err(Error::Invalid(format!(
                "merge: {} and {} are both shard {k}/{count}",
                name(j),
                name(i)
            )));
        }
        seen[k] = Some(i);
    }
    if let Some(k) = seen.iter().position(Option::is_none) {
        return Err(Error::Invalid(format!(
            "merge: shard {k}/{count} is missing; expected all {count} shards' folders"
        )));
    }
    Ok(count)
}

/// Which shard ran each unit, and its results file (or "skipped: …"): every unit of the
/// selection from exactly one shard, else an error naming them.
fn unit_owners<'a>(
    dirs: &[PathBuf],
    records: &'a [ShardRecord],
) -> Result<BTreeMap<&'a str, (usize, &'a str)>> {
    let name = |i: usize| dirs[i].display().to_string();
    let first = &records[0];
    // Every unit from exactly one shard.
    let mut owner: BTreeMap<&str, (usize, &str)> = BTreeMap::new();
    for (i, r) in records.iter().enumerate() {
        for (unit, file) in &r.ran {
            if !first.units.contains(unit) {
                return Err(Error::bad_file(
                    dirs[i].join(RECORD),
                    format!("ran '{unit}', which is not one of the selection's units"),
                ));
            }
            if let Some((j, _)) = owner.insert(unit, (i, file)) {
                return Err(Error::Invalid(format!(
                    "merge: '{unit}' ran in both {} and {}; expected each unit from one shard",
                    name(j),
                    name(i)
                )));
            }
        }
    }
    if let Some(unit) = first.units.iter().find(|u| !owner.contains_key(u.as_str())) {
        return Err(Error::Invalid(format!(
            "merge: '{unit}' was selected but no shard ran it; expected every unit in some shard"
        )));
    }
    Ok(owner)
}

/// Pools the shard folders `dirs` of one `run` or `sweep` into `out`.
fn merge_shards(dirs: &[PathBuf], out: &Path) -> Result<()> {
    let records: Vec<ShardRecord> = dirs
        .iter()
        .map(|d| ShardRecord::read(d))
        .collect::<Result<_>>()?;
    check_one_run(dirs, &records)?;
    let count = check_shard_set(dirs, &records)?;
    let owner = unit_owners(dirs, &records)?;
    let first = &records[0];
    // Read every result (in the selection's order) before anything is written. A run's unit
    // is `SCENE-TECHNIQUE`; its scene is the one of the run's scenes it starts with whose
    // remainder is a technique.
    let setting = |k: &str| first.settings.get(k).cloned().unwrap_or_default();
    let scenes: Vec<String> = setting("scene").split(',').map(String::from).collect();
    let split_unit = |unit: &str| -> (String, String) {
        for sc in &scenes {
            if let Some(t) = unit.strip_prefix(&format!("{sc}-")) {
                if crate::registry::all().iter().any(|i| i.name == t) {
                    return (sc.clone(), t.to_string());
                }
            }
        }
        (scenes[0].clone(), unit.to_string())
    };
    let mut results: Vec<(String, RunResult, Vec<PathBuf>)> = Vec::new();
    let mut skipped: Vec<(String, String, String)> = Vec::new();
    for unit in &first.units {
        let (i, file) = owner[unit.as_str()];
        if let Some(reason) = file.strip_prefix("skipped: ") {
            let (scene, technique) = split_unit(unit);
            skipped.push((scene, technique, reason.to_string()));
            continue;
        }
        let path = dirs[i].join(file);
        let r = RunResult::read(&path)?;
        let mut files = vec![path];
        for image in &r.images {
            let p = dirs[i].join(image);
            if !p.is_file() {
                return Err(Error::bad_file(
                    dirs[i].join(file),
                    format!("lists the image {image}, but {} is missing", p.display()),
                ));
            }
            files.push(p);
        }
        results.push((unit.clone(), r, files));
    }
    writable_dir("out", out)?;
    let set = OutputSet::begin("out", out)?;
    let mut stale = Vec::new();
    if first.command == "sweep" {
        let stem = crate::sweep::summary_stem(&scenes[0], &setting("technique"), &setting("sweep"));
        stale.extend(crate::sweep::replace_sweep_files(&set, out, &stem)?);
    } else {
        for scene in &scenes {
            stale.extend(crate::run::replace_scene_files(&set, out, scene, false)?);
        }
    }
    for (_, _, files) in &results {
        for f in files {
            let bytes = std::fs::read(f).map_err(|e| Error::Io {
                path: f.clone(),
                source: e,
            })?;
            let to = out.join(f.file_name().unwrap_or_default());
            write_atomic(&to, &bytes)?;
        }
    }
    let quality = setting("quality") == "true";
    // The shards wrote their own pages with `--html`: the merged set gets its own, of every run.
    let html = setting("html") == "true";
    let mut pages: Vec<PathBuf> = Vec::new();
    let written = if first.command == "sweep" {
        let points: Vec<(String, RunResult)> =
            results.into_iter().map(|(u, r, _)| (u, r)).collect();
        let (table, figures, stem) = crate::sweep::write_summary(
            &points,
            &setting("technique"),
            &scenes[0],
            &setting("sweep"),
            out,
            quality,
            None,
        )?;
        println!("{}", table.to_terminal());
        if html {
            let page = out.join(format!("{stem}.html"));
            let runs = points.iter().map(|(_, r)| r.clone()).collect();
            write_page(
                &page,
                table.title.clone(),
                vec![table],
                figures,
                with_folder(out, runs),
            )?;
            pages.push(page);
        }
        format!("{} points and {stem}.md/.csv/.tex/.svg", points.len())
    } else {
        // One summary per scene, as `run` writes them.
        let mut all: Vec<String> = Vec::new();
        for scene in &scenes {
            let runs: Vec<RunResult> = (results.iter())
                .filter(|(u, _, _)| &split_unit(u).0 == scene)
                .map(|(_, r, _)| r.clone())
                .collect();
            let notes: Vec<(String, String)> = (skipped.iter())
                .filter(|s| &s.0 == scene)
                .map(|s| (s.1.clone(), s.2.clone()))
                .collect();
            if runs.is_empty() {
                continue;
            }
            let (tables, files) =
                crate::run::write_summary(&runs, &notes, out, scene, quality, None)?;
            for t in &tables {
                println!("{}", t.to_terminal());
            }
            if html {
                let page = out.join(format!("{scene}-report.html"));
                let figures = (files.iter())
                    .filter(|f| f.ends_with(".svg"))
                    .map(|f| out.join(f))
                    .collect();
                let title = format!("gibench run on {scene} (merged from {count} shards)");
                write_page(&page, title, tables, figures, with_folder(out, runs))?;
                pages.push(page);
            }
            all.extend(files);
        }
        format!("{} results and {}", results.len(), all.join(", "))
    };
    set.publish()?;
    let page_lines: String = pages.iter().map(|p| page_line(p)).collect();
    eprintln!(
        "merged {count} shards of `{}`: wrote {written} to {}{page_lines}",
        first.command,
        out.display()
    );
    if let Some(note) = crate::run::removed_note(&stale) {
        eprintln!("{note}");
    }
    Ok(())
}
