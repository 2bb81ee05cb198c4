//! The walk round the good region: each condition's zero set followed by
//! pseudo-arclength continuation in the plane, corners where another property
//! fails, equilibria by Newton at fixed clamps.

use crate::analysis::equilibrium::{Measure, ribbon_data, walls};
use crate::geometry::closure::closure_knot_along;
use crate::geometry::ribbon::Ribbon;
use crate::model::rod::{Clamps, Parameter, RodState};
use crate::scene::MapSpec;
use crate::scene::Scene;
use crate::solve::continuation::{Point, Tracer};
use crate::solve::event::Vanishing;
use crate::solve::root::{Iterate, NoRoot, Probe, Reach, Secant, SecantFailure, Start, bisect};
use crate::solve::step::{Acceptance, StepControl, Trial};
use crate::study::boundary::condition::{
    Condition, OtherStrand, Strands, closest_strands, ribbon_gap, strand_distance,
};
use crate::study::boundary::polish::polish_boundary;
use crate::study::boundary::traced::{Traced, Trail, TrailPoint, merge_crossings, name_pieces};
use crate::study::error::{Context, Result, StudyError, describe, fail};
use crate::study::start::starting_equilibrium;

#[derive(Clone)]
struct Site {
    /// Parameters of the equilibrium.
    p: [f64; 2],
    /// The point it stands for on the curve: `p`, except on a stability
    /// boundary (see [`STABILITY_TOL`]).
    on: [f64; 2],
    point: Point,
}

/// Walk settings.
const FIRST_STEP: f64 = 0.002;
const MIN_STEP: f64 = 1e-6;
const MAX_POINTS: usize = 4000;
/// Most equilibria one walk may solve (a walk creeping through a tangle of
/// tiny corners stops instead of running for hours).
const MAX_EQUILIBRIA: usize = 20_000;
/// Largest clamp move per Newton solve, in either coordinate.
const SUBSTEP: f64 = 0.004;
/// Forward-difference step of condition gradients.
const FD: f64 = 1e-5;
/// Corrector accuracy along the normal.
const CORRECTOR_TOL: f64 = 1e-9;
/// On a stability boundary the Hessian is singular and Newton at fixed clamps
/// ill-conditioned close to it: equilibria are solved about twice this on
/// the stable side, and the boundary point is the secant's extrapolation from
/// there (error of order STABILITY_TOL² times the curvature of λ).
const STABILITY_TOL: f64 = 1e-5;
/// Forward-difference step of the lowest eigenvalue's gradient.
const STABILITY_FD: f64 = 1e-4;
/// The walk's step rule: the tangent may turn by at most acos 0.97 (14°) per
/// step, except on steps below 1e-4 (a corner of the curve, not a jump);
/// the secant corrector's iterations and move are bounded by the corrector.
const WALK_ACCEPTANCE: Acceptance = Acceptance {
    max_iterations: usize::MAX,
    max_correction: f64::INFINITY,
    min_turn: 0.97,
    turn_free_below: 1e-4,
};

struct Walk<'t, 'a> {
    tracer: &'t mut Tracer<'a>,
    measure: Measure,
    base: Clamps,
    /// The map's parameter (p[0]) and the continuation's along its lines (p[1]).
    swept: Parameter,
    along: Parameter,
    bounds: [[f64; 2]; 2],
    max_step: f64,
    equilibria: usize,
}

/// How many segments along each strand a ribbon's touch may lie from the
/// centrelines' closest points: 3, and twice the ribbon's width in segments.
/// Strands crossing at a shallow angle θ touch by their edges up to
/// (w/2)/tan θ along from the centrelines' closest points, past one width for
/// θ < 27°: the Figure 10 ribbon's touch at N = 200 lay 19 segments along,
/// beyond a window of one width (15), and was taken for another crossing.
fn ribbon_window(width: f64, segments: usize) -> usize {
    3 + (2.0 * width * segments as f64).ceil() as usize
}

