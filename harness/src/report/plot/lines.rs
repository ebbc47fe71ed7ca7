//! The line chart: labelled lines of (x, y) points, for any two quantities.

use std::path::Path;

use plotters::prelude::*;

use super::{axis_max, chart_svg, stage_color, ChartFrame, Mark};
use crate::{Error, Result};

/// A line chart: one labelled line of (x, y) points per entry, a legend, axis names. The y axis
/// starts at zero unless a value is negative. Errors when there are no points.
pub fn lines_svg(
    lines: &[(String, Vec<(f64, f64)>)],
    path: &Path,
    title: &str,
    x_desc: &str,
    y_desc: &str,
) -> Result<()> {
    let all = || {
        lines
            .iter()
            .flat_map(|(_, p)| p.iter())
            .filter(|p| p.0.is_finite() && p.1.is_finite())
    };
    if all().next().is_none() {
        return Err(Error::Invalid(format!(
            "{}: nothing to plot",
            path.display()
        )));
    }
    let (x0, x1) = all().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let x1 = if x1 > x0 { x1 } else { x0 + 1.0 };
    let ymax = axis_max(all().map(|p| p.1).fold(0.0, f64::max), 1.1);
    let ymin = all().map(|p| p.1).fold(0.0, f64::min);
    let ymin = if ymin < 0.0 {
        -axis_max(-ymin, 1.1)
    } else {
        0.0
    };
    let (width, height) = (1000u32, 600u32);
    let frame = ChartFrame {
        title,
        size: (width, height),
        label_areas: (50, 80),
        x_desc,
        y_desc: Some(y_desc),
        categories: None,
        legend_title: "series",
    };
    chart_svg(path, &frame, x0..x1, ymin..ymax, |chart| {
        let mut entries = Vec::new();
        for (k, (label, pts)) in lines.iter().enumerate() {
            let color = stage_color(k);
            let pts: Vec<(f64, f64)> = pts
                .iter()
                .copied()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .collect();
            chart.draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))?;
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
            entries.push((label.clone(), color, Mark::Line(2)));
        }
        Ok(entries)
    })
}
