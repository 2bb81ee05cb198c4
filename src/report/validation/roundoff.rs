//! The round-off floor of the convergence test (`solve::outcome::judge`):
//! measured against what Newton reaches when asked for a zero gradient, and
//! against the bound that gates its measurement.

use crate::report::error::Result;
use crate::scene::Scene;
use crate::solve::outcome::FloorCheck;
use crate::study::start::starting_equilibrium;
use std::fmt::Write;

/// The section "Round-off floor".
pub(super) fn section() -> Result<String> {
    let mut s = String::new();
    writeln!(s, "\n## Round-off floor of the convergence test\n")?;
    writeln!(
        s,
        "Every solver stops when its relative gradient is under the tolerance or ‖∇E‖ is under its measured floor: ¼‖∇E(x + δ) − ∇E(x − δ)‖, δ one unit in the last place of every coordinate in a fixed sign pattern (docs/design.md, \"Convergence\"). Here each scene is solved with `gradient_tol = 1e-300`, so Newton runs until ‖∇E‖ is under the floor: the reached gradient against the floor measured there shows that the floor is reached (a correctly rounded equilibrium sits near 0.6 of it) and far below the bound that gates its measurement (16 ε √n (largest stiffness × extent + force scale), the old estimate of the floor). Cantilevers: K2 = K3 = 3, weight 1 along −e1; the rods at rest are straight, unloaded.\n"
    )?;
    writeln!(
        s,
        "| scene | N | stretching stiffness | Newton iterations | ‖∇E‖ reached | relative gradient | measured floor | reached / floor | bound | floor / bound |\n|---|---|---|---|---|---|---|---|---|---|"
    )?;
    let rest = |n: usize| {
        format!(
            "[model]\nsegments = {n}\n[clamps]\nz_star = 1.0\nend = \"free\"\n[initial]\nshape = \"straight\"\n"
        )
    };
    for n in [20, 200, 2000] {
        s += &row("at rest", n, None, &rest(n))?;
    }
    for stiffness in [6.4e5, 1e7, 1e8, 1e9] {
        for n in [100, 400, 1600] {
            let text = format!(
                "[model]\nK2 = 3.0\nK3 = 3.0\nsegments = {n}\nstretching_stiffness = {stiffness:e}\n\
                 [clamps]\nz_star = 1.0\nend = \"free\"\n\
                 [load]\nweight = 1.0\ndirection = [-1.0, 0.0, 0.0]\n"
            );
            s += &row("cantilever", n, Some(stiffness), &text)?;
        }
    }
    Ok(s)
}

/// One row: `text` solved with a tolerance no iterate meets, its floor and bound.
fn row(name: &str, n: usize, stiffness: Option<f64>, text: &str) -> Result<String> {
    let scene = Scene::parse(&format!("{text}[solver]\ngradient_tol = 1e-300\n"))?;
    let stiffness = stiffness.map_or("640000 (default)".to_string(), |s| format!("{s:.1e}"));
    let (newton, state, report) = match starting_equilibrium(&scene, None) {
        Ok(solved) => solved,
        Err(e) => {
            // the whole chain: the step and why it failed
            let mut why = e.to_string();
            let mut source = std::error::Error::source(&e);
            while let Some(s) = source {
                why += &format!(": {s}");
                source = s.source();
            }
            return Ok(format!(
                "| {name} | {n} | {stiffness} | — | not reached: {why} | | | | | |\n"
            ));
        }
    };
    let FloorCheck {
        gradient: gnorm,
        floor,
        bound,
        ..
    } = FloorCheck::at(&newton.energy, &state);
    Ok(format!(
        "| {name} | {n} | {stiffness} | {} | {gnorm:.2e} | {:.2e} | {floor:.2e} | {:.2} | {bound:.2e} | {:.1e} |\n",
        report.iterations,
        report.gradient_norm,
        gnorm / floor,
        floor / bound
    ))
}