/// A parameter in messages: φ as the paper writes it, others by their name.
fn label(p: Parameter) -> &'static str {
    if p == Parameter::Phi {
        "φ/2π"
    } else {
        p.name()
    }
}

fn unit(v: [f64; 2]) -> [f64; 2] {
    let n = v[0].hypot(v[1]).max(1e-300);
    [v[0] / n, v[1] / n]
}

fn dot2(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn along(p: [f64; 2], t: [f64; 2], s: f64) -> [f64; 2] {
    [p[0] + s * t[0], p[1] + s * t[1]]
}

/// Tangent with the good side (the gradient's side) on the left.
fn left_tangent(gradient: [f64; 2]) -> [f64; 2] {
    unit([gradient[1], -gradient[0]])
}

impl Walk<'_, '_> {
    fn clamps(&self, p: [f64; 2]) -> Clamps {
        self.swept.with(&self.along.with(&self.base, p[1]), p[0])
    }

    /// The equilibrium at `p`, continued from the one at `from` in moves of at
    /// most `SUBSTEP` per coordinate.
    fn equilibrium_at(&mut self, from: &Site, p: [f64; 2]) -> Result<Site> {
        self.equilibrium_from(&from.point.state, from.p, p)
    }

    /// The equilibrium at `p`, continued from the equilibrium `state` at `from`.
    fn equilibrium_from(&mut self, state: &RodState, from: [f64; 2], p: [f64; 2]) -> Result<Site> {
        if !(p[0].is_finite() && p[1].is_finite()) {
            fail!("boundary walk: non-finite parameters");
        }
        let moves = ((p[0] - from[0]).abs().max((p[1] - from[1]).abs()) / SUBSTEP).ceil();
        let moves = (moves as usize).max(1);
        let mut point: Option<Point> = None;
        for k in 1..=moves {
            let f = k as f64 / moves as f64;
            let q = [
                from[0] + f * (p[0] - from[0]),
                from[1] + f * (p[1] - from[1]),
            ];
            self.equilibria += 1;
            let start = point.as_ref().map_or(state, |pt| &pt.state);
            let pt = self
                .tracer
                .settle_at(start, self.clamps(q))
                .with_context(|| {
                    format!(
                        "equilibrium at {} = {:.6}, {} = {:.6}",
                        label(self.swept),
                        q[0],
                        label(self.along),
                        q[1]
                    )
                })?;
            point = Some(pt);
        }
        Ok(Site {
            p,
            on: p,
            point: point.expect("at least one move"),
        })
    }

    /// The condition at a site (a crossing follows its strands to the closest
    /// pair nearby).
    fn value(&mut self, c: &mut Condition, site: &Site) -> Result<f64> {
        let state = &site.point.state;
        Ok(match c {
            Condition::Wall => {
                let w = walls(state, self.measure.strip_width);
                w.min_z.min(state.clamps.top_wall() - w.max_z)
            }
            Condition::Crossing(s) => {
                let (points, _) = state.centreline();
                let reach = crate::geometry::closure::reach(&points);
                let segments = points.len() - 1;
                let near = |k: usize| k.saturating_sub(3)..(k + 4).min(segments);
                let mut best = (f64::INFINITY, 0.0, s.first, s.other);
                for i in near(s.first) {
                    let others: Vec<OtherStrand> = match s.other {
                        OtherStrand::Segment(j) => near(j)
                            .filter(|&j| j >= i + 2)
                            .map(OtherStrand::Segment)
                            .collect(),
                        ray => vec![ray],
                    };
                    for o in others {
                        let (d, signed) = strand_distance(&points, i, o, reach);
                        if d < best.0 {
                            best = (d, signed, i, o);
                        }
                    }
                }
                s.first = best.2;
                s.other = best.3;
                match s.other {
                    // a strip's ribbon touches itself before its centreline
                    // crosses (a ray, the closure's, has no width)
                    OtherStrand::Segment(j) if self.measure.strip_width > 0.0 => {
                        let width = self.measure.strip_width;
                        let (points, _, d1) = ribbon_data(state);
                        let ribbon = Ribbon {
                            points: &points,
                            d1: &d1,
                            width,
                        };
                        let window = ribbon_window(width, segments);
                        ribbon_gap(&ribbon, s.first, j, window, s.sign)
                    }
                    _ => s.sign * best.1,
                }
            }
            Condition::Stability => {
                let energy = &self.tracer.newton.energy;
                if energy.model.law.constrained() {
                    fail!(
                        "boundary walk: a stability boundary of a constrained law \
                         (lowest eigenvalue on the constraints' tangent space) is not traced"
                    );
                }
                let sp = crate::linalg::eigen::lowest_eigenvalues(
                    &energy.pattern,
                    &site.point.hessian,
                    None,
                    1,
                    &mut self.tracer.newton.ldlt,
                )
                .context("lowest eigenvalue on the stability boundary")?;
                sp.values[0]
            }
        })
    }

    /// Gradient of the condition in the plane (forward differences).
    fn gradient(&mut self, c: &mut Condition, site: &Site) -> Result<[f64; 2]> {
        let g0 = self.value(c, site)?;
        let h = if *c == Condition::Stability {
            STABILITY_FD
        } else {
            FD
        };
        let mut g = [0.0; 2];
        for (k, gk) in g.iter_mut().enumerate() {
            let mut p = site.p;
            p[k] += h;
            let s = self.equilibrium_at(site, p)?;
            *gk = (self.value(c, &s)? - g0) / h;
        }
        if !(g[0].is_finite() && g[1].is_finite()) || g == [0.0, 0.0] {
            fail!(
                "boundary walk: the condition {} has no gradient",
                c.describe()
            );
        }
        Ok(g)
    }

    /// The first property of a good knot that fails at `site`, other than the
    /// one the walk follows (`on`). On a crossing the knot is checked a step
    /// `FD` into the good side (`normal`), the strands being in contact.
    fn failing(
        &mut self,
        site: &Site,
        on: Option<&Condition>,
        normal: [f64; 2],
    ) -> Result<Option<Vanishing>> {
        let skip = on.map(Condition::vanishing);
        let state = &site.point.state;
        let w = walls(state, self.measure.strip_width);
        if skip != Some(Vanishing::WallGap)
            && (w.min_z <= 0.0 || w.max_z >= state.clamps.top_wall())
        {
            return Ok(Some(Vanishing::WallGap));
        }
        if skip != Some(Vanishing::Singularity) && site.point.negative_count > 0 {
            return Ok(Some(Vanishing::Singularity));
        }
        // on a crossing the knot is checked a step into the good side
        let off;
        let checked = if skip == Some(Vanishing::StrandGap) {
            off = self.equilibrium_at(site, along(site.p, normal, FD))?;
            &off.point.state
        } else {
            state
        };
        // a ribbon touches itself before its centreline crosses: so that
        // boundary first (see `condition_of`). On a crossing of the ribbon,
        // its own pieces (and their flip image's) may still touch at their
        // corners a step into the good side, where the edges the walk
        // follows are apart: they are left out of the check
        let followed: &[Strands] = match on {
            Some(Condition::Crossing(s)) => std::slice::from_ref(s),
            _ => &[],
        };
        if self.measure.strip_width > 0.0 && self.touching_strands(checked, followed).is_some() {
            return Ok(Some(Vanishing::RibbonGap));
        }
        let knot = closure_knot_along(&checked.centreline().0, checked.ray_directions()).ok();
        let knotted = self
            .measure
            .good
            .is_knot(knot.as_ref().map(|k| k.alexander.as_slice()));
        Ok((!knotted).then_some(Vanishing::StrandGap))
    }

    /// The condition behind a failure at the site `bad`, just past a corner
    /// (or the first boundary). A crossing's strands are those closest there,
    /// other than those in `except` (the crossing the walk is on, and those
    /// tried at this corner); its sign by [`Walk::orient_at`].
    fn condition_of(&mut self, failure: Vanishing, bad: &Site, except: &[Strands]) -> Condition {
        match failure {
            Vanishing::WallGap => Condition::Wall,
            Vanishing::Singularity => Condition::Stability,
            // `failing` tells walls, stability, the ribbon's touch and the
            // knot apart: the rest is a crossing (of the ribbon, whose
            // pieces touch, between segments only)
            Vanishing::StrandGap | Vanishing::RibbonGap | Vanishing::StrandMerger => {
                let (points, arc) = bad.point.state.centreline();
                let gap = self.measure.self_distance_gap;
                // a ribbon's: the pieces that touch (not always across the
                // centreline's closest pair, where the ribbon is flat)
                let touching = (failure == Vanishing::RibbonGap)
                    .then(|| self.touching_strands(&bad.point.state, except))
                    .flatten();
                let rays = failure != Vanishing::RibbonGap;
                let (first, other) =
                    touching.unwrap_or_else(|| closest_strands(&points, &arc, gap, except, rays));
                Condition::Crossing(Strands {
                    first,
                    other,
                    sign: 1.0,
                    segments: points.len() - 1,
                })
            }
        }
    }

    /// Two pieces of the ribbon of `state` that touch, other than those
    /// near the strands `except` (and their flip image).
    fn touching_strands(
        &self,
        state: &RodState,
        except: &[Strands],
    ) -> Option<(usize, OtherStrand)> {
        let width = self.measure.strip_width;
        let (points, arc, d1) = ribbon_data(state);
        let window = ribbon_window(width, points.len() - 1);
        let skip = |i: usize, j: usize| {
            except
                .iter()
                .any(|e| e.near_within(i, OtherStrand::Segment(j), window))
        };
        let ribbon = Ribbon {
            points: &points,
            d1: &d1,
            width,
        };
        let [i, j] = ribbon.touching_pair(&arc, self.measure.self_distance_gap, &skip)?;
        Some((i, OtherStrand::Segment(j)))
    }

    /// Orient a crossing positive on the good side: its sign at `reference`,
    /// a good site clearly away from where the strands touch. At a corner
    /// the walk's direction then checks it (see `walk_around`).
    fn orient_at(&mut self, c: &mut Condition, reference: &Site) -> Result<()> {
        if let Condition::Crossing(s) = c {
            let mut probe = Condition::Crossing(*s);
            if self.value(&mut probe, reference)? < 0.0 {
                s.sign = -1.0;
            }
        }
        Ok(())
    }

    /// The point of condition `c` on the line through `p` along `normal`
    /// (secant iteration from the slope `slope`), continued from `from`.
    fn correct_on(
        &mut self,
        c: &mut Condition,
        from: &Site,
        p: [f64; 2],
        normal: [f64; 2],
        slope: f64,
        limit: f64,
    ) -> Result<(Site, usize)> {
        // on a stability boundary the equilibria are solved a little on the
        // stable side of the predicted root and the root is extrapolated
        let offset = if *c == Condition::Stability {
            2.0 * STABILITY_TOL
        } else {
            0.0
        };
        let site = self.equilibrium_at(from, p)?;
        let g = self.value(c, &site)?;
        let secant = Secant {
            max_evaluations: 12,
            tolerance: CORRECTOR_TOL,
            reach: Reach::Around {
                centre: 0.0,
                radius: limit,
            },
            offset,
            confirm: false,
            // points too close for the lowest eigenvalue's accuracy keep
            // the chord's slope
            shortest_chord: if offset == 0.0 {
                0.0
            } else {
                1e3 * CORRECTOR_TOL
            },
            ..Secant::default()
        };
        let start = Start::Slope(
            Iterate {
                at: 0.0,
                value: g,
                point: site,
            },
            slope,
        );
        let found = secant.find(
            start,
            |at, _, last, _| {
                let next = self.equilibrium_at(&last.point, along(p, normal, at))?;
                let value = self.value(c, &next)?;
                Ok(Iterate {
                    at,
                    value,
                    point: next,
                })
            },
            |_, _| false,
        );
        match found {
            Ok(root) => {
                let mut site = root.last.point;
                site.on = along(p, normal, root.at);
                Ok((site, root.iterations))
            }
            Err(SecantFailure { why, .. }) => match why {
                NoRoot::Failed(e) => Err(e),
                NoRoot::Left(_) | NoRoot::Flat => {
                    fail!("corrector left the neighbourhood of {}", c.describe())
                }
                NoRoot::NotConverged => fail!("corrector on {} did not converge", c.describe()),
            },
        }
    }

    /// The point of `c` a distance `s` along the tangent from the walk's
    /// point `at`, corrected along its normal (no farther than half the step).
    fn correct_along(
        &mut self,
        c: &mut Condition,
        at: &Step,
        s: f64,
        sigma: f64,
    ) -> Result<(Site, usize)> {
        let t = left_tangent(at.gradient);
        let slope = at.gradient[0].hypot(at.gradient[1]);
        let p = along(at.site.p, t, s);
        self.correct_on(
            c,
            &at.site,
            p,
            unit(at.gradient),
            slope,
            0.5 * sigma.max(1e-4),
        )
    }

    fn inside(&self, p: [f64; 2]) -> bool {
        (0..2).all(|k| p[k] >= self.bounds[k][0] && p[k] <= self.bounds[k][1])
    }
}

/// A point of the walk: site, its condition's gradient.
struct Step {
    site: Site,
    gradient: [f64; 2],
}

/// Trace the boundary of the good region of `scene`'s map from the scene's
/// start, which must be a good knot: move up in the continuation's parameter
/// to the first boundary, then walk around the region.
pub fn trace_island(
    scene: &Scene,
    spec: &MapSpec,
    segments: Option<usize>,
    on_point: &dyn Fn(usize, &str),
) -> Result<Traced> {
    let cont = scene
        .continuation
        .as_ref()
        .context("[map] needs a [continuation] giving the branches")?;
    let (swept, along) = (spec.parameter, cont.parameter);
    if swept == along {
        fail!(
            "map.parameter: the boundary is traced in (map.parameter, continuation.parameter); \
             both are {}",
            swept.name()
        );
    }
    let (mut newton, state, _) = starting_equilibrium(scene, segments)?;
    let mut tracer = Tracer::new(&mut newton, along, cont.settings());
    let base = state.clamps;
    let mut walk = Walk {
        tracer: &mut tracer,
        measure: scene.measure(),
        base,
        swept,
        along,
        bounds: [spec.range, cont.range],
        max_step: spec.trace_step,
        equilibria: 0,
    };
    let p0 = [swept.value(&base), along.value(&base)];
    if !p0.iter().all(|v| v.is_finite()) {
        fail!(
            "the boundary walk's start: the scene's start carries no value of {} or {}",
            label(swept),
            label(along)
        );
    }
    if !walk.inside(spec.trace_from.unwrap_or(p0)) {
        fail!(
            "the boundary walk's start ({} = {}, {} = {}: map.trace_from or the scene's \
             start) lies outside the map's range",
            label(swept),
            spec.trace_from.unwrap_or(p0)[0],
            label(along),
            spec.trace_from.unwrap_or(p0)[1]
        );
    }
    let start = walk
        .equilibrium_from(&state, p0, p0)
        .context("the map's start")?;
    let (start, p0) = match spec.trace_from {
        Some(p) if p != p0 => {
            let s = walk
                .equilibrium_at(&start, p)
                .context("from the scene's start to map.trace_from")?;
            (s, p)
        }
        _ => (start, p0),
    };
    if let Some(f) = walk.failing(&start, None, [0.0, 0.0])? {
        fail!(
            "the boundary walk starts from a good knot (map.trace_from, or the scene's start); \
             at {} = {}, {} = {} {}",
            label(swept),
            p0[0],
            label(along),
            p0[1],
            f.failure()
        );
    }
    let mut pieces: Vec<Trail> = Vec::new();
    let outcome = walk_around(&mut walk, start, &mut pieces, on_point);
    let stopped = outcome.err().map(|e| describe(&e));
    let closed = stopped.is_none();
    let pieces = merge_crossings(pieces);
    let polished = (closed && spec.polish).then(|| {
        polish_boundary(
            &walk.tracer.newton.energy.model,
            [swept, along],
            base,
            &pieces,
            spec.trace_step,
            walk.measure.strip_width,
        )
    });
    let mut traced = name_pieces([swept, along], walk.equilibria, pieces, closed, stopped);
    match polished {
        Some(Ok(p)) => traced.polished = Some(p),
        Some(Err(why)) => traced.not_polished = Some(why.failure()),
        None => {}
    }
    Ok(traced)
}

/// Walk round the good region from `start`: up along the lines (p[1]) to
/// the first boundary,
/// then along each condition, turning at every corner, until the walk
/// passes its start again.
fn walk_around(
    walk: &mut Walk,
    start: Site,
    pieces: &mut Vec<Trail>,
    on_point: &dyn Fn(usize, &str),
) -> Result<()> {
    let (c, at) = first_boundary(walk, start)?;
    let mut tour = Tour {
        first: at.site.on,
        first_kind: c.vanishing(),
        c,
        at,
        step: StepControl::new(FIRST_STEP, MIN_STEP, walk.max_step, 1.4, 4),
        count: 1,
        stuck: 0,
        tried: Vec::new(),
    };
    pieces.push((
        tour.c,
        vec![TrailPoint {
            at: tour.first,
            normal: unit(tour.at.gradient),
            state: Some(tour.at.site.point.state.clone()),
        }],
    ));
    loop {
        tour.check_budget(walk)?;
        let t = left_tangent(tour.at.gradient);
        let normal = unit(tour.at.gradient);
        let (q, sigma, g) = tour.advance(walk, t)?;
        if !walk.inside(q.p) {
            fail!(
                "the good region reaches the map's range at ({:.5}, {:.5})",
                q.p[0],
                q.p[1]
            );
        }
        match walk.failing(&q, Some(&tour.c), unit(g))? {
            None => {
                if tour.closes(&q, t, sigma) {
                    let first = pieces[0].1[0].clone();
                    pieces.last_mut().unwrap().1.push(first);
                    return Ok(());
                }
                let piece = pieces.last_mut().unwrap();
                piece.1.push(TrailPoint {
                    at: q.on,
                    normal: unit(g),
                    state: Some(q.point.state.clone()),
                });
                tour.count += 1;
                on_point(tour.count, &piece.0.describe());
                tour.at = Step {
                    site: q,
                    gradient: g,
                };
            }
            Some(failure) => {
                tour.turn_at_corner(walk, q, sigma, failure, normal, pieces)?;
                on_point(tour.count, &tour.c.describe());
            }
        }
    }
}

/// The first boundary above the start along the lines (bisected to it), its
/// condition
/// oriented positive on the good side, and the walk's first point on it.
fn first_boundary(walk: &mut Walk, start: Site) -> Result<(Condition, Step)> {
    let up = [0.0, 1.0];
    let mut good = start;
    let bad = loop {
        let p = along(good.p, up, SUBSTEP);
        if !walk.inside(p) {
            fail!(
                "no boundary above the start within the range of {}",
                label(walk.along)
            );
        }
        let s = walk.equilibrium_at(&good, p)?;
        match walk.failing(&s, None, up)? {
            None => good = s,
            Some(f) => break (s, f),
        }
    };
    let reference = good.clone();
    let (mut lo, mut hi, failure) = (good, bad.0, bad.1);
    let tol = if failure == Vanishing::Singularity {
        STABILITY_TOL
    } else {
        1e-9
    };
    while hi.p[1] - lo.p[1] > tol {
        let mid = walk.equilibrium_at(&lo, [lo.p[0], 0.5 * (lo.p[1] + hi.p[1])])?;
        match walk.failing(&mid, None, up)? {
            None => lo = mid,
            Some(_) => hi = mid,
        }
    }
    let mut c = walk.condition_of(failure, &hi, &[]);
    walk.orient_at(&mut c, &reference)?;
    let gradient = walk.gradient(&mut c, &lo)?;
    Ok((c, Step { site: lo, gradient }))
}

/// The walk's progress round the region.
struct Tour {
    /// The condition followed now.
    c: Condition,
    /// The last point on it.
    at: Step,
    /// Step along the curve.
    step: StepControl,
    /// Points so far.
    count: usize,
    /// Corners met in a row without progress.
    stuck: usize,
    /// Crossings tried at this corner.
    tried: Vec<Strands>,
    /// Where the walk started, and on which kind of condition.
    first: [f64; 2],
    first_kind: Vanishing,
}

impl Tour {
    /// Stop a walk that creeps through a tangle of tiny corners.
    fn check_budget(&self, walk: &Walk) -> Result<()> {
        if self.count >= MAX_POINTS || walk.equilibria >= MAX_EQUILIBRIA {
            fail!(
                "boundary walk: {} points and {} equilibria without closing, at ({:.5}, {:.5})",
                self.count,
                walk.equilibria,
                self.at.site.on[0],
                self.at.site.on[1]
            );
        }
        Ok(())
    }

    /// The next point one step along the tangent `t`, corrected onto the
    /// curve, with the step it was found at and its gradient: the one step
    /// loop of path following ([`StepControl::advance`]), halving until the
    /// tangent turns by less than [`WALK_ACCEPTANCE`] allows.
    fn advance(&mut self, walk: &mut Walk, t: [f64; 2]) -> Result<(Site, f64, [f64; 2])> {
        let (c, at) = (&mut self.c, &self.at);
        let found = self.step.advance(&WALK_ACCEPTANCE, |sigma| {
            let (q, iterations) = walk.correct_along(c, at, sigma, sigma)?;
            let g = walk.gradient(c, &q)?;
            Ok::<_, StudyError>(Trial {
                turn: dot2(left_tangent(g), t),
                point: (q, g),
                iterations,
                correction: 0.0,
            })
        });
        match found {
            Ok(((q, g), sigma)) => Ok((q, sigma, g)),
            Err(last) => {
                let why = last.map_or("the boundary turns too sharply".into(), |e: StudyError| {
                    describe(&e)
                });
                fail!(
                    "boundary walk stopped on {} at ({:.5}, {:.5}): {why}",
                    self.c.describe(),
                    self.at.site.p[0],
                    self.at.site.p[1]
                );
            }
        }
    }

    /// The walk closed: its start lies between the last point and `q` (a
    /// step `sigma` along), on the same kind of condition.
    fn closes(&self, q: &Site, t: [f64; 2], sigma: f64) -> bool {
        let first = self.first;
        let d0 = [first[0] - self.at.site.on[0], first[1] - self.at.site.on[1]];
        let d1 = [first[0] - q.on[0], first[1] - q.on[1]];
        let near = d0[0].hypot(d0[1]) < 2.0 * sigma;
        self.count > 3
            && self.c.vanishing() == self.first_kind
            && near
            && dot2(d0, t) > 0.0
            && dot2(d1, t) <= 0.0
    }

    /// A corner: bisect along the curve to where another property fails
    /// (first seen failing at `q`, a step `sigma` along), and turn onto that
    /// property's condition.
    fn turn_at_corner(
        &mut self,
        walk: &mut Walk,
        q: Site,
        sigma: f64,
        first_failure: Vanishing,
        normal: [f64; 2],
        pieces: &mut Vec<Trail>,
    ) -> Result<()> {
        let (good, bad, failure, progress) =
            self.bisect_corner(walk, q, first_failure, normal, sigma)?;
        // a corner right at the previous one: the crossing taken there made
        // no progress (several strands in contact at a tip), so the next
        // closest strands are tried
        if progress < 1e-6 {
            self.stuck += 1;
        } else {
            self.stuck = 0;
            self.tried.clear();
        }
        if let Condition::Crossing(s) = self.c {
            self.tried.push(s);
        }
        if self.stuck > 12 {
            fail!(
                "boundary walk stuck at a corner of {} at ({:.5}, {:.5})",
                self.c.describe(),
                good.on[0],
                good.on[1]
            );
        }
        let corner = good.on;
        let old = unit(walk.gradient(&mut self.c, &good)?);
        pieces.last_mut().unwrap().1.push(TrailPoint {
            at: corner,
            normal: old,
            state: Some(good.point.state.clone()),
        });
        let mut c = walk.condition_of(failure, &bad, &self.tried);
        walk.orient_at(&mut c, &self.at.site)?;
        let mut gradient = walk.gradient(&mut c, &good)?;
        // the region is the intersection of the good sides, so the walk
        // leaves a corner into the old condition's good side; a crossing of
        // the centrelines whose sign at the last point says otherwise is
        // turned round. Not the ribbon's: its gap, the least of four edge
        // pairs' signed distances, is no odd function of the sign (turned
        // round it would vanish elsewhere, not at this corner), and
        // `orient_at` made it positive on the good side already
        let ribbon = walk.measure.strip_width > 0.0
            && matches!(&c, Condition::Crossing(s) if matches!(s.other, OtherStrand::Segment(_)));
        if let Condition::Crossing(s) = &mut c
            && !ribbon
            && dot2(left_tangent(gradient), normal) < 0.0
        {
            s.sign = -s.sign;
            gradient = [-gradient[0], -gradient[1]];
        }
        pieces.push((
            c,
            vec![TrailPoint {
                at: corner,
                normal: unit(gradient),
                state: Some(good.point.state.clone()),
            }],
        ));
        self.count += 1;
        self.c = c;
        self.at = Step {
            site: good,
            gradient,
        };
        self.step.restart();
        Ok(())
    }

    /// Bisect the step `sigma` along the curve between the last good point
    /// and `q`: the last good site, the first failing one, what fails there,
    /// and how far along the corner lies.
    fn bisect_corner(
        &mut self,
        walk: &mut Walk,
        q: Site,
        first_failure: Vanishing,
        normal: [f64; 2],
        sigma: f64,
    ) -> Result<(Site, Site, Vanishing, f64)> {
        let tol = if first_failure == Vanishing::Singularity {
            STABILITY_TOL
        } else {
            1e-8
        };
        let b = bisect(
            0.0,
            sigma,
            |a, b| b - a <= tol,
            |m, _| {
                // no equilibrium on the curve there: count it as past the corner
                let Ok((s, _)) = walk.correct_along(&mut self.c, &self.at, m, sigma) else {
                    return Ok(Probe::Unsolved);
                };
                Ok::<_, StudyError>(match walk.failing(&s, Some(&self.c), normal)? {
                    None => Probe::Holds(m, s),
                    Some(f) => Probe::Fails(m, (s, f)),
                })
            },
        )?;
        let good = b.holds.unwrap_or_else(|| self.at.site.clone());
        let (bad, failure) = b.fails.unwrap_or((q, first_failure));
        Ok((good, bad, failure, b.hi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_good_side_lies_to_the_left_of_the_walk() {
        // good side towards +z* (gradient (1, 0)): walk down along the lines
        assert_eq!(left_tangent([1.0, 0.0]), [0.0, -1.0]);
        let t = left_tangent([0.3, 0.4]);
        // left of t = (−t_y, t_x) points along the gradient
        assert!((-t[1] * 0.3 + t[0] * 0.4) > 0.0);
    }
}
