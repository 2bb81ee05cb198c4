//! The continuum branch through one parameter, and the points on it where a
//! test function vanishes, located to the integrator's tolerance: the
//! continuum polish of the discrete rod's events.
//!
//! A point of the branch is z = (p, λ): the six shooting unknowns and the
//! parameter. It is corrected by Newton's method on the six s = 1 conditions
//! with one coordinate of z held (λ itself, or at a fold an unknown along
//! which the branch passes the fold), and an event is the root of a test
//! function along the branch, found by the secant method (as AUTO-07p locates
//! its special points): folds and branch points where the shooting Jacobian
//! is singular (a bordered determinant), walls where an interior extremum of
//! the height touches a wall, crossings where the signed distance of two
//! strands vanishes. A strip of finite width is measured on its ribbon, the
//! surface r + v d1 for |v| ≤ w/2 ([`ContinuumBranch::on_ribbon`]): its
//! heights reach ±(w/2)|d1·e| past the centreline's, and two strands of it
//! first touch where an edge r ± (w/2) d1 of one crosses an edge of the
//! other ([`TestFunction::RibbonCrossing`]).

use crate::model::rod::{Clamps, Parameter, RodModel};
use crate::solve::continuum::{Continuum, ContinuumError, Frame, Trajectory, Unknowns};
use crate::solve::event::Vanishing;
use crate::solve::root::{Iterate, NoRoot, Reach, Secant, SecantFailure, Start};
use nalgebra::{Matrix6, SMatrix, SVector, Vector3, Vector6};

/// A point of the branch: the unknowns (0..6) and the parameter (6).
pub type BranchPoint = SVector<f64, 7>;

/// The coordinate of a [`BranchPoint`] that is the parameter.
pub const PARAMETER: usize = 6;

/// Corrector iterations before giving up.
const CORRECTOR_ITERATIONS: usize = 30;
/// The factor by which the integrator's tolerance is tightened to measure
/// its noise in the residual.
const NOISE_PROBE: f64 = 1e-2;
/// Secant steps before giving up.
const SECANT_ITERATIONS: usize = 40;
/// How far (in arclength, along each strand) the closest points of two
/// edges of a ribbon may lie from the centrelines' (at least 2 w).
const EDGE_REACH: f64 = 0.05;

/// Why the continuum branch or an event on it could not be computed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BranchError {
    /// The continuum problem itself failed.
    #[error(transparent)]
    Continuum(#[from] ContinuumError),
    /// The corrector did not converge.
    #[error("continuum corrector: residual {residual:.2e} after {iterations} iterations")]
    Corrector {
        /// Iterations made.
        iterations: usize,
        /// The last residual.
        residual: f64,
    },
    /// The test function did not change sign near the start, or the secant
    /// method did not converge.
    #[error("the test function's root was not found: {0}")]
    NoRoot(String),
}

/// Arclengths, and the lowest and highest heights across the section there.
pub type HeightRange = (Vec<f64>, Vec<f64>, Vec<f64>);

/// The family of continuum problems along one parameter.
#[derive(Clone, Debug)]
pub struct ContinuumBranch<'a> {
    model: &'a RodModel,
    clamps: Clamps,
    parameter: Parameter,
    /// Tolerance of the adaptive integrator.
    pub tolerance: f64,
    /// Width w/L of the ribbon on which walls are measured (0: the
    /// centreline).
    ribbon: f64,
}

/// A test function of the continuum branch: a [`Vanishing`] quantity with
/// what it needs to be evaluated (borders, arclengths to seek from).
#[derive(Clone, Debug, PartialEq)]
pub enum TestFunction {
    /// The shooting Jacobian is singular (fold, branch point, change of
    /// stability): the bordered determinant g of [[J, b], [cᵀ, 0]] [v; g] =
    /// [0; 1], with b and c the left and right singular vectors of the
    /// smallest singular value of J at the start.
    Singular {
        /// Border column b.
        left: Vector6<f64>,
        /// Border row c.
        right: Vector6<f64>,
    },
    /// An interior extremum of the height (along the s = 0 clamp's tangent)
    /// reaches a wall; the extremum is sought near arclength `s`.
    Wall {
        /// The top wall (height z*, moving with the clamps), else the
        /// bottom one (height 0).
        top: bool,
        /// Arclength of the extremum (updated as it moves).
        s: f64,
    },
    /// The walls, both: the smaller of the lowest interior extremum's
    /// height and the top wall minus the highest one's (the discrete
    /// boundary walk's condition), the extremum sought afresh along the
    /// whole centreline at every evaluation, so that whichever part of the
    /// rod comes nearest a wall counts.
    Walls,
    /// Two strands of the centreline pass through each other: the signed
    /// distance of their closest points, sought near arclengths `s`.
    Crossing {
        /// Arclengths of the two closest points (updated as they move).
        s: [f64; 2],
    },
    /// Two strands of the ribbon touch: the least of the signed distances
    /// of their four pairs of edges r ± (w/2) d1, each oriented as the
    /// centrelines' signed distance (positive while the ribbons are apart),
    /// sought near the centrelines' closest points at arclengths `s`. Two
    /// narrow ribbons crossing at an angle first touch edge to edge (the
    /// corner of their overlap), so this is their exact first touch.
    RibbonCrossing {
        /// Arclengths of the centrelines' closest points (updated).
        s: [f64; 2],
    },
    /// The closest points of two strands near arclengths `s` merge with
    /// another critical point of their distance (a pitchfork or fold of the
    /// closest approach: where two crossings of the same strands run into
    /// one, and a boundary's crossing piece ends on another): the
    /// determinant of the closest-point conditions' Jacobian there, which
    /// changes sign through the merger on the critical point that persists.
    Merging {
        /// Arclengths of the critical point (updated as it moves).
        s: [f64; 2],
    },
}

