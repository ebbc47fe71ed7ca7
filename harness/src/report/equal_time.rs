//! The equal-time table: techniques at the settings `gibench run --equal-time` found for one
//! frame-time budget, with their errors against each reference component.
//!
//! Reads: [`RunResult`]s whose `settings.equal_time` records the search (budget, knob, value,
//! steps; `papers::equal_time`). Writes: a [`Table`].

use serde_json::Value;

use super::glance::{error_cell, error_columns};
use super::pareto::frame_time_ms;
use super::table::{Cell, Table};
use crate::measure::metrics::ComponentErrors;
use crate::measure::results::RunResult;

/// The search steps a row shows, the last ones (a search of 8 steps and a few failed ones
/// made a 145-character terminal line).
const SHOWN_STEPS: usize = 4;

/// A run's `settings.equal_time` record, if it has one.
fn record(r: &RunResult) -> Option<&Value> {
    r.settings.get("equal_time")
}

/// One row per run with an equal-time record: technique, the knob's value (marked where the
/// knob's range ended the search), the budget, the frame time the search measured and the run
/// measured, relMSE and FLIP against each component (the own marked), and the search's steps.
/// `None` when no run has a record.
pub fn equal_time_table(results: &[RunResult]) -> Option<Table> {
    let runs: Vec<&RunResult> = results.iter().filter(|r| record(r).is_some()).collect();
    if runs.is_empty() {
        return None;
    }
    const NAMES: [&str; 2] = ComponentErrors::NAMES;
    let rows = (runs.iter())
        .map(|r| {
            let e = record(r).expect("filtered above");
            let setting = match (e["knob"].as_str(), e["value"].as_i64()) {
                (Some(k), Some(v)) => match e["end"].as_str() {
                    Some("max") => format!("{k}={v} (its largest: fits)"),
                    Some("min") => format!("{k}={v} (its smallest: over budget)"),
                    Some("jump") => format!("{k}={v} (the next value is over: a jump)"),
                    Some(_) => format!("{k}={v} (over budget)"),
                    None => format!("{k}={v}"),
                },
                _ => "– (no knob)".to_string(),
            };
            let steps: Vec<String> = (e["steps"].as_array().into_iter().flatten())
                .map(|s| match s["frame_ms"].as_f64() {
                    Some(ms) => format!("{} {ms:.1}", s["value"]),
                    None => format!("{} failed", s["value"]),
                })
                .collect();
            [
                Cell::text(&r.scene),
                Cell::text(&r.technique),
                Cell::text(setting),
                Cell::text(super::glance::component_of(r).unwrap_or("–")),
                Cell::Ms(e["budget_ms"].as_f64()),
                Cell::Ms(e["frame_ms"].as_f64()),
                Cell::Ms(frame_time_ms(r)),
            ]
            .into_iter()
            .chain(NAMES.map(|c| error_cell(r, c, |e| e.rel_mse.mean, 4)))
            .chain(NAMES.map(|c| error_cell(r, c, |e| e.flip_mean.mean, 4)))
            .chain([Cell::text(match steps.len() {
                0 => "–".to_string(),
                // The last steps only: the cell must fit a terminal's width (every step is
                // in the results file).
                n if n > SHOWN_STEPS => {
                    format!("… → {}", steps[n - SHOWN_STEPS..].join(" → "))
                }
                _ => steps.join(" → "),
            })])
            .collect()
        })
        .collect();
    let columns = [
        "scene",
        "technique",
        "setting",
        "reference",
        "budget ms",
        "search ms",
        "frame ms",
    ]
    .map(String::from)
    .into_iter()
    .chain(error_columns("relMSE"))
    .chain(error_columns("FLIP"))
    .chain(["search (value ms → …)".to_string()])
    .collect();
    // The search's thresholds as its records give them (the first tuned run's).
    let thresholds = (runs.iter())
        .filter_map(|r| record(r))
        .find(|e| e["knob"].is_string())
        .unwrap_or(&Value::Null);
    let pc = |k: &str| {
        (thresholds[k].as_f64()).map_or("(not recorded)".to_string(), |f| {
            format!("{:.0} %", 100.0 * f)
        })
    };
    let notes = vec![
        {
            let repeats = thresholds["repeats"].as_u64().map_or(String::new(), |n| {
                format!("; the value kept was timed {n} times and judged by the median")
            });
            format!(
                "Equal time: each technique's quality knob (gibench list) set to the largest value \
                 whose frame fitted the budget (within {} of it, the rest left for the run's own \
                 measurement) in a short timed search on this device: steps of a few frames after \
                 a warm-up, each value's median frame (column search, value and ms per step), \
                 ending once a fitting value reached {} of the budget, where no untried value lay \
                 between one that fitted and one that did not, or at the knob's range end (said \
                 in column setting: its largest value fits, or its smallest, or every value \
                 tried, is over budget; or a jump: the frame time leaps between the value kept, \
                 under the low end, and the next){repeats}. frame ms: the run's own measurement at that \
                 setting, which the machine's noise may put a little off the search's.",
                pc("fit"),
                pc("low"),
            )
        },
        format!(
            "relMSE (of indirect irradiance) and FLIP against each indirect component of the \
             reference: one-bounce and multi-bounce; {} marks the run's own, the component its \
             technique computes (column reference).",
            super::table::OWN_MARK
        ),
    ];
    let mut notes = notes;
    notes.extend(remeasured_notes(&runs, &pc("run_low")));
    Some(Table {
        title: "Error at equal time".to_string(),
        columns,
        rows,
        notes,
    })
}

