//! Typed access to a decoded [`Recording`]: its metadata records ([`crate::meta`]) and the
//! messages of each topic as the structs of [`crate::messages`], by field name through the
//! schema stored in the file ([`crate::value::from_value`]), so that files of older format
//! versions and of other producers read the same way. No reader outside this crate spells a
//! record name, a key or a field path.

use std::collections::BTreeMap;

use super::{decode_typed, Recording};
use crate::messages::TopicMessage;
use crate::meta::{from_entries, MetadataRecord, RecordingInfo, RunDescription, RunNames, RunResult, SceneRecord, Setup, UrdfRecord, SETUP_KEY};
use crate::value::Value;
use crate::{from_log_time, Error};

/// How long the per-joint and per-contact arrays of every message must be
/// ([`Recording::read_sized`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArraySizes {
    pub joints: usize,
    pub contacts: usize,
}

impl Recording {
    /// Every metadata record, by name (records with the same name are merged, later keys win):
    /// for tools that show or export them all. Read a known record with [`Recording::record`].
    pub fn metadata_records(&self) -> &BTreeMap<String, BTreeMap<String, String>> {
        &self.metadata
    }

    /// The metadata record `R`; an error names the file, the record and the missing or bad key.
    pub fn record<R: MetadataRecord>(&self) -> Result<R, Error> {
        self.record_opt()?.ok_or_else(|| self.meta_err(R::NAME, "the recording has no such record".into()))
    }

    /// [`Recording::record`], `None` when the file has no such record (e.g. the `result` of a
    /// recording cut short).
    pub fn record_opt<R: MetadataRecord>(&self) -> Result<Option<R>, Error> {
        self.metadata.get(R::NAME).map(|entries| from_entries(entries).map_err(|d| self.meta_err(R::NAME, d))).transpose()
    }

    fn meta_err(&self, record: &str, detail: String) -> Error {
        Error::Metadata { file: self.source.clone(), record: record.to_string(), detail }
    }

    /// Record `recording`: the format version and the tool.
    pub fn info(&self) -> Result<RecordingInfo, Error> {
        self.record()
    }

    /// `recording.format_version`, if present and a number.
    pub fn format_version(&self) -> Option<u32> {
        self.record_opt::<RecordingInfo>().ok().flatten().map(|r| r.format_version)
    }

    /// What ran (record `run`), from a file of any format version: format 0 recorded no joint
    /// names, so they are `joint1` … `jointN` after the length of the first joint-indexed array
    /// decoded; [`RunDescription::setup`] is read when the record has it (format ≥ 1 from `sim`).
    pub fn run(&self) -> Result<RunDescription, Error> {
        let names: RunNames = self.record()?;
        let joint_names = match (names.joint_names, self.format_version()) {
            (Some(j), _) => j,
            (None, Some(0)) => (1..=self.first_joint_array_len.unwrap_or(0)).map(|k| format!("joint{k}")).collect(),
            (None, _) => return Err(self.meta_err(RunNames::NAME, "missing field `joint_names` (every format since 1 has it)".into())),
        };
        let entries = &self.metadata[RunNames::NAME];
        let setup = match entries.contains_key(SETUP_KEY) {
            true => Some(from_entries::<Setup>(entries).map_err(|d| self.meta_err(RunNames::NAME, d))?),
            false => None,
        };
        Ok(RunDescription { scene: names.scene, run: names.run, contacts: names.contacts, joint_names, setup })
    }

    /// [`Recording::run`], `None` when the file has no `run` record (another producer's).
    pub fn run_opt(&self) -> Result<Option<RunDescription>, Error> {
        match self.metadata.contains_key(RunNames::NAME) {
            true => self.run().map(Some),
            false => Ok(None),
        }
    }

    /// Record `scene`: the scene JSON as run, and where it came from.
    pub fn scene(&self) -> Result<SceneRecord, Error> {
        self.record()
    }

