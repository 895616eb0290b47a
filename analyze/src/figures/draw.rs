//! Drawing one figure (a grid of panels of lines, under a title and a legend strip) with
//! plotters as SVG, and its PNG rendered from that SVG ([`super::render`]).
//!
//! Line styles mean the same in every figure: one colour per run (its place in the list of
//! runs, [`COLORS`]), every line [`LINE_WIDTH`] px wide, dashed only for the target r_d; a
//! thin black line is y = 0 where the sign matters (the table's force). One legend strip under
//! the title explains every colour and dash of the figure; panels have none, so no legend hides
//! data. The y axis of each panel follows [`super::scale`]: a log axis when the lines differ by
//! more than a decade, a range that a short start-up spike does not set (the spike's extreme
//! value written in the panel), ticks without useless decimals.
//!
//! Long series are thinned before drawing: a time series keeps the smallest and largest value
//! of each of at most [`BUCKETS`] consecutive groups of samples (so spikes stay visible), a
//! path in a plane keeps every k-th point.

use std::path::Path;

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::{render, scale};

/// At most this many groups of samples per time series (two points each).
const BUCKETS: usize = 1200;
/// At most this many points per path.
const PATH_POINTS: usize = 2500;

const MARGIN: u32 = 12;
const X_LABEL_AREA: u32 = 50;
/// Under a panel that is not in the bottom row: tick labels only.
const X_TICKS_AREA: u32 = 28;
const Y_LABEL_AREA: u32 = 84;
const SUBTITLE_PX: u32 = 18;
/// Every line of every figure, px.
pub(super) const LINE_WIDTH: u32 = 2;
/// A legend strip row, px.
const STRIP_ROW: u32 = 26;

/// Run colours, in order (matplotlib's tab10, red second).
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
            points: t.iter().copied().zip(y.iter().copied()).collect(),
        }
    }
}

/// One entry of a legend strip: a label and how its lines look.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Key {
    pub label: String,
    pub color: RGBColor,
    pub dashed: bool,
    /// A thin line (the y = 0 line) rather than a data line.
    pub thin: bool,
    /// Text only, no line (a remark on the figure).
    pub text_only: bool,
}

impl Key {
    pub fn line(label: impl Into<String>, color: RGBColor) -> Self {
        Key { label: label.into(), color, dashed: false, thin: false, text_only: false }
    }
}

/// One chart: axes and lines.
pub(super) struct Panel {
    pub subtitle: Option<String>,
    pub x_desc: String,
    pub y_desc: String,
    pub lines: Vec<Line>,
    /// A thin black horizontal line at y = 0 (and y = 0 inside the range).
    pub zero_line: bool,
    /// One metre is as long on the x axis as on the y axis.
    pub equal_aspect: bool,
    /// Unit of y for the note on values outside a robust range ([`scale::robust_range`]);
    /// `None`: the whole range is shown.
    pub robust_unit: Option<String>,
    /// A log y axis when [`scale::wants_log`] says so.
    pub log_allowed: bool,
}

impl Panel {
    pub fn new(x_desc: &str, y_desc: &str, lines: Vec<Line>) -> Self {
        Panel {
            subtitle: None,
            x_desc: x_desc.into(),
            y_desc: y_desc.into(),
            lines,
            zero_line: false,
            equal_aspect: false,
            robust_unit: None,
            log_allowed: false,
        }
    }
}

/// A figure: a title over a legend strip over panels in a grid of `cols` columns, filled row
/// by row.
pub(super) struct Plot {
    pub title: String,
    pub panels: Vec<Panel>,
    pub size: (u32, u32),
    pub legend: Vec<Key>,
    pub cols: usize,
}

/// Writes `<stem>.svg` and `<stem>.png`.
pub(super) fn write(plot: &Plot, stem: &Path) -> Result<(), String> {
    save_svg_png(stem, plot.size, |a| draw(a, plot))
}

/// A one-panel chart under a caption, with the figures' margin and label areas (the study
/// figures and the work–precision diagram).
pub(super) fn single_chart<'a, DB: DrawingBackend, X: AsRangedCoord, Y: AsRangedCoord>(
    root: &'a DrawingArea<DB, Shift>,
    title: &str,
    x: X,
    y: Y,
) -> Result<ChartContext<'a, DB, Cartesian2d<X::CoordDescType, Y::CoordDescType>>, DrawingAreaErrorKind<DB::ErrorType>> {
    ChartBuilder::on(root).caption(title, ("sans-serif", 22)).margin(16).x_label_area_size(48).y_label_area_size(80).build_cartesian_2d(x, y)
}

