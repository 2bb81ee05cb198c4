//! The continuum equilibrium integrated to a tolerance: the Kirchhoff
//! equations (A.2) and the strip's (A.1 with 4.3) from the six shooting
//! unknowns at s = 0, by the one integrator of the continuum equations
//! (`model::ode`: adaptive Dormand–Prince 8(5,3)), with the energy and the
//! weight's potential integrated alongside. This is the independent check of
//! `knotrod verify`: it shares the equations' right-hand sides with
//! `shooting.rs` and `strip_shooting.rs` and nothing of the discrete rod.
//!
//! The solvers of the continuum equations live here (`solve`), the equations
//! themselves in `model` (`model::shooting`, `model::strip_shooting`: the
//! right-hand sides, the s = 1 conditions, the strip's law): [`newton`] is
//! Newton shooting, [`shooting`] refines the reference solutions by it,
//! [`branch`] continues a continuum solution in a clamp parameter and locates
//! events on it, [`stability`] counts and finds the frequencies of the
//! linearised problem by shooting its determinant.

pub mod branch;
pub mod newton;
pub mod shooting;
pub mod stability;

use crate::model::energy::strip_energy;
use crate::model::natural::NaturalStrains;
use crate::model::ode::{
    Integrated, IntegrationError, Steps, integrate, integrate_dense, integrate_steps,
    integrate_stops,
};
use crate::model::rod::{Clamps, EndKind, Law, RodModel};
use crate::model::shooting::{
    OdeState, end_conditions, part, rhs_loaded, rhs_loaded_derivative, start_frame,
};
use crate::model::strip_shooting::{StripOdeState, StripRhs, sadowsky, strip_rhs};
use crate::solve::continuum::newton::{NewtonShootingFailure, newton_shooting};
use nalgebra::{Matrix6, SVector, Vector3, Vector6};
use std::f64::consts::PI;

/// The s = 1 residual, its Jacobian in the unknowns, and the state at s = 1
/// they came from (r, d1, d2, d3, n, m, ∫u3: a strip's strains left out).
pub(crate) type Linearised = (Vector6<f64>, Matrix6<f64>, OdeState);

/// Why a continuum solution could not be made.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ContinuumError {
    /// The model has no continuum counterpart here.
    #[error("the continuum check does not cover {0}")]
    Unsupported(&'static str),
    /// A shooting unknown is NaN or infinite.
    #[error("shooting unknown {0} is not finite")]
    NotFinite(usize),
    /// The adaptive integrator stopped before s = 1.
    #[error("continuum: {0}")]
    Integration(#[from] IntegrationError),
    /// Newton did not bring the s = 1 residual below its tolerance.
    #[error(
        "shooting Newton did not converge in {iterations} iterations (residual {residual:.3e})"
    )]
    NotConverged {
        /// Iterations made.
        iterations: usize,
        /// The last residual's norm.
        residual: f64,
    },
    /// The Jacobian of the s = 1 conditions is singular or not finite.
    #[error("shooting Newton: singular or non-finite Jacobian of the s = 1 conditions")]
    Singular,
}

/// The constitutive law the continuum equations take.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContinuumLaw {
    /// Kirchhoff rod, unknowns n(0), m(0) in the s = 0 material frame.
    Kirchhoff {
        /// B22 / B11.
        k2: f64,
        /// B33 / B11.
        k3: f64,
    },
    /// Sadowsky strip, unknowns n(0), u1(0), m2(0), u3(0) (paper Sec. 4).
    Strip {
        /// ε of the DER's law.
        regularisation: f64,
    },
}

/// One continuum boundary-value problem: the law, loads and clamps.
#[derive(Clone, Debug)]
pub struct Continuum {
    /// The law.
    pub law: ContinuumLaw,
    /// Body force w g per unit length (lab frame).
    pub weight: Vector3<f64>,
    /// Natural strains û(s).
    pub natural: NaturalStrains,
    /// The clamps (s = 0 frame and the s = 1 conditions).
    pub clamps: Clamps,
    /// Relative and absolute tolerance of the adaptive integrator.
    pub tolerance: f64,
}

/// The six shooting unknowns at s = 0: n(0), m(0) for a rod; n(0), u1(0),
/// m2(0), u3(0) for a strip.
pub type Unknowns = Vector6<f64>;

