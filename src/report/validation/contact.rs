//! Contact: the trefoil on the rays, from configuration A through B to C.

use super::runs::{run_text, scene_text};
use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::Event;
use crate::analysis::event::EventKind;
use crate::report::error::{Context, Result};
use std::fmt::Write;
use std::path::Path;

/// The section "Contact: the trefoil on the rays".
pub(super) fn section(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\n## Contact: the trefoil on the rays, A → B → C (Figures 3-5)\n"
    )?;
    s += &contact_table(scenes)?;
    Ok(s)
}

/// Configuration A and the events along the branch, against the paper.
fn contact_table(scenes: &Path) -> Result<String> {
    let (eqs, events) = run_text(&scene_text(scenes, "trefoil_contact_start.toml", None)?)?;
    let mut s = String::new();
    let a = eqs
        .iter()
        .find(|e| e.phi_over_2pi.abs() < 1e-12)
        .context("configuration A")?;
    writeln!(
        s,
        "Command: `cargo run --release -- run scenes/trefoil_contact_start.toml` (N = 100, h = 0.005).\n"
    )?;
    writeln!(s, "| quantity | knotrod | paper |\n|---|---|---|")?;
    s += &configuration_a_rows(a)?;
    s += &event_rows(&events, &eqs)?;
    Ok(s)
}

/// Configuration A's contacts, twist, link and self-distance.
fn configuration_a_rows(a: &Equilibrium) -> Result<String> {
    let mut s = String::new();
    let cs: Vec<String> = a
        .contacts
        .iter()
        .map(|c| format!("{} at s = {:.3} (force {:.1})", c.obstacle, c.s, c.force))
        .collect();
    writeln!(
        s,
        "| A: contacts | {} | two, with the rays, s ≈ 0.17, 0.83 |",
        cs.join("; ")
    )?;
    writeln!(s, "| A: Tw | {:.4} | −0.07 |", a.twist)?;
    writeln!(s, "| A: link | {:.4} | 3.0 |", a.link)?;
    writeln!(
        s,
        "| A: min self-distance | {:.4} (h = 0.005) | > h |",
        a.min_self_distance
    )?;
    Ok(s)
}

/// Where contacts are lost, jumps and walls occur, up and back down (and
/// where the strands first touch each other on the way up, from `eqs`).
fn event_rows(events: &[Event], eqs: &[Equilibrium]) -> Result<String> {
    let mut s = String::new();
    let find_with = |kind: EventKind, leg: usize, detail: &str| {
        events
            .iter()
            .filter(|e| e.kind == kind && e.branch == leg && e.detail.contains(detail))
            .map(|e| format!("{:.5}", e.phi_over_2pi))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let find = |kind: EventKind, leg: usize| {
        events
            .iter()
            .filter(|e| e.kind == kind && e.branch == leg)
            .map(|e| format!("{:.5}", e.phi_over_2pi))
            .collect::<Vec<_>>()
            .join(", ")
    };
    writeln!(
        s,
        "| B: ray contact force reaches zero (up) | φ/2π = {} | 0.768 |",
        find_with(EventKind::ContactLost, 0, "ray")
    )?;
    let or_none = |found: String| {
        if found.is_empty() {
            "none".to_string()
        } else {
            found
        }
    };
    // the loading path's equilibria are 0.01 apart in φ/2π; a contact's
    // start is not located as an event
    // past B (before it the knot presses on itself around the rays)
    let b = events
        .iter()
        .find(|e| e.kind == EventKind::ContactLost && e.branch == 0 && e.detail.contains("ray"))
        .map_or(f64::INFINITY, |e| e.phi_over_2pi);
    let first_touch = eqs
        .iter()
        .filter(|e| e.branch == 0 && e.phi_over_2pi > b)
        .find(|e| e.contacts.iter().any(|c| c.obstacle == "self"))
        .map(|e| format!("{:.2}", e.phi_over_2pi))
        .unwrap_or_default();
    writeln!(
        s,
        "| self-contact near X (the strands touch instead of crossing): first equilibrium touching on the way up past B; lost on the way down | φ/2π = {}; {} | — (no contact in the paper's X) |",
        or_none(first_touch),
        or_none(find_with(EventKind::ContactLost, 1, "self"))
    )?;
    writeln!(
        s,
        "| jumps on the way up | φ/2π = {} | at B |",
        find(EventKind::Jump, 0)
    )?;
    writeln!(
        s,
        "| C: walls on the way up (W1, W2) | φ/2π = {} | 0.774, 0.82 |",
        find(EventKind::Wall, 0)
    )?;
    writeln!(
        s,
        "| back down: jumps | φ/2π = {} | at S (no return to B) |",
        find(EventKind::Jump, 1)
    )?;
    Ok(s)
}
