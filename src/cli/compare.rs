//! `gibench compare`: CURRENT runs against BASE runs stage by stage, with a rank test's
//! p-value, the median ratio and a verdict, refusing to compare runs with themselves.
//!
//! `--format markdown` prints the short Markdown of a pull request's comment or a CI job's
//! summary instead of the terminal table; `--fail-on slower` makes a regression exit with
//! [`CHANGE_STATUS`] (3), for runners whose timings can be trusted to gate a change.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Args;
use gibench_harness::measure::results::RunResult;
use gibench_harness::output::OutputSet;
use gibench_harness::report;
use gibench_harness::report::compare::{run_key, Statistic, Verdict};
use gibench_harness::{Error, Result};

use super::results_io::results_under;
use gibench_papers::files::check_stem;

#[derive(Args)]
pub(crate) struct CompareArgs {
    /// Folder of the BASE runs (searched recursively for results files; one subfolder per repeat).
    base: PathBuf,
    /// Folder of the CURRENT runs, likewise.
    current: PathBuf,
    /// Smallest relative change a verdict needs: slower only when the median ratio is above
    /// 1 + tolerance (and the rank test's p is below --alpha); 0.15 is half a 30 % change,
    /// above a shared CPU's run-to-run drift of the fastest frames.
    #[arg(long, default_value_t = gibench_harness::report::compare::DEFAULT_TOLERANCE)]
    tolerance: f64,
    /// Significance level of the two-sided Mann–Whitney U test a verdict needs (p < alpha).
    #[arg(long, default_value_t = gibench_harness::report::compare::DEFAULT_ALPHA)]
    alpha: f64,
    /// Decide on each repeat divided by the calibration workload timed in its session (for
    /// runs made in sessions far apart, such as a committed baseline); without it the verdict
    /// is decided on raw times and the calibrated ratio is only shown.
    #[arg(long)]
    calibrate: bool,
    /// Each repeat's figure of a stage: `min`, its fastest frame (robust to other processes on
    /// the machine, which only add time; blind to a change that slows only some frames), or
    /// `median`, its median frame (as the tables; moves with the machine's load).
    #[arg(long, value_enum, default_value_t = StatisticArg::Min)]
    statistic: StatisticArg,
    /// Fail when a run is on one side only (by default such runs are listed and passed over):
    /// CI's check that the committed baseline covers every technique as it is run today.
    #[arg(long)]
    require_all: bool,
    /// Output directory for the comparison (Markdown, CSV, LaTeX, JSON).
    #[arg(long, default_value = "results/local")]
    out: PathBuf,
    /// File name stem of the outputs.
    #[arg(long, default_value = "compare")]
    stem: String,
    /// What to print on standard output: `table`, the whole comparison as a terminal table,
    /// or `markdown`, the changed stages only (slower first, then faster) and a count of the
    /// unchanged, for a pull request's comment or a CI job's summary. The files in --out are
    /// the same either way.
    #[arg(long, value_enum, default_value_t = OutputFormat::Table)]
    format: OutputFormat,
    /// Exit with status 3 (after printing and writing everything) when a stage's verdict is
    /// this: `slower` (a regression), `faster`, or `any-change` (either). Only for runners
    /// whose timings are stable enough to gate a change; without it the verdicts never change
    /// the exit status.
    #[arg(long, value_enum)]
    fail_on: Option<FailOn>,
    /// Compare runs made on different devices (adapter and backend) all the same: their
    /// difference would read as a change, so without this a cross-device comparison is
    /// refused. Both sides' devices are named either way.
    #[arg(long)]
    cross_device: bool,
    /// Match runs as if these parameters were not set (comma-separated): a parameter a
    /// technique gained since the BASE runs were made, so that CURRENT's runs (which record it)
    /// still match BASE's. Only for a parameter whose value CURRENT ran at does what BASE's
    /// code did or is the change being measured; named in the outputs' notes.
    #[arg(long, value_delimiter = ',', value_name = "NAME")]
    ignore_param: Vec<String>,
}

/// The exit status of `gibench compare --fail-on` when a verdict it names is found (1 is an
/// error, 2 a usage error).
pub(crate) const CHANGE_STATUS: u8 = 3;

/// `--format`'s values.
#[derive(Clone, Copy, clap::ValueEnum)]
enum OutputFormat {
    Table,
    Markdown,
}

/// `--fail-on`'s values.
#[derive(Clone, Copy, PartialEq, clap::ValueEnum)]
enum FailOn {
    Slower,
    Faster,
    AnyChange,
}

