//! The continuum polish of a branch's events: each fold, branch point,
//! change of stability, wall and self-crossing that the discrete rod located
//! is located again on the continuum branch (solve::continuum::branch), from
//! the discrete equilibrium there, to the integrator's tolerance. The two
//! answers side by side give the discrete rod's error at its N, and the
//! polished value carries its own error estimate (the change when the
//! tolerance falls a hundredfold).

use crate::analysis::equilibrium::{Measure, self_approach};
use crate::analysis::event::{ContinuumEvent, Event, EventKind, PolishFailure};
use crate::model::rod::{Parameter, RodModel, RodState};
use crate::solve::continuum::branch::{
    BranchError, BranchPoint, ContinuumBranch, Located, PARAMETER, TestFunction, singular_borders,
};
use crate::solve::continuum::{ContinuumError, Unknowns};
use crate::solve::event::Vanishing;
use rayon::prelude::*;

/// Tolerance of the integrator for the polish (its error estimate comes from
/// a second pass at a hundredth of it).
pub const POLISH_TOLERANCE: f64 = 1e-10;

/// The resolution (relative) to which a fold is located in the unknown held
/// there: the located state's error along the branch.
pub const FOLD_RESOLUTION: f64 = 1e-7;

/// Why an event or a boundary could not be polished on the continuum.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PolishError {
    /// The event has no continuum test (or its test cannot start there).
    #[error("{0}")]
    Event(PolishFailure),
    /// The continuum branch failed.
    #[error(transparent)]
    Branch(#[from] BranchError),
    /// A point of a traced boundary failed from both sides.
    #[error("{first}; across the other way: {second}")]
    BothWays {
        /// Across the first way.
        first: Box<PolishError>,
        /// Across the other way.
        second: Box<PolishError>,
    },
    /// A corner failed along both curves.
    #[error("{first}; along the other curve: {second}")]
    AlongOther {
        /// Along the first curve.
        first: Box<PolishError>,
        /// Along the other.
        second: Box<PolishError>,
    },
    /// A boundary point failed, and again from its nearest polished neighbour.
    #[error("{first}; from the nearest polished point: {second}")]
    FromNeighbour {
        /// From the discrete point.
        first: Box<PolishError>,
        /// From the neighbour.
        second: Box<PolishError>,
    },
    /// A failure with where it happened (a boundary's phase, piece, point).
    #[error("{at}: {source}")]
    At {
        /// Where.
        at: String,
        /// What.
        source: Box<PolishError>,
    },
    /// The traced boundary has no pieces.
    #[error("no boundary to polish")]
    NoBoundary,
    /// A walk point carries no discrete equilibrium to start from.
    #[error("no discrete equilibrium")]
    NoDiscreteEquilibrium,
    /// A corner's piece has no polished point to start from.
    #[error("no polished point")]
    NoPolishedPoint,
    /// A crossing of a clamp's closing ray has no continuum test.
    #[error("a crossing of a clamp's ray is not polished")]
    ClampRayCrossing,
    /// A crossing names a segment past the centreline's end.
    #[error("no segment {0} on the centreline")]
    NoSegment(usize),
    /// The root lies too far from its start (another extremum's or branch's).
    #[error("the root moved {moved:.2e} from its start, more than {reach:.2e}")]
    Moved {
        /// How far it moved in the free coordinate.
        moved: f64,
        /// How far it may.
        reach: f64,
    },
    /// The rod at the root passes through a wall.
    #[error("the root at ({:.5}, {:.5}) is not between the walls", at[0], at[1])]
    OutsideWalls {
        /// The root in the plane.
        at: [f64; 2],
    },
    /// A corner's secant iteration failed.
    #[error("the corner's secant steps {0}")]
    Corner(CornerFailure),
    /// A corner's secant step would leave the corner.
    #[error("the corner's secant step {0:.2e} left the corner")]
    CornerLeft(f64),
    /// Too many of a boundary's points failed for its area to mean much.
    #[error("{failed} of {of} points failed, the first: {first}")]
    TooManyFailed {
        /// Points that failed.
        failed: usize,
        /// Points in all.
        of: usize,
        /// The first failure.
        first: Box<PolishError>,
    },
}

