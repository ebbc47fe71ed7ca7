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
//!   the GPU timestamp and the wall-clock timings (`gibench report --detailed`).
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
//! fonts), rendered into memory and written atomically:
//!
//! * [`stacked_bar_svg`]: one horizontal bar per run, labelled "technique @ scene", stacked by
//!   stage in execution order (same value rule as [`stage_table`]), with the total at the end of
//!   the bar and a legend mapping colours to stage names;
//! * [`sweep_plot_svg`]: one line per stage plus a total line against a swept parameter (tile
//!   count, VPL count, ...), categorical x axis in the given order.
//!
//! A stage keeps its colour within a plot; colours follow the stage order of the plot's runs.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::results::{RunResult, StageKind, StageResult};
use crate::stats::Stats;
use crate::{Error, Result};

/// One table cell.
#[derive(Clone, Debug, PartialEq)]
pub enum Cell {
    /// Text, left-aligned.
    Text(String),
    /// Milliseconds, right-aligned; `None` renders as "–" (empty in CSV).
    Ms(Option<f64>),
    /// A number with the given count of decimals, right-aligned; `None` as for [`Cell::Ms`].
    Num(Option<f64>, u8),
}

impl Cell {
    /// A text cell.
    pub fn text(s: impl Into<String>) -> Cell {
        Cell::Text(s.into())
    }

    fn is_numeric(&self) -> bool {
        matches!(self, Cell::Ms(_) | Cell::Num(..))
    }

    /// The cell as shown in the terminal, Markdown and LaTeX (before escaping).
    pub fn display(&self) -> String {
        match self {
            Cell::Text(s) => s.clone(),
            Cell::Ms(v) => match finite(*v) {
                Some(v) if v.abs() >= LARGE => format!("{v:.3e}"),
                Some(v) if v != 0.0 && v.abs() < 0.1 => format!("{v:.3}"),
                Some(v) => format!("{v:.2}"),
                None => MISSING.to_string(),
            },
            Cell::Num(v, d) => match finite(*v) {
                Some(v) if v.abs() >= LARGE => format!("{v:.3e}"),
                Some(v) => format!("{v:.*}", *d as usize),
                None => MISSING.to_string(),
            },
        }
    }

    /// The cell as a CSV field (unquoted): more decimals for milliseconds, empty when missing.
    fn csv(&self) -> String {
        match self {
            Cell::Text(s) => s.clone(),
            Cell::Ms(v) => finite(*v)
                .map(|v| match v.abs() >= LARGE {
                    true => format!("{v:e}"),
                    false => format!("{v:.4}"),
                })
                .unwrap_or_default(),
            Cell::Num(v, d) => finite(*v)
                .map(|v| match v.abs() >= LARGE {
                    true => format!("{v:e}"),
                    false => format!("{v:.*}", *d as usize),
                })
                .unwrap_or_default(),
        }
    }
}

/// Shown for a missing value.
const MISSING: &str = "–";

/// The widest line [`Table::to_terminal`] writes where its cells allow.
pub const TERMINAL_WIDTH: usize = 120;

/// `text` with its words (split at spaces) wrapped into lines of at most `width` characters;
/// a longer word stands on a line of its own.
fn wrap(text: &str, width: usize) -> String {
    let mut out = String::new();
    let mut len = 0;
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        let w = word.chars().count();
        if len > 0 && len + 1 + w > width {
            out.push('\n');
            len = 0;
        } else if len > 0 {
            out.push(' ');
            len += 1;
        }
        out.push_str(word);
        len += w;
    }
    out
}

/// From this magnitude on, a number is written with an exponent (`1.000e308`, not a cell of
/// 300 digits).
const LARGE: f64 = 1e9;

fn finite(v: Option<f64>) -> Option<f64> {
    v.filter(|v| v.is_finite())
}

/// A table rendered from results. Rows shorter than `columns` are padded with empty cells; cells
/// beyond the last column are not rendered. A column whose cells are all numeric is
/// right-aligned.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    pub title: String,
    pub columns: Vec<String>,
    pub rows: Vec<Vec<Cell>>,
    /// Printed under the table: how the numbers were taken, the device, ...
    pub notes: Vec<String>,
}

impl Table {
    fn cell(&self, row: usize, col: usize) -> Option<&Cell> {
        self.rows[row].get(col)
    }

    fn right_aligned(&self, col: usize) -> bool {
        !self.rows.is_empty()
            && self
                .rows
                .iter()
                .all(|r| r.get(col).is_some_and(Cell::is_numeric))
    }

    /// The displayed text of every cell, padded to the column count.
    fn display_rows(&self) -> Vec<Vec<String>> {
        (0..self.rows.len())
            .map(|r| {
                (0..self.columns.len())
                    .map(|c| self.cell(r, c).map(Cell::display).unwrap_or_default())
                    .collect()
            })
            .collect()
    }