/// A continuum solution from given unknowns.
#[derive(Clone, Debug)]
pub struct ContinuumSolution {
    /// The s = 1 conditions' mismatch (r − r*, d3 off the clamp's tangent,
    /// angle of d1; pinned: r − r*, m; free: n, m).
    pub end_residual: Vector6<f64>,
    /// n(0) in the s = 0 material frame.
    pub n0: Vector3<f64>,
    /// m(0) in the s = 0 material frame.
    pub m0: Vector3<f64>,
    /// Tw = (1/2π) ∫ u3 ds.
    pub twist: f64,
    /// Elastic energy minus the weight's work, ∫ (W − w g·r) ds.
    pub energy: f64,
    /// r(s) at s = k / (len − 1) (empty unless samples were asked for).
    pub centreline: Vec<Vector3<f64>>,
    /// Steps the integrator took.
    pub steps: u32,
}

/// A polished solution: the unknowns Newton shooting converged to.
#[derive(Clone, Debug)]
pub struct Polished {
    /// The unknowns.
    pub unknowns: Unknowns,
    /// The s = 1 residual's norm there.
    pub residual: f64,
    /// Newton iterations.
    pub iterations: usize,
}

/// Converged when the s = 1 residual's norm is below this.
const NEWTON_TOL: f64 = 1e-10;
const NEWTON_ITERATIONS: usize = 40;

// the rod's state (A.2) then ∫W ds and ∫ w g·r ds
const ROD: usize = 21;
// the strip's state then ∫W ds and ∫ w g·r ds
const STRIP: usize = 23;
// the rod's state (A.2) and its derivatives in the six unknowns
pub(crate) const VARIATIONAL: usize = 19 * 7;
// the strip's state and its derivatives in the six unknowns
pub(crate) const STRIP_VARIATIONAL: usize = 21 * 7;

fn check_finite(p: &Unknowns) -> Result<(), ContinuumError> {
    match p.iter().position(|v| !v.is_finite()) {
        Some(k) => Err(ContinuumError::NotFinite(k)),
        None => Ok(()),
    }
}

/// The centreline point and material frame at one s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// r(s).
    pub r: Vector3<f64>,
    /// d1(s).
    pub d1: Vector3<f64>,
    /// d2(s).
    pub d2: Vector3<f64>,
    /// d3(s) = r'(s).
    pub d3: Vector3<f64>,
    /// d3'(s) = r''(s).
    pub curvature: Vector3<f64>,
    /// d1'(s): how the ribbon's edges r ± (w/2) d1 turn.
    pub d1_rate: Vector3<f64>,
}

/// The frame of a state `y` (r, d1, d2, d3 first) with its rate `dy`.
fn frame(y: &[f64], dy: &[f64]) -> Frame {
    Frame {
        r: Vector3::from_column_slice(&y[0..3]),
        d1: Vector3::from_column_slice(&y[3..6]),
        d2: Vector3::from_column_slice(&y[6..9]),
        d3: Vector3::from_column_slice(&y[9..12]),
        curvature: Vector3::from_column_slice(&dy[9..12]),
        d1_rate: Vector3::from_column_slice(&dy[3..6]),
    }
}

/// The frames of uniform samples y_k (s = k / (len − 1)) of y' = f(s, y).
fn sampled_frames<const D: usize>(
    ys: &[SVector<f64, D>],
    f: impl Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
) -> Vec<Frame> {
    let ds = 1.0 / (ys.len().max(2) - 1) as f64;
    ys.iter()
        .enumerate()
        .map(|(k, y)| frame(y.as_slice(), f(k as f64 * ds, y).as_slice()))
        .collect()
}

/// A continuum solution kept as its integrator's steps
/// ([`Continuum::into_trajectory`]).
pub struct Trajectory {
    continuum: Continuum,
    path: Path,
}

/// The steps of a rod's or a strip's integration, with its law.
enum Path {
    Rod {
        steps: Steps<ROD>,
        k2: f64,
        k3: f64,
    },
    Strip {
        steps: Steps<STRIP>,
        regularisation: f64,
    },
}

