//! Parameter-space maps: the island of good knots (paper Fig. 7) from a grid of
//! one-parameter branches — a branch in the continuation's parameter (φ for
//! the paper's maps) at each value of the swept parameter (z*), each reached
//! independently by continuation from the scene's start,
//! computed in parallel (rayon) and deterministic whatever the thread count.
//! Good intervals are bounded by the located events (S, W1, W2, X), which form
//! the boundary curves. Maps shard (`--shard i/n`, `knotrod merge`) and resume
//! from the lines already written.

use crate::analysis::class::Class;
use crate::analysis::equilibrium::{Equilibrium, Measure};
use crate::analysis::event::{Event, EventKind};
use crate::model::rod::{Parameter, parameter_by_name, ranges_by_name};
use crate::scene::{MapSpec, Scene, SliceSpec};
use crate::study::boundary::{GridCheck, Traced};
use crate::study::branch::{BranchOptions, BranchRun};
use crate::study::error::{Context, Result, StudyError, describe};
use crate::study::run::continue_to;
use crate::study::start::starting_equilibrium;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A point of a line of the map.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct LinePoint {
    /// Value of the parameter along the line (the continuation's; φ as φ/2π).
    #[serde(alias = "phi_over_2pi")]
    pub along: f64,
    /// Tw.
    pub twist: f64,
    /// Class.
    pub class: Class,
}

/// An interval of good knots along a line, with what bounds it.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Interval {
    /// Lower end, in the parameter along the line.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// Boundary label at the lower end (S, W1, X, range, ...).
    pub lo_label: String,
    /// Boundary label at the upper end (W2, X, S, range, ...).
    pub hi_label: String,
}

impl std::fmt::Display for Interval {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "[{:.4} ({}), {:.4} ({})]",
            self.lo, self.lo_label, self.hi, self.hi_label
        )
    }
}

/// One line of the map: the branch along the continuation's parameter at one
/// value of the swept parameter.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Line {
    /// Index in the map's grid.
    pub index: usize,
    /// Value of the swept parameter.
    pub value: f64,
    /// The branch, in order along its arclength.
    pub points: Vec<LinePoint>,
    /// Located events.
    pub events: Vec<Event>,
    /// Good intervals.
    pub intervals: Vec<Interval>,
    /// Why the line failed, if it did.
    pub error: Option<String>,
}

/// A map: lines, classified grid, boundary curves, area and bounding box.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Map {
    /// Scene name.
    pub scene: String,
    /// The swept parameter (the map's vertical axis).
    #[serde(with = "parameter_by_name")]
    pub parameter: Parameter,
    /// The parameter along each line (the continuation's: the horizontal axis).
    #[serde(default = "phi", with = "parameter_by_name")]
    pub along: Parameter,
    /// Lines, by increasing index.
    pub lines: Vec<Line>,
    /// Named boundary curves, (swept value, value along) points: the traced
    /// boundary's pieces when it was traced, else the grid's.
    pub boundaries: BTreeMap<String, Vec<[f64; 2]>>,
    /// Boundary curves chained from the grid's interval ends (the check).
    #[serde(default)]
    pub grid_boundaries: BTreeMap<String, Vec<[f64; 2]>>,
    /// The boundary traced by two-parameter continuation from the start.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub traced: Option<Traced>,
    /// Classified grid: rows = lines, columns = `grid_along`.
    pub grid: Vec<Vec<Class>>,
    /// Values along the lines of the grid columns.
    #[serde(alias = "grid_phi")]
    pub grid_along: Vec<f64>,
    /// Area of the good region in the (swept, along) plane.
    pub good_area: f64,
    /// {swept: [lo, hi], along: [lo, hi]} of the good region (written keyed
    /// by the parameters' names).
    #[serde(with = "ranges_by_name")]
    pub bounding_box: BTreeMap<Parameter, [f64; 2]>,
}

/// Maps written before maps took any parameter along their lines ran in φ.
fn phi() -> Parameter {
    Parameter::Phi
}

