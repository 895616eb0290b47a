//! [`TextTable`]: the aligned plain-text table every table of both tools is printed as (columns
//! two spaces apart, a dashed rule under the header, names left- and numbers right-aligned,
//! Unicode width-aware; drawn by `comfy-table`), and the same table as Markdown.

use comfy_table::{presets::NOTHING, CellAlignment, Table};

/// A header row and rows; the first `left` columns (names) are left-aligned, the others
/// (numbers) right-aligned.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TextTable {
    pub head: Vec<String>,
    pub rows: Vec<Vec<String>>,
    pub left: usize,
}

impl TextTable {
    /// A table with this header and no rows; one name column.
    pub fn new(head: &[&str]) -> Self {
        Self { head: head.iter().map(|h| h.to_string()).collect(), rows: Vec::new(), left: 1 }
    }

    /// Aligned text, each line ending in `\n` without trailing blanks.
    pub fn aligned(&self) -> String {
        let mut t = Table::new();
        t.load_style(NOTHING).add_row(self.head.clone());
        // the rule under the header is a row of dashes as wide as each column
        let widths: Vec<usize> = {
            let mut m = Table::new();
            m.load_style(NOTHING).add_row(self.head.clone()).add_rows(self.rows.clone());
            m.column_max_content_widths().iter().map(|&w| w as usize).collect()
        };
        t.add_row(widths.iter().map(|&w| "-".repeat(w)).collect::<Vec<_>>());
        t.add_rows(self.rows.clone());
        let last = self.head.len().saturating_sub(1);
        for (c, col) in t.column_iter_mut().enumerate() {
            col.set_padding((0, if c < last { 2 } else { 0 }));
            if c >= self.left {
                col.set_cell_alignment(CellAlignment::Right);
            }
        }
        let mut text: String = t.trim_fmt().lines().map(|l| l.trim_end().to_string() + "\n").collect();
        if self.head.is_empty() {
            text.clear();
        }
        text
    }

    /// A GitHub pipe table (names left, numbers right), `|` in cells escaped.
    pub fn markdown(&self) -> String {
        let cell = |s: &str| s.replace('|', "\\|");
        let row = |cells: &[String]| format!("| {} |\n", cells.iter().map(|c| cell(c)).collect::<Vec<_>>().join(" | "));
        let rule: Vec<String> = (0..self.head.len()).map(|c| if c < self.left { ":--" } else { "--:" }.to_string()).collect();
        let mut out = row(&self.head) + &row(&rule);
        for r in &self.rows {
            out.push_str(&row(r));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_align_names_left_and_numbers_right() {
        let mut t = TextTable::new(&["run", "x rms [mm]", "y rms [mm]"]);
        t.rows.push(vec!["two-elbow".into(), "3.602".into(), "3.789".into()]);
        t.rows.push(vec!["é日本".into(), "10.472".into(), "-".into()]);
        let want = "\
run        x rms [mm]  y rms [mm]
---------  ----------  ----------
two-elbow       3.602       3.789
é日本          10.472           -
";
        assert_eq!(t.aligned(), want);
        assert_eq!(t.markdown().lines().nth(1), Some("| :-- | --: | --: |"));
    }
}
