//! Scenes run from their TOML text, for tables that vary a scene file.

use crate::report::error::Result;
use crate::scene::Scene;
use std::path::Path;

/// A scene's equilibria and events.
pub(super) type Run = (
    Vec<crate::analysis::equilibrium::Equilibrium>,
    Vec<crate::analysis::event::Event>,
);

/// Runs a scene given as TOML text and returns its equilibria and events.
pub(super) fn run_text(text: &str) -> Result<Run> {
    run_collected(&Scene::parse(text)?)
}

/// Runs a scene and returns its equilibria and events.
pub(super) fn run_collected(scene: &Scene) -> Result<Run> {
    let mut eqs = Vec::new();
    let events = crate::study::run::run_scene(
        scene,
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
