//! The command line's house rules (issue 52): `src/main.rs` stands on top (nothing imports its
//! `Cli` or `Command`), and the modules of `src/cli/` that commands share (options, params,
//! files, results_io, progress, page, shard) and the crate's own shared files (registry, rays)
//! never use a command's module. A command may use shared modules and, where it runs another
//! command's work (`reproduce` running a run or a sweep), that command's.

use std::path::{Path, PathBuf};

use gibench_test_support::source::{rust_files, without_comments};

/// The shared modules of `src/cli/`.
const SHARED: &[&str] = &[
    "options",
    "params",
    "files",
    "results_io",
    "progress",
    "page",
    "shard",
];

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
    let shared = rel.starts_with("src/cli/")
        && SHARED
            .iter()
            .any(|s| rel == format!("src/cli/{s}.rs") || rel.starts_with(&format!("src/cli/{s}/")))
        || rel == "src/registry.rs"
        || rel == "src/rays.rs";
    if shared {
        for c in commands {
            for path in [format!("crate::cli::{c}"), format!("super::{c}")] {
                let hit = code.match_indices(&path).any(|(i, _)| {
                    let next = code[i + path.len()..].chars().next();
                    !next.is_some_and(|ch| ch.is_alphanumeric() || ch == '_')
                });
                if hit {
                    out.push(format!(
                        "{rel}: a shared module uses the command `{c}` (`{path}`)"
                    ));
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
        commands.iter().any(|c| c == "reproduce") && commands.len() > 10,
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

/// The checker finds each kind of breach (what the two `src/` circles of issue 52 were).
#[test]
fn the_checker_finds_both_breaches() {
    let commands = vec!["reproduce".to_string(), "run".to_string()];
    let progress = "use super::reproduce;\nfn f(o: &reproduce::all::Overall) {}";
    assert_eq!(
        breaches("src/cli/progress/mod.rs", progress, &commands).len(),
        1
    );
    let job = "use crate::{Cli, Command};";
    assert_eq!(
        breaches("src/cli/reproduce/job.rs", job, &commands).len(),
        1
    );
    // A command using another command's work, and a shared module using a shared one: fine.
    let ok = "use crate::cli::run::plan;\nuse super::progress::Bars;\nuse super::runner;";
    assert!(breaches("src/cli/reproduce/job.rs", ok, &commands).is_empty());
    assert!(breaches(
        "src/cli/options.rs",
        "use super::params;\nuse super::running;",
        &commands
    )
    .is_empty());
}
