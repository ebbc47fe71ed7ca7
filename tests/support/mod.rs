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