impl TestFunction {
    /// The quantity it measures.
    pub fn vanishing(&self) -> Vanishing {
        match self {
            TestFunction::Singular { .. } => Vanishing::Singularity,
            TestFunction::Wall { .. } | TestFunction::Walls => Vanishing::WallGap,
            TestFunction::Crossing { .. } => Vanishing::StrandGap,
            TestFunction::RibbonCrossing { .. } => Vanishing::RibbonGap,
            TestFunction::Merging { .. } => Vanishing::StrandMerger,
        }
    }
}

/// An event located on the continuum branch.
#[derive(Clone, Debug, PartialEq)]
pub struct Located {
    /// Where: the unknowns and the parameter.
    pub point: BranchPoint,
    /// The test function there (with its updated arclengths).
    pub test: TestFunction,
    /// Its value there.
    pub value: f64,
    /// Secant steps taken.
    pub steps: usize,
    /// The last secant step in the held coordinate: along the parameter,
    /// the step predicted from the last point and found too small to take.
    pub last_step: f64,
    /// The point before it.
    pub previous: BranchPoint,
}

impl Located {
    /// The error of the located parameter value. Along the parameter, the
    /// secant's next step, too small to take (the root's distance from the
    /// last point solved at, to the order of the step before it squared):
    /// not the gap to the point before, which is the error of that point
    /// and so grows the faster the iteration converged. Along an unknown
    /// held at a fold, the parameter's last change (stationary there).
    pub fn parameter_error(&self, held: usize) -> f64 {
        if held == PARAMETER {
            self.last_step.abs()
        } else {
            (self.point[PARAMETER] - self.previous[PARAMETER]).abs()
        }
    }
}

impl<'a> ContinuumBranch<'a> {
    /// The branch of `model` through `clamps` in `parameter`, integrated to
    /// `tolerance`.
    pub fn new(
        model: &'a RodModel,
        clamps: Clamps,
        parameter: Parameter,
        tolerance: f64,
    ) -> Result<Self, BranchError> {
        Continuum::of(model, clamps, tolerance)?;
        Ok(ContinuumBranch {
            model,
            clamps,
            parameter,
            tolerance,
            ribbon: 0.0,
        })
    }

    /// The same branch with its walls measured on the ribbon of width
    /// `width` (w/L, along d1) instead of the centreline.
    pub fn on_ribbon(self, width: f64) -> Self {
        ContinuumBranch {
            ribbon: width,
            ..self
        }
    }

    /// The same branch at another tolerance.
    pub fn with_tolerance(&self, tolerance: f64) -> Self {
        ContinuumBranch {
            tolerance,
            ..self.clone()
        }
    }

    /// The clamps at parameter value `value`.
    pub fn clamps_at(&self, value: f64) -> Clamps {
        self.parameter.with(&self.clamps, value)
    }

    /// The continuum problem at parameter value `value`.
    pub fn problem(&self, value: f64) -> Result<Continuum, BranchError> {
        Ok(Continuum::of(
            self.model,
            self.clamps_at(value),
            self.tolerance,
        )?)
    }

