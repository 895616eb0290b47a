//! The work–precision diagram: max hand error against wall time, log–log, one line per
//! method, written as SVG and PNG with plotters. The PNG uses the DejaVu Sans font shipped in
//! `sim/assets` (its licence is beside it), so it renders the same on any machine.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::precision::Row;

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // an embedded, valid font: registration cannot fail at run time
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, plotters::coord::Shift>, rows: &[Row], title: &str) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let ok: Vec<&Row> = rows.iter().filter(|r| r.status == "ok" && r.wall_s.is_finite() && r.wall_s > 0.0).collect();
    if ok.is_empty() {
        return Err("no successful run to plot".into());
    }
    let floor = 1e-16;
    let err = |r: &Row| r.max_hand_error_m.max(floor);
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for r in &ok {
        x0 = x0.min(r.wall_s);
        x1 = x1.max(r.wall_s);
        y0 = y0.min(err(r));
        y1 = y1.max(err(r));
    }
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d((x0 / 1.5..x1 * 1.5).log_scale(), (y0 / 3.0..y1 * 3.0).log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("wall time of the run [s]")
        .y_desc("max hand error vs reference [m]")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(e)?;
    let mut series: Vec<&str> = Vec::new();
    for r in &ok {
        if !series.contains(&r.series.as_str()) {
            series.push(&r.series);
        }
    }
    for (k, name) in series.iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        // in ladder order (loose to tight), so the line follows the tolerance, not timing noise
        let pts: Vec<(f64, f64)> = ok.iter().filter(|r| r.series == *name).map(|r| (r.wall_s, err(r))).collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
            .map_err(e)?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
        chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 4, color.filled()))).map_err(e)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(e)?;
    root.present().map_err(e)
}

/// Write the diagram as `<stem>.svg` and `<stem>.png` (1000 x 700 px).
pub fn work_precision(rows: &[Row], title: &str, stem: &Path) -> Result<(), String> {
    register_font();
    let svg = stem.with_extension("svg");
    let png = stem.with_extension("png");
    draw(SVGBackend::new(&svg, (1000, 700)).into_drawing_area(), rows, title).map_err(|e| format!("{}: {e}", svg.display()))?;
    draw(BitMapBackend::new(&png, (1000, 700)).into_drawing_area(), rows, title).map_err(|e| format!("{}: {e}", png.display()))
}
