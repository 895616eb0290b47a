//! [`Tap`]: the reader's own record consumer fed by a writer, so that a program that writes a
//! recording can hand the messages it writes to a [`Visitor`] exactly as a later read of the
//! file would ([`crate::stream_recording`]): the same decoders chosen from the same schemas, the
//! same checks (time order per channel, decoding errors), the same `run` record attached to
//! each message, and at the end the same [`Recording`] (metadata and channels, no messages).
//! `sim` prints its table from this, instead of reading its files back.
//!
//! The records arrive in the order they were written, which is the file's order per channel
//! (a writer that groups topics into chunks reorders messages across channels only), so a
//! visitor that keeps per-topic state (every reduction of `analyze`) sees what a reader sees.

use std::borrow::Cow;
use std::collections::BTreeMap;

use mcap::records::{Channel, MessageHeader, Metadata, Record, SchemaHeader};

use super::{State, Visitor};
use crate::writer::Mirror;
use crate::{Error, Recording};

/// Feeds written records to the reader's state and its messages to a visitor. The first
/// error (a message that does not decode, time going backwards, or the visitor's own) stops
/// the feeding and is kept for [`Tap::finish`]; it never stops the writing.
pub struct Tap {
    state: State,
    visitor: Box<dyn Visitor + Send>,
    error: Option<Error>,
}

/// What a [`Tap`] gives back: the recording as a reader would return it (or the first error),
/// and the visitor.
pub struct Tapped {
    pub recording: Result<Recording, Error>,
    pub visitor: Box<dyn Visitor + Send>,
}

impl Tap {
    /// A tap labelled `file` (as errors and [`Recording::source`] name it: the reader uses the
    /// path as given), decoding the messages of `topics` (all when `None`) for `visitor`.
    pub fn new(file: String, topics: Option<&[&str]>, visitor: Box<dyn Visitor + Send>) -> Self {
        let mut state = State::new(file, topics);
        // as a read of the file decodes for this visitor: typed, into kept storage (`read_state`)
        state.typed = visitor.typed();
        state.by_ref = state.typed && visitor.by_ref();
        Tap { state, visitor, error: None }
    }

    fn feed(&mut self, record: Record<'_>) {
        if self.error.is_none() {
            if let Err(e) = self.state.record(record, &mut *self.visitor) {
                self.error = Some(e);
            }
        }
    }

}

/// The records as written, to the reader's state (the tap is the writer's first [`Mirror`]).
impl Mirror for Tap {
    fn schema(&mut self, id: u16, name: &str, encoding: &str, data: &[u8]) {
        let header = SchemaHeader { id, name: name.into(), encoding: encoding.into() };
        self.feed(Record::Schema { header, data: Cow::Borrowed(data) });
    }

    fn channel(&mut self, id: u16, schema_id: u16, topic: &str, message_encoding: &str, metadata: &BTreeMap<String, String>) {
        let ch = Channel { id, schema_id, topic: topic.into(), message_encoding: message_encoding.into(), metadata: metadata.clone() };
        self.feed(Record::Channel(ch));
    }

    fn metadata(&mut self, name: &str, entries: &BTreeMap<String, String>) {
        self.feed(Record::Metadata(Metadata { name: name.into(), metadata: entries.clone() }));
    }

    fn message(&mut self, channel_id: u16, sequence: u32, log_time_ns: u64, data: &[u8]) {
        let header = MessageHeader { channel_id, sequence, log_time: log_time_ns, publish_time: log_time_ns };
        self.feed(Record::Message { header, data: Cow::Borrowed(data) });
    }
}

impl Tap {
    /// The recording as read (metadata, channels with their message counts), or the first
    /// error; and the visitor back.
    pub fn finish(self) -> Tapped {
        let recording = match self.error {
            Some(e) => Err(e),
            None => Ok(self.state.into_recording()),
        };
        Tapped { recording, visitor: self.visitor }
    }
}
