//! Newton's method for equilibria of the discrete rod: energy minimisation with
//! a line search and a diagonal shift for indefinite Hessians.

use crate::model::energy::{GradientInfo, RodEnergy};
use crate::model::rod::RodState;
use crate::linalg::sparse::Ldlt;
use serde::{Deserialize, Serialize};

/// Settings of the Newton minimiser.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct NewtonSettings {
    /// Stop when ‖∇E‖ ≤ tol × (scale of the internal forces), or when ‖∇E‖
    /// reaches its round-off floor (ε × largest stiffness × extent × √n).
    pub gradient_tol: f64,
    /// Give up after this many iterations.
    pub max_iterations: usize,
    /// Largest node displacement of one step (a step is scaled down to it).
    pub max_step: f64,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        NewtonSettings {
            gradient_tol: 1e-10,
            max_iterations: 1000,
            max_step: 0.05,
        }
    }
}

/// What one Newton solve did.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NewtonReport {
    /// Whether the gradient test was met.
    pub converged: bool,
    /// Newton iterations taken.
    pub iterations: usize,
    /// Relative gradient norm at each iterate (the residual history).
    pub residual_history: Vec<f64>,
    /// Final relative gradient norm.
    pub gradient_norm: f64,
    /// Final energy.
    pub energy: f64,
    /// Number of numerical factorisations.
    pub factorizations: usize,
    /// Contact forces at the solution (with a contact model).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contacts: Vec<crate::solve::sqp::ContactForce>,
    /// The contact rows behind them, with their forces (for stability).
    #[serde(skip)]
    pub contact_rows: Vec<(crate::model::contact::Gap, f64)>,
}

impl NewtonReport {
    pub(crate) fn start() -> Self {
        NewtonReport {
            converged: false,
            iterations: 0,
            residual_history: Vec::new(),
            gradient_norm: f64::NAN,
            energy: f64::NAN,
            factorizations: 0,
            contacts: Vec::new(),
            contact_rows: Vec::new(),
        }
    }

    pub(crate) fn record(&mut self, iteration: usize, rel: f64, energy: f64) {
        self.residual_history.push(rel);
        self.gradient_norm = rel;
        self.energy = energy;
        self.iterations = iteration;
    }

    pub(crate) fn not_converged(&self) -> SolveError {
        let h = &self.residual_history;
        SolveError::NotConverged {
            iterations: self.iterations,
            residual: self.gradient_norm,
            tail: h[h.len().saturating_sub(6)..].to_vec(),
        }
    }
}

/// Why a solve failed.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    /// No convergence within the iteration budget.
    #[error(
        "Newton did not converge in {iterations} iterations (relative gradient {residual:.3e}; last ones {tail:?})"
    )]
    NotConverged {
        /// Iterations taken.
        iterations: usize,
        /// Final relative gradient.
        residual: f64,
        /// The last few relative gradients.
        tail: Vec<f64>,
    },
    /// A NaN or infinity appeared.
    #[error("non-finite value in {step} at Newton iteration {iteration}")]
    NonFinite {
        /// Where it appeared.
        step: &'static str,
        /// At which iteration.
        iteration: usize,
    },
    /// The line search could not decrease the energy.
    #[error(
        "line search failed at Newton iteration {iteration} (relative gradient {residual:.3e})"
    )]
    LineSearch {
        /// At which iteration.
        iteration: usize,
        /// Relative gradient there.
        residual: f64,
    },
}

/// A Newton minimiser bound to one energy (its sparse pattern and symbolic
/// factorisation are reused across iterations and solves).
pub struct Newton {
    /// The energy being minimised.
    pub energy: RodEnergy,
    /// Factorisation workspace.
    pub ldlt: Ldlt,
    /// Contact with the rays, obstacles and itself (solved by SQP).
    pub contact: Option<crate::model::contact::ContactModel>,
    grad: Vec<f64>,
    values: Vec<f64>,
    step: Vec<f64>,
    trial_step: Vec<f64>,
}

impl Newton {
    /// A minimiser for `energy`.
    pub fn new(energy: RodEnergy) -> Self {
        let n = energy.map.len();
        let nnz = energy.pattern.nnz();
        let ldlt = Ldlt::new(&energy.pattern);
        Newton {
            energy,
            ldlt,
            contact: None,
            grad: vec![0.0; n],
            values: vec![0.0; nnz],
            step: vec![0.0; n],
            trial_step: vec![0.0; n],
        }
    }

