//! What the root tests share: the `gibench` binary they were built with, run as a command.
//! Each test file takes it with `mod support;` and uses what it needs.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::process::{Command, Output};

/// The `gibench` binary of this build, as a command to add arguments to.
pub fn gibench() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gibench"))
}

/// Runs `gibench ARGS` to the end; its exit status and output.
pub fn run<S: AsRef<OsStr>>(args: &[S]) -> Output {
    gibench().args(args).output().expect("gibench starts")
}

/// Runs `gibench ARGS` and asserts it succeeded (its stderr in the message).
pub fn run_ok<S: AsRef<OsStr> + std::fmt::Debug>(args: &[S]) -> Output {
    let o = run(args);
    assert!(
        o.status.success(),
        "gibench {args:?} failed:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// The shared reference image ending in `suffix` (`-reference.png`, `-reference-indirect.png`,
/// `-reference-frames.png`) that the run whose results file is `json` was compared with: the
/// run set writes it once, named after the scene and a key of its contents, and each run's
/// `images` lists it.
pub fn reference_image(json: &std::path::Path, suffix: &str) -> std::path::PathBuf {
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(json).unwrap()).unwrap();
    let stem = json.file_stem().unwrap().to_string_lossy().into_owned();
    let name = v["images"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|i| i.as_str())
        .find(|i| i.ends_with(suffix) && !i.starts_with(&stem))
        .unwrap_or_else(|| panic!("{}: no shared image '*{suffix}' in images", json.display()));
    json.with_file_name(name)
}
