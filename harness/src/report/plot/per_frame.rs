//! The per-frame quality plot: each run's error against the reference, frame by frame (the lag
//! of incremental techniques).

use std::path::Path;

use super::lines_svg;
use crate::measure::results::RunResult;
use crate::report::runs::run_label;
use crate::{Error, Result};

/// The metrics [`per_frame_lines`] and [`quality_over_frames_svg`] take.
pub const PER_FRAME_METRICS: &[&str] = &["rmse", "rel_mse", "mae", "bias", "flip", "flicker"];

/// Checks `metric` is one of [`PER_FRAME_METRICS`]; the error names option `metric`.
pub fn check_per_frame_metric(metric: &str) -> Result<()> {
    if !PER_FRAME_METRICS.contains(&metric) {
        let (last, rest) = PER_FRAME_METRICS.split_last().expect("not empty");
        return Err(Error::param(
            "metric",
            format!("expected {} or {last} (got '{metric}')", rest.join(", ")),
        ));
    }
    Ok(())
}

/// One labelled line of a chart: its label and its (x, y) points.
pub type Line = (String, Vec<(f64, f64)>);

/// Each result's per-frame values of `metric` (see [`PER_FRAME_METRICS`]) as (frame, value)
/// points, labelled "technique @ scene"; results without any are left out.
pub fn per_frame_lines(results: &[RunResult], metric: &str) -> Result<Vec<Line>> {
    check_per_frame_metric(metric)?;
    let pick = |f: &crate::measure::metrics::FrameQuality| -> Option<f64> {
        match metric {
            "rmse" => Some(f.rmse),
            "rel_mse" => Some(f.rel_mse),
            "mae" => Some(f.mae),
            "bias" => Some(f.bias),
            "flip" => Some(f.flip_mean),
            "flicker" => f.temporal,
            _ => None,
        }
    };
    let mut lines: Vec<Line> = results
        .iter()
        .filter_map(|r| {
            let q = r.quality.as_ref()?;
            let pts: Vec<(f64, f64)> = q
                .frames
                .iter()
                .filter_map(|f| {
                    pick(f)
                        .filter(|v| v.is_finite())
                        .map(|v| (f.frame as f64, v))
                })
                .collect();
            (!pts.is_empty()).then(|| (run_label(r), pts))
        })
        .collect();
    if metric == "flicker" {
        lines.extend(floor_lines(results));
    }
    Ok(lines)
}

/// The reference's flicker floor of each scene, as a flat line over the frames its runs
/// compared (one per scene and floor): a flicker line at it is at the floor.
fn floor_lines(results: &[RunResult]) -> Vec<Line> {
    let mut out: Vec<Line> = Vec::new();
    for r in results {
        let Some(q) = r.quality.as_ref() else {
            continue;
        };
        let Some(floor) = q.flicker_floor.filter(|f| f.is_finite()) else {
            continue;
        };
        let frames = q.frames.iter().filter(|f| f.temporal.is_some());
        let (lo, hi) = frames.fold((f64::MAX, f64::MIN), |(lo, hi), f| {
            (lo.min(f.frame as f64), hi.max(f.frame as f64))
        });
        let label = format!("reference's flicker floor @ {}", r.scene);
        if lo <= hi && !out.iter().any(|(l, p)| *l == label && p[0].1 == floor) {
            out.push((label, vec![(lo, floor), (hi, floor)]));
        }
    }
    out
}

/// Per-frame image error against the reference for each result that has quality data: one
/// line per result ("technique @ scene"), frame number on the x axis, `metric` (one of
/// [`PER_FRAME_METRICS`]) on the y axis. This is the lag plot of incremental techniques: their
/// error grows while the light moves. Errors when no result has a value.
pub fn quality_over_frames_svg(
    results: &[RunResult],
    metric: &str,
    path: &Path,
    title: &str,
) -> Result<()> {
    let lines = per_frame_lines(results, metric)?;
    if lines.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no results hold per-frame '{metric}' values",
            path.display()
        )));
    }
    lines_svg(&lines, path, title, "frame", metric)
}
