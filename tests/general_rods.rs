//! General rods: the weight and natural strains. The DER against the
//! continuum solution of the same problem by shooting, with its order in N,
//! and a naturally curved ring at rest.

use knotrod::model::shooting::ShootingSolution;
use knotrod::scene::Scene;
use knotrod::solve::continuum::shooting::refine_shooting_loaded;
use knotrod::study::start::solve_scene;
use nalgebra::Vector3;

/// A rod of K2 = 3, K3 = 2 with shifted, turned clamps, N segments, and
/// `extra` scene text (its load or natural strains); nearly inextensible
/// (EA L²/B = 1e7) so that the stretch, which shooting does not have, stays
/// below the discretisation error.
fn rod(n: usize, model_extra: &str, extra: &str) -> String {
    format!(
        "[model]\nsegments = {n}\nK2 = 3.0\nK3 = 2.0\nstretching_stiffness = 1e7\n{model_extra}\n\
         [clamps]\nz_star = 0.8\ndelta = 0.1\nphi_over_2pi = 0.1\n\
         [initial]\nbump = [-0.1, 0.0, 0.0]\n[solver]\ngradient_tol = 1e-12\n{extra}"
    )
}

/// The relative distance of the DER's (n(0), m(0)) at N = 50, 100, 200 from
/// the shooting solution polished from the finest, and that solution's n(0).
fn against_shooting(model_extra: &str, extra: &str) -> (Vec<f64>, Vector3<f64>) {
    against_shooting_general(|n| rod(n, model_extra, extra))
}

/// n(0) of the plain rod (no weight, naturally straight) at N = 200.
fn plain_n0() -> Vector3<f64> {
    let scene = Scene::parse(&rod(200, "", "")).unwrap();
    Vector3::from(solve_scene(&scene, None).unwrap().n0)
}

#[test]
fn a_heavy_rod_agrees_with_shooting_at_second_order() {
    let (errors, ns) =
        against_shooting("", "[load]\nweight = 20.0\ndirection = [-1.0, 0.3, -0.5]\n");
    // the weight matters here: the answer without it is far away
    let off = (plain_n0() - ns).norm() / ns.norm();
    assert!(off > 100.0 * errors[2], "weight changes n(0) by {off}");
}

#[test]
fn a_naturally_curved_and_twisted_rod_agrees_with_shooting_at_second_order() {
    let (errors, ns) = against_shooting("natural_strains = [1.5, -0.5, 2.0]", "");
    let off = (plain_n0() - ns).norm() / ns.norm();
    assert!(
        off > 100.0 * errors[2],
        "natural strains change n(0) by {off}"
    );
}

#[test]
fn a_ring_of_natural_curvature_two_pi_rests_at_zero_energy() {
    // clamps that meet (z* = δ = φ = 0): the ring û1 = 2π closes on them
    // with its tangent back along e3, at rest; the start is the exact
    // continuum ring (n(0) = m(0) = 0 in the shooting ODE)
    let ring = |n: usize| {
        let text = format!(
            "[model]\nsegments = {n}\nK2 = 2.0\nK3 = 1.5\nnatural_strains = [6.283185307179586, 0.0, 0.0]\n\
             [clamps]\nz_star = 0.0\ndelta = 0.0\nphi_over_2pi = 0.0\n\
             [initial]\nshape = \"shooting\"\nn0 = [0.0, 0.0, 0.0]\nm0 = [0.0, 0.0, 0.0]\n\
             [solver]\ngradient_tol = 1e-12\n[stability]\neigenvalues = 2\n"
        );
        let eq = solve_scene(&Scene::parse(&text).unwrap(), None).unwrap();
        assert!(
            eq.converged && eq.stable,
            "N = {n}: {} negative",
            eq.negative_eigenvalues
        );
        let reaction = Vector3::from(eq.n0).norm() + Vector3::from(eq.m0).norm();
        (eq.energy, reaction)
    };
    let runs: Vec<(f64, f64)> = [25, 50, 100].into_iter().map(ring).collect();
    eprintln!("ring û1 = 2π, N = 25, 50, 100: (energy, |n(0)| + |m(0)|) = {runs:?}");
    for (e, r) in &runs {
        assert!(*e < 1e-3 && *r < 1e-1, "{runs:?}");
    }
    // what remains is the discretisation's, shrinking at second order
    for k in 0..2 {
        assert!(runs[k].1 / runs[k + 1].1 > 3.0, "{runs:?}");
    }
}

