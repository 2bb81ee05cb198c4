//! `knotrod bench`: standard workloads timed with their work counts, and the
//! growth of per-step costs with N (fitted exponents).

use crate::analysis::equilibrium::Conformation;
use crate::geometry::closure::ray_closure;
use crate::geometry::distance::min_self_distance;
use crate::geometry::knot::knot_type;
use crate::geometry::writhe::{try_writhe_closed, writhe_closed};
use crate::linalg::counters::{Work, within};
use crate::linalg::eigen::lowest_eigenvalues;
use crate::linalg::sparse::Ldlt;
use crate::model::energy::RodEnergy;
use crate::model::rod::RodState;
use crate::report::error::{Context, Result};
use crate::scene::Scene;
use nalgebra::Vector3;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// One timed workload.
#[derive(Clone, Debug, Serialize)]
pub struct Workload {
    /// Name.
    pub name: String,
    /// N.
    pub segments: usize,
    /// Wall time.
    pub seconds: f64,
    /// Newton and corrector iterations.
    pub newton_iterations: usize,
    /// Sparse factorisations.
    pub factorizations: usize,
    /// Peak resident memory of the process so far (Linux VmHWM), bytes.
    pub peak_bytes: u64,
    /// Largest error of its answers against the converged continuum ones
    /// (events: in φ/2π), where it has answers to compare; for a polished
    /// island, its area's relative error estimate.
    pub accuracy: Option<f64>,
}

/// The bench report.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Workloads.
    pub workloads: Vec<Workload>,
    /// Fitted exponent of cost versus N per operation (N = 200 … 3200).
    pub exponents: BTreeMap<String, f64>,
    /// Seconds per call, per operation and N.
    pub per_call: BTreeMap<String, Vec<(usize, f64)>>,
    /// Fitted exponent of the whole Figure 3 branch's time with its
    /// eigenvalues versus N (N = 200 … 1600).
    pub branch_exponent: Option<f64>,
}

