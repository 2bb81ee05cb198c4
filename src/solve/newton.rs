//! Newton's method for equilibria of the discrete rod: energy minimisation with
//! a line search and a diagonal shift for indefinite Hessians, and the plain
//! Newton iteration on ∇E = 0 (which converges to saddles too).

use crate::linalg::eigen::lowest_eigenvalues;
use crate::linalg::sparse::Ldlt;
use crate::model::energy::{GradientInfo, RodEnergy};
use crate::model::rod::RodState;
use crate::solve::outcome::{
    FloorProbe, Judgement, SolveError, SolveReport, SolverSettings, Stall, armijo, floor_bound,
    judge,
};

/// Work vectors of Newton's method on one energy's pattern (allocated once,
/// reused by every iteration and solve).
pub struct Newton {
    grad: Vec<f64>,
    values: Vec<f64>,
    step: Vec<f64>,
    trial_step: Vec<f64>,
    floor: FloorProbe,
}

impl Newton {
    /// Work vectors for `energy`.
    pub fn new(energy: &RodEnergy) -> Self {
        let n = energy.map.len();
        let nnz = energy.pattern.nnz();
        Newton {
            grad: vec![0.0; n],
            values: vec![0.0; nnz],
            step: vec![0.0; n],
            trial_step: vec![0.0; n],
            floor: FloorProbe::default(),
        }
    }

