//! Rewriting a recording with its topics grouped per chunk (feature `synth`, for tests and
//! benchmarks of the chunk-skipping reader): every chunk holds the messages of one group of
//! topics only, as a writer that groups topics would write it. Schemas, channels (same ids),
//! messages (same headers and bytes, each channel in its order) and metadata are copied; the
//! file is written by the `mcap` crate's writer, with or without a summary section.

use std::collections::BTreeMap;
use std::io::Cursor;

use mcap::records::{MessageHeader, Record};

/// A group's buffered bytes and messages.
type Buffered = (usize, Vec<(MessageHeader, Vec<u8>)>);

/// Rewrites the MCAP bytes `src`: the messages of each group of `groups` (topic names; topics
/// in no group form one more group) go to chunks of their own, a chunk being closed when its
/// group has `chunk_bytes` of messages buffered and at the end. `summary`: write the summary
/// section (schemas, channels, chunk indexes, statistics) or none at all.
pub fn regroup_chunks(src: &[u8], groups: &[&[&str]], chunk_bytes: usize, summary: bool) -> Result<Vec<u8>, mcap::McapError> {
    let options = mcap::WriteOptions::new()
        .profile("")
        .compression(Some(mcap::Compression::Zstd))
        .chunk_size(None) // chunks end where a group is flushed
        .emit_summary_records(summary)
        .emit_summary_offsets(summary);
    let mut out = options.create(Cursor::new(Vec::new()))?;
    let mut topic_of = BTreeMap::new();
    let group_of = |topic: &str| groups.iter().position(|g| g.contains(&topic)).unwrap_or(groups.len());
    let mut buffered: Vec<Buffered> = vec![(0, Vec::new()); groups.len() + 1];
    let mut known_schemas = BTreeMap::new();
    let write_group = |out: &mut mcap::Writer<Cursor<Vec<u8>>>, group: &mut Buffered| -> Result<(), mcap::McapError> {
        if group.1.is_empty() {
            return Ok(());
        }
        for (header, data) in group.1.drain(..) {
            out.write_to_known_channel(&header, &data)?;
        }
        group.0 = 0;
        out.flush()
    };
    for record in mcap::read::ChunkFlattener::new(src)? {
        match record? {
            Record::Schema { header, data } if known_schemas.insert(header.id, ()).is_none() => {
                out.add_schema_with_id(header.id, &header.name, &header.encoding, &data)?;
            }
            Record::Channel(ch) if !topic_of.contains_key(&ch.id) => {
                out.add_channel_with_id(ch.id, ch.schema_id, &ch.topic, &ch.message_encoding, &ch.metadata)?;
                topic_of.insert(ch.id, ch.topic);
            }
            Record::Message { header, data } => {
                let g = group_of(topic_of.get(&header.channel_id).map_or("", String::as_str));
                buffered[g].0 += data.len();
                buffered[g].1.push((header, data.into_owned()));
                if buffered[g].0 >= chunk_bytes {
                    write_group(&mut out, &mut buffered[g])?;
                }
            }
            Record::Metadata(m) => out.write_metadata(&m)?,
            _ => {}
        }
    }
    for group in &mut buffered {
        write_group(&mut out, group)?;
    }
    out.finish()?;
    Ok(out.into_inner().into_inner())
}
