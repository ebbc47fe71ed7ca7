//! The stacked bar chart: one horizontal bar per run, split into its stages.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{axis_max, category, chart_svg, label_width, stage_color, Axis, Categories};
use super::{CategoryAxis, ChartFrame, Mark, FONT, LEGEND_W};
use crate::measure::results::RunResult;
use crate::report::runs::{run_label, stage_ms, stage_names};
use crate::report::Cell;
use crate::{Error, Result};

/// One horizontal bar per run ("technique @ scene", first run on top), stacked by stage in
/// execution order (median ms: flushed wall time, else GPU timestamps), the total
/// written after each bar, and a legend of stage colours. Errors on empty `results`.
pub fn stacked_bar_svg(results: &[RunResult], path: &Path, title: &str) -> Result<()> {
    if results.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no results to plot",
            path.display()
        )));
    }
    let n = results.len();
    let names = stage_names(results);
    let labels: Vec<String> = results.iter().map(run_label).collect();
    let bars = stage_segments(results, &names);
    let totals: Vec<Option<f64>> = bars.iter().map(|b| b.last().map(|s| s.2)).collect();
    let xmax = axis_max(totals.iter().flatten().copied().fold(0.0, f64::max), 1.18);

    let label_area = label_width(&labels, 15.0);
    let width = (label_area + 640 + LEGEND_W).max(1000);
    let height = (130 + 44 * n as u32)
        .max(120 + 24 * names.len() as u32)
        .max(280);
    // Slot 0 is at the bottom; run i is drawn in slot n - 1 - i.
    let label_of = |v: &f64| {
        category(*v, n)
            .map(|p| labels[n - 1 - p].clone())
            .unwrap_or_default()
    };
    let frame = ChartFrame {
        title,
        size: (width, height),
        label_areas: (50, label_area),
        x_desc: "milliseconds (median)",
        y_desc: None,
        categories: Some(CategoryAxis {
            axis: Axis::Y,
            slots: n,
            label: &label_of,
        }),
        legend_title: "stages",
    };
    chart_svg(path, &frame, 0.0..xmax, Categories(n), |chart| {
        for (i, bar) in bars.iter().enumerate() {
            let y = (n - 1 - i) as f64;
            chart.draw_series(bar.iter().map(|&(k, x0, x1)| {
                Rectangle::new([(x0, y - 0.32), (x1, y + 0.32)], stage_color(k).filled())
            }))?;
            if let Some(total) = totals[i] {
                let text =
                    TextStyle::from((FONT, 14).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
                chart.draw_series(std::iter::once(
                    EmptyElement::at((total, y))
                        + Text::new(
                            format!("{} ms", Cell::Ms(Some(total)).display()),
                            (6, 0),
                            text,
                        ),
                ))?;
            }
        }
        Ok(names
            .iter()
            .enumerate()
            .map(|(k, s)| (s.clone(), stage_color(k), Mark::Box))
            .collect())
    })
}

/// Each run's bar segments: (stage index in `names`, start, end), in the run's execution order.
fn stage_segments(results: &[RunResult], names: &[String]) -> Vec<Vec<(usize, f64, f64)>> {
    results
        .iter()
        .map(|r| {
            let mut x = 0.0;
            r.stages
                .iter()
                .filter_map(|s| {
                    let v = stage_ms(s)?.max(0.0);
                    let k = names.iter().position(|n| *n == s.name)?;
                    x += v;
                    Some((k, x - v, x))
                })
                .collect()
        })
        .collect()
}
