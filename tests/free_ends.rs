//! Pinned and free ends: a cantilever under its weight, Greenhill's heavy
//! column, a naturally curved rod at rest, a clamped-pinned heavy rod against
//! shooting (each with its order in N), the dof numbering, and the scene
//! errors of combinations that have no isolated equilibrium. Derivatives by
//! finite differences are in energy_derivatives.rs.

use knotrod::model::rod::{EndKind, Ends};
use knotrod::model::shooting::ShootingSolution;
use knotrod::report::analytic::{
    cantilever_tip_deflection, free_semicircle, heavy_column_constant, heavy_column_weight,
};
use knotrod::scene::Scene;
use knotrod::solve::continuum::shooting::refine_shooting_loaded;
use knotrod::study::start::solve_scene;
use nalgebra::Vector3;

fn order(coarse: f64, fine: f64) -> f64 {
    (coarse / fine).log2()
}

/// Errors at N, 2N, 4N falling at second order (observed order within 0.2).
fn assert_second_order(errors: &[f64]) {
    for k in 0..errors.len() - 1 {
        let p = order(errors[k], errors[k + 1]);
        assert!(p > 1.8 && p < 2.2, "{errors:?}: order {p}");
    }
}

#[test]
fn a_cantilever_under_its_weight_deflects_by_w_over_8_at_second_order() {
    let w = 1e-3;
    let errors: Vec<f64> = [25, 50, 100]
        .into_iter()
        .map(|n| (cantilever_tip_deflection(n, w).unwrap() / (w / 8.0) - 1.0).abs())
        .collect();
    eprintln!("cantilever tip / (w/8) − 1, N = 25, 50, 100: {errors:?}");
    assert_second_order(&errors);
    assert!(errors[2] < 2e-4, "{errors:?}");
}

#[test]
fn greenhills_heavy_column_buckles_at_7_8373_at_second_order() {
    // the classical first zero for the clamped-free heavy column,
    // w L³/EI = 7.837 (Greenhill 1881; Timoshenko & Gere, Theory of Elastic
    // Stability, 2nd ed., §2.13: (q l³/EI)_cr = 7.837), here from the
    // continuum equation θ'' + w (1 − s) θ = 0 to more digits
    let exact = heavy_column_constant().unwrap();
    assert!((exact - 7.8373).abs() < 1e-4, "{exact}");
    let loads: Vec<f64> = [50, 100, 200]
        .into_iter()
        .map(|n| heavy_column_weight(n, 1e8).unwrap())
        .collect();
    let errors: Vec<f64> = loads.iter().map(|w| (w - exact).abs() / exact).collect();
    eprintln!(
        "heavy column w L³/B, N = 50, 100, 200: {loads:?} (continuum {exact}), relative errors {errors:?}"
    );
    assert_second_order(&errors);
    let richardson = (4.0 * loads[2] - loads[1]) / 3.0;
    assert!((richardson - exact).abs() < 1e-5, "{loads:?}: {richardson}");
}

#[test]
fn a_rod_of_natural_curvature_pi_with_a_free_end_rests_as_the_semicircle() {
    let runs: Vec<(f64, f64, f64)> = [25, 50, 100]
        .into_iter()
        .map(|n| free_semicircle(n).unwrap())
        .collect();
    eprintln!(
        "free semicircle û1 = π, N = 25, 50, 100: (energy, |n(0)| + |m(0)|, shape) = {runs:?}"
    );
    for (e, r, _) in &runs {
        // at rest: the free end lets every vertex take its natural strain
        assert!(*e < 1e-14 && *r < 1e-6, "{runs:?}");
    }
    assert_second_order(&runs.iter().map(|r| r.2).collect::<Vec<_>>());
    assert!(runs[2].2 < 1e-4, "{runs:?}");
}

/// A plastified rod given by its end deflection (the scene's
/// `natural_strains = { end_deflection = 0.05 }`, as the lab's strips of
/// Figure 10 were), held at one end and free at the other, rests with its
/// free end that far off the held end's tangent, at second order in N.
#[test]
fn a_plastified_rod_free_at_one_end_rests_at_its_end_deflection() {
    let offset = |n: usize| {
        let text = format!(
            "[model]\nsegments = {n}\nstretching_stiffness = 1e8\n\
             natural_strains = {{ end_deflection = 0.05 }}\n\
             [clamps]\nz_star = 1.0\nend = \"free\"\n[solver]\ngradient_tol = 1e-12\n"
        );
        let scene = Scene::parse(&text).unwrap();
        let u = scene.rod_model(None).natural_strains.at(0.0);
        assert!(
            u[0] > 0.1 && u[0] < 0.101 && u[1] == 0.0 && u[2] == 0.0,
            "{u:?}"
        );
        let eq = solve_scene(&scene, None).unwrap();
        assert!(eq.converged, "N = {n}");
        // the held end sits at the origin with its tangent along z
        let end = eq.state.end_point();
        (end.x.powi(2) + end.y.powi(2)).sqrt()
    };
    // coarse N: the discrete arc's error (~1e-7 at N = 25) stays well above
    // the solver's tolerance
    let errors: Vec<f64> = [10, 20, 40]
        .into_iter()
        .map(|n| (offset(n) - 0.05).abs())
        .collect();
    eprintln!("plastified rod's end deflection − 0.05, N = 10, 20, 40: {errors:?}");
    assert_second_order(&errors);
    assert!(errors[2] < 1e-6, "{errors:?}");
    for bad in ["0.9", "nan", "{ end_deflection = 0.05, width = 1 }"] {
        let text = if bad.starts_with('{') {
            format!("[model]\nnatural_strains = {bad}\n")
        } else {
            format!("[model]\nnatural_strains = {{ end_deflection = {bad} }}\n")
        };
        assert!(Scene::parse(&text).is_err(), "accepted {text}");
    }
    let msg = Scene::parse("[model]\nnatural_strains = { end_deflection = 0.9 }\n")
        .unwrap_err()
        .to_string();
    assert!(msg.contains("natural_strains.end_deflection"), "{msg}");
}

