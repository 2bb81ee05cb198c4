//! Writing a recording: [`Recorder`].

use super::foxglove::scene_update;
use super::messages::{
    EVENT_SCHEMA, EVENTS_TOPIC, SCALARS_SCHEMA, SCALARS_TOPIC, SCENE_TOPIC, STATE_SCHEMA,
    STATE_TOPIC, Scalars, StateMessage, TF_TOPIC,
};
use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::Event;
use crate::io::error::{IoError, Result};
use crate::io::output::Output;
use crate::model::rod::RodModel;
use foxglove::Encode;
use foxglove::messages::{
    FrameTransform, Quaternion, SceneUpdate, Timestamp, Vector3 as FgVector3,
};
use mcap::records::{MessageHeader, Metadata};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// An MCAP recording being written, to a temporary file that
/// [`Recorder::finish`] finalises and renames into place (see [`Output`]):
/// dropped unfinished, or after a failed write, it leaves the file that was
/// there as it was.
pub struct Recorder {
    writer: Option<Mcap>,
    /// The first failure: later calls name it (the MCAP writer itself only
    /// says that an earlier write failed), and `finish` returns it.
    failed: Option<IoError>,
    path: PathBuf,
    channels: [u16; 5],
    count: u64,
    sequence: u32,
    rod_diameter: f64,
    model: RodModel,
}

fn encode<T: Encode>(m: &T, path: &Path) -> Result<Vec<u8>> {
    let mut buf = Vec::new();
    m.encode(&mut buf).map_err(|e| IoError::Recording {
        path: path.into(),
        reason: format!("encoding a Foxglove message: {e}"),
    })?;
    Ok(buf)
}

/// An MCAP writer error at `step` on `path`: a full disk as such.
fn mcap_error(step: &'static str, path: &Path) -> impl FnOnce(mcap::McapError) -> IoError {
    let path = path.to_path_buf();
    move |source| match source {
        mcap::McapError::Io(e) => crate::io::output::file_error(step, &path, e),
        source => IoError::Mcap { step, path, source },
    }
}

/// The MCAP writer of a recording file.
type Mcap = mcap::Writer<BufWriter<Output>>;

/// One channel of a recording (and of the live view): its topic, its
/// schema and the encoding of its messages.
pub(crate) struct ChannelSpec {
    /// Topic.
    pub topic: &'static str,
    /// The schema (name, encoding, data).
    pub schema: foxglove::Schema,
    /// "protobuf" or "json".
    pub message_encoding: &'static str,
}

/// The five channels: scene, transform, scalars, state, events.
pub(crate) fn channel_specs() -> [ChannelSpec; 5] {
    let protobuf = |topic, schema: Option<foxglove::Schema>| ChannelSpec {
        topic,
        schema: schema.expect("Foxglove's well-known messages have schemas"),
        message_encoding: "protobuf",
    };
    let json = |topic, name: &str, data: &'static str| ChannelSpec {
        topic,
        schema: foxglove::Schema::new(name, "jsonschema", data.as_bytes()),
        message_encoding: "json",
    };
    [
        protobuf(SCENE_TOPIC, SceneUpdate::get_schema()),
        protobuf(TF_TOPIC, FrameTransform::get_schema()),
        json(SCALARS_TOPIC, "knotrod.Scalars", SCALARS_SCHEMA),
        json(STATE_TOPIC, "knotrod.RodState", STATE_SCHEMA),
        json(EVENTS_TOPIC, "knotrod.Event", EVENT_SCHEMA),
    ]
}

/// The five channels, in the order of [`Recorder`]'s `channels`.
fn add_channels(writer: &mut Mcap, path: &Path) -> Result<[u16; 5]> {
    let mut ids = [0; 5];
    for (id, spec) in ids.iter_mut().zip(channel_specs()) {
        let s = &spec.schema;
        let sid = writer
            .add_schema(&s.name, &s.encoding, &s.data)
            .map_err(mcap_error("adding a schema", path))?;
        *id = writer
            .add_channel(sid, spec.topic, spec.message_encoding, &BTreeMap::new())
            .map_err(mcap_error("adding a channel", path))?;
    }
    Ok(ids)
}

/// The metadata: the scene text, the versions and the model.
fn write_metadata(
    writer: &mut Mcap,
    path: &Path,
    scene_text: &str,
    model: &RodModel,
) -> Result<()> {
    let mut meta = BTreeMap::new();
    meta.insert("scene".to_string(), scene_text.to_string());
    meta.insert(
        "knotrod_version".to_string(),
        env!("CARGO_PKG_VERSION").to_string(),
    );
    meta.insert(
        "git_revision".to_string(),
        crate::io::build_info::git_revision().to_string(),
    );
    let model_json =
        serde_json::to_string(model).map_err(IoError::json("encoding the model", path))?;
    meta.insert("model".to_string(), model_json);
    writer
        .write_metadata(&Metadata {
            name: "knotrod".into(),
            metadata: meta,
        })
        .map_err(mcap_error("writing the metadata", path))
}

