//! The Markdown renderer: a GitHub-flavoured pipe table under a `###` title, notes after it.

use std::fmt::Write as _;

use super::table::Table;

impl Table {
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
}
