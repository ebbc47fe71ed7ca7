//! The `gibench` binary as a command, for the root package's tests (the only ones Cargo gives
//! its path, as `env!("CARGO_BIN_EXE_gibench")`: they hand it to [`Gibench::new`]).

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A `gibench` binary, run as a command.
#[derive(Clone, Copy, Debug)]
pub struct Gibench(&'static str);

impl Gibench {
    /// The binary at `path`.
    pub const fn new(path: &'static str) -> Gibench {
        Gibench(path)
    }

    /// The binary as a command to add arguments to.
    pub fn command(&self) -> Command {
        Command::new(self.0)
    }

    /// Runs `gibench ARGS` to the end; its exit status and output.
    pub fn run<S: AsRef<OsStr>>(&self, args: &[S]) -> Output {
        self.command().args(args).output().expect("gibench starts")
    }

    /// Runs `gibench ARGS` and asserts it succeeded (its stderr in the message).
    pub fn run_ok<S: AsRef<OsStr> + std::fmt::Debug>(&self, args: &[S]) -> Output {
        let o = self.run(args);
        assert!(
            o.status.success(),
            "gibench {args:?} failed:\n{}",
            String::from_utf8_lossy(&o.stderr)
        );
        o
    }
}

/// The shared reference image ending in `suffix` (`-reference.png`, `-reference-indirect.png`,
/// `-reference-frames.png`) that the run whose results file is `json` was compared with: the
/// run set writes it once, named after the scene and a key of its contents, and each run's
/// `images` lists it.
pub fn reference_image(json: &Path, suffix: &str) -> PathBuf {
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
