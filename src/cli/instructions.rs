//! `gibench instructions`: the CPU kernels' instruction counts under callgrind (the valgrind
//! gate), written as a baseline or compared with one.

use std::path::{Path, PathBuf};

use clap::Args;
use gibench_harness::report;
use gibench_harness::{Error, Result};

#[derive(Args)]
pub(crate) struct InstructionsArgs {
    /// The baseline counts (JSON).
    #[arg(long, default_value = "results/baseline/instructions.json")]
    baseline: PathBuf,
    /// Write the counts as the new baseline instead of comparing.
    #[arg(long)]
    write: bool,
    /// Relative increase counted as a regression.
    #[arg(long, default_value_t = 0.02)]
    threshold: f64,
    /// Only these kernels, comma-separated (default: all; `gibench-kernels list`).
    #[arg(long, value_delimiter = ',')]
    kernels: Vec<String>,
}

/// The first line `program --version` prints, if it runs.
fn tool_version(program: &str) -> Option<String> {
    let o = std::process::Command::new(program)
        .arg("--version")
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    o.status
        .success()
        .then(|| text.lines().next().unwrap_or("").trim().to_string())
}

/// Instructions callgrind counts inside `gibench_kernel_body` for one kernel.
fn count_instructions(kernels: &Path, name: &str) -> Result<u64> {
    let o = std::process::Command::new("valgrind")
        .args([
            "--tool=callgrind",
            "--toggle-collect=gibench_kernel_body",
            "--callgrind-out-file=/dev/null",
        ])
        .arg(kernels)
        .args(["run", name])
        .output()
        .map_err(|e| Error::Invalid(format!("could not run valgrind: {e}")))?;
    let stderr = String::from_utf8_lossy(&o.stderr);
    if !o.status.success() {
        return Err(Error::Invalid(format!(
            "valgrind on kernel '{name}' failed: {stderr}"
        )));
    }
    stderr
        .lines()
        .find_map(|l| l.split("Collected :").nth(1))
        .and_then(|n| n.trim().parse().ok())
        .ok_or_else(|| Error::Invalid(format!("no instruction count for '{name}' in: {stderr}")))
}

/// `gibench instructions`: counts every selected kernel and writes or checks the baseline.
pub(crate) fn exec(args: &InstructionsArgs) -> Result<()> {
    if !(args.threshold.is_finite() && args.threshold >= 0.0) {
        return Err(Error::param("threshold", "must be a number >= 0"));
    }
    let valgrind = tool_version("valgrind").ok_or_else(|| {
        Error::Invalid(
            "valgrind was not found; install it (Debian: apt-get install valgrind)".into(),
        )
    })?;
    let kernels = kernels_binary()?;
    let names = kernel_names(&kernels, &args.kernels)?;
    let rustc = tool_version("rustc").unwrap_or_default();
    let baseline = if args.write {
        None
    } else {
        Some(read_baseline(&args.baseline)?)
    };
    let mut counts = serde_json::Map::new();
    let mut rows = Vec::new();
    let mut regressions = Vec::new();
    for name in &names {
        let n = count_instructions(&kernels, name)?;
        counts.insert(name.clone(), serde_json::json!(n));
        if let Some(b) = &baseline {
            rows.push(compare_row(name, n, b, args.threshold, &mut regressions));
        }
    }
    if args.write {
        return write_baseline(args, &valgrind, &rustc, counts, names.len());
    }
    let b = baseline.expect("compared");
    let same_tools = b["valgrind"].as_str() == Some(valgrind.as_str())
        && b["rustc"].as_str() == Some(rustc.as_str());
    let table = report::Table {
        title: format!(
            "Instructions per kernel (callgrind), against {}",
            args.baseline.display()
        ),
        columns: ["kernel", "baseline", "now", "ratio", "verdict"]
            .map(String::from)
            .to_vec(),
        rows,
        notes: vec![format!(
            "Instructions collected inside gibench_kernel_body (gibench-kernels run NAME) under {valgrind}; \
             a regression is a count more than {:.1} % above the baseline's.",
            args.threshold * 100.0
        )],
    };
    println!("{}", table.to_terminal());
    if regressions.is_empty() {
        return Ok(());
    }
    if !same_tools {
        eprintln!(
            "warning: instruction counts above the baseline ({}), but the baseline was made with {} and {}, this run with {valgrind} and {rustc}: regenerate it (gibench instructions --write) rather than trust the comparison",
            regressions.join(", "),
            b["valgrind"].as_str().unwrap_or("?"),
            b["rustc"].as_str().unwrap_or("?")
        );
        return Ok(());
    }
    Err(Error::Invalid(format!(
        "instruction-count regression beyond {:.1} %: {}",
        args.threshold * 100.0,
        regressions.join(", ")
    )))
}

