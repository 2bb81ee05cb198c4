//! General rods: the weight and natural strains. The DER against the
//! continuum solution of the same problem by shooting, with its order in N,
//! and a naturally curved ring at rest.

use knotrod::model::shooting::{ShootingSolution, refine_shooting_loaded};
use knotrod::scene::Scene;
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
    let solve = |n: usize| {
        let scene = Scene::parse(&rod(n, model_extra, extra)).unwrap();
        let eq = solve_scene(&scene, None).unwrap();
        assert!(eq.converged);
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
    let (ns, ms) = refine_shooting_loaded(n0, m0, 3.0, 2.0, (weight, &natural), &clamps, 20_000)
        .expect("shooting converges from the DER reactions");
    let sol = ShootingSolution::integrate_loaded(ns, ms, 3.0, 2.0, weight, natural, 20_000);
    assert!(sol.boundary_residual(&clamps).norm() < 1e-10);
    let errors: Vec<f64> = runs
        .iter()
        .map(|(n, m, _, _)| ((n - ns).norm() + (m - ms).norm()) / (ns.norm() + ms.norm()))
        .collect();
    eprintln!(
        "DER vs shooting ({model_extra} {extra}), N = 50, 100, 200: relative errors {errors:?}"
    );
    for k in 0..2 {
        let order = (errors[k] / errors[k + 1]).log2();
        assert!(order > 1.9, "errors {errors:?}, order {order}");
    }
    assert!(errors[2] < 1e-3, "errors {errors:?}");
    (errors, ns)
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

#[test]
fn a_rod_with_a_natural_strain_table_agrees_with_shooting_at_second_order() {
    // û1(s) = 2 + s, û3(s) = 1 − s: the DER samples û at each vertex's
    // s = (i − ½)h, the shooting ODE at every RK4 stage
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
