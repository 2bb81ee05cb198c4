//! What every minimiser shares: its settings, its report, its errors, the
//! Armijo line search and the relative residual test.

use crate::model::contact::{ContactForce, Gap};
use crate::model::energy::{GradientInfo, RodEnergy};
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

    /// The report of a point the continuation's corrector converged to, in
    /// `iterations` with relative gradient `rel`.
    pub fn of_corrector(iterations: usize, rel: f64, energy: f64) -> Self {
        SolveReport {
            converged: true,
            iterations,
            residual_history: vec![rel],
            gradient_norm: rel,
            energy,
            ..SolveReport::start()
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
    /// The gradient stopped decreasing above its measured round-off floor.
    #[error(
        "the gradient stalled above its measured round-off floor from Newton iteration \
         {iteration} on (‖∇E‖ {gradient:.3e}, floor {floor:.3e}, relative gradient \
         {residual:.3e}): the evaluation's rounding exceeds what the state's resolves; use \
         fewer segments or a smaller stretching stiffness (larger model.rod_diameter)"
    )]
    RoundOff {
        /// The iteration the stall began at.
        iteration: usize,
        /// Relative gradient there.
        residual: f64,
        /// ‖∇E‖ there.
        gradient: f64,
        /// The measured floor there.
        floor: f64,
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

/// The one convergence test of every solver (Newton, SQP, the continuation
/// corrector): the iterate is converged when its relative gradient (against
/// the scale of the internal forces) is at most `tol`, or when ‖∇E‖ is at its
/// *measured* round-off floor — the change of the gradient under one rounding
/// unit of every coordinate (`FloorProbe`), below which no step can reduce
/// it. The floor is measured only when ‖∇E‖ lies under `floor_bound`, an
/// upper bound of it (checked by `tests/reliability.rs`), so a solve far from
/// its floor costs nothing extra. Returns the relative gradient and the
/// measured floor when ‖∇E‖ is at it.
pub fn judge(
    info: &GradientInfo,
    gnorm: f64,
    tol: f64,
    bound: f64,
    measure: impl FnOnce() -> f64,
) -> Judgement {
    // no internal force at all (a rod at rest): only the floor can judge
    let rel = if info.force_scale > 0.0 {
        gnorm / info.force_scale
    } else if gnorm == 0.0 {
        0.0
    } else {
        f64::INFINITY
    };
    if rel <= tol {
        return Judgement {
            gradient: gnorm,
            rel,
            floor: None,
            converged: true,
        };
    }
    if gnorm > bound {
        return Judgement {
            gradient: gnorm,
            rel,
            floor: None,
            converged: false,
        };
    }
    let floor = measure();
    Judgement {
        gradient: gnorm,
        rel,
        floor: Some(floor),
        converged: gnorm <= floor,
    }
}

/// Iterates near the floor after which a gradient that has not halved is
/// stalled.
const STALL_ITERATIONS: usize = 20;

/// How near its floor a gradient must be for its failure to decrease to be
/// the rounding's: further up, a slow approach (capped steps from far away)
/// is progress, and the iteration budget judges it.
const NEAR_FLOOR: f64 = 4.0;

/// Watches for a gradient that stops decreasing above its measured floor, so
/// that such a solve ends with [`SolveError::RoundOff`] instead of running
/// out its iteration budget.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stall {
    best: Option<(usize, Judgement)>,
    near: usize,
}

impl Stall {
    /// Account for iterate `iteration`; the error once stalled.
    pub fn check(&mut self, iteration: usize, j: &Judgement) -> Result<(), SolveError> {
        let Some(floor) = j.floor.filter(|f| j.gradient <= NEAR_FLOOR * f) else {
            return Ok(());
        };
        match self.best {
            Some((_, b)) if j.gradient > 0.5 * b.gradient => self.near += 1,
            _ => {
                self.best = Some((iteration, *j));
                self.near = 0;
            }
        }
        match self.best {
            Some((at, b)) if self.near >= STALL_ITERATIONS => Err(SolveError::RoundOff {
                iteration: at,
                residual: b.rel,
                gradient: b.gradient,
                floor: b.floor.unwrap_or(floor),
            }),
            _ => Ok(()),
        }
    }
}

/// What [`judge`] found of one iterate.
#[derive(Clone, Copy, Debug)]
pub struct Judgement {
    /// ‖∇E‖.
    pub gradient: f64,
    /// ‖∇E‖ over the scale of the internal forces.
    pub rel: f64,
    /// The measured round-off floor of ‖∇E‖, where it was measured.
    pub floor: Option<f64>,
    /// Whether the iterate is an equilibrium to the tolerance or to the floor.
    pub converged: bool,
}

