//! The CSV renderer (RFC 4180): data only, no title and no notes.

use super::table::{finite, Cell, Table, LARGE};

impl Cell {
    /// The cell as a CSV field (unquoted): more decimals for milliseconds, empty when missing.
    pub(super) fn csv(&self) -> String {
        match self {
            Cell::Text(s) => s.clone(),
            Cell::Ms(v) => finite(*v)
                .map(|v| match v.abs() >= LARGE {
                    true => format!("{v:e}"),
                    false => format!("{v:.4}"),
                })
                .unwrap_or_default(),
            Cell::Num(v, d) | Cell::Own(v, d) => finite(*v)
                .map(|v| match v.abs() >= LARGE {
                    true => format!("{v:e}"),
                    false => format!("{v:.*}", *d as usize),
                })
                .unwrap_or_default(),
        }
    }
}

impl Table {
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
}

/// Quotes a CSV field when it holds a comma, a quote or a line break (RFC 4180).
fn csv_quote(field: &str) -> String {
    if field.contains([',', '"', '\r', '\n']) {
        format!("\"{}\"", field.replace('"', "\"\""))
    } else {
        field.to_string()
    }
}
