//! Recordings: every equilibrium of a run written to MCAP as it is computed,
//! with Foxglove's well-known schemas (protobuf `foxglove.SceneUpdate` and
//! `foxglove.FrameTransform`) for the 3D panel, a JSON channel of scalars for
//! plots, the full state for exact restarts, the events, and metadata. And the
//! way back: reading states, scalars and events from a recording.
//!
//! [`messages`] holds the topics and the JSON messages; [`writer`] the
//! [`Recorder`], [`reader`] the way back, [`foxglove`] the 3D scene.

pub mod foxglove;
pub mod messages;
pub mod reader;
pub mod writer;

pub use foxglove::scene_update;
pub use messages::{
    EVENTS_TOPIC, SCALARS_TOPIC, SCENE_TOPIC, STATE_TOPIC, Scalars, StateMessage, TF_TOPIC,
};
pub use reader::{Recording, each_state, parse_recording, parse_state, read_recording, read_state};
pub use writer::Recorder;
