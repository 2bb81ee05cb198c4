//! What every minimiser shares: its settings, its report, its errors, the
//! Armijo line search and the relative residual test.

use crate::model::contact::{ContactForce, Gap};
use crate::model::energy::GradientInfo;
use crate::model::rod::RodState;
use serde::{Deserialize, Serialize};

/// Settings of the Newton minimiser.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSettings {
    /// Stop when ‖∇E‖ ≤ tol × (scale of the internal forces), or when ‖∇E‖
    /// reaches its round-off floor (ε × largest stiffness × extent × √n).
    pub gradient_tol: f64,
    /// Give up after this many iterations.
    pub max_iterations: usize,
    /// Largest node displacement of one step (a step is scaled down to it).
    pub max_step: f64,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            gradient_tol: 1e-10,
            max_iterations: 1000,
            max_step: 0.05,
        }
    }
}

/// What one Newton solve did.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SolveReport {
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
    pub contacts: Vec<ContactForce>,
    /// The contact rows behind them, with their forces (for stability).
    #[serde(skip)]
    pub contact_rows: Vec<(Gap, f64)>,
}

impl SolveReport {
    pub(crate) fn start() -> Self {
        SolveReport {
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
    /// The gradient reached its round-off floor far from an equilibrium.
    #[error(
        "the gradient reached its round-off floor at Newton iteration {iteration} with the \
         relative gradient still {residual:.3e} (> 1e-6): this N and stiffness are past what \
         f64 resolves (stiffness ratio × N² ≳ 1e15); use fewer segments or a smaller \
         stretching stiffness (larger model.rod_diameter)"
    )]
    RoundOff {
        /// At which iteration.
        iteration: usize,
        /// Relative gradient there.
        residual: f64,
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
    // a floor above a relative gradient of 1e-6 is not an equilibrium to
    // trust: the problem is past what f64 resolves (see `stalled`)
    (
        rel,
        gnorm <= round_off_floor(max_diagonal, state, dofs) && rel <= FLOOR_TRUST,
    )
}

/// The gradient norm below which no step can improve it: ε × largest
/// stiffness × extent × √n.
fn round_off_floor(max_diagonal: f64, state: &RodState, dofs: usize) -> f64 {
    let extent = state.nodes.iter().map(|x| x.amax()).fold(0.0, f64::max);
    16.0 * f64::EPSILON * max_diagonal * extent.max(1e-3) * (dofs as f64).sqrt()
}

/// The largest relative gradient accepted at the round-off floor.
pub const FLOOR_TRUST: f64 = 1e-6;

/// Whether the gradient is at its round-off floor while the relative
/// gradient is still above `FLOOR_TRUST`: no step can improve it, and the
/// state is no equilibrium worth reporting.
pub fn stalled(gnorm: f64, rel: f64, max_diagonal: f64, state: &RodState, dofs: usize) -> bool {
    rel > FLOOR_TRUST && gnorm <= round_off_floor(max_diagonal, state, dofs)
}
