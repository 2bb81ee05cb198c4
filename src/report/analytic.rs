//! Classical results for straight rods, computed with the discrete rod, to
//! check it against closed forms: Euler buckling of a clamped-clamped rod
//! (P = 4π² B/L²), Greenhill's torsional buckling (M L/B = 2 x₁ with
//! tan x₁ = x₁, i.e. 2.8606 π), and with a free end: a cantilever's tip
//! under its weight (w L³/8B), Greenhill's heavy column (w L³/B = 7.8373)
//! and a naturally curved rod at rest.

use crate::linalg::eigen::lowest_eigenvalues;
use crate::model::energy::{RodEnergy, Terms};
use crate::model::ode::integrate_stops;
use crate::model::rod::{Clamps, EndKind, RodModel, RodState};
use crate::report::error::{ReportError, Result, fail};
use crate::solve::minimizer::Minimizer;
use crate::solve::outcome::SolverSettings;
use crate::solve::root::bisect_predicate;
use nalgebra::SVector;
use std::f64::consts::PI;

/// The straight (uniformly twisted) equilibrium for `clamps`, stable or not,
/// with its count of negative Hessian eigenvalues.
pub fn straight_equilibrium(newton: &mut Minimizer, clamps: Clamps) -> Result<(RodState, usize)> {
    let n = newton.energy.model.segments;
    let mut st = RodState::straight(n, clamps);
    newton.find_equilibrium(&mut st, &SolverSettings::default())?;
    let mut g = vec![0.0; newton.energy.map.len()];
    let mut v = vec![0.0; newton.energy.pattern.nnz()];
    newton.energy.hessian(&st, &mut g, &mut v);
    let sp = lowest_eigenvalues(&newton.energy.pattern, &v, None, 0, &mut newton.ldlt)?;
    Ok((st, sp.negative_count))
}

/// Bisection on the inertia: the parameter in [lo, hi] at which the state
/// first has a negative eigenvalue (to 40 halvings).
fn loss_of_stability(
    lo: f64,
    hi: f64,
    mut unstable: impl FnMut(f64) -> Result<bool>,
) -> Result<f64> {
    if unstable(lo)? || !unstable(hi)? {
        fail!("bracket [{lo}, {hi}] does not contain the loss of stability");
    }
    // 40 halvings
    let narrowest = 1.5 * (hi - lo) * 2f64.powi(-40);
    bisect_predicate(lo, hi, |lo, hi| hi - lo <= narrowest, |p| Ok(!unstable(p)?))
}

/// Compressive axial force at which a straight isotropic (K2 = 1) clamped rod
/// with N segments and stretching stiffness S first becomes unstable under end
/// shortening (continuum: 4π²).
pub fn euler_buckling_load(n: usize, stretching_stiffness: f64) -> Result<f64> {
    let model = RodModel {
        weight: [0.0; 3],
        natural_strains: Default::default(),
        segments: n,
        k2: 1.0,
        k3: 3.0,
        stretching_stiffness,
        law: Default::default(),
    };
    let mut newton = Minimizer::new(RodEnergy::new(model));
    let p_e = 4.0 * PI * PI;
    let s = stretching_stiffness;
    // an end shortening ε gives a compressive force ≈ S ε
    let eps = loss_of_stability(0.8 * p_e / s, 1.2 * p_e / s, |eps| {
        Ok(straight_equilibrium(&mut newton, Clamps::new(1.0 - eps, 0.0, 0.0))?.1 > 0)
    })?;
    let (st, _) = straight_equilibrium(&mut newton, Clamps::new(1.0 - eps, 0.0, 0.0))?;
    Ok(-newton.energy.clamp_reactions(&st).force[2])
}

/// Twisting moment K3 φ at which a straight isotropic clamped rod with no axial
/// load (z* = 1) first becomes unstable as its clamp is rotated.
pub fn greenhill_twisting_moment(n: usize, k3: f64, stretching_stiffness: f64) -> Result<f64> {
    let model = RodModel {
        weight: [0.0; 3],
        natural_strains: Default::default(),
        segments: n,
        k2: 1.0,
        k3,
        stretching_stiffness,
        law: Default::default(),
    };
    let mut newton = Minimizer::new(RodEnergy::new(model));
    let phi = loss_of_stability(7.0 / k3, 11.0 / k3, |phi| {
        Ok(straight_equilibrium(
            &mut newton,
            Clamps {
                phi,
                ..Clamps::new(1.0, 0.0, 0.0)
            },
        )?
        .1 > 0)
    })?;
    Ok(k3 * phi)
}

/// The continuum Greenhill moment for clamped ends, M L/B = 2 x₁ where x₁ is
/// the smallest positive root of tan x = x (8.98682 = 2.8606 π).
pub fn greenhill_constant() -> f64 {
    let mut x: f64 = 4.49;
    for _ in 0..50 {
        x -= (x.tan() - x) / (1.0 / x.cos().powi(2) - 1.0);
    }
    2.0 * x
}

