//! The boundary of the island of good knots traced directly in the plane of
//! two clamp parameters (the map's swept parameter, φ/2π). Each boundary is a
//! codimension-one condition on the equilibria, zero on the curve and
//! positive on the good side:
//! - a wall touched: the smaller of the lowest interior node height (z = 0)
//!   and z* minus the highest (z = z*) — one condition, since the flip
//!   symmetry maps z to z* − z and a symmetric knot touches both at once;
//! - a crossing: the signed distance of the two strands (two segments, or a
//!   segment and a clamp's ray) whose passage changes the knot;
//! - stability: the lowest eigenvalue of the Hessian.
//!
//! A condition is followed by pseudo-arclength continuation of its zero set in
//! the plane: a predictor along the curve's tangent, a corrector along its
//! normal (secant iteration on the condition), each evaluation an equilibrium
//! found by Newton at fixed clamps from its neighbour, so that the whole walk
//! stays on one family of equilibria. Walking with the good region on the
//! left, the walk turns onto the next condition at every corner where another
//! property fails, until it closes on its start.

use crate::equilibrium::{Measure, Shape, starting_equilibrium};
use crate::geometry::distance::segment_distance;
use crate::map::{Line, MapSpec};
use crate::model::rod::{Clamps, Parameter};
use crate::scene::Scene;
use crate::solve::continuation::{Point, Tracer};
use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The other strand of a crossing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Other {
    /// Another segment of the centreline.
    Segment(usize),
    /// The ray continuing the s = 0 clamp (along −e3).
    BottomRay,
    /// The ray continuing the s = 1 clamp (along +e3).
    TopRay,
}

/// Two strands whose passage through each other changes the knot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strands {
    /// Segment of the centreline (segment k joins centreline points k, k+1).
    pub first: usize,
    /// The strand it crosses.
    pub other: Other,
    /// Orientation: +1 or −1, so that the good side is positive.
    pub sign: f64,
    /// Number of centreline segments (for the flip image of the strands).
    pub segments: usize,
}

/// A boundary condition: zero on the curve, positive on the good side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Condition {
    /// Walls: min(lowest interior node height, z* − highest).
    Wall,
    /// Signed distance of two crossing strands.
    Crossing(Strands),
    /// Lowest eigenvalue of the Hessian.
    Stability,
}

/// The property of a good knot that fails first at a state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Failure {
    Wall,
    Knot,
    Stability,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Failure::Wall => "it is not between the walls",
            Failure::Knot => "its ray closure is not a trefoil",
            Failure::Stability => "it is unstable",
        })
    }
}

impl Condition {
    fn failure(&self) -> Failure {
        match self {
            Condition::Wall => Failure::Wall,
            Condition::Crossing(_) => Failure::Knot,
            Condition::Stability => Failure::Stability,
        }
    }

    /// Description, as in the JSON summary.
    pub fn describe(&self) -> String {
        match self {
            Condition::Wall => "wall".into(),
            Condition::Crossing(s) => match s.other {
                Other::Segment(j) => format!("crossing of segments {} and {j}", s.first),
                Other::BottomRay => format!("segment {} crossing the bottom ray", s.first),
                Other::TopRay => format!("segment {} crossing the top ray", s.first),
            },
            Condition::Stability => "lowest eigenvalue zero".into(),
        }
    }
}

/// One piece of the traced boundary: a polyline on one condition.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Piece {
    /// Paper-style name (W1, W2, X, X1, S, ...).
    pub label: String,
    /// The condition followed.
    pub condition: String,
    /// Points (swept parameter, φ/2π) in walk order (good region on the left).
    pub points: Vec<[f64; 2]>,
}

/// How the traced boundary compares with the grid of one-parameter branches.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct GridCheck {
    /// Grid interval ends compared (lines whose value the loop spans).
    pub ends: usize,
    /// Largest |φ/2π(grid end) − φ/2π(nearest boundary crossing of that line)|.
    pub max_phi_deviation: f64,
    /// Lines where the loop and the grid count different interval ends.
    pub lines_with_other_count: Vec<f64>,
}

