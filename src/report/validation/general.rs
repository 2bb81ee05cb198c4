//! General rods: clamps in any frames, natural shapes and the model's scalars
//! as parameters — the DER against the continuum solution of the same
//! problem, exact solutions at rest, invariance under a rigid motion, and a
//! branch in K3 against Greenhill's load.

use super::format::order;
use crate::model::rod::{Parameter, RodState};
use crate::report::analytic::greenhill_constant;
use crate::report::error::{ReportError, Result};
use crate::scene::Scene;
use crate::solve::continuum::shooting::refine_shooting_loaded;
use crate::study::run::run_scene;
use crate::study::start::solve_scene;
use nalgebra::Vector3;
use std::f64::consts::PI;
use std::fmt::Write;
use std::path::Path;

/// The section "General rods" of the validation report.
pub fn section(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(s, "## General rods\n")?;
    s += &tilted_table()?;
    s += &semicircle_table()?;
    s += &rigid_motion_table(scenes)?;
    s += &k3_branch_table()?;
    s += &heavy_knot_table(scenes)?;
    s += &strip_weight_table(scenes)?;
    Ok(s)
}

fn failed(why: impl Into<String>) -> ReportError {
    ReportError::Failed(why.into())
}

/// The scene text of both clamps general (the s = 0 one moved, rotated by
/// Euler angles and turned; the s = 1 one shifted, rotated by an axis and
/// angle, tilted and turned), K2 = 3, K3 = 2, EA L²/B = 1e7, at N segments.
pub fn tilted_clamps_scene(n: usize) -> String {
    format!(
        "[model]\nsegments = {n}\nK2 = 3.0\nK3 = 2.0\nstretching_stiffness = 1e7\n\
         [clamps]\nz_star = 0.7\ndelta = 0.0\nphi_over_2pi = 0.15\nend_shift = [0.2, -0.1]\n\
         end_rotation = {{ axis_angle = [1.0, 1.0, 0.0, 0.3] }}\nend_tilt = 0.4\nend_tilt_azimuth = 0.7\n\
         [clamps.start]\nposition = [0.05, 0.0, -0.1]\nrotation = {{ euler_zyx = [0.3, -0.2, 0.1] }}\n\
         turn_over_2pi = 0.05\n\
         [initial]\nbump = [-0.1, 0.05, 0.0]\n[solver]\ngradient_tol = 1e-12\n"
    )
}

/// Tilted and rotated clamps: the DER's reactions against polished shooting.
fn tilted_table() -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "### Tilted and rotated clamps against shooting\n\n\
         The s = 0 clamp at (0.05, 0, −0.1) rotated by Euler angles (0.3, −0.2, 0.1) and turned by 0.05 turn; \
         the s = 1 clamp at (0.2, −0.1, 0.7), rotated by 0.3 rad about (1, 1, 0), its tangent tilted by 0.4 rad \
         towards the azimuth 0.7 rad, turned by φ/2π = 0.15; K2 = 3, K3 = 2, EA L²/B = 1e7. The reference is the \
         continuum solution by shooting from the s = 0 frame to the s = 1 frame (the adaptive DOP853 integrator to 1e-12, Newton on \
         the six end conditions to 1e-11), polished from the finest DER's reactions.\n"
    )?;
    let runs = [50, 100, 200]
        .into_iter()
        .map(|n| {
            let scene = Scene::parse(&tilted_clamps_scene(n))?;
            let eq = solve_scene(&scene, None)?;
            Ok((n, Vector3::from(eq.n0), Vector3::from(eq.m0), scene))
        })
        .collect::<Result<Vec<_>>>()?;
    let (_, n0, m0, scene) = &runs[2];
    let weight = Vector3::from(scene.rod_model(None).weight);
    let (ns, ms) = polish("tilted clamps", scene, weight, *n0, *m0)?;
    writeln!(
        s,
        "Shooting: n(0) = ({:.6}, {:.6}, {:.6}), m(0) = ({:.6}, {:.6}, {:.6}) (material frame at s = 0).\n",
        ns.x, ns.y, ns.z, ms.x, ms.y, ms.z
    )?;
    writeln!(s, "| N | ‖Δn(0)‖ + ‖Δm(0)‖, relative | p |")?;
    writeln!(s, "|---|---|---|")?;
    let mut prev = None;
    for (n, a, b, _) in &runs {
        let e = reaction_error((*a, *b), (ns, ms));
        let p = prev.map_or(String::new(), |x| order(x, e));
        writeln!(s, "| {n} | {e:.3e} | {p} |")?;
        prev = Some(e);
    }
    Ok(s)
}

