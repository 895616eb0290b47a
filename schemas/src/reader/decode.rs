//! Decoding a channel's messages into [`Value`]s: the decoder chosen from the channel's
//! message and schema encodings (MCAP spec, "Well-known encodings"), and the conversion of a
//! protobuf message decoded by `prost-reflect` into a [`Value`].

use prost_reflect::{DescriptorPool, DynamicMessage, MessageDescriptor, ReflectMessage};

use super::ChannelInfo;
use crate::value::Value;
use crate::{ros2msg, Error};

pub(super) struct SchemaRec {
    pub(super) name: String,
    pub(super) encoding: String,
    pub(super) data: Vec<u8>,
}

pub(super) enum Decoder {
    /// One of this crate's metric messages with this crate's schema, decoded typed.
    Known(super::known::KnownKind),
    Protobuf(MessageDescriptor),
    Ros2(ros2msg::MsgSchema),
    Json,
    Skip(String),
}

/// Chooses and builds the decoder of a channel from its encodings and schema.
pub(super) fn decoder_for(
    file: &str,
    info: &ChannelInfo,
    schema: Option<&SchemaRec>,
) -> Result<Decoder, Error> {
    let bad = |detail: String| Error::BadSchema {
        file: file.to_string(),
        topic: info.topic.clone(),
        schema: info.schema_name.clone(),
        encoding: info.schema_encoding.clone(),
        detail,
    };
    let (menc, senc) = (
        info.message_encoding.as_str(),
        info.schema_encoding.as_str(),
    );
    match (menc, senc, schema) {
        ("json", _, _) => Ok(Decoder::Json),
        ("protobuf", "protobuf", Some(s)) => {
            let pool = DescriptorPool::decode(s.data.as_slice()).map_err(|e| bad(e.to_string()))?;
            let desc = pool
                .get_message_by_name(&s.name)
                .ok_or_else(|| bad(format!("the descriptor set has no message {}", s.name)))?;
            Ok(Decoder::Protobuf(desc))
        }
        ("cdr", "ros2msg", Some(s)) => {
            let text = std::str::from_utf8(&s.data)
                .map_err(|e| bad(format!("schema text is not UTF-8: {e}")))?;
            Ok(Decoder::Ros2(ros2msg::parse(&s.name, text).map_err(bad)?))
        }
        _ => Ok(Decoder::Skip(format!(
            "message encoding {menc:?} with schema encoding {senc:?} is not decoded by this reader"
        ))),
    }
}

/// Converts a decoded protobuf message, fields in descriptor order. Members of a oneof (and
/// proto3 `optional` fields) that are not set are left out; other unset fields read as their
/// default, as protobuf defines.
pub(super) fn message_to_value(msg: &DynamicMessage) -> Value {
    let mut out = Vec::new();
    for fd in msg.descriptor().fields() {
        if fd.containing_oneof().is_some() && !msg.has_field(&fd) {
            continue;
        }
        out.push((fd.name().to_string(), proto_to_value(&msg.get_field(&fd))));
    }
    Value::Struct(out)
}

fn proto_to_value(v: &prost_reflect::Value) -> Value {
    use prost_reflect::{MapKey, Value as P};
    match v {
        P::Bool(b) => Value::Bool(*b),
        P::I32(x) => Value::I64(i64::from(*x)),
        P::I64(x) => Value::I64(*x),
        P::U32(x) => Value::U64(u64::from(*x)),
        P::U64(x) => Value::U64(*x),
        P::F32(x) => Value::F64(f64::from(*x)),
        P::F64(x) => Value::F64(*x),
        P::String(s) => Value::String(s.clone()),
        P::Bytes(b) => Value::Bytes(b.to_vec()),
        P::EnumNumber(n) => Value::I64(i64::from(*n)),
        P::Message(m) => message_to_value(m),
        P::List(items) => Value::List(items.iter().map(proto_to_value).collect()),
        P::Map(map) => {
            let mut entries: Vec<(&MapKey, &P)> = map.iter().collect();
            entries.sort_by(|a, b| a.0.cmp(b.0));
            let key = |k: &MapKey| match k {
                MapKey::Bool(b) => Value::Bool(*b),
                MapKey::I32(x) => Value::I64(i64::from(*x)),
                MapKey::I64(x) => Value::I64(*x),
                MapKey::U32(x) => Value::U64(u64::from(*x)),
                MapKey::U64(x) => Value::U64(*x),
                MapKey::String(s) => Value::String(s.clone()),
            };
            Value::List(
                entries
                    .into_iter()
                    .map(|(k, v)| {
                        Value::Struct(vec![
                            ("key".into(), key(k)),
                            ("value".into(), proto_to_value(v)),
                        ])
                    })
                    .collect(),
            )
        }
    }
}
