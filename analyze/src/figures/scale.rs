//! What the y axis of a panel shows: tick labels without useless decimals ([`tick`]), a range
//! that a start-up spike does not set ([`robust_range`]), a log axis where the lines differ by
//! more than a decade ([`wants_log`]), and the lines cut at that range ([`clip_y`]).
//!
//! - **Ticks**: plotters chooses 1-2-5 steps (its `key_points`); each label is the shortest
//!   decimal within 1e-9 of the tick (so 0.30000000000000004 reads 0.3, 3000.0 reads 3000), with
//!   a true minus sign (U+2212).
//! - **Robust range**: the 1st to 99th percentile of every finite sample of the panel (type 1,
//!   the inverse of the empirical distribution: Hyndman & Fan 1996), widened by 10 % of its span
//!   on each side; the whole range is kept unless it is more than twice as wide as that. A
//!   transient shorter than 1 % of the run (the motors' first milliseconds) then lies outside
//!   and is annotated with its extreme value instead of squeezing the rest into a few pixels.
//! - **Log axis**: for lines that are never negative whose largest values differ by more than a
//!   factor [`LOG_RATIO`] and at most [`LOG_SPAN`] (the paper's energies: 114 J with two
//!   elbows, 3195 J with none); the axis starts a decade below the smallest line's final value,
//!   so early values under it are not drawn.

/// Lines whose maxima differ by more than this factor get a log axis.
pub(super) const LOG_RATIO: f64 = 10.0;
/// ... unless they differ by more than this: a line that small is drawn at 0 on a linear axis
/// rather than lost below a log axis.
pub(super) const LOG_SPAN: f64 = 1e4;

/// The tick label of `v`: the fewest decimals (at most 6) within 1e-9 of it, `−` for minus.
pub(super) fn tick(v: f64) -> String {
    let tol = 1e-9 * v.abs().max(1.0);
    let d = (0..=6).find(|&d| {
        let p = 10f64.powi(d);
        ((v * p).round() / p - v).abs() <= tol
    });
    let s = format!("{:.*}", d.unwrap_or(6) as usize, v);
    let s = if s.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') { s.trim_start_matches('-').to_string() } else { s };
    s.replace('-', "\u{2212}")
}

/// The label of tick `v` on a linear axis `span` long: as many decimals as a tenth of the span
/// needs, plus one, trailing zeros dropped (0.00002 on a 1e-4 axis, 0.5 on a 5 s one), so
/// ticks of a small range do not all read 0.
pub(super) fn tick_in(v: f64, span: f64) -> String {
    if !(span.is_finite() && span > 0.0) {
        return tick(v);
    }
    let step = (span / 10.0).log10().floor();
    if v.abs() < 1e-6 * span {
        return "0".into();
    }
    if span < 1e-3 {
        // a tiny axis (a joint that barely moves): scientific, the digits the step needs
        let k = (span.log10().floor() - step).clamp(0.0, 6.0) as usize;
        return format!("{v:.k$e}").replace('-', "\u{2212}");
    }
    let d = (1.0 - step).clamp(0.0, 15.0) as usize;
    let s = format!("{v:.d$}");
    let s = if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s };
    let s = if s.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') { "0".to_string() } else { s };
    s.replace('-', "\u{2212}")
}

/// The `q`-quantile (type 1) of sorted finite values.
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let k = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1;
    sorted[k]
}

