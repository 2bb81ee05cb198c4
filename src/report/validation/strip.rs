//! The elastic strip's Figure 8: branches in φ at several z*, at two N.

use super::runs::{run_text, scene_text};
use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::EventKind;
use crate::report::error::Result;
use std::fmt::Write;
use std::path::Path;

/// The section "Elastic strip: Figure 8".
pub(super) fn section(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\n## Elastic strip: Figure 8 (branches in φ, δ = 0.05)\n"
    )?;
    writeln!(
        s,
        "`scenes/fig8_strip.toml`: Sadowsky law with u2 = 0 enforced (SQP, clarabel QPs polished on the KKT system), started from the double ring unfolded into the knotted wedge, continued on the KKT system. Good = walled, trefoil, stable, self-distance > h. Paper: a stable walled knotted strip with no self-contact at z* = 0.215, φ/2π ≈ 0.94; no pitchfork, branches down to φ/2π < 0.5.\n"
    )?;
    s += &strip_table(scenes)?;
    writeln!(
        s,
        "\nAt z* ≥ 0.17 the good set of one branch splits in two: the strands pass through each other twice inside the walled range (two crossings X between which the centreline is unknotted). The split is present at N = 100 and N = 200 alike; the island map below shows it as a notch from the top of the island."
    )?;
    Ok(s)
}

/// Per N and z*: the φ range, good intervals, stability, largest |u2| and
/// the number of folds and branch points.
fn strip_table(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "| N | z* | φ/2π range | good intervals of φ/2π | stable everywhere | largest \\|u2\\| | events fold/branch point |\n|---|---|---|---|---|---|---|"
    )?;
    for n in [100, 200] {
        let (eqs, events) = run_text(&scene_text(scenes, "fig8_strip.toml", Some(n))?)?;
        let folds = events
            .iter()
            .filter(|e| e.kind == EventKind::Fold || e.kind == EventKind::BranchPoint)
            .count();
        for z in [0.115, 0.150, 0.180, 0.200, 0.215] {
            let mut pts: Vec<&Equilibrium> =
                eqs.iter().filter(|e| (e.z_star - z).abs() < 1e-9).collect();
            pts.sort_by(|a, b| a.phi_over_2pi.total_cmp(&b.phi_over_2pi));
            let intervals = good_intervals(&pts);
            let u2 = pts.iter().filter_map(|p| p.max_u2).fold(0.0, f64::max);
            writeln!(
                s,
                "| {n} | {z:.3} | [{:.3}, {:.3}] | {} | {} | {u2:.1e} | {folds} |",
                pts.first().map_or(f64::NAN, |p| p.phi_over_2pi),
                pts.last().map_or(f64::NAN, |p| p.phi_over_2pi),
                intervals.join(" "),
                pts.iter().all(|p| p.stable)
            )?;
        }
    }
    Ok(s)
}

/// The runs of good knots along points sorted by φ, as "[lo, hi]" cells.
fn good_intervals(pts: &[&Equilibrium]) -> Vec<String> {
    let mut intervals = Vec::new();
    let mut start: Option<f64> = None;
    let mut last = f64::NAN;
    for p in pts {
        match (p.good_knot, start) {
            (true, None) => start = Some(p.phi_over_2pi),
            (false, Some(a)) => {
                intervals.push(format!("[{a:.3}, {last:.3}]"));
                start = None;
            }
            _ => {}
        }
        last = p.phi_over_2pi;
    }
    if let Some(a) = start {
        intervals.push(format!("[{a:.3}, {last:.3}]"));
    }
    intervals
}