fn peak_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .map(|l| l.to_string())
        })
        .and_then(|l| {
            l.split_whitespace()
                .nth(1)
                .and_then(|v| v.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb * 1024)
}

fn timed(name: &str, segments: usize, f: impl FnOnce() -> Result<()>) -> Result<Workload> {
    // each workload counts its own work
    let work = Work::new();
    let t = Instant::now();
    within(Some(&work), f).with_context(|| format!("workload {name}"))?;
    Ok(Workload {
        name: name.into(),
        segments,
        seconds: t.elapsed().as_secs_f64(),
        newton_iterations: work.iterations(),
        factorizations: work.factorizations(),
        peak_bytes: peak_bytes(),
        accuracy: None,
    })
}

/// Mean seconds per call of `f`, repeated for at least ~0.2 s.
fn per_call(mut f: impl FnMut()) -> f64 {
    f();
    let t = Instant::now();
    let mut n = 0;
    while n < 3 || t.elapsed().as_secs_f64() < 0.2 {
        f();
        n += 1;
    }
    t.elapsed().as_secs_f64() / n as f64
}

/// Run the standard workloads from the scenes in `scenes`.
pub fn run(scenes: &Path) -> Result<Report> {
    let d = Scene::load(&scenes.join("appendix_d.toml"))?;
    let fig3 = Scene::load(&scenes.join("fig3_kirchhoff.toml"))?;
    let fig7 = Scene::load(&scenes.join("fig7_island_kirchhoff.toml"))?;
    let mut workloads = branch_workloads(&d, &fig3)?;
    workloads.extend(event_workloads(scenes)?);
    workloads.extend(island_workloads(&fig7)?);
    workloads.extend(dense_knot_workloads()?);
    workloads.push(verify_workload(scenes)?);
    // per-operation costs on the Appendix D knot resampled at each N
    let mut per: BTreeMap<String, Vec<(usize, f64)>> = BTreeMap::new();
    for n in [200, 400, 800, 1600, 3200] {
        let e = crate::study::start::solve_scene(&d, Some(n))?;
        let state: RodState = e.state.clone();
        let mut push = |name: &str, t: f64| per.entry(name.to_string()).or_default().push((n, t));
        linear_algebra_costs(&d, n, &state, &mut push);
        geometry_costs(&d, &e, &state, &mut push);
        picture_cost(&d, &e, &mut push);
    }
    let exponents = per
        .iter()
        .map(|(k, v)| {
            let (n0, t0) = v.first().copied().unwrap();
            let (n1, t1) = v.last().copied().unwrap();
            (k.clone(), (t1 / t0).ln() / (n1 as f64 / n0 as f64).ln())
        })
        .collect();
    Ok(Report {
        branch_exponent: branch_exponent(&workloads),
        workloads,
        exponents,
        per_call: per,
    })
}

/// `knotrod verify` on a branch of 100 shooting solutions (the Figure 3
/// branch, scenes/verify/branch_100.csv) at N = 100, 200, 400, in parallel.
fn verify_workload(scenes: &Path) -> Result<Workload> {
    use crate::study::verify::{Verdict, VerifyOptions, verify_all};
    let (scene, solutions) = crate::io::verify_file::read_solutions(
        &scenes.join("verify").join("branch_100.csv"),
        Some(&scenes.join("appendix_d.toml")),
    )
    .map_err(|e| crate::report::error::ReportError::Failed(e.to_string()))?;
    timed("verify_branch_100", 100, || {
        let checks = verify_all(&scene, &solutions, &VerifyOptions::default(), &|_| Ok(()))?;
        let confirmed = checks
            .iter()
            .filter(|c| c.verdict == Verdict::Confirmed)
            .count();
        // near φ/2π = 0.74 the rod at N = 100 is another equilibrium (an
        // unknot, or another inertia) at 4 of the points: the methods
        // disagree there, every other point is confirmed
        let coarse = checks
            .iter()
            .filter(|c| matches!(c.verdict, Verdict::MethodsDisagree { .. }))
            .count();
        if confirmed + coarse != checks.len() || coarse > 4 {
            crate::report::error::fail!(
                "verify: {confirmed} of {} confirmed, {coarse} disagree",
                checks.len()
            );
        }
        Ok(())
    })
}

/// The Appendix D knot solved from its shooting data, and the Figure 3
/// branch continued with and without eigenvalues.
fn branch_workloads(d: &Scene, fig3: &Scene) -> Result<Vec<Workload>> {
    let mut workloads = Vec::new();
    workloads.push(timed("appendix_d_from_shooting", 200, || {
        crate::study::start::solve_scene(d, Some(200))
            .map(|_| ())
            .map_err(Into::into)
    })?);
    let mut main_branch = fig3.clone();
    if let Some(c) = main_branch.continuation.as_mut() {
        c.switch_branches = false;
    }
    // stability at every point from the inertia of the corrector's LDLᵀ
    // (issue 9: eigenvalues only when asked), then with the scene's request of
    // the two lowest eigenvalues (and frequencies) at every point on top
    let mut inertia_only = main_branch.clone();
    inertia_only.stability.eigenvalues = 0;
    workloads.push(timed("figure_3_branch", 200, || {
        crate::study::run::run_scene(&inertia_only, Some(200), &mut ())
            .map(|_| ())
            .map_err(Into::into)
    })?);
    // the same at growing N: the stability along a branch is O(N) per
    // step (the step count does not change with N)
    for n in BRANCH_SEGMENTS {
        workloads.push(timed(BRANCH_WITH_EIGENVALUES, n, || {
            crate::study::run::run_scene(&main_branch, Some(n), &mut ())
                .map(|_| ())
                .map_err(Into::into)
        })?);
    }
    Ok(workloads)
}

/// The workload of the Figure 3 branch with its two lowest eigenvalues.
const BRANCH_WITH_EIGENVALUES: &str = "figure_3_branch_with_eigenvalues";

/// The N at which the Figure 3 branch with eigenvalues is timed.
const BRANCH_SEGMENTS: [usize; 4] = [200, 400, 800, 1600];

/// Fitted exponent of the Figure 3 branch's time with eigenvalues versus N
/// (least squares of log time on log N over `BRANCH_SEGMENTS`).
fn branch_exponent(workloads: &[Workload]) -> Option<f64> {
    let points: Vec<(f64, f64)> = workloads
        .iter()
        .filter(|w| w.name == BRANCH_WITH_EIGENVALUES)
        .map(|w| ((w.segments as f64).ln(), w.seconds.ln()))
        .collect();
    if points.len() < 2 {
        return None;
    }
    let m = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / m, b + y / m));
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    Some(sxy / sxx)
}

