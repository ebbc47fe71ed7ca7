//! Stamps the `gibench` binary with the commit it is built from (`GIBENCH_GIT_COMMIT`), so that
//! a copied binary (a before/after comparison, a GPU slot's bundle) records its own build rather
//! than the checkout it happens to run beside. The look-up is the harness's own
//! (`harness/src/run/commit.rs`), included here rather than written twice.

#[path = "harness/src/run/commit.rs"]
mod commit;

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    println!(
        "cargo:rustc-env=GIBENCH_GIT_COMMIT={}",
        commit::describe(root)
    );
    let git = |args: &[&str]| {
        Command::new("git")
            .arg("-C")
            .arg(root)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).into_owned())
    };
    // Stamp again when the commit could change: HEAD's log records every move of HEAD (a
    // commit, an amend, a reset, a checkout), the index every staging; found through git so
    // that a worktree (where `.git` is a file) watches its own. A path that does not exist is
    // left out (cargo would rerun the script on every build).
    for file in ["logs/HEAD", "HEAD", "index"] {
        if let Some(path) = git(&["rev-parse", "--git-path", file]) {
            // Relative to `root` (git's answer for `-C root`), or absolute (a worktree's).
            let path = root.join(path.trim());
            if path.exists() {
                println!("cargo:rerun-if-changed={}", path.display());
            }
        }
    }
    // And when a tracked file changes outside the build and results folders (which `describe`
    // does not count as a code change): the top-level entries git tracks.
    let Some(tracked) = git(&["ls-files"]) else {
        return;
    };
    let top: BTreeSet<&str> = tracked
        .lines()
        .filter_map(|path| path.split('/').next())
        .filter(|name| !matches!(*name, "results" | "target"))
        .collect();
    for name in top {
        println!("cargo:rerun-if-changed={name}");
    }
}
