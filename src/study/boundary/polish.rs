//! The traced boundary polished on the continuum: every point of the walk
//! located again as the root of its condition's continuum test function on
//! the line of the plane through it that crosses the curve most steeply
//! (held swept parameter, free value along the lines, or the other way
//! round); every corner as the root of the next condition's test along the
//! previous condition's curve, by both curves; gaps filled and a point
//! polished between each pair of neighbours, so that the area has an
//! N-independent value and a Richardson error estimate from nested point
//! sets. Every root is checked to lie between the walls and near its start.

use crate::model::rod::{Clamps, Parameter, RodModel, RodState};
use crate::solve::continuum::branch::{BranchPoint, ContinuumBranch, PARAMETER, TestFunction};
use crate::solve::root::{Iterate, NoRoot, Reach, Secant, SecantFailure, Start};
use crate::study::boundary::condition::{Condition, OtherStrand};
use crate::study::boundary::traced::{
    DroppedPoint, Piece, PolishedBoundary, PolishedCorner, Trail, TrailPoint, name_pieces,
};
use crate::study::polish::{
    CornerFailure, FOLD_RESOLUTION, PolishError, discrete_unknowns, fold_held, locate_root,
    singular_at,
};
use rayon::prelude::*;

/// Integrator tolerance of the boundary's polish: its points to about
/// 1e-8, far below what the area's 1e-4 relative error needs.
pub const BOUNDARY_TOLERANCE: f64 = 1e-8;

/// A point of the boundary on the continuum.
#[derive(Clone, Debug)]
struct Polished {
    /// (swept, along).
    at: [f64; 2],
    /// Error estimate of the free coordinate.
    error: f64,
    /// The continuum solution: the unknowns and the free coordinate.
    z: BranchPoint,
    /// The free coordinate of the plane (0 swept, 1 along).
    free: usize,
    /// The test at the root (arclengths updated).
    test: TestFunction,
    /// The condition's unit gradient, as at the walk's point it came from.
    normal: [f64; 2],
}

/// The plane of the walk, on the continuum.
struct Plane<'a> {
    model: &'a RodModel,
    params: [Parameter; 2],
    /// The clamps of the other parameters.
    base: Clamps,
    /// The walk's largest step: how far apart the points may lie, and about
    /// how far the polish may move one.
    spacing: f64,
    /// Width of the ribbon the walls and crossings are measured on (0: the
    /// centreline).
    ribbon: f64,
}

/// The free coordinate of a line crossing a curve of unit normal `normal`:
/// the one the normal leans along.
fn free_of(normal: [f64; 2]) -> usize {
    usize::from(normal[1].abs() >= normal[0].abs())
}