/// A 3D map: its slices and the good region's volume and bounding box.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Map3 {
    /// Scene name.
    pub scene: String,
    /// The slicing parameter.
    #[serde(with = "parameter_by_name")]
    pub slice_parameter: Parameter,
    /// The swept parameter of each slice.
    #[serde(with = "parameter_by_name")]
    pub parameter: Parameter,
    /// Slice values.
    pub slice_values: Vec<f64>,
    /// Good area of each slice.
    pub slice_areas: Vec<f64>,
    /// Volume of the good region in (slice, swept, along) (trapezoids across
    /// the slices).
    pub good_volume: f64,
    /// Bounding box of the good region over all slices.
    #[serde(with = "ranges_by_name")]
    pub bounding_box: BTreeMap<Parameter, [f64; 2]>,
    /// Area enclosed by each slice's traced boundary (None: not closed).
    #[serde(default)]
    pub traced_areas: Vec<Option<f64>>,
    /// The slices' maps.
    pub slices: Vec<Map>,
}

/// Join slice maps into a 3D map.
pub fn assemble_3d(scene: &str, spec: &SliceSpec, slices: Vec<Map>) -> Map3 {
    let areas: Vec<f64> = slices.iter().map(|m| m.good_area).collect();
    let volume = spec
        .values
        .windows(2)
        .zip(areas.windows(2))
        .map(|(v, a)| 0.5 * (a[0] + a[1]) * (v[1] - v[0]))
        .sum();
    let mut bounding_box: BTreeMap<Parameter, [f64; 2]> = BTreeMap::new();
    for (m, &v) in slices.iter().zip(&spec.values) {
        if m.bounding_box.is_empty() {
            continue;
        }
        let mut grow = |k: Parameter, r: [f64; 2]| {
            let e = bounding_box.entry(k).or_insert(r);
            *e = [e[0].min(r[0]), e[1].max(r[1])];
        };
        grow(spec.parameter, [v, v]);
        for (k, r) in &m.bounding_box {
            grow(*k, *r);
        }
    }
    Map3 {
        scene: scene.into(),
        slice_parameter: spec.parameter,
        parameter: slices.first().map_or(spec.parameter, |m| m.parameter),
        slice_values: spec.values.clone(),
        slice_areas: areas,
        good_volume: volume,
        bounding_box,
        traced_areas: slices
            .iter()
            .map(|m| m.traced.as_ref().and_then(|t| t.area))
            .collect(),
        slices,
    }
}

/// The classified points of the first branch of a run (the lowest branch
/// number) placed by parameter `along`, in order along the branch (second
/// leg reversed, then the first).
pub fn line_points(eqs: &[Equilibrium], along: Parameter) -> Vec<LinePoint> {
    let first = eqs.iter().map(|e| e.branch).min().unwrap_or(0);
    let mut down: Vec<&Equilibrium> = eqs
        .iter()
        .filter(|e| e.branch == first && e.leg == 1)
        .collect();
    down.reverse();
    down.into_iter()
        .chain(eqs.iter().filter(|e| e.branch == first && e.leg == 0))
        .map(|e| LinePoint {
            along: along.value(&e.state.clamps),
            twist: e.twist,
            class: Class::of(e.stable, e.knotted, e.good_knot),
        })
        .collect()
}

/// The event that bounds a good run between branch points `p` and `q`: the one
/// nearest to that segment in the (along, Tw) plane (the branch may pass the
/// same value several times).
fn boundary_label(
    events: &[Event],
    along: Parameter,
    p: &LinePoint,
    q: &LinePoint,
    lower: bool,
) -> (f64, String) {
    let (ax, ay, bx, by) = (p.along, p.twist, q.along, q.twist);
    let dist = |e: &Event| {
        let (dx, dy) = (bx - ax, by - ay);
        let len2 = (dx * dx + dy * dy).max(1e-300);
        let x = e.value(along);
        let t = (((x - ax) * dx + (e.twist - ay) * dy) / len2).clamp(0.0, 1.0);
        ((x - ax - t * dx).powi(2) + (e.twist - ay - t * dy).powi(2)).sqrt()
    };
    let scale = ((bx - ax).powi(2) + (by - ay).powi(2)).sqrt();
    let best = events
        .iter()
        .filter(|e| {
            matches!(
                e.kind,
                EventKind::Wall
                    | EventKind::Crossing
                    | EventKind::RibbonContact
                    | EventKind::BranchPoint
                    | EventKind::Fold
                    | EventKind::Stability
            )
        })
        // the event lies on the arc between the two points: near their chord
        .filter(|e| dist(e) <= 0.3 * scale + 1e-9)
        .min_by(|x, y| dist(x).total_cmp(&dist(y)));
    match best {
        Some(e) => {
            let label = match (e.kind, lower) {
                (EventKind::Wall, true) => "W1",
                (EventKind::Wall, false) => "W2",
                (EventKind::Crossing | EventKind::RibbonContact, _) => "X",
                (EventKind::Fold, _) => "F",
                _ => "S",
            };
            (e.value(along), label.to_string())
        }
        None => (0.5 * (ax + bx), "?".to_string()),
    }
}