/// The legend box of a one-panel chart ([`single_chart`]), upper right.
pub(super) fn legend_box<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(chart: &mut ChartContext<'a, DB, CT>) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    DB::ErrorType: 'static,
{
    chart.configure_series_labels().background_style(WHITE.mix(0.85)).border_style(BLACK).label_font(("sans-serif", 14)).position(SeriesLabelPosition::UpperRight).draw()
}

/// Draws a figure of `size` pixels as SVG in memory, renders its PNG from it, and writes
/// `<stem>.svg` and `<stem>.png` each atomically (`schemas::atomic`). Errors name the file.
pub(super) fn save_svg_png(
    stem: &Path,
    size: (u32, u32),
    svg: impl FnOnce(DrawingArea<SVGBackend, Shift>) -> Result<(), String>,
) -> Result<(), String> {
    let svg_path = stem.with_extension("svg");
    let png_path = stem.with_extension("png");
    let mut text = String::new();
    svg(SVGBackend::with_string(&mut text, size).into_drawing_area())
        .map_err(|e| format!("{}: {e}", svg_path.display()))?;
    let text = render::finish_svg(&text);
    let png = render::png_from_svg(&text).map_err(|e| format!("{}: {e}", png_path.display()))?;
    schemas::atomic::write_file(&svg_path, text).map_err(|e| e.to_string())?;
    schemas::atomic::write_file(&png_path, png).map_err(|e| e.to_string())?;
    Ok(())
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, plot: &Plot) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let mut body = root.titled(&plot.title, ("sans-serif", 24)).map_err(e)?;
    if !plot.legend.is_empty() {
        let rows = strip_rows(&body, &plot.legend).map_err(e)?;
        let (strip, rest) = body.split_vertically(STRIP_ROW * rows.len() as u32 + 6);
        draw_strip(&strip, &rows).map_err(e)?;
        body = rest;
    }
    let cols = plot.cols.max(1);
    let rows = plot.panels.len().div_ceil(cols).max(1);
    let areas = body.split_evenly((rows, cols));
    for (k, (area, panel)) in areas.iter().zip(&plot.panels).enumerate() {
        let bottom = k / cols == rows - 1 || k + cols >= plot.panels.len();
        draw_panel(area, panel, bottom)?;
    }
    root.present().map_err(e)
}

/// The y range a panel's lines are judged on (before padding): the log range when the panel
/// gets a log axis (`true`), else the robust range where the panel asks for one, else the data's.
pub(super) fn y_span(panel: &Panel) -> Option<(f64, f64, bool)> {
    let pts: Vec<&[(f64, f64)]> = panel.lines.iter().map(|l| l.points.as_slice()).collect();
    if let Some((lo, hi)) = scale::wants_log(&pts).filter(|_| panel.log_allowed && !panel.equal_aspect) {
        return Some((lo, hi, true));
    }
    let ys = || panel.lines.iter().flat_map(|l| l.points.iter().map(|p| p.1));
    if panel.robust_unit.is_some() {
        return scale::robust_range(ys()).map(|((a, b), _)| (a, b, false));
    }
    bounds(&panel.lines).map(|b| (b[2], b[3], false))
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

fn strip_font() -> TextStyle<'static> {
    TextStyle::from(("sans-serif", 16).into_font())
}

/// The legend entries in rows that fit the width, each with its width, px.
fn strip_rows<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    keys: &[Key],
) -> Result<Vec<Vec<(Key, i32)>>, DrawingAreaErrorKind<DB::ErrorType>> {
    let (w, _) = area.dim_in_pixel();
    let mut rows: Vec<Vec<(Key, i32)>> = vec![Vec::new()];
    let mut used = 0;
    for key in keys {
        let line = if key.text_only { 0 } else { 30 };
        let width = area.estimate_text_size(&super::markup::plain(&key.label), &strip_font())?.0 as i32 + line + 22;
        if used + width > w as i32 - 20 && !rows.last().is_some_and(Vec::is_empty) {
            rows.push(Vec::new());
            used = 0;
        }
        used += width;
        if let Some(row) = rows.last_mut() {
            row.push((key.clone(), width));
        }
    }
    Ok(rows)
}

