//! `gibench report --speedup`: the same runs on several devices side by side, as ratios.
//!
//! Runs are grouped by device (`adapter (backend)`, in the order first seen) and matched by
//! [`run_key`](super::compare::run_key) (scene, technique, resolution, parameters). For every
//! run made on the first device and another one, a row per stage (and one for the whole frame)
//! gives both times and the speedup, the first device's time over the other's: above 1, the
//! other device is faster. A stage's time is the table's ([`stage_ms`]: the flushed wall time's
//! median, else the GPU timestamps'); the frame's, [`frame_time_ms`].

use super::compare::run_key;
use super::pareto::frame_time_ms;
use super::runs::stage_ms;
use super::{device_label as device, Cell, Table};
use crate::measure::results::RunResult;
use crate::{Error, Result};

/// The speedup table of `runs` (see the module docs); an error naming `speedup` when they come
/// from fewer than two devices or no run was made on two.
pub fn speedup_table(runs: &[RunResult]) -> Result<Table> {
    let mut devices: Vec<String> = Vec::new();
    for r in runs {
        let d = device(r);
        if !devices.contains(&d) {
            devices.push(d);
        }
    }
    if devices.len() < 2 {
        return Err(Error::param(
            "speedup",
            format!(
                "needs runs from at least two devices; all {} are from {}",
                runs.len(),
                devices.first().map_or("none", |d| d.as_str())
            ),
        ));
    }
    let reference = &devices[0];
    let mut rows = Vec::new();
    for other in &devices[1..] {
        for a in runs.iter().filter(|r| device(r) == *reference) {
            let key = run_key(a);
            let Some(b) = runs
                .iter()
                .find(|r| device(r) == *other && run_key(r) == key)
            else {
                continue;
            };
            let mut push = |what: &str, ta: Option<f64>, tb: Option<f64>| {
                let speedup = ta.zip(tb).filter(|(_, b)| *b > 0.0).map(|(a, b)| a / b);
                rows.push(vec![
                    Cell::text(&key),
                    Cell::text(other.as_str()),
                    Cell::text(what),
                    Cell::Ms(ta),
                    Cell::Ms(tb),
                    Cell::Num(speedup, 2),
                ]);
            };
            for s in &a.stages {
                let t = b.stages.iter().find(|t| t.name == s.name);
                push(&s.name, stage_ms(s), t.and_then(stage_ms));
            }
            push("frame", frame_time_ms(a), frame_time_ms(b));
        }
    }
    if rows.is_empty() {
        return Err(Error::param(
            "speedup",
            format!(
                "no run was made on {reference} and on another device (runs match by scene, technique, resolution and parameters)"
            ),
        ));
    }
    Ok(Table {
        title: format!("Speedup against {reference}"),
        columns: ["run", "device", "stage", "reference ms", "device ms", "speedup"]
            .map(String::from)
            .to_vec(),
        rows,
        notes: vec![format!(
            "Per stage, the median flushed wall time (else the GPU timestamps') on {reference} (the reference: the first device of the inputs) and on the device of the row; frame: the median frame time (else the stages' sum). Speedup: the reference's time over the device's (above 1: the device is faster)."
        )],
    })
}