/// Good intervals of φ/2π along the first branch of a run in φ (the paper's
/// branches; see [`branch_intervals_in`]).
pub fn branch_intervals(eqs: &[Equilibrium], events: &[Event]) -> Vec<Interval> {
    branch_intervals_in(Parameter::Phi, eqs, events)
}

/// Good intervals in parameter `along` on the first branch of a run (see
/// [`line_points`]), each bounded by that branch's events.
pub fn branch_intervals_in(
    along: Parameter,
    eqs: &[Equilibrium],
    events: &[Event],
) -> Vec<Interval> {
    let first = eqs.iter().map(|e| e.branch).min().unwrap_or(0);
    let on: Vec<Event> = events
        .iter()
        .filter(|e| e.branch == first)
        .cloned()
        .collect();
    intervals_of(&line_points(eqs, along), &on, along)
}

/// Good intervals of a line: maximal runs of good points, bounded by the
/// events (of the same branch) between their ends and the neighbouring
/// points, placed by parameter `along`.
pub fn intervals_of(points: &[LinePoint], events: &[Event], along: Parameter) -> Vec<Interval> {
    let mut intervals = Vec::new();
    let good: Vec<bool> = points.iter().map(|p| p.class == Class::Good).collect();
    let mut k = 0;
    while k < good.len() {
        if !good[k] {
            k += 1;
            continue;
        }
        let start = k;
        while k < good.len() && good[k] {
            k += 1;
        }
        let end = k - 1;
        let x = |i: usize| points[i].along;
        let (a, la) = if start == 0 {
            (x(0), "range".to_string())
        } else {
            boundary_label(
                events,
                along,
                &points[start - 1],
                &points[start],
                x(start - 1) < x(start),
            )
        };
        let (b, lb) = if end + 1 == good.len() {
            (x(end), "range".to_string())
        } else {
            boundary_label(
                events,
                along,
                &points[end],
                &points[end + 1],
                x(end + 1) < x(end),
            )
        };
        let (lo, hi, lo_label, hi_label) = if a <= b {
            (a, b, la, lb)
        } else {
            (b, a, lb, la)
        };
        intervals.push(Interval {
            lo,
            hi,
            lo_label,
            hi_label,
        });
    }
    intervals
}

/// Compute line `index` of the map.
pub fn line(scene: &Scene, spec: &MapSpec, index: usize, segments: Option<usize>) -> Line {
    let value = spec.value(index);
    let mut out = Line {
        index,
        value,
        points: vec![],
        events: vec![],
        intervals: vec![],
        error: None,
    };
    match compute_line(scene, spec, value, segments) {
        Ok((eqs, events, along)) => {
            out.points = line_points(&eqs, along);
            out.intervals = branch_intervals_in(along, &eqs, &events);
            out.events = events;
        }
        Err(e) => out.error = Some(describe(&e)),
    }
    out
}