    /// The s = 1 residual at z and its Jacobian in all seven coordinates
    /// (the parameter's column by central differences: of the s = 1
    /// conditions alone where the parameter moves only that clamp).
    pub fn linearise(
        &self,
        z: &BranchPoint,
    ) -> Result<(Vector6<f64>, SMatrix<f64, 6, 7>), BranchError> {
        let p: Unknowns = z.fixed_rows::<6>(0).into();
        let (r, jp, end) = self.problem(z[PARAMETER])?.linearise_to_end(&p)?;
        let h = 1e-6 * (1.0 + z[PARAMETER].abs());
        // a parameter of the s = 1 clamp alone changes only the s = 1
        // conditions: their change on the same end state (two
        // integrations fewer, and free of the integrator's noise)
        let at = |value: f64| -> Result<Vector6<f64>, BranchError> {
            let problem = self.problem(value)?;
            Ok(if self.parameter.moves_end_only() {
                problem.residual_of_end(&end)
            } else {
                problem.residual(&p)?
            })
        };
        let (plus, minus) = (at(z[PARAMETER] + h)?, at(z[PARAMETER] - h)?);
        let mut jac = SMatrix::<f64, 6, 7>::zeros();
        jac.fixed_columns_mut::<6>(0).copy_from(&jp);
        jac.set_column(PARAMETER, &((plus - minus) / (2.0 * h)));
        Ok((r, jac))
    }

    /// A unit tangent of the branch at z (the null vector of the 6×7
    /// Jacobian; its sign is arbitrary).
    pub fn tangent(&self, z: &BranchPoint) -> Result<BranchPoint, BranchError> {
        let (_, jac) = self.linearise(z)?;
        null_vector(&jac).ok_or(BranchError::Continuum(ContinuumError::Singular))
    }

    /// [`Self::correct`] from a point that may already lie on the branch
    /// (a secant step's chord prediction near the root, two in five of a
    /// polish's corrections): its residual first, since the Jacobian's
    /// integration costs about twelve residuals'.
    fn correct_near(&self, z: BranchPoint, held: usize) -> Result<BranchPoint, BranchError> {
        if self
            .residual_at(&z)
            .is_ok_and(|r| r.norm() < self.corrector_tolerance())
        {
            return Ok(z);
        }
        self.correct(z, held)
    }

    /// The residual below which a point is on the branch.
    fn corrector_tolerance(&self) -> f64 {
        (10.0 * self.tolerance).max(1e-14)
    }

    /// Newton's method on the s = 1 conditions from `z` with coordinate
    /// `held` fixed: the point of the branch there.
    pub fn correct(&self, mut z: BranchPoint, held: usize) -> Result<BranchPoint, BranchError> {
        let tol = self.corrector_tolerance();
        let (mut r, mut jac) = self.linearise(&z)?;
        for iteration in 0..CORRECTOR_ITERATIONS {
            let residual = r.norm();
            if residual < tol {
                return Ok(z);
            }
            let mut a = Matrix6::zeros();
            let mut k = 0;
            for c in 0..7 {
                if c != held {
                    a.set_column(k, &jac.column(c));
                    k += 1;
                }
            }
            // a truncated SVD solve: a direction whose singular value is below
            // 1e-7 of the largest is a branch point's null direction, in
            // which the residual is often the integrator's noise (on a
            // symmetric branch through a pitchfork), and stepping along it
            // would amplify that noise. But a start off the symmetric branch
            // leaves a true residual there that only the full solve removes:
            // where directions were dropped, both steps are tried and the one
            // reaching the smaller residual taken
            let svd = a.svd(true, true);
            let largest = svd.singular_values.max();
            let cutoff = 1e-7 * largest;
            let truncated = svd.singular_values.iter().any(|&v| v < cutoff);
            let mut next: Option<(Vector6<f64>, BranchPoint)> = None;
            let mut solved = false;
            for eps in [cutoff, f64::EPSILON * largest] {
                if eps < cutoff && !truncated {
                    break;
                }
                let Some(dx) = svd
                    .solve(&(-r), eps)
                    .ok()
                    .filter(|d| d.iter().all(|v| v.is_finite()))
                else {
                    continue;
                };
                solved = true;
                let mut step = BranchPoint::zeros();
                let mut k = 0;
                for c in 0..7 {
                    if c != held {
                        step[c] = dx[k];
                        k += 1;
                    }
                }
                if let Some((rn, s)) = self.line_search(&z, &step, residual)
                    && next
                        .as_ref()
                        .is_none_or(|(best, _)| rn.norm() < best.norm())
                {
                    next = Some((rn, s));
                }
            }
            if !solved {
                return Err(ContinuumError::Singular.into());
            }
            let Some((rn, step)) = next else {
                // the residual no longer falls: converged if what remains is
                // the integrator's noise (near a branch point, whose null
                // direction amplifies it, that lies well above the tolerance)
                return self.at_noise(z, &r, iteration);
            };
            z += step;
            let scale = 1.0 + z.fixed_rows::<6>(0).norm();
            // converged: the Jacobian there is not needed
            if rn.norm() < tol {
                return Ok(z);
            }
            // a full step too small to move z: Newton is done, and z a
            // solution only if the residual left is noise (the truncated
            // solve cannot reduce a residual along a dropped null direction,
            // as just past a fold)
            if step.norm() < 1e-11 * scale {
                return self.at_noise(z, &rn, iteration + 1);
            }
            (r, jac) = self.linearise(&z)?;
        }
        self.at_noise(z, &r, CORRECTOR_ITERATIONS)
    }

