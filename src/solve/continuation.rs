//! Pseudo-arclength continuation of equilibria, ∇E(q; p) = 0, in one clamp
//! parameter p: tangent predictor, Newton corrector on the bordered system
//! [H  ∂_p∇E; w τ_qᵀ  τ_p] (block elimination with the sparse LDLᵀ of H, which
//! need not be definite), adaptive step, and location of events by bisection
//! in arclength on a test function. Constrained laws (the strip's u2 = 0) are
//! continued on the KKT system instead: unknowns (q, λ), the constraint rows
//! bordered in, stability from the inertia reduced to the tangent space.

use crate::linalg::sparse::Ldlt;
use crate::model::rod::{Clamps, Parameter, RodState};
use crate::solve::kkt::Kkt;
use crate::solve::minimizer::Minimizer;
use crate::solve::outcome::{FloorProbe, SolveError, floor_bound, judge};
use crate::solve::root::{Bracket, Probe, bisect};
use crate::solve::step::{Acceptance, StepControl, Trial};
use serde::{Deserialize, Serialize};

/// Settings of one continuation.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct ContinuationSettings {
    /// Initial arclength step (≈ parameter step where the branch is flat).
    pub step: f64,
    /// Smallest step before giving up.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Most points on one branch direction.
    pub max_points: usize,
    /// Corrector tolerance on the relative gradient.
    pub tolerance: f64,
    /// Corrector iterations before the step is cut.
    pub max_corrector_iterations: usize,
    /// Events are located to this arclength.
    pub locate_tolerance: f64,
}

impl ContinuationSettings {
    /// Its step control: from `step`, halved on failure down to `min_step`,
    /// ×1.5 after a corrector of at most 3 iterations, up to `max_step`.
    pub fn step_control(&self) -> StepControl {
        StepControl::new(self.step, self.min_step, self.max_step, 1.5, 3)
    }
}

impl Default for ContinuationSettings {
    fn default() -> Self {
        ContinuationSettings {
            step: 0.005,
            min_step: 1e-7,
            max_step: 0.02,
            max_points: 2000,
            tolerance: 1e-10,
            max_corrector_iterations: 10,
            locate_tolerance: 1e-9,
        }
    }
}

/// A converged point of a branch with its unit tangent (weighted norm).
#[derive(Clone, Debug)]
pub struct Point {
    /// The equilibrium.
    pub state: RodState,
    /// Tangent on the free dofs (then on the multipliers, for constrained laws).
    pub tangent_q: Vec<f64>,
    /// Tangent component along the parameter (dp/ds).
    pub tangent_p: f64,
    /// Negative eigenvalues of the Hessian (LDLᵀ inertia).
    pub negative_count: usize,
    /// Corrector iterations it took.
    pub iterations: usize,
    /// Relative gradient at convergence.
    pub residual: f64,
    /// How far the corrector moved from the predictor, relative to the step
    /// (weighted norm): large when it had to jump to another part of the
    /// branch, e.g. across a hairpin.
    pub correction: f64,
    /// The Hessian at the point (values on the energy's pattern), which the
    /// corrector evaluated anyway: stability analysis reuses it.
    pub hessian: std::sync::Arc<[f64]>,
}

