//! The reductions the metrics use: peaks, minima, time below zero.

/// Time with `v < 0` by the trapezoid rule on `1[v < 0]` (see [`super::ContactMetrics::pull_time_s`]).
pub(super) fn negative_time(times: &[f64], values: &[f64]) -> f64 {
    let neg = |v: f64| if v < 0.0 { 0.5 } else { 0.0 };
    times
        .windows(2)
        .zip(values.windows(2))
        .map(|(t, v)| (t[1] - t[0]) * (neg(v[0]) + neg(v[1])))
        .sum()
}
