//! Reading the repository's own Rust sources, for the tests that check its house rules (the
//! harness's layers, the technique crates' and `src/`'s imports).

use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`, recursively, in no particular order.
pub fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    walk(dir, &mut out);
    out
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            walk(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// `code` without `//` comments (doc links may point anywhere; only code is a dependency). A
/// `//` after a `"` on its line is kept, as it may be inside a string.
pub fn without_comments(code: &str) -> String {
    code.lines()
        .map(|l| match l.find("//") {
            Some(i) if !l[..i].contains('"') => &l[..i],
            _ => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}