/// `--statistic`'s values.
#[derive(Clone, Copy, clap::ValueEnum)]
enum StatisticArg {
    Min,
    Median,
}

/// Drops the parameters `names` from every run of both sides before matching; a name no run
/// on either side has is refused (a misspelt name would otherwise change nothing). Returns the
/// note that says which were ignored.
fn ignore_params(names: &[String], sides: [&mut Vec<RunResult>; 2]) -> Result<Option<String>> {
    if names.is_empty() {
        return Ok(None);
    }
    let mut found = vec![false; names.len()];
    for (side, runs) in ["BASE", "CURRENT"].into_iter().zip(sides) {
        // Two runs of one side that differ only in an ignored parameter would become repeats
        // of one run, their settings mixed: refused, naming both.
        let mut before: BTreeMap<String, String> = BTreeMap::new();
        for r in runs.iter_mut() {
            let key = run_key(r);
            for (name, found) in names.iter().zip(&mut found) {
                *found |= r.parameters.remove(name).is_some();
            }
            let merged = run_key(r);
            match before.get(&merged) {
                Some(other) if *other != key => {
                    return Err(Error::param(
                        "ignore-param",
                        format!("{side} holds {other} and {key}: with {} ignored they would be one run, their settings mixed; compare each setting apart", names.join(", ")),
                    ));
                }
                _ => {
                    before.insert(merged, key);
                }
            }
        }
    }
    if let Some((name, _)) = names.iter().zip(&found).find(|(_, f)| !**f) {
        return Err(Error::param(
            "ignore-param",
            format!("no run on either side has a parameter '{name}' (expected a parameter one side's runs record)"),
        ));
    }
    Ok(Some(format!(
        "Runs matched as if they did not set {} (--ignore-param).",
        names.join(", ")
    )))
}

