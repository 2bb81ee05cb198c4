//! The validation report: every number in docs/validation.md is computed here
//! (`knotrod validate > docs/validation.md`), never typed by hand.

use crate::analytic::{euler_buckling_load, greenhill_constant, greenhill_twisting_moment};
use crate::equilibrium::{Equilibrium, solve_scene};
use crate::geometry::closure::ray_closure;
use crate::geometry::writhe::writhe_closed;
use crate::model::energy::RodEnergy;
use crate::model::rod::{Clamps, RodModel, RodState};
use crate::model::shooting::{ShootingSolution, refine_shooting};
use crate::scene::{InitialShape, Scene};
use crate::solve::newton::{Newton, NewtonSettings};
use crate::summary::relative_deviation;
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
        let mut newton = Newton::new(RodEnergy::new(model));
        let mut st = RodState::straight(n, Clamps::new(1.0, 0.0, f));
        newton.minimize(&mut st, &NewtonSettings::default())?;
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
fn figure_3_events(d: &Scene, n: usize) -> Result<Vec<crate::branch::Event>> {
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
    crate::run::run_scene(&scene, Some(n), &mut |_| Ok(()))
}

fn figure_3_table(d: &Scene) -> Result<String> {
    let mut s = String::new();
    let targets = [
        ("W1", "wall", 0.774, Some(0.774)),
        ("W2", "wall", 0.82, Some(0.82)),
        ("X", "crossing", 0.96, Some(0.96)),
        ("S", "branch_point", 0.75, None),
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
    let scene = Scene::load(&scenes.join("fig7_island_kirchhoff.toml"))?;
    let spec = scene.map.clone().context("fig7 scene has no [map]")?;
    let cont = scene
        .continuation
        .as_ref()
        .context("fig7 scene has no [continuation]")?;
    let cache =
        std::env::temp_dir().join(format!("knotrod-validate-island-{}", std::process::id()));
    let indices: Vec<usize> = (0..spec.lines).collect();
    let lines = crate::map::compute_lines(&scene, &spec, &indices, None, &cache, &|_| {})?;
    let _ = std::fs::remove_dir_all(&cache);
    let map = crate::map::assemble("fig7_island_kirchhoff", &spec, cont.range, lines);
    let mut s = String::new();
    writeln!(
        s,
        "Command: `cargo run --release -- map scenes/fig7_island_kirchhoff.toml` (N = {}, {} lines).\n",
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
        "\nGood knots for z* in [{:.3}, {:.3}] (lines {:.3} apart) and φ/2π in [{:.4}, {:.4}]; area {:.5} in the (z*, φ/2π) plane. Boundaries met: {}. The paper (Fig. 7-left) bounds the island by the curves S, W1, W2 and X and prints no numbers; Fig. 3 (z* = 0.115) and our Figure 3 events above place its bottom edge, and Figure 6's five branches its drift.",
        bb.get("z_star").map_or(f64::NAN, |v| v[0]),
        bb.get("z_star").map_or(f64::NAN, |v| v[1]),
        spec.value(1) - spec.value(0),
        bb.get("phi_over_2pi").map_or(f64::NAN, |v| v[0]),
        bb.get("phi_over_2pi").map_or(f64::NAN, |v| v[1]),
        map.good_area,
        map.boundaries
            .keys()
            .cloned()
            .collect::<Vec<_>>()
            .join(", ")
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