/// The messages of state `index` on the first four channels (scene,
/// transform, scalars, state), as a recording and the live view send them
/// (`path` names the recording in errors).
pub(crate) fn state_messages(
    index: u64,
    e: &Equilibrium,
    model: &RodModel,
    rod_diameter: f64,
    path: &Path,
) -> Result<[Vec<u8>; 4]> {
    let stamp = Some(Timestamp::new(index as u32, 0));
    let scene = encode(&scene_update(e, rod_diameter, stamp), path)?;
    let tf = FrameTransform {
        timestamp: stamp,
        parent_frame_id: "world".into(),
        child_frame_id: "rod".into(),
        translation: Some(FgVector3 {
            x: 0.0,
            y: 0.0,
            z: 0.0,
        }),
        rotation: Some(Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }),
    };
    let scalars = serde_json::to_vec(&Scalars::of(index, e))
        .map_err(IoError::json("encoding the scalars", path))?;
    let state = StateMessage {
        index,
        model: model.clone(),
        state: e.state.clone(),
    };
    let state = serde_json::to_vec(&state).map_err(IoError::json("encoding the state", path))?;
    Ok([scene, encode(&tf, path)?, scalars, state])
}

impl Recorder {
    /// Create `path`, with metadata holding the scene text and versions.
    pub fn create(
        path: &Path,
        scene_text: &str,
        model: &RodModel,
        rod_diameter: f64,
    ) -> Result<Self> {
        let file = Output::create(path)?;
        let mut writer = mcap::WriteOptions::new()
            // a stream (FIFO, device, standard output) cannot seek back: its
            // chunks are then assembled in memory
            .disable_seeking(file.is_stream())
            .profile("")
            .library(format!("knotrod {}", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::new(file))
            .map_err(mcap_error("writing the header", path))?;
        let channels = add_channels(&mut writer, path)?;
        write_metadata(&mut writer, path, scene_text, model)?;
        Ok(Recorder {
            writer: Some(writer),
            failed: None,
            path: path.into(),
            channels,
            count: 0,
            sequence: 0,
            rod_diameter,
            model: model.clone(),
        })
    }

    /// `value` as JSON bytes.
    fn json<T: serde::Serialize + ?Sized>(&self, step: &'static str, value: &T) -> Result<Vec<u8>> {
        serde_json::to_vec(value).map_err(IoError::json(step, &self.path))
    }

    /// Where it is written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The writer, unless finished or failed (then the first failure).
    fn writer(&mut self) -> Result<&mut Mcap> {
        if let Some(first) = &self.failed {
            return Err(IoError::Recording {
                path: self.path.clone(),
                reason: format!("not written: {first}"),
            });
        }
        self.writer.as_mut().ok_or_else(|| IoError::Recording {
            path: self.path.clone(),
            reason: "recording already finished".into(),
        })
    }

    /// Keep the first failure of `r` (returned by `finish`); this call
    /// answers with a copy.
    fn note<T>(&mut self, r: Result<T>) -> Result<T> {
        r.map_err(|e| {
            let path = self.path.clone();
            let copy = match &e {
                IoError::NoSpace { streamed, .. } => IoError::NoSpace {
                    path,
                    streamed: *streamed,
                },
                e => IoError::Recording {
                    path,
                    reason: std::error::Error::source(e)
                        .map_or_else(|| e.to_string(), |s| format!("writing failed: {s}")),
                },
            };
            self.failed.get_or_insert(e);
            copy
        })
    }

    fn write(&mut self, channel: usize, log_time: u64, data: &[u8]) -> Result<()> {
        self.sequence += 1;
        let (sequence, channel_id, path) =
            (self.sequence, self.channels[channel], self.path.clone());
        let w = self.writer()?;
        let r = w
            .write_to_known_channel(
                &MessageHeader {
                    channel_id,
                    sequence,
                    log_time,
                    publish_time: log_time,
                },
                data,
            )
            .map_err(mcap_error("writing a message", &path));
        self.note(r)
    }

    /// Record one equilibrium (log time = its index, in seconds).
    pub fn record(&mut self, e: &Equilibrium) -> Result<()> {
        let index = self.count;
        let t = index * 1_000_000_000;
        let messages = state_messages(index, e, &self.model, self.rod_diameter, &self.path)?;
        for (channel, data) in messages.iter().enumerate() {
            self.write(channel, t, data)?;
        }
        self.count += 1;
        Ok(())
    }

    /// Record the located events (at the time of the last state).
    pub fn events(&mut self, events: &[Event]) -> Result<()> {
        let t = self.count.saturating_sub(1) * 1_000_000_000;
        for e in events {
            let event = self.json("encoding an event", e)?;
            self.write(4, t, &event)?;
        }
        Ok(())
    }

    /// Number of states recorded.
    pub fn len(&self) -> u64 {
        self.count
    }

    /// No state recorded yet.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Write the summary, close the file and rename it into place. After a
    /// failed write the temporary file is removed instead and the first
    /// failure returned.
    pub fn finish(mut self) -> Result<()> {
        if let Some(first) = self.failed.take() {
            return Err(first);
        }
        let Some(mut w) = self.writer.take() else {
            return Ok(());
        };
        w.finish().map_err(mcap_error("finalising", &self.path))?;
        let out = w
            .into_inner()
            .into_inner()
            .map_err(|e| crate::io::output::file_error("finalising", &self.path, e.into_error()))?;
        out.commit()
    }
}
