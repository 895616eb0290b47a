//! Drawing one figure (one or more stacked panels of lines) with plotters, as SVG and PNG.
//!
//! Long series are thinned before drawing: a time series keeps the smallest and largest value
//! of each of at most [`BUCKETS`] consecutive groups of samples (so spikes stay visible), a
//! path in a plane keeps every k-th point.

use std::path::Path;

use image::ImageEncoder;
use plotters::coord::Shift;
use plotters::prelude::*;

/// At most this many groups of samples per time series (two points each).
const BUCKETS: usize = 1200;
/// At most this many points per path.
const PATH_POINTS: usize = 2500;

const MARGIN: u32 = 14;
const X_LABEL_AREA: u32 = 52;
const Y_LABEL_AREA: u32 = 92;
const SUBTITLE_PX: u32 = 18;

/// Run (or joint) colours, in order (matplotlib's tab10, red second).
pub(super) const COLORS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(90, 90, 90),
];

/// How a line is drawn and named in the legend.
pub(super) struct Line {
    pub label: String,
    pub color: RGBColor,
    pub dashed: bool,
    /// A path in a plane (thinned by stride) rather than a time series (thinned by min/max).
    pub path: bool,
    /// Mark the first point with a dot (where a path starts).
    pub start_dot: bool,
    /// Stroke width, px.
    pub width: u32,
    pub points: Vec<(f64, f64)>,
}

impl Line {
    pub fn series(label: String, color: RGBColor, t: &[f64], y: &[f64]) -> Self {
        Line {
            label,
            color,
            dashed: false,
            path: false,
            start_dot: false,
            width: 2,
            points: t.iter().copied().zip(y.iter().copied()).collect(),
        }
    }
}

/// One chart: axes, lines, legend.
pub(super) struct Panel {
    pub subtitle: Option<String>,
    pub x_desc: String,
    pub y_desc: String,
    pub lines: Vec<Line>,
    /// A black horizontal line at y = 0 with this legend label.
    pub zero_line: Option<String>,
    /// One metre is as long on the x axis as on the y axis.
    pub equal_aspect: bool,
    pub legend: SeriesLabelPosition,
    /// No legend box (the figure has a legend strip instead).
    pub no_legend: bool,
    /// Room above the highest line, as a fraction of the data's y range (for the legend).
    pub top_pad: f64,
    /// Fixed y range (set by [`Plot::share_y`]).
    y_range: Option<(f64, f64)>,
}

impl Panel {
    pub fn new(x_desc: &str, y_desc: &str, lines: Vec<Line>) -> Self {
        Panel {
            subtitle: None,
            x_desc: x_desc.into(),
            y_desc: y_desc.into(),
            lines,
            zero_line: None,
            equal_aspect: false,
            legend: SeriesLabelPosition::UpperLeft,
            no_legend: false,
            top_pad: 0.06,
            y_range: None,
        }
    }
}

/// A figure: a title over panels stacked top to bottom.
pub(super) struct Plot {
    pub title: String,
    pub panels: Vec<Panel>,
    pub size: (u32, u32),
    /// A legend in one row under the title, for all panels.
    pub legend_strip: Vec<(String, RGBColor)>,
    /// All panels get the same y range.
    pub share_y: bool,
}

/// Writes `<stem>.svg` and `<stem>.png`.
pub(super) fn write(plot: &Plot, stem: &Path) -> Result<(), String> {
    save_svg_png(stem, plot.size, |a| draw(a, plot), |a| draw(a, plot))
}

/// Draws a figure of `size` pixels twice, with `svg` and `png`, in memory, and writes
/// `<stem>.svg` and `<stem>.png` each atomically and exclusively (`schemas::atomic`; plotters'
/// own file backends write in place). The PNG is encoded as plotters encodes its files (the
/// `image` crate's PNG defaults). Errors name the file.
pub(super) fn save_svg_png(
    stem: &Path,
    size: (u32, u32),
    svg: impl FnOnce(DrawingArea<SVGBackend, Shift>) -> Result<(), String>,
    png: impl FnOnce(DrawingArea<BitMapBackend, Shift>) -> Result<(), String>,
) -> Result<(), String> {
    let svg_path = stem.with_extension("svg");
    let png_path = stem.with_extension("png");
    let mut text = String::new();
    svg(SVGBackend::with_string(&mut text, size).into_drawing_area())
        .map_err(|e| format!("{}: {e}", svg_path.display()))?;
    schemas::atomic::write_file(&svg_path, text).map_err(|e| e.to_string())?;
    let (w, h) = size;
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    png(BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area())
        .map_err(|e| format!("{}: {e}", png_path.display()))?;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(&rgb, w, h, image::ColorType::Rgb8)
        .map_err(|e| format!("{}: encoding the PNG: {e}", png_path.display()))?;
    schemas::atomic::write_file(&png_path, bytes).map_err(|e| e.to_string())?;
    Ok(())
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, plot: &Plot) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let mut body = root.titled(&plot.title, ("sans-serif", 24)).map_err(e)?;
    if !plot.legend_strip.is_empty() {
        let (strip, rest) = body.split_vertically(34);
        draw_strip(&strip, &plot.legend_strip).map_err(e)?;
        body = rest;
    }
    let shared = if plot.share_y {
        plot.panels
            .iter()
            .filter_map(|p| bounds(&p.lines))
            .reduce(|a, b| {
                [
                    a[0].min(b[0]),
                    a[1].max(b[1]),
                    a[2].min(b[2]),
                    a[3].max(b[3]),
                ]
            })
    } else {
        None
    };
    let areas = body.split_evenly((plot.panels.len().max(1), 1));
    for (area, panel) in areas.iter().zip(&plot.panels) {
        match shared {
            Some(b) => {
                let y_range = Some(padded(b[2], b[3], 0.06));
                draw_panel(
                    area,
                    &Panel {
                        y_range,
                        ..panel.clone_frame()
                    },
                    &panel.lines,
                )?
            }
            None => draw_panel(area, panel, &panel.lines)?,
        }
    }
    root.present().map_err(e)
}