/// The notes on runs measured again (their earlier runs' timings) and on runs still over the
/// budget in their own measurement; `run_low` is the low end a run must reach ("85 %").
fn remeasured_notes(runs: &[&RunResult], run_low: &str) -> Vec<String> {
    // A run whose own measurement left the budget is said, not hidden in the column.
    let off: Vec<String> =
        (runs.iter())
            .filter_map(|r| {
                let e = record(r)?;
                let (budget, ms) = (e["budget_ms"].as_f64()?, frame_time_ms(r)?);
                // Over it though a value fitted (a range end of "min" or "over budget" says none
                // did, and the setting column says so).
                let fitted = !matches!(e["end"].as_str(), Some("min" | "over budget"));
                (e["knob"].is_string() && fitted && ms > budget).then(|| {
                    format!(
                    "{} {}: the run measured {ms:.2} ms, over the {budget} ms budget (its search: \
                     {})",
                    r.scene,
                    r.technique,
                    e["frame_ms"].as_f64().map_or("–".into(), |s| format!("{s:.2} ms")),
                )
                })
            })
            .collect();
    // Runs measured off the mark before (over the budget, or under its low end), which sent
    // their technique back to the search and ran it again.
    let again: Vec<String> = (runs.iter())
        .filter_map(|r| {
            let before = record(r)?["runs"].as_array().filter(|a| !a.is_empty())?;
            let list: Vec<String> = (before.iter())
                .map(|b| {
                    let ms = b["frame_ms"]
                        .as_f64()
                        .map_or("–".into(), |m| format!("{m:.2} ms"));
                    format!("{} at {ms}", b["value"])
                })
                .collect();
            Some(format!("{} {}: {}", r.scene, r.technique, list.join(", ")))
        })
        .collect();
    let mut notes = Vec::new();
    if !again.is_empty() {
        notes.push(format!(
            "Run again after the run's own measurement left {}-100 % of the budget (that \
             measurement then counted as one more timing of its value, and the search went on): \
             {}.",
            run_low.trim_end_matches(" %"),
            again.join("; ")
        ));
    }
    if !off.is_empty() {
        notes.push(format!(
            "Over the budget in the run's own measurement (the machine's noise between two \
             timings of one setting): {}.",
            off.join("; ")
        ));
    }
    notes
}