/// DER reactions (n(0), m(0)) at N = 50, 100, 200 of a scene against the
/// shooting solution of the same clamps polished from the finest, with K2 = 3,
/// K3 = 2; returns the relative errors.
fn against_shooting_general(scene_of: impl Fn(usize) -> String) -> (Vec<f64>, Vector3<f64>) {
    let solve = |n: usize| {
        let scene = Scene::parse(&scene_of(n)).unwrap();
        let eq = solve_scene(&scene, None).unwrap();
        assert!(eq.converged, "N = {n}");
        let model = scene.rod_model(None);
        (
            Vector3::from(eq.n0),
            Vector3::from(eq.m0),
            scene.clamps(),
            (Vector3::from(model.weight), model.natural_strains),
        )
    };
    let runs: Vec<_> = [50, 100, 200].into_iter().map(solve).collect();
    let (n0, m0, clamps, (weight, natural)) = runs[2].clone();
    let (ns, ms) = refine_shooting_loaded(n0, m0, 3.0, 2.0, (weight, &natural), &clamps)
        .expect("shooting converges from the DER reactions");
    let sol =
        ShootingSolution::integrate_from(&clamps, ns, ms, [3.0, 2.0], (weight, natural), 20_000)
            .unwrap();
    assert!(sol.boundary_residual(&clamps).norm() < 1e-10);
    let errors: Vec<f64> = runs
        .iter()
        .map(|(n, m, _, _)| ((n - ns).norm() + (m - ms).norm()) / (ns.norm() + ms.norm()))
        .collect();
    eprintln!("DER vs shooting, N = 50, 100, 200: relative errors {errors:?}");
    for k in 0..2 {
        let order = (errors[k] / errors[k + 1]).log2();
        assert!(
            order > 1.9 && order < 2.1,
            "errors {errors:?}, order {order}"
        );
    }
    assert!(errors[2] < 1e-3, "errors {errors:?}");
    (errors, ns)
}

#[test]
fn tilted_and_rotated_clamps_agree_with_shooting_at_second_order() {
    // both clamps general: the s = 0 one moved and rotated by Euler angles,
    // the s = 1 one shifted, rotated by an axis and angle, tilted and turned
    // (the validation report's case, so the test and the report agree)
    against_shooting_general(knotrod::report::validation::tilted_clamps_scene);
}

