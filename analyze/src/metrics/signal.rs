//! Reading one recording's series and metadata with errors that name the file, and the
//! reductions the metrics use (peaks, minima, time below zero).

use schemas::Recording;

use crate::Error;

/// Reads series and metadata of one recording, with errors that name the file.
pub(super) struct Source<'a>(pub(super) &'a Recording);

impl Source<'_> {
    fn file(&self) -> String {
        self.0.source.clone()
    }

    pub(super) fn meta(&self, record: &str, key: &str) -> Result<&str, Error> {
        self.0
            .metadata_value(record, key)
            .ok_or_else(|| Error::MissingMetadata {
                file: self.file(),
                record: record.into(),
                key: key.into(),
            })
    }

    pub(super) fn bad_meta(&self, record: &str, key: &str, value: &str, detail: &str) -> Error {
        Error::BadMetadata {
            file: self.file(),
            record: record.into(),
            key: key.into(),
            value: value.into(),
            detail: detail.into(),
        }
    }

    /// A metadata value holding a JSON array of strings.
    pub(super) fn json_names(&self, record: &str, key: &str) -> Result<Vec<String>, Error> {
        let v = self.meta(record, key)?;
        serde_json::from_str(v).map_err(|e| {
            self.bad_meta(record, key, v, &format!("not a JSON array of strings: {e}"))
        })
    }

    /// Times and rows of a field, at least one message, every row `expected` long.
    pub(super) fn arrays(
        &self,
        topic: &str,
        field: &str,
        expected: usize,
        per: &'static str,
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), Error> {
        let (t, rows) = self.0.series(topic, field)?;
        if t.is_empty() {
            return Err(Error::NoSamples {
                file: self.file(),
                topic: topic.into(),
            });
        }
        if let Some(index) = rows.iter().position(|r| r.len() != expected) {
            return Err(Error::WrongLength {
                file: self.file(),
                topic: topic.into(),
                field: field.into(),
                index,
                t_s: t[index],
                found: rows[index].len(),
                expected,
                per,
            });
        }
        Ok((t, rows))
    }

    /// Times and values of a scalar field, at least one message.
    pub(super) fn scalars(&self, topic: &str, field: &str) -> Result<(Vec<f64>, Vec<f64>), Error> {
        let (t, rows) = self.arrays(topic, field, 1, "message (a scalar field)")?;
        Ok((t, rows.into_iter().map(|r| r[0]).collect()))
    }
}

/// Entry `j` of every row (rows were checked to be long enough).
pub(super) fn column(rows: &[Vec<f64>], j: usize) -> Vec<f64> {
    rows.iter().map(|r| r[j]).collect()
}

/// The last row (rows were checked to be non-empty).
pub(super) fn last(rows: &[Vec<f64>]) -> &[f64] {
    rows.last().map_or(&[], Vec::as_slice)
}

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
