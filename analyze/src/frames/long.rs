//! A topic's wide frame -> the long ("tidy") layout: one row per sample and signal, with the
//! columns `time`, `topic`, `signal`, `name`, `unit`, `value` (Wickham, "Tidy Data", J. Stat.
//! Softw. 59(10), 2014: each variable a column, each observation a row).
//!
//! - `signal`: the message field (`current`, `actual.x`), as `schemas::units` spells it;
//! - `name`: the joint, contact, frame or index of the array entry (`joint4`, `elbow7`), null
//!   for a field outside any array (`kinetic`, `actual.x`);
//! - `unit`: the field's unit (`schemas::units`), null for a field without one (mode codes);
//! - `value`: Float64 (integers and booleans converted: exact below 2^53, true = 1).
//!
//! Rows run in time order, and within a time in the wide table's column order. Text columns (a
//! URDF, a frame id) are not values and are left out, as are the nulls of a column that a
//! message did not have: a topic without either has exactly samples × signals rows, the wide
//! table's numbers in order.

use polars::prelude::*;

use super::{ColumnInfo, TopicFrame, TIME_COLUMN};

/// Column names of the long layout, in order.
pub const LONG_COLUMNS: [&str; 6] = [TIME_COLUMN, "topic", "signal", "name", "unit", "value"];

/// The long table of `t`, and the wide columns left out because they are text.
pub fn long_frame(t: &TopicFrame) -> PolarsResult<(DataFrame, Vec<String>)> {
    let df = &t.frame;
    let time = df.column(TIME_COLUMN)?.f64()?.clone();
    let mut signals: Vec<(&ColumnInfo, Float64Chunked)> = Vec::new();
    let mut text = Vec::new();
    for (col, info) in df.columns().iter().zip(&t.columns) {
        if info.name == TIME_COLUMN {
            continue;
        }
        if matches!(col.dtype(), DataType::String) {
            text.push(info.name.clone());
            continue;
        }
        let values = col.as_materialized_series().cast(&DataType::Float64)?;
        signals.push((info, values.f64()?.clone()));
    }
    let rows = df.height() * signals.len();
    let (mut tc, mut signal, mut name, mut unit, mut value) =
        (Vec::with_capacity(rows), Vec::with_capacity(rows), Vec::with_capacity(rows), Vec::with_capacity(rows), Vec::with_capacity(rows));
    for (i, t_s) in time.iter().enumerate() {
        for (info, values) in &signals {
            let Some(x) = values.get(i) else { continue };
            tc.push(t_s);
            signal.push(info.field.as_str());
            name.push(info.label.as_deref());
            unit.push(info.unit);
            value.push(x);
        }
    }
    let n = tc.len();
    let columns = vec![
        Column::new(LONG_COLUMNS[0].into(), tc),
        Column::new(LONG_COLUMNS[1].into(), vec![t.topic.as_str(); n]),
        Column::new(LONG_COLUMNS[2].into(), signal),
        Column::new(LONG_COLUMNS[3].into(), name),
        Column::new(LONG_COLUMNS[4].into(), unit),
        Column::new(LONG_COLUMNS[5].into(), value),
    ];
    Ok((DataFrame::new(n, columns)?, text))
}
