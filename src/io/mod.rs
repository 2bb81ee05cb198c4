//! Files: scene files, restart states, MCAP recordings (writer, reader,
//! Foxglove geometry), JSON summaries and map files, plots, exports.

pub mod curve_file;
pub mod error;
pub mod export;
pub mod json;
pub mod map_files;
pub mod plot;
pub mod recording;
pub mod scene_file;
pub mod summary;

pub use error::IoError;
