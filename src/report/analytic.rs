//! Classical stability results for straight clamped rods, computed with the
//! discrete rod, to check it against closed forms: Euler buckling of a
//! clamped-clamped rod (P = 4π² B/L²) and Greenhill's torsional buckling
//! (M L/B = 2 x₁ with tan x₁ = x₁, i.e. 2.8606 π).

use crate::linalg::eigen::lowest_eigenvalues;
use crate::model::energy::RodEnergy;
use crate::model::rod::{Clamps, RodModel, RodState};
use crate::report::error::{Result, fail};
use crate::solve::minimizer::Minimizer;
use crate::solve::outcome::SolverSettings;
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
    mut lo: f64,
    mut hi: f64,
    mut unstable: impl FnMut(f64) -> Result<bool>,
) -> Result<f64> {
    if unstable(lo)? || !unstable(hi)? {
        fail!("bracket [{lo}, {hi}] does not contain the loss of stability");
    }
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if unstable(mid)? { hi = mid } else { lo = mid }
    }
    Ok(0.5 * (lo + hi))
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