/// Smallest and largest finite x and y over all lines, or `None` without a finite point.
fn bounds(lines: &[Line]) -> Option<[f64; 4]> {
    let mut b = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    for &(x, y) in lines.iter().flat_map(|l| &l.points) {
        if x.is_finite() && y.is_finite() {
            b = [b[0].min(x), b[1].max(x), b[2].min(y), b[3].max(y)];
        }
    }
    (b[0] <= b[1]).then_some(b)
}

/// `lo..hi` widened by `pad` of its length on both sides, or to a unit-ish width if empty.
fn padded(lo: f64, hi: f64, pad: f64) -> (f64, f64) {
    let w = hi - lo;
    if w > 1e-12 * lo.abs().max(hi.abs()) && w > 0.0 {
        (lo - pad * w, hi + pad * w)
    } else {
        let h = (0.1 * lo.abs())
            .max(1e-9)
            .max(if lo == 0.0 { 1.0 } else { 0.0 });
        (lo - h, hi + h)
    }
}

/// Widens the range with fewer units per pixel so both axes have the same scale.
fn equalize(x: &mut (f64, f64), y: &mut (f64, f64), w_px: f64, h_px: f64) {
    let (ux, uy) = ((x.1 - x.0) / w_px, (y.1 - y.0) / h_px);
    let u = ux.max(uy);
    let widen = |r: &mut (f64, f64), px: f64| {
        let (c, half) = ((r.0 + r.1) / 2.0, u * px / 2.0);
        *r = (c - half, c + half);
    };
    widen(x, w_px);
    widen(y, h_px);
}

impl Panel {
    /// Everything but the lines.
    fn clone_frame(&self) -> Panel {
        Panel {
            subtitle: self.subtitle.clone(),
            x_desc: self.x_desc.clone(),
            y_desc: self.y_desc.clone(),
            lines: Vec::new(),
            zero_line: self.zero_line.clone(),
            equal_aspect: self.equal_aspect,
            legend: self.legend.clone(),
            no_legend: self.no_legend,
            top_pad: self.top_pad,
            y_range: self.y_range,
        }
    }
}

