//! A decoded message as a tree, independent of its wire encoding.
//!
//! Protobuf, ROS 2 CDR and JSON messages all decode to [`Value`]. Field order is the schema's
//! declaration order (protobuf descriptor order, `.msg` line order; JSON objects come sorted by
//! key). Mapping of the wire types:
//!
//! | wire type | `Value` |
//! |---|---|
//! | bool | `Bool` |
//! | signed integers, protobuf enums | `I64` |
//! | unsigned integers, ROS `byte`/`char` scalars | `U64` |
//! | float32, float64 | `F64` (float32 widened exactly) |
//! | string | `String` |
//! | protobuf `bytes`, ROS `uint8`/`byte`/`char` arrays | `Bytes` |
//! | repeated / arrays | `List` |
//! | message / nested type | `Struct` |
//! | protobuf map | `List` of `Struct { key, value }`, sorted by key |
//! | JSON `null` | `F64(NaN)` (JSON writers use it for non-finite numbers) |

mod de;
pub use de::from_value;

/// A decoded message or field.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Bool(bool),
    I64(i64),
    U64(u64),
    F64(f64),
    String(String),
    Bytes(Vec<u8>),
    List(Vec<Value>),
    Struct(Vec<(String, Value)>),
}

impl Value {
    /// Equal trees with every number compared bit for bit: NaN payloads equal, `0.0` and `-0.0`
    /// different, where `==` would say the opposite of both. What a second decoder of the same
    /// bytes must reproduce exactly (the format's tests compare the typed and hand-walked reads
    /// with the generic one this way).
    pub fn same_bits(&self, other: &Value) -> bool {
        match (self, other) {
            (Value::F64(x), Value::F64(y)) => x.to_bits() == y.to_bits(),
            (Value::List(x), Value::List(y)) => x.len() == y.len() && x.iter().zip(y).all(|(a, b)| a.same_bits(b)),
            (Value::Struct(x), Value::Struct(y)) => x.len() == y.len() && x.iter().zip(y).all(|((ka, a), (kb, b))| ka == kb && a.same_bits(b)),
            _ => self == other,
        }
    }

    /// Follows a dotted path: struct field names and list indices, e.g. `"actual.x"`,
    /// `"current"`, `"transforms.0.translation.x"`. The empty path is `self`. For generic tools and
    /// the format's own tests: readers of our topics use typed structs ([`from_value`],
    /// [`crate::Recording::read`]), so that no field path is spelled outside this crate (CI
    /// checks `sim` and `analyze` for it).
    pub fn get(&self, path: &str) -> Option<&Value> {
        if path.is_empty() {
            return Some(self);
        }
        let mut v = self;
        for seg in path.split('.') {
            v = match v {
                Value::Struct(fields) => fields.iter().find(|(k, _)| k == seg).map(|(_, v)| v)?,
                Value::List(items) => items.get(seg.parse::<usize>().ok()?)?,
                _ => return None,
            };
        }
        Some(v)
    }

    /// A scalar number as f64 (`Bool` gives 0 or 1; integers beyond 2^53 round).
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            Value::F64(x) => Some(x),
            Value::I64(x) => Some(x as f64),
            Value::U64(x) => Some(x as f64),
            Value::Bool(b) => Some(if b { 1.0 } else { 0.0 }),
            _ => None,
        }
    }

    /// A list of numbers (or `Bytes`) as f64s; `None` for scalars or non-numeric items.
    pub fn as_f64_vec(&self) -> Option<Vec<f64>> {
        match self {
            Value::List(items) => items.iter().map(Value::as_f64).collect(),
            Value::Bytes(b) => Some(b.iter().map(|&x| f64::from(x)).collect()),
            _ => None,
        }
    }

    /// The text of a `String` value.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            Value::String(s) => Some(s),
            _ => None,
        }
    }

    /// The items of a `List`.
    pub fn as_list(&self) -> Option<&[Value]> {
        match self {
            Value::List(items) => Some(items),
            _ => None,
        }
    }

    /// A short description of the kind, for error messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Bool(_) => "bool",
            Value::I64(_) => "i64",
            Value::U64(_) => "u64",
            Value::F64(_) => "f64",
            Value::String(_) => "string",
            Value::Bytes(_) => "bytes",
            Value::List(_) => "list",
            Value::Struct(_) => "struct",
        }
    }

    /// Converts parsed JSON (objects keep serde_json's key order, i.e. sorted).
    pub fn from_json(j: &serde_json::Value) -> Value {
        use serde_json::Value as J;
        match j {
            J::Null => Value::F64(f64::NAN),
            J::Bool(b) => Value::Bool(*b),
            J::Number(n) => {
                if let Some(u) = n.as_u64() {
                    Value::U64(u)
                } else if let Some(i) = n.as_i64() {
                    Value::I64(i)
                } else {
                    Value::F64(n.as_f64().unwrap_or(f64::NAN))
                }
            }
            J::String(s) => Value::String(s.clone()),
            J::Array(a) => Value::List(a.iter().map(Value::from_json).collect()),
            J::Object(o) => Value::Struct(
                o.iter()
                    .map(|(k, v)| (k.clone(), Value::from_json(v)))
                    .collect(),
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Value {
        Value::Struct(vec![
            ("time".into(), Value::F64(0.5)),
            (
                "current".into(),
                Value::List(vec![Value::F64(1.0), Value::I64(-2)]),
            ),
            (
                "actual".into(),
                Value::Struct(vec![
                    ("x".into(), Value::F64(3.0)),
                    ("n".into(), Value::String("a".into())),
                ]),
            ),
        ])
    }

    #[test]
    fn get_follows_fields_and_indices() {
        let v = sample();
        assert_eq!(v.get("actual.x"), Some(&Value::F64(3.0)));
        assert_eq!(v.get("current.1"), Some(&Value::I64(-2)));
        assert_eq!(v.get("current.2"), None);
        assert_eq!(v.get("actual.y"), None);
        assert_eq!(v.get("time.x"), None);
        assert_eq!(v.get(""), Some(&v));
    }

    #[test]
    fn numeric_views() {
        let v = sample();
        assert_eq!(
            v.get("current").and_then(Value::as_f64_vec),
            Some(vec![1.0, -2.0])
        );
        assert_eq!(v.get("time").and_then(Value::as_f64_vec), None);
        assert_eq!(v.get("actual.n").and_then(Value::as_f64), None);
        assert_eq!(v.get("actual.n").and_then(Value::as_str), Some("a"));
        assert_eq!(Value::Bytes(vec![7]).as_f64_vec(), Some(vec![7.0]));
    }

    #[test]
    fn json_conversion_keeps_integer_kinds() {
        let j: serde_json::Value = serde_json::from_str(r#"{"b":-3,"a":[1,2.5,null]}"#).unwrap();
        let v = Value::from_json(&j);
        assert_eq!(v.get("b"), Some(&Value::I64(-3)));
        assert_eq!(v.get("a.0"), Some(&Value::U64(1)));
        assert_eq!(v.get("a.1"), Some(&Value::F64(2.5)));
        assert!(v
            .get("a.2")
            .and_then(Value::as_f64)
            .is_some_and(f64::is_nan));
    }
}