/// û1 = π between the frames of its semicircle: at rest.
fn semicircle_table() -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\n### A rod of natural curvature û1 = π clamped in the frames of its semicircle\n\n\
         s = 0 clamp: identity at the origin; s = 1 clamp at (0, −2/π, 0) turned by π about e1; K2 = 2, K3 = 1.5; \
         started from the cubic between the clamps, not from the arc. The continuum answer is the semicircle \
         r(s) = (0, −(1 − cos πs)/π, sin(πs)/π) with zero energy and zero reactions.\n"
    )?;
    writeln!(
        s,
        "| N | energy | p | ‖n(0)‖ + ‖m(0)‖ | p | max node distance from the arc | p | stable |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|---|---|")?;
    let arc = |t: f64| Vector3::new(0.0, -(1.0 - (PI * t).cos()) / PI, (PI * t).sin() / PI);
    let mut prev: Option<[f64; 3]> = None;
    for n in [25, 50, 100, 200] {
        let text = format!(
            "[model]\nsegments = {n}\nK2 = 2.0\nK3 = 1.5\nnatural_strains = [{PI}, 0.0, 0.0]\n\
             [clamps]\nz_star = 0.0\ndelta = 0.0\nphi_over_2pi = 0.0\nend_shift = [0.0, {}]\n\
             end_rotation = {{ axis_angle = [1.0, 0.0, 0.0, {PI}] }}\n\
             [solver]\ngradient_tol = 1e-12\n[stability]\neigenvalues = 2\n",
            -2.0 / PI
        );
        let eq = solve_scene(&Scene::parse(&text)?, None)?;
        let reaction = Vector3::from(eq.n0).norm() + Vector3::from(eq.m0).norm();
        let shape = shape_error(&eq.state, arc);
        let cur = [eq.energy, reaction, shape];
        let p = |k: usize| prev.map_or(String::new(), |q| order(q[k], cur[k]));
        writeln!(
            s,
            "| {n} | {:.3e} | {} | {:.3e} | {} | {:.3e} | {} | {} |",
            cur[0],
            p(0),
            cur[1],
            p(1),
            cur[2],
            p(2),
            eq.stable
        )?;
        prev = Some(cur);
    }
    writeln!(
        s,
        "\nThe energy, a square of the strain error, falls at twice the order of the strains.\n"
    )?;
    Ok(s)
}

/// Largest distance of the interior nodes from the curve `r` at their arc lengths.
fn shape_error(state: &RodState, r: impl Fn(f64) -> Vector3<f64>) -> f64 {
    let n = state.segments();
    (1..=n)
        .map(|i| (state.nodes[i] - r((i as f64 - 0.5) / n as f64)).norm())
        .fold(0.0, f64::max)
}

/// Appendix D and the same clamps moved by one rigid motion.
fn rigid_motion_table(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    let text = std::fs::read_to_string(scenes.join("appendix_d.toml"))?;
    let paper = Scene::parse(&text)?;
    let c = paper.clamps();
    let q = nalgebra::UnitQuaternion::from_euler_angles(0.7, -0.4, 1.1);
    let p = Vector3::new(0.3, -0.2, 0.5);
    let end = q * c.end_point() + p;
    let [w, x, y, z] = [q.w, q.i, q.j, q.k];
    let moved = text.replace(
        "[clamps]\nz_star = 0.115\ndelta = 0.05\nphi_over_2pi = 0.802\n",
        &format!(
            "[clamps]\nz_star = {}\ndelta = 0.0\nphi_over_2pi = 0.802\nend_shift = [{}, {}]\n\
             end_rotation = {{ quaternion = [{w}, {x}, {y}, {z}] }}\n\
             [clamps.start]\nposition = [{}, {}, {}]\nrotation = {{ quaternion = [{w}, {x}, {y}, {z}] }}\n",
            end.z, end.x, end.y, p.x, p.y, p.z
        ),
    );
    let general = Scene::parse(&moved)?;
    if general.clamps().is_paper() {
        return Err(failed(
            "rigid motion: appendix_d.toml's [clamps] block was not replaced",
        ));
    }
    writeln!(
        s,
        "\n### Invariance under a rigid motion\n\n\
         Appendix D at N = 100, and the same clamps moved by x ↦ Q x + p (Q from Euler angles (1.1, −0.4, 0.7), \
         p = (0.3, −0.2, 0.5)): both solved from the shooting start, which the general scene integrates from its \
         moved s = 0 frame. The reactions are in the material frame at s = 0, so all of these are invariant.\n"
    )?;
    writeln!(
        s,
        "| quantity | paper's clamps | moved clamps | difference |"
    )?;
    writeln!(s, "|---|---|---|---|")?;
    let a = solve_scene(&paper, Some(100))?;
    let b = solve_scene(&general, Some(100))?;
    let dn = (Vector3::from(a.n0) - Vector3::from(b.n0)).norm() / Vector3::from(a.n0).norm();
    let dm = (Vector3::from(a.m0) - Vector3::from(b.m0)).norm() / Vector3::from(a.m0).norm();
    writeln!(
        s,
        "| n(0) | ({:.5}, {:.5}, {:.5}) | ({:.5}, {:.5}, {:.5}) | {dn:.1e} relative |",
        a.n0[0], a.n0[1], a.n0[2], b.n0[0], b.n0[1], b.n0[2]
    )?;
    writeln!(
        s,
        "| m(0) | ({:.5}, {:.5}, {:.5}) | ({:.5}, {:.5}, {:.5}) | {dm:.1e} relative |",
        a.m0[0], a.m0[1], a.m0[2], b.m0[0], b.m0[1], b.m0[2]
    )?;
    writeln!(
        s,
        "| energy | {:.8} | {:.8} | {:.1e} |",
        a.energy,
        b.energy,
        (a.energy - b.energy).abs()
    )?;
    writeln!(
        s,
        "| Tw | {:.8} | {:.8} | {:.1e} |",
        a.twist,
        b.twist,
        (a.twist - b.twist).abs()
    )?;
    writeln!(
        s,
        "| Wr of the ray closure | {:.8} | {:.8} | {:.1e} |",
        a.writhe,
        b.writhe,
        (a.writhe - b.writhe).abs()
    )?;
    let knot = |e: &crate::analysis::equilibrium::Equilibrium| {
        e.knot_name.clone().unwrap_or_else(|| "none".into())
    };
    writeln!(
        s,
        "| knot, walled, negative eigenvalues | {}, {}, {} | {}, {}, {} | |",
        knot(&a),
        a.walled,
        a.negative_eigenvalues,
        knot(&b),
        b.walled,
        b.negative_eigenvalues
    )?;
    Ok(s)
}

