//! The time-versus-error plot: one point per run with quality data, the Pareto front joined.

use std::path::Path;

use plotters::prelude::*;

use super::{axis_max, chart_svg, stage_color, ChartFrame, Mark};
use crate::measure::results::RunResult;
use crate::report::glance::{component_of, mixed_components};
use crate::report::pareto::{pareto_front, ranked_component, time_error_points_of};
use crate::{Error, Result};

/// Time versus error: one point per run with quality (technique and setting), the Pareto
/// front joined by a line and drawn filled, the others hollow. The error is every run's against
/// one component ([`ranked_component`]), which the axis names; only for results files that hold
/// each run's own errors alone is it each run's own, each legend entry naming its component
/// where they differ ("vs multi-bounce"). Errors when no run has both.
pub fn time_vs_error_svg(results: &[RunResult], path: &Path, title: &str) -> Result<()> {
    let (points, runs) = time_error_points_of(results);
    let ranked = ranked_component(results);
    let mixed = ranked.is_none() && mixed_components(results).is_some();
    let y_desc = match ranked {
        Some(c) => format!("relative MSE against the {c} reference (mean)"),
        None => "relative MSE against the run's reference component (mean)".to_string(),
    };
    if points.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no run has both a frame time and an error against the reference (run with --quality)",
            path.display()
        )));
    }
    let front = pareto_front(&points);
    let xmax = axis_max(points.iter().map(|p| p.1).fold(0.0, f64::max), 1.15);
    let ymax = axis_max(points.iter().map(|p| p.2).fold(0.0, f64::max), 1.15);
    let frame = ChartFrame {
        title,
        size: (1000, 600),
        label_areas: (50, 80),
        x_desc: "time per frame (ms; median frame, else Σ stage medians)",
        y_desc: Some(&y_desc),
        categories: None,
        legend_title: "technique, setting",
    };
    chart_svg(path, &frame, 0.0..xmax, 0.0..ymax, |chart| {
        chart.draw_series(LineSeries::new(
            front.iter().map(|&i| (points[i].1, points[i].2)),
            BLACK.stroke_width(1),
        ))?;
        let mut entries = Vec::new();
        for (k, (label, t, e)) in points.iter().enumerate() {
            let color = stage_color(k);
            let on_front = front.contains(&k);
            let style = if on_front {
                color.filled()
            } else {
                color.stroke_width(2)
            };
            chart.draw_series(std::iter::once(Circle::new((*t, *e), 6, style)))?;
            let mark = if on_front { " (Pareto front)" } else { "" };
            let vs = match component_of(&results[runs[k]]) {
                Some(c) if mixed => format!(" vs {c}"),
                _ => String::new(),
            };
            entries.push((format!("{label}{vs}{mark}"), color, Mark::Box));
        }
        Ok(entries)
    })
}
