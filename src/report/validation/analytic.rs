//! Analytic cases: a straight rod under uniform twist, Euler buckling and
//! torsional (Greenhill) buckling, and with a free end a cantilever under
//! its weight, Greenhill's heavy column and a naturally curved rod at rest,
//! against their continuum values.

use super::format::order;
use crate::model::energy::RodEnergy;
use crate::model::rod::{Clamps, RodModel, RodState};
use crate::report::analytic::{
    cantilever_tip_deflection, euler_buckling_load, free_semicircle, greenhill_constant,
    greenhill_twisting_moment, heavy_column_constant, heavy_column_weight,
};
use crate::report::error::Result;
use crate::solve::minimizer::Minimizer;
use crate::solve::outcome::SolverSettings;
use std::f64::consts::PI;
use std::fmt::Write;

/// The section "Analytic cases".
pub(super) fn section() -> Result<String> {
    let mut s = String::new();
    writeln!(s, "## Analytic cases\n")?;
    s += &twist_table()?;
    s += &euler_table()?;
    s += &greenhill_table()?;
    s += &free_end_tables()?;
    Ok(s)
}

/// A straight rod twisted by φ: Tw and E against φ/2π and K3 φ²/2.
fn twist_table() -> Result<String> {
    let mut s = String::new();
    writeln!(s, "### Straight rod twisted by φ (K2 = 1, z* = 1)\n")?;
    writeln!(s, "| N | φ/2π | K3 | Tw − φ/2π | E − K3 φ²/2 |")?;
    writeln!(s, "|---|---|---|---|---|")?;
    for (n, f, k3) in [(20, 0.3, 3.0), (50, 1.3, 1.0), (200, -0.75, 1.5)] {
        let model = RodModel {
            weight: [0.0; 3],
            natural_strains: Default::default(),
            segments: n,
            k2: 1.0,
            k3,
            stretching_stiffness: 640_000.0,
            law: Default::default(),
        };
        let mut newton = Minimizer::new(RodEnergy::new(model));
        let mut st = RodState::straight(n, Clamps::new(1.0, 0.0, f));
        newton.minimize(&mut st, &SolverSettings::default())?;
        let phi = 2.0 * PI * f;
        writeln!(
            s,
            "| {n} | {f} | {k3} | {:.1e} | {:.1e} |",
            st.twist() - f,
            newton.energy.energy(&st) - k3 * phi * phi / 2.0
        )?;
    }
    Ok(s)
}

/// The Euler buckling load at two stretching stiffnesses, against 4π².
fn euler_table() -> Result<String> {
    let mut s = String::new();
    let p_e = 4.0 * PI * PI;
    writeln!(
        s,
        "\n### Euler buckling of a clamped isotropic rod (continuum 4π² = {p_e:.5})\n"
    )?;
    writeln!(
        s,
        "Compressive force at the first negative eigenvalue, found by bisection on the inertia.\n"
    )?;
    writeln!(
        s,
        "| N | S = 6.4e5: P | rel. error | S = 1e9: P | rel. error | p |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|")?;
    let mut prev = None;
    for n in [50, 100, 200, 400] {
        let p1 = euler_buckling_load(n, 640_000.0)?;
        let p2 = euler_buckling_load(n, 1e9)?;
        let e2 = (p2 - p_e).abs() / p_e;
        let p = prev.map_or(String::new(), |e| order(e, e2));
        writeln!(
            s,
            "| {n} | {p1:.5} | {:.2e} | {p2:.5} | {e2:.2e} | {p} |",
            (p1 - p_e).abs() / p_e
        )?;
        prev = Some(e2);
    }
    Ok(s)
}

/// The twisting moment at torsional buckling, against Greenhill's constant.
fn greenhill_table() -> Result<String> {
    let mut s = String::new();
    let m_c = greenhill_constant();
    writeln!(
        s,
        "\n### Torsional (Greenhill) buckling, clamped ends, no axial load (continuum M L/B = 2x₁, tan x₁ = x₁: {m_c:.5} = {:.4}π)\n",
        m_c / PI
    )?;
    writeln!(s, "| N | K3 φ at loss of stability | rel. error | p |")?;
    writeln!(s, "|---|---|---|---|")?;
    let mut prev = None;
    for n in [50, 100, 200, 400] {
        let m = greenhill_twisting_moment(n, 3.0, 640_000.0)?;
        let e = (m - m_c).abs() / m_c;
        let p = prev.map_or(String::new(), |x| order(x, e));
        writeln!(s, "| {n} | {m:.5} | {e:.2e} | {p} |")?;
        prev = Some(e);
    }
    Ok(s)
}

/// A free end: the cantilever's tip under a small weight, the heavy column,
/// the rod of natural curvature π at rest.
fn free_end_tables() -> Result<String> {
    let mut s = String::new();
    let w = 1e-3;
    // the tip error is h² to five digits: tip = (w/8)(1 − 1/N²)
    writeln!(
        s,
        "\n### Cantilever under its weight (clamped at s = 0, free at s = 1; w L³/B = {w} across the rod; continuum tip deflection w L³/8B)\n"
    )?;
    writeln!(s, "| N | tip deflection / (w/8) | rel. error | p |")?;
    writeln!(s, "|---|---|---|---|")?;
    let mut prev = None;
    for n in [25, 50, 100, 200] {
        let tip = cantilever_tip_deflection(n, w)? / (w / 8.0);
        let e = (tip - 1.0).abs();
        let p = prev.map_or(String::new(), |x| order(x, e));
        writeln!(s, "| {n} | {tip:.8} | {e:.2e} | {p} |")?;
        prev = Some(e);
    }
    let exact = heavy_column_constant()?;
    writeln!(
        s,
        "\n### Greenhill's heavy column (clamped at the base, free at the top, isotropic; continuum w L³/B = {exact:.6}, the first zero of J₋₁/₃(2/3 √(w L³/B)), classically 7.837)\n"
    )?;
    writeln!(
        s,
        "Weight at the first negative eigenvalue of the straight column, by bisection on the inertia (S = 1e8).\n"
    )?;
    writeln!(s, "| N | w L³/B | rel. error | p |")?;
    writeln!(s, "|---|---|---|---|")?;
    let mut prev = None;
    for n in [50, 100, 200] {
        let wc = heavy_column_weight(n, 1e8)?;
        let e = (wc - exact).abs() / exact;
        let p = prev.map_or(String::new(), |x| order(x, e));
        writeln!(s, "| {n} | {wc:.5} | {e:.2e} | {p} |")?;
        prev = Some(e);
    }
    writeln!(
        s,
        "\n### Natural curvature û1 = π, clamped at s = 0, free at s = 1 (continuum: the semicircle, zero energy and reactions)\n"
    )?;
    writeln!(
        s,
        "| N | energy | \\|n(0)\\| + \\|m(0)\\| | max distance from the semicircle | p |"
    )?;
    writeln!(s, "|---|---|---|---|---|")?;
    let mut prev = None;
    for n in [25, 50, 100] {
        let (e, r, d) = free_semicircle(n)?;
        let p = prev.map_or(String::new(), |x| order(x, d));
        writeln!(s, "| {n} | {e:.1e} | {r:.1e} | {d:.2e} | {p} |")?;
        prev = Some(d);
    }
    Ok(s)
}