/// The island's boundary traced by two-parameter continuation.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Traced {
    /// The pieces in walk order.
    pub pieces: Vec<Piece>,
    /// The walk came back to its start.
    pub closed: bool,
    /// Area enclosed (closed walks only).
    pub area: Option<f64>,
    /// Extent of the traced boundary: {parameter: [lo, hi], "phi_over_2pi": [lo, hi]}.
    pub bounding_box: BTreeMap<String, [f64; 2]>,
    /// Points on the boundary and equilibria solved for them.
    pub points: usize,
    /// Equilibria solved (Newton at fixed clamps).
    pub equilibria: usize,
    /// Why the walk stopped before closing, if it did.
    pub stopped: Option<String>,
    /// Comparison with the grid's good intervals.
    #[serde(default)]
    pub grid_check: Option<GridCheck>,
}

impl Traced {
    /// φ/2π where the traced loop crosses the line (swept parameter = v).
    pub fn cuts(&self, v: f64) -> Vec<f64> {
        let all: Vec<[f64; 2]> = self.pieces.iter().flat_map(|p| p.points.clone()).collect();
        all.windows(2)
            .filter(|w| (w[0][0] <= v) != (w[1][0] <= v))
            .map(|w| w[0][1] + (v - w[0][0]) / (w[1][0] - w[0][0]) * (w[1][1] - w[0][1]))
            .collect()
    }

    /// A walk that could not start.
    pub fn failed(why: String) -> Self {
        Traced {
            pieces: vec![],
            closed: false,
            area: None,
            bounding_box: BTreeMap::new(),
            points: 0,
            equilibria: 0,
            stopped: Some(why),
            grid_check: None,
        }
    }
}

/// The traced boundary of a map, read from `cache/trace.json` when an earlier
/// (interrupted) run wrote it, else traced and written there.
pub fn trace_cached(
    scene: &Scene,
    spec: &MapSpec,
    segments: Option<usize>,
    cache: &std::path::Path,
    on_point: &dyn Fn(usize, &str),
) -> Result<Traced> {
    std::fs::create_dir_all(cache).with_context(|| format!("creating {}", cache.display()))?;
    let file = cache.join("trace.json");
    if let Some(t) = std::fs::read_to_string(&file)
        .ok()
        .and_then(|t| serde_json::from_str::<Traced>(&t).ok())
    {
        return Ok(t);
    }
    let traced = trace_island(scene, spec, segments, on_point)
        .unwrap_or_else(|e| Traced::failed(format!("{e:#}")));
    let tmp = file.with_extension("json.tmp");
    std::fs::write(&tmp, serde_json::to_vec(&traced)?)?;
    std::fs::rename(&tmp, &file)?;
    Ok(traced)
}

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
const MAX_EQUILIBRIA: usize = 100_000;
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

