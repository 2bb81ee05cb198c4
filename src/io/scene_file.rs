//! Scene files: the TOML read and validated, relative paths resolved against
//! the scene's folder, and the restart state of `[initial]` read from its
//! summary or recording.

use crate::io::recording::read_state;
use crate::model::rod::RodState;
use crate::scene::{InitialShape, Scene, SceneError};
use crate::study::error::describe;
use std::path::Path;

impl Scene {
    /// Read and validate a scene file, with its restart state if it has one.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = crate::io::read_text(path, crate::io::SCENE_FILE_LIMIT).map_err(|source| {
            SceneError::Io {
                path: path.into(),
                source,
            }
        })?;
        let mut scene = Scene::parse(&text).map_err(|e| match e {
            SceneError::Parse { message, .. } => SceneError::Parse {
                path: path.into(),
                message,
            },
            other => other,
        })?;
        if scene.name.is_none() {
            scene.name = path.file_stem().map(|s| s.to_string_lossy().into_owned());
        }
        // relative initial files are relative to the scene's folder
        if let Some(f) = &scene.initial.file
            && f.is_relative()
            && !f.exists()
            && let Some(dir) = path.parent()
        {
            scene.initial.file = Some(dir.join(f));
        }
        scene.initial.state = restart_state(&scene)?;
        Ok(scene)
    }
}

fn invalid(field: &'static str, reason: String) -> SceneError {
    SceneError::Invalid { field, reason }
}

/// The state `[initial]` restarts from: a recorded state, or an equilibrium
/// of a previous run's JSON summary.
fn restart_state(scene: &Scene) -> Result<Option<RodState>, SceneError> {
    let init = &scene.initial;
    if let Some(path) = &init.from_recording {
        let msg = read_state(path, init.index as u64)
            .map_err(|e| invalid("initial.from_recording", describe(&e)))?;
        return Ok(Some(msg.state));
    }
    if init.shape != InitialShape::File {
        return Ok(None);
    }
    let Some(path) = &init.file else {
        return Err(invalid("initial.file", "missing".into()));
    };
    let text = crate::io::read_text(path, crate::io::DATA_FILE_LIMIT).map_err(|e| {
        invalid(
            "initial.file",
            format!("cannot read {}: {e}", path.display()),
        )
    })?;
    let summary: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        invalid(
            "initial.file",
            format!("{} is not JSON: {e}", path.display()),
        )
    })?;
    let entry = summary
        .get("equilibria")
        .and_then(|e| e.get(init.index))
        .and_then(|e| e.get("state"))
        .ok_or_else(|| {
            invalid(
                "initial.index",
                format!("{} has no equilibria[{}].state", path.display(), init.index),
            )
        })?;
    let state: RodState = serde_json::from_value(entry.clone()).map_err(|e| {
        invalid(
            "initial.file",
            format!("malformed state in {}: {e}", path.display()),
        )
    })?;
    Ok(Some(state))
}