/// How a corner's secant iteration failed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CornerFailure {
    /// It took its iterations without converging (nor stalling).
    #[error("did not converge")]
    NotConverged,
    /// The test along the curve was flat or undefined.
    #[error("met a flat or undefined test ({0:.2e})")]
    Flat(f64),
    /// A step's root or test failed.
    #[error("{0}")]
    Step(Box<PolishError>),
}

impl From<ContinuumError> for PolishError {
    fn from(e: ContinuumError) -> Self {
        PolishError::Branch(e.into())
    }
}

impl PolishError {
    /// The failure as data on an event.
    pub fn failure(&self) -> PolishFailure {
        match self {
            PolishError::Event(f) => f.clone(),
            PolishError::NoBoundary => PolishFailure::NoBoundary,
            PolishError::TooManyFailed { failed, of, first } => PolishFailure::TooManyFailed {
                failed: *failed,
                of: *of,
                first: Box::new(first.failure()),
            },
            e => PolishFailure::Continuum {
                message: e.to_string(),
            },
        }
    }

    /// This failure, placed `at` a phase or point.
    pub fn at(self, at: impl Into<String>) -> Self {
        PolishError::At {
            at: at.into(),
            source: Box::new(self),
        }
    }
}

/// Polish every event of `events` that has a continuum counterpart, from the
/// equilibria `located` there (`located[k]` at `events[k]`), on the branch
/// in `parameter` of `model`. Events at one place share one polish; one that
/// cannot be polished says why in its `not_polished`.
pub fn polish_events(
    model: &RodModel,
    parameter: Parameter,
    measure: &Measure,
    events: &mut [Event],
    located: &[RodState],
) {
    // one polish per (branch, class, place)
    let mut groups: Vec<(Vanishing, usize, Vec<usize>)> = Vec::new();
    for (k, e) in events.iter().enumerate() {
        let Some(c) = e.kind.vanishing() else {
            continue;
        };
        if k >= located.len() {
            continue;
        }
        let value = parameter.value(&located[k].clamps);
        match groups.iter_mut().find(|(gc, first, _)| {
            *gc == c
                && events[*first].branch == e.branch
                && (parameter.value(&located[*first].clamps) - value).abs() < 1e-9
        }) {
            Some(g) => g.2.push(k),
            None => groups.push((c, k, vec![k])),
        }
    }
    let results: Vec<Result<ContinuumEvent, PolishError>> = groups
        .par_iter()
        .map(|(c, first, members)| {
            // a fold is a fold whichever event of its place is polished
            let fold = members.iter().any(|&k| events[k].kind == EventKind::Fold);
            polish_one(model, parameter, measure, &located[*first], *c, fold)
        })
        .collect();
    for ((_, _, members), result) in groups.iter().zip(results) {
        for &k in members {
            match &result {
                Ok(c) => events[k].continuum = Some(c.clone()),
                Err(why) => events[k].not_polished = Some(why.failure()),
            }
        }
    }
}

/// The discrete rod's shooting unknowns at `state`: its clamp reactions
/// (n(0), m(0)) for a rod, n(0), u1(0), m2(0), u3(0) for a strip.
pub fn discrete_unknowns(model: &RodModel, state: &RodState) -> Unknowns {
    use crate::model::energy::{RodEnergy, Terms};
    use crate::model::rod::Law;
    use crate::model::strip_shooting::StripUnknowns;
    let energy = RodEnergy::with_ends(model.clone(), Terms::ALL, state.clamps.ends);
    if matches!(model.law, Law::Strip { .. }) {
        let p = StripUnknowns::from_der(&energy, state);
        Unknowns::new(p.n0[0], p.n0[1], p.n0[2], p.u1, p.m2, p.u3)
    } else {
        let r = energy.clamp_reactions(state);
        Unknowns::new(
            r.force[0],
            r.force[1],
            r.force[2],
            r.moment[0],
            r.moment[1],
            r.moment[2],
        )
    }
}

