//! `gibench export --format bmf`: results folders (and an instruction-count file, and
//! criterion's output) as Bencher Metric Format JSON, for `bencher run --adapter json --file
//! ...` to keep their history (docs/history.md).
//!
//! Benchmarks are named `SCENE@WxH/TECHNIQUE/STAGE` (and `.../frame`, `.../gpu-frame-span`,
//! `.../image-error`). Where the exported runs of one scene, resolution and technique differ
//! (a sweep, or runs of other targets made with other frame counts), a segment after the
//! technique names what differs among them, sorted by name: the parameters and the run options
//! `timing`, `frames`, `warmup`, `first-frame` and `seed` whose values are not the same in all
//! of them (`absent` for a run without the parameter), e.g.
//! `cornell@256x192/ism/vpls=1024/accumulate`; runs alike in all of them are repeats (a single
//! run, or the repeats of one, keeps the short name). Each benchmark holds measures whose
//! `value` is the median over the repeats found and whose `lower_value` and `upper_value` are
//! the smallest and largest repeat (present with two repeats or more):
//!
//! * `latency`, Bencher's built-in measure, in its unit, **nanoseconds**: per stage, each
//!   repeat's median stage time (flushed wall time, else GPU timestamps, as the tables show);
//!   per frame, each repeat's median frame time; `gpu-frame-span`, the median GPU span of a
//!   frame (first stage's start to last stage's end);
//! * `rmse` and `flip` (custom measures, no unit): each repeat's mean RMSE and mean FLIP over
//!   its compared frames, where the runs were made with `--quality`;
//! * `instructions` (custom): a kernel's instruction count under callgrind, from a file that
//!   `gibench instructions --write` made, as `kernels/KERNEL`;
//! * criterion's benchmarks (`--criterion target/criterion`), as `kernels/<criterion id>`:
//!   `latency` in nanoseconds, the `value` the point estimate of the **mean** time per
//!   iteration of the latest run (`new/estimates.json`) and the bounds its confidence interval
//!   (criterion's bootstrap, 95 % by default); `cpu-time` (custom, nanoseconds of the
//!   process's CPU time) for the groups whose name ends in `-cpu`, which `benches/kernels.rs`
//!   measures so.
//!
//! The testbed (`--print-testbed`) is named from the runs' adapter, backend and driver.

use std::collections::BTreeMap;
use std::path::PathBuf;

use clap::{Args, ValueEnum};
use gibench_harness::measure::results::RunResult;
use gibench_harness::measure::stats::median;
use gibench_harness::report::stage_ms;
use gibench_harness::{Error, Result};
use serde_json::{json, Map, Value};

use super::results_io::results_under;
use gibench_papers::files::writable_file;

/// Formats `gibench export` writes.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub(crate) enum Format {
    /// Bencher Metric Format JSON (`bencher run --adapter json`).
    Bmf,
}

#[derive(Args)]
pub(crate) struct ExportResultsArgs {
    /// Folders of results files, searched recursively (one subfolder per repeat, as for
    /// `gibench compare`).
    inputs: Vec<PathBuf>,
    /// The output format.
    #[arg(long, value_enum)]
    format: Format,
    /// An instruction-count file (`gibench instructions --write`, e.g.
    /// results/baseline/instructions.json) to export beside the runs.
    #[arg(long)]
    instructions: Option<PathBuf>,
    /// Criterion's output folder (target/criterion after `cargo bench`) to export beside the
    /// runs: each benchmark's latest estimates (`.../new/estimates.json`) as
    /// `kernels/<criterion id>`.
    #[arg(long, value_name = "DIR")]
    criterion: Option<PathBuf>,
    /// The file to write (default: standard output).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print only the testbed name (adapter, backend, driver) of the runs, for
    /// `bencher run --testbed`.
    #[arg(long)]
    print_testbed: bool,
}

