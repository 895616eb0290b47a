//! [`TextTable`]: the aligned plain-text table every table of both tools is printed as (columns
//! two spaces apart, a dashed rule under the header, names left- and numbers right-aligned,
//! Unicode width-aware; drawn by `comfy-table`), and the same table as Markdown; the same table
//! fitted to a width ([`TextTable::fitted`]: a terminal's), and prose wrapped to one ([`wrap`]).

use comfy_table::{presets::NOTHING, CellAlignment, Table};
use unicode_width::UnicodeWidthStr;

/// Blanks between two columns of [`TextTable::aligned`].
const GAP: usize = 2;

/// The narrowest a wrapped column is made, whatever the width asked for.
const MIN_COLUMN: usize = 8;

/// A header row and rows; the first `left` columns (names) are left-aligned, the others
/// (numbers) right-aligned, but the last when `notes` says it is text (notes after the numbers).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TextTable {
    pub head: Vec<String>,
    pub rows: Vec<Vec<String>>,
    pub left: usize,
    pub notes: bool,
}

impl TextTable {
    /// A table with this header and no rows; one name column.
    pub fn new(head: &[&str]) -> Self {
        Self { head: head.iter().map(|h| h.to_string()).collect(), rows: Vec::new(), left: 1, notes: false }
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
            if c >= self.left && !(self.notes && c == last) {
                col.set_cell_alignment(CellAlignment::Right);
            }
        }
        let mut text: String = t.trim_fmt().lines().map(|l| l.trim_end().to_string() + "\n").collect();
        if self.head.is_empty() {
            text.clear();
        }
        text
    }

    /// [`aligned`](Self::aligned), fitted to `width` columns (the text as it is when it fits).
    /// A wider table is split into column groups that each fit, printed one under the other
    /// (a blank line between), each repeating the name columns (the first `left`, or only the
    /// first when they leave no room for the widest other column) so that every row keeps its
    /// name; a column too wide even alone next to the names has its header and cells wrapped
    /// onto more lines (at a blank or after a comma). Cells are never cut or changed otherwise.
    pub fn fitted(&self, width: usize) -> String {
        let full = self.aligned();
        if self.head.is_empty() || full.lines().all(|l| l.width() <= width) {
            return full;
        }
        let widths: Vec<usize> = (0..self.head.len())
            .map(|c| std::iter::once(&self.head[c]).chain(self.rows.iter().filter_map(|r| r.get(c))).map(|s| cell_width(s)).max().unwrap_or(0))
            .collect();
        let span = |cols: &[usize]| cols.iter().map(|&c| widths[c]).sum::<usize>() + GAP * cols.len().saturating_sub(1);
        let left = self.left.clamp(1, self.head.len());
        let widest_other = widths[left..].iter().copied().max().unwrap_or(0);
        let all_names: Vec<usize> = (0..left).collect();
        let keys = if left > 1 && span(&all_names) + GAP + widest_other > width { 1 } else { left };
        if keys == self.head.len() {
            return full;
        }
        let room = width.saturating_sub(span(&(0..keys).collect::<Vec<_>>()) + GAP).max(MIN_COLUMN);
        let mut groups: Vec<Vec<usize>> = Vec::new();
        for c in keys..self.head.len() {
            match groups.last_mut() {
                Some(g) if span(g) + GAP + widths[c].min(room) <= room => g.push(c),
                _ => groups.push(vec![c]),
            }
        }
        let parts: Vec<String> = groups
            .iter()
            .map(|g| {
                let cols: Vec<usize> = (0..keys).chain(g.iter().copied()).collect();
                let pick = |cells: &[String]| cols.iter().map(|&c| cells.get(c).map_or(String::new(), |s| wrap_cell(s, room))).collect::<Vec<_>>();
                TextTable {
                    head: pick(&self.head),
                    rows: self.rows.iter().map(|r| pick(r)).collect(),
                    left: cols.iter().filter(|&&c| c < self.left).count(),
                    notes: self.notes && g.last() == Some(&(self.head.len() - 1)),
                }
                .aligned()
            })
            .collect();
        parts.join("\n")
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

/// The width of a cell: of its widest line.
fn cell_width(s: &str) -> usize {
    s.lines().map(UnicodeWidthStr::width).max().unwrap_or(0)
}

/// A cell wider than `width` broken into lines of at most `width` (at a blank, or after a
/// comma; a word longer than that is broken anywhere), else as it is.
fn wrap_cell(s: &str, width: usize) -> String {
    if cell_width(s) <= width {
        return s.to_string();
    }
    s.lines().map(|l| break_line(l, width, &[' ', ','], "").join("\n")).collect::<Vec<_>>().join("\n")
}

/// `text` as lines of at most `width` columns: broken after any of `at` (a blank at the break
/// is dropped), a piece longer than `width` broken anywhere; every line after the first begins
/// with `indent` (counted in the width).
fn break_line(text: &str, width: usize, at: &[char], indent: &str) -> Vec<String> {
    // the pieces: each ends just after a break character
    let mut pieces: Vec<&str> = Vec::new();
    let mut start = 0;
    for (i, ch) in text.char_indices() {
        if at.contains(&ch) {
            pieces.push(&text[start..i + ch.len_utf8()]);
            start = i + ch.len_utf8();
        }
    }
    if start < text.len() {
        pieces.push(&text[start..]);
    }
    // a unit stays with its number ("352 J"), a minus sign with both its terms ("r − r_d")
    let mut glued: Vec<String> = Vec::new();
    for piece in pieces {
        match glued.last_mut() {
            Some(last) if is_unit(piece) || piece.trim_end() == "−" || last.trim_end().ends_with('−') => last.push_str(piece),
            _ => glued.push(piece.to_string()),
        }
    }
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    let limit = |lines: &Vec<String>| if lines.is_empty() { width } else { width.saturating_sub(indent.width()).max(1) };
    for piece in &glued {
        if !line.is_empty() && (line.clone() + piece).trim_end().width() > limit(&lines) {
            lines.push(std::mem::take(&mut line).trim_end().to_string());
        }
        if line.is_empty() && !lines.is_empty() {
            // a new line does not begin with the blank it was broken at
            let piece = piece.trim_start_matches(' ');
            line.push_str(piece);
        } else {
            line.push_str(piece);
        }
        // a piece longer than a whole line: broken anywhere
        while line.trim_end().width() > limit(&lines) {
            let mut cut = 0;
            let mut w = 0;
            for (i, ch) in line.char_indices() {
                let cw = unicode_width::UnicodeWidthChar::width(ch).unwrap_or(0);
                if w + cw > limit(&lines) {
                    break;
                }
                w += cw;
                cut = i + ch.len_utf8();
            }
            let cut = cut.max(line.chars().next().map_or(0, char::len_utf8));
            let rest = line.split_off(cut);
            lines.push(line);
            line = rest;
        }
    }
    if !line.trim_end().is_empty() || lines.is_empty() {
        lines.push(line.trim_end().to_string());
    }
    lines.into_iter().enumerate().map(|(k, l)| if k == 0 { l } else { format!("{indent}{l}") }).collect()
}

/// Whether `word` (a piece of [`break_line`]) is a unit that follows a number: `J`, `mm`, `s`,
/// `N`, `%`, … with its punctuation (`mm.`, `s)`, `J,`).
fn is_unit(word: &str) -> bool {
    let w = word.trim_end().trim_end_matches(['.', ',', ';', ':', ')']);
    matches!(w, "J" | "mm" | "m" | "s" | "N" | "A" | "V" | "W" | "%" | "m/s" | "rad" | "Hz")
}

/// Prose (one paragraph) as lines of at most `width` columns, broken at blanks, the first line
/// beginning with `first` and the others with `rest` (a list item: `"- "` and `"  "`); each line
/// ends in `\n`. Words are never broken unless one alone is wider than a line.
pub fn wrap(text: &str, width: usize, first: &str, rest: &str) -> String {
    let lines = break_line(&format!("{first}{text}"), width, &[' '], rest);
    lines.into_iter().map(|l| l + "\n").collect()
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

    /// A table wider than the width is split into column groups that each fit and repeat the
    /// name columns; every cell is still there, unchanged.
    #[test]
    fn a_wide_table_splits_into_column_groups_that_fit() {
        let mut t = TextTable::new(&["run", "contact", "a long header [J]", "another header [s]", "third [N]"]);
        t.left = 2;
        t.rows.push(vec!["two-elbow".into(), "elbow4".into(), "113.9904".into(), "4.964".into(), "-6.905".into()]);
        t.rows.push(vec!["no-elbow".into(), "elbow7".into(), "3194.5357".into(), "0.024".into(), "-31.661".into()]);
        assert_eq!(t.fitted(200), t.aligned());
        let got = t.fitted(40);
        assert!(got.lines().all(|l| l.width() <= 40), "{got}");
        let want = "\
run        contact  a long header [J]
---------  -------  -----------------
two-elbow  elbow4            113.9904
no-elbow   elbow7           3194.5357

run        contact  another header [s]
---------  -------  ------------------
two-elbow  elbow4                4.964
no-elbow   elbow7                0.024

run        contact  third [N]
---------  -------  ---------
two-elbow  elbow4      -6.905
no-elbow   elbow7     -31.661
";
        assert_eq!(got, want);
    }

    /// Names that leave no room: only the first is repeated; a column too wide even alone is
    /// wrapped in its cells (after a comma), not cut.
    #[test]
    fn a_column_too_wide_alone_wraps_its_cells() {
        let mut t = TextTable::new(&["run", "contacts", "t [s]"]);
        t.left = 2;
        t.rows.push(vec!["whole-table".into(), "joint3,elbow4,joint5,joint6,elbow7,joint8".into(), "5.000".into()]);
        let got = t.fitted(30);
        assert!(got.lines().all(|l| l.width() <= 30), "{got}");
        assert!(got.contains("whole-table  joint3,elbow4,\n             joint5,joint6,\n             elbow7,joint8\n"), "{got}");
        assert!(got.contains("whole-table  5.000"), "{got}");
    }

    #[test]
    fn prose_wraps_at_blanks_with_a_hanging_indent() {
        let s = "In two-elbow, the bilateral table pulls elbow4 down for 99 % of the run (4.96 of 5.00 s).";
        let got = wrap(s, 40, "- ", "  ");
        assert_eq!(got, "- In two-elbow, the bilateral table\n  pulls elbow4 down for 99 % of the run\n  (4.96 of 5.00 s).\n");
        assert_eq!(wrap("short", 40, "", ""), "short\n");
        // a word longer than a line is broken, nothing is lost
        let long = wrap("x 0123456789abcdef", 8, "", "");
        assert_eq!(long.replace(['\n', ' '], ""), "x0123456789abcdef");
        assert!(long.lines().all(|l| l.width() <= 8), "{long}");
    }
}
