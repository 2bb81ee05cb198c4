//! One equilibrium of a scene: initial shape, Newton solve, and the quantities
//! the paper reports (clamp reactions, twist, walls, stability).

use crate::model::energy::RodEnergy;
use crate::model::rod::{RodModel, RodState};
use crate::model::shooting::{ShootingSolution, refine_shooting};
use crate::scene::{InitialShape, Scene};
use crate::solve::newton::{Newton, NewtonReport};
use crate::stability::lowest_eigenvalues;
use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// An equilibrium and its measurements (one entry of "equilibria" in the JSON summary).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Equilibrium {
    /// End displacement.
    pub z_star: f64,
    /// End shift.
    pub delta: f64,
    /// End rotation / 2π (continuous).
    pub phi_over_2pi: f64,
    /// Newton met its gradient test.
    pub converged: bool,
    /// Final relative gradient norm.
    pub gradient_norm: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// Relative gradient per iteration.
    pub residual_history: Vec<f64>,
    /// Elastic energy.
    pub energy: f64,
    /// Internal force at s = 0 (material frame).
    pub n0: [f64; 3],
    /// Internal moment at s = 0 (material frame).
    pub m0: [f64; 3],
    /// Tw = (1/2π) ∫ u3 ds.
    pub twist: f64,
    /// Lowest interior node height.
    pub min_z: f64,
    /// Highest interior node height.
    pub max_z: f64,
    /// 0 < z < z* at every interior node.
    pub walled: bool,
    /// Lowest eigenvalues of the Hessian on the free dofs.
    pub lowest_eigenvalues: Vec<f64>,
    /// Lowest eigenvalues of H v = ω² M v (lumped translational mass).
    pub omega_squared: Vec<f64>,
    /// Count of negative eigenvalues (inertia).
    pub negative_eigenvalues: usize,
    /// All eigenvalues positive.
    pub stable: bool,
    /// The full discrete state (restart with `[initial] shape = "file"`).
    pub state: RodState,
}

/// The initial state a scene asks for, at N segments.
pub fn initial_state(scene: &Scene, model: &RodModel) -> Result<RodState> {
    let clamps = scene.clamps();
    let n = model.segments;
    let init = &scene.initial;
    Ok(match init.shape {
        InitialShape::Straight => RodState::straight(n, clamps),
        InitialShape::Shooting => {
            let (mut n0, mut m0) = (
                Vector3::from(init.n0.context("initial.n0 missing")?),
                Vector3::from(init.m0.context("initial.m0 missing")?),
            );
            let steps = init.steps.map_or(20_000, |s| s as usize);
            if init.refine {
                (n0, m0) = refine_shooting(n0, m0, model.k2, model.k3, &clamps, steps)
                    .context("initial.refine: shooting refinement did not converge")?;
            }
            let sol = ShootingSolution::integrate(n0, m0, model.k2, model.k3, steps);
            RodState::from_curve(n, clamps, |s| sol.position(s), |s| sol.d1(s))
        }
        InitialShape::File => {
            let path = init.file.as_ref().context("initial.file missing")?;
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("initial.file: cannot read {}", path.display()))?;
            let summary: serde_json::Value = serde_json::from_str(&text)
                .with_context(|| format!("initial.file: {} is not JSON", path.display()))?;
            let entry = summary
                .get("equilibria")
                .and_then(|e| e.get(init.index))
                .and_then(|e| e.get("state"))
                .with_context(|| {
                    format!(
                        "initial.index: {} has no equilibria[{}].state",
                        path.display(),
                        init.index
                    )
                })?;
            let mut state: RodState = serde_json::from_value(entry.clone())
                .with_context(|| format!("initial.file: malformed state in {}", path.display()))?;
            if state.segments() != n
                || state.theta.len() != n + 1
                || state.reference.len() != n + 1
                || state.reference_twist.len() != n + 1
            {
                bail!(
                    "initial.file: state has {} segments, model.segments is {n}",
                    state.segments()
                );
            }
            state.set_clamps(clamps);
            state
        }
    })
}

/// Measure an equilibrium found by `newton` (its energy is reused for the Hessian).
pub fn analyse(
    newton: &mut Newton,
    state: &RodState,
    report: &NewtonReport,
    k: usize,
) -> Result<Equilibrium> {
    let energy: &RodEnergy = &newton.energy;
    let n = energy.map.len();
    let mut grad = vec![0.0; n];
    let mut values = vec![0.0; energy.pattern.nnz()];
    energy.hessian(state, &mut grad, &mut values);
    let plain = lowest_eigenvalues(&energy.pattern, &values, None, k, &mut newton.ldlt)
        .context("stability of the Hessian")?;
    let mass = energy.lumped_mass();
    let pencil = lowest_eigenvalues(&energy.pattern, &values, Some(&mass), k, &mut newton.ldlt)
        .context("stability with the lumped mass")?;
    let reactions = newton.energy.clamp_reactions(state);
    let (min_z, max_z) = state.z_range();
    let z_star = state.clamps.z_star;
    let stable = plain.negative_count == 0 && plain.values.first().is_none_or(|v| *v > 0.0);
    Ok(Equilibrium {
        z_star,
        delta: state.clamps.delta,
        phi_over_2pi: state.clamps.phi_over_2pi(),
        converged: report.converged,
        gradient_norm: report.gradient_norm,
        iterations: report.iterations,
        residual_history: report.residual_history.clone(),
        energy: report.energy,
        n0: reactions.force.into(),
        m0: reactions.moment.into(),
        twist: state.twist(),
        min_z,
        max_z,
        walled: min_z > 0.0 && max_z < z_star,
        lowest_eigenvalues: plain.values,
        omega_squared: pencil.values,
        negative_eigenvalues: plain.negative_count,
        stable,
        state: state.clone(),
    })
}

/// Solve a scene at N segments (the scene's own N if None).
pub fn solve_scene(scene: &Scene, segments: Option<usize>) -> Result<Equilibrium> {
    let model = scene.rod_model(segments);
    let mut state = initial_state(scene, &model)?;
    let mut newton = Newton::new(RodEnergy::new(model));
    let report = newton
        .minimize(&mut state, &scene.solver)
        .context("Newton minimisation")?;
    analyse(
        &mut newton,
        &state,
        &report,
        scene.stability.eigenvalues as usize,
    )
}