fn compute_line(
    scene: &Scene,
    spec: &MapSpec,
    value: f64,
    segments: Option<usize>,
) -> Result<(Vec<Equilibrium>, Vec<Event>, Parameter)> {
    let c = scene
        .continuation
        .as_ref()
        .context("[map] needs a [continuation] giving the branches")?;
    let (mut newton, state, _) = starting_equilibrium(scene, segments)?;
    let settings = c.settings();
    let state = continue_to(&mut newton, state, spec.parameter, value, &settings)?;
    let options = BranchOptions {
        parameter: c.parameter,
        range: c.range,
        settings,
        locate_events: true,
        switch_branches: false,
        measure: Measure {
            eigenvalues: 0,
            ..scene.measure()
        },
        stop_at: Vec::new(),
    };
    let mut eqs = Vec::new();
    let mut obs = crate::study::observer::equilibria(|e: Equilibrium| {
        eqs.push(e);
        Ok(())
    });
    let mut run = BranchRun::new(&mut newton, options, &mut obs, 0);
    run.follow(state, &[1.0, -1.0])?;
    let events = std::mem::take(&mut run.events);
    drop(run);
    Ok((eqs, events, c.parameter))
}

/// Lines of shard `i` of `n`.
pub fn shard_lines(spec: &MapSpec, shard: (usize, usize)) -> Vec<usize> {
    (0..spec.lines).filter(|k| k % shard.1 == shard.0).collect()
}

/// Where a map's computed lines are kept, so that an interrupted map resumes
/// (io keeps them as files beside the output).
pub trait LineStore: Sync {
    /// Line `index` with parameter value `value`, if it was computed already.
    fn get(&self, index: usize, value: f64) -> Option<Line>;
    /// Keep a computed line.
    fn put(&self, line: &Line)
    -> std::result::Result<(), Box<dyn std::error::Error + Send + Sync>>;
}

/// Compute (or take from `store`) the given lines in parallel, reporting each.
pub fn compute_lines(
    scene: &Scene,
    spec: &MapSpec,
    indices: &[usize],
    segments: Option<usize>,
    store: &dyn LineStore,
    on_line: &(dyn Fn(&Line) + Sync),
) -> Result<Vec<Line>> {
    use rayon::prelude::*;
    // the workers count into the run's work
    let work = crate::linalg::counters::current();
    let mut lines: Vec<Line> = indices
        .par_iter()
        .map(|&k| -> Result<Line> {
            // resume: a line already kept is not computed again
            if let Some(l) = store.get(k, spec.value(k)) {
                on_line(&l);
                return Ok(l);
            }
            let l =
                crate::linalg::counters::within(work.as_ref(), || line(scene, spec, k, segments));
            store.put(&l).map_err(StudyError::Observer)?;
            on_line(&l);
            Ok(l)
        })
        .collect::<Result<Vec<Line>>>()?;
    lines.sort_by_key(|l| l.index);
    Ok(lines)
}

/// Assemble a map from its lines (boundaries, grid, area, bounding box):
/// lines along parameter `along` over `range` (the continuation's).
pub fn assemble(
    scene_name: &str,
    spec: &MapSpec,
    along: Parameter,
    range: [f64; 2],
    mut lines: Vec<Line>,
    traced: Option<Traced>,
) -> Map {
    lines.sort_by_key(|l| l.index);
    lines.dedup_by_key(|l| l.index);
    for l in lines.iter_mut() {
        l.intervals = intervals_of(&l.points, &l.events, along);
    }
    let grid_along: Vec<f64> = (0..spec.grid_columns)
        .map(|j| {
            range[0] + (range[1] - range[0]) * j as f64 / (spec.grid_columns.max(2) - 1) as f64
        })
        .collect();
    let grid = lines.iter().map(|l| grid_row(l, &grid_along)).collect();
    let mut ends: Vec<(usize, f64, f64, String)> = Vec::new();
    let mut area = 0.0;
    let (mut vlo, mut vhi, mut alo, mut ahi) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    let widths: Vec<f64> = lines
        .iter()
        .map(|l| l.intervals.iter().map(|i| i.hi - i.lo).sum())
        .collect();
    for (k, l) in lines.iter().enumerate() {
        for i in &l.intervals {
            ends.push((k, l.value, i.lo, format!("{}/lo", i.lo_label)));
            ends.push((k, l.value, i.hi, format!("{}/hi", i.hi_label)));
            vlo = vlo.min(l.value);
            vhi = vhi.max(l.value);
            alo = alo.min(i.lo);
            ahi = ahi.max(i.hi);
        }
        if k > 0 {
            area += 0.5 * (widths[k] + widths[k - 1]) * (l.value - lines[k - 1].value);
        }
    }
    let grid_boundaries = chain_boundaries(&ends);
    let traced = traced.map(|mut t| {
        t.grid_check = grid_check(&t, &lines);
        t
    });
    let boundaries = match &traced {
        Some(t) if !t.pieces.is_empty() => t
            .pieces
            .iter()
            .map(|p| (p.label.clone(), p.points.clone()))
            .collect(),
        _ => grid_boundaries.clone(),
    };
    let mut bounding_box = BTreeMap::new();
    if vlo.is_finite() {
        bounding_box.insert(spec.parameter, [vlo, vhi]);
        bounding_box.insert(along, [alo, ahi]);
    }
    Map {
        scene: scene_name.into(),
        parameter: spec.parameter,
        along,
        lines,
        boundaries,
        grid_boundaries,
        traced,
        grid,
        grid_along,
        good_area: area,
        bounding_box,
    }
}

