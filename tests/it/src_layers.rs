//! The command line's house rules (issue 52): `src/main.rs` stands on top (nothing imports its
//! `Cli` or `Command`); the commands of `src/cli/` use the modules they share (`results_io`,
//! `src/rays.rs`) and the libraries below (the papers, the harness), never one another; and a
//! shared module never uses a command. (The paper work, where one command runs another's, is
//! the `gibench-papers` library's, layered by `papers/tests/it/layers.rs`.)

use std::path::{Path, PathBuf};

use gibench_test_support::source::{rust_files, without_comments};

/// The shared modules of `src/cli/`.
const SHARED: &[&str] = &["results_io"];

/// The command modules: every module of `src/cli/` that is not shared.
fn commands(cli: &Path) -> Vec<String> {
    std::fs::read_dir(cli)
        .unwrap()
        .flatten()
        .map(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n.strip_suffix(".rs").unwrap_or(&n).to_string()
        })
        .filter(|n| n != "mod" && !SHARED.contains(&n.as_str()))
        .collect()
}

/// The problems of one file's code (comments removed) under the rules.
fn breaches(rel: &str, code: &str, commands: &[String]) -> Vec<String> {
    let mut out = Vec::new();
    for bad in [
        "crate::Cli",
        "crate::Command",
        "crate::{Cli",
        "crate::{Command",
    ] {
        if code.contains(bad) {
            out.push(format!(
                "{rel}: uses `{bad}` (main.rs's parser: nothing stands above it)"
            ));
        }
    }
    // Every file of src/ but main.rs: a shared module uses no command, a command no other one.
    let own = rel
        .strip_prefix("src/cli/")
        .map(|r| r.split(['/', '.']).next().unwrap_or(r));
    if rel != "src/main.rs" && !rel.starts_with("src/bin/") {
        for c in commands.iter().filter(|c| own != Some(c.as_str())) {
            for path in [format!("crate::cli::{c}"), format!("super::{c}")] {
                let hit = code.match_indices(&path).any(|(i, _)| {
                    let next = code[i + path.len()..].chars().next();
                    !next.is_some_and(|ch| ch.is_alphanumeric() || ch == '_')
                });
                if hit {
                    out.push(format!("{rel}: uses the command `{c}` (`{path}`)"));
                }
            }
        }
    }
    out
}

#[test]
fn shared_modules_never_use_a_command_and_nothing_uses_main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let commands = commands(&root.join("src/cli"));
    assert!(
        commands.iter().any(|c| c == "report") && commands.len() > 5,
        "{commands:?}"
    );
    let files = rust_files(&root.join("src"));
    let mut wrong = Vec::new();
    for f in &files {
        let rel = f
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        let code = without_comments(&std::fs::read_to_string(f).unwrap());
        wrong.extend(breaches(&rel, &code, &commands));
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// The checker finds each kind of breach: a shared module using a command, a command using
/// another, anything using main.rs's parser (the two `src/` circles of issue 52 were of the
/// first and last kinds).
#[test]
fn the_checker_finds_each_breach() {
    let commands = vec!["report".to_string(), "export".to_string()];
    let shared = "use super::report;\nfn f(o: &report::ReportArgs) {}";
    assert_eq!(
        breaches("src/cli/results_io.rs", shared, &commands).len(),
        1
    );
    let other = "use crate::cli::export::ExportResultsArgs;";
    assert_eq!(breaches("src/cli/report.rs", other, &commands).len(), 1);
    let main = "use crate::{Cli, Command};";
    assert_eq!(breaches("src/cli/report.rs", main, &commands).len(), 1);
    assert_eq!(
        breaches("src/rays.rs", "use crate::cli::report;", &commands).len(),
        1
    );
    // A command using its own submodules, a shared module, the papers library: fine.
    let ok = "use super::results_io::results_under;\nuse gibench_papers::files;\nuse crate::cli::report::x;";
    assert!(breaches("src/cli/report.rs", ok, &commands).is_empty());
}
