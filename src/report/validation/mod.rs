//! The validation report: every number in docs/validation.md is computed here
//! (`knotrod validate > docs/validation.md`), never typed by hand.

use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::EventKind;
use crate::geometry::closure::ray_closure;
use crate::geometry::writhe::writhe_closed;
use crate::io::summary::relative_deviation;
use crate::model::energy::RodEnergy;
use crate::model::rod::{Clamps, RodModel, RodState};
use crate::model::shooting::{ShootingSolution, refine_shooting};
use crate::report::analytic::{euler_buckling_load, greenhill_constant, greenhill_twisting_moment};
use crate::scene::{InitialShape, Scene};
use crate::solve::minimizer::Minimizer;
use crate::solve::outcome::SolverSettings;
use crate::study::start::solve_scene;
use anyhow::{Context, Result};
use nalgebra::Vector3;
use std::f64::consts::PI;
use std::fmt::Write;
use std::path::Path;

fn norm3(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

fn order(e_coarse: f64, e_fine: f64) -> String {
    if e_coarse > 0.0 && e_fine > 0.0 {
        format!("{:.2}", (e_coarse / e_fine).log2())
    } else {
        "–".into()
    }
}

/// Table cells "| value | order |" for a row of errors, the order taken
/// against the previous row (if any).
fn error_cells(prev: Option<&[f64]>, cur: &[f64]) -> String {
    let mut line = String::new();
    for (c, e) in cur.iter().enumerate() {
        let p = prev.map_or(String::new(), |p| order(p[c], *e));
        line += &format!("| {e:.3e} | {p} ");
    }
    line + "|"
}

/// The continuum solution for a shooting scene: its data refined on the s = 1
/// boundary conditions, as (n(0), m(0), Tw).
pub fn continuum_reference(scene: &Scene) -> Option<([f64; 3], [f64; 3], f64)> {
    if scene.initial.shape != InitialShape::Shooting {
        return None;
    }
    let model = scene.rod_model(None);
    let (n0, m0) = (scene.initial.n0?, scene.initial.m0?);
    let (n0, m0) = refine_shooting(
        Vector3::from(n0),
        Vector3::from(m0),
        model.k2,
        model.k3,
        &scene.clamps(),
        40_000,
    )?;
    let tw = ShootingSolution::integrate(n0, m0, model.k2, model.k3, 40_000).twist();
    Some((n0.into(), m0.into(), tw))
}

/// Convergence in N of a scene's equilibrium, as markdown tables.
pub fn convergence_table(scene: &Scene, segments: &[usize]) -> Result<String> {
    let model = scene.rod_model(None);
    let mut rows: Vec<(usize, Equilibrium)> = Vec::new();
    for &n in segments {
        let eq = solve_scene(scene, Some(n)).with_context(|| format!("N = {n}"))?;
        rows.push((n, eq));
    }
    let mut s = String::new();
    writeln!(
        s,
        "Scene `{}` (K2 = {}, K3 = {}, stretching stiffness {:.3e}).\n",
        scene.name.as_deref().unwrap_or(""),
        model.k2,
        model.k3,
        model.stretching_stiffness
    )?;
    writeln!(
        s,
        "| N | n1(0) | n2(0) | n3(0) | m1(0) | m2(0) | m3(0) | Tw | E | lowest ω² | Newton its | time (s) |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|")?;
    for (n, e) in &rows {
        writeln!(
            s,
            "| {n} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.6} | {:.6} | {:.4} | {} |",
            e.n0[0],
            e.n0[1],
            e.n0[2],
            e.m0[0],
            e.m0[1],
            e.m0[2],
            e.twist,
            e.energy,
            e.omega_squared.first().copied().unwrap_or(f64::NAN),
            e.iterations,
        )?;
    }
    if let Some((n0, m0, tw)) = continuum_reference(scene) {
        writeln!(
            s,
            "| shooting (refined) | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.6} | | | |",
            n0[0], n0[1], n0[2], m0[0], m0[1], m0[2], tw
        )?;
        writeln!(
            s,
            "\nErrors against the refined shooting solution, observed order p = log2(e(N/2)/e(N)):\n"
        )?;
        writeln!(
            s,
            "| N | ‖n(0) − n_ref‖ | p | ‖m(0) − m_ref‖ | p | \\|Tw − Tw_ref\\| | p |"
        )?;
        writeln!(s, "|---|---|---|---|---|---|---|")?;
        let errs: Vec<[f64; 3]> = rows
            .iter()
            .map(|(_, e)| [norm3(&e.n0, &n0), norm3(&e.m0, &m0), (e.twist - tw).abs()])
            .collect();
        for (k, (n, _)) in rows.iter().enumerate() {
            let prev = k.checked_sub(1).map(|j| errs[j].as_slice());
            writeln!(s, "| {n} {}", error_cells(prev, &errs[k]))?;
        }
    }
    writeln!(
        s,
        "\nSelf-convergence: differences between successive N, order p = log2(d(N/2→N)/d(N→2N)):\n"
    )?;
    writeln!(
        s,
        "| N → 2N | ‖Δn(0)‖ | p | ‖Δm(0)‖ | p | \\|ΔTw\\| | p | \\|ΔE\\| | p | \\|Δω²₁\\| | p |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|")?;
    let first = |e: &Equilibrium| e.omega_squared.first().copied().unwrap_or(f64::NAN);
    let diffs: Vec<[f64; 5]> = rows
        .windows(2)
        .map(|w| {
            let (a, b) = (&w[0].1, &w[1].1);
            [
                norm3(&a.n0, &b.n0),
                norm3(&a.m0, &b.m0),
                (a.twist - b.twist).abs(),
                (a.energy - b.energy).abs(),
                (first(a) - first(b)).abs(),
            ]
        })
        .collect();
    for (k, d) in diffs.iter().enumerate() {
        let prev = k.checked_sub(1).map(|j| diffs[j].as_slice());
        writeln!(
            s,
            "| {} → {} {}",
            rows[k].0,
            rows[k + 1].0,
            error_cells(prev, d)
        )?;
    }
    Ok(s)
}

fn paper_table(scene: &Scene, n: usize) -> Result<String> {
    let e = solve_scene(scene, Some(n))?;
    let r = scene
        .reference
        .as_ref()
        .context("scene has no [reference]")?;
    let mut s = String::new();
    writeln!(
        s,
        "| quantity | knotrod (N = {n}) | {} | deviation |",
        r.source.as_deref().unwrap_or("paper")
    )?;
    writeln!(s, "|---|---|---|---|")?;
    let v = |a: &[f64; 3]| format!("({:.3}, {:.3}, {:.3})", a[0], a[1], a[2]);
    if let Some(n0) = &r.n0 {
        writeln!(
            s,
            "| n(0) | {} | {} | {:.2}% of ‖n(0)‖ |",
            v(&e.n0),
            v(n0),
            100.0 * relative_deviation(&e.n0, n0)
        )?;
    }
    if let Some(m0) = &r.m0 {
        writeln!(
            s,
            "| m(0) | {} | {} | {:.2}% of ‖m(0)‖ |",
            v(&e.m0),
            v(m0),
            100.0 * relative_deviation(&e.m0, m0)
        )?;
    }
    if let Some(tw) = r.twist {
        writeln!(s, "| Tw | {:.4} | {tw} | {:+.4} |", e.twist, e.twist - tw)?;
    }
    if let Some(l) = r.link {
        writeln!(
            s,
            "| link Tw + Wr | {:.4} (Wr = {:.4}) | {l} | {:+.4} |",
            e.link,
            e.writhe,
            e.link - l
        )?;
    }
    if let Some(d) = r.knot_determinant {
        writeln!(
            s,
            "| knot determinant | {} ({}) | {d} | |",
            e.knot_determinant,
            e.knot_name.as_deref().unwrap_or("?")
        )?;
    }
    writeln!(
        s,
        "| min self-distance | {:.4} at s = ({:.3}, {:.3}) | > 0 (contact-free) | |",
        e.min_self_distance, e.min_self_distance_s[0], e.min_self_distance_s[1]
    )?;
    if let Some(w) = r.walled {
        writeln!(
            s,
            "| walled | {} (z in [{:.4}, {:.4}]) | {w} | |",
            e.walled, e.min_z, e.max_z
        )?;
    }
    if let Some(st) = r.stable {
        writeln!(
            s,
            "| stable | {} (lowest ω² = {:.3}, {} negative) | {st} | |",
            e.stable,
            e.omega_squared.first().copied().unwrap_or(f64::NAN),
            e.negative_eigenvalues
        )?;
    }
    writeln!(
        s,
        "| Newton | {} iterations, relative gradient {:.1e} | | |",
        e.iterations, e.gradient_norm
    )?;
    Ok(s)
}

fn analytic_tables() -> Result<String> {
    let mut s = String::new();
    // uniform twist
    writeln!(s, "### Straight rod twisted by φ (K2 = 1, z* = 1)\n")?;
    writeln!(s, "| N | φ/2π | K3 | Tw − φ/2π | E − K3 φ²/2 |")?;
    writeln!(s, "|---|---|---|---|---|")?;
    for (n, f, k3) in [(20, 0.3, 3.0), (50, 1.3, 1.0), (200, -0.75, 1.5)] {
        let model = RodModel {
            segments: n,
            k2: 1.0,
            k3,
            stretching_stiffness: 640_000.0,
            law: Default::default(),
        };
        let mut newton = Minimizer::new(RodEnergy::new(model));
        let mut st = RodState::straight(n, Clamps::new(1.0, 0.0, f));
        newton.minimize(&mut st, &SolverSettings::default())?;
        let phi = 2.0 * PI * f;
        writeln!(
            s,
            "| {n} | {f} | {k3} | {:.1e} | {:.1e} |",
            st.twist() - f,
            newton.energy.energy(&st) - k3 * phi * phi / 2.0
        )?;
    }
    let p_e = 4.0 * PI * PI;
    writeln!(
        s,
        "\n### Euler buckling of a clamped isotropic rod (continuum 4π² = {p_e:.5})\n"
    )?;
    writeln!(
        s,
        "Compressive force at the first negative eigenvalue, found by bisection on the inertia.\n"
    )?;
    writeln!(
        s,
        "| N | S = 6.4e5: P | rel. error | S = 1e9: P | rel. error | p |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|")?;
    let mut prev = None;
    for n in [50, 100, 200, 400] {
        let p1 = euler_buckling_load(n, 640_000.0)?;
        let p2 = euler_buckling_load(n, 1e9)?;
        let e2 = (p2 - p_e).abs() / p_e;
        let p = prev.map_or(String::new(), |e| order(e, e2));
        writeln!(
            s,
            "| {n} | {p1:.5} | {:.2e} | {p2:.5} | {e2:.2e} | {p} |",
            (p1 - p_e).abs() / p_e
        )?;
        prev = Some(e2);
    }
    let m_c = greenhill_constant();
    writeln!(
        s,
        "\n### Torsional (Greenhill) buckling, clamped ends, no axial load (continuum M L/B = 2x₁, tan x₁ = x₁: {m_c:.5} = {:.4}π)\n",
        m_c / PI
    )?;
    writeln!(s, "| N | K3 φ at loss of stability | rel. error | p |")?;
    writeln!(s, "|---|---|---|---|")?;
    let mut prev = None;
    for n in [50, 100, 200, 400] {
        let m = greenhill_twisting_moment(n, 3.0, 640_000.0)?;
        let e = (m - m_c).abs() / m_c;
        let p = prev.map_or(String::new(), |x| order(x, e));
        writeln!(s, "| {n} | {m:.5} | {e:.2e} | {p} |")?;
        prev = Some(e);
    }
    Ok(s)
}

fn stiffness_table(scene: &Scene) -> Result<String> {
    let (n_ref, _, tw_ref) =
        continuum_reference(scene).context("stiffness study needs a shooting scene")?;
    let mut s = String::new();
    writeln!(
        s,
        "| S = EA L²/B11 | Tw (Richardson 400/800) | \\|Tw − Tw_ref\\| | ‖n(0) − n_ref‖ (Richardson) | largest \\|strain\\| at N = 800 |"
    )?;
    writeln!(s, "|---|---|---|---|---|")?;
    for stiff in [1e4, 1e5, 6.4e5, 1e7, 1e8] {
        let mut sc = scene.clone();
        sc.model.stretching_stiffness = Some(stiff);
        let a = solve_scene(&sc, Some(400))?;
        let b = solve_scene(&sc, Some(800))?;
        let tw = (4.0 * b.twist - a.twist) / 3.0;
        let n0: [f64; 3] = std::array::from_fn(|k| (4.0 * b.n0[k] - a.n0[k]) / 3.0);
        let h = 1.0 / 800.0;
        let strain = (1..800)
            .map(|j| ((b.state.nodes[j + 1] - b.state.nodes[j]).norm() / h - 1.0).abs())
            .fold(0.0, f64::max);
        writeln!(
            s,
            "| {stiff:.1e} | {tw:.6} | {:.2e} | {:.2e} | {strain:.2e} |",
            (tw - tw_ref).abs(),
            norm3(&n0, &n_ref)
        )?;
    }
    Ok(s)
}

fn writhe_table(scenes: &[&Scene]) -> Result<String> {
    let mut s = String::new();
    let radii = [1e1, 1e2, 1e3, 1e4, 1e5, 1e6];
    write!(s, "| scene (N = 200) |")?;
    for r in radii {
        write!(s, " Wr, rays {r:.0e} |")?;
    }
    writeln!(s, " Tw | link (rays 1e6) | paper Tw + Wp* |")?;
    writeln!(s, "|---|{}---|---|---|", "---|".repeat(radii.len()))?;
    for scene in scenes {
        let e = solve_scene(scene, Some(200))?;
        let (p, _) = e.state.centreline();
        write!(s, "| {} |", scene.name.as_deref().unwrap_or(""))?;
        for r in radii {
            let w = writhe_closed(&ray_closure(&p, -Vector3::z(), Vector3::z(), r));
            write!(s, " {w:.7} |")?;
        }
        let paper = scene
            .reference
            .as_ref()
            .and_then(|r| r.link)
            .map_or(String::new(), |l| l.to_string());
        writeln!(s, " {:.5} | {:.5} | {paper} |", e.twist, e.link)?;
    }
    Ok(s)
}

/// Events of the Figure 3 branch (main branch, φ/2π in [0.745, 0.99]) at N.
fn figure_3_events(d: &Scene, n: usize) -> Result<Vec<crate::analysis::event::Event>> {
    let mut scene = d.clone();
    scene.continuation = Some(crate::scene::ContinuationSpec {
        parameter: crate::model::rod::Parameter::Phi,
        range: [0.745, 0.99],
        direction: crate::scene::Direction::Both,
        locate_events: true,
        switch_branches: false,
        step: None,
        max_step: None,
        max_points: None,
    });
    Ok(crate::study::run::run_scene(&scene, Some(n), &mut |_| {
        Ok(())
    })?)
}

fn figure_3_table(d: &Scene) -> Result<String> {
    let mut s = String::new();
    let targets = [
        ("W1", EventKind::Wall, 0.774, Some(0.774)),
        ("W2", EventKind::Wall, 0.82, Some(0.82)),
        ("X", EventKind::Crossing, 0.96, Some(0.96)),
        ("S", EventKind::BranchPoint, 0.75, None),
    ];
    let ns = [100, 200, 400];
    let mut found: Vec<Vec<f64>> = Vec::new();
    for &n in &ns {
        let events = figure_3_events(d, n)?;
        found.push(
            targets
                .iter()
                .map(|(_, kind, near, _)| {
                    events
                        .iter()
                        .filter(|e| e.kind == *kind && e.branch == 0)
                        .map(|e| e.phi_over_2pi)
                        .min_by(|a, b| (a - near).abs().total_cmp(&(b - near).abs()))
                        .unwrap_or(f64::NAN)
                })
                .collect(),
        );
    }
    writeln!(
        s,
        "| event | paper φ/2π | N = 100 | N = 200 | N = 400 | Richardson (200, 400) | observed order |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|---|")?;
    for (k, (label, _, _, paper)) in targets.iter().enumerate() {
        let (a, b, c) = (found[0][k], found[1][k], found[2][k]);
        let rich = (4.0 * c - b) / 3.0;
        writeln!(
            s,
            "| {label} | {} | {a:.5} | {b:.5} | {c:.5} | {rich:.5} | {} |",
            paper.map_or("(read off Fig. 3 only)".into(), |p| format!("{p}")),
            order((a - b).abs(), (b - c).abs())
        )?;
    }
    Ok(s)
}

fn island_table(scenes: &Path) -> Result<String> {
    island_table_of(scenes, "fig7_island_kirchhoff", &["S", "W1", "W2", "X"])
}

/// A map's table, with its traced boundary compared with the curves the
/// paper names (`paper`).
fn island_table_of(scenes: &Path, name: &str, paper: &[&str]) -> Result<String> {
    let scene = Scene::load(&scenes.join(format!("{name}.toml")))?;
    let spec = scene.map.clone().context("fig7 scene has no [map]")?;
    let cont = scene
        .continuation
        .as_ref()
        .context("fig7 scene has no [continuation]")?;
    let cache =
        std::env::temp_dir().join(format!("knotrod-validate-island-{}", std::process::id()));
    let indices: Vec<usize> = (0..spec.lines).collect();
    let lines = crate::study::map::compute_lines(
        &scene,
        &spec,
        &indices,
        None,
        &crate::io::map_files::LineFolder::create(&cache)?,
        &|_| {},
    )?;
    let traced = crate::io::map_files::trace_cached(&scene, &spec, None, &cache, &|_, _| {})?;
    let _ = std::fs::remove_dir_all(&cache);
    let map = crate::study::map::assemble(name, &spec, cont.range, lines, Some(traced));
    let mut s = String::new();
    writeln!(
        s,
        "Command: `cargo run --release -- map scenes/{name}.toml` (N = {}, {} lines).\n",
        scene.model.segments, spec.lines
    )?;
    writeln!(
        s,
        "| z* | good interval(s) of φ/2π (lower boundary, upper boundary) |"
    )?;
    writeln!(s, "|---|---|")?;
    for l in &map.lines {
        let iv: Vec<String> = l.intervals.iter().map(|i| i.to_string()).collect();
        if !iv.is_empty() || l.error.is_some() {
            writeln!(
                s,
                "| {:.3} | {}{} |",
                l.value,
                iv.join(" "),
                l.error
                    .as_deref()
                    .map(|e| format!(" failed: {e}"))
                    .unwrap_or_default()
            )?;
        }
    }
    let bb = &map.bounding_box;
    writeln!(
        s,
        "\nGood knots for z* in [{:.3}, {:.3}] (lines {:.3} apart) and φ/2π in [{:.4}, {:.4}]; area {:.5} in the (z*, φ/2π) plane. Boundaries met: {}.",
        bb.get("z_star").map_or(f64::NAN, |v| v[0]),
        bb.get("z_star").map_or(f64::NAN, |v| v[1]),
        spec.value(1) - spec.value(0),
        bb.get("phi_over_2pi").map_or(f64::NAN, |v| v[0]),
        bb.get("phi_over_2pi").map_or(f64::NAN, |v| v[1]),
        map.good_area,
        map.grid_boundaries
            .keys()
            .cloned()
            .collect::<Vec<_>>()
            .join(", ")
    )?;
    if let Some(t) = &map.traced {
        s += &traced_table(t)?;
        let mut ours: Vec<&str> = t.pieces.iter().map(|p| p.label.as_str()).collect();
        let order = ours.join(", ");
        ours.sort();
        let mut theirs = paper.to_vec();
        theirs.sort();
        writeln!(
            s,
            "Curves in walk order: {order}; {} the paper's ({}).",
            if ours == theirs {
                "exactly"
            } else {
                "not the same as"
            },
            paper.join(", ")
        )?;
        s += &refined_ends(&scene, &spec, &map, t)?;
        // the loop across the scene's own z*, where the paper prints the
        // good interval of its Figure 3 (Kirchhoff rod)
        let z = spec.parameter.value(&scene.clamps());
        let mut cuts = t.cuts(z);
        cuts.sort_by(f64::total_cmp);
        let cuts: Vec<String> = cuts.iter().map(|c| format!("{c:.4}")).collect();
        writeln!(
            s,
            "\nThe loop crosses {} = {z} at φ/2π = {}.",
            spec.parameter.name(),
            cuts.join(", ")
        )?;
    }
    Ok(s)
}

/// Grid ends more than 5e-4 from the traced loop, recomputed on their line
/// with a continuation step 20 times finer: a coarse step can jump over a
/// thin sliver of another class.
fn refined_ends(
    scene: &Scene,
    spec: &crate::scene::MapSpec,
    map: &crate::study::map::Map,
    t: &crate::study::boundary::Traced,
) -> Result<String> {
    let mut s = String::new();
    let mut fine = scene.clone();
    let c = fine
        .continuation
        .as_mut()
        .context("the map has a [continuation]")?;
    let step = c.max_step.unwrap_or(0.01) / 20.0;
    c.max_step = Some(step);
    for l in &map.lines {
        let cuts = t.cuts(l.value);
        let nearest = |x: f64| {
            cuts.iter()
                .copied()
                .min_by(|a, b| (a - x).abs().total_cmp(&(b - x).abs()))
        };
        let far: Vec<(f64, f64)> = l
            .intervals
            .iter()
            .flat_map(|i| [i.lo, i.hi])
            .filter_map(|e| nearest(e).map(|c| (e, c)))
            .filter(|(e, c)| (e - c).abs() > 5e-4)
            .collect();
        if far.is_empty() {
            continue;
        }
        if s.is_empty() {
            writeln!(
                s,
                "\nGrid ends more than 5e-4 from the loop, recomputed with a continuation step of {step} instead of {}:\n",
                step * 20.0
            )?;
            writeln!(
                s,
                "| z* | grid end | refined line's nearest end | traced loop |"
            )?;
            writeln!(s, "|---|---|---|---|")?;
        }
        let refined = crate::study::map::line(&fine, spec, l.index, None);
        let ends: Vec<(f64, String)> = refined
            .intervals
            .iter()
            .flat_map(|i| [(i.lo, i.lo_label.clone()), (i.hi, i.hi_label.clone())])
            .collect();
        for (e, loop_end) in far {
            let r = ends
                .iter()
                .min_by(|a, b| (a.0 - loop_end).abs().total_cmp(&(b.0 - loop_end).abs()));
            writeln!(
                s,
                "| {:.3} | {:.5} | {} | {:.5} |",
                l.value,
                e,
                r.map_or("—".to_string(), |r| format!("{:.5} ({})", r.0, r.1)),
                loop_end
            )?;
        }
    }
    Ok(s)
}

/// The boundary walked by two-parameter continuation, against the grid.
fn traced_table(t: &crate::study::boundary::Traced) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\nThe boundary traced directly (two-parameter continuation of each condition, the good region on the left, turning at each corner onto the condition that fails there): {} points, {} equilibria solved, {}.\n",
        t.points,
        t.equilibria,
        if t.closed {
            "the walk closes on its start".to_string()
        } else {
            format!("open: {}", t.stopped.as_deref().unwrap_or("?"))
        }
    )?;
    writeln!(
        s,
        "| curve | condition | from (z*, φ/2π) | to (z*, φ/2π) | points |"
    )?;
    writeln!(s, "|---|---|---|---|---|")?;
    for p in &t.pieces {
        let (a, b) = (p.points[0], p.points[p.points.len() - 1]);
        writeln!(
            s,
            "| {} | {} | ({:.4}, {:.4}) | ({:.4}, {:.4}) | {} |",
            p.label,
            p.condition,
            a[0],
            a[1],
            b[0],
            b[1],
            p.points.len()
        )?;
    }
    let bb = &t.bounding_box;
    let range = |k: &str| bb.get(k).copied().unwrap_or([f64::NAN; 2]);
    writeln!(
        s,
        "\nTraced extent: z* in [{:.4}, {:.4}], φ/2π in [{:.4}, {:.4}]; enclosed area {}.",
        range("z_star")[0],
        range("z_star")[1],
        range("phi_over_2pi")[0],
        range("phi_over_2pi")[1],
        t.area.map_or("—".to_string(), |a| format!("{a:.5}"))
    )?;
    if let Some(g) = &t.grid_check {
        writeln!(
            s,
            "Check against the grid: {} interval ends of the lines the loop spans lie within {:.1e} in φ/2π of the loop's crossings of those lines (chords of the traced polyline against bisected events); lines where the loop and the grid count different ends: {}.",
            g.ends,
            g.max_phi_deviation,
            if g.lines_with_other_count.is_empty() {
                "none".to_string()
            } else {
                g.lines_with_other_count
                    .iter()
                    .map(|v| format!("{v:.3}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        )?;
    }
    Ok(s)
}

/// Runs a scene (optionally at another N, with TOML appended) and returns its
/// equilibria and events.
fn run_text(
    text: &str,
) -> Result<(
    Vec<crate::analysis::equilibrium::Equilibrium>,
    Vec<crate::analysis::event::Event>,
)> {
    let scene = Scene::parse(text)?;
    let mut eqs = Vec::new();
    let events = crate::study::run::run_scene(&scene, None, &mut |e| {
        eqs.push(e);
        Ok(())
    })?;
    Ok((eqs, events))
}

fn scene_text(scenes: &Path, file: &str, segments: Option<usize>) -> Result<String> {
    let text = std::fs::read_to_string(scenes.join(file))?;
    let text = text
        .split("[output]")
        .next()
        .unwrap_or_default()
        .to_string();
    Ok(match segments {
        Some(n) => text
            .lines()
            .map(|l| {
                if l.starts_with("segments = ") {
                    format!("segments = {n}")
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n"),
        None => text,
    })
}

fn loading_table(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "| steps up / down | jump up at φ/2π | jump down at φ/2π |\n|---|---|---|"
    )?;
    for (up, down) in [(60, 35), (97, 53)] {
        let text = scene_text(scenes, "loading_twist_snap.toml", None)?
            .replace("steps = 60", &format!("steps = {up}"))
            .replace("steps = 35", &format!("steps = {down}"));
        let (_, events) = run_text(&text)?;
        let jumps: Vec<f64> = events
            .iter()
            .filter(|e| e.kind == EventKind::Jump)
            .map(|e| e.phi_over_2pi)
            .collect();
        writeln!(
            s,
            "| {up} / {down} | {} | {} |",
            jumps.first().map_or("—".into(), |v| format!("{v:.5}")),
            jumps.get(1).map_or("—".into(), |v| format!("{v:.5}"))
        )?;
    }
    Ok(s)
}

fn strip_table(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "| N | z* | φ/2π range | good intervals of φ/2π | stable everywhere | largest \\|u2\\| | events fold/branch point |\n|---|---|---|---|---|---|---|"
    )?;
    for n in [100, 200] {
        let (eqs, events) = run_text(&scene_text(scenes, "fig8_strip.toml", Some(n))?)?;
        let folds = events
            .iter()
            .filter(|e| e.kind == EventKind::Fold || e.kind == EventKind::BranchPoint)
            .count();
        for z in [0.115, 0.150, 0.180, 0.200, 0.215] {
            let mut pts: Vec<&crate::analysis::equilibrium::Equilibrium> =
                eqs.iter().filter(|e| (e.z_star - z).abs() < 1e-9).collect();
            pts.sort_by(|a, b| a.phi_over_2pi.total_cmp(&b.phi_over_2pi));
            let mut intervals = Vec::new();
            let mut start: Option<f64> = None;
            let mut last = f64::NAN;
            for p in &pts {
                match (p.good_knot, start) {
                    (true, None) => start = Some(p.phi_over_2pi),
                    (false, Some(a)) => {
                        intervals.push(format!("[{a:.3}, {last:.3}]"));
                        start = None;
                    }
                    _ => {}
                }
                last = p.phi_over_2pi;
            }
            if let Some(a) = start {
                intervals.push(format!("[{a:.3}, {last:.3}]"));
            }
            let u2 = pts.iter().filter_map(|p| p.max_u2).fold(0.0, f64::max);
            writeln!(
                s,
                "| {n} | {z:.3} | [{:.3}, {:.3}] | {} | {} | {u2:.1e} | {folds} |",
                pts.first().map_or(f64::NAN, |p| p.phi_over_2pi),
                pts.last().map_or(f64::NAN, |p| p.phi_over_2pi),
                intervals.join(" "),
                pts.iter().all(|p| p.stable)
            )?;
        }
    }
    Ok(s)
}

fn double_ring_table() -> Result<String> {
    use crate::model::energy::RodEnergy;
    use crate::model::rod::{Law, RodModel};
    let mut s = String::new();
    writeln!(
        s,
        "| N | K at which the double ring's lowest eigenvalue changes sign (K2 = K3 = K) | error against 2 |\n|---|---|---|"
    )?;
    for n in [50, 100, 200] {
        let scene = Scene::parse(&format!(
            "[model]\nsegments = {n}\n[clamps]\nz_star = 0.0\ndelta = 0.0\nphi_over_2pi = 1.0\n[initial]\nshape = \"double_ring\"\nsteps = 1\n"
        ))?;
        let (_, ring, _) = crate::study::start::starting_equilibrium(&scene, None)?;
        let lowest = |k: f64| -> Result<f64> {
            let energy = RodEnergy::new(RodModel {
                segments: n,
                k2: k,
                k3: k,
                stretching_stiffness: 640_000.0,
                law: Law::Kirchhoff,
            });
            let mut g = vec![0.0; energy.map.len()];
            let mut v = vec![0.0; energy.pattern.nnz()];
            energy.hessian(&ring, &mut g, &mut v);
            let mut ldlt = crate::linalg::sparse::Ldlt::new(&energy.pattern);
            let sp =
                crate::linalg::eigen::lowest_eigenvalues(&energy.pattern, &v, None, 1, &mut ldlt)?;
            Ok(sp.values[0])
        };
        let (mut lo, mut hi) = (1.5, 2.5);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if lowest(mid)? > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let k = 0.5 * (lo + hi);
        writeln!(s, "| {n} | {k:.6} | {:.2e} |", k - 2.0)?;
    }
    Ok(s)
}

fn asymptotics_table() -> Result<String> {
    use crate::study::asymptotics::{
        curve_i, curve_ii, max_one_contact_z_star, one_contact_shifts,
    };
    let mut s = String::new();
    writeln!(
        s,
        "Along Δφ = 0.8 z* (N = 200): the end shifts δ_I, δ_II where the strands pass at c1, c2, against eqs. (6.15), (6.18) with exact coefficients ({:.4}, {:.4}).\n",
        crate::study::asymptotics::curve_i_first_order(),
        crate::study::asymptotics::curve_i_second_order()
    )?;
    writeln!(
        s,
        "| z* | Δφ | δ_I numerical | δ_I (6.15) | relative error | δ_II numerical | δ_II (6.18) | relative error |\n|---|---|---|---|---|---|---|---|"
    )?;
    for z in [0.08, 0.04, 0.02] {
        let dphi = 0.8 * z;
        let (d2, d1) = one_contact_shifts(200, z, dphi)?;
        let (a1, a2) = (curve_i(z, dphi), curve_ii(z, dphi));
        writeln!(
            s,
            "| {z} | {dphi:.3} | {d1:.6} | {a1:.6} | {:.2e} | {d2:.3e} | {a2:.3e} | {:.2e} |",
            (d1 - a1) / a1,
            (d2 - a2) / a2
        )?;
    }
    let zmax = max_one_contact_z_star(100, 0.001, 0.002)?;
    writeln!(
        s,
        "\nLargest z* of the one-contact curve at δ = 0.001 (N = 100, bisection to 0.002): {zmax:.4}; the paper's limit as δ → 0 is 0.223 (the self-contacting planar elastica)."
    )?;
    Ok(s)
}

fn map3_table(scenes: &Path) -> Result<String> {
    let scene = Scene::load(&scenes.join("fig9_strip_3d.toml"))?;
    let spec = scene.map.clone().context("fig9 scene has no [map]")?;
    let slices = spec
        .slices
        .clone()
        .context("fig9 scene has no [map.slices]")?;
    let cont = scene.continuation.as_ref().context("no [continuation]")?;
    let mut maps = Vec::new();
    for k in 0..slices.values.len() {
        let slice = slices.scene(&scene, k);
        let sspec = slice.map.clone().unwrap();
        let cache =
            std::env::temp_dir().join(format!("knotrod-validate-fig9-{}-{k}", std::process::id()));
        let idx: Vec<usize> = (0..sspec.lines).collect();
        let lines = crate::study::map::compute_lines(
            &slice,
            &sspec,
            &idx,
            None,
            &crate::io::map_files::LineFolder::create(&cache)?,
            &|_| {},
        )?;
        let traced = crate::io::map_files::trace_cached(&slice, &sspec, None, &cache, &|_, _| {})?;
        let _ = std::fs::remove_dir_all(&cache);
        maps.push(crate::study::map::assemble(
            "fig9",
            &sspec,
            cont.range,
            lines,
            Some(traced),
        ));
    }
    let m3 = crate::study::map::assemble_3d("fig9_strip_3d", &slices, maps);
    let mut s = String::new();
    writeln!(
        s,
        "Command: `cargo run --release -- map scenes/fig9_strip_3d.toml` (N = {}, {} lines per slice).\n",
        scene.model.segments, spec.lines
    )?;
    writeln!(
        s,
        "| δ | good area (grid) | z* range | φ/2π range | traced boundary: area, z* range, φ/2π range | largest φ/2π gap to the grid's ends |\n|---|---|---|---|---|---|"
    )?;
    for (m, v) in m3.slices.iter().zip(&m3.slice_values) {
        let r = |b: &std::collections::BTreeMap<String, [f64; 2]>, k: &str| {
            b.get(k)
                .map_or("—".to_string(), |b| format!("[{:.3}, {:.3}]", b[0], b[1]))
        };
        let traced = match &m.traced {
            Some(t) if t.closed => format!(
                "{:.5}, {}, {}",
                t.area.unwrap_or(f64::NAN),
                r(&t.bounding_box, "z_star"),
                r(&t.bounding_box, "phi_over_2pi")
            ),
            Some(t) => format!("open: {}", t.stopped.as_deref().unwrap_or("?")),
            None => "—".to_string(),
        };
        let gap = m
            .traced
            .as_ref()
            .and_then(|t| t.grid_check.as_ref())
            .map_or("—".to_string(), |g| {
                format!("{:.1e} ({} ends)", g.max_phi_deviation, g.ends)
            });
        writeln!(
            s,
            "| {v} | {:.5} | {} | {} | {traced} | {gap} |",
            m.good_area,
            r(&m.bounding_box, "z_star"),
            r(&m.bounding_box, "phi_over_2pi")
        )?;
    }
    // the slice whose traced region reaches highest in z*, traced again at 2N
    let top = m3
        .slices
        .iter()
        .enumerate()
        .filter_map(|(k, m)| {
            let t = m.traced.as_ref().filter(|t| t.closed)?;
            Some((k, t.bounding_box.get("z_star")?[1]))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((k, zmax)) = top {
        let slice = slices.scene(&scene, k);
        let sspec = slice.map.clone().unwrap();
        let n = 2 * scene.model.segments as usize;
        let t = crate::study::boundary::trace_island(&slice, &sspec, Some(n), &|_, _| {})?;
        let fine = t
            .bounding_box
            .get("z_star")
            .map_or("—".to_string(), |b| format!("{:.4}", b[1]));
        writeln!(
            s,
            "\nThe traced region reaching highest, at δ = {}: largest z* {zmax:.4} at N = {}, {fine} at N = {n} (walk {}; area {}).",
            slices.values[k],
            scene.model.segments,
            if t.closed { "closed" } else { "open" },
            t.area.map_or("—".to_string(), |a| format!("{a:.5}"))
        )?;
    }
    let b = |k: &str| {
        m3.bounding_box
            .get(k)
            .map_or("—".to_string(), |b| format!("[{:.3}, {:.3}]", b[0], b[1]))
    };
    writeln!(
        s,
        "\nGood volume {:.5} in (δ, z*, φ/2π); bounding box δ {}, z* {}, φ/2π {}. The paper: no good knots outside 0.01 < δ < 0.3, 0.05 < z* < 0.45, 0.02 < 1 − φ/2π < 0.5.",
        m3.good_volume,
        b("delta"),
        b("z_star"),
        b("phi_over_2pi")
    )?;
    Ok(s)
}

fn contact_table(scenes: &Path) -> Result<String> {
    let (eqs, events) = run_text(&scene_text(scenes, "trefoil_contact_start.toml", None)?)?;
    let mut s = String::new();
    let a = eqs
        .iter()
        .find(|e| e.phi_over_2pi.abs() < 1e-12)
        .context("configuration A")?;
    writeln!(
        s,
        "Command: `cargo run --release -- run scenes/trefoil_contact_start.toml` (N = 100, h = 0.005).\n"
    )?;
    writeln!(s, "| quantity | knotrod | paper |\n|---|---|---|")?;
    let cs: Vec<String> = a
        .contacts
        .iter()
        .map(|c| format!("{} at s = {:.3} (force {:.1})", c.obstacle, c.s, c.force))
        .collect();
    writeln!(
        s,
        "| A: contacts | {} | two, with the rays, s ≈ 0.17, 0.83 |",
        cs.join("; ")
    )?;
    writeln!(s, "| A: Tw | {:.4} | −0.07 |", a.twist)?;
    writeln!(s, "| A: link | {:.4} | 3.0 |", a.link)?;
    writeln!(
        s,
        "| A: min self-distance | {:.4} (h = 0.005) | > h |",
        a.min_self_distance
    )?;
    let find_with = |kind: EventKind, leg: usize, detail: &str| {
        events
            .iter()
            .filter(|e| e.kind == kind && e.branch == leg && e.detail.contains(detail))
            .map(|e| format!("{:.5}", e.phi_over_2pi))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let find = |kind: EventKind, leg: usize| {
        events
            .iter()
            .filter(|e| e.kind == kind && e.branch == leg)
            .map(|e| format!("{:.5}", e.phi_over_2pi))
            .collect::<Vec<_>>()
            .join(", ")
    };
    writeln!(
        s,
        "| B: ray contact force reaches zero (up) | φ/2π = {} | 0.768 |",
        find_with(EventKind::ContactLost, 0, "ray")
    )?;
    let self_lost = find_with(EventKind::ContactLost, 0, "self");
    writeln!(
        s,
        "| self-contact lost (up; near X the strands touch instead of crossing) | φ/2π = {} | — (no contact in the paper's X) |",
        if self_lost.is_empty() {
            "none".to_string()
        } else {
            self_lost
        }
    )?;
    writeln!(
        s,
        "| jumps on the way up | φ/2π = {} | at B |",
        find(EventKind::Jump, 0)
    )?;
    writeln!(
        s,
        "| C: walls on the way up (W1, W2) | φ/2π = {} | 0.774, 0.82 |",
        find(EventKind::Wall, 0)
    )?;
    writeln!(
        s,
        "| back down: jumps | φ/2π = {} | at S (no return to B) |",
        find(EventKind::Jump, 1)
    )?;
    Ok(s)
}

/// The whole validation report (markdown).
pub fn report(scenes: &Path) -> Result<String> {
    let d = Scene::load(&scenes.join("appendix_d.toml"))?;
    let e = Scene::load(&scenes.join("appendix_e.toml"))?;
    let mut s = String::new();
    writeln!(s, "# Validation\n")?;
    writeln!(
        s,
        "Generated by `cargo run --release -- validate > docs/validation.md` (knotrod {}); every number below is computed by that command. Do not edit by hand.\n",
        env!("CARGO_PKG_VERSION")
    )?;
    writeln!(s, "## Analytic cases\n")?;
    s += &analytic_tables()?;
    writeln!(s, "\n## Appendix D (good knot), N = 200\n")?;
    s += &paper_table(&d, 200)?;
    writeln!(
        s,
        "\n## Appendix E (stable, knotted, not walled), N = 200\n"
    )?;
    s += &paper_table(&e, 200)?;
    writeln!(s, "\n## Writhe of the ray closure versus ray length\n")?;
    writeln!(
        s,
        "The rod closed by rays along ∓z and a far loop; the writhe's error decays as 1/(ray length), and summaries use 1e6. The link Tw + Wr equals 3 + φ/2π (Călugăreanu–White for the ribbon d1 closed by the clamps' frames).\n"
    )?;
    s += &writhe_table(&[&d, &e])?;
    writeln!(
        s,
        "\n## Figure 3: events along the branch, convergence in N\n"
    )?;
    writeln!(
        s,
        "The flip-symmetric branch at z* = 0.115, δ = 0.05 continued in φ from the Appendix D knot (`scenes/fig3_kirchhoff.toml`); events located by bisection in arclength (walls W1, W2: the rod touches z = 0 or z = z*; X: the centreline crosses itself and the knot determinant drops from 3 to 1; S: pitchfork, one eigenvalue through zero). The paper prints two digits for W2 and X.\n"
    )?;
    s += &figure_3_table(&d)?;
    writeln!(
        s,
        "\n## Figure 7-left: the island of good knots (Kirchhoff rod, δ = 0.05)\n"
    )?;
    s += &island_table(scenes)?;
    writeln!(
        s,
        "\nThe paper's island is bounded by the four curves S, W1, W2 and X (compare the traced curves above). At z* = 0.115 the paper's Figure 3 has good knots from W1 = 0.774 to W2 = 0.82 (two digits); the loop's crossings of that line are above. The two walls are one condition (the flip maps z to z* − z, so a symmetric knot touches both at once) and one curve round the island's lowest z*, named W1 and W2 on its two sides. S is the pitchfork of the flip-symmetric family (lowest eigenvalue zero). Where a grid end differs from the loop by more than the chords' error, the line's coarse continuation step jumped over a sliver of unwalled states between W2 and X; the refined line (table above) finds the traced W2."
    )?;
    writeln!(
        s,
        "\n## Quasi-static loading: a buckled strip-like rod twisted until it snaps\n"
    )?;
    writeln!(
        s,
        "`scenes/loading_twist_snap.toml` (K2 = 20, K3 = 1.5, z* = 0.8, N = 100): the clamp turned to 1.2 turns and back to 0.5. Jumps are located by bisecting the step to 1e-4 turns, so they do not depend on the step sequence.\n"
    )?;
    s += &loading_table(scenes)?;
    writeln!(
        s,
        "\n## Elastic strip: Figure 8 (branches in φ, δ = 0.05)\n"
    )?;
    writeln!(
        s,
        "`scenes/fig8_strip.toml`: Sadowsky law with u2 = 0 enforced (SQP, clarabel QPs polished on the KKT system), started from the double ring unfolded into the knotted wedge, continued on the KKT system. Good = walled, trefoil, stable, self-distance > h. Paper: a stable walled knotted strip with no self-contact at z* = 0.215, φ/2π ≈ 0.94; no pitchfork, branches down to φ/2π < 0.5.\n"
    )?;
    s += &strip_table(scenes)?;
    writeln!(
        s,
        "\nAt z* ≥ 0.17 the good set of one branch splits in two: the strands pass through each other twice inside the walled range (two crossings X between which the centreline is unknotted). The split is present at N = 100 and N = 200 alike; the island map below shows it as a notch from the top of the island."
    )?;
    writeln!(
        s,
        "\n## Figure 7-right: the island of good knots (elastic strip, δ = 0.05)\n"
    )?;
    s += &island_table_of(scenes, "fig7_island_strip", &["W1", "W2", "X1", "X2"])?;
    writeln!(
        s,
        "\nThe strip's island is larger than the rod's (area and φ range), as the paper finds; the paper bounds it by W1, W2, X1 and X2 (compare the traced curves above). The grid shows a notch the paper does not describe: an unknotted wedge that enters the island from above at z* ≈ 0.17 and splits the good interval of each z* above it in two (see the Figure 8 table, same at N = 200). The walk shows what it is: not another curve but a fold of a crossing curve — the same strands (near the flip axis) pass through each other at two values of φ, and the walk follows that curve down into the notch and up again. Near the island's upper-left corner, where the two crossing curves meet, several segment pairs of nearly coincident strands are in contact at once and the walk turns through a few short corners there."
    )?;
    writeln!(s, "\n## Figure 9: good knots of the strip in (δ, z*, φ)\n")?;
    s += &map3_table(scenes)?;
    writeln!(s, "\n## The double ring's stability (criterion 2.7)\n")?;
    writeln!(
        s,
        "The Kirchhoff double ring (z* = δ = 0, φ = 2π) is stable iff sqrt((K2 − 1)/K2 · (K3 − 1)/K3) ≥ 1/2, i.e. K ≥ 2 for K2 = K3 = K. The sign change of its lowest Hessian eigenvalue, located by bisection in K:\n"
    )?;
    s += &double_ring_table()?;
    writeln!(
        s,
        "\n## Near the double ring: curves I and II (Figure 13)\n"
    )?;
    s += &asymptotics_table()?;
    writeln!(
        s,
        "\n## Contact: the trefoil on the rays, A → B → C (Figures 3-5)\n"
    )?;
    s += &contact_table(scenes)?;
    writeln!(s, "\n## Convergence in N, Appendix D\n")?;
    writeln!(
        s,
        "Command: `cargo run --release -- convergence scenes/appendix_d.toml --segments 50,100,200,400,800`.\n"
    )?;
    s += &convergence_table(&d, &[50, 100, 200, 400, 800])?;
    writeln!(
        s,
        "\n## Near-inextensibility: the stretching penalty's error, Appendix D\n"
    )?;
    writeln!(
        s,
        "Richardson extrapolation of N = 400 and 800 removes the O(1/N²) error; what remains is the model error of a finite stretching stiffness, measured against the refined shooting solution of the inextensible rod.\n"
    )?;
    s += &stiffness_table(&d)?;
    Ok(s)
}