    /// The Newton step from z halved while the residual does not fall below
    /// `residual` (a failed integration counts as not falling): the residual
    /// reached and the step taken. The trial points need only the residual,
    /// a fraction of the Jacobian's integration.
    fn line_search(
        &self,
        z: &BranchPoint,
        step: &BranchPoint,
        residual: f64,
    ) -> Option<(Vector6<f64>, BranchPoint)> {
        let mut t = 1.0;
        for _ in 0..10 {
            if let Ok(rn) = self.residual_at(&(z + t * step))
                && rn.norm() < residual
            {
                return Some((rn, t * step));
            }
            t *= 0.5;
        }
        None
    }

    /// z, where Newton's method made no more progress with residual `r`, if
    /// that residual is the integrator's noise: measured again at a hundredth
    /// of the tolerance, the residual left must be no larger than its change
    /// (the noise of the working tolerance). Otherwise z is not a solution.
    fn at_noise(
        &self,
        z: BranchPoint,
        r: &Vector6<f64>,
        iterations: usize,
    ) -> Result<BranchPoint, BranchError> {
        let refused = BranchError::Corrector {
            iterations,
            residual: r.norm(),
        };
        let Ok(fine) = self
            .with_tolerance(self.tolerance * NOISE_PROBE)
            .residual_at(&z)
        else {
            return Err(refused);
        };
        if fine.norm() <= (fine - r).norm() {
            Ok(z)
        } else {
            Err(refused)
        }
    }

    /// The s = 1 residual at z.
    fn residual_at(&self, z: &BranchPoint) -> Result<Vector6<f64>, BranchError> {
        let p: Unknowns = z.fixed_rows::<6>(0).into();
        Ok(self.problem(z[PARAMETER])?.residual(&p)?)
    }

    /// Frames at the increasing arclengths `stops`, on the solution at z.
    pub fn frames_at(&self, z: &BranchPoint, stops: &[f64]) -> Result<Vec<Frame>, BranchError> {
        let p: Unknowns = z.fixed_rows::<6>(0).into();
        Ok(self.problem(z[PARAMETER])?.frames_at(&p, stops)?)
    }

    /// The solution at z as its integrator's steps, for frames at many
    /// arclengths of one solution (a closest approach's Newton).
    pub fn trajectory(&self, z: &BranchPoint) -> Result<Trajectory, BranchError> {
        let p: Unknowns = z.fixed_rows::<6>(0).into();
        Ok(self.problem(z[PARAMETER])?.into_trajectory(&p)?)
    }

    /// The height of r along the s = 0 clamp's tangent (the walls' normal).
    fn height(&self, z: &BranchPoint, r: &Vector3<f64>) -> f64 {
        let c = self.clamps_at(z[PARAMETER]);
        (r - c.start_point()).dot(&c.start_tangent())
    }

    /// The test function at z (its arclengths updated to the solution
    /// there), and its value.
    pub fn evaluate(
        &self,
        z: &BranchPoint,
        test: &TestFunction,
    ) -> Result<(TestFunction, f64), BranchError> {
        match test {
            TestFunction::Singular { left, right } => {
                let p: Unknowns = z.fixed_rows::<6>(0).into();
                let (_, j) = self.problem(z[PARAMETER])?.linearise(&p)?;
                Ok((test.clone(), bordered_determinant(&j, left, right)?))
            }
            TestFunction::Wall { top, s } => {
                let (s, h) = self.extremum(z, &self.trajectory(z)?, *s, *top)?;
                // the top wall moves with z* along a branch in z*
                let wall = if *top {
                    self.clamps_at(z[PARAMETER]).top_wall()
                } else {
                    0.0
                };
                Ok((TestFunction::Wall { top: *top, s }, h - wall))
            }
            TestFunction::Walls => Ok((TestFunction::Walls, self.wall_gap(z)?)),
            TestFunction::Crossing { s } => {
                let (s, d, _) = self.closest_strands(&self.trajectory(z)?, *s)?;
                Ok((TestFunction::Crossing { s }, d))
            }
            TestFunction::RibbonCrossing { s } => {
                let (s, gap) = self.ribbon_gap(&self.trajectory(z)?, *s)?;
                Ok((TestFunction::RibbonCrossing { s }, gap))
            }
            TestFunction::Merging { s } => {
                let (s, _, det) = self.closest_strands(&self.trajectory(z)?, *s)?;
                Ok((TestFunction::Merging { s }, det))
            }
        }
    }