/// Join interval ends (line index, parameter, value along, "label/side") into
/// boundary curves: an end continues the curve of the same label and side
/// whose last end lies on the previous line and is nearest along it (within
/// 0.05); otherwise it starts a new curve. A label with several curves is
/// numbered along the lines (X1, X2, … as in the paper).
fn chain_boundaries(ends: &[(usize, f64, f64, String)]) -> BTreeMap<String, Vec<[f64; 2]>> {
    let mut curves: Vec<(String, usize, Vec<[f64; 2]>)> = Vec::new(); // key, last line, points
    let mut sorted: Vec<&(usize, f64, f64, String)> = ends.iter().collect();
    sorted.sort_by(|a, b| (a.0, &a.3).cmp(&(b.0, &b.3)).then(a.2.total_cmp(&b.2)));
    for &(line, value, x, ref key) in sorted {
        let best = curves
            .iter()
            .enumerate()
            .filter(|(_, c)| &c.0 == key && c.1 + 1 == line)
            .map(|(i, c)| (i, (c.2.last().unwrap()[1] - x).abs()))
            .filter(|&(_, d)| d <= 0.05)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match best {
            Some((i, _)) => {
                curves[i].1 = line;
                curves[i].2.push([value, x]);
            }
            None => curves.push((key.clone(), line, vec![[value, x]])),
        }
    }
    let mut named: BTreeMap<String, Vec<Vec<[f64; 2]>>> = BTreeMap::new();
    for (key, _, points) in curves {
        let label = key.split('/').next().unwrap_or("?").to_string();
        named.entry(label).or_default().push(points);
    }
    let mut out = BTreeMap::new();
    for (label, mut list) in named {
        if list.len() == 1 {
            out.insert(label, list.pop().unwrap());
            continue;
        }
        let mean = |c: &Vec<[f64; 2]>| c.iter().map(|p| p[1]).sum::<f64>() / c.len() as f64;
        list.sort_by(|a, b| mean(a).total_cmp(&mean(b)));
        for (k, c) in list.into_iter().enumerate() {
            out.insert(format!("{label}{}", k + 1), c);
        }
    }
    out
}

/// Class of a line at each grid column: the stable state if several, else
/// the first.
fn grid_row(l: &Line, columns: &[f64]) -> Vec<Class> {
    columns
        .iter()
        .map(|&x| {
            let mut found: Option<Class> = None;
            for w in l.points.windows(2) {
                let (a, b) = (w[0].along, w[1].along);
                if (a - x) * (b - x) <= 0.0 && a != b {
                    let c = if (x - a).abs() <= (x - b).abs() {
                        w[0].class
                    } else {
                        w[1].class
                    };
                    if found.is_none() || (found == Some(Class::Unstable) && c != Class::Unstable) {
                        found = Some(c);
                    }
                }
            }
            found.unwrap_or(Class::None)
        })
        .collect()
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
        max_deviation: worst,
        lines_with_other_count: other,
    })
}