/// The test function of an event whose quantity `c` vanishes at the discrete `state`.
fn test_function(
    branch: &ContinuumBranch,
    z: &BranchPoint,
    state: &RodState,
    measure: &Measure,
    c: Vanishing,
) -> Result<TestFunction, PolishError> {
    match c {
        Vanishing::Singularity => singular_at(branch, z),
        Vanishing::WallGap => {
            // the interior node nearest a wall (of a ribbon: its lowest or
            // highest point across the width there)
            let (points, arc) = state.centreline();
            let (origin, axis) = (state.clamps.start_point(), state.clamps.start_tangent());
            let top = state.clamps.top_wall();
            let n = state.segments();
            let half = 0.5 * measure.strip_width;
            let (mut best, mut on_top, mut s) = (f64::INFINITY, false, 0.5);
            for i in 1..=n.min(points.len() - 2) {
                let h = (points[i] - origin).dot(&axis);
                let reach = half * state.directors(i.min(n - 1))[0].dot(&axis).abs();
                for (w, t, h) in [(0.0, false, h - reach), (top, true, h + reach)] {
                    if (h - w).abs() < best {
                        (best, on_top, s) = ((h - w).abs(), t, arc[i]);
                    }
                }
            }
            Ok(TestFunction::Wall { top: on_top, s })
        }
        Vanishing::StrandGap => {
            // the centrelines' crossing, also of a ribbon (its knot changes)
            let centreline = Measure {
                strip_width: 0.0,
                ..measure.clone()
            };
            let approach = self_approach(state, &centreline)
                .ok_or(PolishError::Event(PolishFailure::NoSelfApproach))?;
            // a strand passing through a ray, not through the centreline
            if approach.distance > 2.0 / state.segments() as f64 {
                return Err(PolishError::Event(PolishFailure::RayCrossing {
                    distance: approach.distance,
                }));
            }
            Ok(TestFunction::Crossing { s: approach.s })
        }
        Vanishing::RibbonGap => {
            // the ribbon's pieces touch: sought from the centrelines'
            // closest points across from where they do
            let approach = self_approach(state, measure)
                .ok_or(PolishError::Event(PolishFailure::NoSelfApproach))?;
            Ok(TestFunction::RibbonCrossing { s: approach.s })
        }
        // no event kind carries a merger of critical points
        Vanishing::StrandMerger => Err(PolishError::Event(PolishFailure::Merger)),
    }
}

/// One event located on the continuum branch from the discrete `state`.
fn polish_one(
    model: &RodModel,
    parameter: Parameter,
    measure: &Measure,
    state: &RodState,
    c: Vanishing,
    fold: bool,
) -> Result<ContinuumEvent, PolishError> {
    let branch = ContinuumBranch::new(model, state.clamps, parameter, POLISH_TOLERANCE)?
        .on_ribbon(measure.strip_width);
    let discrete = parameter.value(&state.clamps);
    let mut z = BranchPoint::zeros();
    z.fixed_rows_mut::<6>(0)
        .copy_from(&discrete_unknowns(model, state));
    z[PARAMETER] = discrete;
    // hold the parameter, except at a fold: there the unknown the branch
    // moves along fastest (relative to its size)
    let held = if fold {
        fold_held(&branch, &z)?
    } else {
        PARAMETER
    };
    let test = test_function(&branch, &z, state, measure, c)?;
    let root = locate_root(&branch, z, held, test)?;
    let fine = &root.fine;
    let value = fine.point[PARAMETER];
    let fine_branch = branch.with_tolerance(POLISH_TOLERANCE * 1e-2);
    let p: Unknowns = fine.point.fixed_rows::<6>(0).into();
    let twist = fine_branch
        .problem(value)
        .and_then(|pr| Ok(pr.solve(&p, 0)?))?
        .twist;
    let arclengths = match &fine.test {
        TestFunction::Wall { s, .. } => vec![*s],
        TestFunction::Walls => vec![],
        TestFunction::Crossing { s }
        | TestFunction::RibbonCrossing { s }
        | TestFunction::Merging { s } => s.to_vec(),
        TestFunction::Singular { .. } => vec![],
    };
    Ok(ContinuumEvent {
        parameter,
        value,
        error: root.error,
        discrete_minus_continuum: discrete - value,
        twist,
        unknowns: [p[0], p[1], p[2], p[3], p[4], p[5]],
        arclengths,
        steps: root.steps,
    })
}

