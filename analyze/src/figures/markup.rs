//! Sub- and superscripts in figure text: `W₁`, `r_d` as the reader expects them, never a literal
//! `_` or `^`.
//!
//! A label marks a subscript with [`sub`] and a superscript with [`sup`]: the text between
//! private-use code points (U+E000 subscript, U+E001 superscript, U+E002 end; Unicode §23.5,
//! private use, so no font draws them and no real text contains them). plotters passes them
//! through to the SVG untouched; [`svg_tspans`] turns them into `<tspan>`s with SVG 1.1's
//! `baseline-shift="sub"`/`"super"` at 70 % of the font size (SVG 1.1 §10.9.2, which resvg
//! renders for the PNG and every browser for the SVG); [`html`] into `<sub>`/`<sup>` for the
//! index pages; [`plain`] drops the marks (terminal text, `alt` attributes).

/// Starts a subscript.
pub(super) const SUB: char = '\u{E000}';
/// Starts a superscript.
pub(super) const SUP: char = '\u{E001}';
/// Ends either.
pub(super) const END: char = '\u{E002}';

/// `text` as a subscript.
pub(super) fn sub(text: impl std::fmt::Display) -> String {
    format!("{SUB}{text}{END}")
}

/// `text` as a superscript.
pub(super) fn sup(text: impl std::fmt::Display) -> String {
    format!("{SUP}{text}{END}")
}

/// The SVG document with every marked span as a shifted, smaller `<tspan>`.
pub(super) fn svg_tspans(svg: &str) -> String {
    svg.replace(SUB, r#"<tspan baseline-shift="sub" font-size="70%">"#)
        .replace(SUP, r#"<tspan baseline-shift="super" font-size="70%">"#)
        .replace(END, "</tspan>")
}

/// HTML (and Markdown, which passes inline HTML through) with `<sub>`/`<sup>`; `text` must
/// already be escaped.
pub fn html(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 16);
    let mut open = Vec::new();
    for c in text.chars() {
        match c {
            SUB => {
                out.push_str("<sub>");
                open.push("</sub>");
            }
            SUP => {
                out.push_str("<sup>");
                open.push("</sup>");
            }
            END => out.push_str(open.pop().unwrap_or_default()),
            c => out.push(c),
        }
    }
    out
}

/// The text without the marks.
pub fn plain(text: &str) -> String {
    text.chars().filter(|c| ![SUB, SUP, END].contains(c)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marks_become_tspans_sub_tags_or_nothing() {
        let label = format!("W{} = ∫ τ{} q̇{} dt, r{}", sub(3), sub(3), sub(3), sub("d"));
        let svg = svg_tspans(&format!("<text>{label}</text>"));
        assert_eq!(svg.matches(r#"<tspan baseline-shift="sub" font-size="70%">"#).count(), 4, "{svg}");
        assert_eq!(svg.matches("</tspan>").count(), 4);
        assert_eq!(html(&format!("x{}", sup(2))), "x<sup>2</sup>");
        assert_eq!(plain(&label), "W3 = ∫ τ3 q̇3 dt, rd");
        assert!(!svg.contains(SUB) && !svg.contains(END));
    }
}
