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
    /// A [`Cell::Num`] marked as the run's own: an error against the reference component its
    /// technique computes, beside its errors against the others. Shown with a trailing
    /// [`OWN_MARK`]; bare in CSV (whose `reference` column names the own component).
    Own(Option<f64>, u8),
}

/// Follows an error against the run's own reference component ([`Cell::Own`]).
pub const OWN_MARK: &str = "*";

impl Cell {
    /// A text cell.
    pub fn text(s: impl Into<String>) -> Cell {
        Cell::Text(s.into())
    }

    pub(super) fn is_numeric(&self) -> bool {
        matches!(self, Cell::Ms(_) | Cell::Num(..) | Cell::Own(..))
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
            Cell::Own(v, d) => match finite(*v) {
                Some(_) => format!("{}{OWN_MARK}", Cell::Num(*v, *d).display()),
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
    /// Marks the table as a smoke run's, never to pass for benchmark results: its title opens
    /// with "SMOKE RUN" and `note` (what made it one) comes first under it.
    pub fn mark_smoke(&mut self, note: &str) {
        self.title = format!("SMOKE RUN: {}", self.title);
        self.notes.insert(0, note.to_string());
    }

    pub(super) fn cell(&self, row: usize, col: usize) -> Option<&Cell> {
        self.rows[row].get(col)
    }

    /// How many of the leading columns say which run a row is ([`IDENTIFYING`]).
    pub(super) fn identifying_columns(&self) -> usize {
        (self.columns.iter())
            .take_while(|c| IDENTIFYING.contains(&c.as_str()))
            .count()
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

/// A rendering of a table written to a file ([`write_tables_as`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableFormat {
    Markdown,
    Csv,
    Latex,
}

impl TableFormat {
    pub const ALL: [TableFormat; 3] = [TableFormat::Markdown, TableFormat::Csv, TableFormat::Latex];

    /// `markdown`, `csv` or `latex` (the error names `option`).
    pub fn parse(option: &str, s: &str) -> Result<TableFormat> {
        match s {
            "markdown" | "md" => Ok(TableFormat::Markdown),
            "csv" => Ok(TableFormat::Csv),
            "latex" | "tex" => Ok(TableFormat::Latex),
            _ => Err(Error::param(
                option,
                format!("expected markdown, csv or latex (got '{s}')"),
            )),
        }
    }

    fn extension(self) -> &'static str {
        match self {
            TableFormat::Markdown => "md",
            TableFormat::Csv => "csv",
            TableFormat::Latex => "tex",
        }
    }

    fn render(self, table: &Table) -> String {
        match self {
            TableFormat::Markdown => table.to_markdown(),
            TableFormat::Csv => table.to_csv(),
            TableFormat::Latex => table.to_latex(),
        }
    }
}

/// Writes `stem.md`, `stem.csv` and `stem.tex` into `dir` (created if needed), each atomically;
/// returns their paths in that order.
pub fn write_tables(table: &Table, dir: &Path, stem: &str) -> Result<Vec<PathBuf>> {
    write_tables_as(table, dir, stem, &TableFormat::ALL)
}

/// [`write_tables`] in the given formats only.
pub fn write_tables_as(
    table: &Table,
    dir: &Path,
    stem: &str,
    formats: &[TableFormat],
) -> Result<Vec<PathBuf>> {
    if stem.is_empty() || stem.contains(['/', '\\']) {
        return Err(Error::Invalid(format!(
            "table file stem '{stem}' must be a non-empty file name"
        )));
    }
    let mut paths = Vec::with_capacity(formats.len());
    for f in formats {
        let path = dir.join(format!("{stem}.{}", f.extension()));
        crate::output::write_atomic(&path, f.render(table).as_bytes())?;
        paths.push(path);
    }
    Ok(paths)
}

/// The key a column is chosen by (`gibench report --columns`): its header in lower case with
/// spaces as `-` ("frame p95": `frame-p95`, "relMSE": `relmse`), "Σ stages" as `sum`.
pub fn column_key(header: &str) -> String {
    let bare = header.split(" (").next().unwrap_or(header).trim();
    match bare {
        "Σ stages" => "sum".to_string(),
        h => h.to_lowercase().replace(' ', "-"),
    }
}

/// The headers of the columns that say which run a row is (kept by
/// [`Table::select_columns`], frozen in the HTML page), when they lead a table.
const IDENTIFYING: [&str; 6] = [
    "device",
    "scene",
    "technique",
    "resolution",
    "setting",
    "run",
];

impl Table {
    /// This table with its identifying columns ([`Table::identifying_columns`]: scene,
    /// technique, resolution, setting) and then the columns `keys` name ([`column_key`]), in their
    /// order; a key that names no column picks every column whose key it leads (`relmse`: the
    /// relMSE against each component). A key that picks nothing is an error that names it,
    /// `option`, and the keys there are — before anything is written.
    pub fn select_columns(&self, option: &str, keys: &[String]) -> Result<Table> {
        let ids = self.identifying_columns();
        let mut picked: Vec<usize> = (0..ids).collect();
        for k in keys {
            let k = k.trim().to_lowercase();
            // A key names its column, else every column whose key it leads ("relmse":
            // "relmse-one-bounce" and "relmse-multi-bounce").
            let exact: Vec<usize> = (0..self.columns.len())
                .filter(|&c| column_key(&self.columns[c]) == k)
                .collect();
            let named = match exact.is_empty() {
                false => exact,
                true => (0..self.columns.len())
                    .filter(|&c| column_key(&self.columns[c]).starts_with(&format!("{k}-")))
                    .collect(),
            };
            if named.is_empty() {
                let there: Vec<String> = (self.columns.iter().skip(ids))
                    .map(|c| column_key(c))
                    .collect();
                return Err(Error::param(
                    option,
                    format!("no column '{k}' in this table; it has {}", there.join(", ")),
                ));
            }
            for c in named {
                if !picked.contains(&c) {
                    picked.push(c);
                }
            }
        }
        Ok(Table {
            title: self.title.clone(),
            columns: picked.iter().map(|&c| self.columns[c].clone()).collect(),
            rows: (self.rows.iter())
                .map(|r| {
                    (picked.iter())
                        .map(|&c| r.get(c).cloned().unwrap_or(Cell::text("")))
                        .collect()
                })
                .collect(),
            notes: self.notes.clone(),
        })
    }
}
