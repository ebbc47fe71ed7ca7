//! The papers crate's layers (`papers/src/lib.rs`): support, runs, papers, fleet, each module
//! using only its own layer and those below it; and inside `reproduce`, a paper's module never
//! uses the `all` planner or the command-target `job` above it. Fails naming the file and the
//! path (tried: `crate::reproduce` in `run.rs`, `super::all` in `ism2008.rs`).

use std::path::Path;

use gibench_test_support::source::{paths_under, rust_files, without_comments};

/// The top-level modules from the bottom up.
const LAYERS: &[&[&str]] = &[
    &[
        "registry", "options", "params", "files", "page", "progress", "shard",
    ],
    &["run", "sweep", "reference", "equal_time"],
    &["reproduce"],
    &["merge"],
];

/// The paper modules of `reproduce/`, which stand below `reproduce::all` and `reproduce::job`.
const PAPERS: &[&str] = &["laine2007", "gaitatzes2010", "ism2008", "barczak2006"];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

/// The problems of the file `rel` (relative to `papers/src`) whose code is `code`.
fn breaches(rel: &Path, code: &str) -> Vec<String> {
    let first = rel.iter().next().unwrap().to_string_lossy();
    let own = first.strip_suffix(".rs").unwrap_or(&first).to_string();
    if own == "lib" {
        return Vec::new();
    }
    let Some(own_layer) = layer_of(&own) else {
        return vec![format!(
            "{}: `{own}` is in no layer of this test's LAYERS (add it where it belongs)",
            rel.display()
        )];
    };
    let mut out = Vec::new();
    for module in paths_under(code, "crate::") {
        match layer_of(&module) {
            Some(l) if l <= own_layer => {}
            _ => out.push(format!(
                "{}: uses `crate::{module}`, not in a layer at or below `{own}`",
                rel.display()
            )),
        }
    }
    let paper = rel.iter().nth(1).map(|p| p.to_string_lossy().into_owned());
    let paper = paper.as_deref().map(|p| p.strip_suffix(".rs").unwrap_or(p));
    if own == "reproduce" && paper.is_some_and(|p| PAPERS.contains(&p)) {
        for above in ["all", "job"] {
            let uses = paths_under(code, "super::")
                .into_iter()
                .chain(paths_under(code, "crate::reproduce::"))
                .any(|m| m == above);
            if uses {
                out.push(format!(
                    "{}: a paper's module uses `reproduce::{above}`, which stands above it",
                    rel.display()
                ));
            }
        }
    }
    out
}

#[test]
fn every_module_uses_only_its_layer_and_those_below() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let files = rust_files(&root);
    assert!(
        files.len() > 20,
        "only {} files under {}",
        files.len(),
        root.display()
    );
    let wrong: Vec<String> = files
        .iter()
        .flat_map(|f| {
            let code = without_comments(&std::fs::read_to_string(f).unwrap());
            breaches(f.strip_prefix(&root).unwrap(), &code)
        })
        .collect();
    assert!(wrong.is_empty(), "layering broken:\n{}", wrong.join("\n"));
}

/// The rule catches what it is for: a support module reaching up, a run using a paper, a
/// paper's module using the planner (the cases that would close a circle).
#[test]
fn the_rule_names_an_upward_use() {
    let cases = [
        ("progress/overall.rs", "use crate::reproduce::all::Target;"),
        ("run.rs", "use crate::reproduce::ReproduceArgs;"),
        ("ism2008.rs", "use super::all::TARGETS;"),
        ("barczak2006/figures.rs", "use crate::reproduce::job::Job;"),
    ];
    for (file, code) in cases {
        let rel = if file.starts_with("ism") || file.starts_with("barczak") {
            Path::new("reproduce").join(file)
        } else {
            Path::new(file).to_path_buf()
        };
        assert_eq!(breaches(&rel, code).len(), 1, "{file}: {code}");
    }
    assert!(breaches(Path::new("sweep.rs"), "use crate::run::plan;").is_empty());
    assert!(breaches(Path::new("reproduce/all/mod.rs"), "use super::job::Job;").is_empty());
}