/// `gibench export`: reads the inputs, checks they make one testbed, writes the JSON.
pub(crate) fn exec(args: &ExportResultsArgs) -> Result<()> {
    if args.inputs.is_empty() && args.instructions.is_none() && args.criterion.is_none() {
        return Err(Error::param(
            "inputs",
            "give at least one folder of results files, --instructions FILE or --criterion DIR",
        ));
    }
    if let Some(out) = &args.out {
        writable_file("out", out, "history.json")?;
    }
    let mut runs: Vec<RunResult> = Vec::new();
    let mut seen: Vec<PathBuf> = Vec::new();
    for dir in &args.inputs {
        for (path, r) in results_under("inputs", dir)? {
            let canonical = path.canonicalize().map_err(|e| Error::io(&path, e))?;
            if seen.contains(&canonical) {
                return Err(Error::bad_file(
                    &path,
                    "reached twice through the inputs (a folder and one inside it?); each run \
                     must count once",
                ));
            }
            seen.push(canonical);
            runs.push(r);
        }
    }
    let testbed = testbed(&runs)?;
    if args.print_testbed {
        match testbed {
            Some(t) => println!("{t}"),
            None => {
                return Err(Error::param(
                    "print-testbed",
                    "needs folders of results files: the testbed is named from their device",
                ))
            }
        }
        return Ok(());
    }
    let instructions = args
        .instructions
        .as_ref()
        .map(|p| read_instructions(p).map(|k| (p.clone(), k)))
        .transpose()?;
    let criterion = args.criterion.as_deref().map(read_criterion).transpose()?;
    let bmf = bmf(
        &runs,
        instructions.as_ref().map(|(_, k)| k),
        criterion.as_deref().unwrap_or_default(),
    )?;
    let text = serde_json::to_string_pretty(&bmf).map_err(|e| Error::Invalid(e.to_string()))?;
    match &args.out {
        Some(out) => {
            gibench_harness::output::write_atomic(out, format!("{text}\n").as_bytes())?;
            eprintln!(
                "wrote {} benchmarks ({} runs{}{}) to {}",
                bmf.len(),
                runs.len(),
                if instructions.is_some() {
                    ", instruction counts"
                } else {
                    ""
                },
                criterion.as_ref().map_or(String::new(), |c| format!(
                    ", {} criterion benchmarks",
                    c.len()
                )),
                out.display()
            );
        }
        None => println!("{text}"),
    }
    Ok(())
}

/// The testbed the runs were made on, as a Bencher slug (lower case, digits and dashes, at
/// most 64 characters): adapter, backend and driver, and a software rasteriser's recorded
/// thread setting (`driver_env`). `None` without runs; an error when the runs come from more
/// than one (their histories must not mix).
fn testbed(runs: &[RunResult]) -> Result<Option<String>> {
    // Devices are told apart by their whole names, not by their slugs, which may be cut.
    let mut devices: Vec<String> = runs
        .iter()
        .map(|r| {
            let d = &r.device;
            format!("{} {} {}{}", d.adapter, d.backend, d.driver, d.env_text())
        })
        .collect();
    devices.sort();
    devices.dedup();
    match devices.as_slice() {
        [] => Ok(None),
        [one] if one.chars().any(|c| c.is_ascii_alphanumeric()) => Ok(Some(slug(one))),
        [_] => Err(Error::param(
            "inputs",
            "the runs' device has no adapter, backend or driver name to name a testbed by",
        )),
        many => Err(Error::param(
            "inputs",
            format!(
                "the runs come from {} devices ({}); export each device's runs on their own \
                 (one testbed per upload)",
                many.len(),
                many.iter().map(|d| slug(d)).collect::<Vec<_>>().join(", ")
            ),
        )),
    }
}

/// `words` as a Bencher slug: lower-case letters and digits, single dashes between words, at
/// most 64 characters. A longer one keeps its first 55 characters and ends in 8 hex digits of
/// a hash of the whole words (FNV-1a, stable across builds), so that two devices whose names
/// differ only past the cut still get two testbeds.
fn slug(words: &str) -> String {
    let mut s = String::new();
    for c in words.chars() {
        if c.is_ascii_alphanumeric() {
            s.push(c.to_ascii_lowercase());
        } else if !s.is_empty() && !s.ends_with('-') {
            s.push('-');
        }
    }
    let s = s.trim_end_matches('-');
    if s.len() <= 64 {
        return s.to_string();
    }
    let hash = words.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    });
    format!("{}-{:08x}", s[..55].trim_end_matches('-'), hash as u32)
}

/// The kernels' instruction counts in `path` (`{"kernels": {"NAME": COUNT, ...}}`).
fn read_instructions(path: &std::path::Path) -> Result<BTreeMap<String, u64>> {
    let bytes = gibench_harness::error::read_bounded(path, 1 << 24)?;
    let v: Value = serde_json::from_slice(&bytes)
        .map_err(|e| Error::bad_file(path, format!("not JSON: {e}")))?;
    let kernels = v.get("kernels").and_then(Value::as_object).ok_or_else(|| {
        Error::bad_file(
            path,
            "has no 'kernels' object; expected an instruction-count file of `gibench instructions --write`",
        )
    })?;
    kernels
        .iter()
        .map(|(k, n)| {
            n.as_u64().map(|n| (k.clone(), n)).ok_or_else(|| {
                Error::bad_file(
                    path,
                    format!("kernels.{k} is {n}; expected a count (a whole number >= 0)"),
                )
            })
        })
        .collect()
}

