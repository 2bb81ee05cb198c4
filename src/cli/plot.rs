//! `knotrod plot`: redraw the bifurcation diagram of a summary or recording.

use crate::analysis::event::Event;
use crate::io::plot::{PlotPoint, bifurcation_diagram};
use crate::io::summary::Summary;
use anyhow::{Context, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Redraw the diagram of `summary` (a `run --json` summary or an `.mcap`
/// recording) to `out` (default: its path without extension).
pub fn plot(summary: &Path, out: Option<PathBuf>) -> Result<()> {
    let stem = out.unwrap_or_else(|| summary.with_extension(""));
    let (title, points, events) = if summary.extension().is_some_and(|e| e == "mcap") {
        from_recording(summary)?
    } else {
        from_summary(summary)?
    };
    for f in bifurcation_diagram(&stem, &title, &points, &events)? {
        writeln!(std::io::stdout().lock(), "plot written to {}", f.display())?;
    }
    Ok(())
}

/// Title, points and events of a recording.
fn from_recording(path: &Path) -> Result<(String, Vec<PlotPoint>, Vec<Event>)> {
    let rec = crate::io::recording::read_recording(path)?;
    let points: Vec<PlotPoint> = rec.scalars.iter().map(PlotPoint::from).collect();
    let title = path
        .file_stem()
        .unwrap_or_default()
        .to_string_lossy()
        .into_owned();
    Ok((title, points, rec.events))
}

/// Title, points and events of a JSON summary.
fn from_summary(path: &Path) -> Result<(String, Vec<PlotPoint>, Vec<Event>)> {
    let text = crate::io::read_text(path, crate::io::DATA_FILE_LIMIT)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let s: Summary = serde_json::from_str(&text)
        .with_context(|| format!("{} is not a knotrod summary", path.display()))?;
    let points = s.equilibria.iter().map(PlotPoint::from).collect();
    Ok((
        format!("{} (N = {})", s.scene, s.segments),
        points,
        s.events,
    ))
}
