//! Scenes run from their TOML text, for tables that vary a scene file.

use crate::report::error::Result;
use crate::scene::Scene;
use std::path::Path;

/// Runs a scene given as TOML text and returns its equilibria and events.
pub(super) fn run_text(
    text: &str,
) -> Result<(
    Vec<crate::analysis::equilibrium::Equilibrium>,
    Vec<crate::analysis::event::Event>,
)> {
    let scene = Scene::parse(text)?;
    let mut eqs = Vec::new();
    let events = crate::study::run::run_scene(
        &scene,
        None,
        &mut crate::study::observer::equilibria(|e| {
            eqs.push(e);
            Ok(())
        }),
    )?;
    Ok((eqs, events))
}

/// A scene file's text without its `[output]` table, with `segments = N`
/// replaced when `segments` is given.
pub(super) fn scene_text(scenes: &Path, file: &str, segments: Option<usize>) -> Result<String> {
    let text = std::fs::read_to_string(scenes.join(file))?;
    let text = text
        .split("[output]")
        .next()
        .unwrap_or_default()
        .to_string();
    Ok(match segments {
        Some(n) => text
            .lines()
            .map(|l| {
                if l.starts_with("segments = ") {
                    format!("segments = {n}")
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n"),
        None => text,
    })
}