impl Trajectory {
    /// The frames at the increasing arclengths `stops`: from the step end
    /// at or before the first, then from stop to stop, so that stops close
    /// together (a central difference) come from one piece of integration.
    pub fn frames_at(&self, stops: &[f64]) -> Result<Vec<Frame>, ContinuumError> {
        let c = &self.continuum;
        Ok(match &self.path {
            Path::Rod { steps, k2, k3 } => {
                let f = |s: f64, y: &SVector<f64, ROD>| c.rod_rhs(s, y, *k2, *k3);
                let ys = steps.at(stops, f, c.tolerance)?;
                ys.iter()
                    .zip(stops)
                    .map(|(y, &s)| frame(y.as_slice(), f(s, y).as_slice()))
                    .collect()
            }
            Path::Strip {
                steps,
                regularisation,
            } => {
                let f = |s: f64, y: &SVector<f64, STRIP>| c.strip_rhs(s, y, *regularisation);
                let ys = steps.at(stops, f, c.tolerance)?;
                ys.iter()
                    .zip(stops)
                    .map(|(y, &s)| frame(y.as_slice(), f(s, y).as_slice()))
                    .collect()
            }
        })
    }
}

/// The rate of a state (`core`, its rate `value`) and of its six
/// perturbations (the blocks of `y` after it, each the state's size) by the
/// equations' `derivative`; with `lambda` = ω² the perturbations obey the
/// linearised dynamics (A.4): each n̄_i' gains −ω² r̄·d_i (unit mass per
/// length, no rotary inertia).
fn with_perturbations<const C: usize, const V: usize>(
    y: &SVector<f64, V>,
    core: &SVector<f64, C>,
    value: SVector<f64, C>,
    derivative: impl Fn(&SVector<f64, C>) -> SVector<f64, C>,
    lambda: f64,
) -> SVector<f64, V> {
    let mut dy = SVector::<f64, V>::zeros();
    dy.fixed_rows_mut::<C>(0).copy_from(&value);
    for c in 1..7 {
        let delta: SVector<f64, C> = y.fixed_rows::<C>(C * c).into();
        let mut jd = derivative(&delta);
        if lambda != 0.0 {
            let r = part(&delta, 0);
            for i in 0..3 {
                jd[12 + i] -= lambda * r.dot(&part(core, 1 + i));
            }
        }
        dy.fixed_rows_mut::<C>(C * c).copy_from(&jd);
    }
    dy
}

impl Continuum {
    /// The continuum problem of a discrete rod model at `clamps`.
    /// The model's scalars that the clamps carry (a branch in K3 or the
    /// weight) apply.
    pub fn of(model: &RodModel, clamps: Clamps, tolerance: f64) -> Result<Self, ContinuumError> {
        let scaled;
        let model = if clamps.scalars.is_unset() {
            model
        } else {
            scaled = clamps.scalars.apply(model);
            &scaled
        };
        let law = match model.law {
            Law::Kirchhoff => ContinuumLaw::Kirchhoff {
                k2: model.k2,
                k3: model.k3,
            },
            Law::Strip { regularisation } => {
                if !clamps.start.is_default() {
                    return Err(ContinuumError::Unsupported(
                        "a strip with a general s = 0 clamp",
                    ));
                }
                if clamps.ends.end != EndKind::Clamped {
                    return Err(ContinuumError::Unsupported(
                        "a strip with a pinned or free end",
                    ));
                }
                ContinuumLaw::Strip { regularisation }
            }
            Law::Unbendable => {
                return Err(ContinuumError::Unsupported("the unbendable rod (K2 → ∞)"));
            }
        };
        if clamps.ends.start != EndKind::Clamped {
            return Err(ContinuumError::Unsupported(
                "a rod whose s = 0 end is not clamped (the shooting starts there)",
            ));
        }
        Ok(Continuum {
            law,
            weight: Vector3::from(model.weight),
            natural: model.natural_strains.clone(),
            clamps,
            tolerance,
        })
    }

    /// The rod's state (A.2) at s = 0 from the unknowns n(0), m(0), then
    /// ∫W ds and ∫ w g·r ds.
    fn rod_start(&self, p: &Unknowns) -> SVector<f64, ROD> {
        let mut y0 = SVector::<f64, ROD>::zeros();
        y0.fixed_rows_mut::<19>(0)
            .copy_from(&start_frame(&self.clamps));
        for c in 0..6 {
            y0[12 + c] = p[c];
        }
        y0
    }