/// Legend entries side by side, centred.
fn draw_strip<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, RGBColor)],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = TextStyle::from(("sans-serif", 16).into_font());
    let widths: Vec<i32> = entries
        .iter()
        .map(|(label, _)| {
            area.estimate_text_size(label, &font)
                .map(|(w, _)| w as i32 + 30 + 18)
        })
        .collect::<Result<_, _>>()?;
    let (w, h) = area.dim_in_pixel();
    let mut x = (w as i32 - widths.iter().sum::<i32>()).max(0) / 2;
    let y = h as i32 / 2;
    for ((label, color), width) in entries.iter().zip(widths) {
        area.draw(&PathElement::new(
            vec![(x, y), (x + 24, y)],
            color.stroke_width(3),
        ))?;
        area.draw(&Text::new(label.clone(), (x + 30, y - 8), font.clone()))?;
        x += width;
    }
    Ok(())
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    lines: &[Line],
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let Some([x0, x1, mut y0, mut y1]) = bounds(lines) else {
        let (w, h) = area.dim_in_pixel();
        let style = TextStyle::from(("sans-serif", 20).into_font()).pos(
            plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Center,
                plotters::style::text_anchor::VPos::Center,
            ),
        );
        let what = panel.subtitle.as_deref().unwrap_or("this figure");
        area.draw_text(
            &format!("no data for {what} in the recordings"),
            &style,
            (w as i32 / 2, h as i32 / 2),
        )
        .map_err(e)?;
        return Ok(());
    };
    if panel.zero_line.is_some() {
        (y0, y1) = (y0.min(0.0), y1.max(0.0));
    }
    let mut xr = if panel.equal_aspect {
        padded(x0, x1, 0.05)
    } else {
        (x0, x1)
    };
    if xr.1 <= xr.0 {
        xr = padded(x0, x1, 0.0);
    }
    let mut yr = padded(y0, y1, 0.06);
    yr.1 += (panel.top_pad - 0.06).max(0.0) * (yr.1 - yr.0) / 1.12;
    if let Some(r) = panel.y_range {
        yr = r;
    }
    if panel.equal_aspect {
        let (w, h) = area.dim_in_pixel();
        let sub = if panel.subtitle.is_some() {
            SUBTITLE_PX + 10
        } else {
            0
        };
        let w_px = w.saturating_sub(2 * MARGIN + Y_LABEL_AREA).max(1) as f64;
        let h_px = h.saturating_sub(2 * MARGIN + X_LABEL_AREA + sub).max(1) as f64;
        equalize(&mut xr, &mut yr, w_px, h_px);
    }
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(MARGIN)
        .margin_right(MARGIN + 16)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA);
    if let Some(s) = &panel.subtitle {
        builder.caption(s, ("sans-serif", SUBTITLE_PX));
    }
    let mut chart = builder
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(panel.x_desc.as_str())
        .y_desc(panel.y_desc.as_str())
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(e)?;
    if let Some(label) = &panel.zero_line {
        chart
            .draw_series(LineSeries::new(
                [(xr.0, 0.0), (xr.1, 0.0)],
                BLACK.stroke_width(1),
            ))
            .map_err(e)?
            .label(label.as_str())
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], BLACK.stroke_width(1)));
    }
    for line in lines {
        let pts = thin(line);
        if pts.is_empty() {
            continue;
        }
        let (style, width) = (line.color.stroke_width(line.width), line.width);
        let color = line.color;
        let dashed = line.dashed;
        let anno = if dashed {
            chart
                .draw_series(DashedLineSeries::new(pts.clone(), 9, 6, style))
                .map_err(e)?
        } else {
            chart
                .draw_series(LineSeries::new(pts.clone(), style))
                .map_err(e)?
        };
        anno.label(line.label.as_str()).legend(move |(x, y)| {
            let s = color.stroke_width(width);
            let (a, b) = if dashed { (9, 15) } else { (24, 0) };
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (a, 0)], s)
                + PathElement::new(vec![(b, 0), (24, 0)], s)
        });
        if line.start_dot {
            chart
                .draw_series(std::iter::once(Circle::new(pts[0], 5, color.filled())))
                .map_err(e)?;
        }
    }
    if panel.no_legend {
        return Ok(());
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.88))
        .border_style(RGBColor(120, 120, 120))
        .label_font(("sans-serif", 15))
        .position(panel.legend.clone())
        .margin(12)
        .draw()
        .map_err(e)
}

/// The finite points of a line, thinned (see the module documentation).
fn thin(line: &Line) -> Vec<(f64, f64)> {
    let pts: Vec<(f64, f64)> = line
        .points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    if line.path {
        if pts.len() <= PATH_POINTS {
            return pts;
        }
        let step = pts.len().div_ceil(PATH_POINTS);
        let mut out: Vec<_> = pts.iter().copied().step_by(step).collect();
        if !(pts.len() - 1).is_multiple_of(step) {
            out.push(pts[pts.len() - 1]);
        }
        return out;
    }
    min_max_thin(&pts, BUCKETS)
}

/// Per group of consecutive points, the points with the smallest and largest y, in order.
pub(super) fn min_max_thin(pts: &[(f64, f64)], buckets: usize) -> Vec<(f64, f64)> {
    if pts.len() <= 2 * buckets {
        return pts.to_vec();
    }
    let size = pts.len().div_ceil(buckets);
    let mut out = Vec::with_capacity(2 * buckets + 2);
    for chunk in pts.chunks(size) {
        let (mut lo, mut hi) = (0, 0);
        for (k, p) in chunk.iter().enumerate() {
            if p.1 < chunk[lo].1 {
                lo = k;
            }
            if p.1 > chunk[hi].1 {
                hi = k;
            }
        }
        let (a, b) = (lo.min(hi), lo.max(hi));
        out.push(chunk[a]);
        if b != a {
            out.push(chunk[b]);
        }
    }
    if out.last() != pts.last() {
        out.push(pts[pts.len() - 1]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thinning_keeps_spikes_and_ends() {
        let mut pts: Vec<(f64, f64)> = (0..10_000).map(|k| (k as f64, 0.0)).collect();
        pts[4321].1 = -31.0;
        pts[777].1 = 5.0;
        let out = min_max_thin(&pts, 100);
        assert!(out.len() <= 202, "{}", out.len());
        assert!(out.contains(&(4321.0, -31.0)) && out.contains(&(777.0, 5.0)));
        assert_eq!((out[0], *out.last().unwrap()), (pts[0], pts[9999]));
        assert!(out.windows(2).all(|w| w[0].0 < w[1].0));
    }

    #[test]
    fn equal_aspect_gives_both_axes_the_same_scale() {
        let (mut x, mut y) = ((0.0, 1.0), (0.0, 0.1));
        equalize(&mut x, &mut y, 800.0, 400.0);
        assert!(((x.1 - x.0) / 800.0 - (y.1 - y.0) / 400.0).abs() < 1e-15);
        assert_eq!(x, (0.0, 1.0));
        assert_eq!(padded(2.0, 2.0, 0.1), (1.8, 2.2));
        assert_eq!(padded(0.0, 0.0, 0.1), (-1.0, 1.0));
    }
}