/// The clamps of a rod standing on the origin along e3, its s = 1 end free.
pub fn cantilever_clamps() -> Clamps {
    let mut c = Clamps::new(1.0, 0.0, 0.0);
    c.ends.end = EndKind::Free;
    c
}

/// A Kirchhoff rod of N segments, bending ratio K2, stretching stiffness S,
/// weight w g and natural strains û.
fn free_end_minimizer(n: usize, k2: f64, s: f64, weight: [f64; 3], natural: [f64; 3]) -> Minimizer {
    let model = RodModel {
        weight,
        natural_strains: natural.into(),
        segments: n,
        k2,
        k3: 2.0,
        stretching_stiffness: s,
        law: Default::default(),
    };
    Minimizer::new(RodEnergy::with_ends(
        model,
        Terms::ALL,
        cantilever_clamps().ends,
    ))
}

/// Tip deflection of a cantilever (clamped at the origin along e3, free at
/// s = 1) under a weight w across it along −e2 (bending about d1, B11 = 1):
/// −y of r(1), whose small-load continuum value is w L³/(8 B).
pub fn cantilever_tip_deflection(n: usize, w: f64) -> Result<f64> {
    let mut newton = free_end_minimizer(n, 3.0, 640_000.0, [0.0, -w, 0.0], [0.0; 3]);
    let mut st = RodState::straight(n, cantilever_clamps());
    newton.minimize(&mut st, &SolverSettings::default())?;
    Ok(-st.end_point().y)
}

/// Weight w L³/B at which an isotropic column clamped at the origin along
/// e3 and free at the top first becomes unstable under its weight along −e3
/// (bisection on the inertia of the straight equilibrium). Continuum:
/// 7.8373, the first zero of J₋₁/₃(2/3 √(w L³/B)) (Greenhill 1881).
pub fn heavy_column_weight(n: usize, stretching_stiffness: f64) -> Result<f64> {
    loss_of_stability(6.0, 10.0, |w| {
        let mut newton = free_end_minimizer(n, 1.0, stretching_stiffness, [0.0, 0.0, -w], [0.0; 3]);
        Ok(straight_equilibrium(&mut newton, cantilever_clamps())?.1 > 0)
    })
}

/// The rod of natural curvature û1 = π clamped at the origin along e3 and
/// free at s = 1, relaxed from straight: its energy, |n(0)| + |m(0)|, and
/// the largest distance of r(s) at the nodes and at s = 1 from the
/// semicircle (0, −(1 − cos πs)/π, sin πs/π) it rests as (all zero in the
/// continuum).
pub fn free_semicircle(n: usize) -> Result<(f64, f64, f64)> {
    let mut newton = free_end_minimizer(n, 2.0, 640_000.0, [0.0; 3], [PI, 0.0, 0.0]);
    let mut st = RodState::straight(n, cantilever_clamps());
    newton.minimize(&mut st, &SolverSettings::default())?;
    let arc =
        |s: f64| nalgebra::Vector3::new(0.0, -(1.0 - (PI * s).cos()) / PI, (PI * s).sin() / PI);
    let h = 1.0 / n as f64;
    let shape = (1..=n)
        .map(|i| (st.nodes[i] - arc((i as f64 - 0.5) * h)).norm())
        .fold((st.end_point() - arc(1.0)).norm(), f64::max);
    let r = newton.energy.clamp_reactions(&st);
    Ok((
        newton.energy.energy(&st),
        r.force.norm() + r.moment.norm(),
        shape,
    ))
}

/// The continuum heavy column's critical weight: the smallest w with a
/// nonzero solution of θ'' + w (1 − s) θ = 0, θ(0) = 0 (clamped base),
/// θ'(1) = 0 (free top, no moment), by the continuum integrator and
/// bisection on θ'(1): 7.83735, the first zero of J₋₁/₃(2/3 √w)
/// (classically w L³/EI = 7.837).
pub fn heavy_column_constant() -> Result<f64> {
    let end_slope = |w: f64| -> Result<f64> {
        let f = |s: f64, y: &SVector<f64, 2>| SVector::<f64, 2>::new(y[1], -w * (1.0 - s) * y[0]);
        let (ends, _) = integrate_stops(SVector::<f64, 2>::new(0.0, 1.0), f, 1e-13, &[1.0])
            .map_err(|e| ReportError::Failed(format!("heavy column at w = {w}: {e}")))?;
        Ok(ends[0][1])
    };
    // to adjacent floats
    bisect_predicate(6.0, 9.0, |_, _| false, |w| Ok(end_slope(w)? > 0.0))
}