/// A heavy rod of K2 = 3, K3 = 2 clamped at the origin and pinned at s = 1.
fn pinned_rod(n: usize) -> String {
    format!(
        "[model]\nsegments = {n}\nK2 = 3.0\nK3 = 2.0\nstretching_stiffness = 1e8\n\
         [clamps]\nz_star = 0.8\ndelta = 0.1\nphi_over_2pi = 0.1\nend = \"pinned\"\n\
         [initial]\nbump = [-0.1, 0.0, 0.0]\n[solver]\ngradient_tol = 1e-12\n\
         [load]\nweight = 20.0\ndirection = [-1.0, 0.3, -0.5]\n"
    )
}

#[test]
fn a_clamped_pinned_heavy_rod_agrees_with_shooting_at_second_order() {
    let solve = |n: usize| {
        let scene = Scene::parse(&pinned_rod(n)).unwrap();
        let eq = solve_scene(&scene, None).unwrap();
        assert!(eq.converged, "N = {n}");
        let model = scene.rod_model(None);
        let loads = (Vector3::from(model.weight), model.natural_strains);
        (
            Vector3::from(eq.n0),
            Vector3::from(eq.m0),
            scene.clamps(),
            loads,
            eq.state,
        )
    };
    let runs: Vec<_> = [50, 100, 200].into_iter().map(solve).collect();
    let (n0, m0, clamps, loads, _) = runs[2].clone();
    assert_eq!(clamps.ends.end, EndKind::Pinned);
    // shooting with the pinned end's conditions r(1) = r*, m(1) = 0
    let (ns, ms) = refine_shooting_loaded(n0, m0, 3.0, 2.0, (loads.0, &loads.1), &clamps)
        .expect("shooting converges from the DER reactions");
    let sol = ShootingSolution::integrate_from(&clamps, ns, ms, [3.0, 2.0], loads, 20_000).unwrap();
    assert!(sol.boundary_residual(&clamps).norm() < 1e-10);
    let errors: Vec<f64> = runs
        .iter()
        .map(|(n, m, ..)| ((n - ns).norm() + (m - ms).norm()) / (ns.norm() + ms.norm()))
        .collect();
    // and the shape: the end edge turns about the pin to the continuum's t(1)
    let tangent_errors: Vec<f64> = runs
        .iter()
        .map(|(.., st)| {
            let n = st.segments();
            (knotrod::model::rod::tangent(&st.nodes, n) - sol.at(1.0).fixed_rows::<3>(9)).norm()
        })
        .collect();
    eprintln!(
        "clamped-pinned vs shooting, N = 50, 100, 200: reactions {errors:?}, end tangent {tangent_errors:?}"
    );
    for k in 0..2 {
        let p = order(errors[k], errors[k + 1]);
        assert!(p > 1.9 && p < 2.1, "{errors:?}: order {p}");
        let p = order(tangent_errors[k], tangent_errors[k + 1]);
        assert!(p > 1.8 && p < 2.2, "{tangent_errors:?}: order {p}");
    }
    assert!(errors[2] < 1e-3, "{errors:?}");
    // the pinned end carries no moment: the clamped one does
    assert!(ms.norm() > 0.1);
}

fn ends(start: EndKind, end: EndKind) -> Ends {
    Ends { start, end }
}

