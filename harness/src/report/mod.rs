//! Tables and plots rendered from results files ([`RunResult`]) only — never typed by hand.
//!
//! # Tables
//!
//! A [`Table`] is a title, column headers, rows of [`Cell`]s and notes (how the numbers were
//! taken, on which device). It is built from results by
//!
//! * [`stage_table`]: one row per run (scene, technique, resolution), one column per stage (the
//!   union of the runs' stage names, in execution order), then "Σ stages", the median frame time
//!   and FPS. A stage cell is the median flushed CPU wall time (Laine's per-task method), else the
//!   median GPU timestamp time ([`StageResult::best_ms`]). This is the table `gibench run` prints and
//!   `gibench report` writes.
//! * [`stage_table_detailed`]: one run, one row per stage, with median/mean/p5/p95/min/max of both
//!   the GPU timestamp and the wall-clock timings (`gibench report --detailed`);
//! * [`glance_table`]: the first screen of a page: per run its frame time, error against its
//!   reference component and Pareto rank ([`pareto_line`]: the front in one line, the stage
//!   table's last note);
//! * [`equal_time_table`]: the settings `gibench run --equal-time` found for a budget and the
//!   errors at them;
//! * [`roofline_table`]: one run, one row per GPU stage, its achieved fractions of the device's
//!   measured bandwidth and arithmetic rate ([`crate::measure::roofline`]; also `--detailed`).
//!
//! and rendered by
//!
//! * [`Table::to_terminal`]: aligned plain-text columns for stdout, notes below;
//! * [`Table::to_markdown`]: a `###` title, a GitHub-flavoured pipe table (numeric columns
//!   right-aligned) and the notes as paragraphs after it;
//! * [`Table::to_csv`]: RFC 4180 (comma separated, CRLF line ends, fields with a comma, quote or
//!   line break quoted and quotes doubled). The header row is the first record. **The CSV holds
//!   data only: no title and no notes** (so that any CSV reader loads it); millisecond cells carry
//!   four decimals and a missing value is an empty field;
//! * [`Table::to_latex`]: a booktabs `tabular` (`\toprule`, `\midrule`, `\bottomrule`; needs
//!   `\usepackage{booktabs}`) preceded by the title as a `%` comment and followed by the notes as
//!   a `\footnotesize` paragraph, ready to `\input` inside a `table` float. LaTeX specials
//!   (`& % $ # _ { } ~ ^ \`) are escaped.
//!
//! [`write_tables`] writes the Markdown, CSV and LaTeX renderings next to each other, atomically.
//!
//! In the terminal, Markdown and LaTeX renderings a millisecond value has two decimals (three
//! below 0.1 ms, so that short stages do not all read 0.00) and a missing value is "–".
//!
//! # Plots
//!
//! SVG files drawn with plotters' SVG backend (text stays text: `<text>` elements, no embedded
//! fonts), rendered into memory and written atomically, each with the same figure as a vector
//! PDF beside it (`name.pdf`, [`svg_to_pdf`]: for `\includegraphics`):
//!
//! * [`stacked_bar_svg`]: one horizontal bar per run, labelled "technique @ scene", stacked by
//!   stage in execution order (same value rule as [`stage_table`]), with the total at the end of
//!   the bar and a legend mapping colours to stage names;
//! * [`sweep_plot_svg`]: one line per stage plus a total line against a swept parameter (tile
//!   count, VPL count, ...), categorical x axis in the given order.
//!
//! A stage keeps its colour within a plot; colours follow the stage order of the plot's runs.
//!
//! [`RunResult`]: crate::measure::results::RunResult
//! [`StageResult::best_ms`]: crate::measure::results::StageResult::best_ms

pub mod compare;
mod csv;
mod equal_time;
mod glance;
pub mod html;
mod latex;
mod markdown;
mod pareto;
mod plot;
mod roofline;
mod runs;
mod speedup;
mod stages;
mod table;
mod terminal;
#[cfg(test)]
mod tests;

pub use equal_time::equal_time_table;
pub use glance::{component_of, glance_table, pareto_line, pareto_ranks};
pub use pareto::{distinct_label, frame_time_ms, pareto_front, time_error_points};
pub use plot::{
    check_per_frame_metric, lines_svg, pdf_path, per_frame_lines, quality_over_frames_svg,
    stacked_bar_svg, svg_to_pdf, sweep_plot_svg, time_vs_error_svg, Line, PER_FRAME_METRICS,
};
pub use roofline::roofline_table;
pub use runs::stage_ms;
pub use speedup::speedup_table;
pub use stages::{
    device_label, stage_table, stage_table_detailed, tile_balance_cell, vpl_count_cell,
};
pub use table::{column_key, write_tables, write_tables_as, Cell, Table, TableFormat};
pub use terminal::TERMINAL_WIDTH;
