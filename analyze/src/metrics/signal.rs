//! The reductions the metrics use: peaks, minima, time below zero.

/// Index of the first minimum; the first NaN wins, so a non-finite sample is never hidden.
pub(super) fn argmin(values: impl Iterator<Item = f64>) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (k, v) in values.enumerate() {
        if v.is_nan() {
            return Some(k);
        }
        if best.is_none_or(|(_, b)| v < b) {
            best = Some((k, v));
        }
    }
    best.map(|(k, _)| k)
}

/// `(min_k v_k, t_k)` at the first minimum (a NaN wins); NaNs when empty.
pub(super) fn min_with_time(times: &[f64], values: &[f64]) -> (f64, f64) {
    argmin(values.iter().copied()).map_or((f64::NAN, f64::NAN), |k| (values[k], times[k]))
}

/// `(max_k |v_k|, t_k)` at the first maximum (a NaN wins); NaNs when empty.
pub(super) fn peak_abs(times: &[f64], values: &[f64]) -> (f64, f64) {
    argmin(values.iter().map(|v| -v.abs()))
        .map_or((f64::NAN, f64::NAN), |k| (values[k].abs(), times[k]))
}

/// Time with `v < 0` by the trapezoid rule on `1[v < 0]` (see [`super::ContactMetrics::pull_time_s`]).
pub(super) fn negative_time(times: &[f64], values: &[f64]) -> f64 {
    let neg = |v: f64| if v < 0.0 { 0.5 } else { 0.0 };
    times
        .windows(2)
        .zip(values.windows(2))
        .map(|(t, v)| (t[1] - t[0]) * (neg(v[0]) + neg(v[1])))
        .sum()
}
