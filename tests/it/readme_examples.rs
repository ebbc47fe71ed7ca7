//! Every command of the README's *Running* block runs as written, shrunk to a small size: the
//! sizes (frames, resolution, map sizes, samples, rays) are replaced or added, nothing else is
//! changed. The commands run in order in one empty folder, so each finds what the earlier ones
//! wrote (`report results/local` reads the first runs' results); `compare base/ current/` gets
//! two small runs made for it first, and `plot-quality results/keller/lag` the committed folder
//! copied in. A README example that names a removed option, a scene that is gone or a
//! technique that dies on a scene fails here.

use crate::support;

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The commands of the first `sh` block under `## Running`, comments removed, `gibench` first.
fn running_commands(readme: &str) -> Vec<Vec<String>> {
    let section = readme
        .split("\n## Running\n")
        .nth(1)
        .expect("README has a '## Running' section");
    let section = section.split("\n## ").next().unwrap();
    let block = section
        .split("```sh\n")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("'## Running' has an sh block");
    block
        .lines()
        .map(|l| l.split(" #").next().unwrap().trim())
        .filter(|l| !l.is_empty())
        .map(|l| l.split_whitespace().map(String::from).collect::<Vec<_>>())
        .inspect(|words| assert_eq!(words[0], "gibench", "not a gibench command: {words:?}"))
        .collect()
}

/// `words` (a README command without `gibench`) at a small size: each size option present gets
/// the small value; `run` and `sweep` get the size options they lack (and `--quiet`).
fn shrunk(words: &[String]) -> Vec<String> {
    let command = words[0].as_str();
    let small: &[(&str, &str)] = match command {
        "run" | "sweep" => &[
            ("--frames", "2"),
            ("--warmup", "3"),
            ("--resolution", "64x48"),
            ("--shadow-size", "64"),
            ("--spp", "4"),
        ],
        "reference" => &[("--resolution", "64x48"), ("--spp", "4")],
        "export-scene" => &[("--rays", "4096")],
        "raycast" => &[("--repeats", "1")],
        _ => &[],
    };
    let mut out: Vec<String> = words.to_vec();
    for (option, value) in small {
        match out.iter().position(|w| w == option) {
            Some(i) => out[i + 1] = value.to_string(),
            None if matches!(command, "run" | "sweep" | "reference") => {
                out.extend([option.to_string(), value.to_string()])
            }
            None => {}
        }
    }
    if matches!(command, "run" | "sweep") {
        out.push("--quiet".into());
        if out.iter().any(|w| w == "--quality") {
            out.extend(["--quality-pairs".into(), "1".into()]);
        }
    }
    out
}

fn gibench(dir: &Path, args: &[String]) -> std::process::Output {
    support::GIBENCH
        .command()
        .args(args)
        // The scenes are found from the workspace root compiled in, wherever the command runs.
        .current_dir(dir)
        .output()
        .unwrap()
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            copy_dir(&p, &to.join(e.file_name()));
        } else {
            std::fs::copy(&p, to.join(e.file_name())).unwrap();
        }
    }
}

#[test]
fn every_running_example_succeeds_at_a_small_size() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let commands = running_commands(&readme);
    assert!(commands.len() >= 10, "{commands:?}");
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // What the examples take as given: two builds' results (five repeats a side, alternated,
    // as *Comparing two builds* says) and the committed lag results.
    for repeat in 1..=5 {
        for side in ["base", "current"] {
            let out = format!("{side}/r{repeat}");
            let mut args: Vec<String> = [
                "run",
                "--scene",
                "cornell",
                "--technique",
                "direct",
                "--timing",
                "stages",
                "--frames",
                "3",
                "--warmup",
                "3",
                "--resolution",
                "64x48",
                "--shadow-size",
                "64",
                "--no-images",
                "--quiet",
                "--out",
            ]
            .map(String::from)
            .to_vec();
            args.push(out);
            let o = gibench(dir, &args);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        }
    }
    copy_dir(
        &root().join("results/keller/lag"),
        &dir.join("results/keller/lag"),
    );
    let mut failed = Vec::new();
    for words in &commands {
        let args = shrunk(&words[1..]);
        let start = std::time::Instant::now();
        let o = gibench(dir, &args);
        eprintln!(
            "{:.1} s: gibench {}",
            start.elapsed().as_secs_f64(),
            args.join(" ")
        );
        let stderr = String::from_utf8_lossy(&o.stderr);
        if !o.status.success() || stderr.contains("panicked") {
            failed.push(format!(
                "gibench {} (as written: {}):\n{}",
                args.join(" "),
                words.join(" "),
                stderr.lines().rev().take(15).collect::<Vec<_>>().join("\n")
            ));
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n\n"));
}

/// The shrinking replaces sizes and adds missing ones, and leaves every other word as written.
#[test]
fn shrinking_changes_only_sizes() {
    let words: Vec<String> =
        "run --scene sibenik --frames 200 --resolution 1024x768 --shadow-size 1024"
            .split_whitespace()
            .map(String::from)
            .collect();
    let s = shrunk(&words).join(" ");
    assert_eq!(
        s,
        "run --scene sibenik --frames 2 --resolution 64x48 --shadow-size 64 --warmup 3 --spp 4 --quiet"
    );
    let words: Vec<String> = "report results/local --stem mytable"
        .split_whitespace()
        .map(String::from)
        .collect();
    assert_eq!(shrunk(&words), words);
}
