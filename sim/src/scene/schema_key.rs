//! The top-level `"$schema"` key of a scene or sweep file: the path or URL of the file's JSON
//! Schema, for editors (`sim schema`). The parser accepts it at the top level only, as a string,
//! and drops it before the spec exists, so it is never part of a [`super::SceneSpec`] (nor of
//! the scene a recording stores) and every other key reads, and fails, exactly as without it.
//!
//! Done as a deserializer adapter below `serde_path_to_error` rather than as a field of the
//! spec, so that serde's "unknown field …, expected one of …" lists stay as they were.

use std::fmt;

use serde::de::{self, value::StringDeserializer, DeserializeSeed, Deserializer, MapAccess, Visitor};

/// The key, as written in a file.
pub const SCHEMA_KEY: &str = "$schema";

/// `D` with a top-level `"$schema"` string key accepted and dropped (nested objects are left to
/// the types, which reject it as any unknown key).
pub struct SkipSchemaKey<D>(pub D);

impl<'de, D: Deserializer<'de>> Deserializer<'de> for SkipSchemaKey<D> {
    type Error = D::Error;

    fn deserialize_any<V: Visitor<'de>>(self, v: V) -> Result<V::Value, D::Error> {
        self.0.deserialize_any(Top(v))
    }

    fn deserialize_map<V: Visitor<'de>>(self, v: V) -> Result<V::Value, D::Error> {
        self.0.deserialize_map(Top(v))
    }

    fn deserialize_struct<V: Visitor<'de>>(self, name: &'static str, fields: &'static [&'static str], v: V) -> Result<V::Value, D::Error> {
        self.0.deserialize_struct(name, fields, Top(v))
    }

    fn is_human_readable(&self) -> bool {
        self.0.is_human_readable()
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf option
        unit unit_struct newtype_struct seq tuple tuple_struct enum identifier ignored_any
    }
}

/// The top-level visitor: a map is read through [`Skip`], any other value goes to `V` as it is
/// (so a document that is no object fails as before).
struct Top<V>(V);

macro_rules! forward_visits {
    ($($method:ident($ty:ty)),* $(,)?) => {
        $(fn $method<E: de::Error>(self, v: $ty) -> Result<Self::Value, E> {
            self.0.$method(v)
        })*
    };
}

impl<'de, V: Visitor<'de>> Visitor<'de> for Top<V> {
    type Value = V::Value;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        self.0.expecting(f)
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<V::Value, A::Error> {
        self.0.visit_map(Skip(map))
    }

    forward_visits! {
        visit_bool(bool), visit_i64(i64), visit_i128(i128), visit_u64(u64), visit_u128(u128),
        visit_f64(f64), visit_str(&str), visit_borrowed_str(&'de str), visit_string(String),
        visit_bytes(&[u8]), visit_borrowed_bytes(&'de [u8]), visit_byte_buf(Vec<u8>),
    }

    fn visit_none<E: de::Error>(self) -> Result<V::Value, E> {
        self.0.visit_none()
    }

    fn visit_unit<E: de::Error>(self) -> Result<V::Value, E> {
        self.0.visit_unit()
    }

    fn visit_some<D2: Deserializer<'de>>(self, d: D2) -> Result<V::Value, D2::Error> {
        self.0.visit_some(d)
    }

    fn visit_newtype_struct<D2: Deserializer<'de>>(self, d: D2) -> Result<V::Value, D2::Error> {
        self.0.visit_newtype_struct(d)
    }

    fn visit_seq<A: de::SeqAccess<'de>>(self, seq: A) -> Result<V::Value, A::Error> {
        self.0.visit_seq(seq)
    }

    fn visit_enum<A: de::EnumAccess<'de>>(self, e: A) -> Result<V::Value, A::Error> {
        self.0.visit_enum(e)
    }
}

/// The top-level map without its `"$schema"` entries.
struct Skip<A>(A);

