//! Fuzz targets: each takes arbitrary bytes and must return, never panic,
//! abort or hang, whatever they hold. The cargo-fuzz targets in `fuzz/` and
//! the seeded run in `tests/fuzz.rs` call these same functions.

use crate::geometry::knot::knot_type;
use crate::geometry::polyline::parse_points;
use crate::io::recording::{parse_recording, parse_state};
use crate::scene::{Job, Scene, SceneError};
use nalgebra::Vector3;
use std::path::Path;

/// Most points handed to the knot code from one input (keeps a run fast;
/// the knot code itself has its own limits).
const MOST_POINTS: usize = 2000;

/// A scene's text: parsed and validated, and its budget estimated. The
/// messages of its refusals read as prose ([`one_spaced`]).
pub fn scene_text(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match Scene::parse(text) {
        Ok(scene) => {
            for job in [Job::Run, Job::Map] {
                let e = scene.estimate(job, None);
                assert!(e.memory_bytes >= 0.0 && e.seconds >= 0.0, "estimate {e:?}");
                if let Err(e) = scene.check_budget(job, None, false) {
                    one_spaced(&e.to_string());
                }
            }
            let _ = scene.file_stem("fuzz");
        }
        // the parser's errors quote the input, which may hold any spacing
        Err(e @ SceneError::Invalid { .. }) => one_spaced(&e.to_string()),
        Err(_) => {}
    }
}

/// No run of two or more spaces inside a line of an error message: the
/// indentation of a string literal broken over lines without its `\`.
pub fn one_spaced(message: &str) {
    assert!(
        !message.lines().any(|l| l.trim().contains("  ")),
        "a run of spaces in the message {message:?}"
    );
}

/// A curve file's text: parsed, and its knot type found (closed).
pub fn curve_text(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(points) = parse_points(text)
        && points.len() <= MOST_POINTS
    {
        check_knot(&points);
    }
}

/// Points from raw bytes (three i16 per point, in units of 1/1000): many
/// crossings, coincident points and collinear runs.
pub fn knot_points(data: &[u8]) {
    check_knot(&points_of(data));
}

/// The points `knot_points` reads from bytes (at most 2000).
pub fn points_of(data: &[u8]) -> Vec<Vector3<f64>> {
    data.chunks_exact(6)
        .take(MOST_POINTS)
        .map(|c| {
            let v = |k: usize| i16::from_le_bytes([c[k], c[k + 1]]) as f64 / 1000.0;
            Vector3::new(v(0), v(2), v(4))
        })
        .collect()
}

/// The knot type of a closed curve, when one is found, is a knot's: its
/// determinant |Δ(−1)| is odd.
fn check_knot(points: &[Vector3<f64>]) {
    if let Ok(k) = knot_type(points) {
        assert!(
            k.determinant % 2 == 1,
            "determinant {} of {:?}",
            k.determinant,
            k.alexander
        );
    }
}

/// A recording's bytes: read whole, and its first state.
pub fn recording_bytes(data: &[u8]) {
    let path = Path::new("<fuzz>");
    let _ = parse_recording(path, data);
    let _ = parse_state(path, data, 0);
}
