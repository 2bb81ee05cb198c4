//! JSON files: pretty JSON and a final newline, written atomically.

use crate::io::error::{IoError, Result};
use crate::io::output::Output;
use serde::Serialize;
use std::path::Path;

/// Write `value` to `path` as pretty JSON followed by a newline, creating the
/// parent folder, atomically and refusing a second writer
/// ([`crate::io::output::Output`]).
pub fn write_pretty<T: Serialize + ?Sized>(path: &Path, value: &T) -> Result<()> {
    write_pretty_to(Output::create(path)?, value)
}

/// `write_pretty` to an output opened (and so reserved) earlier.
pub fn write_pretty_to<T: Serialize + ?Sized>(out: Output, value: &T) -> Result<()> {
    let mut text = serde_json::to_string_pretty(value)
        .map_err(IoError::json("cannot encode as JSON", out.path()))?;
    text.push('\n');
    out.put(text.as_bytes())
}

pub use crate::io::output::create_parent;
