//! The first screen of a report: per run, what a frame costs and how far the run is from the
//! reference, with its Pareto rank ([`glance_table`]); and the Pareto front as one line
//! ([`pareto_line`]), which the stage table's notes end with (terminal and Markdown).
//!
//! Reads: [`RunResult`]s with quality data. Writes: a [`Table`], a line.
//!
//! Errors are each run's against its own reference component (one-bounce, multi-bounce or
//! direct): where the runs' components differ, the table and the line say that their errors,
//! and so their ranks, are not comparable.

use super::pareto::{distinct_label, frame_time_ms, pareto_front, time_error_points_of};
use super::table::{Cell, Table};
use crate::measure::results::RunResult;

/// The reference component a run's errors are against ("one-bounce", "multi-bounce",
/// "direct"): the first item of its quality's reference label; `None` without quality.
pub fn component_of(r: &RunResult) -> Option<&str> {
    r.quality
        .as_ref()
        .map(|q| q.reference.split(',').next().unwrap_or_default().trim())
}

/// The Pareto rank of each (label, time, error) point: 1 on the front (no other point is
/// both faster and more accurate, see [`pareto_front`]), 2 on the front of the points left
/// once those are set aside, and so on.
pub fn pareto_ranks(points: &[(String, f64, f64)]) -> Vec<usize> {
    let mut rank = vec![0; points.len()];
    let mut left: Vec<usize> = (0..points.len()).collect();
    let mut k = 1;
    while !left.is_empty() {
        let sub: Vec<(String, f64, f64)> = left.iter().map(|&i| points[i].clone()).collect();
        let on: Vec<usize> = pareto_front(&sub).iter().map(|&j| left[j]).collect();
        if on.is_empty() {
            // (Only points whose values are not numbers; none reach here from `time_error_points_of`.)
            left.iter().for_each(|&i| rank[i] = k);
            break;
        }
        on.iter().for_each(|&i| rank[i] = k);
        left.retain(|i| !on.contains(i));
        k += 1;
    }
    rank
}

/// "one-bounce: a, b; multi-bounce: c" where the runs with quality data are scored against
/// more than one component; `None` where they share one.
pub(super) fn mixed_components(results: &[RunResult]) -> Option<String> {
    let mut groups: Vec<(&str, Vec<String>)> = Vec::new();
    for r in results {
        let Some(c) = component_of(r) else { continue };
        let label = distinct_label(results, r);
        match groups.iter_mut().find(|(g, _)| *g == c) {
            Some((_, labels)) => labels.push(label),
            None => groups.push((c, vec![label])),
        }
    }
    (groups.len() > 1).then(|| {
        groups
            .iter()
            .map(|(c, labels)| format!("{c}: {}", labels.join(", ")))
            .collect::<Vec<_>>()
            .join("; ")
    })
}

/// The first screen of a report: one row per run, fastest first: frame ms, FPS, the reference
/// component its errors are against, relMSE, FLIP and Pareto rank. `None` when no run has
/// quality data (there is nothing to weigh the time against).
pub fn glance_table(results: &[RunResult]) -> Option<Table> {
    if results.iter().all(|r| r.quality.is_none()) {
        return None;
    }
    let (points, point_runs) = time_error_points_of(results);
    let ranks = pareto_ranks(&points);
    let rank_of = |i: usize| {
        point_runs
            .iter()
            .position(|&j| j == i)
            .map(|p| ranks[p] as f64)
    };
    let mut order: Vec<usize> = (0..results.len()).collect();
    order.sort_by(|&a, &b| {
        let t = |i: usize| frame_time_ms(&results[i]).unwrap_or(f64::INFINITY);
        t(a).total_cmp(&t(b))
    });
    let rows = order
        .iter()
        .map(|&i| {
            let r = &results[i];
            let q = r.quality.as_ref();
            vec![
                Cell::text(distinct_label(results, r)),
                Cell::Ms(frame_time_ms(r)),
                Cell::Num(r.frame.as_ref().map(|f| f.fps), 1),
                Cell::text(component_of(r).unwrap_or("–")),
                Cell::Num(q.map(|q| q.rel_mse.mean), 4),
                Cell::Num(q.map(|q| q.flip_mean.mean), 4),
                Cell::Num(rank_of(i), 0),
            ]
        })
        .collect();
    let mut notes = vec![
        "frame ms: the median whole frame where frames were timed, else the sum of the stages' \
         medians; FPS: 1000 / mean frame time; relMSE (of indirect irradiance) and FLIP: means over \
         the compared frames against the reference component named; Pareto rank 1: no other run \
         is both faster and of lower relMSE, 2: the same once the rank-1 runs are set aside, and \
         so on. The full per-stage table follows."
            .to_string(),
    ];
    if let Some(mixed) = mixed_components(results) {
        notes.push(format!(
            "Not comparable: these runs' errors are against different reference components \
             ({mixed}), and so are their Pareto ranks."
        ));
    }
    Some(Table {
        title: "At a glance: frame time against error".to_string(),
        columns: [
            "run",
            "frame ms",
            "FPS",
            "reference",
            "relMSE",
            "FLIP",
            "Pareto rank",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        notes,
    })
}

/// The Pareto front in one line: "Pareto front (frame ms, relMSE): a 1.20 ms 0.9812 → b …",
/// fastest first, with a warning where the runs' errors are against different components;
/// `None` when no run has both numbers.
pub fn pareto_line(results: &[RunResult]) -> Option<String> {
    let (points, _) = time_error_points_of(results);
    let front = pareto_front(&points);
    if front.is_empty() {
        return None;
    }
    let steps: Vec<String> = front
        .iter()
        .map(|&i| {
            let (label, t, e) = &points[i];
            format!("{label} {t:.2} ms {e:.4}")
        })
        .collect();
    let mut line = format!(
        "Pareto front (frame ms and relMSE; no other run is both faster and more accurate): {}.",
        steps.join(" → ")
    );
    if mixed_components(results).is_some() {
        line.push_str(
            " Its runs' errors are against different reference components (column reference): not comparable.",
        );
    }
    Some(line)
}
