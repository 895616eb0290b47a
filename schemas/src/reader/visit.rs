//! What a streamed read hands out: each decoded message ([`DecodedMessage`], with the `run`
//! record read so far) to a [`Visitor`], and its typed reading with the array checks of
//! [`crate::Recording::read_sized`] ([`decode_typed`], one routine for both).
//!
//! A message's [`Body`] is the generic tree ([`Value`]) or, for a visitor that asks for it
//! ([`Visitor::typed`]) and a channel with this crate's own schema, the struct decoded straight
//! from the bytes ([`Known`]); every method of [`DecodedMessage`] gives the same answer for
//! both.

use std::borrow::Cow;
use std::collections::BTreeMap;

use crate::messages::TopicMessage;
use crate::meta::RunDescription;
use crate::topics::{array_index, array_required, ArrayIndex};
use crate::value::{from_value, Value};
use crate::{from_log_time, ArraySizes, Error};

pub use super::known::Known;

/// A decoded message's content.
#[derive(Debug, Clone, PartialEq)]
pub enum Body {
    /// The generic tree, decoded through the schema stored in the file.
    Value(Value),
    /// One of this crate's metric messages, decoded typed ([`Visitor::typed`]).
    Known(Known),
}

/// One decoded message, handed to a [`Visitor`].
#[derive(Debug, Clone)]
pub struct DecodedMessage<'a> {
    /// The file (label) it comes from.
    pub file: &'a str,
    pub topic: &'a str,
    /// Its index among the messages of its channel (0-based, file order).
    pub index: usize,
    pub log_time_ns: u64,
    pub body: Body,
    /// What ran (the `run` record), when the file has given it before this message (`sim`
    /// writes it first): the array sizes and the output grid to check the message against.
    pub run: Option<&'a RunDescription>,
}

impl DecodedMessage<'_> {
    /// The first value of the message that is NaN or infinite, with its field path (`error.x`,
    /// `current[2]`), in field order; `None` when every number is finite.
    pub fn non_finite(&self) -> Option<(String, f64)> {
        let value = match &self.body {
            Body::Value(v) => v,
            Body::Known(k) => return k.non_finite(),
        };
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
        walk(value, &mut String::new())
    }

    /// The message as the generic tree (built from the struct for a [`Body::Known`]).
    pub fn value(&self) -> Cow<'_, Value> {
        match &self.body {
            Body::Value(v) => Cow::Borrowed(v),
            Body::Known(k) => Cow::Owned(k.to_value()),
        }
    }

    /// The per-joint and per-contact arrays of the message: `(field, kind, length)`, leaving out
    /// an optional array recorded empty ([`crate::topics::array_required`]).
    pub fn arrays(&self) -> impl Iterator<Item = (&str, ArrayIndex, usize)> + '_ {
        let keep = |field: &str, len: usize| len > 0 || array_required(self.topic, field);
        let (fields, known) = match &self.body {
            Body::Value(Value::Struct(fields)) => (fields.as_slice(), None),
            Body::Value(_) => (&[][..], None),
            Body::Known(k) => (&[][..], Some(known_arrays(self.topic, k))),
        };
        let generic = fields.iter().filter_map(move |(field, v)| match (array_index(self.topic, field), v) {
            (Some(kind), Value::List(items)) if keep(field, items.len()) => Some((field.as_str(), kind, items.len())),
            _ => None,
        });
        generic.chain(known.into_iter().flatten().filter(move |&(field, _, len)| keep(field, len)))
    }

    /// [`DecodedMessage::arrays`], each handed to `f` in the same order until it fails (no
    /// iterator built: for a check of every message).
    pub fn try_for_each_array<E>(&self, mut f: impl FnMut(&str, ArrayIndex, usize) -> Result<(), E>) -> Result<(), E> {
        match &self.body {
            Body::Known(k) => known_each_array(self.topic, k, |field, kind, len| match len > 0 || array_required(self.topic, field) {
                true => f(field, kind, len),
                false => Ok(()),
            }),
            Body::Value(_) => self.arrays().try_for_each(|(field, kind, len)| f(field, kind, len)),
        }
    }

    /// The per-joint and per-contact array sizes of [`DecodedMessage::run`].
    pub fn sizes(&self) -> Option<ArraySizes> {
        self.run.map(|r| ArraySizes { joints: r.joint_names.len(), contacts: r.contacts.len() })
    }

    /// Every per-joint and per-contact array has the length [`DecodedMessage::sizes`] gives
    /// (an optional array may be empty); `Ok` when no `run` record has been read. Errors name
    /// the file, the topic, the field, the message and its time.
    pub fn check_sizes(&self) -> Result<(), Error> {
        let Some(sizes) = self.sizes() else { return Ok(()) };
        for (field, kind, len) in self.arrays() {
            check_length(self.file, self.topic, self.index, self.log_time_ns, field, kind, len, sizes)?;
        }
        Ok(())
    }

    /// Log time, s.
    pub fn t_s(&self) -> f64 {
        from_log_time(self.log_time_ns)
    }

    /// The message as `M` (by field name); with `sizes`, every per-joint and per-contact array
    /// must have that many entries (see [`Recording::read_sized`]). Errors name the file, the
    /// topic, the message and the field.
    pub fn decode<M: TopicMessage + Clone + 'static>(&self, sizes: Option<ArraySizes>) -> Result<M, Error> {
        self.decode_ref::<M>(sizes).map(Cow::into_owned)
    }

    /// [`DecodedMessage::decode`], borrowed from a [`Body::Known`] (no copy).
    pub fn decode_ref<M: TopicMessage + Clone + 'static>(&self, sizes: Option<ArraySizes>) -> Result<Cow<'_, M>, Error> {
        match &self.body {
            Body::Value(v) => decode_typed(self.file, self.topic, self.index, self.log_time_ns, v, sizes).map(Cow::Owned),
            Body::Known(k) => {
                if let Some(sizes) = sizes {
                    known_each_array(self.topic, k, |field, kind, len| check_length(self.file, self.topic, self.index, self.log_time_ns, field, kind, len, sizes))?;
                }
                let wrong = || Error::Field {
                    file: self.file.to_string(),
                    topic: self.topic.into(),
                    index: self.index,
                    log_time_ns: self.log_time_ns,
                    detail: format!("the message is a {}, not a {}", known_name(k), std::any::type_name::<M>()),
                };
                k.as_typed::<M>().map(Cow::Borrowed).ok_or_else(wrong)
            }
        }
    }
}