    /// Replace the step by a small move (largest node move 1e-3) along the
    /// lowest eigenvector of H when its eigenvalue is negative, downhill.
    fn negative_curvature_step(&mut self, map: crate::model::rod::DofMap) {
        let Ok(sp) = crate::linalg::eigen::lowest_eigenvalues(
            &self.energy.pattern,
            &self.values,
            None,
            1,
            &mut self.ldlt,
        ) else {
            return;
        };
        let (Some(&lambda), Some(v)) = (sp.values.first(), sp.vectors.first()) else {
            return;
        };
        let largest = (0..v.len())
            .filter(|&d| map.is_translation(d))
            .map(|d| v[d].abs())
            .fold(0.0, f64::max);
        if lambda >= 0.0 || largest == 0.0 {
            return;
        }
        let uphill: f64 = v.iter().zip(&self.grad).map(|(a, b)| a * b).sum();
        let scale = if uphill > 0.0 { -1e-3 } else { 1e-3 } / largest;
        self.step
            .iter_mut()
            .zip(v)
            .for_each(|(s, x)| *s = scale * x);
    }

    fn max_diagonal(&self) -> f64 {
        self.energy
            .pattern
            .diagonal
            .iter()
            .map(|&s| self.values[s].abs())
            .fold(0.0, f64::max)
    }

    /// Gradient and Hessian at `state` (into the workspace), the relative
    /// gradient, and whether the gradient is at its round-off floor (ε ×
    /// largest stiffness × extent × √n: no step can improve it below that).
    fn linearise(
        &mut self,
        state: &RodState,
        iteration: usize,
    ) -> Result<(GradientInfo, f64, bool), SolveError> {
        crate::linalg::counters::NEWTON_ITERATIONS
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let info = self.energy.hessian(state, &mut self.grad, &mut self.values);
        let gnorm = norm(&self.grad);
        if !info.energy.is_finite() || !gnorm.is_finite() {
            return Err(SolveError::NonFinite {
                step: "energy/gradient evaluation",
                iteration,
            });
        }
        let (rel, at_floor) = residual(&info, gnorm, self.max_diagonal(), state, self.grad.len());
        Ok((info, rel, at_floor))
    }

    /// Newton's method on ∇E = 0 from `state` without line search or shift:
    /// converges to the nearby equilibrium whatever its stability (a saddle
    /// too), where [`Self::minimize`] would leave a saddle.
    pub fn find_equilibrium(
        &mut self,
        state: &mut RodState,
        settings: &NewtonSettings,
    ) -> Result<NewtonReport, SolveError> {
        let mut report = NewtonReport::start();
        let map = self.energy.map;
        let mut next = state.clone();
        for it in 0..=settings.max_iterations {
            let (info, rel, at_floor) = self.linearise(state, it)?;
            report.record(it, rel, info.energy);
            if rel <= settings.gradient_tol || at_floor {
                report.converged = true;
                return Ok(report);
            }
            report.factorizations += 1;
            if self.ldlt.factor(&self.values).is_err() {
                return Err(SolveError::NonFinite {
                    step: "singular Hessian",
                    iteration: it,
                });
            }
            for (s, g) in self.step.iter_mut().zip(&self.grad) {
                *s = -g;
            }
            self.ldlt.solve_in_place(&mut self.step);
            state.displace_into(&map, &self.step, &mut next);
            std::mem::swap(state, &mut next);
        }
        Err(report.not_converged())
    }

    /// Minimise the energy from `state` (updated in place).
    pub fn minimize(
        &mut self,
        state: &mut RodState,
        settings: &NewtonSettings,
    ) -> Result<NewtonReport, SolveError> {
        if self.energy.penalty.is_some() {
            // constrained laws: SQP, each step a QP solved by clarabel
            return crate::solve::sqp::minimize(self, state, settings);
        }
        if let Some(model) = self.contact.clone() {
            // Newton while nothing is near contact (steps capped so that no
            // pair can close the margin in one), SQP with contact rows once
            // something is
            let capped = NewtonSettings {
                max_step: settings.max_step.min(0.5 * model.margin),
                ..*settings
            };
            let near = |s: &RodState| !model.gaps(s).is_empty();
            if !near(state) {
                let report = self.minimize_until(state, &capped, Some(&near))?;
                if report.converged {
                    return Ok(report);
                }
            }
            return crate::solve::sqp::minimize(self, state, settings);
        }
        self.minimize_until(state, settings, None)
    }