    /// The rod's right-hand side with the energy density and the weight's
    /// potential alongside.
    fn rod_rhs(&self, s: f64, y: &SVector<f64, ROD>, k2: f64, k3: f64) -> SVector<f64, ROD> {
        let core: OdeState = y.fixed_rows::<19>(0).into();
        let mut dy = SVector::<f64, ROD>::zeros();
        let natural = self.natural.vector_at(s);
        dy.fixed_rows_mut::<19>(0)
            .copy_from(&rhs_loaded(&core, k2, k3, &self.weight, &natural));
        let m = part(y, 5);
        dy[19] = 0.5 * (m[0] * m[0] + m[1] * m[1] / k2 + m[2] * m[2] / k3);
        dy[20] = self.weight.dot(&part(y, 0));
        dy
    }

    /// The strip's state at s = 0 from n(0), u1(0), m2(0), u3(0), and m(0).
    pub(crate) fn strip_start(
        &self,
        p: &Unknowns,
        regularisation: f64,
    ) -> (SVector<f64, STRIP>, Vector3<f64>) {
        let mut y0 = SVector::<f64, STRIP>::zeros();
        let a0 = p[3] - self.natural.at(0.0)[0];
        let (m13, _) = sadowsky(a0, p[5], regularisation);
        let m0 = Vector3::new(m13[0], p[4], m13[1]);
        y0[3] = 1.0;
        y0[7] = 1.0;
        y0[11] = 1.0;
        for c in 0..3 {
            y0[12 + c] = p[c];
            y0[15 + c] = m0[c];
        }
        y0[18] = a0;
        y0[19] = p[5];
        (y0, m0)
    }

    /// The strip's state at s = 0 and its derivatives in the six unknowns
    /// n(0), u1(0), m2(0), u3(0): m1(0), m3(0) follow u1(0), u3(0) through
    /// the law's gradient, so their derivatives are its Hessian.
    pub(crate) fn strip_variational_start(
        &self,
        p: &Unknowns,
        regularisation: f64,
    ) -> SVector<f64, STRIP_VARIATIONAL> {
        let mut y0 = SVector::<f64, STRIP_VARIATIONAL>::zeros();
        y0.fixed_rows_mut::<21>(0)
            .copy_from(&self.strip_start(p, regularisation).0.fixed_rows::<21>(0));
        let (_, h) = sadowsky(y0[18], y0[19], regularisation);
        for c in 0..3 {
            y0[21 * (c + 1) + 12 + c] = 1.0;
        }
        // u1(0) moves a(0), m1(0) and m3(0); m2(0) itself; u3(0) likewise
        for (c, strain, column) in [(3, 18, 0), (5, 19, 1)] {
            let block = 21 * (c + 1);
            y0[block + strain] = 1.0;
            y0[block + 15] = h[(0, column)];
            y0[block + 17] = h[(1, column)];
        }
        y0[21 * 5 + 16] = 1.0;
        y0
    }

    /// The strip's equations and their exact linearisation along six
    /// perturbations; with `lambda` = ω² each n̄_i' gains −ω² r̄·d_i (A.4).
    pub(crate) fn strip_variational_rhs(
        &self,
        s: f64,
        y: &SVector<f64, STRIP_VARIATIONAL>,
        regularisation: f64,
        lambda: f64,
    ) -> SVector<f64, STRIP_VARIATIONAL> {
        let core: StripOdeState = y.fixed_rows::<21>(0).into();
        let rhs = StripRhs::at(s, &core, regularisation, &self.weight, &self.natural);
        with_perturbations(y, &core, rhs.value, |delta| rhs.derivative(delta), lambda)
    }

    /// The strip's right-hand side with the energy density and the weight's
    /// potential alongside.
    fn strip_rhs(
        &self,
        s: f64,
        y: &SVector<f64, STRIP>,
        regularisation: f64,
    ) -> SVector<f64, STRIP> {
        let core: StripOdeState = y.fixed_rows::<21>(0).into();
        let mut dy = SVector::<f64, STRIP>::zeros();
        dy.fixed_rows_mut::<21>(0).copy_from(&strip_rhs(
            s,
            &core,
            regularisation,
            &self.weight,
            &self.natural,
        ));
        dy[21] = strip_energy(y[18], y[19], regularisation, 1.0);
        dy[22] = self.weight.dot(&part(y, 0));
        dy
    }