/// The per-joint and per-contact arrays of a known message on `topic`: `(field, kind, length)`.
fn known_arrays<'a>(topic: &'a str, k: &Known) -> impl Iterator<Item = (&'a str, ArrayIndex, usize)> + use<'a> {
    let (lists, n) = k.lists();
    lists.into_iter().take(n).filter_map(move |(name, len): (&'a str, usize)| array_index(topic, name).map(|kind| (name, kind, len)))
}

/// [`known_arrays`], each handed to `f` in order until it fails.
fn known_each_array<E>(topic: &str, k: &Known, mut f: impl FnMut(&str, ArrayIndex, usize) -> Result<(), E>) -> Result<(), E> {
    use std::ops::ControlFlow;
    use super::known::Field;
    let own = k.array_kind().filter(|_| topic == k.topic());
    let done = k.fields(|name, field| {
        let len = match field {
            Field::List(xs) => xs.len(),
            Field::Names(names) => names.len(),
            Field::Codes(codes) => codes.len(),
            _ => return ControlFlow::Continue(()),
        };
        match own.or_else(|| array_index(topic, name)).map(|kind| f(name, kind, len)) {
            Some(Err(e)) => ControlFlow::Break(e),
            _ => ControlFlow::Continue(()),
        }
    });
    match done {
        ControlFlow::Break(e) => Err(e),
        ControlFlow::Continue(()) => Ok(()),
    }
}

fn known_name(k: &Known) -> &'static str {
    match k {
        Known::Hand(_) => "HandState",
        Known::Motors(_) => "MotorState",
        Known::Constraints(_) => "ConstraintState",
        Known::Energy(_) => "EnergyState",
        Known::Contacts(_) => "ContactState",
    }
}

/// An array of `len` entries of `kind` on `topic` has the length `sizes` requires (an optional
/// array may be empty).
#[allow(clippy::too_many_arguments)]
fn check_length(file: &str, topic: &str, index: usize, log_time_ns: u64, field: &str, kind: ArrayIndex, len: usize, sizes: ArraySizes) -> Result<(), Error> {
    let (expected, per) = match kind {
        ArrayIndex::Joint => (sizes.joints, "joint"),
        ArrayIndex::Contact => (sizes.contacts, "contact"),
    };
    if len != expected && (array_required(topic, field) || len != 0) {
        return Err(Error::WrongLength {
            file: file.to_string(),
            topic: topic.into(),
            field: field.to_string(),
            index,
            t_s: from_log_time(log_time_ns),
            found: len,
            expected,
            per,
        });
    }
    Ok(())
}

/// Receives each decoded message of a [`stream_recording`], per channel in log-time order.
/// An error stops the reading and is returned.
pub trait Visitor {
    fn message(&mut self, message: DecodedMessage<'_>) -> Result<(), Error>;

    /// A metadata record, in file order (`sim` writes the run's records before its messages
    /// and `result` last), so a visitor can use a record for the messages that follow it.
    /// The default ignores it.
    fn metadata(&mut self, _name: &str, _entries: &std::collections::BTreeMap<String, String>) {}

    /// Whether this visitor takes the metric messages typed ([`Body::Known`]) when their schema
    /// is this crate's own (faster: no generic tree); `false` (the default): always a
    /// [`Body::Value`].
    fn typed(&self) -> bool {
        false
    }

    /// Whether this visitor takes the messages by reference ([`Visitor::message_ref`]) and
    /// keeps nothing of them past the call: the reader then decodes each typed message
    /// ([`Visitor::typed`]) into storage it keeps from one message to the next (no allocation
    /// per message). `false` (the default): [`Visitor::message`], which owns each message.
    fn by_ref(&self) -> bool {
        false
    }

    /// One decoded message, borrowed (for a visitor whose [`Visitor::by_ref`] is `true`); the
    /// default hands a copy to [`Visitor::message`].
    fn message_ref(&mut self, message: &DecodedMessage<'_>) -> Result<(), Error> {
        self.message(message.clone())
    }
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
        let value = match m.body {
            Body::Value(v) => v,
            Body::Known(k) => k.to_value(),
        };
        self.0.entry(m.topic.to_string()).or_default().push((m.log_time_ns, value));
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
            check_length(file, topic, index, log_time_ns, field, kind, items.len(), sizes)?;
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
