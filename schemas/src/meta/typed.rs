//! The metadata records as typed JSON, for tools that hand them to people (`analyze export`'s
//! `metadata.json`): numbers as numbers, `on`/`off` and `true`/`false` as booleans, the JSON
//! values this crate stores as text (the scene, name lists, the stabilisation, limit events,
//! contacts) as the objects and lists they are, and the keys that are text for people (names,
//! phrases, the URDF) as strings.
//!
//! The encodings are the ones [`crate::meta`] writes (its table of records and keys): numbers in
//! Rust's `{:e}` form or decimal, which are JSON numbers (RFC 8259 §6: `5e0`, `1e-3`); name
//! lists and nested values as JSON text; booleans as `on`/`off`. A key this crate does not know
//! (a newer writer's) is typed by the same rule: JSON if it parses as a number, boolean, list or
//! object, else text. Every key is kept.

use std::collections::BTreeMap;

use serde_json::Value;

/// Keys whose values are text for people whatever they look like (a run called `1e3` stays
/// `"1e3"`), by record.
const TEXT: &[(&str, &[&str])] = &[
    ("recording", &["tool"]),
    (
        "run",
        &["scene", "run", "integrator", "mass_matrix", "constraint_solver", "model.electrical", "hand_frame", "tool"],
    ),
    ("scene", &["source", "target_csv"]),
    ("urdf", &["file", "xml"]),
    ("result", &["status", "error"]),
    ("limits", &["monitored"]),
];

/// Keys written as `on`/`off` ([`crate::meta::ModelInfo`]).
const ON_OFF: &[(&str, &[&str])] = &[("run", &["model.friction", "model.gravity"])];

fn listed(table: &[(&str, &[&str])], record: &str, key: &str) -> bool {
    table.iter().any(|(r, keys)| *r == record && keys.contains(&key))
}

/// The typed value of `key` = `text` in metadata record `record`.
pub fn typed_value(record: &str, key: &str, text: &str) -> Value {
    if listed(TEXT, record, key) {
        return Value::String(text.to_string());
    }
    if listed(ON_OFF, record, key) {
        match text {
            "on" => return Value::Bool(true),
            "off" => return Value::Bool(false),
            _ => {}
        }
    }
    match serde_json::from_str::<Value>(text) {
        // a bare JSON string or `null` is kept as the text it is (`"null"` is not "no value")
        Ok(v @ (Value::Number(_) | Value::Bool(_) | Value::Array(_) | Value::Object(_))) => v,
        _ => Value::String(text.to_string()),
    }
}

/// Every record, every key, typed ([`typed_value`]): `{record: {key: value}}`.
pub fn typed_records(records: &BTreeMap<String, BTreeMap<String, String>>) -> Value {
    Value::Object(
        records
            .iter()
            .map(|(record, keys)| {
                let keys = keys.iter().map(|(k, v)| (k.clone(), typed_value(record, k, v))).collect();
                (record.clone(), Value::Object(keys))
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn values_get_their_json_types_and_text_stays_text() {
        assert_eq!(typed_value("recording", "format_version", "3"), json!(3));
        assert_eq!(typed_value("run", "duration", "5e0"), json!(5.0));
        assert_eq!(typed_value("run", "integrator.rtol", "1e-8"), json!(1e-8));
        assert_eq!(typed_value("run", "model.friction", "on"), json!(true));
        assert_eq!(typed_value("run", "model.gravity", "off"), json!(false));
        assert_eq!(typed_value("run", "joint_names", r#"["a","b"]"#), json!(["a", "b"]));
        assert_eq!(typed_value("run", "stabilization", r#"{"method":"none"}"#), json!({"method": "none"}));
        assert_eq!(typed_value("scene", "json", r#"{"controller":{"kp":500.0}}"#)["controller"]["kp"], json!(500.0));
        // names and phrases stay text even when they look like numbers
        assert_eq!(typed_value("run", "run", "1e3"), json!("1e3"));
        assert_eq!(typed_value("run", "integrator", "dopri45"), json!("dopri45"));
        assert_eq!(typed_value("result", "status", "complete"), json!("complete"));
        // unknown keys: JSON when it is a number, boolean, list or object, else the text
        assert_eq!(typed_value("x", "y", "true"), json!(true));
        assert_eq!(typed_value("x", "y", "null"), json!("null"));
        assert_eq!(typed_value("x", "y", "NaN"), json!("NaN"));
        assert_eq!(typed_value("x", "y", "elbow-sim 0.1.0"), json!("elbow-sim 0.1.0"));
    }
}
