//! Bad input, round two (issue 31): directions of any size normalised
//! without overflow, a weight that a study makes non-zero checked for its
//! direction, every angle and every varied value bounded by the one limit of
//! its parameter and the error naming the field it came from, loading steps
//! with an iteration budget, and numbers in errors printed short.

use knotrod::model::rod::Parameter;
use knotrod::scene::{MAX_ANGLE, MAX_TURNS, Scene, parameter_range};
use knotrod::study::error::describe;
use knotrod::study::start::solve_scene;

const GOOD: &str =
    "[model]\nsegments = 20\n[clamps]\nz_star = 0.9\ndelta = 0.05\nphi_over_2pi = 0.3\n";

/// A continuation to hang sweeps and maps on.
const BRANCH: &str = "[continuation]\nparameter = \"phi\"\nrange = [0.2, 0.4]\n";

fn error_of(text: &str) -> String {
    match Scene::parse(text) {
        Ok(_) => panic!("scene accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// The scene's error names `field` (in backticks, as the message does).
fn refused(text: &str, field: &str) -> String {
    let e = error_of(text);
    assert!(
        e.contains(&format!("`{field}`")),
        "wanted `{field}`:\n{text}\n{e}"
    );
    e
}

#[test]
fn a_huge_or_tiny_load_direction_is_the_direction_it_points() {
    let at =
        |d: &str| Scene::parse(&format!("{GOOD}[load]\nweight = 1.0\ndirection = {d}\n")).unwrap();
    let unit = at("[1.0, 1.0, 0.0]");
    let w = unit.rod_model(None).weight;
    assert!(
        (w[0] - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15,
        "{w:?}"
    );
    let energy = solve_scene(&unit, None).unwrap().energy;
    for d in [
        "[1e300, 1e300, 0.0]",
        "[1e308, 1e308, 0.0]",
        "[1e-300, 1e-300, 0.0]",
    ] {
        let s = at(d);
        // the overflowing norm made the weight vector 0: the weightless answer
        assert_eq!(s.rod_model(None).weight, w, "{d}");
        let e = solve_scene(&s, None).unwrap().energy;
        assert!(
            (e - energy).abs() <= 1e-12 * energy,
            "{d}: {e} against {energy}"
        );
    }
}

#[test]
fn a_huge_rotation_axis_is_the_axis_it_points() {
    let at = |axis: &str| {
        let text = GOOD.replace(
            "phi_over_2pi = 0.3\n",
            &format!("phi_over_2pi = 0.3\nend_rotation = {{ axis_angle = [{axis}, 0.05] }}\n"),
        );
        Scene::parse(&text).unwrap()
    };
    let unit = at("1.0, 0.0, 0.0");
    let r = unit.clamps().end.orientation.rotation;
    let eq = solve_scene(&unit, None).unwrap();
    for axis in ["1e300, 0.0, 0.0", "1e308, 0.0, 0.0", "1e-300, 0.0, 0.0"] {
        let s = at(axis);
        let q = s.clamps().end.orientation.rotation;
        assert!(q.angle_to(&r) < 1e-15, "{axis}: {q:?} against {r:?}");
        let other = solve_scene(&s, None).unwrap();
        assert!(
            (other.energy - eq.energy).abs() <= 1e-12 * eq.energy
                && (other.link - eq.link).abs() < 1e-9,
            "{axis}: energy {} link {} against {} {}",
            other.energy,
            other.link,
            eq.energy,
            eq.link
        );
    }
}

#[test]
fn subnormal_and_huge_vectors_that_hold_no_direction_name_their_field() {
    refused(
        &format!("{GOOD}[load]\nweight = 1.0\ndirection = [1e-310, 0.0, 0.0]\n"),
        "load.direction",
    );
    let rotation = |r: &str| {
        GOOD.replace(
            "phi_over_2pi = 0.3\n",
            &format!("phi_over_2pi = 0.3\nend_rotation = {r}\n"),
        )
    };
    for r in [
        "{ axis_angle = [1e-310, 0.0, 0.0, 0.05] }",
        "{ axis_angle = [0.0, 0.0, 0.0, 0.05] }",
        "{ quaternion = [1e300, 0.0, 0.0, 0.0] }",
        "{ quaternion = [1e308, 1e308, 0.0, 0.0] }",
        "{ quaternion = [1e-310, 0.0, 0.0, 0.0] }",
    ] {
        let e = refused(&rotation(r), "clamps.end_rotation");
        assert!(!e.contains("NaN"), "{r}: {e}");
    }
}

#[test]
fn a_zero_direction_is_refused_wherever_the_weight_can_become_non_zero() {
    let zero = "[load]\nweight = 0.0\ndirection = [0.0, 0.0, 0.0]\n";
    // weightless and never weighed: the direction is unused
    Scene::parse(&format!("{GOOD}{zero}")).unwrap();
    for study in [
        "[[loading]]\ntargets = { weight = 5.0 }\nsteps = 3\n".to_string(),
        "[continuation]\nparameter = \"weight\"\nrange = [0.0, 5.0]\n".to_string(),
        format!("{BRANCH}[sweep]\nparameter = \"weight\"\nvalues = [0.0, 1.0]\n"),
        format!("{BRANCH}[map]\nparameter = \"weight\"\nrange = [0.0, 1.0]\nlines = 2\n"),
    ] {
        let e = refused(&format!("{GOOD}{zero}{study}"), "load.direction");
        assert!(e.contains("varies the weight"), "{study}: {e}");
    }
}

#[test]
fn every_angle_is_bounded_and_named() {
    let clamps = |extra: &str| GOOD.replace("phi_over_2pi = 0.3\n", extra);
    for (extra, field) in [
        ("phi_over_2pi = 1e308\n", "clamps.phi_over_2pi"),
        ("phi_over_2pi = -1e308\n", "clamps.phi_over_2pi"),
        ("phi_over_2pi = 1e15\n", "clamps.phi_over_2pi"),
        ("end_tilt = 1e300\n", "clamps.end_tilt"),
        ("end_tilt_azimuth = -1e20\n", "clamps.end_tilt_azimuth"),
        (
            "end_rotation = { axis_angle = [1.0, 0.0, 0.0, 1e300] }\n",
            "clamps.end_rotation",
        ),
        (
            "end_rotation = { euler_zyx = [0.0, 1e17, 0.0] }\n",
            "clamps.end_rotation",
        ),
        (
            "[clamps.start]\nturn_over_2pi = -1e308\n",
            "clamps.start.turn_over_2pi",
        ),
        (
            "[clamps.start]\nturn_over_2pi = 1e15\n",
            "clamps.start.turn_over_2pi",
        ),
        ("[clamps.start]\ntilt = 1e10\n", "clamps.start.tilt"),
        (
            "[clamps.start]\ntilt_azimuth = 1e10\n",
            "clamps.start.tilt_azimuth",
        ),
        (
            "[clamps.start]\nrotation = { euler_zyx = [1e300, 0.0, 0.0] }\n",
            "clamps.start.rotation",
        ),
        (
            "[clamps.start]\nposition = [1e300, 0.0, 0.0]\n",
            "clamps.start.position",
        ),
    ] {
        refused(&clamps(extra), field);
    }
    // the limits themselves are accepted
    let edge = format!(
        "end_tilt = {MAX_ANGLE}\nend_rotation = {{ euler_zyx = [{MAX_ANGLE}, 0.0, 0.0] }}\n\
         [clamps.start]\nturn_over_2pi = {MAX_TURNS:?}\n"
    );
    Scene::parse(&clamps(&edge)).unwrap();
}

#[test]
fn every_value_a_study_gives_a_parameter_is_bounded_and_named() {
    for (study, field) in [
        (
            "[[loading]]\ntargets = { end_tilt = 1e300 }\nsteps = 3\n".to_string(),
            "loading.targets",
        ),
        (
            "[[loading]]\ntargets = { weight = 1e6 }\nsteps = 3\n".to_string(),
            "loading.targets",
        ),
        (
            "[[loading]]\nphi_over_2pi = 1e5\nsteps = 3\n".to_string(),
            "loading.phi_over_2pi",
        ),
        (
            "[continuation]\nparameter = \"phi\"\nrange = [0.2, 1e308]\n".to_string(),
            "continuation.range",
        ),
        (
            "[continuation]\nparameter = \"weight\"\nrange = [0.0, 1e5]\n".to_string(),
            "continuation.range",
        ),
        (
            format!("{BRANCH}[sweep]\nparameter = \"weight\"\nvalues = [0.0, 1e5]\n"),
            "sweep.values",
        ),
        (
            format!("{BRANCH}[sweep]\nparameter = \"end_tilt\"\nvalues = [0.0, 1e300]\n"),
            "sweep.values",
        ),
        (
            format!("{BRANCH}[map]\nparameter = \"weight\"\nrange = [0.0, 1e5]\nlines = 2\n"),
            "map.range",
        ),
        (
            format!("{BRANCH}[map]\nrange = [0.8, 0.9]\nlines = 2\ntrace_from = [0.85, 1e300]\n"),
            "map.trace_from",
        ),
        (
            format!(
                "{BRANCH}[map]\nrange = [0.8, 0.9]\nlines = 2\n[map.slices]\n\
                 parameter = \"start_turn_over_2pi\"\nvalues = [0.0, 1e15]\n"
            ),
            "map.slices.values",
        ),
        (
            format!(
                "{BRANCH}[map]\nrange = [0.8, 0.9]\nlines = 2\n[map.slices]\nvalues = [0.01, 0.02]\n\
                 start_phi_over_2pi = [0.3, 1e308]\n"
            ),
            "map.slices.start_phi_over_2pi",
        ),
    ] {
        refused(&format!("{GOOD}{study}"), field);
    }
    // û scaled by a varied natural_scale stays within the scene's own limit
    let curved = GOOD.replace(
        "segments = 20\n",
        "segments = 20\nnatural_strains = [2.0, 0.0, 0.0]\n",
    );
    refused(
        &format!("{curved}[[loading]]\ntargets = {{ natural_scale = 600.0 }}\nsteps = 3\n"),
        "loading.targets",
    );
    Scene::parse(&format!(
        "{curved}[[loading]]\ntargets = {{ natural_scale = 400.0 }}\nsteps = 3\n"
    ))
    .unwrap();
}

#[test]
fn a_parameter_has_one_limit_wherever_its_value_comes_from() {
    // the weight, a turn and a tilt: the scene's field and a loading target
    // take exactly the same values
    for (p, field, inside) in [
        (Parameter::Weight, "[load]\nweight = {v}\n", true),
        (
            Parameter::StartTurn,
            "[clamps.start]\nturn_over_2pi = {v}\n",
            true,
        ),
        (Parameter::EndTilt, "", false),
    ] {
        let (_, hi, _) = parameter_range(p, 0.0);
        for (v, ok) in [(hi, true), (hi * (1.0 + 1e-12), false)] {
            let target = format!(
                "{GOOD}[[loading]]\ntargets = {{ {} = {v:e} }}\nsteps = 1\n",
                p.name()
            );
            assert_eq!(Scene::parse(&target).is_ok(), ok, "{target}");
            let scene = if inside {
                format!("{GOOD}{}", field.replace("{v}", &format!("{v:e}")))
            } else {
                GOOD.replace(
                    "phi_over_2pi = 0.3\n",
                    &format!("phi_over_2pi = 0.3\nend_tilt = {v:e}\n"),
                )
            };
            assert_eq!(Scene::parse(&scene).is_ok(), ok, "{scene}");
        }
    }
}

#[test]
fn a_loading_step_that_runs_out_of_its_budget_says_which_step() {
    let path = "[[loading]]\nz_star = 0.5\nsteps = 2\n";
    let run = |extra: &str| {
        let scene = Scene::parse(&format!("{GOOD}{path}{extra}")).unwrap();
        knotrod::study::run::run_scene(&scene, None, &mut ())
    };
    // the default budget is ample
    run("").unwrap();
    let e = describe(&run("step_iterations = 1\n").unwrap_err());
    assert!(
        e.contains("loading leg 0, step 1") && e.contains("budget of 1 Newton iterations"),
        "{e}"
    );
    refused(
        &format!("{GOOD}{path}step_iterations = 0\n"),
        "loading.step_iterations",
    );
}

#[test]
fn numbers_in_errors_are_short() {
    for text in [
        format!("{GOOD}[diagnostics]\nray_length = 1e308\n"),
        format!("{GOOD}[contact]\nmargin = -1e-300\n"),
        format!("{GOOD}[load]\nweight = 1e300\n"),
        format!("{GOOD}[clamps.start]\nturn_over_2pi = 1e300\n"),
        format!("{GOOD}[initial]\nbump = [1e300, 0.0, 0.0]\n"),
        GOOD.replace("segments = 20\n", "segments = 20\nrod_diameter = 1e-300\n"),
        GOOD.replace("z_star = 0.9", "z_star = 1e300"),
    ] {
        let e = error_of(&text);
        let longest = e
            .split(|c: char| !c.is_ascii_digit())
            .map(str::len)
            .max()
            .unwrap_or(0);
        assert!(longest <= 17, "{text}\n{e}");
    }
    let e = error_of(&format!("{GOOD}[diagnostics]\nray_length = 1e308\n"));
    assert!(e.contains("1e308"), "{e}");
}

#[test]
fn a_contact_margin_past_a_quarter_of_the_rod_is_refused_by_name() {
    // before: every pair a constraint, minutes of progress
    let e = error_of(&format!("{GOOD}[contact]\nmargin = 10\n"));
    assert!(e.contains("contact.margin") && e.contains("0.25"), "{e}");
    Scene::parse(&format!("{GOOD}[contact]\nmargin = 0.25\n")).unwrap();
}

#[test]
fn a_double_ring_that_does_not_relax_names_the_clamps_angle() {
    // the ring traced with φ/2π = 3 of twist in it (before: "the double
    // ring: Newton did not converge in 1000 iterations")
    let text = "[model]\nsegments = 20\n[clamps]\nz_star = 0.0\ndelta = 0.0\nphi_over_2pi = 3.0\n\
                [initial]\nshape = \"double_ring\"\n";
    let scene = Scene::parse(text).unwrap();
    let e = describe(&solve_scene(&scene, None).unwrap_err());
    assert!(e.contains("clamps.phi_over_2pi = 3"), "{e}");
}