    /// The height of the solution at z at 199 interior points of the
    /// centreline (s = k/200): the arclengths and the heights.
    pub fn heights(&self, z: &BranchPoint) -> Result<(Vec<f64>, Vec<f64>), BranchError> {
        let (stops, low, _) = self.height_range(z)?;
        Ok((stops, low))
    }

    /// The lowest and highest heights across the section (the ribbon's
    /// edges, or the centreline's when it has no width) at the 199 interior
    /// points s = k/200: the arclengths, the lowest and the highest.
    pub fn height_range(&self, z: &BranchPoint) -> Result<HeightRange, BranchError> {
        const SAMPLES: usize = 200;
        let stops: Vec<f64> = (1..SAMPLES).map(|k| k as f64 / SAMPLES as f64).collect();
        let p: Unknowns = z.fixed_rows::<6>(0).into();
        let sampled = self.problem(z[PARAMETER])?.frames_sampled(&p, SAMPLES)?;
        let frames = &sampled[1..SAMPLES];
        let axis = self.clamps_at(z[PARAMETER]).start_tangent();
        let (low, high) = frames
            .iter()
            .map(|f| {
                let h = self.height(z, &f.r);
                let reach = 0.5 * self.ribbon * f.d1.dot(&axis).abs();
                (h - reach, h + reach)
            })
            .unzip();
        Ok((stops, low, high))
    }

    /// The smaller of the lowest interior extremum's height and the top
    /// wall minus the highest one's: the centreline sampled at 200 points,
    /// the local extremum nearest a wall refined by Newton.
    fn wall_gap(&self, z: &BranchPoint) -> Result<f64, BranchError> {
        let (stops, low, high) = self.height_range(z)?;
        let top = self.clamps_at(z[PARAMETER]).top_wall();
        // local minima against the bottom wall, maxima against the top
        let mut best: Option<(f64, usize, bool)> = None;
        for i in 1..low.len() - 1 {
            for (upper, gap) in [(false, low[i]), (true, top - high[i])] {
                let h = if upper { &high } else { &low };
                let sign = if upper { -1.0 } else { 1.0 };
                let extremal = sign * (h[i] - h[i - 1]) <= 0.0 && sign * (h[i] - h[i + 1]) <= 0.0;
                if extremal && best.is_none_or(|b| gap < b.0) {
                    best = Some((gap, i, upper));
                }
            }
        }
        let (_, i, upper) =
            best.ok_or_else(|| BranchError::NoRoot("no interior extremum of the height".into()))?;
        let (_, height) = self.extremum(z, &self.trajectory(z)?, stops[i], upper)?;
        Ok(if upper { top - height } else { height })
    }

    /// The interior extremum of the height nearest arclength `s0`: Newton
    /// on h'(s) = d3·e = 0 with h''(s) = d3'·e from the frame equations. On
    /// a ribbon, the extremum of its highest (`upper`) or lowest edge.
    fn extremum(
        &self,
        z: &BranchPoint,
        path: &Trajectory,
        s0: f64,
        upper: bool,
    ) -> Result<(f64, f64), BranchError> {
        if self.ribbon > 0.0 {
            return self.edge_extremum(z, path, s0, upper);
        }
        let axis = self.clamps_at(z[PARAMETER]).start_tangent();
        let mut s = s0;
        for _ in 0..30 {
            let (f, d) = frame_and_rate(path, s)?;
            let slope = f.d3.dot(&axis);
            let curvature = d.dot(&axis);
            if curvature == 0.0 || !curvature.is_finite() {
                break;
            }
            let step = -slope / curvature;
            s = (s + step).clamp(1e-6, 1.0 - 1e-6);
            if step.abs() < 1e-13 {
                let f = path.frames_at(&[s])?[0];
                return Ok((s, self.height(z, &f.r)));
            }
        }
        Err(BranchError::NoRoot(format!(
            "no interior extremum of the height near s = {s0:.4}"
        )))
    }