#[test]
fn a_rigidly_moved_knot_has_the_same_reactions_twist_energy_and_knot() {
    use knotrod::model::rod::{Clamps, Orientation, StartClamp};
    use nalgebra::{UnitQuaternion, Vector3};
    // Appendix D, then the same clamps moved by one rigid motion (x ↦ Q x + p)
    let paper = Scene::load(std::path::Path::new("scenes/appendix_d.toml")).unwrap();
    let mut scene = paper.clone();
    scene.model.segments = 100;
    let reference = solve_scene(&scene, None).unwrap();
    let q = UnitQuaternion::from_euler_angles(0.7, -0.4, 1.1);
    let p = Vector3::new(0.3, -0.2, 0.5);
    let c = scene.clamps();
    let end = q * c.end_point() + p;
    let mut moved = Clamps {
        z_star: end.z,
        delta: 0.0,
        phi: c.phi,
        ..c
    };
    moved.end.shift = [end.x, end.y];
    moved.end.orientation = Orientation {
        rotation: q,
        ..Orientation::default()
    };
    moved.start = StartClamp {
        position: p,
        orientation: Orientation {
            rotation: q,
            ..Orientation::default()
        },
        turn: 0.0,
    };
    let [w, x, y, z] = [q.w, q.i, q.j, q.k];
    let text = std::fs::read_to_string("scenes/appendix_d.toml").unwrap().replace(
        "[clamps]\nz_star = 0.115\ndelta = 0.05\nphi_over_2pi = 0.802\n",
        &format!(
            "[clamps]\nz_star = {}\ndelta = 0.0\nphi_over_2pi = 0.802\nend_shift = [{}, {}]\n\
             end_rotation = {{ quaternion = [{w}, {x}, {y}, {z}] }}\n\
             [clamps.start]\nposition = [{}, {}, {}]\nrotation = {{ quaternion = [{w}, {x}, {y}, {z}] }}\n",
            end.z, end.x, end.y, p.x, p.y, p.z
        ),
    );
    let mut general = Scene::parse(&text).unwrap();
    general.model.segments = 100;
    assert!(!general.clamps().is_paper());
    assert!((general.clamps().end_point() - moved.end_point()).norm() < 1e-15);
    let eq = solve_scene(&general, None).unwrap();
    assert!(eq.converged);
    let rel = |a: [f64; 3], b: [f64; 3]| {
        (Vector3::from(a) - Vector3::from(b)).norm() / Vector3::from(b).norm()
    };
    // the reactions are in the material frame at s = 0: invariant
    assert!(
        rel(eq.n0, reference.n0) < 1e-7,
        "{:?} vs {:?}",
        eq.n0,
        reference.n0
    );
    assert!(
        rel(eq.m0, reference.m0) < 1e-7,
        "{:?} vs {:?}",
        eq.m0,
        reference.m0
    );
    assert!((eq.energy - reference.energy).abs() < 1e-8 * reference.energy);
    assert!((eq.twist - reference.twist).abs() < 1e-8);
    assert!((eq.writhe - reference.writhe).abs() < 1e-6);
    assert_eq!(eq.knot_determinant, reference.knot_determinant);
    assert_eq!(eq.walled, reference.walled);
    assert_eq!(eq.negative_eigenvalues, reference.negative_eigenvalues);
}

#[test]
fn a_rod_of_natural_curvature_pi_rests_as_the_semicircle_of_its_clamps() {
    // û1 = π bends the rod about d1 = e1 into the semicircle from the origin
    // (tangent e3) to (0, −2/π, 0) (tangent −e3): clamped there, turned by π
    // about e1, it rests at zero energy and zero reactions; the start is the
    // cubic between the clamps, not the arc
    let pi = std::f64::consts::PI;
    let arc = |s: f64| Vector3::new(0.0, -(1.0 - (pi * s).cos()) / pi, (pi * s).sin() / pi);
    let run = |n: usize| {
        let text = format!(
            "[model]\nsegments = {n}\nK2 = 2.0\nK3 = 1.5\nnatural_strains = [{pi}, 0.0, 0.0]\n\
             [clamps]\nz_star = 0.0\ndelta = 0.0\nphi_over_2pi = 0.0\nend_shift = [0.0, {}]\n\
             end_rotation = {{ axis_angle = [1.0, 0.0, 0.0, {pi}] }}\n\
             [solver]\ngradient_tol = 1e-12\n[stability]\neigenvalues = 2\n",
            -2.0 / pi
        );
        let scene = Scene::parse(&text).unwrap();
        let eq = solve_scene(&scene, None).unwrap();
        assert!(eq.converged && eq.stable, "N = {n}");
        let reaction = Vector3::from(eq.n0).norm() + Vector3::from(eq.m0).norm();
        let state = &eq.state;
        let shape = (1..=n)
            .map(|i| (state.nodes[i] - arc((i as f64 - 0.5) / n as f64)).norm())
            .fold(0.0, f64::max);
        (eq.energy, reaction, shape)
    };
    let runs: Vec<(f64, f64, f64)> = [25, 50, 100].into_iter().map(run).collect();
    eprintln!("semicircle û1 = π, N = 25, 50, 100: (energy, |n(0)| + |m(0)|, shape) = {runs:?}");
    for k in 0..2 {
        let order = |a: f64, b: f64| (a / b).log2();
        assert!(order(runs[k].0, runs[k + 1].0) > 1.8, "{runs:?}");
        assert!(order(runs[k].1, runs[k + 1].1) > 1.8, "{runs:?}");
        assert!(order(runs[k].2, runs[k + 1].2) > 1.8, "{runs:?}");
    }
    assert!(
        runs[2].0 < 1e-4 && runs[2].1 < 1e-2 && runs[2].2 < 1e-4,
        "{runs:?}"
    );
}