/// One criterion benchmark's latest estimate, nanoseconds.
struct CriterionBench {
    /// Criterion's `full_id`, e.g. `rays/closest-hit-1024/cornell`.
    id: String,
    /// The mean's point estimate and its confidence interval (criterion's bootstrap, 95 % by
    /// default), widened to hold the point estimate.
    mean: f64,
    lower: f64,
    upper: f64,
}

/// The benchmarks of criterion's output folder `dir` (`target/criterion`): every
/// `new/benchmark.json` beside a `new/estimates.json`, at any depth (criterion nests a
/// group's benchmarks by function and value). Saved baselines (`base/`, `--save-baseline`'s
/// folders) and reports are passed over. An error names the file that cannot be read, or the
/// folder when it holds no benchmark.
fn read_criterion(dir: &std::path::Path) -> Result<Vec<CriterionBench>> {
    fn walk(dir: &std::path::Path, found: &mut Vec<PathBuf>) -> Result<()> {
        let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
        let mut dirs: Vec<PathBuf> = Vec::new();
        for entry in entries {
            let entry = entry.map_err(|e| Error::io(dir, e))?;
            if entry
                .file_type()
                .map_err(|e| Error::io(entry.path(), e))?
                .is_dir()
            {
                dirs.push(entry.path());
            }
        }
        dirs.sort();
        for d in dirs {
            if d.file_name().is_some_and(|n| n == "new") {
                if d.join("benchmark.json").is_file() {
                    found.push(d);
                }
            } else {
                walk(&d, found)?;
            }
        }
        Ok(())
    }
    if !dir.is_dir() {
        return Err(Error::param(
            "criterion",
            format!(
                "{} is not a folder; expected criterion's output folder (target/criterion \
                 after `cargo bench`)",
                dir.display()
            ),
        ));
    }
    let mut found = Vec::new();
    walk(dir, &mut found)?;
    if found.is_empty() {
        return Err(Error::param(
            "criterion",
            format!(
                "{} holds no criterion benchmark (no .../new/benchmark.json); expected \
                 criterion's output folder (target/criterion after `cargo bench`)",
                dir.display()
            ),
        ));
    }
    let read = |path: &std::path::Path| -> Result<Value> {
        let bytes = gibench_harness::error::read_bounded(path, 1 << 24)?;
        serde_json::from_slice(&bytes).map_err(|e| Error::bad_file(path, format!("not JSON: {e}")))
    };
    let mut out = Vec::new();
    for new in found {
        let bench_file = new.join("benchmark.json");
        let id = read(&bench_file)?
            .get("full_id")
            .and_then(Value::as_str)
            .filter(|id| !id.is_empty())
            .ok_or_else(|| {
                Error::bad_file(
                    &bench_file,
                    "has no 'full_id' string; expected criterion's benchmark.json",
                )
            })?
            .to_string();
        let est_file = new.join("estimates.json");
        let est = read(&est_file)?;
        let mean = &est["mean"];
        let num = |v: &Value| v.as_f64().filter(|x| x.is_finite() && *x >= 0.0);
        let (Some(value), Some(lo), Some(hi)) = (
            num(&mean["point_estimate"]),
            num(&mean["confidence_interval"]["lower_bound"]),
            num(&mean["confidence_interval"]["upper_bound"]),
        ) else {
            return Err(Error::bad_file(
                &est_file,
                "has no 'mean' with a 'point_estimate' and a 'confidence_interval' \
                 (lower_bound, upper_bound) of numbers >= 0; expected criterion's \
                 estimates.json",
            ));
        };
        out.push(CriterionBench {
            id,
            mean: value,
            lower: lo.min(value),
            upper: hi.max(value),
        });
    }
    Ok(out)
}

/// A BMF metric: the median of `values` (non-empty, finite), with the smallest and largest as
/// lower and upper values when there are two or more.
fn metric(values: &[f64]) -> Value {
    let mut m = Map::new();
    m.insert("value".into(), json!(median(values)));
    if values.len() > 1 {
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        m.insert("lower_value".into(), json!(lo));
        m.insert("upper_value".into(), json!(hi));
    }
    Value::Object(m)
}

