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
    let ((x0, x1), (y0, y1)) = (pad(x0, x1), pad(y0, y1));
    let mut chart = super::draw::single_chart(&root, labels[0], x0..x1, y0..y1).map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(labels[1])
        .y_desc(labels[2])
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(e)?;
    for (k, s) in series.iter().enumerate() {
        let color = if s.mark == Mark::Crosses { BLACK } else { COLORS[k % COLORS.len()] };
        let pts: Vec<(f64, f64)> = s.points.iter().filter(finite).copied().collect();
        if pts.is_empty() {
            continue;
        }
        let legend = move |(x, y): (i32, i32)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(super::draw::LINE_WIDTH));
        match s.mark {
            Mark::Line => {
                chart
                    .draw_series(LineSeries::new(pts.clone(), color.stroke_width(super::draw::LINE_WIDTH)))
                    .map_err(e)?
                    .label(s.name.as_str())
                    .legend(legend);
                chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled()))).map_err(e)?;
            }
            Mark::Dots => {
                chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.mix(0.6).filled()))).map_err(e)?.label(s.name.as_str()).legend(legend);
            }
            Mark::Crosses => {
                chart.draw_series(pts.into_iter().map(|p| Cross::new(p, 5, color.stroke_width(2)))).map_err(e)?.label(s.name.as_str()).legend(legend);
            }
        }
    }
    super::draw::legend_box(&mut chart).map_err(e)?;
    root.present().map_err(e)
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
}