    /// Aligned plain-text columns (two spaces apart), a dashed line under the header, the title
    /// above and the notes below, every line at most [`TERMINAL_WIDTH`] characters where the
    /// cells allow: a table wider than that is folded into blocks, each repeating the leading
    /// text columns (at most three: scene, technique, resolution) with columns grouped by the
    /// rows that have values in them (one technique's stages together), and listing only the
    /// rows with a value in the block; columns without any value are left out; the notes are
    /// wrapped.
    pub fn to_terminal(&self) -> String {
        let rows = self.display_rows();
        let width = |s: &str| s.chars().count();
        let widths: Vec<usize> = (0..self.columns.len())
            .map(|c| {
                rows.iter()
                    .map(|r| width(&r[c]))
                    .chain([width(&self.columns[c])])
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let span = |cols: &[usize]| -> usize {
            cols.iter().map(|c| widths[*c]).sum::<usize>() + 2 * cols.len().saturating_sub(1)
        };
        let all: Vec<usize> = (0..self.columns.len()).collect();
        let keys: Vec<usize> = (0..self.columns.len().min(3))
            .take_while(|c| !self.right_aligned(*c))
            .collect();
        // Blocks of columns: all of them when they fit; else the columns grouped by which rows
        // have a value in them (a technique's own stages; the columns every row has), groups
        // in order of first appearance, each split into blocks that fit after the keys.
        let mut blocks: Vec<Vec<usize>> = Vec::new();
        if span(&all) <= TERMINAL_WIDTH || keys.len() == all.len() {
            blocks.push(all);
        } else {
            let has = |r: &Vec<String>, c: usize| !r[c].is_empty() && r[c] != MISSING;
            let mut groups: Vec<(Vec<bool>, Vec<usize>)> = Vec::new();
            for c in keys.len()..self.columns.len() {
                let signature: Vec<bool> = rows.iter().map(|r| has(r, c)).collect();
                match groups.iter_mut().find(|(s, _)| *s == signature) {
                    Some((_, cols)) => cols.push(c),
                    None => groups.push((signature, vec![c])),
                }
            }
            // Columns without a value in any row are left out of the terminal. A group goes
            // into the current block when it fits there whole, else starts the next.
            let mut block = keys.clone();
            for (_, cols) in groups.into_iter().filter(|(s, _)| s.contains(&true)) {
                let with: Vec<usize> = block.iter().chain(&cols).copied().collect();
                if block.len() > keys.len() && span(&with) > TERMINAL_WIDTH {
                    blocks.push(std::mem::replace(&mut block, keys.clone()));
                }
                for c in cols {
                    block.push(c);
                    if span(&block) > TERMINAL_WIDTH && block.len() > keys.len() + 1 {
                        block.pop();
                        blocks.push(std::mem::replace(&mut block, keys.clone()));
                        block.push(c);
                    }
                }
            }
            blocks.push(block);
        }
        let line = |cols: &[usize], cells: &dyn Fn(usize) -> String| {
            let mut s = String::new();
            for (k, &c) in cols.iter().enumerate() {
                if k > 0 {
                    s.push_str("  ");
                }
                let text = cells(c);
                let pad = " ".repeat(widths[c] - width(&text));
                if self.right_aligned(c) {
                    s.push_str(&pad);
                    s.push_str(&text);
                } else {
                    s.push_str(&text);
                    s.push_str(&pad);
                }
            }
            s.trim_end().to_string()
        };
        let mut out = String::new();
        if !self.title.is_empty() {
            out.push_str(&self.title);
            out.push('\n');
        }
        let folded = blocks.len() > 1;
        for (b, cols) in blocks.iter().enumerate() {
            if b > 0 {
                out.push('\n');
            }
            out.push_str(&line(cols, &|c| self.columns[c].clone()));
            out.push('\n');
            out.push_str(&line(cols, &|c| "-".repeat(widths[c])));
            out.push('\n');
            for r in &rows {
                let shown = !folded
                    || cols[keys.len()..]
                        .iter()
                        .any(|&c| !r[c].is_empty() && r[c] != MISSING);
                if shown {
                    out.push_str(&line(cols, &|c| r[c].clone()));
                    out.push('\n');
                }
            }
        }
        if !self.notes.is_empty() {
            out.push('\n');
            for n in &self.notes {
                out.push_str(&wrap(n, TERMINAL_WIDTH));
                out.push('\n');
            }
        }
        out
    }

    /// A `### title`, a pipe table (header, separator, one line per row; `|` in cells escaped)
    /// and the notes as paragraphs after it.
    pub fn to_markdown(&self) -> String {
        let esc = |s: &str| s.replace('|', "\\|").replace(['\r', '\n'], " ");
        let line = |cells: Vec<String>| format!("| {} |\n", cells.join(" | "));
        let mut out = String::new();
        if !self.title.is_empty() {
            let _ = writeln!(out, "### {}\n", esc(&self.title));
        }
        out.push_str(&line(self.columns.iter().map(|c| esc(c)).collect()));
        out.push_str(&line(
            (0..self.columns.len())
                .map(|c| if self.right_aligned(c) { "---:" } else { "---" }.to_string())
                .collect(),
        ));
        for r in self.display_rows() {
            out.push_str(&line(r.iter().map(|c| esc(c)).collect()));
        }
        for n in &self.notes {
            let _ = write!(out, "\n{n}\n");
        }
        out
    }

    /// RFC 4180 CSV: the header record, then one record per row; CRLF line ends. No title, no
    /// notes (see the module documentation).
    pub fn to_csv(&self) -> String {
        let mut out = String::new();
        let mut record = |fields: Vec<String>| {
            let fields: Vec<String> = fields.iter().map(|f| csv_quote(f)).collect();
            out.push_str(&fields.join(","));
            out.push_str("\r\n");
        };
        record(self.columns.clone());
        for r in 0..self.rows.len() {
            record(
                (0..self.columns.len())
                    .map(|c| self.cell(r, c).map(Cell::csv).unwrap_or_default())
                    .collect(),
            );
        }
        out
    }

    /// A booktabs `tabular` with the title as a `%` comment above it and the notes as a
    /// `\footnotesize` paragraph below it.
    pub fn to_latex(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "% generated by gibench from results files; do not edit"
        );
        if !self.title.is_empty() {
            let _ = writeln!(out, "% {}", self.title.replace(['\r', '\n'], " "));
        }
        let spec: String = (0..self.columns.len())
            .map(|c| if self.right_aligned(c) { 'r' } else { 'l' })
            .collect();
        let _ = writeln!(out, "\\begin{{tabular}}{{{spec}}}");
        out.push_str("\\toprule\n");
        let line = |cells: Vec<String>| format!("{} \\\\\n", cells.join(" & "));
        out.push_str(&line(
            self.columns.iter().map(|c| latex_escape(c)).collect(),
        ));
        out.push_str("\\midrule\n");
        for r in self.display_rows() {
            out.push_str(&line(r.iter().map(|c| latex_escape(c)).collect()));
        }
        out.push_str("\\bottomrule\n\\end{tabular}\n");
        if !self.notes.is_empty() {
            out.push_str("\n{\\footnotesize\n");
            for n in &self.notes {
                let _ = writeln!(out, "{}\\par", latex_escape(n));
            }
            out.push_str("}\n");
        }
        out
    }
}

/// Quotes a CSV field when it holds a comma, a quote or a line break (RFC 4180).
fn csv_quote(field: &str) -> String {
    if field.contains([',', '"', '\r', '\n']) {
        format!("\"{}\"", field.replace('"', "\"\""))
    } else {
        field.to_string()
    }
}

/// Escapes LaTeX specials and spells a few non-ASCII symbols the tables use in ASCII LaTeX.
fn latex_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' | '%' | '$' | '#' | '_' | '{' | '}' => {
                out.push('\\');
                out.push(ch);
            }
            '~' => out.push_str("\\textasciitilde{}"),
            '^' => out.push_str("\\textasciicircum{}"),
            '\\' => out.push_str("\\textbackslash{}"),
            '–' => out.push_str("--"),
            '—' => out.push_str("---"),
            'Σ' => out.push_str("$\\Sigma$"),
            '×' => out.push_str("$\\times$"),
            'µ' | 'μ' => out.push_str("$\\mu$"),
            '\r' | '\n' => out.push(' '),
            _ => out.push(ch),
        }
    }
    out
}