/// Why a continuation step failed.
#[derive(Debug, thiserror::Error)]
pub enum ContinuationError {
    /// The Hessian could not be factorised (exactly singular).
    #[error("continuation: singular Hessian at {0}")]
    Singular(&'static str),
    /// The corrector did not converge.
    #[error("continuation: corrector did not converge in {0} iterations")]
    Corrector(usize),
    /// Non-finite values.
    #[error("continuation: non-finite value in {0}")]
    NonFinite(&'static str),
    /// A start state that is no equilibrium.
    #[error(transparent)]
    Newton(#[from] SolveError),
}

/// A located change along a branch: the first point past it, and the width
/// of the parameter's interval it lies in.
#[derive(Clone, Debug)]
pub struct Bracketed {
    /// The first point where the predicate fails.
    pub point: Point,
    /// |parameter there − parameter at the last point where it held|.
    pub within: f64,
}

/// Traces branches of equilibria of one rod in one parameter.
pub struct Tracer<'a> {
    /// Energy, factorisation workspace.
    pub newton: &'a mut Minimizer,
    /// The continuation parameter.
    pub parameter: Parameter,
    /// Settings.
    pub settings: ContinuationSettings,
    grad: Vec<f64>,
    values: Vec<f64>,
    fp: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    /// Weight of the dofs in the arclength norm (1/number of dofs).
    weight: f64,
    /// Number of free dofs (the multipliers follow them in the vectors).
    dofs: usize,
    /// Constrained laws: the KKT system.
    kkt: Option<Kkt>,
    /// Constraint rows of the last linearisation (allocation reused).
    rows: Vec<(f64, [f64; 11])>,
    /// Scratch of the measured round-off floor.
    floor: FloorProbe,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl<'a> Tracer<'a> {
    /// A tracer in `parameter`.
    pub fn new(
        newton: &'a mut Minimizer,
        parameter: Parameter,
        settings: ContinuationSettings,
    ) -> Self {
        let n = newton.energy.map.len();
        let kkt = newton.energy.penalty.map(|_| Kkt::new(&newton.energy));
        let dim = n + kkt.as_ref().map_or(0, |k| k.constraints);
        Tracer {
            newton,
            parameter,
            settings,
            grad: vec![0.0; dim],
            values: vec![],
            fp: vec![0.0; dim],
            a: vec![0.0; dim],
            b: vec![0.0; dim],
            weight: 1.0 / n as f64,
            dofs: n,
            kkt,
            rows: Vec::new(),
            floor: FloorProbe::default(),
        }
    }

    /// The factorisation of the last linearisation.
    fn solver(&mut self) -> &mut Ldlt {
        match &mut self.kkt {
            Some(k) => &mut k.ldlt,
            None => &mut self.newton.ldlt,
        }
    }

    /// Negative eigenvalues of the (reduced) Hessian at the last linearisation.
    fn negative_count(&self) -> usize {
        match &self.kkt {
            Some(k) => k.reduced_negative_count(),
            None => self.newton.ldlt.negative_count(),
        }
    }

    /// Dot product over the dofs (not the multipliers): the arclength metric.
    fn dot_q(&self, a: &[f64], b: &[f64]) -> f64 {
        dot(&a[..self.dofs], &b[..self.dofs])
    }

    /// Apply a step (dofs, then multipliers) and move the clamps.
    fn step_into(&self, from: &RodState, dq: &[f64], clamps: Clamps, next: &mut RodState) {
        let map = self.newton.energy.map;
        from.move_into(&map, &dq[..self.dofs], clamps, next);
        if self.kkt.is_some() {
            for (l, d) in next.multipliers[1..].iter_mut().zip(&dq[self.dofs..]) {
                *l += d;
            }
        }
    }

    /// Parameter value of a state.
    pub fn parameter_of(&self, state: &RodState) -> f64 {
        self.parameter.value(&state.clamps)
    }

    /// Evaluate gradient, Hessian, ∂_p∇E at `state` and factor H. Returns the
    /// relative gradient and whether the one convergence test
    /// ([`judge`]) holds.
    fn linearise(&mut self, state: &RodState) -> Result<(f64, bool), ContinuationError> {
        let energy = &self.newton.energy;
        let n = self.dofs;
        self.values.resize(energy.pattern.nnz(), 0.0);
        let info = energy.hessian(state, &mut self.grad[..n], &mut self.values);
        let velocity = self.parameter.velocity(state);
        energy.parameter_derivative(state, self.parameter, &mut self.fp[..n], &mut self.b[..n]);
        let gnorm = dot(&self.grad[..n], &self.grad[..n]).sqrt();
        let mut infeasibility = 0.0f64;
        if let Some(kkt) = &mut self.kkt {
            // residual (∇E + Jᵀ(λ + ρc), c) and its parameter derivative
            let rows = &mut self.rows;
            energy.constraint_rows_into(state, rows);
            for (g, r) in self.grad[n..].iter_mut().zip(rows.iter()) {
                *g = r.0;
            }
            energy.constraint_parameter_derivative(rows, &velocity, &mut self.fp[n..]);
            kkt.assemble(&self.values, rows);
            let h = energy.model.segment_length();
            infeasibility = rows.iter().map(|r| (r.0 / h).abs()).fold(0.0, f64::max);
        }
        if !gnorm.is_finite() || self.values.iter().any(|v| !v.is_finite()) {
            return Err(ContinuationError::NonFinite("gradient/Hessian"));
        }
        let max_diag = energy.pattern.max_abs_diagonal(&self.values);
        let bound = floor_bound(&info, max_diag, state, n);
        let floor = &mut self.floor;
        let judgement = judge(&info, gnorm, self.settings.tolerance, bound, || {
            floor.measure(energy, state)
        });
        let (rel, converged) = (judgement.rel, judgement.converged);
        crate::linalg::counters::set_residual(rel);
        let factored = match &mut self.kkt {
            Some(k) => k.ldlt.factor(&k.values),
            None => self.newton.ldlt.factor(&self.values),
        };
        factored.map_err(|_| ContinuationError::Singular("linearisation"))?;
        if infeasibility > crate::solve::sqp::CURVATURE_TOL {
            return Ok((rel.max(infeasibility), false));
        }
        Ok((rel, converged))
    }

    /// Tangent at a converged state (factorisation of `linearise` in place):
    /// (v, 1) with H v = -∂_p∇E, normalised, oriented along `orient`.
    fn tangent(&mut self, orient: Option<(&[f64], f64)>, sign: f64) -> (Vec<f64>, f64) {
        self.b.copy_from_slice(&self.fp);
        let mut b = std::mem::take(&mut self.b);
        self.solver().solve_in_place(&mut b);
        self.b = b;
        let v: Vec<f64> = self.b.iter().map(|x| -x).collect();
        let norm = (self.weight * self.dot_q(&v, &v) + 1.0).sqrt();
        let mut tq: Vec<f64> = v.iter().map(|x| x / norm).collect();
        let mut tp = 1.0 / norm;
        let s = match orient {
            Some((q, p)) => self.weight * self.dot_q(&tq, q) + tp * p,
            None => sign,
        };
        if s < 0.0 {
            tq.iter_mut().for_each(|x| *x = -*x);
            tp = -tp;
        }
        (tq, tp)
    }

    /// A branch point from an equilibrium `state`, its tangent oriented so that
    /// the parameter moves in the direction of `sign` (±1).
    pub fn start(&mut self, mut state: RodState, sign: f64) -> Result<Point, ContinuationError> {
        if let Some(k) = &self.kkt {
            state.multipliers.resize(k.constraints + 1, 0.0);
        }
        let (residual, _) = self.linearise(&state)?;
        let negative_count = self.negative_count();
        let (tangent_q, tangent_p) = self.tangent(None, sign);
        Ok(Point {
            state,
            tangent_q,
            tangent_p,
            negative_count,
            iterations: 0,
            residual,
            correction: 0.0,
            hessian: self.values.as_slice().into(),
        })
    }

    /// The converged point at `state`, from the linearisation just factored
    /// there: inertia, tangent (oriented along `orient`, else with the
    /// parameter increasing) and the Hessian for the stability analysis.
    fn point_at(
        &mut self,
        state: RodState,
        iterations: usize,
        residual: f64,
        orient: Option<(&[f64], f64)>,
        correction: f64,
    ) -> Point {
        let negative_count = self.negative_count();
        let (tangent_q, tangent_p) = self.tangent(orient, 1.0);
        Point {
            state,
            tangent_q,
            tangent_p,
            negative_count,
            iterations,
            residual,
            correction,
            hessian: self.values.as_slice().into(),
        }
    }

    /// A Newton step that moves a node by more than 0.05 (or is not finite)
    /// is not converging to the equilibrium it started near.
    fn runs_away(&self, dq: &[f64]) -> bool {
        let map = self.newton.energy.map;
        let largest = (0..self.dofs)
            .filter(|&d| map.is_translation(d))
            .map(|d| dq[d].abs())
            .fold(0.0, f64::max);
        largest > 0.05 || dq.iter().any(|v| !v.is_finite())
    }

    /// The point at arclength `sigma` from `from` along its tangent direction
    /// (`direction` overrides the tangent, e.g. a null vector at a branch point).
    pub fn correct(
        &mut self,
        from: &Point,
        sigma: f64,
        direction: Option<(&[f64], f64)>,
    ) -> Result<Point, ContinuationError> {
        let (tq, tp) = direction.unwrap_or((&from.tangent_q, from.tangent_p));
        let mut tq = tq.to_vec();
        tq.resize(self.a.len(), 0.0);
        let p_pred = self.parameter_of(&from.state) + sigma * tp;
        let mut state = from.state.clone();
        let mut next = from.state.clone();
        for (a, t) in self.a.iter_mut().zip(&tq) {
            *a = sigma * t;
        }
        self.step_into(
            &from.state,
            &self.a,
            self.parameter.with(&from.state.clamps, p_pred),
            &mut state,
        );
        let mut offset = vec![0.0; tq.len()];
        let mut p = p_pred;
        for it in 0..=self.settings.max_corrector_iterations {
            crate::linalg::counters::add_iteration();
            let (rel, converged) = self.linearise(&state)?;
            let c = self.weight * self.dot_q(&tq, &offset) + tp * (p - p_pred);
            if converged && c.abs() <= 1e-10 * sigma.abs().max(1e-12) {
                let correction =
                    (self.weight * self.dot_q(&offset, &offset) + (p - p_pred).powi(2)).sqrt()
                        / sigma.abs().max(1e-300);
                let orient = (from.tangent_q.as_slice(), from.tangent_p);
                return Ok(self.point_at(state, it, rel, Some(orient), correction));
            }
            if it == self.settings.max_corrector_iterations {
                break;
            }
            let (mut a, mut b) = (std::mem::take(&mut self.a), std::mem::take(&mut self.b));
            a.copy_from_slice(&self.grad);
            b.copy_from_slice(&self.fp);
            let solver = self.solver();
            solver.solve_in_place(&mut a);
            solver.solve_in_place(&mut b);
            (self.a, self.b) = (a, b);
            let denom = tp - self.weight * self.dot_q(&tq, &self.b);
            let dp = (-c + self.weight * self.dot_q(&tq, &self.a)) / denom;
            if !dp.is_finite() {
                return Err(ContinuationError::NonFinite("corrector"));
            }
            // the step dq = -a - dp b, in place of a
            for (a, b) in self.a.iter_mut().zip(&self.b) {
                *a = -*a - dp * b;
            }
            if self.runs_away(&self.a) {
                return Err(ContinuationError::Corrector(it + 1));
            }
            let dq = &self.a;
            p += dp;
            self.step_into(&state, dq, self.parameter.with(&state.clamps, p), &mut next);
            std::mem::swap(&mut state, &mut next);
            offset.iter_mut().zip(dq).for_each(|(o, d)| *o += d);
        }
        Err(ContinuationError::Corrector(
            self.settings.max_corrector_iterations,
        ))
    }

    /// The equilibrium at the clamps `target`, by Newton at fixed clamps from
    /// the equilibrium `from`. The first step is the linearised move of the
    /// equilibrium with the clamps (H dq = -(∇E + ∂_c∇E Δc)); the result
    /// carries its tangent in the tracer's parameter. Used to follow a
    /// condition across the plane of two parameters (`crate::study::boundary`).
    pub fn settle_at(
        &mut self,
        from: &RodState,
        target: Clamps,
    ) -> Result<Point, ContinuationError> {
        let n = self.dofs;
        let mut state = from.clone();
        if let Some(k) = &self.kkt {
            state.multipliers.resize(k.constraints + 1, 0.0);
        }
        let mut next = state.clone();
        // the clamps' move as a velocity: ∂_c∇E is linear in it
        let velocity = from.clamps.velocity_to(&target, from);
        for it in 0..=self.settings.max_corrector_iterations {
            crate::linalg::counters::add_iteration();
            let (rel, converged) = self.linearise(&state)?;
            if it > 0 && converged {
                return Ok(self.point_at(state, it, rel, None, 0.0));
            }
            if it == self.settings.max_corrector_iterations {
                break;
            }
            let mut a = std::mem::take(&mut self.a);
            a.copy_from_slice(&self.grad);
            if it == 0 {
                // ∂_c∇E Δc into the spare workspace `b`
                let energy = &self.newton.energy;
                let mut fc = std::mem::take(&mut self.b);
                energy.gradient_parameter_derivative(&state, &velocity, &mut fc[..n]);
                energy.add_scalar_changes(&state, &target, &mut fc[..n]);
                if self.kkt.is_some() {
                    energy.constraint_parameter_derivative(&self.rows, &velocity, &mut fc[n..]);
                }
                a.iter_mut().zip(&fc).for_each(|(x, f)| *x += f);
                self.b = fc;
            }
            self.solver().solve_in_place(&mut a);
            a.iter_mut().for_each(|x| *x = -*x);
            self.a = a;
            if self.runs_away(&self.a) {
                return Err(ContinuationError::Corrector(it + 1));
            }
            self.step_into(&state, &self.a, target, &mut next);
            std::mem::swap(&mut state, &mut next);
        }
        Err(ContinuationError::Corrector(
            self.settings.max_corrector_iterations,
        ))
    }

    /// Bisection in arclength on (0, sigma) for the change of a predicate that
    /// holds at `from` and fails at the point `sigma` away: returns the first
    /// point where it fails, within `locate_tolerance` in arclength.
    pub fn locate(
        &mut self,
        from: &Point,
        sigma: f64,
        same: &mut dyn FnMut(&mut Self, &Point) -> bool,
    ) -> Result<Point, ContinuationError> {
        self.locate_bracketed(from, sigma, same).map(|b| b.point)
    }

    /// [`Self::locate`], with the width of the parameter's interval the
    /// change was bisected to: `locate_tolerance`'s worth, or wider where
    /// the corrector failed near a singular point and the bisection stopped
    /// there.
    pub fn locate_bracketed(
        &mut self,
        from: &Point,
        sigma: f64,
        same: &mut dyn FnMut(&mut Self, &Point) -> bool,
    ) -> Result<Bracketed, ContinuationError> {
        let tolerance = self.settings.locate_tolerance;
        let b = bisect(
            0.0,
            sigma,
            |lo, hi| (hi - lo).abs() <= tolerance,
            |mid, b: &Bracket<f64, Point>| {
                // at a singular point itself the bordered system degenerates:
                // try nearby abscissae before giving up on more precision
                let width = b.hi - b.lo;
                for shift in [0.0, 0.1, -0.1, 0.2, -0.2] {
                    let at = mid + shift * width;
                    if let Ok(p) = self.correct(from, at, None) {
                        return Ok::<_, ContinuationError>(if same(self, &p) {
                            Probe::Holds(at, self.parameter_of(&p.state))
                        } else {
                            Probe::Fails(at, p)
                        });
                    }
                }
                Ok(Probe::Stop)
            },
        )?;
        let lo_value = b.holds.unwrap_or_else(|| self.parameter_of(&from.state));
        let point = match b.fails {
            Some(p) => p,
            None => self.correct(from, b.hi, None)?,
        };
        Ok(Bracketed {
            within: (self.parameter_of(&point.state) - lo_value).abs(),
            point,
        })
    }

    /// Lowest eigenvalue and its eigenvector of the Hessian at a point.
    pub fn lowest_mode(&mut self, point: &Point) -> Result<(f64, Vec<f64>), ContinuationError> {
        let energy = &self.newton.energy;
        self.values.resize(energy.pattern.nnz(), 0.0);
        energy.hessian(&point.state, &mut self.grad, &mut self.values);
        let sp = crate::linalg::eigen::lowest_eigenvalues(
            &energy.pattern,
            &self.values,
            None,
            2,
            &mut self.newton.ldlt,
        )
        .map_err(|_| ContinuationError::Singular("lowest mode"))?;
        // the mode nearest zero (at a branch point one eigenvalue vanishes)
        let k = if sp.values.len() > 1 && sp.values[1].abs() < sp.values[0].abs() {
            1
        } else {
            0
        };
        // constrained laws: the mode lives on the dofs, multipliers follow
        let mut v = sp.vectors[k].clone();
        v.resize(self.a.len(), 0.0);
        Ok((sp.values[k], v))
    }

    /// Cosine of the turn between the unit tangents of `a` and `b`, in the
    /// arclength metric (dofs weighted 1/dofs, multipliers not counted).
    pub fn turn(&self, a: &Point, b: &Point) -> f64 {
        self.weight * self.dot_q(&a.tangent_q, &b.tangent_q) + a.tangent_p * b.tangent_p
    }

    /// The acceptance rule of a step on a branch of equilibria.
    pub const ACCEPTANCE: Acceptance = Acceptance {
        max_iterations: 6,
        max_correction: 0.5,
        min_turn: 0.9,
        turn_free_below: 0.0,
    };

    /// One step along the branch from `from`: predictor, corrector,
    /// acceptance ([`Tracer::ACCEPTANCE`]) and step-size control, halving
    /// until a step is accepted. Returns the new point and the arclength it
    /// lies from `from`; None when the step fell below `min_step` (the branch
    /// is lost).
    pub fn advance(&mut self, from: &Point, step: &mut StepControl) -> Option<(Point, f64)> {
        step.advance(&Self::ACCEPTANCE, |sigma| {
            let b = self.correct(from, sigma, None)?;
            Ok::<_, ContinuationError>(Trial {
                iterations: b.iterations,
                correction: b.correction,
                turn: self.turn(from, &b),
                point: b,
            })
        })
        .ok()
    }

    /// The first point of a branch leaving the branch point `bp` along the
    /// null vector `null` (sign ±1), `sigma` away.
    pub fn switch(
        &mut self,
        bp: &Point,
        null: &[f64],
        sign: f64,
        sigma: f64,
    ) -> Result<Point, ContinuationError> {
        let norm = self.weighted_norm(null);
        // the null vector as the tangent, which also orients the new branch
        let fake = Point {
            tangent_q: null.iter().map(|x| sign * x / norm).collect(),
            tangent_p: 0.0,
            ..bp.clone()
        };
        self.correct(&fake, sigma, None)
    }

    /// Newton at the parameter value `target` from the branch point `near`:
    /// the corrector along the parameter axis.
    pub fn settle_at_parameter(
        &mut self,
        near: &Point,
        target: f64,
    ) -> Result<Point, ContinuationError> {
        let axis = Point {
            tangent_q: vec![0.0; near.tangent_q.len()],
            tangent_p: 1.0,
            ..near.clone()
        };
        let pn = self.parameter_of(&near.state);
        self.correct(&axis, target - pn, None)
    }

    /// Weighted norm of a dof vector.
    pub fn weighted_norm(&self, q: &[f64]) -> f64 {
        (self.weight * self.dot_q(q, q)).sqrt()
    }
}
