//! The first screen of a report: per run, what a frame costs and how far the run is from the
//! reference, with its Pareto rank ([`glance_table`]); and the Pareto front as one line
//! ([`pareto_line`]), which the stage table's notes end with (terminal and Markdown).
//!
//! Reads: [`RunResult`]s with quality data. Writes: a [`Table`], a line.
//!
//! Every run is scored against both indirect components (one-bounce and multi-bounce,
//! [`ComponentErrors`]); the tables show both with the run's own marked ([`error_cell`]), and
//! ranks and fronts are taken on one component ([`ranked_component`]). Only runs from results
//! files written before that are ranked on their own components, said not comparable where those
//! differ.

use super::pareto::{
    distinct_label, frame_time_ms, pareto_front, ranked_component, time_error_points_of,
};
use super::table::{Cell, Table};
use crate::measure::metrics::ComponentErrors;
use crate::measure::results::RunResult;

/// The reference component a run's errors are against ("one-bounce", "multi-bounce",
/// "direct"): the first item of its quality's reference label; `None` without quality.
pub fn component_of(r: &RunResult) -> Option<&str> {
    r.quality.as_ref().map(|q| q.own_component())
}

/// A cell of `r`'s error `metric` against `component` ([`ComponentErrors::NAMES`]), marked
/// ([`Cell::Own`]) where that is the run's own component; "–" where the run has no such error.
pub fn error_cell(
    r: &RunResult,
    component: &str,
    metric: fn(&ComponentErrors) -> f64,
    decimals: u8,
) -> Cell {
    let q = r.quality.as_ref();
    let v = q.and_then(|q| q.against(component)).map(|e| metric(&e));
    match q.is_some_and(|q| q.own_component() == component) {
        true => Cell::Own(v, decimals),
        false => Cell::Num(v, decimals),
    }
}

/// The headers of [`error_cell`]s of `metric` ("relMSE one-bounce", "relMSE multi-bounce").
pub(super) fn error_columns(metric: &str) -> impl Iterator<Item = String> + '_ {
    (ComponentErrors::NAMES.into_iter()).map(move |c| format!("{metric} {c}"))
}