    /// Newton minimisation that stops early (not converged) at the first
    /// accepted iterate where `stop` holds.
    fn minimize_until(
        &mut self,
        state: &mut RodState,
        settings: &NewtonSettings,
        stop: Option<&dyn Fn(&RodState) -> bool>,
    ) -> Result<NewtonReport, SolveError> {
        let mut report = NewtonReport::start();
        let mut shift = 0.0f64;
        let mut next_shift = 0.0f64;
        let mut trial = state.clone();
        for it in 0..=settings.max_iterations {
            let (info, rel, at_floor) = self.linearise(state, it)?;
            report.record(it, rel, info.energy);
            if rel <= settings.gradient_tol || at_floor {
                report.converged = true;
                return Ok(report);
            }
            if it == settings.max_iterations {
                break;
            }
            // Newton direction with the smallest diagonal shift that makes the
            // Hessian positive definite (a descent direction for minimisation).
            let diag_scale = self.max_diagonal().max(1e-300);
            // Levenberg-style: after a full step try the pure Newton step
            // (quadratic convergence near a minimum), after a cut step a
            // larger shift; raise it until H + shift is positive definite
            let previous = shift;
            shift = next_shift;
            loop {
                for &s in &self.energy.pattern.diagonal {
                    self.values[s] += shift;
                }
                report.factorizations += 1;
                let ok = self.ldlt.factor(&self.values).is_ok() && self.ldlt.negative_count() == 0;
                for &s in &self.energy.pattern.diagonal {
                    self.values[s] -= shift;
                }
                if ok {
                    break;
                }
                shift = if shift == 0.0 {
                    (0.1 * previous).max(1e-8 * diag_scale)
                } else {
                    shift * 10.0
                };
                if shift > 1e6 * diag_scale {
                    return Err(SolveError::NonFinite {
                        step: "Hessian regularisation",
                        iteration: it,
                    });
                }
            }
            for (s, g) in self.step.iter_mut().zip(&self.grad) {
                *s = -g;
            }
            self.ldlt.solve_in_place(&mut self.step);
            if self.step.iter().any(|v| !v.is_finite()) {
                return Err(SolveError::NonFinite {
                    step: "Newton step",
                    iteration: it,
                });
            }
            let map = self.energy.map;
            // near a saddle (small gradient, H indefinite) a shifted Newton step
            // creeps: step off along the direction of negative curvature instead
            if shift > 0.0 && rel < 1e-6 {
                self.negative_curvature_step(map);
            }
            // cap the largest node move
            let largest = (0..self.step.len())
                .filter(|&d| map.is_translation(d))
                .map(|d| self.step[d].abs())
                .fold(0.0, f64::max);
            if largest > settings.max_step {
                let f = settings.max_step / largest;
                self.step.iter_mut().for_each(|v| *v *= f);
            }
            // Armijo backtracking on the energy
            let slope: f64 = self.step.iter().zip(&self.grad).map(|(s, g)| s * g).sum();
            let (energy, step, trial_step) = (&self.energy, &self.step, &mut self.trial_step);
            let alpha = armijo(info.energy, slope, |alpha| {
                for (t, v) in trial_step.iter_mut().zip(step) {
                    *t = alpha * v;
                }
                state.displace_into(&map, trial_step, &mut trial);
                Some(energy.energy(&trial))
            })
            .ok_or(SolveError::LineSearch {
                iteration: it,
                residual: rel,
            })?;
            // a full step keeps the pure Newton method; a cut step (a poor
            // quadratic model: near-singular H, far from equilibrium) damps
            // the next one
            next_shift = if alpha >= 0.5 {
                0.0
            } else {
                (10.0 * shift).max(1e-8 * diag_scale)
            };
            std::mem::swap(state, &mut trial);
            if stop.is_some_and(|f| f(state)) {
                return Ok(report);
            }
        }
        Err(report.not_converged())
    }
}

/// Armijo backtracking from a merit value `merit0` with directional derivative
/// `slope` along the step: `merit(alpha)` evaluates the trial (None rejects it
/// outright, e.g. a step through a contact); returns the accepted α. Near
/// convergence the decrease is below round-off: a trial equal to working
/// precision is accepted.
pub fn armijo(merit0: f64, slope: f64, mut merit: impl FnMut(f64) -> Option<f64>) -> Option<f64> {
    let tol = 1e-14 * merit0.abs().max(1.0);
    let mut alpha = 1.0;
    for _ in 0..40 {
        if let Some(e) = merit(alpha)
            && e.is_finite()
            && e <= merit0 + 1e-4 * alpha * slope.min(0.0) + tol
        {
            return Some(alpha);
        }
        alpha *= 0.5;
    }
    None
}

/// Relative gradient (against the scale of the internal forces) and whether
/// the gradient is at its round-off floor, ε × largest stiffness × extent × √n:
/// below it no step can improve it. Shared by Newton and the continuation
/// corrector.
pub fn residual(
    info: &GradientInfo,
    gnorm: f64,
    max_diagonal: f64,
    state: &RodState,
    dofs: usize,
) -> (f64, bool) {
    let rel = if info.force_scale > 1e-300 {
        gnorm / info.force_scale
    } else {
        0.0
    };
    let extent = state.nodes.iter().map(|x| x.amax()).fold(0.0, f64::max);
    let floor = 16.0 * f64::EPSILON * max_diagonal * extent.max(1e-3) * (dofs as f64).sqrt();
    (rel, gnorm <= floor)
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}