    /// The extremum nearest `s0` of the ribbon's height across its width,
    /// f(s) = h(s) ± (w/2)|d1·e| (+ for the highest edge, `upper`): Newton on
    /// f'(s) = d3·e ± (w/2) sgn(d1·e) d1'·e, its slope f'' by central
    /// differences. f is smooth at its extrema (|d1·e| only kinks where the
    /// ribbon is level across, a maximum of the lowest edge, never a minimum).
    fn edge_extremum(
        &self,
        z: &BranchPoint,
        path: &Trajectory,
        s0: f64,
        upper: bool,
    ) -> Result<(f64, f64), BranchError> {
        let axis = self.clamps_at(z[PARAMETER]).start_tangent();
        let sign = if upper { 1.0 } else { -1.0 };
        let half = 0.5 * self.ribbon;
        let value = |f: &Frame| self.height(z, &f.r) + sign * half * f.d1.dot(&axis).abs();
        let slope = |f: &Frame| {
            let across = f.d1.dot(&axis);
            f.d3.dot(&axis) + sign * half * across.signum() * f.d1_rate.dot(&axis)
        };
        const DS: f64 = 1e-5;
        let mut s = s0;
        for _ in 0..30 {
            let lo = (s - DS).max(1e-6);
            let hi = (s + DS).min(1.0 - 1e-6);
            let f = path.frames_at(&[lo, s, hi])?;
            let curvature = (slope(&f[2]) - slope(&f[0])) / (hi - lo);
            if curvature == 0.0 || !curvature.is_finite() {
                break;
            }
            let step = -slope(&f[1]) / curvature;
            s = (s + step).clamp(1e-6, 1.0 - 1e-6);
            if step.abs() < 1e-12 {
                let f = path.frames_at(&[s])?[0];
                return Ok((s, value(&f)));
            }
        }
        Err(BranchError::NoRoot(format!(
            "no interior extremum of the ribbon's height near s = {s0:.4}"
        )))
    }

    /// The ribbon's gap at two strands whose centrelines are closest near
    /// arclengths `s0`: the least over the four pairs of edges r ± (w/2) d1
    /// of their signed distance (along the edges' tangents' cross product),
    /// each turned positive on the side where the centrelines are apart.
    /// Each pair's closest points are found by Newton from the centrelines'
    /// (the edges' second derivatives by central differences); a pair with
    /// no closest approach within [`EDGE_REACH`] of the centrelines' (the
    /// edges turn away from each other there) cannot touch there and is
    /// left out.
    fn ribbon_gap(&self, path: &Trajectory, s0: [f64; 2]) -> Result<([f64; 2], f64), BranchError> {
        let (s, centre, _) = self.closest_strands(path, s0)?;
        let side = centre.signum();
        let mut gap = f64::INFINITY;
        for signs in [[1.0, 1.0], [1.0, -1.0], [-1.0, 1.0], [-1.0, -1.0]] {
            if let Some(signed) = self.edge_distance(path, s, signs)? {
                gap = gap.min(side * signed);
            }
        }
        if gap == f64::INFINITY {
            return Err(BranchError::NoRoot(format!(
                "no closest approach of the ribbon's edges near s = {:.4}, {:.4}",
                s[0], s[1]
            )));
        }
        Ok((s, gap))
    }

