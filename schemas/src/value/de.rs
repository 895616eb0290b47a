//! A decoded [`Value`] as a serde `Deserializer`, so that a message decoded through the schema
//! stored in a file (any producer, any format version) becomes a typed struct by field *name*:
//! `MotorState { current, voltage, … }`. Fields the struct does not know are ignored; a field
//! it needs and the message lacks is an error naming it (serde's "missing field `x`").
//! Integers widen to f64 where the struct wants a float (JSON channels write `0` for `0.0`).

use serde::de::value::{Error, MapDeserializer, SeqDeserializer};
use serde::de::{self, IntoDeserializer, Visitor};
use serde::forward_to_deserialize_any;

use super::Value;

/// Deserializes `T` from a decoded message.
pub fn from_value<'de, T: de::Deserialize<'de>>(v: &'de Value) -> Result<T, Error> {
    T::deserialize(v)
}

impl<'de> IntoDeserializer<'de, Error> for &'de Value {
    type Deserializer = Self;
    fn into_deserializer(self) -> Self {
        self
    }
}

impl<'de> de::Deserializer<'de> for &'de Value {
    type Error = Error;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        match self {
            Value::Bool(b) => visitor.visit_bool(*b),
            Value::I64(x) => visitor.visit_i64(*x),
            Value::U64(x) => visitor.visit_u64(*x),
            Value::F64(x) => visitor.visit_f64(*x),
            Value::String(s) => visitor.visit_borrowed_str(s),
            Value::Bytes(b) => visitor.visit_borrowed_bytes(b),
            Value::List(items) => visitor.visit_seq(SeqDeserializer::new(items.iter())),
            Value::Struct(fields) => visitor.visit_map(MapDeserializer::new(fields.iter().map(|(k, v)| (k.as_str(), v)))),
        }
    }

    /// A present field is `Some` (a decoded message has no null).
    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        visitor.visit_some(self)
    }

    forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf unit unit_struct newtype_struct seq tuple
        tuple_struct map struct enum identifier ignored_any
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, PartialEq, serde::Deserialize)]
    struct Sample {
        time: f64,
        current: Vec<f64>,
        actual: Xy,
        #[serde(default)]
        added_later: Option<f64>,
    }

    #[derive(Debug, PartialEq, serde::Deserialize)]
    struct Xy {
        x: f64,
        y: f64,
    }

    fn sample(fields: Vec<(&str, Value)>) -> Value {
        Value::Struct(fields.into_iter().map(|(k, v)| (k.to_string(), v)).collect())
    }

    #[test]
    fn structs_lists_and_widened_integers() {
        let v = sample(vec![
            ("time", Value::F64(0.5)),
            ("current", Value::List(vec![Value::F64(1.5), Value::I64(-2), Value::U64(3)])),
            ("actual", sample(vec![("x", Value::F64(1.0)), ("y", Value::U64(2)), ("z", Value::F64(9.0))])),
            ("unknown", Value::String("ignored".into())),
        ]);
        let s: Sample = from_value(&v).unwrap();
        assert_eq!(s, Sample { time: 0.5, current: vec![1.5, -2.0, 3.0], actual: Xy { x: 1.0, y: 2.0 }, added_later: None });
    }

    #[test]
    fn a_missing_or_mistyped_field_is_named() {
        let v = sample(vec![("time", Value::F64(0.5)), ("actual", sample(vec![("x", Value::F64(1.0)), ("y", Value::F64(2.0))]))]);
        let e = from_value::<Sample>(&v).unwrap_err().to_string();
        assert!(e.contains("missing field `current`"), "{e}");
        let v = sample(vec![
            ("time", Value::String("noon".into())),
            ("current", Value::List(vec![])),
            ("actual", sample(vec![("x", Value::F64(1.0)), ("y", Value::F64(2.0))])),
        ]);
        let e = from_value::<Sample>(&v).unwrap_err().to_string();
        assert!(e.contains("noon"), "{e}");
    }
}