    /// Replace the step by a small move (largest node move 1e-3) along the
    /// lowest eigenvector of H when its eigenvalue is negative, downhill.
    fn negative_curvature_step(&mut self, energy: &RodEnergy, ldlt: &mut Ldlt) {
        let map = energy.map;
        let Ok(sp) = lowest_eigenvalues(&energy.pattern, &self.values, None, 1, ldlt) else {
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

    fn max_diagonal(&self, energy: &RodEnergy) -> f64 {
        energy.pattern.max_abs_diagonal(&self.values)
    }

    /// Gradient and Hessian at `state` (into the workspace) and the one
    /// convergence test ([`judge`]) of the iterate against `tol`.
    fn linearise(
        &mut self,
        energy: &RodEnergy,
        state: &RodState,
        iteration: usize,
        tol: f64,
    ) -> Result<(GradientInfo, Judgement), SolveError> {
        crate::linalg::counters::add_iteration();
        let info = energy.hessian(state, &mut self.grad, &mut self.values);
        let gnorm = norm(&self.grad);
        if !info.energy.is_finite() || !gnorm.is_finite() {
            return Err(SolveError::NonFinite {
                step: "energy/gradient evaluation",
                iteration,
            });
        }
        let bound = floor_bound(&info, self.max_diagonal(energy), state, self.grad.len());
        let floor = &mut self.floor;
        let judgement = judge(&info, gnorm, tol, bound, || floor.measure(energy, state));
        crate::linalg::counters::set_residual(judgement.rel);
        Ok((info, judgement))
    }

    /// Newton's method on ∇E = 0 from `state` without line search or shift:
    /// converges to the nearby equilibrium whatever its stability (a saddle
    /// too), where minimisation would leave a saddle.
    pub fn find_equilibrium(
        &mut self,
        energy: &RodEnergy,
        ldlt: &mut Ldlt,
        state: &mut RodState,
        settings: &SolverSettings,
    ) -> Result<SolveReport, SolveError> {
        let mut report = SolveReport::start();
        let map = energy.map;
        let mut next = state.clone();
        let mut stall = Stall::default();
        for it in 0..=settings.max_iterations {
            let (info, judgement) = self.linearise(energy, state, it, settings.gradient_tol)?;
            report.record(it, judgement.rel, info.energy);
            if judgement.converged {
                report.converged = true;
                return Ok(report);
            }
            stall.check(it, &judgement)?;
            report.factorizations += 1;
            if ldlt.factor(&self.values).is_err() {
                return Err(SolveError::NonFinite {
                    step: "singular Hessian",
                    iteration: it,
                });
            }
            for (s, g) in self.step.iter_mut().zip(&self.grad) {
                *s = -g;
            }
            ldlt.solve_in_place(&mut self.step);
            state.displace_into(&map, &self.step, &mut next);
            std::mem::swap(state, &mut next);
        }
        Err(report.not_converged())
    }

    /// Factor H + shift·I with the smallest shift, from `first`, that makes
    /// it positive definite: after a zero shift 0.1 × `previous` (at least
    /// 1e-8 × `diag_scale`), then ×10. Returns the shift used (None past
    /// 1e6 × `diag_scale`), counting the factorisations in `factorizations`.
    fn factor_shifted(
        &mut self,
        energy: &RodEnergy,
        ldlt: &mut Ldlt,
        first: f64,
        previous: f64,
        diag_scale: f64,
        factorizations: &mut usize,
    ) -> Option<f64> {
        let mut shift = first;
        loop {
            for &s in &energy.pattern.diagonal {
                self.values[s] += shift;
            }
            *factorizations += 1;
            let ok = ldlt.factor(&self.values).is_ok() && ldlt.negative_count() == 0;
            for &s in &energy.pattern.diagonal {
                self.values[s] -= shift;
            }
            if ok {
                return Some(shift);
            }
            shift = if shift == 0.0 {
                (0.1 * previous).max(1e-8 * diag_scale)
            } else {
                shift * 10.0
            };
            if shift > 1e6 * diag_scale {
                return None;
            }
        }
    }

    /// The (shifted) Newton step −(H + shift)⁻¹∇E from the factorisation in
    /// `ldlt`, replaced near a saddle by a step along negative curvature, and
    /// capped to a largest node move of `max_step`.
    fn newton_step(
        &mut self,
        energy: &RodEnergy,
        ldlt: &mut Ldlt,
        shift: f64,
        rel: f64,
        max_step: f64,
        it: usize,
    ) -> Result<(), SolveError> {
        for (s, g) in self.step.iter_mut().zip(&self.grad) {
            *s = -g;
        }
        ldlt.solve_in_place(&mut self.step);
        if self.step.iter().any(|v| !v.is_finite()) {
            return Err(SolveError::NonFinite {
                step: "Newton step",
                iteration: it,
            });
        }
        // near a saddle (small gradient, H indefinite) a shifted Newton step
        // creeps: step off along the direction of negative curvature instead
        if shift > 0.0 && rel < 1e-6 {
            self.negative_curvature_step(energy, ldlt);
        }
        // cap the largest node move
        let map = energy.map;
        let largest = (0..self.step.len())
            .filter(|&d| map.is_translation(d))
            .map(|d| self.step[d].abs())
            .fold(0.0, f64::max);
        if largest > max_step {
            let f = max_step / largest;
            self.step.iter_mut().for_each(|v| *v *= f);
        }
        Ok(())
    }

    /// Newton minimisation that stops early (not converged) at the first
    /// accepted iterate where `stop` holds.
    pub fn minimize_until(
        &mut self,
        energy: &RodEnergy,
        ldlt: &mut Ldlt,
        state: &mut RodState,
        settings: &SolverSettings,
        stop: Option<&dyn Fn(&RodState) -> bool>,
    ) -> Result<SolveReport, SolveError> {
        let mut report = SolveReport::start();
        let mut shift = 0.0f64;
        let mut next_shift = 0.0f64;
        let mut trial = state.clone();
        let mut stall = Stall::default();
        for it in 0..=settings.max_iterations {
            let (info, judgement) = self.linearise(energy, state, it, settings.gradient_tol)?;
            let rel = judgement.rel;
            report.record(it, rel, info.energy);
            if judgement.converged {
                report.converged = true;
                return Ok(report);
            }
            stall.check(it, &judgement)?;
            if it == settings.max_iterations {
                break;
            }
            // Newton direction with the smallest diagonal shift that makes the
            // Hessian positive definite (a descent direction for minimisation).
            let diag_scale = self.max_diagonal(energy).max(1e-300);
            // Levenberg-style: after a full step try the pure Newton step
            // (quadratic convergence near a minimum), after a cut step a
            // larger shift; raise it until H + shift is positive definite
            let previous = shift;
            shift = self
                .factor_shifted(
                    energy,
                    ldlt,
                    next_shift,
                    previous,
                    diag_scale,
                    &mut report.factorizations,
                )
                .ok_or(SolveError::NonFinite {
                    step: "Hessian regularisation",
                    iteration: it,
                })?;
            self.newton_step(energy, ldlt, shift, rel, settings.max_step, it)?;
            let map = energy.map;
            // Armijo backtracking on the energy
            let slope: f64 = self.step.iter().zip(&self.grad).map(|(s, g)| s * g).sum();
            let (step, trial_step) = (&self.step, &mut self.trial_step);
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

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}
