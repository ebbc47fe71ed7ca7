//! The chart set-up every plot shares, written once: an SVG canvas with a legend column, a
//! captioned chart with its axes, label fonts and mesh, the legend, and the atomic write; plus
//! the stage colours, the categorical axis and axis helpers. One module per plot kind.

use std::path::Path;

use plotters::coord::ranged1d::{AsRangedCoord, DefaultFormatting, KeyPointHint, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::{Error, Result};

mod lines;
mod per_frame;
mod stacked_bar;
mod sweep;
mod time_error;

pub use lines::lines_svg;
pub use per_frame::{
    check_per_frame_metric, per_frame_lines, quality_over_frames_svg, Line, PER_FRAME_METRICS,
};
pub use stacked_bar::stacked_bar_svg;
pub use sweep::sweep_plot_svg;
pub use time_error::time_vs_error_svg;

type PlotResult = std::result::Result<(), Box<dyn std::error::Error>>;

const FONT: &str = "sans-serif";
/// Width of the legend column to the right of a plot, in pixels.
const LEGEND_W: u32 = 240;

/// Colour of the `i`-th stage: Tableau 10, then plotters' 99-colour palette.
fn stage_color(i: usize) -> RGBColor {
    const TABLEAU: [(u8, u8, u8); 10] = [
        (78, 121, 167),
        (242, 142, 43),
        (225, 87, 89),
        (118, 183, 178),
        (89, 161, 79),
        (237, 201, 72),
        (176, 122, 161),
        (255, 157, 167),
        (156, 117, 95),
        (186, 176, 172),
    ];
    match TABLEAU.get(i) {
        Some(&(r, g, b)) => RGBColor(r, g, b),
        None => {
            let (r, g, b) = Palette99::pick(i - TABLEAU.len()).rgb();
            RGBColor(r, g, b)
        }
    }
}

/// How a legend entry is drawn.
#[derive(Clone, Copy)]
enum Mark {
    Box,
    Line(u32),
}

/// Draws a legend (title, then one swatch and name per entry) into `area`.
fn draw_legend(
    area: &DrawingArea<SVGBackend, Shift>,
    title: &str,
    entries: &[LegendEntry],
) -> PlotResult {
    let style = TextStyle::from((FONT, 14).into_font())
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let top = 60;
    let bold = TextStyle::from((FONT, 15, FontStyle::Bold).into_font())
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    area.draw(&Text::new(title.to_string(), (10, top), bold))?;
    for (k, (name, color, mark)) in entries.iter().enumerate() {
        let y = top + 24 * (k as i32 + 1);
        match mark {
            Mark::Box => area.draw(&Rectangle::new([(10, y - 6), (26, y + 6)], color.filled()))?,
            Mark::Line(w) => area.draw(&PathElement::new(
                vec![(8, y), (28, y)],
                color.stroke_width(*w),
            ))?,
        }
        area.draw(&Text::new(name.clone(), (34, y), style.clone()))?;
    }
    Ok(())
}

/// Renders into an SVG string with `draw`, then writes it to `path` atomically, and the same
/// figure as a PDF beside it ([`pdf_path`], [`svg_to_pdf`]) for `\includegraphics`.
fn write_svg(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<SVGBackend, Shift>) -> PlotResult,
) -> Result<()> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(root)
            .map_err(|e| Error::Invalid(format!("{}: plotting failed: {e}", path.display())))?;
    }
    let pdf = svg_to_pdf(&svg)
        .map_err(|e| Error::Invalid(format!("{}: no PDF of the figure: {e}", path.display())))?;
    crate::output::write_atomic(path, svg.as_bytes())?;
    crate::output::write_atomic(&pdf_path(path), &pdf)
}

/// Where the PDF of the figure at `svg` goes: the same name with `.pdf`.
pub fn pdf_path(svg: &Path) -> std::path::PathBuf {
    svg.with_extension("pdf")
}

/// The SVG `svg` as a one-page vector PDF (svg2pdf), its text set in the system's sans-serif
/// font (DejaVu Sans, Liberation Sans or Arial, the first installed; the fonts are read once
/// per process) and embedded; text is left out where none of them is installed.
pub fn svg_to_pdf(svg: &str) -> std::result::Result<Vec<u8>, String> {
    use std::sync::{Arc, OnceLock};
    static FONTS: OnceLock<Arc<svg2pdf::usvg::fontdb::Database>> = OnceLock::new();
    let fonts = FONTS.get_or_init(|| {
        let mut db = svg2pdf::usvg::fontdb::Database::new();
        db.load_system_fonts();
        let installed = |family: &str| {
            db.faces()
                .any(|f| f.families.iter().any(|(name, _)| name == family))
        };
        match ["DejaVu Sans", "Liberation Sans", "Arial"]
            .into_iter()
            .find(|f| installed(f))
        {
            Some(family) => db.set_sans_serif_family(family),
            None => eprintln!(
                "warning: no DejaVu Sans, Liberation Sans or Arial font is installed: the figures' \
                 PDFs have no text (apt-get install fonts-dejavu-core); the SVGs are whole"
            ),
        }
        Arc::new(db)
    });
    let options = svg2pdf::usvg::Options {
        fontdb: fonts.clone(),
        ..Default::default()
    };
    let tree = svg2pdf::usvg::Tree::from_str(svg, &options).map_err(|e| e.to_string())?;
    svg2pdf::to_pdf(
        &tree,
        svg2pdf::ConversionOptions::default(),
        svg2pdf::PageOptions::default(),
    )
    .map_err(|e| e.to_string())
}

