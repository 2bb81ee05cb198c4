//! Reading a recording back: its scalars, events and metadata, or one state.

use super::messages::{EVENTS_TOPIC, SCALARS_TOPIC, STATE_TOPIC, Scalars, StateMessage};
use crate::analysis::event::Event;
use crate::io::error::{IoError, Result};
use std::collections::BTreeMap;
use std::path::Path;

/// What a recording holds.
#[derive(Debug, Default)]
pub struct Recording {
    /// Scalars of every state, in order.
    pub scalars: Vec<Scalars>,
    /// Events.
    pub events: Vec<Event>,
    /// Metadata (scene text, versions).
    pub metadata: BTreeMap<String, String>,
    /// Topics and their message counts.
    pub channels: BTreeMap<String, u64>,
}

fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    crate::io::read_limited(path, crate::io::DATA_FILE_LIMIT)
        .map_err(IoError::file("cannot read recording", path))
}

/// The error for an MCAP file that cannot be parsed.
fn unreadable(path: &Path) -> impl Fn(mcap::McapError) -> IoError + Copy + use<'_> {
    move |e| IoError::Recording {
        path: path.into(),
        reason: format!("not a readable MCAP recording ({e})"),
    }
}

/// One record of a recording, as the validated pass hands it on.
enum Item<'a> {
    /// A message on a topic.
    Message { topic: &'a str, data: &'a [u8] },
    /// A metadata record.
    Metadata(mcap::records::Metadata),
}

/// Every message and metadata record of an MCAP file, in file order, with
/// its chunks' CRCs checked before any of their records is used, the data
/// section's CRC checked, and no record longer than the file allowed (so a
/// corrupted length is an error, not an allocation of that size).
fn each_record(path: &Path, bytes: &[u8], mut on: impl FnMut(Item) -> Result<()>) -> Result<()> {
    use mcap::records::Record;
    use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
    let bad = unreadable(path);
    let options = LinearReaderOptions::default()
        .with_prevalidate_chunk_crcs(true)
        .with_validate_data_section_crc(true)
        .with_validate_summary_section_crc(true)
        // no record (or decompressed chunk) is longer than 64 times the file
        .with_record_length_limit(bytes.len().saturating_mul(64).max(1 << 16));
    let mut reader = LinearReader::new_with_options(options);
    let mut rest = bytes;
    let mut topics: BTreeMap<u16, String> = BTreeMap::new();
    while let Some(event) = reader.next_event() {
        match event.map_err(bad)? {
            LinearReadEvent::ReadRequest(need) => {
                let len = need.min(rest.len());
                reader.insert(len).copy_from_slice(&rest[..len]);
                reader.notify_read(len);
                rest = &rest[len..];
            }
            LinearReadEvent::Record { data, opcode } => {
                use mcap::records::op;
                // only the records read here are parsed, and their string and
                // map lengths are checked against the record first: the
                // parser reserves a declared length before reading it
                if ![op::CHANNEL, op::MESSAGE, op::METADATA].contains(&opcode) {
                    continue;
                }
                if !lengths_fit(opcode, data) {
                    return Err(IoError::Recording {
                        path: path.into(),
                        reason: format!(
                            "not a readable MCAP recording (a record of opcode {opcode:#04x} \
                             declares a string or map longer than itself)"
                        ),
                    });
                }
                match mcap::parse_record(opcode, data).map_err(bad)? {
                    Record::Channel(c) => {
                        topics.insert(c.id, c.topic);
                    }
                    Record::Message { header, data } => {
                        let topic =
                            topics
                                .get(&header.channel_id)
                                .ok_or_else(|| IoError::Recording {
                                    path: path.into(),
                                    reason: format!(
                                        "a message on channel {} that was never declared",
                                        header.channel_id
                                    ),
                                })?;
                        on(Item::Message { topic, data: &data })?;
                    }
                    Record::Metadata(m) => on(Item::Metadata(m))?,
                    _ => {}
                }
            }
        }
    }
    Ok(())
}

