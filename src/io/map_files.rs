//! A map's files: its computed lines and traced boundary kept beside the
//! output (an interrupted map resumes from them), and the partial results of
//! shards and their merge.

use crate::model::rod::Parameter;
use crate::scene::{MapSpec, Scene};
use crate::study::boundary::{Traced, trace_island};
use crate::study::error::{StudyError, describe};
use crate::study::map::{Line, LineStore, Map, assemble};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A map file that could not be used.
#[derive(Debug, thiserror::Error)]
pub enum MapFileError {
    /// A file or folder could not be read or written.
    #[error("{what} {}", path.display())]
    File {
        /// What was being done ("cannot read", "creating", "writing").
        what: &'static str,
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A file that is not what it should be.
    #[error("{} is not {what}", path.display())]
    Format {
        /// What it should be.
        what: &'static str,
        /// The file.
        path: PathBuf,
        /// The parser's message.
        #[source]
        source: serde_json::Error,
    },
    /// A file could not be written (full disk, another writer).
    #[error(transparent)]
    Write(Box<crate::io::IoError>),
    /// Shards do not make a whole map.
    #[error("{0}")]
    Merge(String),
    /// A result that could not be encoded as JSON.
    #[error("encoding JSON: {0}")]
    Encode(#[from] serde_json::Error),
    /// The study behind the file failed.
    #[error(transparent)]
    Study(#[from] StudyError),
}

fn file_error(what: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> MapFileError {
    let path = path.to_path_buf();
    move |source| MapFileError::File { what, path, source }
}

/// Write `bytes` to `file` atomically ([`crate::io::output::Output`]).
fn write_atomically(file: &Path, bytes: &[u8]) -> Result<(), MapFileError> {
    crate::io::output::write_file(file, bytes).map_err(|e| MapFileError::Write(Box::new(e)))
}

/// The lines of a map kept as `line_KKKKK.json` in a folder, each with the
/// key of what made it.
pub struct LineFolder {
    folder: PathBuf,
    key: String,
}

/// A kept line and what it was computed from.
#[derive(Serialize, Deserialize)]
struct KeptLine {
    key: String,
    line: Line,
}

/// The version of the sources that compute a line (see
/// [`crate::io::build_info::SOURCE_HASH`]).
pub const SOURCE_VERSION: &str = crate::io::build_info::SOURCE_HASH;

/// What determines a map's lines and walk: the whole scene after defaults
/// (model, start, solver, continuation, map), the map settings, N and the
/// version of the sources that compute them (`source`).
fn cache_key(
    scene: &Scene,
    spec: &MapSpec,
    segments: Option<usize>,
    source: &str,
) -> Result<String, MapFileError> {
    Ok(serde_json::to_string(&(
        scene,
        spec,
        segments.unwrap_or(scene.model.segments as usize),
        source,
    ))?)
}

impl LineFolder {
    /// The folder (created if need be) for the lines of `spec` over `scene`
    /// at N = `segments` (the scene's own if None): lines kept there for
    /// anything else are recomputed.
    pub fn create(
        folder: &Path,
        scene: &Scene,
        spec: &MapSpec,
        segments: Option<usize>,
    ) -> Result<Self, MapFileError> {
        Self::of_source(folder, scene, spec, segments, SOURCE_VERSION)
    }

    /// `create`, as the sources of version `source` would.
    fn of_source(
        folder: &Path,
        scene: &Scene,
        spec: &MapSpec,
        segments: Option<usize>,
        source: &str,
    ) -> Result<Self, MapFileError> {
        std::fs::create_dir_all(folder).map_err(file_error("creating", folder))?;
        Ok(LineFolder {
            folder: folder.to_path_buf(),
            key: cache_key(scene, spec, segments, source)?,
        })
    }

    fn file(&self, index: usize) -> PathBuf {
        self.folder.join(format!("line_{index:05}.json"))
    }
}

impl LineStore for LineFolder {
    fn get(&self, index: usize, value: f64) -> Option<Line> {
        std::fs::read_to_string(self.file(index))
            .ok()
            .and_then(|t| serde_json::from_str::<KeptLine>(&t).ok())
            .filter(|k| k.key == self.key)
            .map(|k| k.line)
            .filter(|l| l.index == index && l.value == value)
    }

    fn put(&self, line: &Line) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
        let bytes = serde_json::to_vec(&KeptLine {
            key: self.key.clone(),
            line: line.clone(),
        })?;
        match write_atomically(&self.file(line.index), &bytes) {
            // another map of the same cache computes the same line
            Err(MapFileError::Write(e)) if matches!(*e, crate::io::IoError::Refused { .. }) => {
                Ok(())
            }
            r => Ok(r?),
        }
    }
}

/// The traced boundary of a map, read from `cache/trace.json` when an earlier
/// (interrupted) run of the same scene and N wrote it, else traced and
/// written there. A walk that fails is a traced boundary that says why.
pub fn trace_cached(
    scene: &Scene,
    spec: &MapSpec,
    segments: Option<usize>,
    cache: &Path,
    on_point: &dyn Fn(usize, &str),
) -> Result<Traced, MapFileError> {
    #[derive(Serialize, Deserialize)]
    struct Cached {
        key: String,
        traced: Traced,
    }
    std::fs::create_dir_all(cache).map_err(file_error("creating", cache))?;
    let file = cache.join("trace.json");
    let key = cache_key(scene, spec, segments, SOURCE_VERSION)?;
    if let Some(c) = std::fs::read_to_string(&file)
        .ok()
        .and_then(|t| serde_json::from_str::<Cached>(&t).ok())
        && c.key == key
    {
        return Ok(c.traced);
    }
    let traced = trace_island(scene, spec, segments, on_point)
        .unwrap_or_else(|e| Traced::failed(describe(&e)));
    let cached = Cached { key, traced };
    let bytes = serde_json::to_vec(&cached)?;
    write_atomically(&file, &bytes)?;
    Ok(cached.traced)
}

/// A partial result of shard i/n.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Partial {
    /// Scene name.
    pub scene: String,
    /// The map settings.
    pub spec: MapSpec,
    /// The parameter along the lines (the continuation's; partial maps
    /// written before it was kept ran in φ).
    #[serde(default = "phi")]
    pub along: Parameter,
    /// Its range along the lines.
    #[serde(alias = "phi_range")]
    pub range: [f64; 2],
    /// Shard (i, n).
    pub shard: (usize, usize),
    /// Its lines.
    pub lines: Vec<Line>,
    /// The traced boundary (shard 0 computes it).
    #[serde(default)]
    pub traced: Option<Traced>,
}

fn phi() -> Parameter {
    Parameter::Phi
}

/// Merge partial results into a map.
pub fn merge(parts: &[PathBuf]) -> Result<Map, MapFileError> {
    let mut all = Vec::new();
    let mut head: Option<Partial> = None;
    let mut traced = None;
    for p in parts {
        let text = crate::io::read_text(p, crate::io::DATA_FILE_LIMIT)
            .map_err(file_error("cannot read", p))?;
        let part: Partial = serde_json::from_str(&text).map_err(|source| MapFileError::Format {
            what: "a partial map",
            path: p.clone(),
            source,
        })?;
        all.extend(part.lines.clone());
        if part.traced.is_some() {
            traced = part.traced.clone();
        }
        head.get_or_insert(part);
    }
    let h =
        head.ok_or_else(|| MapFileError::Merge("merge needs at least one partial result".into()))?;
    let map = assemble(&h.scene, &h.spec, h.along, h.range, all, traced);
    let missing: Vec<usize> = (0..h.spec.lines)
        .filter(|k| !map.lines.iter().any(|l| l.index == *k))
        .collect();
    if !missing.is_empty() {
        return Err(MapFileError::Merge(format!(
            "merge: lines {missing:?} are missing (a shard was not merged)"
        )));
    }
    Ok(map)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line kept by a build of other sources is recomputed, not resumed,
    /// though the scene, the map settings, N and the package version agree.
    #[test]
    fn lines_of_another_build_are_not_resumed() {
        let scene = Scene::load(Path::new("scenes/fig7_island_kirchhoff.toml")).unwrap();
        let spec = scene.map.clone().unwrap();
        let dir = std::env::temp_dir().join(format!("knotrod-cache-key-{}", std::process::id()));
        let old = LineFolder::of_source(&dir, &scene, &spec, Some(20), "0000000000000000").unwrap();
        let line = Line {
            index: 3,
            value: 0.5,
            points: vec![],
            events: vec![],
            intervals: vec![],
            error: None,
        };
        old.put(&line).unwrap();
        assert!(old.get(3, 0.5).is_some(), "the same build resumes its line");
        let new = LineFolder::create(&dir, &scene, &spec, Some(20)).unwrap();
        assert!(
            new.get(3, 0.5).is_none(),
            "another build's line was resumed"
        );
        assert_eq!(SOURCE_VERSION.len(), 16);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