impl Plane<'_> {
    fn clamps(&self, at: [f64; 2]) -> Clamps {
        self.params[0].with(&self.params[1].with(&self.base, at[1]), at[0])
    }

    /// The continuum line through `at` free in coordinate `free`.
    fn line(
        &self,
        at: [f64; 2],
        free: usize,
        tolerance: f64,
    ) -> Result<ContinuumBranch<'_>, PolishError> {
        Ok(
            ContinuumBranch::new(self.model, self.clamps(at), self.params[free], tolerance)?
                .on_ribbon(self.ribbon),
        )
    }

    /// The continuum test function of condition `c` at the discrete `state`
    /// (z: its shooting unknowns on `branch`). Walls are both walls at once:
    /// near a flip-symmetric knot both are touched almost together, and the
    /// continuum may touch either first.
    fn test_of(
        &self,
        branch: &ContinuumBranch,
        z: &BranchPoint,
        state: &RodState,
        c: &Condition,
    ) -> Result<TestFunction, PolishError> {
        match c {
            Condition::Wall => Ok(TestFunction::Walls),
            Condition::Stability => singular_at(branch, z),
            Condition::Crossing(s) => {
                let OtherStrand::Segment(j) = s.other else {
                    return Err(PolishError::ClampRayCrossing);
                };
                let (points, arc) = state.centreline();
                let i = s.first;
                if j + 1 >= points.len() {
                    return Err(PolishError::NoSegment(j));
                }
                let (_, ta, tb) = crate::geometry::distance::segment_distance(
                    &points[i],
                    &points[i + 1],
                    &points[j],
                    &points[j + 1],
                );
                let s = [
                    arc[i] + ta * (arc[i + 1] - arc[i]),
                    arc[j] + tb * (arc[j + 1] - arc[j]),
                ];
                Ok(if self.ribbon > 0.0 {
                    TestFunction::RibbonCrossing { s }
                } else {
                    TestFunction::Crossing { s }
                })
            }
        }
    }

    /// The discrete equilibrium's point in the plane and its shooting
    /// unknowns on the line free in `free`.
    fn start(&self, state: &RodState, free: usize) -> ([f64; 2], BranchPoint) {
        let at = [
            self.params[0].value(&state.clamps),
            self.params[1].value(&state.clamps),
        ];
        let mut z = BranchPoint::zeros();
        z.fixed_rows_mut::<6>(0)
            .copy_from(&discrete_unknowns(self.model, state));
        z[PARAMETER] = at[free];
        (at, z)
    }

    /// A walk point on its condition, polished on the line through it that
    /// crosses the curve most steeply, else on the other line.
    fn point(&self, p: &TrailPoint, c: &Condition) -> Result<Polished, PolishError> {
        let free = free_of(p.normal);
        self.point_on(p, c, free).or_else(|first| {
            self.point_on(p, c, 1 - free)
                .map_err(|second| PolishError::BothWays {
                    first: Box::new(first),
                    second: Box::new(second),
                })
        })
    }

    /// A walk point on its condition, polished on the line through it free
    /// in coordinate `free`.
    fn point_on(
        &self,
        p: &TrailPoint,
        c: &Condition,
        free: usize,
    ) -> Result<Polished, PolishError> {
        let state = p.state.as_ref().ok_or(PolishError::NoDiscreteEquilibrium)?;
        let (at, z) = self.start(state, free);
        let branch = self.line(at, free, BOUNDARY_TOLERANCE)?;
        let test = self.test_of(&branch, &z, state, c)?;
        self.checked_root(&branch, at, free, z, test, p.normal, 2.0 * self.spacing)
    }

    /// The root of `test` on a line, refused when it lies farther than
    /// `reach` from the start in the free coordinate (another extremum's or
    /// another branch's root) or where the rod is through a wall.
    #[allow(clippy::too_many_arguments)]
    fn checked_root(
        &self,
        branch: &ContinuumBranch,
        at: [f64; 2],
        free: usize,
        z: BranchPoint,
        test: TestFunction,
        normal: [f64; 2],
        reach: f64,
    ) -> Result<Polished, PolishError> {
        let r = self.root_on(branch, at, free, z, test, normal)?;
        let moved = (r.at[free] - at[free]).abs();
        if moved > reach {
            return Err(PolishError::Moved { moved, reach });
        }
        let line = self.line(r.at, free, branch.tolerance)?;
        if !walled(&line, &r.z, WALL_SLACK)? {
            return Err(PolishError::OutsideWalls { at: r.at });
        }
        Ok(r)
    }

    fn root_on(
        &self,
        branch: &ContinuumBranch,
        mut at: [f64; 2],
        free: usize,
        z: BranchPoint,
        test: TestFunction,
        normal: [f64; 2],
    ) -> Result<Polished, PolishError> {
        let root = match locate_root(branch, z, PARAMETER, test.clone()) {
            Ok(root) => root,
            // a change of stability is a branch point of the symmetric family
            // (the parameter held crosses it) or a fold of the line (no
            // solution past it at that parameter): there an unknown is held
            Err(e) if matches!(test, TestFunction::Singular { .. }) => {
                let held = fold_held(branch, &z).map_err(|_| e)?;
                locate_root(branch, z, held, test)?
            }
            Err(e) => return Err(e),
        };
        at[free] = root.fine.point[PARAMETER];
        Ok(Polished {
            at,
            error: root.error,
            z: root.fine.point,
            free,
            test: root.fine.test,
            normal,
        })
    }

    /// The point of the curve on the line through `at` (free in `free`)
    /// from the continuum solutions `near` on the curve nearby: their
    /// weighted mean as the start, the first one's test.
    fn near_neighbours(
        &self,
        at: [f64; 2],
        free: usize,
        near: &[(&Polished, f64)],
        reach: f64,
    ) -> Result<Polished, PolishError> {
        let branch = self.line(at, free, BOUNDARY_TOLERANCE)?;
        let mut z = near.iter().map(|(p, w)| *w * p.z).sum::<BranchPoint>();
        z[PARAMETER] = at[free];
        // a singular test keeps its neighbour's borders: the singular
        // vectors at a continuum root nearby
        let test = near[0].0.test.clone();
        self.checked_root(&branch, at, free, z, test, near[0].0.normal, reach)
    }

    /// The point of the curve a fraction `w` of the way from `a` to `b`, two
    /// polished neighbours on it.
    fn between(&self, a: &Polished, b: &Polished, w: f64) -> Result<Polished, PolishError> {
        let at = [
            a.at[0] + w * (b.at[0] - a.at[0]),
            a.at[1] + w * (b.at[1] - a.at[1]),
        ];
        // from the nearer neighbour's solution: a mean of two can be far
        // from any solution where the unknowns turn quickly
        // (the other's test is tried too: a wall's may be the other wall)
        let near = if w <= 0.5 {
            [(a, 1.0), (b, 0.0)]
        } else {
            [(b, 1.0), (a, 0.0)]
        };
        // the line across the chord
        let free = usize::from((b.at[0] - a.at[0]).abs() >= (b.at[1] - a.at[1]).abs());
        // a root may lie as far from the chord as the chord is long
        let chord = (b.at[0] - a.at[0]).hypot(b.at[1] - a.at[1]);
        let reach = self.spacing.max(chord);
        // else the other line through that point (as for a walk point): a
        // line meeting the curve where it is a fold of that line may hold
        // no solution near the root
        self.near_neighbours(at, free, &near, reach)
            .or_else(|first| {
                self.near_neighbours(at, 1 - free, &near, reach)
                    .map_err(|second| PolishError::BothWays {
                        first: Box::new(first),
                        second: Box::new(second),
                    })
            })
    }

    /// Each gap of the pieces split into `parts(a, b)` equal parts, the
    /// points between polished in parallel.
    fn subdivide(
        &self,
        pieces: &[Vec<Polished>],
        parts: impl Fn(&Polished, &Polished) -> usize + Sync,
    ) -> Result<Vec<Vec<Polished>>, PolishError> {
        let jobs: Vec<(usize, usize, f64)> = pieces
            .iter()
            .enumerate()
            .flat_map(|(k, p)| {
                let parts = &parts;
                (1..p.len()).flat_map(move |i| {
                    let m = parts(&p[i - 1], &p[i]).max(1);
                    (1..m).map(move |j| (k, i, j as f64 / m as f64))
                })
            })
            .collect();
        let inserted: Vec<Polished> = jobs
            .par_iter()
            .map(|&(k, i, w)| {
                let (a, b) = (&pieces[k][i - 1], &pieces[k][i]);
                self.between(a, b, w).map_err(|e| {
                    e.at(format!(
                        "between ({:.5}, {:.5}) and ({:.5}, {:.5})",
                        a.at[0], a.at[1], b.at[0], b.at[1]
                    ))
                })
            })
            .collect::<Result<_, _>>()?;
        let mut inserted = jobs.iter().zip(inserted).peekable();
        Ok(pieces
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let mut v = vec![p[0].clone()];
                for (i, q) in p.iter().enumerate().skip(1) {
                    while let Some(((_, _, _), r)) =
                        inserted.next_if(|((kk, ii, _), _)| *kk == k && *ii == i)
                    {
                        v.push(r);
                    }
                    v.push(q.clone());
                }
                v
            })
            .collect())
    }

    /// The corner where the test `test_b` vanishes along the curve of
    /// `test_a` (both taken from polished points nearby, so that a singular
    /// test's borders are those at a continuum root), from the walk's
    /// corner `p` (whose normal is `a`'s): the
    /// secant method on the coordinate held on `a`'s lines, each step
    /// `a`'s root on its line and `b`'s test there; then again at a
    /// hundredth of the tolerance. The corner carries `a`'s test; `b`'s
    /// (updated) comes beside it.
    fn corner(
        &self,
        p: &TrailPoint,
        test_a: TestFunction,
        test_b: TestFunction,
    ) -> Result<(Polished, TestFunction), PolishError> {
        let state = p.state.as_ref().ok_or(PolishError::NoDiscreteEquilibrium)?;
        let free = free_of(p.normal);
        let (at, z) = self.start(state, free);
        self.corner_from(at, z, free, p.normal, test_a, test_b)
    }

    /// [`Plane::corner`] from the point `at` (unknowns `z` on its line free
    /// in `free`) of `a`'s curve, whose normal is `normal`.
    fn corner_from(
        &self,
        at: [f64; 2],
        z: BranchPoint,
        free: usize,
        normal: [f64; 2],
        test_a: TestFunction,
        test_b: TestFunction,
    ) -> Result<(Polished, TestFunction), PolishError> {
        let coarse = self.secant_corner(at, free, z, test_a, test_b, BOUNDARY_TOLERANCE, 1e-4)?;
        let fine = self.secant_corner(
            coarse.0.at,
            free,
            coarse.0.z,
            coarse.0.test.clone(),
            coarse.1.clone(),
            BOUNDARY_TOLERANCE * 1e-2,
            (10.0 * coarse.2).max(1e-8),
        )?;
        let mut corner = fine.0;
        corner.error = (0..2)
            .map(|k| (corner.at[k] - coarse.0.at[k]).abs())
            .fold(fine.2 + corner.error, f64::max);
        corner.normal = normal;
        Ok((corner, fine.1))
    }

    /// Whether the crossings of `a` (its point nearest the corner) and `b`
    /// (its nearest) run into one: `a`'s closest points, followed to `b`'s
    /// solution, land on `b`'s (or the other way round). Then the test of
    /// their merger on the critical point that persists.
    fn merger(&self, a: &Polished, b: &Polished) -> Option<TestFunction> {
        let (TestFunction::Crossing { s: sa }, TestFunction::Crossing { s: sb }) =
            (&a.test, &b.test)
        else {
            return None;
        };
        let followed = |from: &TestFunction, to: &Polished| -> Option<[f64; 2]> {
            let line = self.line(to.at, to.free, BOUNDARY_TOLERANCE).ok()?;
            match line.evaluate(&to.z, from).ok()?.0 {
                TestFunction::Crossing { s } => Some(s),
                _ => None,
            }
        };
        // landed: within a hundredth of the way between the two (the
        // closest points are ill-determined along strands nearly parallel)
        let lands = |s: Option<[f64; 2]>, on: &[f64; 2]| {
            s.is_some_and(|s| apart(&s, on) < 1e-2 * apart(sa, sb))
        };
        if lands(followed(&a.test, b), sb) {
            Some(TestFunction::Merging { s: *sb })
        } else if lands(followed(&b.test, a), sa) {
            Some(TestFunction::Merging { s: *sa })
        } else {
            None
        }
    }

    /// Secant iteration for a corner: the root of `test_b` along the curve of
    /// `test_a`, from `at` with first step `step` in the held coordinate;
    /// the corner, `test_b` updated, and the last step.
    #[allow(clippy::too_many_arguments)]
    fn secant_corner(
        &self,
        at: [f64; 2],
        free: usize,
        z: BranchPoint,
        test_a: TestFunction,
        test_b: TestFunction,
        tolerance: f64,
        step: f64,
    ) -> Result<(Polished, TestFunction, f64), PolishError> {
        let held = 1 - free;
        // a's root on the line with the held coordinate at `v`, and b there
        let on_a = |v: f64, z: BranchPoint, ta: &TestFunction, tb: &TestFunction| {
            let mut q = at;
            q[held] = v;
            let branch = self.line(q, free, tolerance)?;
            let along = |held: usize| {
                let scale = 1.0 + z[held].abs();
                let resolution = if held == PARAMETER {
                    0.1 * tolerance
                } else {
                    FOLD_RESOLUTION
                };
                branch.locate(z, held, 1e-4 * scale, resolution * scale, ta.clone())
            };
            // as in root_on: at a fold of the line an unknown is held
            let (located, held) = match along(PARAMETER) {
                Ok(located) => (located, PARAMETER),
                Err(e) if matches!(ta, TestFunction::Singular { .. }) => {
                    let held = fold_held(&branch, &z).map_err(|_| e)?;
                    (along(held)?, held)
                }
                Err(e) => return Err(e.into()),
            };
            let (tb, gb) = branch.evaluate(&located.point, tb)?;
            q[free] = located.point[PARAMETER];
            let error = located.parameter_error(held);
            Ok::<_, PolishError>((
                Polished {
                    at: q,
                    error,
                    z: located.point,
                    free,
                    test: located.test,
                    normal: [0.0, 0.0],
                },
                tb,
                gb,
            ))
        };
        let (pa, tb, ga) = on_a(at[held], z, &test_a, &test_b)?;
        let (pb, tb, gb) = on_a(at[held] + step, pa.z, &pa.test.clone(), &tb)?;
        let iterate = |p: Polished, tb: TestFunction, value| Iterate {
            at: p.at[held],
            value,
            point: (p, tb),
        };
        let secant = Secant {
            max_evaluations: CORNER_ITERATIONS,
            tolerance,
            relative: true,
            reach: Reach::Step(0.05),
            stall: Some((STALLED_ITERATES, 1e-3)),
            ..Secant::default()
        };
        let start = Start::Chord(iterate(pa, tb.clone(), ga), iterate(pb, tb, gb));
        // predict the unknowns along the chord of the last two points
        type Solved = Iterate<(Polished, TestFunction)>;
        let next = |v: f64, dv: f64, b: &Solved, a: Option<&Solved>| {
            let (pb, tb) = &b.point;
            let zc = match a {
                Some(Iterate { point: (pa, _), .. }) => {
                    pb.z + dv / (pb.at[held] - pa.at[held]) * (pb.z - pa.z)
                }
                None => pb.z,
            };
            let (pc, tc, gc) = on_a(v, zc, &pb.test.clone(), tb)?;
            Ok::<_, PolishError>(iterate(pc, tc, gc))
        };
        // steps stalled at the tests' noise (a corner where they vanish
        // together, flat) end at the last point, its error the spread of
        // the last iterates
        match secant.find(start, next, |_, _| false) {
            Ok(root) => {
                let (corner, tb) = root.last.point;
                Ok((corner, tb, root.error))
            }
            Err(SecantFailure { why, values }) => Err(match why {
                NoRoot::Left(dv) => PolishError::CornerLeft(dv),
                NoRoot::NotConverged => PolishError::Corner(CornerFailure::NotConverged),
                NoRoot::Flat => PolishError::Corner(CornerFailure::Flat(values[1])),
                NoRoot::Failed(e) => PolishError::Corner(CornerFailure::Step(Box::new(e))),
            }),
        }
    }
}

