//! `gibench merge`: pools the output folders of several `reproduce all` runs (the shards of a
//! fleet, or machines given different `--only` lists) into one output set with one
//! `reproduce-all.json` / `.md` / `.html`.
//!
//! A target is the unit: its folder's files are copied as they are (its tables were made from
//! its own runs), so the merged tables are the ones each machine wrote. Refused by name before
//! anything is written: folders whose runs differ in mode (quick / paper / test size) or commit,
//! a target run in two folders, two targets claiming one file, a listed file missing, and for
//! shards a count that differs, a shard given twice or missing, or a selection not covered.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use gibench_harness::output::{write_atomic, OutputSet};
use gibench_harness::{Error, Result};

use super::manifest::{Manifest, Record};
use super::targets::{find, TARGETS};
use crate::files::writable_dir;

/// Pools `dirs` (each with a `reproduce-all.json`) into `out`; returns the listing of what it
/// wrote (for the command to print).
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<String> {
    if dirs.is_empty() {
        return Err(Error::param(
            "DIR",
            "expected one or more folders written by `gibench reproduce all`",
        ));
    }
    let manifests: Vec<Manifest> = dirs
        .iter()
        .map(|d| Manifest::read(d))
        .collect::<Result<_>>()?;
    let first = &manifests[0];
    let name = |i: usize| dirs[i].display().to_string();
    // The same settings everywhere.
    for (i, m) in manifests.iter().enumerate().skip(1) {
        for (field, a, b) in [
            ("mode", &first.mode, &m.mode),
            ("git_commit", &first.git_commit, &m.git_commit),
        ] {
            if a != b {
                return Err(Error::Invalid(format!(
                    "merge: {field} differs: '{a}' in {} but '{b}' in {}; expected runs of one mode and commit",
                    name(0),
                    name(i)
                )));
            }
        }
    }
    check_shards(&manifests, dirs)?;
    // Every target once; every file claimed by one target.
    let mut owner: BTreeMap<&str, usize> = BTreeMap::new();
    let mut files: BTreeMap<&str, &str> = BTreeMap::new();
    for (i, m) in manifests.iter().enumerate() {
        for r in m.targets.iter().filter(|r| ran(r)) {
            if let Some(j) = owner.insert(&r.name, i) {
                return Err(Error::Invalid(format!(
                    "merge: target '{}' ran in both {} and {}; expected each target from one folder",
                    r.name,
                    name(j),
                    name(i)
                )));
            }
            for f in &r.files {
                if let Some(other) = files.insert(f, &r.name) {
                    return Err(Error::Invalid(format!(
                        "merge: {f} is a file of both '{other}' and '{}'",
                        r.name
                    )));
                }
                let src = dirs[i].join(f);
                if !src.is_file() {
                    return Err(Error::bad_file(
                        &m.source,
                        format!(
                            "lists {f} for '{}', but {} is missing",
                            r.name,
                            src.display()
                        ),
                    ));
                }
            }
        }
    }
    // Targets left out (or carried) everywhere keep the first such entry.
    let mut records: Vec<Record> = Vec::new();
    for (i, m) in manifests.iter().enumerate() {
        for r in &m.targets {
            if owner.get(r.name.as_str()) == Some(&i) && ran(r) {
                records.push(r.clone());
            }
        }
    }
    for m in &manifests {
        for r in m.targets.iter().filter(|r| r.left_out.is_some()) {
            if !owner.contains_key(r.name.as_str()) && !records.iter().any(|x| x.name == r.name) {
                let mut r = r.clone();
                r.files.clear();
                r.carried_from = None;
                records.push(r);
            }
        }
    }
    let order = |n: &str| TARGETS.iter().position(|t| t.name == n);
    records.sort_by_key(|r| order(&r.name));

    writable_dir("out", out)?;
    let set = OutputSet::begin("out", out)?;
    for r in records.iter().filter(|r| ran(r)) {
        if let Ok(t) = find(&r.name) {
            super::claim_folders(&set, t)?;
        }
        let i = owner[r.name.as_str()];
        for f in &r.files {
            let bytes = std::fs::read(dirs[i].join(f)).map_err(|e| Error::Io {
                path: dirs[i].join(f),
                source: e,
            })?;
            write_atomic(&out.join(f), &bytes)?;
        }
    }
    let join = |f: &dyn Fn(&Manifest) -> &str| {
        let mut v: Vec<&str> = manifests.iter().map(f).filter(|s| !s.is_empty()).collect();
        v.sort();
        v.dedup();
        v.join("; ")
    };
    let estimate: Option<f64> = records
        .iter()
        .filter(|r| ran(r))
        .map(|r| r.estimate_s)
        .sum();
    let mut merged = Manifest::new(
        &first.mode,
        &join(&|m| m.adapter.as_str()),
        None,
        // The fleet's time: its slowest machine's.
        manifests.iter().map(|m| m.seconds).fold(0.0, f64::max),
        estimate,
        records,
        None,
    );
    merged.driver = join(&|m| m.driver.as_str());
    merged.git_commit = first.git_commit.clone();
    merged.cpu_threads = manifests.iter().map(|m| m.cpu_threads).max().unwrap_or(0);
    merged.budget_s = first.budget_s;
    merged.merged_from = dirs.iter().map(|d| d.display().to_string()).collect();
    merged.write(out)?;
    merged.write_index(out)?;
    set.publish()?;
    Ok(merged.listing(out))
}

