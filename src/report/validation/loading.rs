//! Quasi-static loading: the snap of a buckled strip-like rod, for two step
//! sequences.

use super::runs::{run_text, scene_text};
use crate::analysis::event::EventKind;
use crate::report::error::Result;
use std::fmt::Write;
use std::path::Path;

/// The section "Quasi-static loading".
pub(super) fn section(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\n## Quasi-static loading: a buckled strip-like rod twisted until it snaps\n"
    )?;
    writeln!(
        s,
        "`scenes/loading_twist_snap.toml` (K2 = 20, K3 = 1.5, z* = 0.8, N = 100): the clamp turned to 1.2 turns and back to 0.5. Jumps are located by bisecting the step to 1e-4 turns, so they do not depend on the step sequence.\n"
    )?;
    s += &loading_table(scenes)?;
    Ok(s)
}

/// The jumps up and down for two step sequences.
fn loading_table(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "| steps up / down | jump up at φ/2π | jump down at φ/2π |\n|---|---|---|"
    )?;
    for (up, down) in [(60, 35), (97, 53)] {
        let text = scene_text(scenes, "loading_twist_snap.toml", None)?
            .replace("steps = 60", &format!("steps = {up}"))
            .replace("steps = 35", &format!("steps = {down}"));
        let (_, events) = run_text(&text)?;
        let jumps: Vec<f64> = events
            .iter()
            .filter(|e| e.kind == EventKind::Jump)
            .map(|e| e.phi_over_2pi)
            .collect();
        writeln!(
            s,
            "| {up} / {down} | {} | {} |",
            jumps.first().map_or("—".into(), |v| format!("{v:.5}")),
            jumps.get(1).map_or("—".into(), |v| format!("{v:.5}"))
        )?;
    }
    Ok(s)
}