    /// Integrate from `p`, with r(s) at `samples` points if `samples` ≥ 2.
    pub fn solve(&self, p: &Unknowns, samples: usize) -> Result<ContinuumSolution, ContinuumError> {
        check_finite(p)?;
        match self.law {
            ContinuumLaw::Kirchhoff { k2, k3 } => {
                let f = |s: f64, y: &SVector<f64, ROD>| self.rod_rhs(s, y, k2, k3);
                let solved = integrate(self.rod_start(p), f, self.tolerance, samples)?;
                Ok(self.solution(p, p.fixed_rows::<3>(3).into(), solved, 18))
            }
            ContinuumLaw::Strip { regularisation } => {
                let (y0, m0) = self.strip_start(p, regularisation);
                let f = |s: f64, y: &SVector<f64, STRIP>| self.strip_rhs(s, y, regularisation);
                let solved = integrate(y0, f, self.tolerance, samples)?;
                Ok(self.solution(p, m0, solved, 20))
            }
        }
    }

    /// The centreline and material frame at each of the increasing `stops`
    /// in [0, 1], from `p`.
    pub fn frames_at(&self, p: &Unknowns, stops: &[f64]) -> Result<Vec<Frame>, ContinuumError> {
        check_finite(p)?;
        Ok(match self.law {
            ContinuumLaw::Kirchhoff { k2, k3 } => {
                let f = |s: f64, y: &SVector<f64, ROD>| self.rod_rhs(s, y, k2, k3);
                let (ys, _) = integrate_stops(self.rod_start(p), f, self.tolerance, stops)?;
                ys.iter()
                    .zip(stops)
                    .map(|(y, &s)| frame(y.as_slice(), f(s, y).as_slice()))
                    .collect()
            }
            ContinuumLaw::Strip { regularisation } => {
                let f = |s: f64, y: &SVector<f64, STRIP>| self.strip_rhs(s, y, regularisation);
                let y0 = self.strip_start(p, regularisation).0;
                let (ys, _) = integrate_stops(y0, f, self.tolerance, stops)?;
                ys.iter()
                    .zip(stops)
                    .map(|(y, &s)| frame(y.as_slice(), f(s, y).as_slice()))
                    .collect()
            }
        })
    }

    /// The solution from `p` as its integrator's steps: frames anywhere on
    /// it at the cost of about one step each ([`Trajectory::frames_at`]).
    pub fn into_trajectory(self, p: &Unknowns) -> Result<Trajectory, ContinuumError> {
        check_finite(p)?;
        let path = match self.law {
            ContinuumLaw::Kirchhoff { k2, k3 } => {
                let f = |s: f64, y: &SVector<f64, ROD>| self.rod_rhs(s, y, k2, k3);
                Path::Rod {
                    steps: integrate_steps(self.rod_start(p), f, self.tolerance)?,
                    k2,
                    k3,
                }
            }
            ContinuumLaw::Strip { regularisation } => {
                let f = |s: f64, y: &SVector<f64, STRIP>| self.strip_rhs(s, y, regularisation);
                let y0 = self.strip_start(p, regularisation).0;
                Path::Strip {
                    steps: integrate_steps(y0, f, self.tolerance)?,
                    regularisation,
                }
            }
        };
        Ok(Trajectory {
            continuum: self,
            path,
        })
    }

    /// The frames at s = k / `intervals`, k = 0..=intervals, from `p`, by
    /// one integration and its dense output (of order 7, to about the
    /// integrator's tolerance): for scanning the solution, not for a value
    /// a root is located on.
    pub fn frames_sampled(
        &self,
        p: &Unknowns,
        intervals: usize,
    ) -> Result<Vec<Frame>, ContinuumError> {
        check_finite(p)?;
        let samples = intervals.max(1) + 1;
        Ok(match self.law {
            ContinuumLaw::Kirchhoff { k2, k3 } => {
                let f = |s: f64, y: &SVector<f64, ROD>| self.rod_rhs(s, y, k2, k3);
                let ys = integrate_dense(self.rod_start(p), f, self.tolerance, samples)?;
                sampled_frames(&ys, f)
            }
            ContinuumLaw::Strip { regularisation } => {
                let f = |s: f64, y: &SVector<f64, STRIP>| self.strip_rhs(s, y, regularisation);
                let y0 = self.strip_start(p, regularisation).0;
                let ys = integrate_dense(y0, f, self.tolerance, samples)?;
                sampled_frames(&ys, f)
            }
        })
    }