#[test]
fn a_rod_with_a_natural_strain_table_agrees_with_shooting_at_second_order() {
    // û1(s) = 2 + s, û3(s) = 1 − s: the DER samples û at each vertex's
    // s = (i − ½)h, the shooting ODE at every integrator stage
    let table = "natural_strains = [[0.0, 2.0, 0.0, 1.0], [1.0, 3.0, 0.0, 0.0]]";
    let (errors, ns) = against_shooting(table, "");
    // the variation matters: the constant mean (2.5, 0, 0.5) is far away
    let (_, mean) = against_shooting("natural_strains = [2.5, 0.0, 0.5]", "");
    let off = (mean - ns).norm() / ns.norm();
    assert!(
        off > 100.0 * errors[2],
        "the table's slope changes n(0) by {off}"
    );
}

#[test]
fn the_appendix_d_knot_continued_in_its_weight_agrees_with_shooting_at_second_order() {
    // the knot under its own weight along −x, loaded from w = 0 to 25 in
    // steps (each predicted with the exact ∂∇E/∂w), then against shooting
    let heavy = |n: usize| {
        let text = std::fs::read_to_string("scenes/appendix_d.toml")
            .unwrap()
            .replace("segments = 200", &format!("segments = {n}"))
            .replace("rod_diameter = 0.005   # stretching stiffness 16/h² = 640000", "stretching_stiffness = 1e7")
            .replace("[solver]", "[load]\nweight = 0.0\ndirection = [-1.0, 0.0, 0.0]\n[[loading]]\ntargets = { weight = 25.0 }\nsteps = 25\n[solver]");
        let scene = Scene::parse(&text).unwrap();
        let mut last = None;
        knotrod::study::run::run_scene(
            &scene,
            None,
            &mut knotrod::study::observer::equilibria(|e| {
                last = Some(e);
                Ok(())
            }),
        )
        .unwrap();
        let last = last.unwrap();
        let w = knotrod::model::rod::Parameter::Weight.value(&last.state.clamps);
        assert!((w - 25.0).abs() < 1e-12, "the branch ends at w = {w}");
        (
            Vector3::from(last.n0),
            Vector3::from(last.m0),
            scene.clamps(),
        )
    };
    let runs: Vec<_> = [50, 100, 200].into_iter().map(heavy).collect();
    let (n0, m0, clamps) = runs[2];
    let weight = Vector3::new(-25.0, 0.0, 0.0);
    let straight = Default::default();
    let (ns, ms) = refine_shooting_loaded(n0, m0, 3.0, 3.0, (weight, &straight), &clamps)
        .expect("shooting converges from the DER reactions");
    let errors: Vec<f64> = runs
        .iter()
        .map(|(n, m, _)| ((n - ns).norm() + (m - ms).norm()) / (ns.norm() + ms.norm()))
        .collect();
    eprintln!(
        "heavy Appendix D knot (w = 25 along −x), N = 50, 100, 200: relative errors {errors:?}"
    );
    for k in 0..2 {
        let order = (errors[k] / errors[k + 1]).log2();
        assert!(
            order > 1.9 && order < 2.1,
            "errors {errors:?}, order {order}"
        );
    }
    // the weight matters: the weightless knot is far away
    let light = Scene::load(std::path::Path::new("scenes/appendix_d.toml")).unwrap();
    let n_light = Vector3::from(solve_scene(&light, None).unwrap().n0);
    let off = (n_light - ns).norm() / ns.norm();
    eprintln!("the weight changes n(0) by {off} (relative)");
    assert!(off > 10.0 * errors[2], "weight changes n(0) by {off}");
}