/// The y range of a panel whose finite values are `ys` (module docs), and whether it cuts off
/// data; `None` without finite values.
pub(super) fn robust_range(ys: impl Iterator<Item = f64>) -> Option<((f64, f64), bool)> {
    let mut v: Vec<f64> = ys.filter(|y| y.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let (lo, hi) = (v[0], v[v.len() - 1]);
    let (a, b) = (quantile(&v, 0.01), quantile(&v, 0.99));
    let pad = 0.1 * (b - a);
    let (ra, rb) = (a - pad, b + pad);
    if (b - a) > 0.0 && (hi - lo) > 2.0 * (rb - ra) {
        Some(((ra.min(a), rb.max(b)), true))
    } else {
        Some(((lo, hi), false))
    }
}

/// The log axis range for lines of `(x, y)` points, or `None` when a linear axis is right
/// (module docs).
pub(super) fn wants_log(lines: &[&[(f64, f64)]]) -> Option<(f64, f64)> {
    let mut maxima = Vec::new();
    let mut finals = Vec::new();
    for pts in lines {
        let finite: Vec<f64> = pts.iter().map(|p| p.1).filter(|y| y.is_finite()).collect();
        if finite.is_empty() {
            continue;
        }
        if finite.iter().any(|&y| y < 0.0) {
            return None;
        }
        maxima.push(finite.iter().copied().fold(0.0, f64::max));
        finals.push(*finite.last().unwrap_or(&0.0));
    }
    let (lo, hi) = (maxima.iter().copied().fold(f64::INFINITY, f64::min), maxima.iter().copied().fold(0.0, f64::max));
    if maxima.len() < 2 || lo <= 0.0 || hi / lo <= LOG_RATIO || hi / lo > LOG_SPAN {
        return None;
    }
    let smallest_final = finals.iter().copied().filter(|&f| f > 0.0).fold(f64::INFINITY, f64::min);
    let bottom = 10f64.powf((smallest_final.min(lo)).log10().floor() - 1.0);
    let top = 10f64.powf(hi.log10().ceil());
    Some((bottom, if top / hi > 5.0 { hi * 2.0 } else { top }))
}

/// The polyline through `pts` cut at `lo <= y <= hi`: the pieces inside, each with the crossing
/// points where it leaves or enters the band (linear interpolation along each segment).
pub(super) fn clip_y(pts: &[(f64, f64)], lo: f64, hi: f64) -> Vec<Vec<(f64, f64)>> {
    let inside = |y: f64| (lo..=hi).contains(&y);
    let cross = |a: (f64, f64), b: (f64, f64), y: f64| (a.0 + (b.0 - a.0) * (y - a.1) / (b.1 - a.1), y);
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for (k, &p) in pts.iter().enumerate() {
        if k > 0 {
            let a = pts[k - 1];
            // the segment a → p against the band: its parts inside, in order
            let mut ts = vec![0.0, 1.0];
            for y in [lo, hi] {
                let t = (y - a.1) / (p.1 - a.1);
                if t > 0.0 && t < 1.0 {
                    ts.push(t);
                }
            }
            ts.sort_by(f64::total_cmp);
            for w in ts.windows(2) {
                let mid = a.1 + (p.1 - a.1) * (w[0] + w[1]) / 2.0;
                let at = |t: f64| if t == 0.0 { a } else if t == 1.0 { p } else { cross(a, p, a.1 + (p.1 - a.1) * t) };
                if inside(mid) {
                    let (s, e) = (at(w[0]), at(w[1]));
                    if cur.last() != Some(&s) {
                        if !cur.is_empty() {
                            out.push(std::mem::take(&mut cur));
                        }
                        cur.push(s);
                    }
                    cur.push(e);
                } else if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
        } else if inside(p.1) {
            cur.push(p);
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_of_small_ranges_keep_their_digits() {
        let got: Vec<String> = [-4e-5, -2e-5, 0.0, 2e-5].map(|v| tick_in(v, 1e-4)).to_vec();
        assert_eq!(got, ["−4.0e−5", "−2.0e−5", "0", "2.0e−5"]);
        assert_eq!(tick_in(5e-26, 2e-10), "0");
        assert_eq!([-0.02, 0.005, 1e-18].map(|v| tick_in(v, 0.05)), ["−0.02", "0.005", "0"]);
        assert_eq!([0.0, 0.5, 4.5, 5.0].map(|v| tick_in(v, 5.0)), ["0", "0.5", "4.5", "5"]);
        assert_eq!([0.0, 1000.0, 3500.0].map(|v| tick_in(v, 3500.0)), ["0", "1000", "3500"]);
    }

    #[test]
    fn ticks_have_no_useless_decimals() {
        let got: Vec<String> = [0.0, 0.5, 3000.0, 0.1 + 0.2, -2.5, -0.0, 1e-3, 12.25].map(tick).to_vec();
        assert_eq!(got, ["0", "0.5", "3000", "0.3", "−2.5", "0", "0.001", "12.25"]);
    }

    /// A 2 ms spike to 40 in a 5 s run of values within ±5 is outside the range; without the
    /// spike the range is the data's.
    #[test]
    fn a_short_spike_does_not_set_the_range() {
        let run = |spike: bool| (0..5000).map(move |k| if spike && k < 2 { 40.0 } else { 5.0 * (k as f64 * 0.01).sin() });
        let ((lo, hi), cut) = robust_range(run(true)).unwrap();
        assert!(cut && hi < 7.0 && lo > -7.0 && hi > 4.9 && lo < -4.9, "{lo} {hi}");
        let ((lo, hi), cut) = robust_range(run(false)).unwrap();
        assert!(!cut && (hi - 5.0).abs() < 1e-3 && (lo + 5.0).abs() < 1e-3, "{lo} {hi}");
    }

    #[test]
    fn log_axis_only_when_lines_differ_by_more_than_a_decade() {
        let ramp = |e: f64| (0..=100).map(|k| (k as f64, e * k as f64 / 100.0)).collect::<Vec<_>>();
        let (a, b, c) = (ramp(3195.0), ramp(1129.0), ramp(114.0));
        let (lo, hi) = wants_log(&[&a, &b, &c]).expect("3195 J against 114 J");
        assert_eq!((lo, hi), (10.0, 10_000.0));
        assert_eq!(wants_log(&[&a, &b]), None, "within a factor 3");
        assert_eq!(wants_log(&[&a, &ramp(0.01)]), None, "a line at about 0: linear");
        let mut neg = c.clone();
        neg[3].1 = -1.0;
        assert_eq!(wants_log(&[&a, &neg]), None, "negative values: linear");
    }

    #[test]
    fn clipping_keeps_the_inside_and_the_crossings() {
        let pts = [(0.0, 0.0), (1.0, 10.0), (2.0, 0.0), (3.0, 1.0)];
        let pieces = clip_y(&pts, -1.0, 5.0);
        assert_eq!(pieces, vec![vec![(0.0, 0.0), (0.5, 5.0)], vec![(1.5, 5.0), (2.0, 0.0), (3.0, 1.0)]]);
        assert_eq!(clip_y(&pts, -1.0, 20.0), vec![pts.to_vec()]);
    }
}