/// What tells one run of a scene, resolution and technique from another: its parameters
/// (named as `gibench list` names them, valued as `gibench compare` prints them) and the run
/// options that change what is measured (`timing`, `frames`, `warmup`, `first-frame`,
/// `seed`).
fn distinguishing(r: &RunResult) -> BTreeMap<String, String> {
    let mut d: BTreeMap<String, String> = r
        .parameters
        .iter()
        .map(|(k, v)| (k.clone(), v.to_string().trim_matches('"').to_string()))
        .collect();
    for (option, value) in [
        ("timing", r.timing_mode.clone()),
        ("frames", r.frames.measured.to_string()),
        ("warmup", r.frames.warmup.to_string()),
        ("first-frame", r.frames.first.to_string()),
        ("seed", r.seed.to_string()),
    ] {
        // A technique parameter of the same name (none today) keeps its name; the option
        // is then told by a `run-` prefix.
        let name = if d.contains_key(option) {
            format!("run-{option}")
        } else {
            option.to_string()
        };
        d.insert(name, value);
    }
    d
}

/// The runs as benchmarks: each named `SCENE@WxH/TECHNIQUE`, then, where runs of that scene,
/// resolution and technique differ, `/NAME=VALUE,...` of the parameters and run options
/// ([`distinguishing`]) whose values differ among them, sorted by name (`absent` for a run
/// without the parameter), with their repeats (runs alike in all of them). Names are stable
/// for a given set of runs, and a single run, or the repeats of one, keeps the short name.
fn benchmarks(runs: &[RunResult]) -> Result<Vec<(String, Vec<&RunResult>)>> {
    // Scene, resolution and technique -> distinguishing values -> repeats.
    type Repeats<'a> = BTreeMap<BTreeMap<String, String>, Vec<&'a RunResult>>;
    let mut by_prefix: BTreeMap<String, Repeats> = BTreeMap::new();
    for r in runs {
        let prefix = format!(
            "{}@{}x{}/{}",
            r.scene, r.resolution[0], r.resolution[1], r.technique
        );
        by_prefix
            .entry(prefix)
            .or_default()
            .entry(distinguishing(r))
            .or_default()
            .push(r);
    }
    let mut out = Vec::new();
    // Benchmark name -> the run it was given to, to refuse two runs one name.
    let mut named: BTreeMap<String, String> = BTreeMap::new();
    for (prefix, groups) in by_prefix {
        let names: std::collections::BTreeSet<&String> =
            groups.keys().flat_map(|d| d.keys()).collect();
        let differing: Vec<String> = names
            .into_iter()
            .filter(|n| {
                let first = groups.keys().next().and_then(|d| d.get(*n));
                groups.keys().any(|d| d.get(*n) != first)
            })
            .cloned()
            .collect();
        for (dims, repeats) in groups {
            let mut name = prefix.clone();
            if !differing.is_empty() {
                let parts: Vec<String> = differing
                    .iter()
                    .map(|n| format!("{n}={}", dims.get(n).map_or("absent", String::as_str)))
                    .collect();
                name = format!("{name}/{}", parts.join(","));
            }
            let run = format!(
                "{} {}",
                gibench_harness::report::compare::run_key(repeats[0]),
                serde_json::to_string(&repeats[0].parameters).unwrap_or_default()
            );
            if let Some(other) = named.insert(name.clone(), run.clone()) {
                return Err(Error::param(
                    "inputs",
                    format!(
                        "two different runs would share the benchmark names {name}/...: \
                         {other}; {run} (their parameters' values print alike, e.g. \"1\" and 1); export them \
                         from separate folders"
                    ),
                ));
            }
            out.push((name, repeats));
        }
    }
    Ok(out)
}