/// Names of the workloads that compute the Figure 3 events from X to the fold.
const EVENT_WORKLOAD: &str = "figure_3_x_to_fold";

/// The labelled events whose accuracy the event workloads report.
const FIGURE_3_EVENTS: [(&str, crate::analysis::event::EventKind); 5] = {
    use crate::analysis::event::EventKind::{BranchPoint, Crossing, Fold, Wall};
    [
        ("W2", Wall),
        ("X", Crossing),
        ("W1", Wall),
        ("S", BranchPoint),
        ("F1", Fold),
    ]
};

/// The value of each Figure 3 event in `events`: the continuum's where it
/// was polished, else the discrete rod's.
fn figure_3_values(events: &[crate::analysis::event::Event]) -> Result<Vec<f64>> {
    FIGURE_3_EVENTS
        .iter()
        .map(|(label, kind)| {
            let e = events
                .iter()
                .find(|e| e.branch == 0 && e.label == *label && e.kind == *kind)
                .with_context(|| format!("no {label} on the Figure 3 branch"))?;
            Ok(e.continuum.as_ref().map_or(e.phi_over_2pi, |c| c.value))
        })
        .collect()
}

/// The Figure 3 branch from X to the fold (scenes/fig3_polished.toml): by
/// the discrete rod alone at N = 200 and 400, and at N = 60 with every
/// event polished on the continuum branch; each with its largest event
/// error against the polish from another start, the discrete rod at
/// N = 120 (not timed).
fn event_workloads(scenes: &Path) -> Result<Vec<Workload>> {
    let polished = Scene::load(&scenes.join("fig3_polished.toml"))?;
    let run = |scene: &Scene, n: usize| -> Result<Vec<crate::analysis::event::Event>> {
        Ok(crate::study::run::run_scene(
            scene,
            Some(n),
            &mut crate::study::observer::equilibria(|_| Ok(())),
        )?)
    };
    let reference = figure_3_values(&run(&polished, 120)?)?;
    let mut discrete = polished.clone();
    if let Some(c) = discrete.continuation.as_mut() {
        c.polish = false;
    }
    let mut workloads = Vec::new();
    for (scene, n, name) in [
        (&discrete, 200, "discrete"),
        (&discrete, 400, "discrete"),
        (&polished, 60, "polished"),
    ] {
        let mut values = Vec::new();
        let mut w = timed(&format!("{EVENT_WORKLOAD}_{name}"), n, || {
            values = figure_3_values(&run(scene, n)?)?;
            Ok(())
        })?;
        w.accuracy = Some(
            values
                .iter()
                .zip(&reference)
                .map(|(v, r)| (v - r).abs())
                .fold(0.0, f64::max),
        );
        workloads.push(w);
    }
    Ok(workloads)
}