    /// The s = 1 residual and its Jacobian in the unknowns. For a rod, the
    /// Jacobian comes from the variational equations integrated with the
    /// solution (the right-hand side of (A.2) is quadratic in the state, so
    /// its directional derivative is an exact central difference); for a
    /// strip likewise, its linearisation exact through the law's third
    /// derivatives (`StripRhs`).
    pub fn linearise(&self, p: &Unknowns) -> Result<(Vector6<f64>, Matrix6<f64>), ContinuumError> {
        self.linearise_to_end(p).map(|(r, jac, _)| (r, jac))
    }

    /// [`Self::linearise`], with the state at s = 1 it came from: the
    /// residual under other s = 1 clamps is
    /// [`Self::residual_of_end`] of it, no integration.
    pub(crate) fn linearise_to_end(&self, p: &Unknowns) -> Result<Linearised, ContinuumError> {
        check_finite(p)?;
        // the end state and its six derivatives as r, d1, d2, d3, n, m, ∫u3
        let (core, deltas): (OdeState, [OdeState; 6]) = match self.law {
            ContinuumLaw::Kirchhoff { k2, k3 } => {
                let y0 = self.variational_start(p);
                let f =
                    |s: f64, y: &SVector<f64, VARIATIONAL>| self.variational_rhs(s, y, k2, k3, 0.0);
                let end = integrate_stops(y0, f, self.tolerance, &[1.0])?.0[0];
                let cut = |k: usize| -> OdeState { end.fixed_rows::<19>(19 * k).into() };
                (cut(0), std::array::from_fn(|c| cut(c + 1)))
            }
            ContinuumLaw::Strip { regularisation } => {
                let y0 = self.strip_variational_start(p, regularisation);
                let f = |s: f64, y: &SVector<f64, STRIP_VARIATIONAL>| {
                    self.strip_variational_rhs(s, y, regularisation, 0.0)
                };
                let end = integrate_stops(y0, f, self.tolerance, &[1.0])?.0[0];
                // the strip's a and u3 (18, 19) have no place in the rod's state
                let cut =
                    |k: usize| OdeState::from_fn(|i, _| end[21 * k + if i < 18 { i } else { 20 }]);
                (cut(0), std::array::from_fn(|c| cut(c + 1)))
            }
        };
        let residual_of = |y: &OdeState| self.residual_of_end(y);
        let r = residual_of(&core);
        let mut jac = Matrix6::zeros();
        for (c, delta) in deltas.iter().enumerate() {
            // the s = 1 conditions are smooth functions of the end state:
            // their derivative along ∂y(1)/∂p_c by central differences
            let h = 1e-6 / delta.norm().max(1e-300);
            let col =
                (residual_of(&(core + h * delta)) - residual_of(&(core - h * delta))) / (2.0 * h);
            jac.set_column(c, &col);
        }
        if jac.iter().any(|v| !v.is_finite()) {
            return Err(ContinuumError::Singular);
        }
        Ok((r, jac, core))
    }

    /// The s = 1 conditions of this problem's clamps on a rod's state at
    /// s = 1.
    pub(crate) fn residual_of_end(&self, y: &OdeState) -> Vector6<f64> {
        self.end_residual(
            [part(y, 0), part(y, 1), part(y, 3)],
            (part(y, 4), part(y, 5)),
        )
    }

    /// The rod's state at s = 0 from `p` and its derivatives in the six
    /// unknowns (unit vectors of n(0) and m(0)'s components).
    pub(crate) fn variational_start(&self, p: &Unknowns) -> SVector<f64, VARIATIONAL> {
        let mut y0 = SVector::<f64, VARIATIONAL>::zeros();
        y0.fixed_rows_mut::<19>(0)
            .copy_from(&self.rod_start(p).fixed_rows::<19>(0));
        for c in 0..6 {
            y0[19 * (c + 1) + 12 + c] = 1.0;
        }
        y0
    }