/// The BMF document (see the module docs): benchmark name → measure slug → metric.
fn bmf(
    runs: &[RunResult],
    instructions: Option<&BTreeMap<String, u64>>,
    criterion: &[CriterionBench],
) -> Result<BTreeMap<String, Map<String, Value>>> {
    let mut out: BTreeMap<String, Map<String, Value>> = BTreeMap::new();
    for (prefix, repeats) in benchmarks(runs)? {
        let mut add = |bench: String, measure: &str, values: Vec<f64>| {
            let values: Vec<f64> = values.into_iter().filter(|v| v.is_finite()).collect();
            if !values.is_empty() {
                out.entry(bench)
                    .or_default()
                    .insert(measure.to_string(), metric(&values));
            }
        };
        let mut stages: Vec<&str> = Vec::new();
        for r in &repeats {
            for s in &r.stages {
                if !stages.contains(&s.name.as_str()) {
                    stages.push(&s.name);
                }
            }
        }
        const NS_PER_MS: f64 = 1e6;
        for stage in stages {
            let ms: Vec<f64> = repeats
                .iter()
                .filter_map(|r| r.stage(stage).and_then(stage_ms))
                .collect();
            add(
                format!("{prefix}/{stage}"),
                "latency",
                ms.iter().map(|m| m * NS_PER_MS).collect(),
            );
        }
        let frames: Vec<&gibench_harness::measure::results::FrameResult> =
            repeats.iter().filter_map(|r| r.frame.as_ref()).collect();
        add(
            format!("{prefix}/frame"),
            "latency",
            frames
                .iter()
                .map(|f| f.frame_ms.median * NS_PER_MS)
                .collect(),
        );
        add(
            format!("{prefix}/gpu-frame-span"),
            "latency",
            frames
                .iter()
                .filter_map(|f| f.gpu_span_ms.map(|s| s.median * NS_PER_MS))
                .collect(),
        );
        let quality: Vec<_> = repeats.iter().filter_map(|r| r.quality.as_ref()).collect();
        add(
            format!("{prefix}/image-error"),
            "rmse",
            quality.iter().map(|q| q.rmse.mean).collect(),
        );
        add(
            format!("{prefix}/image-error"),
            "flip",
            quality.iter().map(|q| q.flip_mean.mean).collect(),
        );
    }
    for (kernel, count) in instructions.into_iter().flatten() {
        out.entry(format!("kernels/{kernel}"))
            .or_default()
            .insert("instructions".into(), json!({ "value": *count as f64 }));
    }
    for b in criterion {
        // The benches' groups measured in CPU time end in `-cpu` (benches/kernels.rs).
        let cpu = b.id.split('/').next().is_some_and(|g| g.ends_with("-cpu"));
        let measure = if cpu { "cpu-time" } else { "latency" };
        let bench = format!("kernels/{}", b.id);
        let metrics = out.entry(bench.clone()).or_default();
        if metrics.contains_key(measure) {
            return Err(Error::param(
                "criterion",
                format!("two criterion benchmarks would both be {bench} ({measure})"),
            ));
        }
        metrics.insert(
            measure.into(),
            json!({"value": b.mean, "lower_value": b.lower, "upper_value": b.upper}),
        );
    }
    if out.is_empty() {
        return Err(Error::param(
            "inputs",
            "nothing to export: the runs have no timed stage, frame or image error",
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The testbed slug keeps Bencher's slug rules (lower case, digits, single dashes, at
    /// most 64 characters) whatever the adapter's name holds.
    #[test]
    fn testbed_names_are_slugs() {
        let mut r: RunResult = serde_json::from_slice(
            &std::fs::read(
                std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("results/baseline/r1/cornell-direct.json"),
            )
            .unwrap(),
        )
        .unwrap();
        r.device.adapter = "llvmpipe (LLVM 19.1.7, 256 bits) ".repeat(4);
        r.device.backend = "Vulkan".into();
        let t = testbed(std::slice::from_ref(&r)).unwrap().unwrap();
        assert!(t.len() <= 64, "{t}");
        assert!(t.starts_with("llvmpipe-llvm-19-1-7-256-bits-"), "{t}");
        assert!(
            t.chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
                && !t.contains("--")
                && !t.ends_with('-'),
            "{t}"
        );
        // Two devices whose names differ only past the cut: two testbeds, and refused together.
        let mut other = r.clone();
        other.device.backend = "gl".into();
        let u = testbed(std::slice::from_ref(&other)).unwrap().unwrap();
        assert!(u.len() <= 64 && u != t, "{t} / {u}");
        let e = testbed(&[r, other]).unwrap_err().to_string();
        assert!(e.contains("2 devices"), "{e}");
    }

    /// A software rasteriser run with its thread count set (`LP_NUM_THREADS=0`: steadier, and
    /// slower) is another testbed than one left to the driver's default, and the two are not
    /// exported together. Catches a history that mixes the two settings' timings.
    #[test]
    fn a_software_thread_setting_is_its_own_testbed() {
        let r: RunResult = serde_json::from_slice(
            &std::fs::read(
                std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("results/baseline/r1/cornell-direct.json"),
            )
            .unwrap(),
        )
        .unwrap();
        assert!(r.device.driver_env.is_empty(), "{:?}", r.device);
        let mut one = r.clone();
        one.device.driver_env = r
            .device
            .software_env(|k| (k == "LP_NUM_THREADS").then(|| "0".into()));
        let (t, u) = (
            testbed(std::slice::from_ref(&r)).unwrap().unwrap(),
            testbed(std::slice::from_ref(&one)).unwrap().unwrap(),
        );
        assert!(u.ends_with("lp-num-threads-0") && t != u, "{t} / {u}");
        let e = testbed(&[r, one]).unwrap_err().to_string();
        assert!(e.contains("2 devices"), "{e}");
    }
}
