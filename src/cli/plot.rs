//! `knotrod plot`: redraw the bifurcation diagram of a summary or recording,
//! or the map of a map file.

use crate::analysis::event::Event;
use crate::io::plot::{PlotPoint, bifurcation_diagram, island_map, island_slices};
use crate::io::summary::Summary;
use crate::study::map::{Map, Map3};
use anyhow::{Context, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Redraw the diagram of `summary` (a `run --json` summary or an `.mcap`
/// recording) to `out` (default: its path without extension).
pub fn plot(summary: &Path, out: Option<PathBuf>) -> Result<()> {
    let stem = out.unwrap_or_else(|| summary.with_extension(""));
    let written = if summary.extension().is_some_and(|e| e == "mcap") {
        let (title, points, events) = from_recording(summary)?;
        bifurcation_diagram(&stem, &title, &points, &events)?
    } else {
        let text = crate::io::read_text(summary, crate::io::DATA_FILE_LIMIT)
            .with_context(|| format!("cannot read {}", summary.display()))?;
        // a map file (`knotrod map`) is drawn as its map
        if let Ok(map) = serde_json::from_str::<Map>(&text) {
            island_map(&stem, &map)?
        } else if let Ok(map) = serde_json::from_str::<Map3>(&text) {
            island_slices(&stem, &map)?
        } else {
            let (title, points, events) = from_summary(summary, &text)?;
            bifurcation_diagram(&stem, &title, &points, &events)?
        }
    };
    for f in written {
        writeln!(std::io::stdout().lock(), "plot written to {}", f.display())?;
    }
    Ok(())
}

/// Draw several map files' islands on one plane (see
/// [`crate::io::plot::island_overlay`]) to `out` (default: the first
/// file's path without extension).
pub fn overlay(
    files: &[PathBuf],
    out: Option<PathBuf>,
    names: &[String],
    mark: Option<&str>,
    title: Option<&str>,
) -> Result<()> {
    anyhow::ensure!(
        names.is_empty() || names.len() == files.len(),
        "--name: {} names for {} maps",
        names.len(),
        files.len()
    );
    let maps = files
        .iter()
        .map(|f| {
            let text = crate::io::read_text(f, crate::io::DATA_FILE_LIMIT)
                .with_context(|| format!("cannot read {}", f.display()))?;
            serde_json::from_str::<Map>(&text).with_context(|| {
                format!(
                    "{}: several files, or one with --name, --mark or --title, are drawn only as map files (`map --json`)",
                    f.display()
                )
            })
        })
        .collect::<Result<Vec<Map>>>()?;
    let named: Vec<(&str, &Map)> = maps
        .iter()
        .enumerate()
        .map(|(k, m)| (names.get(k).map_or(m.scene.as_str(), |n| n.as_str()), m))
        .collect();
    let mark = match mark {
        Some(m) => {
            let parse = || -> Option<(&str, [f64; 2])> {
                let (name, at) = m.split_once('=')?;
                let (a, b) = at.split_once(',')?;
                let at: [f64; 2] = [a.trim().parse().ok()?, b.trim().parse().ok()?];
                at.iter().all(|v| v.is_finite()).then_some((name, at))
            };
            Some(parse().with_context(|| {
                format!("--mark {m:?}: expected NAME=SWEPT,ALONG (finite numbers)")
            })?)
        }
        None => None,
    };
    let stem = out.unwrap_or_else(|| files[0].with_extension(""));
    let title = title.unwrap_or("good knots");
    for f in crate::io::plot::island_overlay(&stem, title, &named, mark)? {
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

/// Title, points and events of a JSON summary (`text`, read from `path`).
fn from_summary(path: &Path, text: &str) -> Result<(String, Vec<PlotPoint>, Vec<Event>)> {
    let s: Summary = serde_json::from_str(text).with_context(|| {
        format!(
            "{} is neither a knotrod summary nor a map file",
            path.display()
        )
    })?;
    let points = s.equilibria.iter().map(PlotPoint::from).collect();
    Ok((
        format!("{} (N = {})", s.scene, s.segments),
        points,
        s.events,
    ))
}
