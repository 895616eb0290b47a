//! The figures of a design study (`sim optimize`): the convergence of the objective over the
//! evaluations, the map of the objective over one variable (infeasible designs marked), and the
//! Pareto front of energy against hand error. One kind of chart, a scatter with optional lines,
//! in the figures' style (font and colours of this module's parent). The front's definition:
//! K. Deb, *Multi-Objective Optimization Using Evolutionary Algorithms*, Wiley 2001, §2.4.

use std::path::Path;

use plotters::prelude::*;

use super::draw::COLORS;
use super::register_font;

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    /// Dots.
    Dots,
    /// A line through the points, in order, with dots.
    Line,
    /// Crosses (infeasible designs).
    Crosses,
}

/// One series of a study figure.
#[derive(Debug, Clone, PartialEq)]
pub struct StudySeries {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub mark: Mark,
}

/// The width of the legend's panel to the right of the plot, px: the legend never covers data.
const LEGEND_WIDTH: u32 = 250;

/// Whether the y axis is logarithmic: every value positive and the range wider than a decade
/// (a linear axis flattens the curves at the bottom: the 0-kg energies under the 1-kg ones).
pub fn log_axis(y0: f64, y1: f64) -> bool {
    y0 > 0.0 && y1 / y0 > 10.0
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, plotters::coord::Shift>, series: &[StudySeries], labels: [&str; 3]) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let finite = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite();
    let all: Vec<(f64, f64)> = series.iter().flat_map(|s| s.points.iter().filter(finite).copied()).collect();
    if all.is_empty() {
        return Err("no point to plot".into());
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for &(x, y) in &all {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    let pad = |a: f64, b: f64| {
        let d = if b > a { 0.05 * (b - a) } else { 0.05 * a.abs().max(1e-9) };
        (a - d, b + d)
    };
    let (x0, x1) = pad(x0, x1);
    let (w, _) = root.dim_in_pixel();
    let (plot, side) = root.split_horizontally(w.saturating_sub(LEGEND_WIDTH));
    if log_axis(y0, y1) {
        // a factor of 1.15 of room at each end (the log axis' equivalent of 5 % of the range)
        let mut chart = super::draw::single_chart(&plot, labels[0], x0..x1, (y0 / 1.15..y1 * 1.15).log_scale()).map_err(e)?;
        chart.configure_mesh().x_desc(labels[1]).y_desc(format!("{} (log)", labels[2])).label_style(("sans-serif", 14)).axis_desc_style(("sans-serif", 16)).draw().map_err(e)?;
        plot_series(&mut chart, series).map_err(e)?;
    } else {
        let (y0, y1) = pad(y0, y1);
        let mut chart = super::draw::single_chart(&plot, labels[0], x0..x1, y0..y1).map_err(e)?;
        chart.configure_mesh().x_desc(labels[1]).y_desc(labels[2]).label_style(("sans-serif", 14)).axis_desc_style(("sans-serif", 16)).draw().map_err(e)?;
        plot_series(&mut chart, series).map_err(e)?;
    }
    legend_panel(&side, series).map_err(e)?;
    root.present().map_err(e)
}

fn color_of(k: usize, s: &StudySeries) -> RGBColor {
    if s.mark == Mark::Crosses {
        BLACK
    } else {
        COLORS[k % COLORS.len()]
    }
}

fn plot_series<'a, DB: DrawingBackend + 'a, CT: CoordTranslate<From = (f64, f64)>>(chart: &mut ChartContext<'a, DB, CT>, series: &[StudySeries]) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    DB::ErrorType: 'static,
{
    let finite = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite();
    for (k, s) in series.iter().enumerate() {
        let color = color_of(k, s);
        let pts: Vec<(f64, f64)> = s.points.iter().filter(finite).copied().collect();
        match s.mark {
            Mark::Line => {
                chart.draw_series(LineSeries::new(pts.clone(), color.stroke_width(super::draw::LINE_WIDTH)))?;
                chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))?;
            }
            Mark::Dots => {
                chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.mix(0.6).filled())))?;
            }
            Mark::Crosses => {
                chart.draw_series(pts.into_iter().map(|p| Cross::new(p, 5, color.stroke_width(2))))?;
            }
        }
    }
    Ok(())
}

/// The legend in its own panel right of the plot (each series' mark and name), so it never
/// covers a point.
fn legend_panel<DB: DrawingBackend>(side: &DrawingArea<DB, plotters::coord::Shift>, series: &[StudySeries]) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = ("sans-serif", 14).into_font().color(&BLACK);
    for (k, s) in series.iter().enumerate() {
        let color = color_of(k, s);
        let y = 70 + 24 * k as i32;
        match s.mark {
            Mark::Line => {
                side.draw(&PathElement::new(vec![(4, y), (28, y)], color.stroke_width(super::draw::LINE_WIDTH)))?;
                side.draw(&Circle::new((16, y), 3, color.filled()))?;
            }
            Mark::Dots => side.draw(&Circle::new((16, y), 4, color.mix(0.6).filled()))?,
            Mark::Crosses => side.draw(&Cross::new((16, y), 5, color.stroke_width(2)))?,
        }
        side.draw(&Text::new(s.name.clone(), (34, y - 8), font.clone()))?;
    }
    Ok(())
}

/// Writes a study figure as `<stem>.svg` and `<stem>.png` (1000 x 700 px); `labels` are the
/// title and the x and y axes' descriptions.
pub fn study_figure(series: &[StudySeries], labels: [&str; 3], stem: &Path) -> Result<(), String> {
    register_font();
    super::draw::save_svg_png(stem, (1000, 700), |a| draw(a, series, labels))
}

/// The Pareto front of `(x, y)` points, both minimised: the points no other point is at least
/// as good as in both and better in one, sorted by x (first of equal points kept).
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> = points.iter().copied().filter(|q| q.0.is_finite() && q.1.is_finite()).collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for q in p {
        if front.last().is_none_or(|l| q.1 < l.1) {
            front.push(q);
        }
    }
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pareto_front_keeps_exactly_the_non_dominated_points() {
        // (1,5) (2,3) (3,4)x dominated by (2,3), (4,1), (5,1)x dominated by (4,1), (2,3) twice
        let pts = [(3.0, 4.0), (1.0, 5.0), (5.0, 1.0), (2.0, 3.0), (4.0, 1.0), (2.0, 3.0), (f64::NAN, 0.0)];
        assert_eq!(pareto_front(&pts), vec![(1.0, 5.0), (2.0, 3.0), (4.0, 1.0)]);
    }

    /// The where-elbow map's energies (236 … 12 100 J) get a log axis; a range within a decade,
    /// or one that reaches 0 or below, keeps the linear one.
    #[test]
    fn the_energy_axis_is_logarithmic_past_a_decade() {
        assert!(log_axis(236.0, 12_100.0));
        assert!(!log_axis(236.0, 2_000.0) && !log_axis(0.0, 12_100.0) && !log_axis(-1.0, 100.0));
    }
}
