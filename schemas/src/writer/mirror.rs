//! [`Mirror`]: every record a [`super::RecordingWriter`] writes, handed as it is written (the
//! same ids, the same schema and channel metadata, the same message bytes) to someone else: the
//! reader's own consumer ([`crate::Tap`], so `sim` prints its table without reading its files
//! back) or a live viewer (`sim --live` streams the records to Foxglove over its WebSocket
//! protocol). A mirror only observes: it cannot change what reaches the file, so a recording
//! made with one is byte for byte the recording made without.
//!
//! The records are those of the MCAP specification (<https://mcap.dev/spec>: "Schema",
//! "Channel", "Metadata", "Message"), in the order the caller wrote them, which is the file's
//! order per channel (a writer that groups topics into chunks reorders messages across
//! channels only). A schema comes before the first channel that uses it, a channel before its
//! first message. The calls run on the writer's thread (the background one by default): a
//! mirror that blocks (a live view paced to real time) holds the writer, whose bounded queue
//! then holds the simulation, and changes no number.
//!
//! A mirror cannot lose the recording either: the writer wraps every mirror in [`Guarded`],
//! which runs each call under `catch_unwind`. A mirror that panics (a bug in a live server, a
//! viewer library's assertion) is dropped after a warning on stderr naming it, gets nothing
//! more, and the file is written and finished as without it (`schemas/tests/mirror.rs`).

use std::collections::BTreeMap;

/// A consumer of the records a writer writes. Every method but [`Mirror::message`] has a
/// default that ignores the record.
pub trait Mirror: Send {
    /// Schema `id` (from 1, in order of first use; identical schemas share one id): its name,
    /// encoding (`protobuf`, `ros2msg`) and data as written.
    fn schema(&mut self, id: u16, name: &str, encoding: &str, data: &[u8]) {
        let _ = (id, name, encoding, data);
    }

    /// Channel `id` (from 1, in order of first use) of `topic`, with its schema, message
    /// encoding and channel metadata (the `units` of [`crate::units`]) as written.
    fn channel(&mut self, id: u16, schema_id: u16, topic: &str, message_encoding: &str, metadata: &BTreeMap<String, String>) {
        let _ = (id, schema_id, topic, message_encoding, metadata);
    }

    /// A metadata record `name` with its entries as written ([`crate::meta`]).
    fn metadata(&mut self, name: &str, entries: &BTreeMap<String, String>) {
        let _ = (name, entries);
    }

    /// A message on channel `channel_id`: its per-channel `sequence` (from 0), its log time
    /// (also its publish time), ns, and its encoded bytes, as written.
    fn message(&mut self, channel_id: u16, sequence: u32, log_time_ns: u64, data: &[u8]);

    /// The writer finished the file (summary and footer written), or stopped without it.
    fn finish(&mut self) {}
}

/// A [`Mirror`] whose panics stay inside it: each call to the inner mirror runs under
/// [`std::panic::catch_unwind`]; after a panic (the panic hook has printed its message) a
/// warning says the mirror was stopped and the recording goes on, and the inner mirror
/// receives nothing more (not even [`Mirror::finish`]: its state is unknown). The writer wraps
/// every mirror it is given in one.
pub struct Guarded {
    inner: Option<Box<dyn Mirror>>,
}

impl Guarded {
    pub fn new(inner: Box<dyn Mirror>) -> Self {
        Guarded { inner: Some(inner) }
    }

    fn call(&mut self, what: &'static str, f: impl FnOnce(&mut dyn Mirror)) {
        let Some(inner) = self.inner.as_mut() else { return };
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(inner.as_mut())));
        if result.is_err() {
            // dropping it may panic too
            let inner = self.inner.take();
            let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(move || drop(inner)));
            eprintln!("warning: the recording's mirror (the live view) panicked on a {what} record and was stopped; the recording is written without it");
        }
    }
}

impl Mirror for Guarded {
    fn schema(&mut self, id: u16, name: &str, encoding: &str, data: &[u8]) {
        self.call("schema", |m| m.schema(id, name, encoding, data));
    }

    fn channel(&mut self, id: u16, schema_id: u16, topic: &str, message_encoding: &str, metadata: &BTreeMap<String, String>) {
        self.call("channel", |m| m.channel(id, schema_id, topic, message_encoding, metadata));
    }

    fn metadata(&mut self, name: &str, entries: &BTreeMap<String, String>) {
        self.call("metadata", |m| m.metadata(name, entries));
    }

    fn message(&mut self, channel_id: u16, sequence: u32, log_time_ns: u64, data: &[u8]) {
        self.call("message", |m| m.message(channel_id, sequence, log_time_ns, data));
    }

    fn finish(&mut self) {
        self.call("finish", |m| m.finish());
    }
}