/// A branch in K3 of the straight rod twisted by a turn: Greenhill's load.
fn k3_branch_table() -> Result<String> {
    let mut s = String::new();
    let expected = greenhill_constant() / (2.0 * PI);
    writeln!(
        s,
        "\n### A branch in K3: the twisted straight rod loses stability at Greenhill's load\n\n\
         Clamps a length apart (z* = 1) turned by one turn (φ = 2π, so u3 = 2π), K2 = 1, followed up in K3 from 1 \
         (`[continuation] parameter = \"K3\"`, exact ∂∇E/∂K3); the located change of stability against \
         K3 φ = 2x₁, i.e. K3 = {expected:.6}.\n"
    )?;
    writeln!(s, "| N | K3 at the loss of stability | rel. error | p |")?;
    writeln!(s, "|---|---|---|---|")?;
    let mut prev = None;
    for n in [25, 50, 100, 200] {
        let text = format!(
            "[model]\nsegments = {n}\nK2 = 1.0\nK3 = 1.0\n\
             [clamps]\nz_star = 1.0\ndelta = 0.0\nphi_over_2pi = 1.0\n\
             [continuation]\nparameter = \"K3\"\nrange = [1.0, 2.0]\ndirection = \"up\"\nstep = 0.02\nmax_step = 0.05\n\
             [stability]\neigenvalues = 2\n"
        );
        let scene = Scene::parse(&text)?;
        let events = run_scene(&scene, None, &mut ())?;
        let k3 = events
            .iter()
            .filter(|e| e.kind == crate::analysis::event::EventKind::Stability)
            .find_map(|e| e.clamps.map(|c| Parameter::K3.value(&c)))
            .ok_or_else(|| failed(format!("K3 branch at N = {n}: no loss of stability")))?;
        let e = (k3 - expected).abs() / expected;
        let p = prev.map_or(String::new(), |x| order(x, e));
        writeln!(s, "| {n} | {k3:.6} | {e:.2e} | {p} |")?;
        prev = Some(e);
    }
    Ok(s)
}