    /// The signed distance of edges `signs` (±1 each: r ± (w/2) d1) of two
    /// strands at their closest points near arclengths `s0`, along the
    /// cross product of their tangents; None if they have no closest
    /// approach (a minimum of their distance) within [`EDGE_REACH`].
    fn edge_distance(
        &self,
        path: &Trajectory,
        s0: [f64; 2],
        signs: [f64; 2],
    ) -> Result<Option<f64>, BranchError> {
        const DS: f64 = 1e-5;
        let half = 0.5 * self.ribbon;
        let tangent = |f: &Frame, sign: f64| f.d3 + sign * half * f.d1_rate;
        // position, tangent and rate of change of the tangent of one edge
        let edge = |s: f64, sign: f64| -> Result<_, BranchError> {
            let (lo, hi) = ((s - DS).max(0.0), (s + DS).min(1.0));
            let f = path.frames_at(&[lo, s, hi])?;
            let rate = (tangent(&f[2], sign) - tangent(&f[0], sign)) / (hi - lo);
            Ok((f[1].r + sign * half * f[1].d1, tangent(&f[1], sign), rate))
        };
        const MOVE: f64 = 0.01;
        let reach = EDGE_REACH.max(2.0 * self.ribbon);
        let mut t = s0;
        // a strand's end: its edge ends at the corner of the clamped end, and
        // the closest point stays there (a corner against an edge)
        let mut at_end = [false; 2];
        for _ in 0..100 {
            let (ca, ta, ra) = edge(t[0], signs[0])?;
            let (cb, tb, rb) = edge(t[1], signs[1])?;
            let d = ca - cb;
            let g = nalgebra::Vector2::new(d.dot(&ta), -d.dot(&tb));
            let jac = nalgebra::Matrix2::new(
                ta.dot(&ta) + d.dot(&ra),
                -tb.dot(&ta),
                -ta.dot(&tb),
                tb.dot(&tb) - d.dot(&rb),
            );
            let mut step = match at_end {
                [false, false] => {
                    // away from a closest approach (the distance's Hessian
                    // not positive) a descent step
                    let newton = (jac.determinant() > 0.0 && jac[(0, 0)] > 0.0)
                        .then(|| jac.lu().solve(&(-g)))
                        .flatten();
                    newton.unwrap_or(-g)
                }
                [true, true] => nalgebra::Vector2::zeros(),
                _ => {
                    let k = usize::from(at_end[0]);
                    let mut step = nalgebra::Vector2::zeros();
                    step[k] = if jac[(k, k)] > 0.0 {
                        -g[k] / jac[(k, k)]
                    } else {
                        -g[k]
                    };
                    step
                }
            };
            // steps no longer than MOVE: where the edges cross at a shallow
            // angle the first Newton steps overshoot
            if step.norm() > MOVE {
                step *= MOVE / step.norm();
            }
            // stationary (where two closest approaches merge, at a crossing
            // on the flip axis, Newton crawls, but the distance is flat)
            let free_gradient = (0..2).filter(|&k| !at_end[k]).map(|k| g[k].abs());
            if step.norm() < 1e-12 || free_gradient.fold(0.0, f64::max) < 1e-12 {
                return Ok(signed_along(&d, &ta, &tb));
            }
            for k in 0..2 {
                t[k] += step[k];
                if !(0.0..=1.0).contains(&t[k]) {
                    t[k] = t[k].clamp(0.0, 1.0);
                    at_end[k] = true;
                }
            }
            if (t[0] - s0[0]).abs().max((t[1] - s0[1]).abs()) > reach {
                return Ok(None);
            }
        }
        Ok(None)
    }

    /// The closest points of two strands near arclengths `s0` (Newton on
    /// the two orthogonality conditions), their signed distance, positive
    /// along t_a × t_b, and the determinant of the conditions' Jacobian.
    fn closest_strands(
        &self,
        path: &Trajectory,
        s0: [f64; 2],
    ) -> Result<([f64; 2], f64, f64), BranchError> {
        let mut s = s0;
        // next to a merger of critical points Newton converges only
        // linearly (by 2/3 a step at a pitchfork)
        for _ in 0..100 {
            let (fa, ra) = frame_and_rate(path, s[0])?;
            let (fb, rb) = frame_and_rate(path, s[1])?;
            let d = fa.r - fb.r;
            let g = nalgebra::Vector2::new(d.dot(&fa.d3), -d.dot(&fb.d3));
            let jac = nalgebra::Matrix2::new(
                1.0 + d.dot(&ra),
                -fb.d3.dot(&fa.d3),
                -fa.d3.dot(&fb.d3),
                1.0 - d.dot(&rb),
            );
            let det = jac.determinant();
            let Some(step) = jac.lu().solve(&(-g)) else {
                break;
            };
            s = [
                (s[0] + step[0]).clamp(0.0, 1.0),
                (s[1] + step[1]).clamp(0.0, 1.0),
            ];
            if step.norm() < 1e-13 {
                // each from its own step end, as in the iterations
                let f = [path.frames_at(&[s[0]])?[0], path.frames_at(&[s[1]])?[0]];
                let normal = f[0].d3.cross(&f[1].d3);
                if normal.norm() < 1e-8 {
                    break;
                }
                let signed = (f[0].r - f[1].r).dot(&normal) / normal.norm();
                return Ok((s, signed, det));
            }
        }
        Err(BranchError::NoRoot(format!(
            "no closest approach of the strands near s = {:.4}, {:.4}",
            s0[0], s0[1]
        )))
    }

