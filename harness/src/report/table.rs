//! The table model: a [`Table`] of [`Cell`]s with a title and notes, what every renderer reads,
//! and [`write_tables`], which writes its Markdown, CSV and LaTeX renderings side by side.

use std::path::{Path, PathBuf};

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

    pub(super) fn is_numeric(&self) -> bool {
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
}

/// Shown for a missing value.
pub(super) const MISSING: &str = "–";

/// From this magnitude on, a number is written with an exponent (`1.000e308`, not a cell of
/// 300 digits).
pub(super) const LARGE: f64 = 1e9;

pub(super) fn finite(v: Option<f64>) -> Option<f64> {
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
    pub(super) fn cell(&self, row: usize, col: usize) -> Option<&Cell> {
        self.rows[row].get(col)
    }

    pub(super) fn right_aligned(&self, col: usize) -> bool {
        !self.rows.is_empty()
            && self
                .rows
                .iter()
                .all(|r| r.get(col).is_some_and(Cell::is_numeric))
    }

    /// The displayed text of every cell, padded to the column count.
    pub(super) fn display_rows(&self) -> Vec<Vec<String>> {
        (0..self.rows.len())
            .map(|r| {
                (0..self.columns.len())
                    .map(|c| self.cell(r, c).map(Cell::display).unwrap_or_default())
                    .collect()
            })
            .collect()
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
        crate::output::write_atomic(&path, text.as_bytes())?;
        paths.push(path);
    }
    Ok(paths)
}
