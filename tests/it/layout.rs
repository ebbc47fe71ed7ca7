//! Every crate's integration tests are one binary, `tests/it/`, a module per file, so that
//! Cargo builds and links one test executable per crate: a file under a `tests/it/` folder that
//! no `mod` line names would be silently left out, and a test file beside `tests/it/` (a binary
//! of its own) must say in its header why it needs its own process.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The `tests/` folders of the workspace's crates: the root's, the harness's, each
/// technique's.
fn test_folders() -> Vec<PathBuf> {
    let mut out = vec![
        root().join("tests"),
        root().join("harness/tests"),
        root().join("papers/tests"),
    ];
    for e in std::fs::read_dir(root().join("techniques")).unwrap() {
        let tests = e.unwrap().path().join("tests");
        if tests.is_dir() {
            out.push(tests);
        }
    }
    out
}

/// The `.rs` files and folders directly in `dir`, sorted.
fn entries(dir: &Path) -> (Vec<PathBuf>, Vec<PathBuf>) {
    let mut files = Vec::new();
    let mut dirs = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            dirs.push(p);
        } else if p.extension().is_some_and(|x| x == "rs") {
            files.push(p);
        }
    }
    files.sort();
    dirs.sort();
    (files, dirs)
}

/// Every file and folder of module folder `dir` (whose root is `main.rs` or `mod.rs`) is named
/// by a `mod` line of that root; the same in each subfolder.
fn check_modules(dir: &Path, failures: &mut Vec<String>) {
    let (files, dirs) = entries(dir);
    let root_file = ["main.rs", "mod.rs"]
        .iter()
        .map(|n| dir.join(n))
        .find(|p| p.exists());
    let Some(root_file) = root_file else {
        failures.push(format!("{}: no main.rs or mod.rs", dir.display()));
        return;
    };
    let text = std::fs::read_to_string(&root_file).unwrap();
    let declared = |name: &str| text.lines().any(|l| l.trim() == format!("mod {name};"));
    for f in files.iter().filter(|f| **f != root_file) {
        let name = f.file_stem().unwrap().to_string_lossy();
        if !declared(&name) {
            failures.push(format!(
                "{}: no `mod {name};` in {}",
                f.display(),
                root_file.display()
            ));
        }
    }
    for d in dirs {
        let name = d.file_name().unwrap().to_string_lossy();
        if !declared(&name) {
            failures.push(format!(
                "{}: no `mod {name};` in {}",
                d.display(),
                root_file.display()
            ));
        }
        check_modules(&d, failures);
    }
}

#[test]
fn every_test_file_is_a_module_or_says_why_it_is_apart() {
    let mut failures = Vec::new();
    for tests in test_folders() {
        let it = tests.join("it");
        if !it.is_dir() {
            continue;
        }
        check_modules(&it, &mut failures);
        for f in entries(&tests).0 {
            let header: String = std::fs::read_to_string(&f)
                .unwrap()
                .lines()
                .take_while(|l| l.starts_with("//!"))
                .collect::<Vec<_>>()
                .join(" ");
            if !header.contains("own process") {
                failures.push(format!(
                    "{}: a test binary of its own whose header does not say why it needs its \
                     own process (else make it a module of tests/it/)",
                    f.display()
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
