//! Figure 3: the events along the Appendix D branch, converged in N.

use super::format::order;
use crate::analysis::event::EventKind;
use crate::report::error::Result;
use crate::scene::Scene;
use std::fmt::Write;

/// The section "Figure 3: events along the branch".
pub(super) fn section(d: &Scene) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\n## Figure 3: events along the branch, convergence in N\n"
    )?;
    writeln!(
        s,
        "The flip-symmetric branch at z* = 0.115, δ = 0.05 continued in φ from the Appendix D knot (`scenes/fig3_kirchhoff.toml`); events located by bisection in arclength (walls W1, W2: the rod touches z = 0 or z = z*; X: the centreline crosses itself and the knot determinant drops from 3 to 1; S: pitchfork, one eigenvalue through zero). The paper prints two digits for W2 and X.\n"
    )?;
    s += &figure_3_table(d)?;
    Ok(s)
}

/// Events of the Figure 3 branch (main branch, φ/2π in [0.745, 0.99]) at N.
fn figure_3_events(d: &Scene, n: usize) -> Result<Vec<crate::analysis::event::Event>> {
    let mut scene = d.clone();
    scene.continuation = Some(crate::scene::ContinuationSpec {
        parameter: crate::model::rod::Parameter::Phi,
        range: [0.745, 0.99],
        direction: crate::scene::Direction::Both,
        locate_events: true,
        switch_branches: false,
        step: None,
        max_step: None,
        max_points: None,
        stop_at: Vec::new(),
        polish: false,
    });
    Ok(crate::study::run::run_scene(&scene, Some(n), &mut ())?)
}

/// The walls, crossing and branch point nearest the paper's values at
/// N = 100, 200, 400, with their Richardson value and observed order.
fn figure_3_table(d: &Scene) -> Result<String> {
    let mut s = String::new();
    let targets = [
        ("W1", EventKind::Wall, 0.774, Some(0.774)),
        ("W2", EventKind::Wall, 0.82, Some(0.82)),
        ("X", EventKind::Crossing, 0.96, Some(0.96)),
        ("S", EventKind::BranchPoint, 0.75, None),
    ];
    let ns = [100, 200, 400];
    let mut found: Vec<Vec<f64>> = Vec::new();
    for &n in &ns {
        let events = figure_3_events(d, n)?;
        found.push(
            targets
                .iter()
                .map(|(_, kind, near, _)| {
                    events
                        .iter()
                        .filter(|e| e.kind == *kind && e.branch == 0)
                        .map(|e| e.phi_over_2pi)
                        .min_by(|a, b| (a - near).abs().total_cmp(&(b - near).abs()))
                        .unwrap_or(f64::NAN)
                })
                .collect(),
        );
    }
    writeln!(
        s,
        "| event | paper φ/2π | N = 100 | N = 200 | N = 400 | Richardson (200, 400) | observed order |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|---|")?;
    for (k, (label, _, _, paper)) in targets.iter().enumerate() {
        let (a, b, c) = (found[0][k], found[1][k], found[2][k]);
        let rich = (4.0 * c - b) / 3.0;
        writeln!(
            s,
            "| {label} | {} | {a:.5} | {b:.5} | {c:.5} | {rich:.5} | {} |",
            paper.map_or("(read off Fig. 3 only)".into(), |p| format!("{p}")),
            order((a - b).abs(), (b - c).abs())
        )?;
    }
    Ok(s)
}