/// A legend entry: the name, its colour and how its swatch is drawn.
type LegendEntry = (String, RGBColor, Mark);

/// Which axis of a chart.
#[derive(Clone, Copy)]
enum Axis {
    X,
    Y,
}

/// A categorical axis ([`Categories`]): which axis, its slot count and the label of the slot
/// centred on a value.
struct CategoryAxis<'a> {
    axis: Axis,
    slots: usize,
    label: &'a dyn Fn(&f64) -> String,
}

/// What sets one chart apart from the others; [`chart_svg`] draws everything they share.
struct ChartFrame<'a> {
    /// The caption above the chart.
    title: &'a str,
    /// The whole canvas in pixels, the legend column included.
    size: (u32, u32),
    /// Height of the x axis' label area and width of the y axis', in pixels.
    label_areas: (u32, u32),
    /// The x axis' name.
    x_desc: &'a str,
    /// The y axis' name, if it has one.
    y_desc: Option<&'a str>,
    /// A categorical axis, if any; its grid lines are left out.
    categories: Option<CategoryAxis<'a>>,
    /// The heading of the legend column.
    legend_title: &'a str,
}

/// The chart every plot draws, set up once: a white canvas of `frame.size` with a legend column
/// [`LEGEND_W`] wide on the right; a captioned chart over the axes `x` and `y` with its mesh,
/// axis names and label fonts; then `draw` puts in the plot's own series and returns its legend
/// entries, which are drawn under `frame.legend_title`. The SVG is written to `path`
/// atomically.
fn chart_svg<X, Y>(
    path: &Path,
    frame: &ChartFrame,
    x: X,
    y: Y,
    draw: impl FnOnce(
        &mut ChartContext<'_, SVGBackend<'_>, Cartesian2d<X::CoordDescType, Y::CoordDescType>>,
    ) -> std::result::Result<Vec<LegendEntry>, Box<dyn std::error::Error>>,
) -> Result<()>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    write_svg(path, frame.size, |root| {
        root.fill(&WHITE)?;
        let (plot, legend) = root.split_horizontally(frame.size.0 - LEGEND_W);
        let mut chart = ChartBuilder::on(&plot)
            .caption(frame.title, (FONT, 22))
            .margin(12)
            .x_label_area_size(frame.label_areas.0)
            .y_label_area_size(frame.label_areas.1)
            .build_cartesian_2d(x, y)?;
        let mut mesh = chart.configure_mesh();
        match &frame.categories {
            Some(CategoryAxis {
                axis: Axis::X,
                slots,
                label,
            }) => {
                mesh.disable_x_mesh()
                    .x_labels(*slots)
                    .x_label_formatter(*label);
            }
            Some(CategoryAxis {
                axis: Axis::Y,
                slots,
                label,
            }) => {
                mesh.disable_y_mesh()
                    .y_labels(*slots)
                    .y_label_formatter(*label);
            }
            None => {}
        }
        mesh.x_desc(frame.x_desc);
        if let Some(y_desc) = frame.y_desc {
            mesh.y_desc(y_desc);
        }
        mesh.label_style((FONT, 15))
            .axis_desc_style((FONT, 16))
            .draw()?;
        let entries = draw(&mut chart)?;
        draw_legend(&legend, frame.legend_title, &entries)?;
        root.present()?;
        Ok(())
    })
}

/// A categorical axis of `n` slots: slot `i` is centred on the value `i` and spans `i ± 0.5`; the
/// axis spans `-0.5..n - 0.5` and its key points (labels) are the slot centres. (plotters'
/// segmented slice axis misplaces a single category, so the plots use this instead.)
#[derive(Clone)]
struct Categories(usize);

impl Ranged for Categories {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let t = (value + 0.5) / self.0.max(1) as f64;
        (limit.0 as f64 + (limit.1 - limit.0) as f64 * t).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let step = self.0.div_ceil(hint.max_num_points().max(1)).max(1);
        (0..self.0).step_by(step).map(|i| i as f64).collect()
    }

    fn range(&self) -> std::ops::Range<f64> {
        -0.5..self.0 as f64 - 0.5
    }
}

/// The category index of an axis value (labels are asked for at slot centres only).
fn category(v: f64, n: usize) -> Option<usize> {
    let i = v.round();
    (i >= 0.0 && (i as usize) < n && (v - i).abs() < 1e-6).then_some(i as usize)
}

/// Pixel width for a label area holding `labels` (plotters' font-less text estimate).
fn label_width(labels: &[String], font_size: f64) -> u32 {
    let chars = labels.iter().map(|l| l.chars().count()).max().unwrap_or(0) as f64;
    (20.0 + chars * font_size * 0.47).clamp(40.0, 480.0) as u32
}

/// Upper end of a value axis holding values up to `max`.
fn axis_max(max: f64, headroom: f64) -> f64 {
    if max.is_finite() && max > 0.0 {
        max * headroom
    } else {
        1.0
    }
}