/// Passes retrying failed boundary points from their polished neighbours.
const RETRY_PASSES: usize = 3;

/// Secant steps a corner may take.
const CORNER_ITERATIONS: usize = 41;

/// The iterates of a stalled corner secant whose spread is its error.
const STALLED_ITERATES: usize = 4;

/// The continuum solution at z lies between the walls (to `slack`, touching
/// allowed), at the points of [`ContinuumBranch::height_range`].
fn walled(branch: &ContinuumBranch, z: &BranchPoint, slack: f64) -> Result<bool, PolishError> {
    let (_, low, high) = branch.height_range(z)?;
    let top = branch.clamps_at(z[PARAMETER]).top_wall();
    Ok(low.iter().all(|&h| h >= -slack) && high.iter().all(|&h| h <= top + slack))
}

/// How far outside the walls a boundary point's continuum solution may
/// reach (its touch is located to about the integrator's tolerance).
const WALL_SLACK: f64 = 1e-5;

/// How many times nearer the other piece's closest points a point must lie
/// than its own piece's to count as the other's.
const NEARER: f64 = 4.0;

/// The larger arclength difference of two closest-point pairs.
fn apart(a: &[f64; 2], b: &[f64; 2]) -> f64 {
    (a[0] - b[0]).abs().max((a[1] - b[1]).abs())
}