/// The coordinate to hold while locating a fold: the unknown the branch
/// moves along fastest at z (relative to its size). Holding the parameter
/// there would ask for a solution past the fold, where there is none.
pub(crate) fn fold_held(branch: &ContinuumBranch, z: &BranchPoint) -> Result<usize, PolishError> {
    let t = branch.tangent(z)?;
    Ok((0..6)
        .max_by(|&a, &b| {
            let w = |k: usize| t[k].abs() / (1.0 + z[k].abs());
            w(a).total_cmp(&w(b))
        })
        .unwrap_or(0))
}

/// A test function's root on a continuum branch, located at
/// [`POLISH_TOLERANCE`] and again at a hundredth of it.
pub(crate) struct Root {
    /// Its error estimate in the parameter: the change with the tolerance
    /// plus the last secant step.
    pub error: f64,
    /// The root located at the finer tolerance (with its updated test).
    pub fine: Located,
    /// Secant steps of both passes.
    pub steps: usize,
}

/// The root of `test` on `branch` from `z`, holding coordinate `held`
/// (the parameter, or at a fold an unknown), located twice for its error.
pub(crate) fn locate_root(
    branch: &ContinuumBranch,
    z: BranchPoint,
    held: usize,
    test: TestFunction,
) -> Result<Root, PolishError> {
    let scale = 1.0 + z[held].abs();
    // at a fold the parameter is stationary in the held unknown: an error δ
    // there moves it by O(δ²), so δ = 1e-7 suffices (and the test
    // function's noise forbids much less)
    let resolution = if held == PARAMETER {
        branch.tolerance
    } else {
        FOLD_RESOLUTION
    } * scale;
    let coarse = branch.locate(z, held, 1e-4 * scale, resolution, test)?;
    // the same root at a hundredth of the tolerance, from the first
    let fine_branch = branch.with_tolerance(branch.tolerance * 1e-2);
    let step = (10.0 * coarse.last_step.abs()).max(1e-8 * scale);
    let fine = fine_branch.locate(coarse.point, held, step, resolution, coarse.test.clone())?;
    let error =
        (coarse.point[PARAMETER] - fine.point[PARAMETER]).abs() + fine.parameter_error(held);
    Ok(Root {
        error,
        steps: coarse.steps + fine.steps,
        fine,
    })
}

/// The bordered-determinant test of a singular shooting Jacobian, its
/// borders the singular vectors of the smallest singular value at z.
pub(crate) fn singular_at(
    branch: &ContinuumBranch,
    z: &BranchPoint,
) -> Result<TestFunction, PolishError> {
    let p: Unknowns = z.fixed_rows::<6>(0).into();
    let (_, j) = branch
        .problem(z[PARAMETER])
        .and_then(|pr| Ok(pr.linearise(&p)?))?;
    let (left, right) =
        singular_borders(&j).ok_or(PolishError::Event(PolishFailure::NoSingularVectors))?;
    Ok(TestFunction::Singular { left, right })
}