/// "technique @ scene", the label of a run in plots and notes.
fn run_label(r: &RunResult) -> String {
    format!("{} @ {}", r.technique, r.scene)
}

/// The union of the runs' stage names in execution order: a stage first seen in a later run is
/// placed just before the next stage of that run already listed (else at the end).
fn stage_names<'a>(results: impl IntoIterator<Item = &'a RunResult>) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in results {
        for (i, s) in r.stages.iter().enumerate() {
            if names.contains(&s.name) {
                continue;
            }
            let next_known = r.stages[i + 1..]
                .iter()
                .find_map(|t| names.iter().position(|n| *n == t.name));
            match next_known {
                Some(p) => names.insert(p, s.name.clone()),
                None => names.push(s.name.clone()),
            }
        }
    }
    names
}

/// A stage's plotted/tabulated time, treating non-finite values as missing.
pub fn stage_ms(s: &StageResult) -> Option<f64> {
    finite(s.best_ms())
}

/// Sum of the run's stage times; `None` when no stage has a time.
fn stage_sum(r: &RunResult) -> Option<f64> {
    let times: Vec<f64> = r.stages.iter().filter_map(stage_ms).collect();
    (!times.is_empty()).then(|| times.iter().sum())
}

/// The device as one phrase: "adapter (backend, device type; driver ...)".
fn device_text(r: &RunResult) -> String {
    let d = &r.device;
    let driver = [d.driver.trim(), d.driver_info.trim()]
        .iter()
        .filter(|s| !s.is_empty())
        .copied()
        .collect::<Vec<_>>();
    let driver = if driver.is_empty() {
        "unknown".to_string()
    } else {
        driver.join(" ")
    };
    let adapter = if d.adapter.trim().is_empty() {
        "unknown adapter"
    } else {
        d.adapter.trim()
    };
    let mut kind: Vec<&str> = vec![d.backend.trim(), d.device_type.trim()];
    kind.retain(|s| !s.is_empty());
    if kind.is_empty() {
        format!("{adapter} (driver {driver})")
    } else {
        format!("{adapter} ({}; driver {driver})", kind.join(", "))
    }
}

/// Groups runs by `key`, in first-seen order; each group lists its runs' labels.
fn group_runs<K: PartialEq>(
    results: &[&RunResult],
    key: impl Fn(&RunResult) -> K,
) -> Vec<(K, Vec<String>)> {
    let mut groups: Vec<(K, Vec<String>)> = Vec::new();
    for r in results {
        let k = key(r);
        match groups.iter_mut().find(|(g, _)| *g == k) {
            Some((_, labels)) => labels.push(run_label(r)),
            None => groups.push((k, vec![run_label(r)])),
        }
    }
    groups
}

/// The notes shared by both stage tables: frame counts and timing method, wall-time fallbacks,
/// device(s).
fn timing_notes(results: &[&RunResult]) -> Vec<String> {
    let frames_text =
        |&(m, w): &(u32, u32)| format!("{m} measured frames ({w} warm-up frames dropped)");
    let frames = group_runs(results, |r| (r.frames.measured, r.frames.warmup));
    let frames = match frames.as_slice() {
        [] => "the measured frames".to_string(),
        [(k, _)] => frames_text(k),
        groups => groups
            .iter()
            .map(|(k, runs)| format!("{} for {}", frames_text(k), runs.join(", ")))
            .collect::<Vec<_>>()
            .join("; "),
    };
    let mut notes = vec![format!(
        "Times in milliseconds, median over {frames}; GPU stages: CPU wall time with the queue flushed before and \
         after (Laine et al. 2007's per-task method; GPU timestamps are in the results files and in \
         `gibench report --detailed`); frame: no added synchronisation (time between frame starts); CPU stages: \
         wall time; FPS: 1000 / mean frame time."
    )];

    let fallbacks: Vec<String> = results
        .iter()
        .filter_map(|r| {
            let stages: Vec<&str> = r
                .stages
                .iter()
                .filter(|s| s.kind == StageKind::Gpu && s.wall_ms.is_none() && s.gpu_ms.is_some())
                .map(|s| s.name.as_str())
                .collect();
            (!stages.is_empty()).then(|| format!("{} ({})", run_label(r), stages.join(", ")))
        })
        .collect();
    if !fallbacks.is_empty() {
        notes.push(format!(
            "GPU stages timed by GPU timestamps only (no flushed wall time): {}.",
            fallbacks.join("; ")
        ));
    }

    let devices = group_runs(results, device_text);
    match devices.as_slice() {
        [] => {}
        [(d, _)] => notes.push(format!("Device: {d}.")),
        groups => notes.push(format!(
            "Devices: {}.",
            groups
                .iter()
                .map(|(d, runs)| format!("{d} for {}", runs.join(", ")))
                .collect::<Vec<_>>()
                .join("; ")
        )),
    }
    notes
}

/// "mean / min" of the VPLs lighting each measured frame (the `vpls` counter), if counted.
pub fn vpl_count_cell(r: &RunResult) -> Cell {
    match r.counters.get("vpls") {
        Some(c) => Cell::text(format!("{:.1} / {}", c.mean, c.min)),
        None => Cell::text("–"),
    }
}

/// "adapter (backend)": what a run ran on, for tables that pool several devices.
pub fn device_label(r: &RunResult) -> String {
    format!("{} ({})", r.device.adapter, r.device.backend)
}

/// "fewest / most" VPLs any interleaving tile got in any measured frame (the `tile-vpls-min`
/// and `tile-vpls-max` counters), if counted.
pub fn tile_balance_cell(r: &RunResult) -> Cell {
    match (
        r.counters.get("tile-vpls-min"),
        r.counters.get("tile-vpls-max"),
    ) {
        (Some(lo), Some(hi)) => Cell::text(format!("{} / {}", lo.min, hi.max)),
        _ => Cell::text("–"),
    }
}

