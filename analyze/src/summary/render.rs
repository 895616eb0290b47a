//! A summary DataFrame as an aligned text table, JSON (an array of one object per row) or CSV.
//!
//! Numbers in the table: six significant digits, scientific notation outside 1e-3..1e6; JSON and
//! CSV keep every digit (Rust's shortest round-trip form; polars' CSV writer for CSV). Nulls are
//! `-` in the table, `null` in JSON, empty in CSV.

use polars::prelude::*;

use crate::Format;

/// Renders `df` in `format`.
pub fn render_frame(df: &mut DataFrame, format: Format) -> PolarsResult<String> {
    match format {
        Format::Table => Ok(table(df)),
        Format::Json => Ok(json(df)),
        Format::Csv => {
            let mut buf = Vec::new();
            CsvWriter::new(&mut buf).include_header(true).finish(df)?;
            Ok(String::from_utf8_lossy(&buf).into_owned())
        }
    }
}

fn cell(v: &AnyValue<'_>) -> String {
    match v {
        AnyValue::Null => "-".into(),
        AnyValue::Float64(x) => number(*x),
        AnyValue::Float32(x) => number(f64::from(*x)),
        AnyValue::String(s) => s.to_string(),
        AnyValue::StringOwned(s) => s.to_string(),
        other => other.to_string(),
    }
}

/// Six significant digits, scientific outside 1e-3 <= |x| < 1e6.
fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    let a = x.abs();
    if (1e-3..1e6).contains(&a) {
        let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.5e}")
    }
}

fn table(df: &DataFrame) -> String {
    let cols = df.columns();
    let head: Vec<String> = cols.iter().map(|c| c.name().to_string()).collect();
    let numeric: Vec<bool> = cols.iter().map(|c| c.dtype().is_primitive_numeric()).collect();
    let rows: Vec<Vec<String>> = (0..df.height())
        .map(|i| cols.iter().map(|c| c.get(i).map(|v| cell(&v)).unwrap_or_default()).collect())
        .collect();
    let width = |s: &str| s.chars().count();
    let mut w: Vec<usize> = head.iter().map(|h| width(h)).collect();
    for row in &rows {
        for (k, c) in row.iter().enumerate() {
            w[k] = w[k].max(width(c));
        }
    }
    let line = |cells: &[String]| -> String {
        let parts: Vec<String> = cells
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let pad = " ".repeat(w[k] - width(s));
                if numeric[k] { format!("{pad}{s}") } else { format!("{s}{pad}") }
            })
            .collect();
        parts.join("  ").trim_end().to_string() + "\n"
    };
    let mut out = line(&head);
    out += &line(&w.iter().map(|&n| "-".repeat(n)).collect::<Vec<_>>());
    for row in &rows {
        out += &line(row);
    }
    out += &format!("({} rows)\n", df.height());
    out
}

fn json_value(v: AnyValue<'_>) -> serde_json::Value {
    use serde_json::Value as J;
    match v {
        AnyValue::Null => J::Null,
        AnyValue::Boolean(b) => J::Bool(b),
        AnyValue::Float64(x) => serde_json::Number::from_f64(x).map_or(J::Null, J::Number),
        AnyValue::Float32(x) => serde_json::Number::from_f64(f64::from(x)).map_or(J::Null, J::Number),
        AnyValue::Int64(x) => J::from(x),
        AnyValue::Int32(x) => J::from(x),
        AnyValue::UInt64(x) => J::from(x),
        AnyValue::UInt32(x) => J::from(x),
        AnyValue::String(s) => J::from(s),
        AnyValue::StringOwned(s) => J::from(s.as_str()),
        other => J::from(other.to_string()),
    }
}

/// An array of objects with the keys in column order (serde_json's map would sort them).
fn json(df: &DataFrame) -> String {
    let cols = df.columns();
    let keys: Vec<String> = cols
        .iter()
        .map(|c| serde_json::to_string(c.name().as_str()).unwrap_or_default())
        .collect();
    let mut out = String::from("[");
    for i in 0..df.height() {
        out += if i == 0 { "\n  {" } else { ",\n  {" };
        for (k, c) in cols.iter().enumerate() {
            let v = c.get(i).map_or(serde_json::Value::Null, json_value);
            let sep = if k == 0 { "" } else { "," };
            out += &format!("{sep}\n    {}: {}", keys[k], v);
        }
        out += "\n  }";
    }
    out += if df.height() == 0 { "]\n" } else { "\n]\n" };
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_have_six_significant_digits() {
        assert_eq!(number(3194.5357123), "3194.54");
        assert_eq!(number(0.0137801), "0.0137801");
        assert_eq!(number(2.2e-12), "2.20000e-12");
        assert_eq!(number(-6.902), "-6.90200");
        assert_eq!(number(0.0), "0");
    }
}
