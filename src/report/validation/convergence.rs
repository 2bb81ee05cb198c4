//! Convergence in N against the refined shooting solution, and the error of
//! a finite stretching stiffness.

use super::format::{error_cells, norm3};
use crate::analysis::equilibrium::Equilibrium;
use crate::model::rod::RodModel;
use crate::model::shooting::ShootingSolution;
use crate::report::error::{Context, Result};
use crate::scene::{InitialShape, Scene};
use crate::solve::continuum::shooting::refine_shooting;
use crate::study::start::solve_scene;
use nalgebra::Vector3;
use std::fmt::Write;

/// The sections "Convergence in N, Appendix D" and "Near-inextensibility".
pub(super) fn sections(d: &Scene) -> Result<String> {
    let mut s = String::new();
    writeln!(s, "\n## Convergence in N, Appendix D\n")?;
    writeln!(
        s,
        "Command: `cargo run --release -- convergence scenes/appendix_d.toml --segments 50,100,200,400,800`.\n"
    )?;
    s += &convergence_table(d, &[50, 100, 200, 400, 800])?;
    writeln!(
        s,
        "\n## Near-inextensibility: the stretching penalty's error, Appendix D\n"
    )?;
    writeln!(
        s,
        "Richardson extrapolation of N = 400 and 800 removes the O(1/N²) error; what remains is the model error of a finite stretching stiffness, measured against the refined shooting solution of the inextensible rod.\n"
    )?;
    s += &stiffness_table(d)?;
    Ok(s)
}

/// The continuum solution for a shooting scene: its data refined on the s = 1
/// boundary conditions, as (n(0), m(0), Tw).
pub fn continuum_reference(scene: &Scene) -> Option<([f64; 3], [f64; 3], f64)> {
    if scene.initial.shape != InitialShape::Shooting {
        return None;
    }
    let model = scene.rod_model(None);
    let (n0, m0) = (scene.initial.n0?, scene.initial.m0?);
    let (n0, m0) = refine_shooting(
        Vector3::from(n0),
        Vector3::from(m0),
        model.k2,
        model.k3,
        &scene.clamps(),
    )?;
    let tw = ShootingSolution::integrate(n0, m0, model.k2, model.k3, 1)
        .ok()?
        .twist();
    Some((n0.into(), m0.into(), tw))
}

/// Convergence in N of a scene's equilibrium, as markdown tables.
pub fn convergence_table(scene: &Scene, segments: &[usize]) -> Result<String> {
    let model = scene.rod_model(None);
    let mut rows: Vec<(usize, Equilibrium)> = Vec::new();
    for &n in segments {
        let eq = solve_scene(scene, Some(n)).with_context(|| format!("N = {n}"))?;
        rows.push((n, eq));
    }
    let mut s = equilibria_rows(scene, &model, &rows)?;
    if let Some(reference) = continuum_reference(scene) {
        s += &reference_rows(&rows, reference)?;
    }
    s += &self_convergence(&rows)?;
    Ok(s)
}

/// The scene's line and the table of each N's equilibrium.
fn equilibria_rows(
    scene: &Scene,
    model: &RodModel,
    rows: &[(usize, Equilibrium)],
) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "Scene `{}` (K2 = {}, K3 = {}, stretching stiffness {:.3e}).\n",
        scene.name.as_deref().unwrap_or(""),
        model.k2,
        model.k3,
        model.stretching_stiffness
    )?;
    writeln!(
        s,
        "| N | n1(0) | n2(0) | n3(0) | m1(0) | m2(0) | m3(0) | Tw | E | lowest ω² | Newton its | time (s) |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|")?;
    for (n, e) in rows {
        writeln!(
            s,
            "| {n} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.6} | {:.6} | {:.4} | {} |",
            e.n0[0],
            e.n0[1],
            e.n0[2],
            e.m0[0],
            e.m0[1],
            e.m0[2],
            e.twist,
            e.energy,
            e.omega_squared.first().copied().unwrap_or(f64::NAN),
            e.iterations,
        )?;
    }
    Ok(s)
}