/// The Appendix D knot loaded by its weight along −x to w = 25, against shooting.
fn heavy_knot_table(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\n### The Appendix D knot under its weight (w L³/B = 25 along −x) against shooting\n\n\
         Loaded from w = 0 in 25 steps (`[[loading]] targets = {{ weight = 25.0 }}`, each step predicted with the \
         exact ∂∇E/∂w), EA L²/B = 1e7; the reference is shooting with the weight in the force balance, polished \
         from the finest DER's reactions.\n"
    )?;
    let text = std::fs::read_to_string(scenes.join("appendix_d.toml"))?;
    let runs = [50, 100, 200]
        .into_iter()
        .map(|n| {
            let t = text
                .replace("segments = 200", &format!("segments = {n}"))
                .replace("rod_diameter = 0.005", "stretching_stiffness = 1e7 #")
                .replace(
                    "[solver]",
                    "[load]\nweight = 0.0\ndirection = [-1.0, 0.0, 0.0]\n\
                     [[loading]]\ntargets = { weight = 25.0 }\nsteps = 25\n[solver]",
                );
            let scene = Scene::parse(&t)?;
            let mut last = None;
            run_scene(
                &scene,
                None,
                &mut crate::study::observer::equilibria(|e| {
                    last = Some(e);
                    Ok(())
                }),
            )?;
            let last = last.ok_or_else(|| failed("heavy knot: no equilibrium"))?;
            Ok((n, last, scene))
        })
        .collect::<Result<Vec<_>>>()?;
    let (_, last, scene) = &runs[2];
    let weight = Vector3::new(-25.0, 0.0, 0.0);
    let (n0, m0) = (Vector3::from(last.n0), Vector3::from(last.m0));
    let (ns, ms) = polish("heavy knot", scene, weight, n0, m0)?;
    writeln!(
        s,
        "Shooting: n(0) = ({:.5}, {:.5}, {:.5}), m(0) = ({:.5}, {:.5}, {:.5}).\n",
        ns.x, ns.y, ns.z, ms.x, ms.y, ms.z
    )?;
    writeln!(
        s,
        "| N | w reached | walled | stable | ‖Δn(0)‖ + ‖Δm(0)‖, relative | p |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|")?;
    let mut prev = None;
    for (n, e, _) in &runs {
        let w = Parameter::Weight.value(&e.state.clamps);
        let err = reaction_error((Vector3::from(e.n0), Vector3::from(e.m0)), (ns, ms));
        let p = prev.map_or(String::new(), |x| order(x, err));
        writeln!(
            s,
            "| {n} | {w} | {} | {} | {err:.3e} | {p} |",
            e.walled, e.stable
        )?;
        prev = Some(err);
    }
    Ok(s)
}

/// The Figure 10 strip knot followed in its weight from 0 to 25.
fn strip_weight_table(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    let scene = Scene::load(&scenes.join("fig10_strip_weight.toml"))?;
    writeln!(
        s,
        "\n### The Figure 10 strip knot under its weight\n\n\
         `scenes/fig10_strip_weight.toml`: the strip (Sadowsky law, N = {}) at δ = 0.10, z* = 0.17, φ/2π = 0.78 from \
         the unfolded double ring, followed in the weight w L³/B from 0 to 25 along −e3 (the lab's ≈ 25). Every \
         sixth point of the branch and its last:\n",
        scene.model.segments
    )?;
    let (eqs, events) = super::runs::run_collected(&scene)?;
    writeln!(
        s,
        "| w L³/B | n(0) | Tw | Lk | walled | stable | knot | good | self-distance |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|---|---|---|")?;
    let last = eqs.len().saturating_sub(1);
    for (_, e) in eqs
        .iter()
        .enumerate()
        .filter(|(k, _)| k % 6 == 0 || *k == last)
    {
        writeln!(
            s,
            "| {:.3} | ({:.3}, {:.3}, {:.3}) | {:.4} | {:.4} | {} | {} | {} | {} | {:.4} |",
            Parameter::Weight.value(&e.state.clamps),
            e.n0[0],
            e.n0[1],
            e.n0[2],
            e.twist,
            e.link,
            e.walled,
            e.stable,
            e.knot_name.clone().unwrap_or_else(|| "none".into()),
            e.good_knot,
            e.min_self_distance
        )?;
    }
    writeln!(
        s,
        "\nEvents on the branch: {}.\n",
        if events.is_empty() {
            "none (the knot stays walled, stable and knotted up to w = 25)".to_string()
        } else {
            events
                .iter()
                .map(|e| format!("{} ({})", e.label, e.kind))
                .collect::<Vec<_>>()
                .join(", ")
        }
    )?;
    Ok(s)
}

/// The shooting solution of `scene`'s clamps under `weight`, polished from the
/// DER's reactions (n0, m0): the reference of a table.
fn polish(
    what: &str,
    scene: &Scene,
    weight: Vector3<f64>,
    n0: Vector3<f64>,
    m0: Vector3<f64>,
) -> Result<(Vector3<f64>, Vector3<f64>)> {
    let model = scene.rod_model(None);
    refine_shooting_loaded(
        n0,
        m0,
        model.k2,
        model.k3,
        (weight, &model.natural_strains),
        &scene.clamps(),
    )
    .ok_or_else(|| failed(format!("{what}: shooting did not converge from the DER")))
}

/// ‖Δn(0)‖ + ‖Δm(0)‖ relative to the reference's ‖n(0)‖ + ‖m(0)‖.
fn reaction_error(
    (n, m): (Vector3<f64>, Vector3<f64>),
    (ns, ms): (Vector3<f64>, Vector3<f64>),
) -> f64 {
    ((n - ns).norm() + (m - ms).norm()) / (ns.norm() + ms.norm())
}
