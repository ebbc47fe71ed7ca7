//! The sweep plot: each stage's time and their total against a swept parameter.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::{axis_max, category, chart_svg, stage_color, Axis, Categories, CategoryAxis};
use super::{ChartFrame, Mark, PlotResult, LEGEND_W};
use crate::measure::results::RunResult;
use crate::report::runs::{stage_ms, stage_names, stage_sum};
use crate::{Error, Result};

/// Per-stage median times (one coloured line each: flushed wall time, else GPU timestamps)
/// and their total (black) against a swept value: `points` are (x label, run) in the
/// order they are placed on the categorical x axis named `x_name`. A stage missing at some
/// point breaks its line. Errors on empty `points`.
pub fn sweep_plot_svg(
    points: &[(String, RunResult)],
    path: &Path,
    title: &str,
    x_name: &str,
) -> Result<()> {
    if points.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no sweep points to plot",
            path.display()
        )));
    }
    let m = points.len();
    let names = stage_names(points.iter().map(|(_, r)| r));
    let series: Vec<Vec<Option<f64>>> = names
        .iter()
        .map(|name| {
            points
                .iter()
                .map(|(_, r)| r.stage(name).and_then(stage_ms))
                .collect()
        })
        .collect();
    let totals: Vec<Option<f64>> = points.iter().map(|(_, r)| stage_sum(r)).collect();
    let ymax = axis_max(
        series
            .iter()
            .flatten()
            .chain(&totals)
            .flatten()
            .copied()
            .fold(0.0, f64::max),
        1.1,
    );
    let x_labels: Vec<String> = points.iter().map(|(x, _)| x.clone()).collect();

    let width = (160 + 70 * m as u32 + LEGEND_W).max(1000);
    let height = 600u32.max(120 + 24 * (names.len() as u32 + 1));
    let label_of = |v: &f64| {
        category(*v, m)
            .map(|j| x_labels[j].clone())
            .unwrap_or_default()
    };
    let frame = ChartFrame {
        title,
        size: (width, height),
        label_areas: (60, 70),
        x_desc: x_name,
        y_desc: Some("milliseconds (median)"),
        categories: Some(CategoryAxis {
            axis: Axis::X,
            slots: m,
            label: &label_of,
        }),
        legend_title: "stages",
    };
    chart_svg(path, &frame, Categories(m), 0.0..ymax, |chart| {
        for (k, values) in series.iter().enumerate() {
            draw_line(chart, values, stage_color(k), 2)?;
        }
        draw_line(chart, &totals, BLACK, 3)?;

        let mut entries: Vec<_> = names
            .iter()
            .enumerate()
            .map(|(k, s)| (s.clone(), stage_color(k), Mark::Line(2)))
            .collect();
        entries.push(("total (Σ stages)".to_string(), BLACK, Mark::Line(3)));
        Ok(entries)
    })
}

/// One series over the sweep's slots: a line of `width` through the present values, broken
/// where a value is missing, with a dot on each.
fn draw_line(
    chart: &mut ChartContext<'_, SVGBackend<'_>, Cartesian2d<Categories, RangedCoordf64>>,
    values: &[Option<f64>],
    color: RGBColor,
    width: u32,
) -> PlotResult {
    let pts: Vec<(f64, f64)> = values
        .iter()
        .enumerate()
        .filter_map(|(j, v)| v.map(|v| (j as f64, v)))
        .collect();
    // Contiguous runs of present values, so that a missing value breaks the line.
    for run in pts.chunk_by(|a, b| b.0 == a.0 + 1.0) {
        chart.draw_series(LineSeries::new(
            run.iter().copied(),
            color.stroke_width(width),
        ))?;
    }
    chart.draw_series(
        pts.iter()
            .map(|&p| Circle::new(p, 3 + width, color.filled())),
    )?;
    Ok(())
}
