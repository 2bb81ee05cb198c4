//! General rods: the weight. The DER under a body force against the
//! continuum solution of the same problem by shooting, with its order in N.

use knotrod::model::shooting::{ShootingSolution, refine_shooting_loaded};
use knotrod::scene::Scene;
use knotrod::study::start::solve_scene;
use nalgebra::Vector3;

/// A heavy anisotropic rod with shifted, turned clamps, its weight in a
/// direction of no symmetry.
fn heavy(n: usize) -> String {
    format!(
        "[model]\nsegments = {n}\nK2 = 3.0\nK3 = 2.0\n\
         [clamps]\nz_star = 0.8\ndelta = 0.1\nphi_over_2pi = 0.1\n\
         [initial]\nbump = [-0.1, 0.0, 0.0]\n[solver]\ngradient_tol = 1e-12\n\
         [load]\nweight = 20.0\ndirection = [-1.0, 0.3, -0.5]\n"
    )
}

#[test]
fn a_heavy_rod_agrees_with_shooting_at_second_order() {
    let solve = |n: usize| {
        let scene = Scene::parse(&heavy(n)).unwrap();
        let eq = solve_scene(&scene, None).unwrap();
        assert!(eq.converged);
        (
            Vector3::from(eq.n0),
            Vector3::from(eq.m0),
            scene.clamps(),
            scene.rod_model(None).weight,
        )
    };
    let runs: Vec<_> = [50, 100, 200].into_iter().map(solve).collect();
    let (n0, m0, clamps, weight) = runs[2];
    let weight = Vector3::from(weight);
    // the continuum answer, polished from the finest DER's reactions
    let (ns, ms) = refine_shooting_loaded(n0, m0, 3.0, 2.0, weight, &clamps, 20_000)
        .expect("shooting converges from the DER reactions");
    let sol = ShootingSolution::integrate_loaded(ns, ms, 3.0, 2.0, weight, 20_000);
    assert!(sol.boundary_residual(&clamps).norm() < 1e-10);
    // the weight matters here: the answer without it is far away
    let errors: Vec<f64> = runs
        .iter()
        .map(|(n, m, _, _)| ((n - ns).norm() + (m - ms).norm()) / (ns.norm() + ms.norm()))
        .collect();
    eprintln!("DER vs shooting, N = 50, 100, 200: relative errors {errors:?}");
    for k in 0..2 {
        let order = (errors[k] / errors[k + 1]).log2();
        assert!(order > 1.7, "errors {errors:?}, order {order}");
    }
    assert!(errors[2] < 1e-3, "errors {errors:?}");
    let unloaded = Scene::parse(&heavy(200).replace("weight = 20.0", "weight = 0.0")).unwrap();
    let free = solve_scene(&unloaded, None).unwrap();
    let off = (Vector3::from(free.n0) - ns).norm() / ns.norm();
    assert!(off > 100.0 * errors[2], "weight changes n(0) by {off}");
}