/// `gibench compare`: reads both sides, compares, prints and writes the table and JSON; the
/// exit status is [`CHANGE_STATUS`] when `--fail-on` names a verdict found.
pub(crate) fn exec(args: &CompareArgs) -> Result<ExitCode> {
    check_stem(&args.stem)?;
    let settings = gibench_harness::report::compare::Settings::new(
        args.tolerance,
        args.alpha,
        args.calibrate,
        match args.statistic {
            StatisticArg::Min => Statistic::Min,
            StatisticArg::Median => Statistic::Median,
        },
    )?;
    let base = results_under("base", &args.base)?;
    let current = results_under("current", &args.current)?;
    check_distinct_runs(args, &base, &current)?;
    let (mut base, mut current): (Vec<RunResult>, Vec<RunResult>) = (
        base.into_iter().map(|(_, r)| r).collect(),
        current.into_iter().map(|(_, r)| r).collect(),
    );
    let ignored_note = ignore_params(&args.ignore_param, [&mut base, &mut current])?;
    let devices = [devices(&base), devices(&current)];
    let same_devices = devices[0] == devices[1];
    if !same_devices && !args.cross_device {
        return Err(Error::param(
            "cross-device",
            format!(
                "BASE ran on {} and CURRENT on {}: the devices' difference would read as a change; compare runs from one device, or pass --cross-device to compare them anyway",
                devices[0].join(", "),
                devices[1].join(", ")
            ),
        ));
    }
    let device_note = if same_devices {
        format!("Both sides on {}.", devices[0].join(", "))
    } else {
        format!(
            "ACROSS DEVICES (--cross-device): BASE on {}, CURRENT on {}; the ratios include the devices' difference.",
            devices[0].join(", "),
            devices[1].join(", ")
        )
    };
    eprintln!("{device_note}");
    let unmatched = gibench_harness::report::compare::unmatched(&base, &current);
    let listing: Vec<String> = ["BASE", "CURRENT"]
        .iter()
        .zip(&unmatched)
        .filter(|(_, runs)| !runs.is_empty())
        .map(|(side, runs)| format!("only in {side}: {}", runs.join("; ")))
        .collect();
    if args.require_all && !listing.is_empty() {
        return Err(Error::param(
            "require-all",
            format!(
                "every run must be on both sides (matched by scene, technique, resolution and \
                 parameters), but {}; run the missing side again (the committed baseline: bash \
                 results/regenerate.sh baseline)",
                listing.join(", and ")
            ),
        ));
    }
    let rows = gibench_harness::report::compare::compare(&base, &current, &settings)?;
    let mut table = gibench_harness::report::compare::compare_table(&rows, &settings);
    table.notes.push(device_note.clone());
    let mut notes = vec![device_note];
    if let Some(note) = ignored_note {
        eprintln!("{note}");
        table.notes.push(note.clone());
        notes.push(note);
    }
    if !listing.is_empty() {
        let note = format!("Not compared (on one side only): {}.", listing.join("; "));
        eprintln!("warning: {note}");
        table.notes.push(note.clone());
        notes.push(note);
    }
    match args.format {
        OutputFormat::Table => println!(
            "{}",
            gibench_harness::report::compare::compare_terminal(&rows, &settings, &notes)
        ),
        OutputFormat::Markdown => print!(
            "{}",
            gibench_harness::report::compare::compare_markdown(
                &rows,
                &settings,
                [
                    &args.base.display().to_string(),
                    &args.current.display().to_string()
                ],
                &notes
            )
        ),
    }
    let set = OutputSet::begin("out", &args.out)?;
    report::write_tables(&table, &args.out, &args.stem)?;
    let json = serde_json::to_vec_pretty(&rows).map_err(|e| Error::Invalid(e.to_string()))?;
    gibench_harness::output::write_atomic(&args.out.join(format!("{}.json", args.stem)), &json)?;
    set.publish()?;
    eprintln!(
        "wrote {stem}.md, .csv, .tex and .json to {}",
        args.out.display(),
        stem = args.stem
    );
    if let Some(fail_on) = args.fail_on {
        let hit = rows
            .iter()
            .filter(|r| match r.verdict {
                Verdict::Slower => fail_on != FailOn::Faster,
                Verdict::Faster => fail_on != FailOn::Slower,
                Verdict::Unchanged => false,
            })
            .count();
        if hit > 0 {
            eprintln!(
                "{hit} stage(s) {}: exit status {CHANGE_STATUS} (--fail-on {})",
                match fail_on {
                    FailOn::Slower => "slower",
                    FailOn::Faster => "faster",
                    FailOn::AnyChange => "slower or faster",
                },
                clap::ValueEnum::to_possible_value(&fail_on)
                    .map_or(String::new(), |v| v.get_name().to_string())
            );
            return Ok(ExitCode::from(CHANGE_STATUS));
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The devices `runs` were made on, as `adapter (backend)`, sorted and without repeats.
fn devices(runs: &[RunResult]) -> Vec<String> {
    let mut d: Vec<String> = (runs.iter())
        .map(gibench_harness::report::device_label)
        .collect();
    d.sort_unstable();
    d.dedup();
    d
}

/// Refuses a comparison of runs with themselves: BASE and CURRENT the same folder, a results
/// file reached from both sides or twice from one (through a link), or two byte-identical
/// copies of one run (counted as two repeats, a copy would make the rank test surer than the runs allow).
fn check_distinct_runs(
    args: &CompareArgs,
    base: &[(PathBuf, RunResult)],
    current: &[(PathBuf, RunResult)],
) -> Result<()> {
    let folder = |p: &Path| p.canonicalize().map_err(|e| Error::io(p, e));
    if folder(&args.base)? == folder(&args.current)? {
        return Err(Error::param(
            "current",
            format!(
                "{} is the same folder as BASE ({}); compare needs two different sets of runs",
                args.current.display(),
                args.base.display()
            ),
        ));
    }
    let side = |i: usize| if i < base.len() { "BASE" } else { "CURRENT" };
    // Each file's canonical path and a hash of its bytes; equal hashes are confirmed on the bytes.
    let mut seen: Vec<(PathBuf, u64, &Path)> = Vec::new();
    for (i, (path, _)) in base.iter().chain(current).enumerate() {
        let canonical = folder(path)?;
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let hash = {
            use std::hash::{Hash, Hasher};
            let mut h = std::hash::DefaultHasher::new();
            bytes.hash(&mut h);
            h.finish()
        };
        for (j, (c, other_hash, other)) in seen.iter().enumerate() {
            let same_file = *c == canonical;
            let same_bytes = !same_file
                && *other_hash == hash
                && std::fs::read(other).map_err(|e| Error::io(*other, e))? == bytes;
            if same_file || same_bytes {
                return Err(Error::bad_file(
                    path,
                    format!(
                        "in {}, {} {} in {}; compare needs distinct runs (every repeat run anew, \
                         BASE and CURRENT different folders)",
                        side(i),
                        if same_file {
                            "the same file as"
                        } else {
                            "a byte-identical copy of"
                        },
                        other.display(),
                        side(j)
                    ),
                ));
            }
        }
        seen.push((canonical, hash, path));
    }
    Ok(())
}
