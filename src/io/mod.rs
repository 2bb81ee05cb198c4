//! Files: scene files, restart states, MCAP recordings (writer, reader,
//! Foxglove geometry), JSON summaries and map files, plots, exports, and
//! AUTO-07p's output for verify.

pub mod auto;
pub mod build_info;
pub mod convergence_plot;
pub mod curve_file;
pub mod error;
pub mod export;
pub mod fuzz;
pub mod json;
pub mod live;
pub mod map_files;
pub mod output;
pub mod plot;
pub mod recording;
pub mod render;
pub mod scene_file;
pub mod source_hash;
pub mod summary;
pub mod verify_file;
pub mod vtk;

pub use error::IoError;

/// Largest data file read whole (curves, summaries, restarts, recordings, maps).
pub const DATA_FILE_LIMIT: u64 = 1_000_000_000;
/// Largest scene file.
pub const SCENE_FILE_LIMIT: u64 = 16_000_000;

/// The bytes of `path`, refused past `limit` bytes before they are held: the
/// file's size is checked first, and the read itself stops past the limit (a
/// pipe or device has no size to check).
pub fn read_limited(path: &std::path::Path, limit: u64) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let file = std::fs::File::open(path)?;
    let too_big = |size: String| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("the file holds {size} bytes; the most read is {limit}"),
        )
    };
    let len = file.metadata()?.len();
    if len > limit {
        return Err(too_big(len.to_string()));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_big(format!("more than {limit}")));
    }
    Ok(bytes)
}

/// The text of `path` (UTF-8, a leading byte-order mark dropped, as
/// spreadsheets and editors on other systems write one), refused past `limit`
/// bytes (`read_limited`).
pub fn read_text(path: &std::path::Path, limit: u64) -> std::io::Result<String> {
    let mut bytes = read_limited(path, limit)?;
    if bytes.starts_with(UTF8_BOM) {
        bytes.drain(..UTF8_BOM.len());
    }
    String::from_utf8(bytes)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e.utf8_error()))
}

/// UTF-8's byte-order mark.
const UTF8_BOM: &[u8] = "\u{feff}".as_bytes();
