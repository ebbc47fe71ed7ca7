//! The harness's folders form layers: each uses only the folders below it (the order in
//! `harness/src/lib.rs`'s docs and in docs/architecture.md). This test reads every source file
//! under `harness/src` and fails when a file names a folder above its own through a `crate::`
//! path, which is how an import circle between folders would start (for example the results
//! model in `measure/` reaching up into `report/`).

use std::path::Path;

use gibench_test_support::source::{paths_under, rust_files, without_comments};

/// The folders from the bottom up; `error`, `interrupt`, `output` and `rng` are the files every layer may use.
const LAYERS: &[&[&str]] = &[
    &["error", "interrupt", "output", "rng"],
    &["measure"],
    &["scene"],
    &["cpu"],
    &["gpu"],
    &["kit"],
    &["run"],
    &["report"],
];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

/// The first path segment of every `crate::` path in `code` (comments already removed),
/// including each item of a `crate::{a::X, b}` group.
fn crate_modules(code: &str) -> Vec<String> {
    paths_under(code, "crate::")
}

#[test]
fn every_folder_uses_only_the_folders_below_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let files = rust_files(&root);
    let mut wrong = Vec::new();
    let mut checked = 0;
    for file in &files {
        let rel = file.strip_prefix(&root).unwrap();
        let first = rel.iter().next().unwrap().to_string_lossy();
        let own = first.strip_suffix(".rs").unwrap_or(&first).to_string();
        if own == "lib" {
            continue;
        }
        let Some(own_layer) = layer_of(&own) else {
            wrong.push(format!(
                "{}: `{own}` is in no layer of this test's LAYERS (add it where it belongs)",
                rel.display()
            ));
            continue;
        };
        checked += 1;
        let code = without_comments(&std::fs::read_to_string(file).unwrap());
        for module in crate_modules(&code) {
            // `crate::Error` / `crate::Result` are lib.rs's re-exports of `error`.
            let module = match module.as_str() {
                "Error" | "Result" => "error".to_string(),
                _ => module,
            };
            match layer_of(&module) {
                Some(l) if l <= own_layer => {}
                Some(_) => wrong.push(format!(
                    "{}: uses `crate::{module}`, a layer above its own `{own}`",
                    rel.display()
                )),
                None => wrong.push(format!(
                    "{}: uses `crate::{module}`, which is in no layer",
                    rel.display()
                )),
            }
        }
    }
    assert!(
        checked > 50,
        "only {checked} source files found under {}",
        root.display()
    );
    assert!(wrong.is_empty(), "layering broken:\n{}", wrong.join("\n"));
}

/// The technique crates build on the kit: they use the harness's `kit` folder and the layers
/// below it, never the frame loop (`run`) or the reports (`report`) above it, so that a
/// technique is a plug-in of the kit and not of one way of running it. Fails naming the file
/// and the path (tried: `gibench_harness::run::quality::IndirectComponent` in keller).
#[test]
fn technique_crates_use_only_the_kit_and_below() {
    let techniques = Path::new(env!("CARGO_MANIFEST_DIR")).join("../techniques");
    let kit = layer_of("kit").unwrap();
    let mut wrong = Vec::new();
    let mut checked = 0;
    for entry in std::fs::read_dir(&techniques).unwrap() {
        let src = entry.unwrap().path().join("src");
        // The test-support crate is no technique (it runs the frame loop for tests).
        if !src.is_dir() || src.parent().unwrap().ends_with("support") {
            continue;
        }
        let files = rust_files(&src);
        for file in &files {
            checked += 1;
            let code = without_comments(&std::fs::read_to_string(file).unwrap());
            for module in paths_under(&code, "gibench_harness::") {
                let layer = match module.as_str() {
                    "Error" | "Result" => Some(0),
                    // Re-exported crates, not layers.
                    "glam" | "wgpu" => continue,
                    m => layer_of(m),
                };
                if layer.is_none_or(|l| l > kit) {
                    wrong.push(format!(
                        "{}: uses `gibench_harness::{module}`, above the kit",
                        file.strip_prefix(&techniques).unwrap().display()
                    ));
                }
            }
        }
    }
    assert!(checked > 30, "only {checked} technique sources found");
    assert!(wrong.is_empty(), "layering broken:\n{}", wrong.join("\n"));
}