/// The refined shooting solution's row, and each N's errors against it.
fn reference_rows(
    rows: &[(usize, Equilibrium)],
    (n0, m0, tw): ([f64; 3], [f64; 3], f64),
) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "| shooting (refined) | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.6} | | | |",
        n0[0], n0[1], n0[2], m0[0], m0[1], m0[2], tw
    )?;
    writeln!(
        s,
        "\nErrors against the refined shooting solution, observed order p = log2(e(N/2)/e(N)):\n"
    )?;
    writeln!(
        s,
        "| N | ‖n(0) − n_ref‖ | p | ‖m(0) − m_ref‖ | p | \\|Tw − Tw_ref\\| | p |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|---|")?;
    let errs: Vec<[f64; 3]> = rows
        .iter()
        .map(|(_, e)| [norm3(&e.n0, &n0), norm3(&e.m0, &m0), (e.twist - tw).abs()])
        .collect();
    for (k, (n, _)) in rows.iter().enumerate() {
        let prev = k.checked_sub(1).map(|j| errs[j].as_slice());
        writeln!(s, "| {n} {}", error_cells(prev, &errs[k]))?;
    }
    Ok(s)
}

/// Differences between successive N and their observed orders.
fn self_convergence(rows: &[(usize, Equilibrium)]) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\nSelf-convergence: differences between successive N, order p = log2(d(N/2→N)/d(N→2N)):\n"
    )?;
    writeln!(
        s,
        "| N → 2N | ‖Δn(0)‖ | p | ‖Δm(0)‖ | p | \\|ΔTw\\| | p | \\|ΔE\\| | p | \\|Δω²₁\\| | p |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|")?;
    let first = |e: &Equilibrium| e.omega_squared.first().copied().unwrap_or(f64::NAN);
    let diffs: Vec<[f64; 5]> = rows
        .windows(2)
        .map(|w| {
            let (a, b) = (&w[0].1, &w[1].1);
            [
                norm3(&a.n0, &b.n0),
                norm3(&a.m0, &b.m0),
                (a.twist - b.twist).abs(),
                (a.energy - b.energy).abs(),
                (first(a) - first(b)).abs(),
            ]
        })
        .collect();
    for (k, d) in diffs.iter().enumerate() {
        let prev = k.checked_sub(1).map(|j| diffs[j].as_slice());
        writeln!(
            s,
            "| {} → {} {}",
            rows[k].0,
            rows[k + 1].0,
            error_cells(prev, d)
        )?;
    }
    Ok(s)
}

/// Appendix D at stretching stiffnesses 1e4 … 1e8, Richardson-extrapolated
/// in N, against the inextensible shooting solution.
fn stiffness_table(scene: &Scene) -> Result<String> {
    let (n_ref, _, tw_ref) =
        continuum_reference(scene).context("stiffness study needs a shooting scene")?;
    let mut s = String::new();
    writeln!(
        s,
        "| S = EA L²/B11 | Tw (Richardson 400/800) | \\|Tw − Tw_ref\\| | ‖n(0) − n_ref‖ (Richardson) | largest \\|strain\\| at N = 800 |"
    )?;
    writeln!(s, "|---|---|---|---|---|")?;
    for stiff in [1e4, 1e5, 6.4e5, 1e7, 1e8] {
        let mut sc = scene.clone();
        sc.model.stretching_stiffness = Some(stiff);
        let a = solve_scene(&sc, Some(400))?;
        let b = solve_scene(&sc, Some(800))?;
        let tw = (4.0 * b.twist - a.twist) / 3.0;
        let n0: [f64; 3] = std::array::from_fn(|k| (4.0 * b.n0[k] - a.n0[k]) / 3.0);
        let h = 1.0 / 800.0;
        let strain = (1..800)
            .map(|j| ((b.state.nodes[j + 1] - b.state.nodes[j]).norm() / h - 1.0).abs())
            .fold(0.0, f64::max);
        writeln!(
            s,
            "| {stiff:.1e} | {tw:.6} | {:.2e} | {:.2e} | {strain:.2e} |",
            (tw - tw_ref).abs(),
            norm3(&n0, &n_ref)
        )?;
    }
    Ok(s)
}