/// Whether a record is a target this folder's run made (not left out, not carried over).
fn ran(r: &Record) -> bool {
    r.left_out.is_none() && r.carried_from.is_none()
}

/// Shards: all or none of the folders are shards, of one count, each index once, all present,
/// of one selection, and the selection is covered.
fn check_shards(manifests: &[Manifest], dirs: &[PathBuf]) -> Result<()> {
    let sharded: Vec<usize> = (0..manifests.len())
        .filter(|&i| manifests[i].shard.is_some())
        .collect();
    if sharded.is_empty() {
        return Ok(());
    }
    if sharded.len() != manifests.len() {
        let plain = (0..manifests.len())
            .find(|i| !sharded.contains(i))
            .unwrap_or(0);
        return Err(Error::Invalid(format!(
            "merge: {} is a shard ({}) but {} is not; expected the shards of one run",
            dirs[sharded[0]].display(),
            manifests[sharded[0]].shard.as_deref().unwrap_or_default(),
            dirs[plain].display()
        )));
    }
    let parse = |i: usize| -> Result<(usize, usize)> {
        let s = manifests[i].shard.as_deref().unwrap_or_default();
        s.split_once('/')
            .and_then(|(a, b)| Some((a.parse().ok()?, b.parse().ok()?)))
            .ok_or_else(|| Error::bad_file(&manifests[i].source, format!("shard '{s}' is not I/N")))
    };
    let (_, count) = parse(0)?;
    let mut seen: Vec<Option<usize>> = vec![None; count];
    for i in 0..manifests.len() {
        let (k, n) = parse(i)?;
        if n != count || k >= count {
            return Err(Error::Invalid(format!(
                "merge: {} is shard {k}/{n} but {} is of {count} shards; expected one shard count",
                dirs[i].display(),
                dirs[0].display()
            )));
        }
        if let Some(j) = seen[k] {
            return Err(Error::Invalid(format!(
                "merge: {} and {} are both shard {k}/{count}",
                dirs[j].display(),
                dirs[i].display()
            )));
        }
        seen[k] = Some(i);
        if manifests[i].selected != manifests[0].selected {
            return Err(Error::Invalid(format!(
                "merge: {} and {} were split from different selections of targets ({} and {})",
                dirs[0].display(),
                dirs[i].display(),
                manifests[0].selected.join(","),
                manifests[i].selected.join(",")
            )));
        }
    }
    if let Some(k) = seen.iter().position(Option::is_none) {
        return Err(Error::Invalid(format!(
            "merge: shard {k}/{count} is missing; expected all {count} shards' folders"
        )));
    }
    // Every selected target in some shard's manifest (run or left out by a budget).
    for name in &manifests[0].selected {
        if !manifests.iter().any(|m| {
            m.targets
                .iter()
                .any(|r| &r.name == name && r.carried_from.is_none())
        }) {
            return Err(Error::Invalid(format!(
                "merge: target '{name}' was selected but no shard's manifest has it"
            )));
        }
    }
    Ok(())
}