struct Walk<'t, 'a> {
    tracer: &'t mut Tracer<'a>,
    measure: Measure,
    base: Clamps,
    swept: Parameter,
    bounds: [[f64; 2]; 2],
    max_step: f64,
    equilibria: usize,
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

/// Signed distance of segment i from the other strand (positive along
/// tᵢ × t_other) and the unsigned distance.
fn strand_distance(points: &[Vector3<f64>], i: usize, other: Other, reach: f64) -> (f64, f64) {
    let (a0, a1) = (points[i], points[i + 1]);
    let last = *points.last().unwrap();
    let (b0, b1) = match other {
        Other::Segment(j) => (points[j], points[j + 1]),
        Other::BottomRay => (points[0], points[0] - reach * Vector3::z()),
        Other::TopRay => (last, last + reach * Vector3::z()),
    };
    let (d, ta, tb) = segment_distance(&a0, &a1, &b0, &b1);
    let pa = a0 + ta * (a1 - a0);
    let pb = b0 + tb * (b1 - b0);
    let n = (a1 - a0).cross(&(b1 - b0));
    (d, (pb - pa).dot(&n) / n.norm().max(1e-300))
}

impl Strands {
    /// The same strands, up to 3 segments along each, or their image by
    /// the flip symmetry (s ↔ 1 − s, the rays swapped): a flip-symmetric
    /// knot passes through itself at two mirror points at once, so the two
    /// crossings are one boundary.
    fn near(&self, first: usize, other: Other) -> bool {
        // strands crossing at a shallow angle are close over several pairs
        let close = |x: usize, y: usize| x.abs_diff(y) <= 3;
        let same = |a: usize, oa: Other, b: usize, ob: Other| {
            close(a, b)
                && match (oa, ob) {
                    (Other::Segment(i), Other::Segment(j)) => close(i, j),
                    (x, y) => x == y,
                }
        };
        let m = |i: usize| (self.segments - 1).saturating_sub(i);
        let mirror = match other {
            Other::Segment(j) => (m(j), Other::Segment(m(first))),
            Other::BottomRay => (m(first), Other::TopRay),
            Other::TopRay => (m(first), Other::BottomRay),
        };
        same(self.first, self.other, first, other)
            || same(self.first, self.other, mirror.0, mirror.1)
    }
}

/// The strands nearest to passing through each other: the closest pair of
/// segments at least `gap` apart in arc length, or a segment and a ray,
/// other than the strands `except` (the crossings the walk is on or tried
/// already at this corner, in contact
/// at a corner between two crossings).
fn closest_strands(
    points: &[Vector3<f64>],
    arc: &[f64],
    gap: f64,
    except: &[Strands],
) -> (usize, Other) {
    let reach = 2.0 * crate::geometry::closure::extent(points) + 1.0;
    let segments = points.len() - 1;
    let skip = |i: usize, o: Other| except.iter().any(|e| e.near(i, o));
    let mut best = (f64::INFINITY, 0, Other::TopRay);
    for i in 0..segments {
        for j in i + 1..segments {
            if arc[j] - arc[i + 1] >= gap && !skip(i, Other::Segment(j)) {
                let d = strand_distance(points, i, Other::Segment(j), reach).0;
                if d < best.0 {
                    best = (d, i, Other::Segment(j));
                }
            }
        }
        for (ray, base) in [(Other::BottomRay, 0.0), (Other::TopRay, 1.0)] {
            let mid = 0.5 * (arc[i] + arc[i + 1]);
            if (mid - base).abs() >= gap && !skip(i, ray) {
                let d = strand_distance(points, i, ray, reach).0;
                if d < best.0 {
                    best = (d, i, ray);
                }
            }
        }
    }
    (best.1, best.2)
}

impl Walk<'_, '_> {
    fn clamps(&self, p: [f64; 2]) -> Clamps {
        self.swept
            .with(&Parameter::Phi.with(&self.base, p[1]), p[0])
    }

