//! Which source a build or a run came from: `git describe --always` of a checkout, with
//! `-dirty` when tracked files outside `results/` differ from that commit (rewriting committed
//! results, as `results/regenerate.sh` does, changes no code); "unknown" without git.
//!
//! Plain `std`, so that the root crate's build script includes this very file
//! (`#[path]`) to stamp the `gibench` binary with the commit it was built from; the harness
//! calls it at run time only where no binary stamped one (tests, benches, examples).

use std::path::Path;
use std::process::Command;

/// The commit of the checkout at `dir`, as the module's header describes.
pub fn describe(dir: &Path) -> String {
    let git = |args: &[&str]| {
        Command::new("git")
            .arg("-C")
            .arg(dir)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    let Some(commit) = git(&["describe", "--always"]).filter(|s| !s.is_empty()) else {
        return "unknown".into();
    };
    let code_changed = git(&[
        "status",
        "--porcelain",
        "--untracked-files=no",
        "--",
        ".",
        ":(exclude)results",
    ])
    .is_some_and(|s| !s.is_empty());
    if code_changed {
        format!("{commit}-dirty")
    } else {
        commit
    }
}