/// The Figure 7-left island: six grid lines, the whole map, and the
/// boundary walk alone.
fn island_workloads(fig7: &Scene) -> Result<Vec<Workload>> {
    let mut workloads = Vec::new();
    let mut island = fig7.clone();
    if let Some(m) = island.map.as_mut() {
        m.lines = 6;
        m.range = [0.11, 0.21];
    }
    workloads.push(timed("figure_7_island_6_lines", 60, || {
        let spec = island.map.clone().unwrap();
        let cache = std::env::temp_dir().join(format!("knotrod-bench-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&cache);
        let idx: Vec<usize> = (0..spec.lines).collect();
        crate::study::map::compute_lines(
            &island,
            &spec,
            &idx,
            Some(60),
            &crate::io::map_files::LineFolder::create(&cache, &island, &spec, Some(60))?,
            &|_| {},
        )?;
        let _ = std::fs::remove_dir_all(&cache);
        Ok(())
    })?);
    // the whole Figure 7-left map as `knotrod map` computes it: the boundary
    // walk (sequential) and the grid of 27 lines (parallel), N = 100
    workloads.push(timed("figure_7_island_map", 100, || {
        let spec = fig7.map.clone().context("fig7 scene has a [map]")?;
        let cache = std::env::temp_dir().join(format!("knotrod-bench-map-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&cache);
        let t = crate::io::map_files::trace_cached(fig7, &spec, None, &cache, &|_, _| {})?;
        let idx: Vec<usize> = (0..spec.lines).collect();
        crate::study::map::compute_lines(
            fig7,
            &spec,
            &idx,
            None,
            &crate::io::map_files::LineFolder::create(&cache, fig7, &spec, None)?,
            &|_| {},
        )?;
        let _ = std::fs::remove_dir_all(&cache);
        if !t.closed {
            crate::report::error::fail!("boundary walk did not close: {:?}", t.stopped);
        }
        Ok(())
    })?);
    // the walk alone, then the walk with its boundary polished on the
    // continuum (its accuracy: the polished area's relative error estimate)
    for polish in [false, true] {
        let name = if polish {
            "figure_7_island_boundary_polished"
        } else {
            "figure_7_island_boundary_walk"
        };
        let mut area_error = None;
        let mut w = timed(name, 100, || {
            let mut spec = fig7.map.clone().context("fig7 scene has a [map]")?;
            spec.polish = polish;
            let t = crate::study::boundary::trace_island(fig7, &spec, None, &|_, _| {})?;
            if !t.closed {
                crate::report::error::fail!("boundary walk did not close: {:?}", t.stopped);
            }
            if polish {
                let p = t.polished.as_ref().with_context(|| {
                    format!("the boundary was not polished: {:?}", t.not_polished)
                })?;
                area_error = Some(p.area_error / p.area);
            }
            Ok(())
        })?;
        w.accuracy = area_error;
        workloads.push(w);
    }
    Ok(workloads)
}

/// Seconds per call of the energy, its derivatives, the factorisation and
/// the lowest eigenvalues at `state`.
fn linear_algebra_costs(d: &Scene, n: usize, state: &RodState, push: &mut impl FnMut(&str, f64)) {
    let energy = RodEnergy::new(d.rod_model(Some(n)));
    let mut g = vec![0.0; energy.map.len()];
    let mut v = vec![0.0; energy.pattern.nnz()];
    energy.hessian(state, &mut g, &mut v);
    let mut ldlt = Ldlt::new(&energy.pattern);
    push(
        "energy",
        per_call(|| {
            energy.energy(state);
        }),
    );
    push(
        "gradient",
        per_call(|| {
            energy.gradient(state, &mut g);
        }),
    );
    push(
        "hessian",
        per_call(|| {
            energy.hessian(state, &mut g, &mut v);
        }),
    );
    push(
        "factorization",
        per_call(|| {
            ldlt.factor(&v).unwrap();
        }),
    );
    push(
        "lowest_eigenvalues",
        per_call(|| {
            lowest_eigenvalues(&energy.pattern, &v, None, 4, &mut ldlt).unwrap();
        }),
    );
}

/// Seconds per call of the writhe, knot type, self-distance and diagnostics
/// at `state` (the equilibrium `e`).
fn geometry_costs(
    d: &Scene,
    e: &crate::analysis::equilibrium::Equilibrium,
    state: &RodState,
    push: &mut impl FnMut(&str, f64),
) {
    let (p, arc) = state.centreline();
    let closed = ray_closure(&p, -nalgebra::Vector3::z(), nalgebra::Vector3::z(), 1e6);
    push(
        "writhe_at_passages",
        per_call(|| {
            writhe_closed(&closed);
        }),
    );
    let short = ray_closure(&p, -nalgebra::Vector3::z(), nalgebra::Vector3::z(), 3.0);
    push(
        "knot_type_at_passages",
        per_call(|| {
            let _ = knot_type(&short);
        }),
    );
    push(
        "self_distance",
        per_call(|| {
            min_self_distance(&p, &arc, 0.05);
        }),
    );
    let m = d.measure();
    // per continuation step: writhe and knot type carried from the
    // previous point (the full O(N²) ones run only where strands meet)
    push(
        "diagnostics_per_step",
        per_call(|| {
            Conformation::continued(state, &m, e);
        }),
    );
    push(
        "diagnostics_full",
        per_call(|| {
            Conformation::of(state, &m);
        }),
    );
}

/// Seconds per picture of the state (`knotrod render`'s work less reading
/// the file): a 1200×900 PNG, oblique, with its clamps, rays and walls.
fn picture_cost(
    d: &Scene,
    e: &crate::analysis::equilibrium::Equilibrium,
    push: &mut impl FnMut(&str, f64),
) {
    use crate::io::render::{Body, Picture, View, png};
    let c = crate::io::plot::class_colour(e);
    let body = Body {
        state: e.state.clone(),
        diameter: 4.0 / d.rod_model(None).stretching_stiffness.sqrt(),
        ribbon: None,
        colour: [c.0, c.1, c.2],
        label: String::new(),
        caption: "good knot".into(),
        contacts: vec![],
    };
    let picture = Picture {
        width: 1200,
        height: 900,
        view: View::OBLIQUE,
    };
    push(
        "render_png_1200x900",
        per_call(|| {
            png(std::slice::from_ref(&body), &picture).expect("a picture of nonzero size");
        }),
    );
}

/// A deterministic sequence in [−1, 1) (a linear congruential generator).
fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// `m` points on the torus knot T(p, q) (core radius 2, tube 1), each moved
/// by up to `noise` times the shortest step in each coordinate.
fn noisy_torus_knot(p: f64, q: f64, m: usize, noise: f64, seed: u64) -> Vec<Vector3<f64>> {
    let smooth: Vec<Vector3<f64>> = (0..m)
        .map(|k| {
            let t = 2.0 * std::f64::consts::PI * k as f64 / m as f64;
            let r = 2.0 + (q * t).cos();
            Vector3::new(r * (p * t).cos(), r * (p * t).sin(), (q * t).sin())
        })
        .collect();
    let step = (0..m)
        .map(|k| (smooth[(k + 1) % m] - smooth[k]).norm())
        .fold(f64::INFINITY, f64::min);
    let mut u = uniform(seed);
    smooth
        .into_iter()
        .map(|x| x + noise * step * Vector3::new(u(), u(), u()))
        .collect()
}

/// Time what `knotrod knot --closed` computes (knot type and writhe) for
/// `points`; an error if the Alexander polynomial is not `expected`.
fn knot_workload(name: &str, points: &[Vector3<f64>], expected: &[i64]) -> Result<Workload> {
    let failed = |s: String| crate::report::error::ReportError::Failed(format!("{name}: {s}"));
    timed(name, points.len(), || {
        let k = knot_type(points).map_err(|e| failed(e.to_string()))?;
        try_writhe_closed(points).map_err(|e| failed(e.to_string()))?;
        if k.alexander != expected {
            return Err(failed(format!("read as {:?}", k.alexander)));
        }
        Ok(())
    })
}

/// The knot type of 10⁵ points on the torus knot T(3,5) = 10_124, each
/// moved by up to 10⁻⁴ (a deterministic jitter; a smooth curve), and of 10⁶
/// points on the trefoil T(2,3), each moved by up to a quarter of the
/// shortest step (noisy, but provably still a trefoil: segments k and k + 2
/// stay apart along the tangent all the way along the straight homotopy to
/// the smooth curve): simplification, diagram, exact polynomial and writhe.
fn dense_knot_workloads() -> Result<Vec<Workload>> {
    let m = 100_000;
    let mut jitter = uniform(41);
    let t35: Vec<Vector3<f64>> = noisy_torus_knot(3.0, 5.0, m, 0.0, 0)
        .into_iter()
        .map(|x| x + 1e-4 * Vector3::new(jitter(), jitter(), jitter()))
        .collect();
    Ok(vec![
        knot_workload(
            "knot_type_of_100000_points",
            &t35,
            &[1, -1, 0, 1, -1, 1, 0, -1, 1],
        )?,
        knot_workload(
            "knot_type_of_1000000_noisy_points",
            &noisy_torus_knot(2.0, 3.0, 1_000_000, 0.25, 7),
            &[1, -1, 1],
        )?,
    ])
}

/// Print a report as tables.
pub fn print(r: &Report, out: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(
        out,
        "| workload | N | seconds | Newton iterations | factorisations | peak memory (MB) | largest error |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|")?;
    for w in &r.workloads {
        writeln!(
            out,
            "| {} | {} | {:.3} | {} | {} | {:.1} | {} |",
            w.name,
            w.segments,
            w.seconds,
            w.newton_iterations,
            w.factorizations,
            w.peak_bytes as f64 / 1e6,
            w.accuracy.map_or("".into(), |a| format!("{a:.1e}"))
        )?;
    }
    if let Some(x) = r.branch_exponent {
        writeln!(
            out,
            "\nThe Figure 3 branch with eigenvalues: time grows as N^{x:.2} (least squares, N = {} … {}).",
            BRANCH_SEGMENTS[0],
            BRANCH_SEGMENTS[BRANCH_SEGMENTS.len() - 1]
        )?;
    }
    writeln!(
        out,
        "\nTime to the Figure 3 events (W2, X, W1, S, F1, from X to the fold) within a given error of the converged continuum values (the fastest workload above that reaches it):\n"
    )?;
    writeln!(out, "| within | workload | N | seconds | largest error |")?;
    writeln!(out, "|---|---|---|---|---|")?;
    for within in [1e-4, 1e-6, 1e-8] {
        let best = r
            .workloads
            .iter()
            .filter(|w| w.name.starts_with(EVENT_WORKLOAD))
            .filter(|w| w.accuracy.is_some_and(|a| a <= within))
            .min_by(|a, b| a.seconds.total_cmp(&b.seconds));
        match best {
            Some(w) => writeln!(
                out,
                "| {within:.0e} | {} | {} | {:.3} | {:.1e} |",
                w.name,
                w.segments,
                w.seconds,
                w.accuracy.unwrap_or(f64::NAN)
            )?,
            None => writeln!(out, "| {within:.0e} | none measured | | | |")?,
        }
    }
    writeln!(
        out,
        "\n| operation | N = 200 | 400 | 800 | 1600 | 3200 | exponent (200→3200) |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|")?;
    for (k, v) in &r.per_call {
        let cells: Vec<String> = v.iter().map(|(_, t)| format!("{:.3e} s", t)).collect();
        writeln!(
            out,
            "| {k} | {} | {:.2} |",
            cells.join(" | "),
            r.exponents[k]
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn workload(name: &str, segments: usize, seconds: f64) -> Workload {
        Workload {
            name: name.into(),
            segments,
            seconds,
            newton_iterations: 0,
            factorizations: 0,
            peak_bytes: 0,
            accuracy: None,
        }
    }

    #[test]
    fn the_branch_exponent_is_the_slope_of_log_time_on_log_n() {
        // t = 3e-3 N^1.5 with a workload of another name beside it
        let mut w: Vec<Workload> = BRANCH_SEGMENTS
            .iter()
            .map(|&n| workload(BRANCH_WITH_EIGENVALUES, n, 3e-3 * (n as f64).powf(1.5)))
            .collect();
        w.push(workload("figure_3_branch", 200, 100.0));
        let x = branch_exponent(&w).unwrap();
        assert!((x - 1.5).abs() < 1e-12, "{x}");
        assert_eq!(branch_exponent(&w[..1]), None);
    }
}