    /// The equilibrium at `p`, continued from the one at `from` in moves of at
    /// most `SUBSTEP` per coordinate.
    fn settle(&mut self, from: &Site, p: [f64; 2]) -> Result<Site> {
        if !(p[0].is_finite() && p[1].is_finite()) {
            bail!("boundary walk: non-finite parameters");
        }
        let moves = ((p[0] - from.p[0]).abs().max((p[1] - from.p[1]).abs()) / SUBSTEP).ceil();
        let moves = (moves as usize).max(1);
        let mut state = from.point.state.clone();
        let mut point = None;
        for k in 1..=moves {
            let f = k as f64 / moves as f64;
            let q = [
                from.p[0] + f * (p[0] - from.p[0]),
                from.p[1] + f * (p[1] - from.p[1]),
            ];
            self.equilibria += 1;
            let pt = self
                .tracer
                .settle_at(&state, self.clamps(q))
                .with_context(|| {
                    format!(
                        "equilibrium at {} = {:.6}, φ/2π = {:.6}",
                        self.swept.name(),
                        q[0],
                        q[1]
                    )
                })?;
            state = pt.state.clone();
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
                let (lo, hi) = state.z_range();
                lo.min(state.clamps.z_star - hi)
            }
            Condition::Crossing(s) => {
                let (points, _) = state.centreline();
                let reach = 2.0 * crate::geometry::closure::extent(&points) + 1.0;
                let segments = points.len() - 1;
                let near = |k: usize| k.saturating_sub(3)..(k + 4).min(segments);
                let mut best = (f64::INFINITY, 0.0, s.first, s.other);
                for i in near(s.first) {
                    let others: Vec<Other> = match s.other {
                        Other::Segment(j) => near(j)
                            .filter(|&j| j >= i + 2)
                            .map(Other::Segment)
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
                s.sign * best.1
            }
            Condition::Stability => {
                let energy = &self.tracer.newton.energy;
                if energy.model.law.constrained() {
                    bail!(
                        "boundary walk: a stability boundary of a constrained law \
                         (lowest eigenvalue on the constraints' tangent space) is not traced"
                    );
                }
                let sp = crate::stability::lowest_eigenvalues(
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
            let s = self.settle(site, p)?;
            *gk = (self.value(c, &s)? - g0) / h;
        }
        if !(g[0].is_finite() && g[1].is_finite()) || g == [0.0, 0.0] {
            bail!(
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
    ) -> Result<Option<Failure>> {
        let skip = on.map(Condition::failure);
        let state = &site.point.state;
        let (lo, hi) = state.z_range();
        if skip != Some(Failure::Wall) && (lo <= 0.0 || hi >= state.clamps.z_star) {
            return Ok(Some(Failure::Wall));
        }
        if skip != Some(Failure::Stability) && site.point.negative_count > 0 {
            return Ok(Some(Failure::Stability));
        }
        let knotted = if skip == Some(Failure::Knot) {
            let off = self.settle(site, along(site.p, normal, FD))?;
            Shape::of(&off.point.state, &self.measure).knot.determinant == 3
        } else {
            Shape::of(state, &self.measure).knot.determinant == 3
        };
        Ok((!knotted).then_some(Failure::Knot))
    }

    /// The condition behind a failure at the site `bad`, just past a corner
    /// (or the first boundary). A crossing's strands are those closest there,
    /// other than the crossing the walk is `on`; its sign is taken at
    /// `reference`, a good site clearly away from the corner (at the corner
    /// itself both crossings are in contact).
    fn condition_of(
        &mut self,
        failure: Failure,
        reference: &Site,
        bad: &Site,
        except: &[Strands],
    ) -> Result<Condition> {
        Ok(match failure {
            Failure::Wall => Condition::Wall,
            Failure::Stability => Condition::Stability,
            Failure::Knot => {
                let (points, arc) = bad.point.state.centreline();
                let (first, other) =
                    closest_strands(&points, &arc, self.measure.self_distance_gap, except);
                let mut c = Condition::Crossing(Strands {
                    first,
                    other,
                    sign: 1.0,
                    segments: points.len() - 1,
                });
                let mut probe = c;
                let v = self.value(&mut probe, reference)?;
                if let Condition::Crossing(s) = &mut c {
                    s.sign = if v < 0.0 { -1.0 } else { 1.0 };
                }
                c
            }
        })
    }

    /// The point of condition `c` on the line through `p` along `normal`
    /// (secant iteration from the slope `slope`), continued from `from`.
    fn correct(
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
        let mut site = self.settle(from, p)?;
        let mut g = self.value(c, &site)?;
        let (mut s, mut slope, mut last_root) = (0.0, slope, f64::NAN);
        for it in 1..=12 {
            let root = s - g / slope;
            if !root.is_finite() || root.abs() > limit {
                bail!("corrector left the neighbourhood of {}", c.describe());
            }
            if (root - last_root).abs() <= CORRECTOR_TOL
                || (offset == 0.0 && (root - s).abs() <= CORRECTOR_TOL)
            {
                site.on = along(p, normal, root);
                return Ok((site, it));
            }
            let target = root + offset;
            let next = self.settle(&site, along(p, normal, target))?;
            let gn = self.value(c, &next)?;
            // secant update, unless the points are too close for the lowest
            // eigenvalue's accuracy (then the chord's slope is kept)
            let resolvable = offset == 0.0 || (target - s).abs() > 1e3 * CORRECTOR_TOL;
            if gn != g && target != s && resolvable {
                slope = (gn - g) / (target - s);
            }
            (s, g, site, last_root) = (target, gn, next, root);
        }
        bail!("corrector on {} did not converge", c.describe())
    }

    fn inside(&self, p: [f64; 2]) -> bool {
        (0..2).all(|k| p[k] >= self.bounds[k][0] && p[k] <= self.bounds[k][1])
    }
}

/// A piece of the walk: its condition, and its points with the φ component
/// of the condition's unit gradient (positive: the good side lies above).
type Trail = (Condition, Vec<([f64; 2], f64)>);

/// A point of the walk: site, its condition's gradient.
struct Step {
    site: Site,
    gradient: [f64; 2],
}

/// Trace the boundary of the good region of `scene`'s map from the scene's
/// start, which must be a good knot: move up in φ to the first boundary, then
/// walk around the region.
pub fn trace_island(
    scene: &Scene,
    spec: &MapSpec,
    segments: Option<usize>,
    on_point: &dyn Fn(usize, &str),
) -> Result<Traced> {
    let cont = scene
        .continuation
        .as_ref()
        .context("[map] needs a [continuation] in φ")?;
    if spec.parameter == Parameter::Phi {
        bail!("map.parameter: the boundary is traced in (parameter, φ); it cannot be φ");
    }
    let (mut newton, state, _) = starting_equilibrium(scene, segments)?;
    let mut tracer = Tracer::new(&mut newton, Parameter::Phi, cont.settings());
    let base = state.clamps;
    let mut walk = Walk {
        tracer: &mut tracer,
        measure: Measure::of(scene),
        base,
        swept: spec.parameter,
        bounds: [spec.range, cont.range],
        max_step: spec.trace_step,
        equilibria: 0,
    };
    if !(spec.trace_step > 0.0 && spec.trace_step.is_finite()) {
        bail!("map.trace_step must be positive, not {}", spec.trace_step);
    }
    let p0 = [spec.parameter.value(&base), base.phi_over_2pi()];
    if !walk.inside(spec.trace_from.unwrap_or(p0)) {
        bail!(
            "the boundary walk's start ({} = {}, φ/2π = {}: map.trace_from or the scene's \
             start) lies outside the map's range",
            spec.parameter.name(),
            spec.trace_from.unwrap_or(p0)[0],
            spec.trace_from.unwrap_or(p0)[1]
        );
    }
    let start = Site {
        p: p0,
        on: p0,
        point: Point {
            state: state.clone(),
            tangent_q: vec![],
            tangent_p: 0.0,
            negative_count: 0,
            iterations: 0,
            residual: 0.0,
            correction: 0.0,
            hessian: std::sync::Arc::from(Vec::new()),
        },
    };
    let start = walk.settle(&start, p0).context("the map's start")?;
    let (start, p0) = match spec.trace_from {
        Some(p) if p != p0 => {
            let s = walk
                .settle(&start, p)
                .context("from the scene's start to map.trace_from")?;
            (s, p)
        }
        _ => (start, p0),
    };
    if let Some(f) = walk.failing(&start, None, [0.0, 0.0])? {
        bail!(
            "the boundary walk starts from a good knot (map.trace_from, or the scene's start); \
             at {} = {}, φ/2π = {} {f}",
            spec.parameter.name(),
            p0[0],
            p0[1]
        );
    }
    let mut pieces: Vec<Trail> = Vec::new();
    let outcome = walk_around(&mut walk, start, &mut pieces, on_point);
    let stopped = outcome.err().map(|e| format!("{e:#}"));
    let closed = stopped.is_none();
    Ok(finish(walk.swept, walk.equilibria, pieces, closed, stopped))
}

/// Move up in φ from `start` to the first boundary, then walk around.
fn walk_around(
    walk: &mut Walk,
    start: Site,
    pieces: &mut Vec<Trail>,
    on_point: &dyn Fn(usize, &str),
) -> Result<()> {
    // first boundary above the start in φ
    let up = [0.0, 1.0];
    let mut good = start;
    let bad = loop {
        let p = along(good.p, up, SUBSTEP);
        if !walk.inside(p) {
            bail!("no boundary above the start within the map's φ range");
        }
        let s = walk.settle(&good, p)?;
        match walk.failing(&s, None, up)? {
            None => good = s,
            Some(f) => break (s, f),
        }
    };
    let reference = good.clone();
    let (mut lo, mut hi, failure) = (good, bad.0, bad.1);
    let tol = if failure == Failure::Stability {
        STABILITY_TOL
    } else {
        1e-9
    };
    while hi.p[1] - lo.p[1] > tol {
        let mid = walk.settle(&lo, [lo.p[0], 0.5 * (lo.p[1] + hi.p[1])])?;
        match walk.failing(&mid, None, up)? {
            None => lo = mid,
            Some(_) => hi = mid,
        }
    }
    let mut c = walk.condition_of(failure, &reference, &hi, &[])?;
    let gradient = walk.gradient(&mut c, &lo)?;
    let (first, first_kind) = (lo.on, c.failure());
    let mut at = Step { site: lo, gradient };
    pieces.push((c, vec![(first, unit(at.gradient)[1])]));
    let mut sigma = FIRST_STEP;
    let mut count = 1;
    let mut stuck = 0;
    let mut tried: Vec<Strands> = Vec::new();
    loop {
        if count >= MAX_POINTS || walk.equilibria >= MAX_EQUILIBRIA {
            bail!(
                "boundary walk: {count} points and {} equilibria without closing, at ({:.5}, {:.5})",
                walk.equilibria,
                at.site.on[0],
                at.site.on[1]
            );
        }
        let t = left_tangent(at.gradient);
        let normal = unit(at.gradient);
        let slope = at.gradient[0].hypot(at.gradient[1]);
        let attempt = walk
            .correct(
                &mut c,
                &at.site,
                along(at.site.p, t, sigma),
                normal,
                slope,
                0.5 * sigma.max(1e-4),
            )
            .and_then(|(q, it)| {
                let g = walk.gradient(&mut c, &q)?;
                Ok((q, it, g))
            });
        let (q, iterations, g) = match attempt {
            Ok((q, it, g)) if sigma < 1e-4 || dot2(left_tangent(g), t) > 0.97 => (q, it, g),
            other => {
                sigma *= 0.5;
                if sigma < MIN_STEP {
                    let why = other
                        .err()
                        .map_or("the boundary turns too sharply".into(), |e| {
                            format!("{e:#}")
                        });
                    bail!(
                        "boundary walk stopped on {} at ({:.5}, {:.5}): {why}",
                        c.describe(),
                        at.site.p[0],
                        at.site.p[1]
                    );
                }
                continue;
            }
        };
        if !walk.inside(q.p) {
            bail!(
                "the good region reaches the map's range at ({:.5}, {:.5})",
                q.p[0],
                q.p[1]
            );
        }
        match walk.failing(&q, Some(&c), unit(g))? {
            None => {
                // closed: the start lies between this point and the last
                let d0 = [first[0] - at.site.on[0], first[1] - at.site.on[1]];
                let d1 = [first[0] - q.on[0], first[1] - q.on[1]];
                let near = d0[0].hypot(d0[1]) < 2.0 * sigma;
                if count > 3
                    && c.failure() == first_kind
                    && near
                    && dot2(d0, t) > 0.0
                    && dot2(d1, t) <= 0.0
                {
                    let side = pieces[0].1[0].1;
                    pieces.last_mut().unwrap().1.push((first, side));
                    return Ok(());
                }
                let piece = pieces.last_mut().unwrap();
                piece.1.push((q.on, unit(g)[1]));
                count += 1;
                on_point(count, &piece.0.describe());
                at = Step {
                    site: q,
                    gradient: g,
                };
                if iterations <= 4 {
                    sigma = (1.4 * sigma).min(walk.max_step);
                }
            }
            Some(first_failure) => {
                // a corner: bisect along the curve to where another property fails
                let (mut a, mut b) = (0.0, sigma);
                let mut good = at.site.clone();
                let (mut bad, mut failure) = (q, first_failure);
                let tol = if first_failure == Failure::Stability {
                    STABILITY_TOL
                } else {
                    1e-8
                };
                while b - a > tol {
                    let m = 0.5 * (a + b);
                    // no equilibrium on the curve there: count it as past the corner
                    let Ok((s, _)) = walk.correct(
                        &mut c,
                        &at.site,
                        along(at.site.p, t, m),
                        normal,
                        slope,
                        0.5 * sigma.max(1e-4),
                    ) else {
                        b = m;
                        continue;
                    };
                    match walk.failing(&s, Some(&c), normal)? {
                        None => {
                            a = m;
                            good = s;
                        }
                        Some(f) => {
                            b = m;
                            failure = f;
                            bad = s;
                        }
                    }
                }
                // a corner right at the previous one: the crossing taken there
                // made no progress (several strands in contact at a tip), so
                // the next closest strands are tried
                if b < 1e-6 {
                    stuck += 1;
                } else {
                    stuck = 0;
                    tried.clear();
                }
                if let Condition::Crossing(s) = c {
                    tried.push(s);
                }
                if stuck > 12 {
                    bail!(
                        "boundary walk stuck at a corner of {} at ({:.5}, {:.5})",
                        c.describe(),
                        good.on[0],
                        good.on[1]
                    );
                }
                let corner = good.on;
                let old = unit(walk.gradient(&mut c, &good)?)[1];
                pieces.last_mut().unwrap().1.push((corner, old));
                c = walk.condition_of(failure, &at.site, &bad, &tried)?;
                let mut gradient = walk.gradient(&mut c, &good)?;
                // the region is the intersection of the good sides, so the
                // walk leaves a corner into the old condition's good side;
                // a crossing whose sign, taken near the corner, says
                // otherwise is oriented by this instead
                if let Condition::Crossing(s) = &mut c
                    && dot2(left_tangent(gradient), normal) < 0.0
                {
                    s.sign = -s.sign;
                    gradient = [-gradient[0], -gradient[1]];
                }
                pieces.push((c, vec![(corner, unit(gradient)[1])]));
                count += 1;
                on_point(count, &c.describe());
                at = Step {
                    site: good,
                    gradient,
                };
                sigma = FIRST_STEP;
            }
        }
    }
}

/// Two crossing conditions of the same strands, up to a few segments.
fn same_crossing(a: &Condition, b: &Condition) -> bool {
    match (a, b) {
        (Condition::Crossing(a), Condition::Crossing(b)) => a.near(b.first, b.other),
        _ => false,
    }
}

/// The paper's name of a piece: walls are W1 where the good region lies
/// above them in φ, W2 where it lies below.
fn label(c: &Condition, side: f64) -> &'static str {
    match c {
        Condition::Wall if side >= 0.0 => "W1",
        Condition::Wall => "W2",
        Condition::Crossing(_) => "X",
        Condition::Stability => "S",
    }
}

/// Name the pieces as the paper does and measure the loop.
fn finish(
    swept: Parameter,
    equilibria: usize,
    pieces: Vec<Trail>,
    closed: bool,
    stopped: Option<String>,
) -> Traced {
    // a crossing followed across neighbouring segment pairs (a corner where
    // the knot test flickered at a sharp tip) is one curve
    let mut pieces = pieces;
    let mut k = 1;
    while k < pieces.len() {
        if same_crossing(&pieces[k - 1].0, &pieces[k].0) {
            let next = pieces.remove(k);
            pieces[k - 1].1.extend(next.1.into_iter().skip(1));
        } else {
            k += 1;
        }
    }
    // split the pieces where their name changes (a wall curve turning round
    // the island's tip is W1 on one side and W2 on the other)
    let mut named: Vec<Piece> = Vec::new();
    for (c, points) in &pieces {
        let mut current: Option<Piece> = None;
        for (k, &(p, side)) in points.iter().enumerate() {
            let name = label(c, side);
            match current.as_mut() {
                Some(piece) if piece.label == name || k + 1 == points.len() => piece.points.push(p),
                Some(piece) => {
                    piece.points.push(p);
                    let done = current.replace(Piece {
                        label: name.into(),
                        condition: c.describe(),
                        points: vec![p],
                    });
                    named.extend(done);
                }
                None => {
                    current = Some(Piece {
                        label: name.into(),
                        condition: c.describe(),
                        points: vec![p],
                    })
                }
            }
        }
        named.extend(current);
    }
    // a closed walk starts inside a piece: join its two ends
    if closed && named.len() > 1 && named[0].label == named[named.len() - 1].label {
        let first = named.remove(0);
        named
            .last_mut()
            .unwrap()
            .points
            .extend(first.points.into_iter().skip(1));
    }
    // several pieces of one name are numbered along φ (X1, X2 as in the paper)
    let mut by_label: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for (k, p) in named.iter().enumerate() {
        by_label.entry(p.label.clone()).or_default().push(k);
    }
    for (label, mut ks) in by_label {
        if ks.len() < 2 {
            continue;
        }
        let mean = |p: &Piece| p.points.iter().map(|x| x[1]).sum::<f64>() / p.points.len() as f64;
        ks.sort_by(|&a, &b| mean(&named[a]).total_cmp(&mean(&named[b])));
        for (i, k) in ks.into_iter().enumerate() {
            named[k].label = if label == "X" {
                format!("X{}", i + 1)
            } else {
                format!("{label}.{}", i + 1)
            };
        }
    }
    let all: Vec<[f64; 2]> = named.iter().flat_map(|p| p.points.clone()).collect();
    let area = closed.then(|| {
        0.5 * all
            .windows(2)
            .map(|w| w[0][0] * w[1][1] - w[1][0] * w[0][1])
            .sum::<f64>()
            .abs()
    });
    let mut bounding_box = BTreeMap::new();
    if !all.is_empty() {
        for (k, name) in [swept.name(), "phi_over_2pi"].into_iter().enumerate() {
            let lo = all.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
            let hi = all.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
            bounding_box.insert(name.to_string(), [lo, hi]);
        }
    }
    Traced {
        points: all.len(),
        pieces: named,
        closed,
        area,
        bounding_box,
        equilibria,
        stopped,
        grid_check: None,
    }
}

/// Compare a closed traced loop with the grid's good intervals: each line's
/// interval ends against the loop's crossings of that line.
pub fn grid_check(traced: &Traced, lines: &[Line]) -> Option<GridCheck> {
    if !traced.closed {
        return None;
    }
    let (mut ends, mut worst, mut other) = (0, 0.0f64, Vec::new());
    for l in lines {
        let v = l.value;
        let cuts = traced.cuts(v);
        let grid: Vec<f64> = l.intervals.iter().flat_map(|i| [i.lo, i.hi]).collect();
        if cuts.len() != grid.len() {
            other.push(v);
        }
        if cuts.is_empty() {
            continue;
        }
        for e in grid {
            let d = cuts
                .iter()
                .map(|c| (c - e).abs())
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d);
            ends += 1;
        }
    }
    Some(GridCheck {
        ends,
        max_phi_deviation: worst,
        lines_with_other_count: other,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strand_distance_is_signed_and_changes_sign_through_the_crossing() {
        // segment 0 along x at the origin; segment 2 along y at height h
        let at = |h: f64| {
            vec![
                Vector3::new(-1.0, 0.0, 0.0),
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(0.0, -1.0, h),
                Vector3::new(0.0, 1.0, h),
            ]
        };
        let (d, up) = strand_distance(&at(0.3), 0, Other::Segment(2), 10.0);
        let (_, down) = strand_distance(&at(-0.2), 0, Other::Segment(2), 10.0);
        assert!((d - 0.3).abs() < 1e-12 && (up - 0.3).abs() < 1e-12);
        assert!((down + 0.2).abs() < 1e-12);
    }

    #[test]
    fn strands_are_the_same_up_to_neighbours_and_the_flip_image() {
        let s = Strands {
            first: 22,
            other: Other::Segment(76),
            sign: 1.0,
            segments: 101,
        };
        assert!(s.near(24, Other::Segment(74)));
        // the flip image s ↔ 1 − s: segment i ↔ 100 − i, the pair reversed
        assert!(s.near(24, Other::Segment(78)));
        assert!(!s.near(12, Other::Segment(89)));
        let r = Strands {
            first: 10,
            other: Other::BottomRay,
            sign: 1.0,
            segments: 101,
        };
        assert!(r.near(90, Other::TopRay));
        assert!(!r.near(90, Other::BottomRay));
    }

    #[test]
    fn a_wall_curve_round_the_tip_is_w1_on_one_side_and_w2_on_the_other() {
        // a closed walk starting on the wall's upper side (good side below,
        // W2), round the tip (W1), then a stability curve back to the start
        let trail: Vec<Trail> = vec![
            (
                Condition::Wall,
                vec![
                    ([0.2, 0.9], -0.5),
                    ([0.1, 0.8], -0.2),
                    ([0.1, 0.7], 0.3),
                    ([0.2, 0.6], 0.6),
                ],
            ),
            (
                Condition::Stability,
                vec![([0.2, 0.6], 0.1), ([0.3, 0.8], 0.1), ([0.2, 0.9], 0.1)],
            ),
        ];
        let t = finish(Parameter::ZStar, 7, trail, true, None);
        let labels: Vec<&str> = t.pieces.iter().map(|p| p.label.as_str()).collect();
        // the walk's first piece (W2 from the start) joins its last (W2 back to
        // the start) only when they share a name; here S closes the loop
        assert_eq!(labels, ["W2", "W1", "S"]);
        assert_eq!(t.pieces[0].points, vec![[0.2, 0.9], [0.1, 0.8], [0.1, 0.7]]);
        assert_eq!(t.bounding_box["z_star"], [0.1, 0.3]);
        // shoelace area of the polygon (0.2,0.9) (0.1,0.8) (0.1,0.7) (0.2,0.6) (0.3,0.8)
        assert!((t.area.unwrap() - 0.035).abs() < 1e-12, "{:?}", t.area);
        assert_eq!(t.equilibria, 7);
    }

    #[test]
    fn the_good_side_lies_to_the_left_of_the_walk() {
        // good side towards +z* (gradient (1, 0)): walk towards −φ
        assert_eq!(left_tangent([1.0, 0.0]), [0.0, -1.0]);
        let t = left_tangent([0.3, 0.4]);
        // left of t = (−t_y, t_x) points along the gradient
        assert!((-t[1] * 0.3 + t[0] * 0.4) > 0.0);
    }
}