/// Legend rows, each centred: a short line in each entry's style, then its label.
fn draw_strip<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    rows: &[Vec<(Key, i32)>],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (w, _) = area.dim_in_pixel();
    for (r, row) in rows.iter().enumerate() {
        let mut x = (w as i32 - row.iter().map(|k| k.1).sum::<i32>()).max(0) / 2;
        let y = (STRIP_ROW as i32) * r as i32 + STRIP_ROW as i32 / 2 + 2;
        for (key, width) in row {
            if key.text_only {
                area.draw(&Text::new(key.label.clone(), (x, y - 9), strip_font().color(&RGBColor(70, 70, 70))))?;
                x += width;
                continue;
            }
            let style = key.color.stroke_width(if key.thin { 1 } else { LINE_WIDTH });
            let pieces: &[(i32, i32)] = if key.dashed { &[(0, 8), (13, 24)] } else { &[(0, 24)] };
            for &(a, b) in pieces {
                area.draw(&PathElement::new(vec![(x + a, y), (x + b, y)], style))?;
            }
            area.draw(&Text::new(key.label.clone(), (x + 30, y - 9), strip_font()))?;
            x += width;
        }
    }
    Ok(())
}

/// "43.2" for 43.2189: three significant digits, as a tick label.
fn three_digits(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return scale::tick(v);
    }
    let p = 10f64.powi(2 - v.abs().log10().floor() as i32);
    scale::tick((v * p).round() / p)
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, panel: &Panel, bottom: bool) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let lines: Vec<Line> = panel
        .lines
        .iter()
        .map(|l| Line { label: l.label.clone(), points: thin(l), ..*l })
        .collect();
    let Some([x0, x1, mut y0, mut y1]) = bounds(&lines) else {
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
    // the note on what lies outside a robust range: the most extreme value, its time and run
    let mut note = None;
    if let Some(unit) = &panel.robust_unit {
        if let Some(((a, b), true)) = scale::robust_range(lines.iter().flat_map(|l| l.points.iter().map(|p| p.1))) {
            let (a, b) = if panel.zero_line { (a.min(0.0), b.max(0.0)) } else { (a, b) };
            // what the axis shows (padded as below)
            let (a, b) = padded(a, b, 0.06);
            // the most extreme value above the range and the one below, each with its time and run
            let extreme = |above: bool| {
                lines
                    .iter()
                    .flat_map(|l| l.points.iter().map(move |p| (l, *p)))
                    .filter(|(_, p)| if above { p.1 > b } else { p.1 < a })
                    .max_by(|u, v| if above { u.1 .1.total_cmp(&v.1 .1) } else { v.1 .1.total_cmp(&u.1 .1) })
                    .map(|(l, (t, y))| format!("{} {unit} at t = {} s ({})", three_digits(y), three_digits(t), super::markup::plain(&l.label)))
            };
            let parts: Vec<String> = [extreme(true), extreme(false)].into_iter().flatten().map(|p| format!("off scale: {p}")).collect();
            if !parts.is_empty() {
                note = Some(parts);
            }
            let pad = 0.06 / 1.12 * (b - a);
            (y0, y1) = (a + pad, b - pad);
        }
    }
    if panel.zero_line {
        (y0, y1) = (y0.min(0.0), y1.max(0.0));
    }
    // a time axis starts at t = 0 when the first sample is just after it
    let x0 = if !panel.equal_aspect && x0 > 0.0 && x0 < 0.05 * (x1 - x0) { 0.0 } else { x0 };
    let mut xr = if panel.equal_aspect { padded(x0, x1, 0.05) } else { (x0, x1) };
    if xr.1 <= xr.0 {
        xr = padded(x0, x1, 0.0);
    }
    let mut yr = padded(y0, y1, 0.06);
    let x_area = if bottom { X_LABEL_AREA } else { X_TICKS_AREA };
    if panel.equal_aspect {
        let (w, h) = area.dim_in_pixel();
        let sub = if panel.subtitle.is_some() { SUBTITLE_PX + 10 } else { 0 };
        let w_px = w.saturating_sub(2 * MARGIN + Y_LABEL_AREA + 16).max(1) as f64;
        let h_px = h.saturating_sub(2 * MARGIN + x_area + sub).max(1) as f64;
        equalize(&mut xr, &mut yr, w_px, h_px);
    }
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(MARGIN)
        .margin_right(MARGIN + 16)
        .x_label_area_size(x_area)
        .y_label_area_size(Y_LABEL_AREA);
    if let Some(s) = &panel.subtitle {
        builder.caption(s, ("sans-serif", SUBTITLE_PX));
    }
    let pts: Vec<&[(f64, f64)]> = lines.iter().map(|l| l.points.as_slice()).collect();
    let x_desc = if bottom { panel.x_desc.as_str() } else { "" };
    match scale::wants_log(&pts).filter(|_| panel.log_allowed && !panel.equal_aspect) {
        Some((lo, hi)) => {
            let chart = builder.build_cartesian_2d(xr.0..xr.1, (lo..hi).log_scale()).map_err(e)?;
            let y_desc = format!("{} (log scale)", panel.y_desc);
            fill(chart, panel, &lines, (x_desc, &y_desc), (xr, (lo, hi)), true, None)
        }
        None => {
            let chart = builder.build_cartesian_2d(xr.0..xr.1, yr.0..yr.1).map_err(e)?;
            fill(chart, panel, &lines, (x_desc, &panel.y_desc), (xr, yr), false, note)
        }
    }
}