    /// (A.2) and its linearisation along six perturbations; with `lambda` =
    /// ω² the perturbations obey the linearised dynamics (A.4): each n̄_i'
    /// gains −ω² r̄·d_i (unit mass per length, no rotary inertia).
    pub(crate) fn variational_rhs(
        &self,
        s: f64,
        y: &SVector<f64, VARIATIONAL>,
        k2: f64,
        k3: f64,
        lambda: f64,
    ) -> SVector<f64, VARIATIONAL> {
        let natural = self.natural.vector_at(s);
        let core: OdeState = y.fixed_rows::<19>(0).into();
        let value = rhs_loaded(&core, k2, k3, &self.weight, &natural);
        let derivative =
            |delta: &OdeState| rhs_loaded_derivative(&core, delta, k2, k3, &self.weight, &natural);
        with_perturbations(y, &core, value, derivative, lambda)
    }

    /// The solution from an integration whose state holds r, d1, d2, d3, n,
    /// m first, then ∫u3 ds at `twist`, ∫W ds and ∫ w g·r ds after it.
    fn solution<const D: usize>(
        &self,
        p: &Unknowns,
        m0: Vector3<f64>,
        Integrated {
            end,
            samples: dense,
            steps,
        }: Integrated<D>,
        twist: usize,
    ) -> ContinuumSolution {
        ContinuumSolution {
            end_residual: self.end_residual(
                [part(&end, 0), part(&end, 1), part(&end, 3)],
                (part(&end, 4), part(&end, 5)),
            ),
            n0: p.fixed_rows::<3>(0).into(),
            m0,
            twist: end[twist] / (2.0 * PI),
            energy: end[twist + 1] - end[twist + 2],
            centreline: dense.iter().map(|y| part(y, 0)).collect(),
            steps,
        }
    }

    pub(crate) fn end_residual(
        &self,
        rd: [Vector3<f64>; 3],
        nm: (Vector3<f64>, Vector3<f64>),
    ) -> Vector6<f64> {
        end_conditions(rd, nm, &self.clamps)
    }

    /// The s = 1 residual from `p`.
    pub fn residual(&self, p: &Unknowns) -> Result<Vector6<f64>, ContinuumError> {
        Ok(self.solve(p, 0)?.end_residual)
    }

