//! A figure's SVG as plotters wrote it, finished ([`finish_svg`]), and its PNG rendered from
//! that SVG ([`png_from_svg`]) so both show the same text.
//!
//! Why not plotters' bitmap backend: its `ab_glyph` text path places each glyph's bitmap at the
//! pen position without the glyph's left bearing (`px_bounds().min.x`, ab_glyph's docs on
//! `OutlinedGlyph::px_bounds`) and truncates the pen to whole pixels, so narrow letters sit too
//! far left and leave gaps ("tim e t [s]"); it has no shaping (no combining marks) and draws
//! lines without anti-aliasing. resvg (usvg's SVG 1.1/2 text layout, shaping with harfrust, the
//! embedded DejaVu Sans only: no system fonts, so every machine renders the same pixels) draws
//! the SVG as a browser does.

use std::sync::{Arc, OnceLock};

use super::markup;

/// The family every figure names: DejaVu Sans (embedded for the PNG), else the viewer's sans.
const FAMILY: &str = "DejaVu Sans, sans-serif";

/// plotters' SVG with the embedded font's family (a browser without it falls back to its sans
/// serif) and sub/superscripts as `<tspan>`s ([`markup`]).
pub(super) fn finish_svg(svg: &str) -> String {
    markup::svg_tspans(&svg.replace(r#"font-family="sans-serif""#, &format!(r#"font-family="{FAMILY}""#)))
}

/// The font database of every render: DejaVu Sans alone, the sans-serif family.
fn options() -> &'static resvg::usvg::Options<'static> {
    static OPTIONS: OnceLock<resvg::usvg::Options<'static>> = OnceLock::new();
    OPTIONS.get_or_init(|| {
        let mut db = resvg::usvg::fontdb::Database::new();
        db.load_font_data(super::FONT.to_vec());
        db.set_sans_serif_family("DejaVu Sans");
        resvg::usvg::Options {
            font_family: "DejaVu Sans".into(),
            fontdb: Arc::new(db),
            ..Default::default()
        }
    })
}

/// The PNG (8-bit RGBA, opaque where the figure fills its background) of a finished SVG, at one
/// pixel per SVG unit.
pub(super) fn png_from_svg(svg: &str) -> Result<Vec<u8>, String> {
    let tree = resvg::usvg::Tree::from_str(svg, options()).map_err(|e| format!("reading the SVG: {e}"))?;
    let size = tree.size().to_int_size();
    let mut pixmap = resvg::tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| format!("an empty figure ({} x {} px)", size.width(), size.height()))?;
    resvg::render(&tree, resvg::tiny_skia::Transform::identity(), &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|e| format!("encoding the PNG: {e}"))
}

/// The horizontal extent, px, of `text` at `size_px` (the SVG font size) as the PNG renders it:
/// the ink's left and right edges, from a render of the text alone.
#[cfg(test)]
pub(super) fn ink_columns(text: &str, size_px: f64) -> Vec<bool> {
    let (w, h) = (60 + (text.chars().count() as f64 * size_px) as u32, (3.0 * size_px) as u32);
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}"><rect width="{w}" height="{h}" fill="white"/><text x="10" y="{}" font-family="{FAMILY}" font-size="{size_px}">{text}</text></svg>"#,
        2.0 * size_px
    );
    let tree = resvg::usvg::Tree::from_str(&svg, options()).unwrap();
    let mut pixmap = resvg::tiny_skia::Pixmap::new(w, h).unwrap();
    resvg::render(&tree, resvg::tiny_skia::Transform::identity(), &mut pixmap.as_mut());
    (0..w)
        .map(|x| (0..h).any(|y| pixmap.pixel(x, y).is_some_and(|p| p.red() < 128)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The gaps between the letters of "time" at the axis-label size: with the bearing bug
    /// the gap before "e" was 2-3 times the others; here every gap between the letters of one
    /// word is at most 3 px (DejaVu Sans at 14 px: 1-2 px) and the space is wider than any.
    #[test]
    fn png_text_has_even_letter_spacing() {
        let cols = ink_columns("time t", 14.0);
        // runs of blank columns between the first and last ink
        let first = cols.iter().position(|&c| c).expect("some ink");
        let last = cols.iter().rposition(|&c| c).unwrap();
        let mut gaps = Vec::new();
        let mut run = 0;
        for &c in &cols[first..=last] {
            if c {
                if run > 0 {
                    gaps.push(run);
                }
                run = 0;
            } else {
                run += 1;
            }
        }
        // "t|i|m|e| |t": letters touching their neighbour have no gap; the space is the widest
        let widest = *gaps.iter().max().unwrap();
        let word: Vec<_> = gaps.iter().filter(|&&g| g != widest).collect();
        assert!(widest >= 4, "the space between the words: {gaps:?}");
        assert!(word.iter().all(|&&g| g <= 3), "gaps inside \"time\": {gaps:?}");
    }

    #[test]
    fn the_svg_names_the_font_and_shifts_subscripts() {
        let svg = finish_svg(&format!(r#"<text font-family="sans-serif">W{}</text>"#, markup::sub(1)));
        assert!(svg.contains("DejaVu Sans, sans-serif") && svg.contains(r#"baseline-shift="sub""#), "{svg}");
        let png = png_from_svg(&format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="40" height="20"><rect width="40" height="20" fill="white"/>{svg}</svg>"#
        ))
        .unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }
}