impl<'de, A: MapAccess<'de>> MapAccess<'de> for Skip<A> {
    type Error = A::Error;

    fn next_key_seed<K: DeserializeSeed<'de>>(&mut self, seed: K) -> Result<Option<K::Value>, A::Error> {
        loop {
            let Some(key) = self.0.next_key::<String>()? else { return Ok(None) };
            if key == SCHEMA_KEY {
                self.0.next_value::<SchemaPath>()?;
                continue;
            }
            // the key, read already, goes to the type's field visitor as serde would give it
            return seed.deserialize(StringDeserializer::<A::Error>::new(key)).map(Some);
        }
    }

    fn next_value_seed<S: DeserializeSeed<'de>>(&mut self, seed: S) -> Result<S::Value, A::Error> {
        self.0.next_value_seed(seed)
    }

    fn size_hint(&self) -> Option<usize> {
        self.0.size_hint()
    }
}

/// The value of `"$schema"`: any string (not looked at).
struct SchemaPath;

impl<'de> de::Deserialize<'de> for SchemaPath {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = SchemaPath;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("`$schema` to be a string (the path or URL of the file's JSON Schema)")
            }
            fn visit_str<E: de::Error>(self, _: &str) -> Result<SchemaPath, E> {
                Ok(SchemaPath)
            }
        }
        d.deserialize_str(V)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Debug, PartialEq, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Doc {
        a: f64,
        #[serde(default)]
        inner: Option<Inner>,
    }

    #[derive(Debug, PartialEq, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Inner {
        b: f64,
    }

    fn read(text: &str) -> Result<Doc, String> {
        let de = &mut serde_json::Deserializer::from_str(text);
        serde_path_to_error::deserialize(SkipSchemaKey(de)).map_err(|e| format!("{}: {}", e.path(), e.inner()))
    }

    fn read_plain(text: &str) -> Result<Doc, String> {
        let de = &mut serde_json::Deserializer::from_str(text);
        serde_path_to_error::deserialize(de).map_err(|e| format!("{}: {}", e.path(), e.inner()))
    }

    #[test]
    fn a_top_level_schema_string_is_dropped() {
        let want = Doc { a: 1.0, inner: None };
        assert_eq!(read(r#"{"$schema": "s.json", "a": 1}"#).unwrap(), want);
        assert_eq!(read(r#"{"a": 1, "$schema": "https://x/y.json"}"#).unwrap(), want);
        assert_eq!(read(r#"{"a": 1}"#).unwrap(), want);
        let v = SkipSchemaKey(serde_json::json!({"$schema": "s.json", "a": 2})).deserialize_struct("Doc", &["a", "inner"], DocVisitor);
        assert_eq!(v.unwrap(), 2.0);
    }

    /// A visitor reading the `a` of a map (the adapter on a `serde_json::Value`).
    struct DocVisitor;
    impl<'de> Visitor<'de> for DocVisitor {
        type Value = f64;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("a map")
        }
        fn visit_map<A: MapAccess<'de>>(self, mut m: A) -> Result<f64, A::Error> {
            let mut a = f64::NAN;
            while let Some(k) = m.next_key::<String>()? {
                assert_ne!(k, SCHEMA_KEY);
                a = m.next_value()?;
            }
            Ok(a)
        }
    }

    #[test]
    fn schema_is_refused_where_it_is_no_string_or_not_at_the_top() {
        let e = read(r#"{"$schema": 3, "a": 1}"#).unwrap_err();
        assert!(e.contains("expected `$schema` to be a string"), "{e}");
        let e = read(r#"{"a": 1, "inner": {"$schema": "s.json", "b": 2}}"#).unwrap_err();
        assert!(e.starts_with("inner.$schema: unknown field `$schema`, expected `b`"), "{e}");
    }

    #[test]
    fn every_other_error_reads_as_without_the_adapter() {
        for text in [
            r#"{"a": 1, "controler": 2}"#,
            r#"{"a": 1, "controler": 2, "$schema": "s.json"}"#,
            r#"{"a": "x"}"#,
            r#"{"inner": {"c": 1}, "a": 1}"#,
            r#"{}"#,
            r#"[1, 2]"#,
            r#"3"#,
            r#"{"a": 1,}"#,
            r#"{"a": 1e999}"#,
        ] {
            // (a `$schema` after the error is never reached: same message, same column)
            let plain = read_plain(&text.replace(r#", "$schema": "s.json""#, ""));
            assert_eq!(read(text), plain, "{text}");
        }
    }
}
