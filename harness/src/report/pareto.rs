//! The time-versus-error points of runs with quality data and their Pareto front.

use super::runs::stage_ms;
use crate::measure::metrics::ComponentErrors;
use crate::measure::results::RunResult;

/// "technique" plus the parameters whose values differ between runs of that technique in
/// `all` (e.g. "laine clamp=3"), to tell sweep points apart.
pub fn distinct_label(all: &[RunResult], r: &RunResult) -> String {
    let mut label = r.technique.clone();
    let setting = distinct_setting(all, r);
    if !setting.is_empty() {
        label.push(' ');
        label.push_str(&setting);
    }
    if all.iter().any(|o| o.scene != r.scene) {
        label.push_str(&format!(" @ {}", r.scene));
    }
    label
}

/// The parameters whose values differ between the runs of `r`'s technique on its scene in
/// `all`, as "name=value" joined by spaces ("" where none differ).
pub fn distinct_setting(all: &[RunResult], r: &RunResult) -> String {
    let same: Vec<&RunResult> = all
        .iter()
        .filter(|o| o.technique == r.technique && o.scene == r.scene)
        .collect();
    let mut out: Vec<String> = Vec::new();
    for (k, v) in &r.parameters {
        if same.iter().any(|o| o.parameters.get(k) != Some(v)) {
            out.push(format!(
                "{k}={}",
                v.as_str()
                    .map(String::from)
                    .unwrap_or_else(|| v.to_string())
            ));
        }
    }
    out.join(" ")
}

/// A run's time per frame for the time-versus-error plot: the median of whole frames where
/// they were timed, else the sum of the per-stage medians.
pub fn frame_time_ms(r: &RunResult) -> Option<f64> {
    r.frame
        .as_ref()
        .map(|f| f.frame_ms.median)
        .or_else(|| r.stages.iter().map(stage_ms).sum())
        .filter(|t| t.is_finite())
}

/// The reference component runs are ranked and plotted on: the one every run with quality data
/// has its own errors against; else multi-bounce (the whole indirect light) where every such
/// run was scored against it ([`QualitySummary::components`]); `None` where some run was not
/// (a results file written before runs were scored against both components): then each run's
/// own errors are used, and the tables and the plot say they are not comparable.
///
/// [`QualitySummary::components`]: crate::measure::metrics::QualitySummary::components
pub fn ranked_component(results: &[RunResult]) -> Option<&'static str> {
    let scored: Vec<_> = results.iter().filter_map(|r| r.quality.as_ref()).collect();
    let has = |c: &str| scored.iter().all(|q| q.against(c).is_some());
    let mut own: Vec<&str> = scored.iter().map(|q| q.own_component()).collect();
    own.dedup();
    (ComponentErrors::NAMES.into_iter())
        .find(|&c| own == [c])
        .or_else(|| Some("multi-bounce").filter(|&c| has(c)))
}

/// A run's mean relative MSE against `component` (its own errors where `None`); `None` without
/// quality data or that component.
pub fn rel_mse_against(r: &RunResult, component: Option<&str>) -> Option<f64> {
    let q = r.quality.as_ref()?;
    match component {
        Some(c) => q.against(c).map(|e| e.rel_mse.mean),
        None => Some(q.rel_mse.mean),
    }
}

/// The points of the time-versus-error plot: (label, frame ms, mean relative MSE against
/// [`ranked_component`]), runs without quality left out.
pub fn time_error_points(results: &[RunResult]) -> Vec<(String, f64, f64)> {
    time_error_points_of(results).0
}

/// [`time_error_points`] with the index in `results` of the run each point is of: runs with
/// quality data, a frame time and an error that are numbers.
pub(super) fn time_error_points_of(results: &[RunResult]) -> (Vec<(String, f64, f64)>, Vec<usize>) {
    let component = ranked_component(results);
    let mut points = Vec::new();
    let mut runs = Vec::new();
    for (i, r) in results.iter().enumerate() {
        let (Some(e), Some(t)) = (rel_mse_against(r, component), frame_time_ms(r)) else {
            continue;
        };
        if e.is_finite() {
            points.push((distinct_label(results, r), t, e));
            runs.push(i);
        }
    }
    (points, runs)
}

/// Indices of the Pareto front of (time, error) points: those no other point beats in both
/// (at most equal in one and lower in the other), ordered by time.
pub fn pareto_front(points: &[(String, f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        points[a]
            .1
            .total_cmp(&points[b].1)
            .then(points[a].2.total_cmp(&points[b].2))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in order {
        if points[i].2 < best {
            best = points[i].2;
            front.push(i);
        }
    }
    front
}
