//! What a streamed read hands out: each decoded message ([`DecodedMessage`], with the `run`
//! record read so far) to a [`Visitor`], and its typed reading with the array checks of
//! [`crate::Recording::read_sized`] ([`decode_typed`], one routine for both).

use std::collections::BTreeMap;

use crate::messages::TopicMessage;
use crate::meta::RunDescription;
use crate::topics::{array_index, array_required, ArrayIndex};
use crate::value::{from_value, Value};
use crate::{from_log_time, ArraySizes, Error};

/// One decoded message, handed to a [`Visitor`].
#[derive(Debug, Clone)]
pub struct DecodedMessage<'a> {
    /// The file (label) it comes from.
    pub file: &'a str,
    pub topic: &'a str,
    /// Its index among the messages of its channel (0-based, file order).
    pub index: usize,
    pub log_time_ns: u64,
    pub value: Value,
    /// What ran (the `run` record), when the file has given it before this message (`sim`
    /// writes it first): the array sizes and the output grid to check the message against.
    pub run: Option<&'a RunDescription>,
}

impl DecodedMessage<'_> {
    /// The first value of the message that is NaN or infinite, with its field path (`error.x`,
    /// `current[2]`), in field order; `None` when every number is finite.
    pub fn non_finite(&self) -> Option<(String, f64)> {
        fn walk(v: &Value, path: &mut String) -> Option<(String, f64)> {
            match v {
                Value::F64(x) if !x.is_finite() => Some((path.clone(), *x)),
                Value::Struct(fields) => fields.iter().find_map(|(name, v)| {
                    let len = path.len();
                    if !path.is_empty() {
                        path.push('.');
                    }
                    path.push_str(name);
                    let found = walk(v, path);
                    path.truncate(len);
                    found
                }),
                Value::List(items) => items.iter().enumerate().find_map(|(k, v)| {
                    let len = path.len();
                    path.push_str(&format!("[{k}]"));
                    let found = walk(v, path);
                    path.truncate(len);
                    found
                }),
                _ => None,
            }
        }
        walk(&self.value, &mut String::new())
    }

    /// The per-joint and per-contact arrays of the message: `(field, kind, length)`, leaving out
    /// an optional array recorded empty ([`crate::topics::array_required`]).
    pub fn arrays(&self) -> impl Iterator<Item = (&str, ArrayIndex, usize)> + '_ {
        let fields = match &self.value {
            Value::Struct(fields) => fields.as_slice(),
            _ => &[],
        };
        fields.iter().filter_map(|(field, v)| match (array_index(self.topic, field), v) {
            (Some(kind), Value::List(items)) if !items.is_empty() || array_required(self.topic, field) => Some((field.as_str(), kind, items.len())),
            _ => None,
        })
    }

    /// The per-joint and per-contact array sizes of [`DecodedMessage::run`].
    pub fn sizes(&self) -> Option<ArraySizes> {
        self.run.map(|r| ArraySizes { joints: r.joint_names.len(), contacts: r.contacts.len() })
    }

    /// Log time, s.
    pub fn t_s(&self) -> f64 {
        from_log_time(self.log_time_ns)
    }

    /// The message as `M` (by field name); with `sizes`, every per-joint and per-contact array
    /// must have that many entries (see [`Recording::read_sized`]). Errors name the file, the
    /// topic, the message and the field.
    pub fn decode<M: TopicMessage>(&self, sizes: Option<ArraySizes>) -> Result<M, Error> {
        decode_typed(self.file, self.topic, self.index, self.log_time_ns, &self.value, sizes)
    }
}

/// Receives each decoded message of a [`stream_recording`], per channel in log-time order.
/// An error stops the reading and is returned.
pub trait Visitor {
    fn message(&mut self, message: DecodedMessage<'_>) -> Result<(), Error>;
}

impl<F: FnMut(DecodedMessage<'_>) -> Result<(), Error>> Visitor for F {
    fn message(&mut self, message: DecodedMessage<'_>) -> Result<(), Error> {
        self(message)
    }
}

/// Keeps every message: what [`read_recording`] returns.
#[derive(Default)]
pub(crate) struct Collect(pub(crate) BTreeMap<String, Vec<(u64, Value)>>);

impl Visitor for Collect {
    fn message(&mut self, m: DecodedMessage<'_>) -> Result<(), Error> {
        self.0.entry(m.topic.to_string()).or_default().push((m.log_time_ns, m.value));
        Ok(())
    }
}

/// Decodes one message as `M`, checking its array lengths against `sizes`.
pub(crate) fn decode_typed<M: TopicMessage>(
    file: &str,
    topic: &str,
    index: usize,
    log_time_ns: u64,
    v: &Value,
    sizes: Option<ArraySizes>,
) -> Result<M, Error> {
    if let (Some(sizes), Value::Struct(fields)) = (sizes, v) {
        for (field, value) in fields {
            let (Some(kind), Value::List(items)) = (array_index(topic, field), value) else { continue };
            let (expected, per) = match kind {
                ArrayIndex::Joint => (sizes.joints, "joint"),
                ArrayIndex::Contact => (sizes.contacts, "contact"),
            };
            if items.len() != expected && (array_required(topic, field) || !items.is_empty()) {
                return Err(Error::WrongLength {
                    file: file.to_string(),
                    topic: topic.into(),
                    field: field.clone(),
                    index,
                    t_s: from_log_time(log_time_ns),
                    found: items.len(),
                    expected,
                    per,
                });
            }
        }
    }
    from_value(v).map_err(|e| Error::Field {
        file: file.to_string(),
        topic: topic.into(),
        index,
        log_time_ns,
        detail: e.to_string(),
    })
}