/// One row per run: scene, technique, resolution "WxH", "VPLs (mean / min)" and "tile VPLs
/// (fewest / most)" when any run counts them, one column per stage (median ms: flushed wall time, else GPU timestamps),
/// "Σ stages", "frame (median ms)", "FPS". Notes say how the times were taken and on which
/// device(s).
pub fn stage_table(results: &[RunResult]) -> Table {
    let stages = stage_names(results);
    let vpls = results.iter().any(|r| r.counters.contains_key("vpls"));
    let mut columns: Vec<String> = ["scene", "technique", "resolution"]
        .map(String::from)
        .into();
    // Results pooled from several devices: one column says which each row ran on.
    let mut adapters: Vec<String> = results.iter().map(device_label).collect();
    adapters.sort();
    adapters.dedup();
    let pooled = adapters.len() > 1;
    if pooled {
        columns.insert(0, "device".into());
    }
    if vpls {
        columns.push("VPLs (mean / min)".into());
    }
    let tiles = results
        .iter()
        .any(|r| r.counters.contains_key("tile-vpls-min"));
    if tiles {
        columns.push("tile VPLs (fewest / most)".into());
    }
    columns.extend(stages.iter().cloned());
    columns.extend(["Σ stages", "frame (median ms)", "FPS"].map(String::from));
    let quality = results.iter().any(|r| r.quality.is_some());
    if quality {
        columns.extend(["RMSE", "relMSE", "bias", "FLIP", "flicker"].map(String::from));
    }

    let rows = results
        .iter()
        .map(|r| {
            let mut row = vec![
                Cell::text(&r.scene),
                Cell::text(&r.technique),
                Cell::text(format!("{}x{}", r.resolution[0], r.resolution[1])),
            ];
            if pooled {
                row.insert(0, Cell::text(device_label(r)));
            }
            if vpls {
                row.push(vpl_count_cell(r));
            }
            if tiles {
                row.push(tile_balance_cell(r));
            }
            row.extend(
                stages
                    .iter()
                    .map(|name| Cell::Ms(r.stage(name).and_then(stage_ms))),
            );
            row.push(Cell::Ms(stage_sum(r)));
            row.push(Cell::Ms(r.frame.as_ref().map(|f| f.frame_ms.median)));
            row.push(Cell::Num(r.frame.as_ref().map(|f| f.fps), 1));
            if quality {
                let q = r.quality.as_ref();
                row.push(Cell::Num(q.map(|q| q.rmse.mean), 4));
                row.push(Cell::Num(q.map(|q| q.rel_mse.mean), 4));
                row.push(Cell::Num(q.map(|q| q.bias.mean), 4));
                row.push(Cell::Num(q.map(|q| q.flip_mean.mean), 4));
                row.push(Cell::Num(q.and_then(|q| q.temporal.map(|t| t.mean)), 4));
            }
            row
        })
        .collect();

    let mut notes = timing_notes(&results.iter().collect::<Vec<_>>());
    if quality {
        let mut refs: Vec<&str> = results
            .iter()
            .filter_map(|r| r.quality.as_ref().map(|q| q.reference.as_str()))
            .collect();
        refs.dedup();
        notes.push(format!(
            "Quality: means over the compared frames against the CPU reference ({}). RMSE, relMSE \
             (relative MSE, Rousselle et al. 2011) and bias (signed relative error of the mean) of indirect \
             irradiance; FLIP (LDR-FLIP, mean) of the \
             tonemapped composed images; flicker: RMS of the frame-to-frame change of indirect irradiance \
             beyond the reference's change.",
            refs.join("; ")
        ));
    }
    Table {
        title: "Per-stage GPU/CPU time (median ms)".to_string(),
        columns,
        rows,
        notes,
    }
}

/// One run in detail: one row per stage (kind GPU/CPU) with median, mean, p5, p95, min and max
/// of the GPU timestamp times and of the wall-clock times, plus a "frame" row holding the
/// unsynchronised frame times in the wall columns.
pub fn stage_table_detailed(result: &RunResult) -> Table {
    const STATS: [&str; 6] = ["median", "mean", "p5", "p95", "min", "max"];
    let mut columns: Vec<String> = vec!["stage".into(), "kind".into()];
    columns.extend(STATS.iter().map(|s| format!("GPU {s}")));
    columns.extend(STATS.iter().map(|s| format!("wall {s}")));

    let cells = |s: Option<&Stats>| -> Vec<Cell> {
        match s {
            Some(s) => [s.median, s.mean, s.p5, s.p95, s.min, s.max]
                .map(|v| Cell::Ms(Some(v)))
                .into(),
            None => vec![Cell::Ms(None); STATS.len()],
        }
    };
    let mut rows: Vec<Vec<Cell>> = result
        .stages
        .iter()
        .map(|s| {
            let kind = match s.kind {
                StageKind::Gpu => "GPU",
                StageKind::Cpu => "CPU",
            };
            let mut row = vec![Cell::text(&s.name), Cell::text(kind)];
            row.extend(cells(s.gpu_ms.as_ref()));
            row.extend(cells(s.wall_ms.as_ref()));
            row
        })
        .collect();

    let mut notes = timing_notes(&[result]);
    if let Some(f) = &result.frame {
        let mut row = vec![Cell::text("frame"), Cell::text("frame")];
        row.extend(cells(None));
        row.extend(cells(Some(&f.frame_ms)));
        rows.push(row);
        notes.push(format!(
            "The frame row is the time between consecutive frame starts with at most {} frame(s) in flight \
             ({:.1} FPS).",
            f.frames_in_flight, f.fps
        ));
    }

    Table {
        title: format!(
            "{} ({}x{}): per-stage times (ms)",
            run_label(result),
            result.resolution[0],
            result.resolution[1]
        ),
        columns,
        rows,
        notes,
    }
}

/// Writes `stem.md`, `stem.csv` and `stem.tex` into `dir` (created if needed), each atomically;
/// returns their paths in that order.
pub fn write_tables(table: &Table, dir: &Path, stem: &str) -> Result<Vec<PathBuf>> {
    if stem.is_empty() || stem.contains(['/', '\\']) {
        return Err(Error::Invalid(format!(
            "table file stem '{stem}' must be a non-empty file name"
        )));
    }
    let outputs = [
        ("md", table.to_markdown()),
        ("csv", table.to_csv()),
        ("tex", table.to_latex()),
    ];
    let mut paths = Vec::with_capacity(outputs.len());
    for (ext, text) in outputs {
        let path = dir.join(format!("{stem}.{ext}"));
        crate::error::write_atomic(&path, text.as_bytes())?;
        paths.push(path);
    }
    Ok(paths)
}

// ----------------------------------------------------------------------------------------------
// Plots

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
    entries: &[(String, RGBColor, Mark)],
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

