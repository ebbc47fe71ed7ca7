//! Checks on where a command writes, made before any work: output folders and files that must
//! be writable, `--stem` file names; and a path's file name for messages.

use std::path::Path;

use gibench_harness::{Error, Result};

/// Creates `dir` if needed and checks a file can be written there; the error names `option`.
pub fn writable_dir(option: &str, dir: &Path) -> Result<()> {
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

/// The reference cache's folder `dir`, created where missing and kept, then checked as
/// [`writable_dir`]: processes share it (a fleet's shards, parallel tests), and a check that
/// removed a cache folder it had just made could pull it from under another process's probe
/// (seen: "results/cache is not a writable folder" in the fleet test).
pub fn cache_dir(option: &str, dir: &Path) -> Result<()> {
    let dir = gibench_harness::output::without_cur_dirs(dir);
    std::fs::create_dir_all(&dir).map_err(|e| {
        Error::param(
            option,
            format!("{} is not a writable folder: {e}", dir.display()),
        )
    })?;
    writable_dir(option, &dir)
}

/// Checks `path` can be written as a file: not a folder, in a folder that can be created and
/// written ([`writable_dir`]); the error names `option` and suggests `example` inside a folder.
pub fn writable_file(option: &str, path: &Path, example: &str) -> Result<()> {
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

/// The file name of `p`, for messages and listings (empty if it has none).
pub fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// A `--stem` must be a plain file name (checked before any work).
pub fn check_stem(stem: &str) -> Result<()> {
    if stem.is_empty() || stem.contains(['/', '\\']) || stem.starts_with('.') {
        return Err(Error::param(
            "stem",
            format!("'{stem}' must be a file name without folders, not starting with '.'"),
        ));
    }
    Ok(())
}