/// An upper bound of the round-off floor of ‖∇E‖: 16 ε × largest stiffness
/// × extent × √n plus 16 ε √n × the force scale (a gradient of forces that
/// cancel carries their rounding). Only a gate for measuring the floor,
/// never a criterion.
pub fn floor_bound(info: &GradientInfo, max_diagonal: f64, state: &RodState, dofs: usize) -> f64 {
    let extent = state.nodes.iter().map(|x| x.amax()).fold(0.0, f64::max);
    16.0 * f64::EPSILON
        * (dofs as f64).sqrt()
        * (max_diagonal * extent.max(1e-3) + info.force_scale)
}

/// ‖∇E‖ at a state beside its measured floor and the bound gating that
/// measurement, for reports and tests of the convergence test.
#[derive(Clone, Copy, Debug)]
pub struct FloorCheck {
    /// ‖∇E‖.
    pub gradient: f64,
    /// ‖∇E‖ over the scale of the internal forces (0 with no forces).
    pub rel: f64,
    /// The measured round-off floor ([`FloorProbe::measure`]).
    pub floor: f64,
    /// Its bound ([`floor_bound`]).
    pub bound: f64,
}

impl FloorCheck {
    /// The check at `state`, evaluated afresh.
    pub fn at(energy: &RodEnergy, state: &RodState) -> Self {
        let dofs = energy.map.len();
        let (mut grad, mut values) = (vec![0.0; dofs], vec![0.0; energy.pattern.nnz()]);
        let info = energy.hessian(state, &mut grad, &mut values);
        let gradient = grad.iter().map(|g| g * g).sum::<f64>().sqrt();
        let rel = if info.force_scale > 0.0 {
            gradient / info.force_scale
        } else {
            0.0
        };
        let max_diagonal = energy.pattern.max_abs_diagonal(&values);
        FloorCheck {
            gradient,
            rel,
            floor: FloorProbe::default().measure(energy, state),
            bound: floor_bound(&info, max_diagonal, state, dofs),
        }
    }

    /// Whether the state passes the convergence test at `tol`.
    pub fn passes(&self, tol: f64) -> bool {
        self.rel <= tol || self.gradient <= self.floor
    }
}

/// Scratch of the measured round-off floor, allocated on first use and
/// reused by every later measurement of the same solver.
#[derive(Clone, Debug, Default)]
pub struct FloorProbe {
    step: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    states: Option<(RodState, RodState)>,
}

impl FloorProbe {
    /// ¼‖∇E(x + δ) − ∇E(x − δ)‖ with δ one unit in the last place of every
    /// free coordinate (x ± δ are exact floats), in a fixed sign pattern: the
    /// change of the gradient under the largest rounding error of the state,
    /// half a unit, plus the evaluation's own rounding — what no Newton step
    /// can undo (a correctly rounded equilibrium's gradient is about 0.6 of
    /// it: its rounding errors spread evenly over ±½ unit). The signs are a fixed hash of the dof index, so the result
    /// does not depend on threads or runs.
    pub fn measure(&mut self, energy: &RodEnergy, state: &RodState) -> f64 {
        let map = energy.map;
        let n = map.len();
        self.step.resize(n, 0.0);
        self.plus.resize(n, 0.0);
        self.minus.resize(n, 0.0);
        let step = &mut self.step;
        for i in map.free_nodes() {
            let d = map.node(i).expect("a free node has dofs");
            for c in 0..3 {
                step[d + c] = sign(d + c) * ulp(state.nodes[i][c]);
            }
        }
        for j in map.free_angles() {
            let d = map.theta(j).expect("a free angle has a dof");
            step[d] = sign(d) * ulp(state.theta[j]);
        }
        let (plus, minus) = self
            .states
            .get_or_insert_with(|| (state.clone(), state.clone()));
        state.displace_into(&map, step, plus);
        step.iter_mut().for_each(|v| *v = -*v);
        state.displace_into(&map, step, minus);
        energy.gradient(plus, &mut self.plus);
        energy.gradient(minus, &mut self.minus);
        0.25 * self
            .plus
            .iter()
            .zip(&self.minus)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt()
    }
}

/// The spacing of the floats above |x| (0 at 0, which is exact).
fn ulp(x: f64) -> f64 {
    let a = x.abs();
    if a == 0.0 { 0.0 } else { a.next_up() - a }
}

/// ±1 from a fixed hash of `d` (splitmix64's finaliser).
fn sign(d: usize) -> f64 {
    let mut z = (d as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    if (z ^ (z >> 31)) & 1 == 0 { 1.0 } else { -1.0 }
}