/// The note under a table of [`error_cell`]s: what the mark means and which component ranks
/// are taken on (or, for older results files, that they are not comparable).
pub(super) fn errors_note(results: &[RunResult]) -> String {
    let ranked = match ranked_component(results) {
        Some(c) => format!("Pareto ranks and fronts are taken on the errors against {c}."),
        None => match mixed_components(results) {
            Some(mixed) => format!(
                "Some of these results files hold each run's errors against its own component \
                 only, and those differ ({mixed}): their Pareto ranks are not comparable."
            ),
            None => "Pareto ranks are taken on each run's own errors.".to_string(),
        },
    };
    format!(
        "Errors against each indirect component of the reference: one-bounce (light that \
         bounced once) and multi-bounce (all bounces); {} marks the run's own, the component its \
         technique computes (column reference). {ranked}",
        super::table::OWN_MARK
    )
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

/// The runs a Pareto front is taken over: one scene at one resolution on one device (a front
/// over runs of different scenes or devices would rank what cannot be compared).
fn group_of(r: &RunResult) -> (String, [u32; 2], String) {
    (
        r.scene.clone(),
        r.resolution,
        super::stages::device_label(r),
    )
}

/// The groups of [`group_of`] among `results`, in first-seen order.
fn groups(results: &[RunResult]) -> Vec<(String, [u32; 2], String)> {
    let mut out: Vec<(String, [u32; 2], String)> = Vec::new();
    for r in results {
        let g = group_of(r);
        if !out.contains(&g) {
            out.push(g);
        }
    }
    out
}

/// A run's label in the glance: [`distinct_label`] (technique, the parameters that tell its
/// runs apart, the scene where several), with the resolution and the device where those differ
/// between the runs.
fn glance_label(results: &[RunResult], r: &RunResult) -> String {
    let mut label = distinct_label(results, r);
    if results.iter().any(|o| o.resolution != r.resolution) {
        label.push_str(&format!(" {}x{}", r.resolution[0], r.resolution[1]));
    }
    let device = super::stages::device_label(r);
    if results
        .iter()
        .any(|o| super::stages::device_label(o) != device)
    {
        label.push_str(&format!(" on {device}"));
    }
    label
}

/// A group ([`group_of`]), its runs' time-versus-error points, and each point's run's index.
type GroupPoints = (
    (String, [u32; 2], String),
    Vec<(String, f64, f64)>,
    Vec<usize>,
);

/// Per group ([`groups`], in order): the group, and its runs' time-versus-error points each
/// with the index of its run in `results`.
fn points_by_group(results: &[RunResult]) -> Vec<GroupPoints> {
    let (points, runs) = time_error_points_of(results);
    groups(results)
        .into_iter()
        .map(|g| {
            let members: Vec<usize> = (0..points.len())
                .filter(|&p| group_of(&results[runs[p]]) == g)
                .collect();
            let sub = members.iter().map(|&p| points[p].clone()).collect();
            let of = members.iter().map(|&p| runs[p]).collect();
            (g, sub, of)
        })
        .collect()
}

/// Each run's Pareto rank within its group ([`group_of`]); `None` for a run without both a
/// frame time and an error.
fn ranks_by_group(results: &[RunResult]) -> Vec<Option<usize>> {
    let mut rank = vec![None; results.len()];
    for (_, sub, of) in points_by_group(results) {
        for (k, r) in pareto_ranks(&sub).into_iter().enumerate() {
            rank[of[k]] = Some(r);
        }
    }
    rank
}

/// The first screen of a report: one row per run, fastest first: frame ms, FPS, its own
/// reference component, relMSE and FLIP against each component (its own marked) and its Pareto
/// rank among the runs of its scene, resolution and device. `None` when no run has quality data (there is nothing to
/// weigh the time against).
pub fn glance_table(results: &[RunResult]) -> Option<Table> {
    const NAMES: [&str; 2] = ComponentErrors::NAMES;
    if results.iter().all(|r| r.quality.is_none()) {
        return None;
    }
    let ranks = ranks_by_group(results);
    let mut order: Vec<usize> = (0..results.len()).collect();
    order.sort_by(|&a, &b| {
        let t = |i: usize| frame_time_ms(&results[i]).unwrap_or(f64::INFINITY);
        t(a).total_cmp(&t(b))
    });
    let rows = order
        .iter()
        .map(|&i| {
            let r = &results[i];
            [
                Cell::text(glance_label(results, r)),
                Cell::Ms(frame_time_ms(r)),
                Cell::Num(r.frame.as_ref().map(|f| f.fps), 1),
                Cell::text(component_of(r).unwrap_or("–")),
            ]
            .into_iter()
            .chain(NAMES.map(|c| error_cell(r, c, |e| e.rel_mse.mean, 4)))
            .chain(NAMES.map(|c| error_cell(r, c, |e| e.flip_mean.mean, 4)))
            .chain([Cell::Num(ranks[i].map(|k| k as f64), 0)])
            .collect()
        })
        .collect();
    let notes = vec![
        "frame ms: the median whole frame where frames were timed, else the sum of the stages' \
         medians; FPS: 1000 / mean frame time; relMSE (of indirect irradiance) and FLIP: means over \
         the compared frames; Pareto rank, among the runs of the same scene, resolution and \
         device: 1 on the front (no other run is as fast or faster at no higher relMSE; of two \
         identical runs the first listed), 2 on the front once those are set aside, and so on. \
         The full per-stage table follows."
            .to_string(),
        errors_note(results),
    ];
    let columns = ["run", "frame ms", "FPS", "reference"]
        .map(String::from)
        .into_iter()
        .chain(error_columns("relMSE"))
        .chain(error_columns("FLIP"))
        .chain(["Pareto rank".to_string()])
        .collect();
    Some(Table {
        title: "At a glance: frame time against error".to_string(),
        columns,
        rows,
        notes,
    })
}

/// The Pareto front in one line: "Pareto front (frame ms, relMSE): a 1.20 ms 0.9812 → b …",
/// fastest first, one front per scene, resolution and device where the runs span several
/// ("… on cornell 256x192: …; on sibenik …"), with a warning where the runs' errors are
/// against different components; `None` when no run has both numbers.
pub fn pareto_line(results: &[RunResult]) -> Option<String> {
    let all = points_by_group(results);
    let several = all.len() > 1;
    let mut fronts: Vec<String> = Vec::new();
    for (g, sub, _) in &all {
        let steps: Vec<String> = pareto_front(sub)
            .iter()
            .map(|&k| {
                let (label, t, e) = &sub[k];
                format!("{label} {t:.2} ms {e:.4}")
            })
            .collect();
        if steps.is_empty() {
            continue;
        }
        let on = if several {
            format!(" on {} {}x{} ({})", g.0, g.1[0], g.1[1], g.2)
        } else {
            String::new()
        };
        fronts.push(format!("{on}: {}", steps.join(" → ")));
    }
    if fronts.is_empty() {
        return None;
    }
    let against = match ranked_component(results) {
        Some(c) => format!(" against {c}"),
        None => String::new(),
    };
    let mut line = format!(
        "Pareto front (frame ms and relMSE{against}; no other run is as fast or faster at no higher error){}.",
        fronts.join(";")
    );
    if ranked_component(results).is_none() && mixed_components(results).is_some() {
        line.push_str(
            " Its runs' errors are against different reference components (column reference): not comparable.",
        );
    }
    Some(line)
}