/// The closest points of a crossing's test.
fn crossing_points(t: &TestFunction) -> Option<[f64; 2]> {
    match t {
        TestFunction::Crossing { s } | TestFunction::RibbonCrossing { s } => Some(*s),
        _ => None,
    }
}

/// The piece each polished point lies on (`jobs`: its walk piece and
/// index). Where two crossings of the same strands run into one, the
/// discrete walk can end a crossing piece late or start the next early:
/// the polished points there lie on the other piece's critical point. A
/// piece's tail goes to the next piece when each of its points is
/// [`NEARER`] times nearer (in arclength) the next piece's first closest
/// points than the piece's own point before the tail: a jump, not the
/// slide of one crossing's closest points; the next piece's head likewise.
fn pieces_by_critical_point(
    pieces: usize,
    jobs: &[(usize, usize)],
    points: &[Polished],
) -> Vec<usize> {
    let mut piece_of: Vec<usize> = jobs.iter().map(|j| j.0).collect();
    // the start of the longest tail of `s` (from its second entry on) whose
    // entries are all NEARER times nearer `other` than the entry before it
    let tail = |s: &[[f64; 2]], other: &[f64; 2]| -> usize {
        (1..s.len())
            .find(|&cut| {
                s[cut..]
                    .iter()
                    .all(|q| NEARER * apart(q, other) < apart(q, &s[cut - 1]))
            })
            .unwrap_or(s.len())
    };
    for k in 1..pieces {
        let of = |piece: usize, piece_of: &[usize]| -> Option<(Vec<usize>, Vec<[f64; 2]>)> {
            let idx: Vec<usize> = (0..points.len())
                .filter(|&i| piece_of[i] == piece)
                .collect();
            let s: Option<Vec<[f64; 2]>> = idx
                .iter()
                .map(|&i| crossing_points(&points[i].test))
                .collect();
            s.filter(|s| !s.is_empty()).map(|s| (idx, s))
        };
        let (Some((ia, sa)), Some((ib, sb))) = (of(k - 1, &piece_of), of(k, &piece_of)) else {
            continue;
        };
        let cut = tail(&sa, &sb[0]);
        for &i in &ia[cut..] {
            piece_of[i] = k;
        }
        let kept = sa[cut - 1];
        let rev: Vec<[f64; 2]> = sb.iter().rev().copied().collect();
        let head = ib.len() - tail(&rev, &kept);
        for &i in &ib[..head] {
            piece_of[i] = k - 1;
        }
    }
    piece_of
}