    /// The root of `test` along the branch from `start` (on the branch or
    /// near it), holding coordinate `held` and stepping it first by `step`:
    /// secant steps in the held coordinate, each point corrected onto the
    /// branch, until the step is below `resolution`.
    pub fn locate(
        &self,
        start: BranchPoint,
        held: usize,
        step: f64,
        resolution: f64,
        test: TestFunction,
    ) -> Result<Located, BranchError> {
        let za = self.correct(start, held)?;
        let (test, ga) = self.evaluate(&za, &test)?;
        let mut zb = za;
        zb[held] += step;
        zb = self.correct(zb, held)?;
        let (test, gb) = self.evaluate(&zb, &test)?;
        let iterate = |z: BranchPoint, value, test| Iterate {
            at: z[held],
            value,
            point: (z, test),
        };
        let secant = Secant {
            max_evaluations: SECANT_ITERATIONS,
            tolerance: resolution,
            reach: Reach::Chord {
                factor: 1e3,
                floor: step.abs(),
            },
            ..Secant::default()
        };
        let start = Start::Chord(iterate(za, ga, test.clone()), iterate(zb, gb, test));
        // the predictor: the secant of the branch through the last two points
        type Solved = Iterate<(BranchPoint, TestFunction)>;
        let next = |_: f64, dc: f64, b: &Solved, a: Option<&Solved>| {
            let (zb, test) = &b.point;
            let predicted = match a {
                Some(Iterate { point: (za, _), .. }) => zb + dc / (zb[held] - za[held]) * (zb - za),
                None => *zb,
            };
            let zc = self.correct_near(predicted, held)?;
            let (test, gc) = self.evaluate(&zc, test)?;
            Ok::<_, BranchError>(iterate(zc, gc, test))
        };
        // held at a fold, an unknown is only the path: the located quantity
        // is the parameter, stationary there, and converged once it no
        // longer moves at the integrator's tolerance (the test's noise may
        // keep the unknown from reaching `resolution`)
        let settled = |a: &Solved, b: &Solved| {
            let (za, zb) = (&a.point.0, &b.point.0);
            held != PARAMETER
                && (zb[PARAMETER] - za[PARAMETER]).abs()
                    < self.tolerance * (1.0 + zb[PARAMETER].abs())
                && a.value.signum() != b.value.signum()
        };
        match secant.find(start, next, settled) {
            Ok(root) => {
                let (point, test) = root.last.point;
                Ok(Located {
                    point,
                    test,
                    value: root.last.value,
                    steps: root.iterations,
                    last_step: root.step,
                    previous: root.previous.map_or(point, |p| p.point.0),
                })
            }
            Err(SecantFailure {
                why: NoRoot::Failed(e),
                ..
            }) => Err(e),
            Err(SecantFailure {
                values: [ga, gb], ..
            }) => Err(BranchError::NoRoot(format!(
                "secant steps in coordinate {held} did not converge (last values {ga:.3e}, {gb:.3e})"
            ))),
        }
    }
}

/// The component of `d` along ta × tb (None for parallel tangents).
fn signed_along(d: &Vector3<f64>, ta: &Vector3<f64>, tb: &Vector3<f64>) -> Option<f64> {
    let normal = ta.cross(tb);
    (normal.norm() >= 1e-8).then(|| d.dot(&normal) / normal.norm())
}

/// Index of the smallest singular value.
fn smallest(values: &[f64]) -> Option<usize> {
    values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map(|(k, _)| k)
}

/// The null vector of a full-rank 6×7 matrix (unit length).
fn null_vector(a: &SMatrix<f64, 6, 7>) -> Option<BranchPoint> {
    // the 7th right singular vector of the 7×7 matrix padded with a zero row
    let mut m = SMatrix::<f64, 7, 7>::zeros();
    m.fixed_rows_mut::<6>(0).copy_from(a);
    let svd = m.svd(false, true);
    let k = smallest(svd.singular_values.as_slice())?;
    Some(svd.v_t?.row(k).transpose())
}

/// The left and right singular vectors of the smallest singular value of J.
pub fn singular_borders(j: &Matrix6<f64>) -> Option<(Vector6<f64>, Vector6<f64>)> {
    let svd = j.svd(true, true);
    let k = smallest(svd.singular_values.as_slice())?;
    Some((svd.u?.column(k).into(), svd.v_t?.row(k).transpose()))
}

/// g of [[J, b], [cᵀ, 0]] [v; g] = [0; 1]: zero exactly where J is singular,
/// and smooth through it.
fn bordered_determinant(
    j: &Matrix6<f64>,
    b: &Vector6<f64>,
    c: &Vector6<f64>,
) -> Result<f64, BranchError> {
    let mut m = SMatrix::<f64, 7, 7>::zeros();
    m.fixed_view_mut::<6, 6>(0, 0).copy_from(j);
    m.fixed_view_mut::<6, 1>(0, 6).copy_from(b);
    m.fixed_view_mut::<1, 6>(6, 0).copy_from(&c.transpose());
    let mut rhs = SVector::<f64, 7>::zeros();
    rhs[6] = 1.0;
    m.lu()
        .solve(&rhs)
        .map(|x| x[6])
        .ok_or(BranchError::Continuum(ContinuumError::Singular))
}

/// The frame at s and d3'(s).
fn frame_and_rate(path: &Trajectory, s: f64) -> Result<(Frame, Vector3<f64>), BranchError> {
    let f = path.frames_at(&[s])?[0];
    Ok((f, f.curvature))
}
