//! The terminal renderer: aligned plain-text columns, folded into blocks where a table is wider
//! than [`TERMINAL_WIDTH`].

use super::table::{Table, MISSING};

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

impl Table {
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
}