/// Renders into an SVG string with `draw`, then writes it to `path` atomically.
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
    crate::error::write_atomic(path, svg.as_bytes())
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
    // Segments per run: (stage index in `names`, start, end), in the run's execution order.
    let bars: Vec<Vec<(usize, f64, f64)>> = results
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
        .collect();
    let totals: Vec<Option<f64>> = bars.iter().map(|b| b.last().map(|s| s.2)).collect();
    let xmax = axis_max(totals.iter().flatten().copied().fold(0.0, f64::max), 1.18);

    let label_area = label_width(&labels, 15.0);
    let width = (label_area + 640 + LEGEND_W).max(1000);
    let height = (130 + 44 * n as u32)
        .max(120 + 24 * names.len() as u32)
        .max(280);

    write_svg(path, (width, height), |root| {
        root.fill(&WHITE)?;
        let (plot, legend) = root.split_horizontally(width - LEGEND_W);
        let mut chart = ChartBuilder::on(&plot)
            .caption(title, (FONT, 22))
            .margin(12)
            .x_label_area_size(50)
            .y_label_area_size(label_area)
            .build_cartesian_2d(0.0..xmax, Categories(n))?;
        // Slot 0 is at the bottom; run i is drawn in slot n - 1 - i.
        let label_of = |v: &f64| {
            category(*v, n)
                .map(|p| labels[n - 1 - p].clone())
                .unwrap_or_default()
        };
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(n)
            .y_label_formatter(&label_of)
            .x_desc("milliseconds (median)")
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 16))
            .draw()?;

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

        let entries: Vec<_> = names
            .iter()
            .enumerate()
            .map(|(k, s)| (s.clone(), stage_color(k), Mark::Box))
            .collect();
        draw_legend(&legend, "stages", &entries)?;
        root.present()?;
        Ok(())
    })
}

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

    write_svg(path, (width, height), |root| {
        root.fill(&WHITE)?;
        let (plot, legend) = root.split_horizontally(width - LEGEND_W);
        let mut chart = ChartBuilder::on(&plot)
            .caption(title, (FONT, 22))
            .margin(12)
            .x_label_area_size(60)
            .y_label_area_size(70)
            .build_cartesian_2d(Categories(m), 0.0..ymax)?;
        let label_of = |v: &f64| {
            category(*v, m)
                .map(|j| x_labels[j].clone())
                .unwrap_or_default()
        };
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(m)
            .x_label_formatter(&label_of)
            .x_desc(x_name)
            .y_desc("milliseconds (median)")
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 16))
            .draw()?;

        let mut draw_line = |values: &[Option<f64>], color: RGBColor, width: u32| -> PlotResult {
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
        };
        for (k, values) in series.iter().enumerate() {
            draw_line(values, stage_color(k), 2)?;
        }
        draw_line(&totals, BLACK, 3)?;

        let mut entries: Vec<_> = names
            .iter()
            .enumerate()
            .map(|(k, s)| (s.clone(), stage_color(k), Mark::Line(2)))
            .collect();
        entries.push(("total (Σ stages)".to_string(), BLACK, Mark::Line(3)));
        draw_legend(&legend, "stages", &entries)?;
        root.present()?;
        Ok(())
    })
}

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
    let pick = |f: &crate::metrics::FrameQuality| -> Option<f64> {
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
    Ok(results
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
        .collect())
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
    write_svg(path, (width, height), |root| {
        root.fill(&WHITE)?;
        let (plot, legend) = root.split_horizontally(width - LEGEND_W);
        let mut chart = ChartBuilder::on(&plot)
            .caption(title, (FONT, 22))
            .margin(12)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, ymin..ymax)?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 16))
            .draw()?;
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
        draw_legend(&legend, "series", &entries)?;
        root.present()?;
        Ok(())
    })
}

