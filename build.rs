//! Stamps the `gibench` binary with the commit it is built from (`GIBENCH_GIT_COMMIT`), so that
//! a copied binary (a before/after comparison, a GPU slot's bundle) records its own build rather
//! than the checkout it happens to run beside. The look-up is the harness's own
//! (`harness/src/run/commit.rs`), included here rather than written twice.

#[path = "harness/src/run/commit.rs"]
mod commit;

use std::path::Path;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    println!(
        "cargo:rustc-env=GIBENCH_GIT_COMMIT={}",
        commit::describe(root)
    );
    // Stamp again when the commit or any tracked source could change the answer: a commit or a
    // checkout (git's HEAD and index), and an edit anywhere but the build and results folders
    // (which `describe` does not count as a code change).
    let git = root.join(".git");
    if git.is_dir() {
        for file in ["HEAD", "index"] {
            println!("cargo:rerun-if-changed=.git/{file}");
        }
    }
    let entries = std::fs::read_dir(root).expect("the package's folder is readable");
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if !matches!(name.as_str(), ".git" | "target" | "results") {
            println!("cargo:rerun-if-changed={name}");
        }
    }
}
