//! Shared test helpers: the built binary, temporary directories, scenes at
//! another N, runs collected, and a deterministic random sequence.
//!
//! One module of the test binary (tests/suite.rs); each area uses some of these.
#![allow(dead_code)]

use knotrod::analysis::equilibrium::Equilibrium;
use knotrod::analysis::event::Event;
use knotrod::scene::Scene;
use std::path::PathBuf;
use std::process::{Command, Output};

/// Run the built `knotrod` binary with `args`.
pub fn knotrod(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_knotrod"))
        .args(args)
        .output()
        .unwrap()
}

/// Run knotrod and require success.
pub fn knotrod_ok(args: &[&str]) {
    let out = knotrod(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Run `knotrod map scene --json json` and read the map back.
pub fn map_json<T: serde::de::DeserializeOwned>(
    scene: &std::path::Path,
    json: &std::path::Path,
) -> T {
    knotrod_ok(&[
        "map",
        scene.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    serde_json::from_slice(&std::fs::read(json).unwrap()).unwrap()
}

/// A fresh directory `knotrod-{name}-{pid}` under the system's temporary
/// directory (created).
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("knotrod-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A paper scene file's text at another N (its `segments = 200` replaced),
/// without its `[output]` table.
pub fn scene_text_at(file: &str, segments: usize) -> String {
    let text = std::fs::read_to_string(file).unwrap();
    let text = text.replace("segments = 200", &format!("segments = {segments}"));
    text.split("[output]").next().unwrap().to_string()
}

/// A paper scene file parsed at another N, without its `[output]` table.
pub fn scene_at(file: &str, segments: usize) -> Scene {
    Scene::parse(&scene_text_at(file, segments)).unwrap()
}

/// Run a scene; its equilibria and events.
pub fn run(scene: &Scene) -> (Vec<Equilibrium>, Vec<Event>) {
    let mut eqs = Vec::new();
    let events = knotrod::study::run::run_scene(
        scene,
        None,
        &mut knotrod::study::observer::equilibria(|e| {
            eqs.push(e);
            Ok(())
        }),
    )
    .unwrap();
    (eqs, events)
}

/// A deterministic pseudo-random sequence in [-1, 1) (no extra dependency).
pub struct Lcg(pub u64);

impl Lcg {
    /// Next value.
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}