    /// Record `urdf`: the robot description as read.
    pub fn urdf(&self) -> Result<UrdfRecord, Error> {
        self.record()
    }

    /// Record `result`; `None` when the file has none (a recording recovered from damage).
    pub fn result(&self) -> Result<Option<RunResult>, Error> {
        self.record_opt()
    }

    /// Every message of `M`'s topic as an `M`, with its log time in s, in time order. The topic
    /// must be in the file and decoded; a message that lacks a field `M` needs is an error
    /// naming the message and the field.
    pub fn read<M: TopicMessage>(&self) -> Result<Vec<(f64, M)>, Error> {
        self.read_checked(None)
    }

    /// [`Recording::read`], and every per-joint array must have `sizes.joints` entries and every
    /// per-contact array `sizes.contacts` ([`crate::topics::array_index`]); an array that is
    /// not [`crate::topics::array_required`] may instead be empty (not recorded).
    pub fn read_sized<M: TopicMessage>(&self, sizes: ArraySizes) -> Result<Vec<(f64, M)>, Error> {
        self.read_checked(Some(sizes))
    }

    fn read_checked<M: TopicMessage>(&self, sizes: Option<ArraySizes>) -> Result<Vec<(f64, M)>, Error> {
        let topic = M::TOPIC;
        let list = self.topic_messages(topic)?;
        let mut out = Vec::with_capacity(list.len());
        for (index, (t_ns, v)) in list.iter().enumerate() {
            out.push((from_log_time(*t_ns), decode_typed(&self.source, topic, index, *t_ns, v, sizes)?));
        }
        Ok(out)
    }

    /// The decoded messages of `topic` (empty for a channel without messages); an error when the
    /// file has no such topic or did not decode it.
    fn topic_messages(&self, topic: &str) -> Result<&[(u64, Value)], Error> {
        self.check_topic(topic)?;
        Ok(self.messages.get(topic).map_or(&[], Vec::as_slice))
    }

    /// The file has a channel on `topic` and decoded it (when read for that topic); an error
    /// naming the topics it has, or why it was not decoded.
    pub fn check_topic(&self, topic: &str) -> Result<(), Error> {
        if self.messages.contains_key(topic) {
            return Ok(());
        }
        let chans: Vec<_> = self.channels.iter().filter(|c| c.topic == topic).collect();
        if chans.is_empty() {
            let available = self.channels.iter().map(|c| c.topic.clone()).collect();
            return Err(Error::UnknownTopic { file: self.source.clone(), topic: topic.into(), available });
        }
        if let Some(reason) = chans.iter().find_map(|c| c.undecoded.clone()) {
            return Err(Error::UndecodedTopic { file: self.source.clone(), topic: topic.into(), reason });
        }
        Ok(())
    }

    /// Hands the metadata records, then the decoded messages of `topics` to `visitor`, topic by topic in the order given,
    /// each in time order, as [`crate::stream_recording`] would (with the `run` record read):
    /// one computation serves a streamed read and a recording already in memory.
    pub fn replay(&self, topics: &[&str], visitor: &mut dyn crate::Visitor) -> Result<(), Error> {
        let run = self.run_opt()?;
        // the records first, as a streamed reading of a file `sim` wrote meets them
        for (name, entries) in self.metadata_records() {
            visitor.metadata(name, entries);
        }
        for &topic in topics {
            for (index, (log_time_ns, value)) in self.topic_messages(topic)?.iter().enumerate() {
                let m = crate::DecodedMessage { file: &self.source, topic, index, log_time_ns: *log_time_ns, body: crate::Body::Value(value.clone()), run: run.as_ref() };
                visitor.message(m)?;
            }
        }
        Ok(())
    }

    /// Whether `/energy` records the gears' friction loss apart (format 2 on; the field is in
    /// the file's schema), so that a 0 read from an older file is not taken for a value.
    pub fn has_gear_friction_loss(&self) -> bool {
        self.energy_has_gear_friction
    }
}