/// Whether the length-prefixed strings and maps of a Channel or Metadata
/// record lie inside the record (Messages have none before their data).
fn lengths_fit(opcode: u8, data: &[u8]) -> bool {
    use mcap::records::op;
    /// Skip a u32 length and that many bytes from `at`; None if past `end`.
    fn skip(data: &[u8], at: usize, end: usize) -> Option<usize> {
        let len = u32::from_le_bytes(data.get(at..at + 4)?.try_into().ok()?) as usize;
        let next = (at + 4).checked_add(len)?;
        (next <= end).then_some(next)
    }
    /// A map of strings: its byte length, then key and value strings.
    fn map(data: &[u8], at: usize) -> Option<usize> {
        let end = skip(data, at, data.len())?;
        let mut k = at + 4;
        while k < end {
            k = skip(data, k, end)?;
            k = skip(data, k, end)?;
        }
        (k == end).then_some(end)
    }
    let fits = match opcode {
        // id u16, schema id u16, topic, message encoding, metadata
        op::CHANNEL => skip(data, 4, data.len())
            .and_then(|k| skip(data, k, data.len()))
            .and_then(|k| map(data, k)),
        // name, metadata
        op::METADATA => skip(data, 0, data.len()).and_then(|k| map(data, k)),
        _ => Some(0),
    };
    fits.is_some()
}

/// Read scalars, events, metadata and channel counts of a recording.
pub fn read_recording(path: &Path) -> Result<Recording> {
    parse_recording(path, &read_bytes(path)?)
}

/// Scalars, events, metadata and channel counts of a recording's `bytes`
/// (`path` names it in errors).
pub fn parse_recording(path: &Path, bytes: &[u8]) -> Result<Recording> {
    let mut rec = Recording::default();
    each_record(path, bytes, |item| {
        match item {
            Item::Message { topic, data } => {
                *rec.channels.entry(topic.to_string()).or_insert(0) += 1;
                match topic {
                    SCALARS_TOPIC => rec.scalars.push(
                        serde_json::from_slice(data)
                            .map_err(IoError::json("malformed scalars message", path))?,
                    ),
                    EVENTS_TOPIC => rec.events.push(
                        serde_json::from_slice(data)
                            .map_err(IoError::json("malformed event message", path))?,
                    ),
                    _ => {}
                }
            }
            Item::Metadata(md) if md.name == "knotrod" => rec.metadata = md.metadata,
            Item::Metadata(_) => {}
        }
        Ok(())
    })?;
    Ok(rec)
}

/// The state with index `index` of a recording, with its model.
pub fn read_state(path: &Path, index: u64) -> Result<StateMessage> {
    parse_state(path, &read_bytes(path)?, index)
}

/// Every state of a recording's `bytes`, in file order, handed to `on`
/// (`path` names the file in errors): one pass over the file.
pub fn each_state(
    path: &Path,
    bytes: &[u8],
    mut on: impl FnMut(StateMessage) -> Result<()>,
) -> Result<()> {
    each_record(path, bytes, |item| match item {
        Item::Message {
            topic: STATE_TOPIC,
            data,
        } => {
            on(serde_json::from_slice(data)
                .map_err(IoError::json("malformed state message", path))?)
        }
        _ => Ok(()),
    })
}

/// The state with index `index` of a recording's `bytes` (`path` names it in
/// errors).
pub fn parse_state(path: &Path, bytes: &[u8], index: u64) -> Result<StateMessage> {
    let (mut count, mut found) = (0, None);
    each_record(path, bytes, |item| {
        if let Item::Message {
            topic: STATE_TOPIC,
            data,
        } = item
            && found.is_none()
        {
            count += 1;
            let s: StateMessage = serde_json::from_slice(data)
                .map_err(IoError::json("malformed state message", path))?;
            if s.index == index {
                found = Some(s);
            }
        }
        Ok(())
    })?;
    found.ok_or_else(|| IoError::Recording {
        path: path.into(),
        reason: format!("no state with index {index} ({count} states recorded)"),
    })
}