#[test]
fn a_clamped_clamped_dof_map_is_unchanged() {
    // the interleaved (θ_j, x_{j+1}) numbering between two clamps
    let map = knotrod::model::rod::DofMap::clamped(10);
    assert_eq!(map.len(), 4 * 10 - 7);
    assert_eq!(map.theta(1), Some(0));
    assert_eq!(map.node(2), Some(1));
    assert_eq!(map.node(9), Some(4 * 7 + 1));
    assert_eq!(map.theta(9), Some(32));
    assert_eq!(
        (map.node(1), map.node(10), map.theta(0), map.theta(10)),
        (None, None, None, None)
    );
    // a free end adds x_N, θ_N, x_{N+1} at the end of the band
    let free = knotrod::model::rod::DofMap {
        n: 10,
        ends: ends(EndKind::Clamped, EndKind::Free),
    };
    assert_eq!(free.node(10), Some(33));
    assert_eq!(free.theta(10), Some(36));
    assert_eq!(free.node(11), Some(37));
    assert_eq!(free.len(), 40);
}

/// The scene text of a rod with these `[clamps]` extras and more sections.
fn scene(clamps: &str, extra: &str) -> String {
    format!("[model]\nsegments = 20\n[clamps]\nz_star = 0.5\n{clamps}\n{extra}")
}

fn refused(text: &str, field: &str, why: &str) {
    match Scene::parse(text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.contains(field) && msg.contains(why), "{msg}");
        }
    }
}

#[test]
fn impossible_end_combinations_name_their_field_and_say_why() {
    let start = |kind: &str| format!("[clamps.start]\nkind = \"{kind}\"\n");
    refused(
        &scene(&format!("end = \"free\"\n{}", start("free")), ""),
        "clamps.end",
        "no weight",
    );
    refused(
        &scene(
            &format!("end = \"free\"\n{}", start("free")),
            "[load]\nweight = 1.0\n",
        ),
        "clamps.end",
        "nothing holds the weight",
    );
    refused(
        &scene(&format!("end = \"pinned\"\n{}", start("pinned")), ""),
        "clamps.end",
        "two pins",
    );
    refused(
        &scene(&format!("end = \"free\"\n{}", start("pinned")), ""),
        "clamps.end",
        "about the pin",
    );
    for kind in ["strip", "unbendable"] {
        refused(
            &format!(
                "[model]\nsegments = 20\nkind = \"{kind}\"\n[clamps]\nz_star = 0.5\nend = \"free\"\n"
            ),
            "model.kind",
            "kirchhoff",
        );
    }
    refused(
        &scene(
            "end = \"free\"",
            "[continuation]\nparameter = \"z_star\"\nrange = [0.0, 1.0]\n",
        ),
        "continuation.parameter",
        "free",
    );
    refused(
        &scene(
            "end = \"pinned\"",
            "[continuation]\nparameter = \"end_tilt\"\nrange = [-1.0, 1.0]\n",
        ),
        "continuation.parameter",
        "pinned",
    );
    refused(
        &scene(
            &start("free"),
            "[[loading]]\nsteps = 3\ntargets = { start_x = 0.1 }\n",
        ),
        "loading.targets",
        "free",
    );
    refused(
        &scene("end = \"free\"", "[contact]\n"),
        "contact",
        "both ends clamped",
    );
    refused(
        &scene(
            &start("pinned"),
            "[initial]\nshape = \"shooting\"\nn0 = [0.0, 0.0, 0.0]\nm0 = [0.0, 0.0, 0.0]\n",
        ),
        "initial.shape",
        "clamped s = 0",
    );
    refused(&scene("end = \"hinged\"", ""), "end", "");
    // what is possible is accepted: a moving pin, a cantilever
    Scene::parse(&scene(
        "end = \"pinned\"",
        "[continuation]\nparameter = \"z_star\"\nrange = [0.0, 1.0]\n",
    ))
    .unwrap();
    Scene::parse(&scene("end = \"free\"", "[load]\nweight = 1.0\n")).unwrap();
}

#[test]
fn a_free_end_scene_runs_with_the_rays_along_its_end_edge() {
    // a heavy cantilever bent sideways: r(1) and the s = 1 ray follow the rod
    let text = scene(
        "end = \"free\"",
        "[load]\nweight = 3.0\ndirection = [1.0, 0.0, 0.0]\n[stability]\neigenvalues = 2\n",
    );
    let eq = solve_scene(&Scene::parse(&text).unwrap(), None).unwrap();
    assert!(eq.converged && eq.stable);
    let st = &eq.state;
    let [_, up] = st.ray_directions();
    let n = st.segments();
    assert!((up - knotrod::model::rod::tangent(&st.nodes, n)).norm() < 1e-15);
    assert!(up.x > 0.1, "the end edge leans with the weight: {up:?}");
    let (points, _) = st.centreline();
    assert!((points[n + 1] - 0.5 * (st.nodes[n] + st.nodes[n + 1])).norm() < 1e-15);
    // a free end carries no load: the clamp carries all the weight
    let n0 = Vector3::from(eq.n0);
    assert!(
        (n0.norm() - 3.0).abs() < 1e-6 && (n0.x.abs() - 3.0).abs() < 1e-6,
        "n(0) = {n0:?}"
    );
    // the pencil with a massless ghost node beyond s = 1
    assert!(eq.omega_squared.len() == 2 && eq.omega_squared.iter().all(|w| *w > 0.0));
}
