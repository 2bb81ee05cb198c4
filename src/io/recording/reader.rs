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
    std::fs::read(path).map_err(IoError::file("cannot read recording", path))
}

/// The error for an MCAP file that cannot be parsed.
fn unreadable(path: &Path) -> impl Fn(mcap::McapError) -> IoError + Copy + use<'_> {
    move |e| IoError::Recording {
        path: path.into(),
        reason: format!("not a readable MCAP recording ({e})"),
    }
}

/// Read scalars, events, metadata and channel counts of a recording.
pub fn read_recording(path: &Path) -> Result<Recording> {
    let bytes = read_bytes(path)?;
    let bad = unreadable(path);
    let mut rec = Recording::default();
    for m in mcap::MessageStream::new(&bytes).map_err(bad)? {
        let m = m.map_err(bad)?;
        *rec.channels.entry(m.channel.topic.clone()).or_insert(0) += 1;
        match m.channel.topic.as_str() {
            SCALARS_TOPIC => rec.scalars.push(
                serde_json::from_slice(&m.data)
                    .map_err(IoError::json("malformed scalars message", path))?,
            ),
            EVENTS_TOPIC => rec.events.push(
                serde_json::from_slice(&m.data)
                    .map_err(IoError::json("malformed event message", path))?,
            ),
            _ => {}
        }
    }
    for r in mcap::read::LinearReader::new(&bytes).map_err(bad)? {
        if let mcap::records::Record::Metadata(md) = r.map_err(bad)?
            && md.name == "knotrod"
        {
            rec.metadata = md.metadata;
        }
    }
    Ok(rec)
}

/// The state with index `index` of a recording, with its model.
pub fn read_state(path: &Path, index: u64) -> Result<StateMessage> {
    let bytes = read_bytes(path)?;
    let bad = unreadable(path);
    let mut count = 0;
    for m in mcap::MessageStream::new(&bytes).map_err(bad)? {
        let m = m.map_err(bad)?;
        if m.channel.topic == STATE_TOPIC {
            count += 1;
            let s: StateMessage = serde_json::from_slice(&m.data)
                .map_err(IoError::json("malformed state message", path))?;
            if s.index == index {
                return Ok(s);
            }
        }
    }
    Err(IoError::Recording {
        path: path.into(),
        reason: format!("no state with index {index} ({count} states recorded)"),
    })
}
