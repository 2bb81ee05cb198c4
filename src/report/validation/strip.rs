//! The elastic strip's Figure 8: branches in φ at several z*, at two N.

use super::runs::{run_text, scene_text};
use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::{Event, EventKind};
use crate::report::error::{Context, Result};
use crate::scene::Scene;
use crate::study::map::branch_intervals;
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
        "`scenes/fig8_strip.toml`: Sadowsky law with u2 = 0 enforced (SQP, each QP solved on the KKT system), started from the double ring unfolded into the knotted wedge, continued on the KKT system. Paper: a stable walled knotted strip with no self-contact at z* = 0.215, φ/2π ≈ 0.94; no pitchfork, branches down to φ/2π < 0.5.\n"
    )?;
    s += &strip_table(scenes)?;
    writeln!(
        s,
        "\nAt z* ≥ 0.17 the good set of one branch splits in two: the strands pass through each other twice inside the walled range (two crossings X between which the centreline is unknotted). The split is present at N = 100 and N = 200 alike; the island map below shows it as a notch from the top of the island."
    )?;
    Ok(s)
}

/// Per N and z*: the φ range, good intervals bounded by their events, the
/// island map's intervals at the same z* (N = 100), stability, largest |u2|
/// and the number of folds and branch points; then how many interval ends
/// are events and how far the two computations of an interval differ.
fn strip_table(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "| N | z* | φ/2π range | good intervals of φ/2π (bounding events) | island map at this z* (N = 100) | stable everywhere | largest \\|u2\\| | events fold/branch point |\n|---|---|---|---|---|---|---|---|"
    )?;
    let island = Scene::load(&scenes.join("fig7_island_strip.toml"))?;
    let spec = island
        .map
        .clone()
        .context("fig7_island_strip.toml has no [map]")?;
    let (mut ends, mut unbounded, mut largest_gap, mut compared) = (0, 0, 0.0f64, 0);
    for n in [100, 200] {
        let (eqs, events) = run_text(&scene_text(scenes, "fig8_strip.toml", Some(n))?)?;
        let folds = events
            .iter()
            .filter(|e| e.kind == EventKind::Fold || e.kind == EventKind::BranchPoint)
            .count();
        for z in [0.115, 0.150, 0.180, 0.200, 0.215] {
            let at_z = |z_star: f64| (z_star - z).abs() < 1e-9;
            let here: Vec<Equilibrium> = eqs.iter().filter(|e| at_z(e.z_star)).cloned().collect();
            let here_events: Vec<Event> =
                events.iter().filter(|e| at_z(e.z_star)).cloned().collect();
            let intervals = branch_intervals(&here, &here_events);
            for iv in &intervals {
                for label in [&iv.lo_label, &iv.hi_label] {
                    ends += 1;
                    unbounded += usize::from(label == "?" || label == "range");
                }
            }
            // the island map's line at this z*, where the grid has one
            let map_line = (0..spec.lines)
                .find(|&k| (spec.value(k) - z).abs() < 1e-9)
                .filter(|_| n == island.model.segments as usize)
                .map(|k| crate::study::map::line(&island, &spec, k, None));
            let map_cell = match &map_line {
                None => "—".to_string(),
                Some(l) if l.error.is_some() => {
                    format!("failed: {}", l.error.as_deref().unwrap_or(""))
                }
                Some(l) => {
                    if l.intervals.len() == intervals.len() {
                        compared += 1;
                        for (a, b) in l.intervals.iter().zip(&intervals) {
                            largest_gap = largest_gap
                                .max((a.lo - b.lo).abs())
                                .max((a.hi - b.hi).abs());
                        }
                    } else {
                        largest_gap = f64::INFINITY;
                    }
                    cells(&l.intervals)
                }
            };
            let u2 = here.iter().filter_map(|p| p.max_u2).fold(0.0, f64::max);
            let (lo, hi) = here
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(p.phi_over_2pi), hi.max(p.phi_over_2pi))
                });
            writeln!(
                s,
                "| {n} | {z:.3} | [{lo:.3}, {hi:.3}] | {} | {map_cell} | {} | {u2:.1e} | {folds} |",
                cells(&intervals),
                here.iter().all(|p| p.stable)
            )?;
        }
    }
    writeln!(
        s,
        "\nGood = {}. Of the {ends} interval ends, {} are events of the same branch (W1/W2 walls, X crossings, S stability) and {unbounded} are not. Where the island map has a line at the same z* ({compared} lines, N = 100), its intervals differ from the branches' by at most {largest_gap:.1e} in φ/2π.",
        island.good_knot().describe(),
        ends - unbounded
    )?;
    Ok(s)
}

/// Intervals as one table cell.
fn cells(intervals: &[crate::study::map::Interval]) -> String {
    if intervals.is_empty() {
        return "none".into();
    }
    intervals
        .iter()
        .map(|i| i.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}