/// The mesh, the lines (cut at the y range) and the note of one panel, on a linear or log y.
fn fill<DB: DrawingBackend, Y>(
    mut chart: ChartContext<'_, DB, Cartesian2d<RangedCoordf64, Y>>,
    panel: &Panel,
    lines: &[Line],
    (x_desc, y_desc): (&str, &str),
    (xr, yr): ((f64, f64), (f64, f64)),
    log: bool,
    note: Option<Vec<String>>,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    std::ops::Range<f64>: AsRangedCoord,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|v| scale::tick_in(*v, xr.1 - xr.0))
        .y_label_formatter(&|v| if log { scale::tick(*v) } else { scale::tick_in(*v, yr.1 - yr.0) })
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(e)?;
    if panel.zero_line {
        chart.draw_series(LineSeries::new([(xr.0, 0.0), (xr.1, 0.0)], BLACK.stroke_width(1))).map_err(e)?;
    }
    for line in lines {
        if line.points.is_empty() {
            continue;
        }
        let style = line.color.stroke_width(LINE_WIDTH);
        let (lo, hi) = (yr.0.min(yr.1), yr.0.max(yr.1));
        for piece in scale::clip_y(&line.points, lo, hi) {
            if line.dashed {
                chart.draw_series(DashedLineSeries::new(piece, 9, 6, style)).map_err(e)?;
            } else {
                chart.draw_series(LineSeries::new(piece, style)).map_err(e)?;
            }
        }
        if line.start_dot && (lo..=hi).contains(&line.points[0].1) {
            chart
                .draw_series(std::iter::once(Circle::new(line.points[0], 5, line.color.filled())))
                .map_err(e)?;
        }
    }
    if let Some(note) = note {
        // one line per side, on a white box in the top left corner of the plotting area
        let area = chart.plotting_area();
        let style = TextStyle::from(("sans-serif", 13).into_font()).color(&RGBColor(60, 60, 60));
        let mut w = 0;
        for line in &note {
            w = w.max(area.estimate_text_size(line, &style).map_err(e)?.0 as i32);
        }
        let row = 16;
        let at = area.map_coordinate(&(xr.0, yr.1));
        let root = area.strip_coord_spec();
        let (ox, oy) = root.get_base_pixel();
        let (bx, by) = (at.0 + 6 - ox, at.1 + 4 - oy);
        let corners = [(bx - 4, by - 2), (bx + w + 4, by + row * note.len() as i32 + 2)];
        root.draw(&Rectangle::new(corners, WHITE.mix(0.9).filled())).map_err(e)?;
        root.draw(&Rectangle::new(corners, RGBColor(170, 170, 170).stroke_width(1))).map_err(e)?;
        for (k, line) in note.into_iter().enumerate() {
            root.draw(&Text::new(line, (bx, by + row * k as i32), style.clone())).map_err(e)?;
        }
    }
    Ok(())
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