    /// Newton shooting from `p` on the six s = 1 conditions (Jacobian of
    /// [`Self::linearise`], steps halved while the residual grows).
    pub fn polish(&self, p: &Unknowns) -> Result<Polished, ContinuumError> {
        self.residual(p)?;
        // a failed integration inside the Jacobian counts as an infinite residual
        let res = |q: &Vector6<f64>| {
            self.residual(q)
                .unwrap_or_else(|_| Vector6::repeat(f64::INFINITY))
        };
        // the exact Jacobian (variational equations for a rod): quadratic
        // convergence down to the integrator's tolerance
        let jacobian = |q: &Vector6<f64>| {
            self.linearise(q)
                .map_or_else(|_| Matrix6::repeat(f64::NAN), |(_, j)| j)
        };
        match newton_shooting(*p, res, jacobian, NEWTON_TOL, NEWTON_ITERATIONS, 12) {
            Ok((unknowns, residual, iterations)) => Ok(Polished {
                unknowns,
                residual,
                iterations,
            }),
            Err(NewtonShootingFailure::Singular) => Err(ContinuumError::Singular),
            Err(NewtonShootingFailure::NotConverged {
                iterations,
                residual,
            }) => Err(ContinuumError::NotConverged {
                iterations,
                residual,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::shooting::ShootingSolution;
    use crate::solve::continuum::newton::central_jacobian;
    use crate::solve::continuum::shooting::refine_shooting;

    fn appendix_d() -> (Continuum, Unknowns) {
        let clamps = Clamps::new(0.115, 0.05, 0.802);
        let c = Continuum {
            law: ContinuumLaw::Kirchhoff { k2: 3.0, k3: 3.0 },
            weight: Vector3::zeros(),
            natural: NaturalStrains::default(),
            clamps,
            tolerance: 1e-12,
        };
        let p = Unknowns::new(-24.743, 17.772, 37.145, 7.5317, -8.7100, 4.529);
        (c, p)
    }

    #[test]
    fn polishing_by_variational_equations_finds_the_reference_shootings_solution() {
        // the same problem by the reference shooting (Newton with the
        // Jacobian by central differences of whole integrations)
        let (c, p) = appendix_d();
        let (n, m) = refine_shooting(
            p.fixed_rows::<3>(0).into(),
            p.fixed_rows::<3>(3).into(),
            3.0,
            3.0,
            &c.clamps,
        )
        .unwrap();
        let polished = c.polish(&p).unwrap();
        let reference = Unknowns::new(n[0], n[1], n[2], m[0], m[1], m[2]);
        assert!(polished.residual < NEWTON_TOL);
        assert!(
            (polished.unknowns - reference).norm() < 1e-9 * reference.norm(),
            "{} vs {}",
            polished.unknowns,
            reference
        );
        let tw = ShootingSolution::integrate(n, m, 3.0, 3.0, 1)
            .unwrap()
            .twist();
        let sol = c.solve(&polished.unknowns, 0).unwrap();
        assert!((sol.twist - tw).abs() < 1e-10, "{} vs {tw}", sol.twist);
    }

    #[test]
    fn the_energy_is_the_integral_of_the_density() {
        // a rod bent into a circle arc by a pure moment: u1 = m1 everywhere,
        // E = m1² / 2; n = 0 and m = (m1, 0, 0) are constant
        let c = Continuum {
            law: ContinuumLaw::Kirchhoff { k2: 2.0, k3: 5.0 },
            weight: Vector3::zeros(),
            natural: NaturalStrains::default(),
            clamps: Clamps::new(0.5, 0.0, 0.0),
            tolerance: 1e-12,
        };
        let sol = c
            .solve(&Unknowns::new(0.0, 0.0, 0.0, 1.3, 0.0, 0.0), 11)
            .unwrap();
        assert!((sol.energy - 0.5 * 1.3 * 1.3).abs() < 1e-12);
        // the arc of radius 1/1.3 in the (y, z) plane
        for k in [3, 10] {
            let (r, a, s) = (sol.centreline[k], 1.3f64, k as f64 / 10.0);
            let arc = Vector3::new(0.0, -(1.0 - (a * s).cos()) / a, (a * s).sin() / a);
            assert!((r - arc).norm() < 1e-11, "{k}: {}", (r - arc).norm());
        }
        assert_eq!(sol.centreline.len(), 11);
    }

    #[test]
    fn the_variational_jacobian_is_the_difference_quotient() {
        // with a weight and natural strains, which keep (A.2) quadratic
        let (mut c, p) = appendix_d();
        c.weight = Vector3::new(0.3, -0.2, 1.5);
        c.natural = NaturalStrains::Constant([0.4, -0.3, 0.2]);
        let (r, jac) = c.linearise(&p).unwrap();
        assert!((r - c.residual(&p).unwrap()).norm() < 1e-10);
        let fd = central_jacobian(&p, |q| c.residual(q).unwrap());
        let err = (jac - fd).norm() / jac.norm();
        assert!(err < 1e-7, "relative difference {err:.2e}");
    }

    #[test]
    fn the_strips_variational_jacobian_is_the_difference_quotient() {
        // a strip with weight and natural curvature, away from equilibrium
        let c = Continuum {
            law: ContinuumLaw::Strip {
                regularisation: 0.02,
            },
            weight: Vector3::new(0.4, 0.1, -0.8),
            natural: NaturalStrains::Constant([0.5, 0.0, 0.0]),
            clamps: Clamps::new(0.1, 0.05, 0.9),
            tolerance: 1e-12,
        };
        let p = Unknowns::new(0.3, -0.2, 0.5, 4.0 * PI, 0.1, 0.4);
        let (r, jac, end) = c.linearise_to_end(&p).unwrap();
        assert!((r - c.residual(&p).unwrap()).norm() < 1e-10);
        assert!((c.residual_of_end(&end) - r).norm() < 1e-14);
        let fd = central_jacobian(&p, |q| c.residual(q).unwrap());
        let err = (jac - fd).norm() / jac.norm();
        assert!(err < 1e-7, "relative difference {err:.2e}");
    }

    #[test]
    fn bad_unknowns_are_named() {
        let (c, mut p) = appendix_d();
        p[4] = f64::NAN;
        assert_eq!(c.solve(&p, 0).unwrap_err(), ContinuumError::NotFinite(4));
    }
}