/// Shoelace area of a closed polygon.
fn shoelace(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    0.5 * (0..n)
        .map(|k| {
            let (a, b) = (points[k], points[(k + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        .abs()
}

/// Every `stride`-th point of a piece, keeping its ends.
fn thinned(points: &[[f64; 2]], stride: usize) -> Vec<[f64; 2]> {
    let last = points.len() - 1;
    let mut v: Vec<[f64; 2]> = points.iter().step_by(stride).copied().collect();
    if !last.is_multiple_of(stride) {
        v.push(points[last]);
    }
    v
}

/// Polish a closed walk's `trail` (pieces with their discrete equilibria)
/// on the continuum of `model`, in the plane of `params` (swept, along),
/// its points no farther apart than `spacing` (the walk's largest step).
pub(super) fn polish_boundary(
    model: &RodModel,
    params: [Parameter; 2],
    base: Clamps,
    trail: &[Trail],
    spacing: f64,
    ribbon: f64,
) -> Result<PolishedBoundary, PolishError> {
    if trail.is_empty() {
        return Err(PolishError::NoBoundary);
    }
    let plane = Plane {
        model,
        params,
        base,
        spacing,
        ribbon,
    };
    let (jobs, points, dropped) = plane.walk_points(trail)?;
    let piece_of = pieces_by_critical_point(trail.len(), &jobs, &points);
    let on = OnPieces {
        trail,
        piece_of: &piece_of,
        points: &points,
    };
    let corners: Vec<(Polished, Polished)> = (1..trail.len())
        .into_par_iter()
        .map(|k| plane.corner_of(&on, k))
        .collect::<Result<_, _>>()?;
    let largest_shift = jobs
        .iter()
        .zip(&points)
        .map(|(&(k, i), p)| (trail[k].1[i].at[p.free] - p.at[p.free]).abs())
        .fold(0.0, f64::max);
    let pieces = on.assemble(&jobs, &corners);
    // gaps wider than the walk's step (where the polish moved a corner
    // past the discrete piece's end) filled, then a point between each pair
    // of neighbours
    let length = |a: &Polished, b: &Polished| (b.at[0] - a.at[0]).hypot(b.at[1] - a.at[1]);
    let filled = plane
        .subdivide(&pieces, |a, b| (length(a, b) / spacing).ceil() as usize)
        .map_err(|e| e.at("filling the pieces"))?;
    let refined = plane
        .subdivide(&filled, |_, _| 2)
        .map_err(|e| e.at("between two points"))?;
    let area = Area::of(&refined);
    let (pieces, corners) = named(params, trail, &refined, &corners);
    Ok(PolishedBoundary {
        pieces,
        corners,
        area: area.extrapolated,
        area_error: area.error,
        area_polygon: area.polygon,
        largest_point_error: area.largest_point_error,
        largest_shift,
        tolerance: BOUNDARY_TOLERANCE,
        dropped,
    })
}

/// The walk's polished points and the pieces they lie on.
struct OnPieces<'a> {
    trail: &'a [Trail],
    /// The piece of each polished point.
    piece_of: &'a [usize],
    points: &'a [Polished],
}

impl OnPieces<'_> {
    /// The polished point of `piece` nearest its end (`from_end`) or start.
    fn nearest(&self, piece: usize, from_end: bool) -> Option<&Polished> {
        let mut mine = self
            .piece_of
            .iter()
            .zip(self.points)
            .filter(|(k, _)| **k == piece)
            .map(|(_, p)| p);
        if from_end {
            mine.next_back()
        } else {
            mine.next()
        }
    }

    /// The pieces on the continuum: corners at their ends, points in
    /// between (a point the polish moved past a corner dropped); `jobs`:
    /// each point's walk piece and index.
    fn assemble(
        &self,
        jobs: &[(usize, usize)],
        corners: &[(Polished, Polished)],
    ) -> Vec<Vec<Polished>> {
        let trail = self.trail;
        let mut pieces: Vec<Vec<Polished>> = Vec::new();
        for (k, (_, pts)) in trail.iter().enumerate() {
            let mut piece = Vec::new();
            if k > 0 {
                piece.push(corners[k - 1].1.clone());
            }
            piece.extend(
                self.piece_of
                    .iter()
                    .zip(self.points)
                    .filter(|(j, _)| **j == k)
                    .map(|(_, p)| p.clone()),
            );
            if k + 1 < trail.len() {
                piece.push(corners[k].0.clone());
            }
            // the discrete curve's direction at the piece's ends, from the walk
            // points that stay on it
            // (else the whole discrete piece's; with fewer than two points
            // nothing is trimmed)
            let mut mine: Vec<[f64; 2]> = self
                .piece_of
                .iter()
                .zip(jobs)
                .filter(|(p, _)| **p == k)
                .map(|(_, &(kk, i))| trail[kk].1[i].at)
                .collect();
            if mine.len() < 2 {
                mine = pts.iter().map(|p| p.at).collect();
            }
            let n = mine.len();
            if n >= 2 {
                let ends = [[mine[0], mine[1]], [mine[n - 2], mine[n - 1]]];
                trim_past_corners(&mut piece, ends, k > 0, k + 1 < trail.len());
            }
            pieces.push(piece);
        }
        pieces
    }
}

/// The walk's points (other than corners) polished, each with its walk
/// piece and index; a point that fails is left out, and said so (why, as
/// text for the map's file), unless more than a tenth fail.
type WalkPoints = (Vec<(usize, usize)>, Vec<Polished>, Vec<DroppedPoint>);

impl Plane<'_> {
    /// The points other than corners (where one piece ends and the next
    /// starts), each on its line from its discrete equilibrium, else from
    /// its piece's nearest polished point.
    fn walk_points(&self, trail: &[Trail]) -> Result<WalkPoints, PolishError> {
        let last = trail.len() - 1;
        let jobs: Vec<(usize, usize)> = trail
            .iter()
            .enumerate()
            .flat_map(|(k, (_, pts))| {
                let first = usize::from(k > 0);
                let end = if k < last { pts.len() - 1 } else { pts.len() };
                (first..end).map(move |i| (k, i))
            })
            .collect();
        let first: Vec<Result<Polished, PolishError>> = jobs
            .par_iter()
            .map(|&(k, i)| self.point(&trail[k].1[i], &trail[k].0))
            .collect();
        let retried = self.retried(trail, &jobs, first);
        // a point that fails (its discrete start too far from the continuum,
        // next to a branch point say) is left out, and said so: its
        // neighbours' middle is polished instead
        let mut dropped = Vec::new();
        let (jobs, points): (Vec<(usize, usize)>, Vec<Polished>) = jobs
            .into_iter()
            .zip(retried)
            .filter_map(|((k, i), r)| match r {
                Ok(p) => Some(((k, i), p)),
                Err(e) => {
                    let (c, pts) = &trail[k];
                    dropped.push((c.describe(), pts[i].at, e));
                    None
                }
            })
            .unzip();
        if dropped.len() * 10 > jobs.len() {
            let failed = dropped.len();
            let (condition, at, first) = dropped.swap_remove(0);
            return Err(PolishError::TooManyFailed {
                failed,
                of: jobs.len() + failed,
                first: Box::new(first.at(format!("{condition} at ({:.5}, {:.5})", at[0], at[1]))),
            });
        }
        let dropped = dropped
            .into_iter()
            .map(|(condition, at, e)| DroppedPoint {
                condition,
                at: Some(at),
                why: e.failure(),
            })
            .collect();
        Ok((jobs, points, dropped))
    }

    /// The points that failed from their discrete start (too far from the
    /// continuum at small N) tried again from their piece's nearest
    /// polished point, on their own line; passes repeat while they rescue
    /// points.
    fn retried(
        &self,
        trail: &[Trail],
        jobs: &[(usize, usize)],
        mut retried: Vec<Result<Polished, PolishError>>,
    ) -> Vec<Result<Polished, PolishError>> {
        let mut from_neighbour: Vec<Option<PolishError>> = (0..jobs.len()).map(|_| None).collect();
        for _ in 0..RETRY_PASSES {
            let again: Vec<(usize, Result<Polished, PolishError>)> = (0..jobs.len())
                .into_par_iter()
                .filter(|&n| retried[n].is_err())
                .filter_map(|n| {
                    let (k, i) = jobs[n];
                    let near = (0..jobs.len())
                        .filter(|&m| jobs[m].0 == k && retried[m].is_ok())
                        .min_by_key(|&m| jobs[m].1.abs_diff(i))?;
                    let q = retried[near].as_ref().ok()?;
                    // on the discrete point's line, started at the neighbour's
                    // value (the curve there), so that the reach is measured
                    // from the continuum curve, not from the discrete one
                    let p = &trail[k].1[i];
                    let free = free_of(p.normal);
                    let mut at = p.at;
                    at[free] = q.at[free];
                    let r = self.near_neighbours(at, free, &[(q, 1.0)], 2.0 * self.spacing);
                    Some((n, r))
                })
                .collect();
            let mut rescued = 0;
            for (n, r) in again {
                match r {
                    Ok(p) => {
                        retried[n] = Ok(p);
                        rescued += 1;
                    }
                    Err(e) => from_neighbour[n] = Some(e),
                }
            }
            if rescued == 0 {
                break;
            }
        }
        retried
            .into_iter()
            .zip(from_neighbour)
            .map(|(r, e)| match (r, e) {
                (Err(first), Some(second)) => Err(PolishError::FromNeighbour {
                    first: Box::new(first),
                    second: Box::new(second),
                }),
                (r, _) => r,
            })
            .collect()
    }

    /// The corner between pieces `k - 1` and `k`, located along both
    /// curves (their difference joins its error estimate) from the tests of
    /// their polished points nearest it; each side keeps its own piece's
    /// test and normal.
    fn corner_of(&self, on: &OnPieces, k: usize) -> Result<(Polished, Polished), PolishError> {
        let trail = on.trail;
        let (a, pa) = &trail[k - 1];
        let (b, _) = &trail[k];
        let corner = pa.last().expect("pieces have points");
        let state = corner
            .state
            .as_ref()
            .ok_or(PolishError::NoDiscreteEquilibrium)?;
        // the test of the piece's nearest polished point (a singular
        // test's borders at a continuum root), else the discrete corner's
        let test = |piece: usize, from_end: bool| -> Result<TestFunction, PolishError> {
            match on.nearest(piece, from_end) {
                Some(p) => Ok(p.test.clone()),
                None => {
                    let free = free_of(corner.normal);
                    let (at, z) = self.start(state, free);
                    let branch = self.line(at, free, BOUNDARY_TOLERANCE)?;
                    self.test_of(&branch, &z, state, &trail[piece].0)
                }
            }
        };
        let (ta, tb) = (test(k - 1, true)?, test(k, false)?);
        let between = || format!("corner of {} and {}", a.describe(), b.describe());
        let (along_a, along_b) = self.corner_routes(on, k, ta, tb);
        let (ca, cb) = match (along_a, along_b) {
            (Ok((mut ca, mut cb)), Ok((other, _))) => {
                let apart = (0..2)
                    .map(|k| (ca.at[k] - other.at[k]).abs())
                    .fold(other.error, f64::max);
                ca.error = ca.error.max(apart);
                cb.error = ca.error;
                (ca, cb)
            }
            (Ok(c), Err(_)) | (Err(_), Ok(c)) => c,
            (Err(first), Err(second)) => {
                return Err(PolishError::At {
                    at: between(),
                    source: Box::new(PolishError::AlongOther {
                        first: Box::new(first),
                        second: Box::new(second),
                    }),
                });
            }
        };
        let line = self.line(ca.at, ca.free, BOUNDARY_TOLERANCE)?;
        if !walled(&line, &ca.z, WALL_SLACK)? {
            return Err(PolishError::OutsideWalls { at: ca.at }.at(between()));
        }
        Ok((ca, cb))
    }

    /// The corner between pieces `k - 1` (test `ta`) and `k` (test `tb`)
    /// along each of the two curves: of two crossings that run into one,
    /// where their closest points merge, on the critical point that
    /// persists; else from the discrete corner, or (at small N, far from
    /// the continuum's) from the piece's polished point nearest it.
    #[allow(clippy::type_complexity)]
    fn corner_routes(
        &self,
        on: &OnPieces,
        k: usize,
        ta: TestFunction,
        tb: TestFunction,
    ) -> (
        Result<(Polished, Polished), PolishError>,
        Result<(Polished, Polished), PolishError>,
    ) {
        let corner = on.trail[k - 1].1.last().expect("pieces have points");
        let from_b = &on.trail[k].1[0];
        let with = |p: &Polished, test: TestFunction, normal: [f64; 2]| Polished {
            test,
            normal,
            ..p.clone()
        };
        let (near_a, near_b) = (on.nearest(k - 1, true), on.nearest(k, false));
        let merger = match (near_a, near_b) {
            (Some(pa), Some(pb)) => self.merger(pa, pb).map(|m| (m, pa, pb)),
            _ => None,
        };
        if let Some((m, pa, pb)) = merger {
            let crossing = |m: &TestFunction| match m {
                TestFunction::Merging { s } => TestFunction::Crossing { s: *s },
                other => other.clone(),
            };
            return (
                self.corner_from(pa.at, pa.z, pa.free, pa.normal, ta, m.clone())
                    .map(|(c, m)| (c.clone(), with(&c, crossing(&m), pb.normal))),
                self.corner_from(pb.at, pb.z, pb.free, pb.normal, tb, m)
                    .map(|(c, m)| (with(&c, crossing(&m), pa.normal), c)),
            );
        }
        let from_polished = |p: Option<&Polished>, ta: &TestFunction, tb: &TestFunction| {
            p.ok_or(PolishError::NoPolishedPoint)
                .and_then(|p| self.corner_from(p.at, p.z, p.free, p.normal, ta.clone(), tb.clone()))
        };
        let retried = |first: PolishError, second: PolishError| PolishError::FromNeighbour {
            first: Box::new(first),
            second: Box::new(second),
        };
        (
            self.corner(corner, ta.clone(), tb.clone())
                .or_else(|e| from_polished(near_a, &ta, &tb).map_err(|f| retried(e, f)))
                .map(|(c, tb)| (c.clone(), with(&c, tb, from_b.normal))),
            self.corner(from_b, tb.clone(), ta.clone())
                .or_else(|e| from_polished(near_b, &tb, &ta).map_err(|f| retried(e, f)))
                .map(|(c, ta)| (with(&c, ta, corner.normal), c)),
        )
    }
}

/// The area of a polished boundary and its error.
struct Area {
    /// Richardson-extrapolated from the polygons of all points and of every
    /// other one.
    extrapolated: f64,
    /// Its error estimate.
    error: f64,
    /// The shoelace area of all the points.
    polygon: f64,
    /// Largest error estimate of a point.
    largest_point_error: f64,
}

impl Area {
    /// The area within the closed chain of `refined` pieces (each ending
    /// where the next starts).
    fn of(refined: &[Vec<Polished>]) -> Area {
        // areas of nested polygons: all points (h), and without the middles (2h)
        let polygon = |stride: usize| -> Vec<[f64; 2]> {
            refined
                .iter()
                .flat_map(|p| {
                    let at: Vec<[f64; 2]> = p.iter().map(|q| q.at).collect();
                    let mut t = thinned(&at, stride);
                    t.pop();
                    t
                })
                .collect()
        };
        let (a1, a2) = (shoelace(&polygon(1)), shoelace(&polygon(2)));
        let r1 = a1 + (a1 - a2) / 3.0;
        let largest_point_error = refined
            .iter()
            .flatten()
            .map(|p| p.error)
            .fold(0.0, f64::max);
        // each point's error moves the boundary across half of each chord
        // beside it
        let ring: Vec<&Polished> = refined
            .iter()
            .flat_map(|p| p[..p.len() - 1].iter())
            .collect();
        let n = ring.len();
        let chord = |i: usize| {
            let (a, b) = (ring[i].at, ring[(i + 1) % n].at);
            (b[0] - a[0]).hypot(b[1] - a[1])
        };
        let points_error: f64 = (0..n)
            .map(|i| ring[i].error * 0.5 * (chord((i + n - 1) % n) + chord(i)))
            .sum();
        // the Richardson correction is the finest polygon's estimated error,
        // which bounds the extrapolated area's (an order smaller)
        Area {
            extrapolated: r1,
            error: (r1 - a1).abs() + points_error,
            polygon: a1,
            largest_point_error,
        }
    }
}

/// The polished pieces named as the discrete walk's, and the corners
/// between them (beside the walk's).
fn named(
    params: [Parameter; 2],
    trail: &[Trail],
    refined: &[Vec<Polished>],
    corners: &[(Polished, Polished)],
) -> (Vec<Piece>, Vec<PolishedCorner>) {
    let trail_polished: Vec<Trail> = trail
        .iter()
        .zip(refined)
        .map(|((c, _), p)| {
            let pts = p
                .iter()
                .map(|q| TrailPoint {
                    at: q.at,
                    normal: q.normal,
                    state: None,
                })
                .collect();
            (*c, pts)
        })
        .collect();
    let named = name_pieces(params, 0, trail_polished, true, None);
    // the named piece ending (end) or starting at a corner
    let label_at = |at: [f64; 2], end: bool| {
        named
            .pieces
            .iter()
            .find(|p| if end { p.points.last() } else { p.points.first() } == Some(&at))
            .map_or(String::new(), |p| p.label.clone())
    };
    let corners = corners
        .iter()
        .enumerate()
        .map(|(k, (c, _))| PolishedCorner {
            between: [label_at(c.at, true), label_at(c.at, false)],
            point: c.at,
            error: c.error,
            discrete: trail[k].1.last().expect("pieces have points").at,
        })
        .collect();
    (named.pieces, corners)
}

/// Drop the interior points of a polished piece that the polish moved past
/// one of its corners (along the discrete curve's direction `ends` at its
/// start and end).
fn trim_past_corners(piece: &mut Vec<Polished>, ends: [[[f64; 2]; 2]; 2], start: bool, end: bool) {
    let direction = |a: [f64; 2], b: [f64; 2]| [b[0] - a[0], b[1] - a[1]];
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    if start {
        let t = direction(ends[0][0], ends[0][1]);
        let c = piece[0].at;
        while piece.len() > 2 && dot(direction(c, piece[1].at), t) <= 0.0 {
            piece.remove(1);
        }
    }
    if end {
        let t = direction(ends[1][0], ends[1][1]);
        let c = piece[piece.len() - 1].at;
        while piece.len() > 2 && dot(direction(piece[piece.len() - 2].at, c), t) <= 0.0 {
            piece.remove(piece.len() - 2);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A polished point with a crossing's closest points at `s`.
    fn crossing_point(s: [f64; 2]) -> Polished {
        Polished {
            at: [0.0, 0.0],
            error: 0.0,
            z: BranchPoint::zeros(),
            free: 0,
            test: TestFunction::Crossing { s },
            normal: [0.0, 1.0],
        }
    }

    #[test]
    fn a_crossing_pieces_tail_on_the_next_pieces_critical_point_moves_to_it() {
        // piece 0's closest points slide towards piece 1's, then its last
        // three points sit on piece 1's critical point (the walk ended it late)
        let s0: Vec<[f64; 2]> = [0.04, 0.06, 0.08, 0.1, 0.1076, 0.1157, 0.1155, 0.1152]
            .iter()
            .map(|&a| [a, a + 0.77])
            .collect();
        // the pieces each point lies on, for piece 1's closest points `s1`
        let pieces_with = |s1: &[[f64; 2]]| {
            let jobs: Vec<(usize, usize)> = (0..s0.len())
                .map(|i| (0, i))
                .chain((0..s1.len()).map(|i| (1, i)))
                .collect();
            let points: Vec<Polished> = s0.iter().chain(s1).map(|&s| crossing_point(s)).collect();
            pieces_by_critical_point(2, &jobs, &points)
        };
        assert_eq!(
            pieces_with(&[[0.1151, 0.8849], [0.1140, 0.8860], [0.11, 0.89]]),
            [0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1]
        );
        // crossings of other strands, far apart: nothing moves
        assert_eq!(
            pieces_with(&[[0.3, 0.6], [0.31, 0.61]]),
            [0, 0, 0, 0, 0, 0, 0, 0, 1, 1]
        );
    }

    #[test]
    fn nested_polygons_of_a_circle_extrapolate_to_its_area() {
        // a quarter circle as one piece (ends kept), closed through the origin
        let arc = |n: usize| -> Vec<[f64; 2]> {
            (0..=n)
                .map(|k| {
                    let t = std::f64::consts::FRAC_PI_2 * k as f64 / n as f64;
                    [t.cos(), t.sin()]
                })
                .collect()
        };
        let fine = arc(16);
        let closed = |p: Vec<[f64; 2]>| {
            let mut v = p;
            v.push([0.0, 0.0]);
            v
        };
        let a1 = shoelace(&closed(thinned(&fine, 1)));
        let a2 = shoelace(&closed(thinned(&fine, 2)));
        let exact = std::f64::consts::FRAC_PI_4;
        let richardson = a1 + (a1 - a2) / 3.0;
        assert!((exact - a1).abs() > 1e-3);
        assert!((exact - richardson).abs() < 1e-5, "{richardson}");
        // every other point keeps the piece's ends
        assert_eq!(thinned(&arc(5), 2).len(), 4);
        assert_eq!(*thinned(&arc(5), 2).last().unwrap(), arc(5)[5]);
    }
}
