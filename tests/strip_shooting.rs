//! The continuum elastic strip by shooting (paper Sec. 4: (A.1) with u2 = 0
//! and the Sadowsky law differentiated along s, (4.3)) against the DER strip:
//! a pre-curved strip (û1 ≠ 0) and the Figure 8 strip knot, each converging
//! at second order in N; bad strip fields named.

use knotrod::model::strip_shooting::{StripProblem, StripSolution, StripUnknowns};
use knotrod::scene::Scene;
use knotrod::study::start::{solve_scene, starting_equilibrium};
use nalgebra::Vector3;

/// A strip scene at N segments with clamps (z*, δ, φ/2π), `model_extra`
/// in `[model]` and `initial` as its `[initial]` section; nearly
/// inextensible (EA L²/B = 1e7) so that the stretch, which shooting does
/// not have, stays below the discretisation error.
fn strip(n: usize, model_extra: &str, clamps: [f64; 3], initial: &str) -> String {
    let [z, d, p] = clamps;
    format!(
        "[model]\nkind = \"strip\"\nsegments = {n}\nstretching_stiffness = 1e7\n{model_extra}\n\
         [clamps]\nz_star = {z}\ndelta = {d}\nphi_over_2pi = {p}\n\
         [initial]\n{initial}\n[solver]\ngradient_tol = 1e-12\n[stability]\neigenvalues = 0\n"
    )
}

/// The `[initial]` section of a strip shooting start from `p`.
fn shooting_start(p: &StripUnknowns) -> String {
    format!(
        "shape = \"shooting\"\nn0 = [{}, {}, {}]\nu1_0 = {}\nm2_0 = {}\nu3_0 = {}\n",
        p.n0[0], p.n0[1], p.n0[2], p.u1, p.m2, p.u3
    )
}

/// The strip of `model_extra` at `clamps`, reached at N = 200 by `reach`
/// (the scene text of its `[initial]`), polished by strip shooting from that
/// DER equilibrium; then the DER at N = 50, 100, 200 started from the
/// continuum solution, and the relative distance of each one's (n(0), m(0))
/// from the continuum's. Returns the errors, the continuum solution and
/// whether the DER strip at N = 200 is knotted.
fn against_strip_shooting(
    model_extra: &str,
    clamps: [f64; 3],
    reach: &str,
) -> (Vec<f64>, StripSolution, bool) {
    let scene = Scene::parse(&strip(200, model_extra, clamps, reach)).unwrap();
    let (newton, state, report) = starting_equilibrium(&scene, None).unwrap();
    assert!(report.converged);
    let model = scene.rod_model(None);
    let regularisation = match model.law {
        knotrod::model::rod::Law::Strip { regularisation } => regularisation,
        _ => unreachable!("a strip scene"),
    };
    let problem = StripProblem {
        regularisation,
        weight: Vector3::from(model.weight),
        natural: model.natural_strains.clone(),
        clamps: scene.clamps(),
        intervals: 20_000,
    };
    let start = StripUnknowns::from_der(&newton.energy, &state);
    let p = problem
        .refine(start)
        .expect("strip shooting converges from the DER equilibrium");
    let sol = problem.integrate(&p).unwrap();
    assert!(sol.boundary_residual(&scene.clamps()).norm() < 1e-10);
    let (ns, ms) = sol.reactions();
    let mut knotted = false;
    let errors: Vec<f64> = [50, 100, 200]
        .into_iter()
        .map(|n| {
            let text = strip(n, model_extra, clamps, &shooting_start(&p));
            let eq = solve_scene(&Scene::parse(&text).unwrap(), None).unwrap();
            assert!(eq.converged, "N = {n}");
            knotted = eq.knotted;
            let (n0, m0) = (Vector3::from(eq.n0), Vector3::from(eq.m0));
            ((n0 - ns).norm() + (m0 - ms).norm()) / (ns.norm() + ms.norm())
        })
        .collect();
    let orders: Vec<f64> = (0..2).map(|k| (errors[k] / errors[k + 1]).log2()).collect();
    eprintln!(
        "DER vs strip shooting ({model_extra}, clamps {clamps:?}): n(0) = {ns:?}, m(0) = {ms:?}, \
         u1(0) = {}, u3(0) = {}, Tw = {}; N = 50, 100, 200: relative errors {errors:?}, orders {orders:?}",
        p.u1,
        p.u3,
        sol.twist()
    );
    for order in &orders {
        assert!(
            (1.8..=2.2).contains(order),
            "errors {errors:?}, orders {orders:?}"
        );
    }
    (errors, sol, knotted)
}

/// The doubly covered ring unfolded to the scene's clamps (paper Sec. 6,
/// as scenes/fig8_strip.toml reaches its knots).
const DOUBLE_RING: &str = "shape = \"double_ring\"\nsteps = 20\n";

#[test]
fn a_pre_curved_strip_agrees_with_strip_shooting_at_second_order() {
    // û1 = 3: the strip knot near the double ring, its curvature u1 ≈ 4π
    // everywhere and u1 − û1 far from the law's singular zero
    let (errors, sol, _) = against_strip_shooting(
        "natural_strains = [3.0, 0.0, 0.0]",
        [0.1, 0.05, 0.95],
        DOUBLE_RING,
    );
    // the strip's error constant is larger than the rod's (|u1| ≈ 10 here)
    assert!(errors[2] < 1e-2, "{errors:?}");
    // the natural curvature matters: the straight strip's answer is far away
    let (_, straight, _) = against_strip_shooting("", [0.1, 0.05, 0.95], DOUBLE_RING);
    let ((n, m), (ns, ms)) = (sol.reactions(), straight.reactions());
    let off = ((n - ns).norm() + (m - ms).norm()) / (n.norm() + m.norm());
    // (by 0.17, sixty times the N = 200 error)
    assert!(off > 30.0 * errors[2], "û1 changes n(0), m(0) by {off}");
}

