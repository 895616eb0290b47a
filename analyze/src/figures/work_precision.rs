//! The work–precision diagram of `sim precision`: error against wall time, log–log, one line
//! per method in the order of its ladder (loose to tight), in the figures' style (font and
//! colours of this module's parent). Hairer & Wanner, *Solving ODEs II*, §IV.10.

use std::path::Path;

use plotters::prelude::*;

use super::draw::COLORS;
use super::register_font;

/// One line of the diagram: a method and its measured points `(wall time s, error)`.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkPrecisionSeries {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// Errors below this are drawn at it (an exact run would have no place on a log axis).
const ERROR_FLOOR: f64 = 1e-16;

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    series: &[WorkPrecisionSeries],
    title: &str,
    y_desc: &str,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let points = || series.iter().flat_map(|s| s.points.iter()).filter(|p| p.0.is_finite() && p.0 > 0.0 && p.1.is_finite());
    if points().next().is_none() {
        return Err("no successful run to plot".into());
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for &(x, y) in points() {
        let y = y.max(ERROR_FLOOR);
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    let mut chart = super::draw::single_chart(&root, title, (x0 / 1.5..x1 * 1.5).log_scale(), (y0 / 3.0..y1 * 3.0).log_scale()).map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("wall time of the run [s]")
        .y_desc(y_desc)
        .x_label_formatter(&|v| super::scale::tick(*v))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(e)?;
    for (k, s) in series.iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        let pts: Vec<(f64, f64)> =
            s.points.iter().filter(|p| p.0.is_finite() && p.0 > 0.0 && p.1.is_finite()).map(|&(x, y)| (x, y.max(ERROR_FLOOR))).collect();
        if pts.is_empty() {
            continue;
        }
        chart
            .draw_series(LineSeries::new(pts.clone(), color.stroke_width(super::draw::LINE_WIDTH)))
            .map_err(e)?
            .label(s.name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(super::draw::LINE_WIDTH)));
        chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 4, color.filled()))).map_err(e)?;
    }
    super::draw::legend_box(&mut chart).map_err(e)?;
    root.present().map_err(e)
}

/// Writes the diagram as `<stem>.svg` and `<stem>.png` (1000 x 700 px); `y_desc` names the
/// error on the y axis.
pub fn work_precision(series: &[WorkPrecisionSeries], title: &str, y_desc: &str, stem: &Path) -> Result<(), String> {
    register_font();
    super::draw::save_svg_png(stem, (1000, 700), |a| draw(a, series, title, y_desc))
}
