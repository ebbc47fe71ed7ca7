//! Reading results files: the files and folders `report` and `plot-quality` are given, and the
//! folders of runs `compare` searches recursively (passing over other JSON files, naming the
//! damaged ones).

use std::path::{Path, PathBuf};

use gibench_harness::measure::results::RunResult;
use gibench_harness::{Error, Result};

/// The results files given (or found in the given folders), without their folders.
pub(crate) fn read_results(inputs: &[PathBuf]) -> Result<Vec<RunResult>> {
    Ok(read_results_with_folders(inputs)?
        .into_iter()
        .map(|(_, r)| r)
        .collect())
}

/// The results files given (or found in the given folders: JSON files that are not results are
/// passed over there), each with its folder.
pub(crate) fn read_results_with_folders(inputs: &[PathBuf]) -> Result<Vec<(PathBuf, RunResult)>> {
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
pub(crate) fn shown_list(paths: &[PathBuf]) -> String {
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

/// Every results file under `dir`, recursively, with its path. JSON files that are not results
/// (no `schema_version` and `technique`) are passed over; a results file that cannot be read
/// (truncated, newer schema, invalid values) is named on standard error, and is an error when
/// its scene and technique are in no file read from `dir` (the side would lose that run).
pub(crate) fn results_under(option: &str, dir: &Path) -> Result<Vec<(PathBuf, RunResult)>> {
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