/// "technique" plus the parameters whose values differ between runs of that technique in
/// `all` (e.g. "laine clamp=3"), to tell sweep points apart.
pub fn distinct_label(all: &[RunResult], r: &RunResult) -> String {
    let same: Vec<&RunResult> = all
        .iter()
        .filter(|o| o.technique == r.technique && o.scene == r.scene)
        .collect();
    let mut label = r.technique.clone();
    for (k, v) in &r.parameters {
        if same.iter().any(|o| o.parameters.get(k) != Some(v)) {
            label.push_str(&format!(
                " {k}={}",
                v.as_str()
                    .map(String::from)
                    .unwrap_or_else(|| v.to_string())
            ));
        }
    }
    if all.iter().any(|o| o.scene != r.scene) {
        label.push_str(&format!(" @ {}", r.scene));
    }
    label
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

/// The points of the time-versus-error plot: (label, frame ms, mean relative MSE against the
/// reference), runs without quality left out.
pub fn time_error_points(results: &[RunResult]) -> Vec<(String, f64, f64)> {
    results
        .iter()
        .filter_map(|r| {
            let q = r.quality.as_ref()?;
            let t = frame_time_ms(r)?;
            q.rel_mse
                .mean
                .is_finite()
                .then(|| (distinct_label(results, r), t, q.rel_mse.mean))
        })
        .collect()
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

/// Time versus error: one point per run with quality (technique and setting), the Pareto
/// front joined by a line and drawn filled, the others hollow. Errors when no run has both.
pub fn time_vs_error_svg(results: &[RunResult], path: &Path, title: &str) -> Result<()> {
    let points = time_error_points(results);
    if points.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no run has both a frame time and an error against the reference (run with --quality)",
            path.display()
        )));
    }
    let front = pareto_front(&points);
    let xmax = axis_max(points.iter().map(|p| p.1).fold(0.0, f64::max), 1.15);
    let ymax = axis_max(points.iter().map(|p| p.2).fold(0.0, f64::max), 1.15);
    let (width, height) = (1000u32, 600u32);
    write_svg(path, (width, height), |root| {
        root.fill(&WHITE)?;
        let (plot, legend) = root.split_horizontally(width - LEGEND_W);
        let mut chart = ChartBuilder::on(&plot)
            .caption(title, (FONT, 22))
            .margin(12)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..xmax, 0.0..ymax)?;
        chart
            .configure_mesh()
            .x_desc("time per frame (ms; median frame, else Σ stage medians)")
            .y_desc("relative MSE against the reference (mean)")
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 16))
            .draw()?;
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
            entries.push((format!("{label}{mark}"), color, Mark::Box));
        }
        draw_legend(&legend, "technique, setting", &entries)?;
        root.present()?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use crate::results::{DeviceInfo, FrameRange, FrameResult, SCHEMA_VERSION};

    /// The front keeps exactly the points nothing beats in both time and error.
    #[test]
    fn pareto_front_keeps_the_unbeaten_points() {
        let p = |t: f64, e: f64| (String::new(), t, e);
        let points = vec![
            p(10.0, 0.5),
            p(5.0, 0.9),
            p(20.0, 0.1),
            p(12.0, 0.6),
            p(5.0, 1.0),
        ];
        // (12, 0.6) is beaten by (10, 0.5); (5, 1.0) by (5, 0.9).
        assert_eq!(pareto_front(&points), vec![1, 0, 2]);
    }

    /// Stats of 100 frames with the given median.
    fn stats(median: f64) -> Stats {
        Stats {
            count: 100,
            mean: median * 1.01,
            median,
            p5: median * 0.9,
            p95: median * 1.2,
            p99: median * 1.4,
            min: median * 0.8,
            max: median * 1.5,
        }
    }

    fn stage(name: &str, kind: StageKind, gpu: Option<f64>, wall: Option<f64>) -> StageResult {
        StageResult {
            name: name.into(),
            kind,
            gpu_ms: gpu.map(stats),
            wall_ms: wall.map(stats),
            cpu_ms: None,
        }
    }

    fn run(scene: &str, technique: &str, stages: Vec<StageResult>, frame_median: f64) -> RunResult {
        RunResult {
            schema_version: SCHEMA_VERSION,
            gibench_version: "0.1.0".into(),
            git_commit: "abc1234".into(),
            timestamp: 1_700_000_000,
            scene: scene.into(),
            technique: technique.into(),
            parameters: BTreeMap::from([("vpls".to_string(), serde_json::json!(256))]),
            settings: BTreeMap::from([("shadow_map_size".to_string(), serde_json::json!(1024))]),
            resolution: [1280, 720],
            frames: FrameRange {
                warmup: 10,
                measured: 100,
                first: 10,
            },
            seed: 7,
            timing_mode: "both".into(),
            device: DeviceInfo {
                adapter: "Test GPU".into(),
                backend: "Vulkan".into(),
                device_type: "DiscreteGpu".into(),
                driver: "testdrv".into(),
                driver_info: "1.2.3".into(),
                timestamp_queries: true,
                timestamp_period_ns: 1.0,
            },
            stages,
            frame: Some(FrameResult {
                frame_ms: stats(frame_median),
                fps: 1000.0 / (frame_median * 1.01),
                frames_in_flight: 2,
                samples_ms: vec![frame_median],
            }),
            counters: BTreeMap::from([("shadow maps".to_string(), stats(1.0))]),
            prepare_ms: None,
            first_frame_ms: None,
            quality: None,
            images: vec!["frame.png".into()],
            warnings: Vec::new(),
            calibration_ms: None,
            peak_memory_mb: None,
        }
    }

    /// Run A: three GPU stages (GPU timestamps a little above the wall times), the last one
    /// without GPU timestamps (wall time 0.75 ms).
    /// Run B: a name with a comma and quotes, a scene with `_` and `%`, an extra CPU stage.
    fn two_runs() -> Vec<RunResult> {
        let a = run(
            "sponza",
            "direct",
            vec![
                stage("g-buffer", StageKind::Gpu, Some(0.6), Some(0.5)),
                stage("shadow map", StageKind::Gpu, Some(1.5), Some(1.234)),
                stage("compose", StageKind::Gpu, None, Some(0.75)),
            ],
            3.0,
        );
        let b = run(
            "cornell_box 100%",
            "ism, \"imperfect\"",
            vec![
                stage("g-buffer", StageKind::Gpu, Some(0.3), Some(0.25)),
                stage("vpl trace", StageKind::Cpu, None, Some(2.0)),
                stage("compose", StageKind::Gpu, Some(0.1), Some(0.05)),
            ],
            4.5,
        );
        vec![a, b]
    }

    /// Runs from two devices pooled into one table get a device column naming each row's;
    /// runs from one device do not.
    #[test]
    fn pooled_devices_get_a_device_column() {
        let mut runs = two_runs();
        assert!(!stage_table(&runs).columns.contains(&"device".to_string()));
        runs[1].device.adapter = "NVIDIA H200".into();
        let t = stage_table(&runs);
        assert_eq!(t.columns[0], "device");
        let cell = |r: usize| match &t.rows[r][0] {
            Cell::Text(s) => s.clone(),
            other => panic!("{other:?}"),
        };
        assert!(cell(1).starts_with("NVIDIA H200") && !cell(0).starts_with("NVIDIA"));
    }

    #[test]
    fn stage_union_keeps_execution_order() {
        let t = stage_table(&two_runs());
        let expected = [
            "scene",
            "technique",
            "resolution",
            "g-buffer",
            "shadow map",
            "vpl trace",
            "compose",
            "Σ stages",
            "frame (median ms)",
            "FPS",
        ];
        assert_eq!(t.columns, expected);
        assert_eq!(t.rows.len(), 2);
    }

    #[test]
    fn markdown_has_header_separator_and_one_row_per_result() {
        let md = stage_table(&two_runs()).to_markdown();
        let lines: Vec<&str> = md.lines().filter(|l| l.starts_with('|')).collect();
        assert_eq!(lines.len(), 4, "header, separator, two rows:\n{md}");
        assert!(
            lines[0].contains("| g-buffer | shadow map | vpl trace | compose | Σ stages |"),
            "{md}"
        );
        assert_eq!(
            lines[1],
            "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
        );
        // Run A: medians 0.50, 1.23 (1.234), no vpl trace, 0.75 (wall); sum 2.484; frame 3.00.
        assert_eq!(
            lines[2],
            "| sponza | direct | 1280x720 | 0.50 | 1.23 | – | 0.75 | 2.48 | 3.00 | 330.0 |"
        );
        // Run B: 0.05 ms shows three decimals.
        assert!(
            lines[3].contains("| 0.25 | – | 2.00 | 0.050 | 2.30 | 4.50 |"),
            "{}",
            lines[3]
        );
        assert!(md.starts_with("### "));
        assert!(md.contains("\nTimes in milliseconds, median over 100 measured frames (10 warm-up frames dropped); GPU stages: CPU wall time with the queue flushed before and after"), "{md}");
        assert!(
            md.contains("Device: Test GPU (Vulkan, DiscreteGpu; driver testdrv 1.2.3)."),
            "{md}"
        );
    }

    #[test]
    fn tables_use_flushed_wall_time() {
        let runs = two_runs();
        let t = stage_table(&runs);
        let compose = t.columns.iter().position(|c| c == "compose").unwrap();
        assert_eq!(t.rows[0][compose], Cell::Ms(Some(0.75)));
        // The flushed wall time wins over a GPU timestamp (Laine's per-task method).
        let gbuffer = t.columns.iter().position(|c| c == "g-buffer").unwrap();
        assert_eq!(t.rows[1][gbuffer], Cell::Ms(Some(0.25)));
        // No stage lacks a wall time here: no fallback note.
        assert!(!t.notes.iter().any(|n| n.contains("GPU timestamps only")));
    }

    #[test]
    fn differing_devices_are_each_listed() {
        let mut runs = two_runs();
        runs[1].device.adapter = "Other GPU".into();
        runs[1].frames.measured = 50;
        let notes = stage_table(&runs).notes.join("\n");
        assert!(notes.contains("Devices: Test GPU (Vulkan, DiscreteGpu; driver testdrv 1.2.3) for direct @ sponza; Other GPU"), "{notes}");
        assert!(
            notes.contains(
                "100 measured frames (10 warm-up frames dropped) for direct @ sponza; 50 measured"
            ),
            "{notes}"
        );
    }

    /// A huge value (a results file may say 1e308 ms) is written with an exponent, not as a
    /// cell of 300 digits; ordinary values keep their decimals.
    #[test]
    fn huge_values_are_written_with_an_exponent() {
        for cell in [Cell::Ms(Some(1e308)), Cell::Num(Some(-1e308), 1)] {
            assert!(cell.display().len() <= 12, "{}", cell.display());
            assert!(cell.csv().len() <= 12, "{}", cell.csv());
            assert!(cell.display().contains("e308"), "{}", cell.display());
        }
        assert_eq!(Cell::Ms(Some(12.345)).display(), "12.35");
        assert_eq!(Cell::Num(Some(123456.0), 1).display(), "123456.0");
    }

    /// A table wider than the terminal is folded into blocks no wider than it, each repeating
    /// scene, technique and resolution and listing only the rows with values in its columns;
    /// every value is still shown once; notes are wrapped. (Before, the default run printed
    /// one line of over 300 characters per technique.)
    #[test]
    fn wide_tables_fold_to_the_terminal_width() {
        let mut t = Table {
            title: "wide".into(),
            columns: ["scene", "technique", "resolution"]
                .map(String::from)
                .into(),
            rows: Vec::new(),
            notes: vec![format!("{} end", "word ".repeat(60))],
        };
        t.columns
            .extend((0..30).map(|k| format!("stage-number-{k}")));
        for (name, range) in [("alpha", 0..16), ("beta", 16..30)] {
            let mut row = vec![Cell::text("sibenik"), Cell::text(name), Cell::text("64x48")];
            row.extend(
                (0..30).map(|k| Cell::Ms(range.contains(&k).then_some(1000.0 + k as f64 + 0.25))),
            );
            t.rows.push(row);
        }
        let out = t.to_terminal();
        assert!(
            out.lines().all(|l| l.chars().count() <= TERMINAL_WIDTH),
            "{out}"
        );
        for k in 0..30 {
            let v = format!("{:.2}", 1000.0 + k as f64 + 0.25);
            assert_eq!(out.matches(&v).count(), 1, "{v} in\n{out}");
        }
        // Every row a block lists has a value in that block (alpha's and beta's own stages
        // are apart).
        for block in out.split("\n\n").filter(|b| b.contains("stage-number")) {
            let rows = block.lines().skip_while(|l| !l.starts_with("---")).skip(1);
            for l in rows {
                assert!(l.contains("10"), "a row without values: {l}");
            }
        }
        assert!(out.contains("word end"));
        // A narrow table is unchanged: one block, every row.
        let narrow = two_runs();
        let out = stage_table(&narrow[..1]).to_terminal();
        assert!(out.lines().all(|l| l.chars().count() <= TERMINAL_WIDTH));
    }

    #[test]
    fn csv_quotes_commas_and_quotes() {
        let csv = stage_table(&two_runs()).to_csv();
        let records: Vec<&str> = csv.split("\r\n").collect();
        assert_eq!(
            records.len(),
            4,
            "header, two rows, trailing empty: {csv:?}"
        );
        assert_eq!(records[3], "");
        assert!(records[0].starts_with("scene,technique,resolution,g-buffer,shadow map,"));
        assert_eq!(
            records[1],
            "sponza,direct,1280x720,0.5000,1.2340,,0.7500,2.4840,3.0000,330.0"
        );
        assert!(
            records[2].starts_with("cornell_box 100%,\"ism, \"\"imperfect\"\"\",1280x720,"),
            "{}",
            records[2]
        );
        assert!(!csv.contains("Times in milliseconds"), "no notes in CSV");
    }

    #[test]
    fn latex_escapes_specials() {
        let tex = stage_table(&two_runs()).to_latex();
        assert!(tex.contains("\\begin{tabular}{lllrrrrrrr}"), "{tex}");
        assert!(
            tex.contains("\\toprule") && tex.contains("\\midrule") && tex.contains("\\bottomrule")
        );
        assert!(
            tex.contains("cornell\\_box 100\\% & ism, \"imperfect\" & 1280x720"),
            "{tex}"
        );
        assert!(tex.contains("$\\Sigma$ stages"), "{tex}");
        assert!(tex.contains("{\\footnotesize\n"), "{tex}");
        assert_eq!(latex_escape("a&b%c$d#e_f{g}h~i^j\\k"), "a\\&b\\%c\\$d\\#e\\_f\\{g\\}h\\textasciitilde{}i\\textasciicircum{}j\\textbackslash{}k");
        // Missing values are en dashes.
        assert!(tex.contains("& -- &"), "{tex}");
    }

    #[test]
    fn terminal_columns_align() {
        let out = stage_table(&two_runs()).to_terminal();
        let lines: Vec<&str> = out.lines().collect();
        assert!(lines[0].starts_with("Per-stage"));
        let header = lines[1];
        let dashes = lines[2];
        assert!(dashes.starts_with("------"));
        // Right-aligned numeric columns: every data row ends where the header ends.
        let width = |s: &str| s.chars().count();
        assert_eq!(width(lines[3]), width(header), "{out}");
        assert_eq!(width(lines[4]), width(header), "{out}");
        assert_eq!(width(dashes), width(header), "{out}");
        assert!(out.contains("\nDevice: Test GPU"));
    }

    #[test]
    fn detailed_table_has_one_row_per_stage_and_frame() {
        let runs = two_runs();
        let t = stage_table_detailed(&runs[0]);
        assert_eq!(t.columns.len(), 14);
        assert_eq!(t.columns[2], "GPU median");
        assert_eq!(t.columns[13], "wall max");
        assert_eq!(t.rows.len(), 4);
        assert_eq!(t.rows[1][0], Cell::text("shadow map"));
        assert_eq!(t.rows[1][2].display(), "1.50");
        assert_eq!(t.rows[1][8].display(), "1.23");
        assert_eq!(t.rows[2][2], Cell::Ms(None));
        assert_eq!(t.rows[3][0], Cell::text("frame"));
        assert_eq!(t.rows[3][8].display(), "3.00");
        assert!(t.title.starts_with("direct @ sponza (1280x720)"));
        assert!(t.to_markdown().contains("| compose | GPU | – | – |"));
    }

    #[test]
    fn write_tables_writes_three_files() {
        let dir = tempfile::tempdir().unwrap();
        let table = stage_table(&two_runs());
        let paths = write_tables(&table, &dir.path().join("tables"), "stages").unwrap();
        let names: Vec<String> = paths
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["stages.md", "stages.csv", "stages.tex"]);
        assert_eq!(
            std::fs::read_to_string(&paths[0]).unwrap(),
            table.to_markdown()
        );
        assert_eq!(std::fs::read_to_string(&paths[1]).unwrap(), table.to_csv());
        assert_eq!(
            std::fs::read_to_string(&paths[2]).unwrap(),
            table.to_latex()
        );
        assert!(write_tables(&table, dir.path(), "").is_err());
    }

    /// The text content of every `<text>` element.
    fn svg_texts(svg: &str) -> Vec<String> {
        svg.split("<text")
            .skip(1)
            .map(|t| {
                t[t.find('>').unwrap() + 1..t.find("</text>").unwrap()]
                    .trim()
                    .to_string()
            })
            .collect()
    }

    #[test]
    fn stacked_bar_svg_has_bars_labels_and_legend() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bars.svg");
        stacked_bar_svg(&two_runs(), &path, "Stage times").unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
            "{svg}"
        );
        let texts = svg_texts(&svg);
        for name in [
            "g-buffer",
            "shadow map",
            "vpl trace",
            "compose",
            "Stage times",
            "milliseconds (median)",
            "direct @ sponza",
        ] {
            assert!(
                texts.iter().any(|t| t == name),
                "no <text> '{name}' in {texts:?}"
            );
        }
        // The quotes of run B's name are escaped, not raw.
        assert!(
            texts
                .iter()
                .any(|t| t.contains("ism, &quot;imperfect&quot; @ cornell_box 100%")),
            "{texts:?}"
        );
        assert!(texts.iter().any(|t| t == "2.48 ms"), "{texts:?}");
        // Six segments (three stages per run) in the stage colours plus the legend swatches.
        let blue = format!("fill=\"#{:02X}{:02X}{:02X}\"", 78, 121, 167);
        assert_eq!(
            svg.matches(&blue).count(),
            3,
            "two g-buffer segments and a legend swatch"
        );
    }

    #[test]
    fn zero_and_missing_stage_times_do_not_panic() {
        let dir = tempfile::tempdir().unwrap();
        let mut runs = two_runs();
        runs[0].stages[0].gpu_ms = Some(stats(0.0));
        runs[0].stages[1].gpu_ms = None;
        runs[0].stages[1].wall_ms = None;
        let mut zero = runs[0].clone();
        for s in &mut zero.stages {
            s.gpu_ms = Some(stats(0.0));
        }
        zero.frame = None;
        let mut none = runs[1].clone();
        none.stages.clear();
        runs.extend([zero, none]);
        stacked_bar_svg(&runs, &dir.path().join("bars.svg"), "zeros").unwrap();
        stacked_bar_svg(&runs[2..], &dir.path().join("bars0.svg"), "all zero").unwrap();
        let points: Vec<(String, RunResult)> = runs
            .iter()
            .enumerate()
            .map(|(i, r)| (i.to_string(), r.clone()))
            .collect();
        sweep_plot_svg(&points, &dir.path().join("sweep.svg"), "zeros", "n").unwrap();
        sweep_plot_svg(
            &points[2..],
            &dir.path().join("sweep0.svg"),
            "all zero",
            "n",
        )
        .unwrap();
        let t = stage_table(&runs);
        assert_eq!(
            t.rows[3].iter().filter(|c| **c == Cell::Ms(None)).count(),
            5,
            "{:?}",
            t.rows[3]
        );
        let _ = (t.to_markdown(), t.to_csv(), t.to_latex(), t.to_terminal());
    }

    #[test]
    fn sweep_plot_svg_has_stage_lines_and_total() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sweep.svg");
        let runs = two_runs();
        let points: Vec<(String, RunResult)> = ["64", "256", "1024"]
            .iter()
            .zip([runs[0].clone(), runs[1].clone(), runs[0].clone()])
            .map(|(x, r)| (x.to_string(), r))
            .collect();
        sweep_plot_svg(&points, &path, "VPL count sweep", "VPLs").unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.starts_with("<svg"));
        let texts = svg_texts(&svg);
        for name in [
            "g-buffer",
            "shadow map",
            "vpl trace",
            "compose",
            "total (Σ stages)",
            "VPLs",
            "64",
            "256",
            "1024",
        ] {
            assert!(
                texts.iter().any(|t| t == name),
                "no <text> '{name}' in {texts:?}"
            );
        }
        assert!(svg.contains("<polyline"), "lines are drawn");
    }

    #[test]
    fn empty_input_is_an_error_not_a_panic() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("empty.svg");
        assert!(matches!(
            stacked_bar_svg(&[], &path, "empty"),
            Err(Error::Invalid(_))
        ));
        assert!(matches!(
            sweep_plot_svg(&[], &path, "empty", "x"),
            Err(Error::Invalid(_))
        ));
        assert!(!path.exists());
        let t = stage_table(&[]);
        assert!(t.rows.is_empty());
        assert_eq!(
            t.to_markdown()
                .lines()
                .filter(|l| l.starts_with('|'))
                .count(),
            2
        );
        let _ = (t.to_csv(), t.to_latex(), t.to_terminal());
    }
}
