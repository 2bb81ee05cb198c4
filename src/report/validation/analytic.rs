//! Analytic cases: a straight rod under uniform twist, Euler buckling and
//! torsional (Greenhill) buckling, against their continuum values.

use super::format::order;
use crate::model::energy::RodEnergy;
use crate::model::rod::{Clamps, RodModel, RodState};
use crate::report::analytic::{euler_buckling_load, greenhill_constant, greenhill_twisting_moment};
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