#[test]
fn the_figure_8_strip_knot_agrees_with_strip_shooting_at_second_order() {
    // z* = 0.215, δ = 0.05, φ/2π = 0.94 (Fig. 8, right)
    // z* = 0.215, δ = 0.05, φ/2π = 0.94 (Fig. 8, right): the knot
    let (errors, _, knotted) = against_strip_shooting("", [0.215, 0.05, 0.94], DOUBLE_RING);
    assert!(knotted, "the DER strip is not knotted");
    assert!(errors[2] < 1e-2, "{errors:?}");
}

#[test]
fn bad_strip_fields_and_tables_name_their_field() {
    let at = |model: &str, initial: &str| strip(20, model, [0.1, 0.05, 0.95], initial);
    let shooting =
        "shape = \"shooting\"\nn0 = [0.0, 0.0, 0.0]\nu1_0 = 12.0\nm2_0 = 0.0\nu3_0 = 0.0\n";
    for (text, field) in [
        // the strip's unknowns
        (
            at(
                "",
                "shape = \"shooting\"\nn0 = [0.0, 0.0, 0.0]\nm2_0 = 0.0\nu3_0 = 0.0\n",
            ),
            "initial.u1_0",
        ),
        (
            at(
                "",
                "shape = \"shooting\"\nn0 = [0.0, 0.0, 0.0]\nu1_0 = 1.0\nu3_0 = 0.0\n",
            ),
            "initial.m2_0",
        ),
        (
            at("", &shooting.replace("u3_0 = 0.0", "u3_0 = nan")),
            "initial.u3_0",
        ),
        (
            at("", &format!("{shooting}m0 = [0.0, 0.0, 0.0]\n")),
            "initial.m0",
        ),
        (at("", "u1_0 = 3.0\n"), "initial.u1_0"),
        (
            strip(20, "", [0.1, 0.05, 0.95], shooting)
                .replace("kind = \"strip\"", "kind = \"kirchhoff\""),
            "initial.u1_0",
        ),
        // natural strains of a strip: û1 only
        (
            at("natural_strains = [1.0, 0.5, 0.0]", ""),
            "model.natural_strains",
        ),
        (
            at(
                "natural_strains = [[0.0, 1.0, 0.0, 0.0], [1.0, 1.0, 0.0, 0.2]]",
                "",
            ),
            "model.natural_strains",
        ),
        // tables: sorted, covering [0, 1], finite, rows of four, two rows at least
        (
            at(
                "natural_strains = [[0.0, 1.0, 0.0, 0.0], [0.5, 1.0, 0.0, 0.0], [0.4, 1.0, 0.0, 0.0], [1.0, 1.0, 0.0, 0.0]]",
                "",
            ),
            "model.natural_strains",
        ),
        (
            at(
                "natural_strains = [[0.1, 1.0, 0.0, 0.0], [1.0, 1.0, 0.0, 0.0]]",
                "",
            ),
            "model.natural_strains",
        ),
        (
            at(
                "natural_strains = [[0.0, 1.0, 0.0, 0.0], [0.9, 1.0, 0.0, 0.0]]",
                "",
            ),
            "model.natural_strains",
        ),
        (
            at(
                "natural_strains = [[0.0, 1.0, 0.0, 0.0], [1.0, inf, 0.0, 0.0]]",
                "",
            ),
            "model.natural_strains",
        ),
        (
            at(
                "natural_strains = [[0.0, 1.0, 0.0, 0.0], [nan, 1.0, 0.0, 0.0], [1.0, 1.0, 0.0, 0.0]]",
                "",
            ),
            "model.natural_strains",
        ),
        (
            at(
                "natural_strains = [[0.0, 1.0, 0.0, 0.0], [1.0, 2e3, 0.0, 0.0]]",
                "",
            ),
            "model.natural_strains",
        ),
        (
            at(
                "natural_strains = [[0.0, 1.0, 0.0], [1.0, 1.0, 0.0, 0.0]]",
                "",
            ),
            "natural_strains",
        ),
        (
            at("natural_strains = [[0.0, 1.0, 0.0, 0.0]]", ""),
            "model.natural_strains",
        ),
        (at("natural_strains = [\"a\", 1.0]", ""), "natural_strains"),
    ] {
        let e = Scene::parse(&text).unwrap_err();
        assert!(e.to_string().contains(field), "{text}\n{e}");
    }
    // a table longer than the limit
    let rows: Vec<String> = (0..=200_000)
        .map(|k| format!("[{}, 1.0, 0.0, 0.0]", k as f64 / 200_000.0))
        .collect();
    let long = at(&format!("natural_strains = [{}]", rows.join(", ")), "");
    let e = Scene::parse(&long).unwrap_err();
    assert!(e.to_string().contains("model.natural_strains"), "{e}");
    // and good ones parse
    for model in [
        "natural_strains = [2.0, 0.0, 0.0]",
        "natural_strains = [[0.0, 2.0, 0.0, 0.0], [0.3, 1.0, 0.0, 0.0], [1.0, 3.0, 0.0, 0.0]]",
    ] {
        Scene::parse(&at(model, shooting)).unwrap();
    }
}