/// The `gibench-kernels` executable beside this one.
fn kernels_binary() -> Result<PathBuf> {
    let kernels = std::env::current_exe()
        .map_err(|e| Error::Invalid(e.to_string()))?
        .with_file_name("gibench-kernels");
    if !kernels.is_file() {
        return Err(Error::Invalid(format!(
            "{} not found beside gibench; build it with `cargo build --release --bins`",
            kernels.display()
        )));
    }
    Ok(kernels)
}

/// The kernels to count: `chosen` (each checked against `gibench-kernels list`), or all.
fn kernel_names(kernels: &Path, chosen: &[String]) -> Result<Vec<String>> {
    let listed = std::process::Command::new(kernels)
        .arg("list")
        .output()
        .map_err(|e| Error::io(kernels, e))?;
    let all: Vec<String> = String::from_utf8_lossy(&listed.stdout)
        .lines()
        .map(str::to_string)
        .collect();
    if chosen.is_empty() {
        return Ok(all);
    }
    for k in chosen {
        if !all.contains(k) {
            return Err(Error::param(
                "kernels",
                format!("unknown kernel '{k}'; known: {}", all.join(", ")),
            ));
        }
    }
    Ok(chosen.to_vec())
}

/// The baseline file's JSON.
fn read_baseline(path: &Path) -> Result<serde_json::Value> {
    let bytes = gibench_harness::error::read_bounded(path, 1 << 20)?;
    serde_json::from_slice(&bytes)
        .map_err(|e| Error::bad_file(path, format!("not an instruction baseline: {e}")))
}

/// The table row of kernel `name` counted `n` against the baseline `b`; a regression beyond
/// `threshold` is also added to `regressions`.
fn compare_row(
    name: &str,
    n: u64,
    b: &serde_json::Value,
    threshold: f64,
    regressions: &mut Vec<String>,
) -> Vec<report::Cell> {
    let base = b["kernels"][name].as_u64();
    let (ratio, verdict) = match base {
        Some(base) if base > 0 => {
            let r = n as f64 / base as f64;
            let v = if r > 1.0 + threshold {
                regressions.push(format!("{name} (+{:.1} %)", (r - 1.0) * 100.0));
                "regression"
            } else if r < 1.0 - threshold {
                "fewer"
            } else {
                "unchanged"
            };
            (Some(r), v)
        }
        _ => (None, "not in the baseline"),
    };
    vec![
        report::Cell::text(name),
        report::Cell::Num(base.map(|b| b as f64), 0),
        report::Cell::Num(Some(n as f64), 0),
        report::Cell::Num(ratio, 4),
        report::Cell::text(verdict),
    ]
}

/// Writes `counts` (of `kernels` kernels) as the new baseline, with the tools that made them.
fn write_baseline(
    args: &InstructionsArgs,
    valgrind: &str,
    rustc: &str,
    counts: serde_json::Map<String, serde_json::Value>,
    kernels: usize,
) -> Result<()> {
    let json = serde_json::json!({
        "valgrind": valgrind,
        "rustc": rustc,
        "git_commit": gibench_harness::run::runner::git_commit(),
        "kernels": counts,
    });
    let bytes = serde_json::to_vec_pretty(&json).map_err(|e| Error::Invalid(e.to_string()))?;
    gibench_harness::output::write_atomic(&args.baseline, &bytes)?;
    eprintln!(
        "wrote the instruction counts of {} kernels to {}",
        kernels,
        args.baseline.display()
    );
    Ok(())
}
