//! The continuum polish of a branch's events (issue 20): the Figure 3 branch
//! from X to the fold found by a coarse discrete rod, every event located
//! again on the continuum branch, checked against AUTO-07p, against an
//! independent fixed-step integrator, against itself from another start, and
//! the discrete rod's error against it converging in N.

use knotrod::analysis::event::{Event, EventKind};
use knotrod::model::natural::NaturalStrains;
use knotrod::model::shooting::shooting_residual;
use knotrod::scene::Scene;
use knotrod::solve::continuum::Unknowns;
use knotrod::solve::continuum::branch::{BranchPoint, ContinuumBranch, PARAMETER};
use knotrod::solve::continuum::newton::central_jacobian;
use knotrod::study::run::run_scene;
use nalgebra::Vector3;
use std::path::Path;

fn polished_events(n: usize) -> (Scene, Vec<Event>) {
    let scene = Scene::load(Path::new("scenes/fig3_polished.toml")).unwrap();
    let events = run_scene(&scene, Some(n), &mut ()).unwrap();
    (scene, events)
}

/// The polished event labelled `label` (of `kind`).
fn find<'a>(events: &'a [Event], label: &str, kind: EventKind) -> &'a Event {
    events
        .iter()
        .find(|e| e.label == label && e.kind == kind)
        .unwrap_or_else(|| panic!("no {label} ({kind}) in {events:#?}"))
}

const EVENTS: [(&str, EventKind); 5] = [
    ("W2", EventKind::Wall),
    ("X", EventKind::Crossing),
    ("W1", EventKind::Wall),
    ("S", EventKind::BranchPoint),
    ("F1", EventKind::Fold),
];

/// AUTO-07p 0.9.2 (NCOL = 4, NTST = 400; benches/peers/auto07p) on the same
/// branch: its fold LP, and the walls and crossing from its collocation
/// polynomials (its branch point, located with the EPSS = 1e-3 it needs to
/// find S at all, lies 1e-6 off and is checked otherwise below).
const AUTO_07P: [(&str, f64); 4] = [
    ("W2", 0.8182439365),
    ("X", 0.9639507200),
    ("W1", 0.7738218532),
    ("F1", 0.7390451490),
];

#[test]
fn every_event_is_polished_and_agrees_with_auto_07p_and_with_itself_from_another_n() {
    let (_, coarse) = polished_events(60);
    let (_, finer) = polished_events(120);
    for (label, kind) in EVENTS {
        let a = find(&coarse, label, kind).continuum.as_ref().unwrap();
        let b = find(&finer, label, kind).continuum.as_ref().unwrap();
        // the error bars are small and cover the difference between two
        // polishes from different discrete starts
        assert!(a.error < 1e-8 && b.error < 1e-8, "{label}: {a:?} {b:?}");
        assert!(
            (a.value - b.value).abs() <= a.error + b.error + 1e-11,
            "{label}: {} ± {:.1e} vs {} ± {:.1e}",
            a.value,
            a.error,
            b.value,
            b.error
        );
        // the discrete rod converges to it, at second order for the
        // events the discrete rod locates on its own Hessian (S and the fold)
        let order = (a.discrete_minus_continuum / b.discrete_minus_continuum)
            .abs()
            .log2();
        assert!(
            b.discrete_minus_continuum.abs() < a.discrete_minus_continuum.abs() && order > 1.0,
            "{label}: discrete errors {:.3e} (N = 60), {:.3e} (N = 120)",
            a.discrete_minus_continuum,
            b.discrete_minus_continuum
        );
        if matches!(kind, EventKind::BranchPoint | EventKind::Fold) {
            assert!((1.8..2.3).contains(&order), "{label}: order {order}");
        }
        if let Some((_, auto)) = AUTO_07P.iter().find(|(l, _)| *l == label) {
            // AUTO's values carry 1e-10 digits and a few 1e-9 of its own
            // interpolation between stored solutions
            assert!(
                (a.value - auto).abs() < 2e-8,
                "{label}: {} vs AUTO-07p {auto}",
                a.value
            );
        }
    }
}

#[test]
fn the_polished_branch_point_is_where_a_central_difference_shooting_jacobian_is_singular() {
    // independent of the variational equations: the Jacobian by central
    // differences of whole integrations of the reference shooting
    let (scene, events) = polished_events(60);
    let s = find(&events, "S", EventKind::BranchPoint)
        .continuum
        .clone()
        .unwrap();
    let model = scene.rod_model(Some(60));
    let clamps = knotrod::model::rod::Clamps::new(0.115, 0.05, s.value);
    let branch =
        ContinuumBranch::new(&model, clamps, knotrod::model::rod::Parameter::Phi, 1e-12).unwrap();
    let det_at = |value: f64| {
        let mut z = BranchPoint::zeros();
        z.fixed_rows_mut::<6>(0)
            .copy_from(&Unknowns::from(s.unknowns));
        z[PARAMETER] = value;
        let z = branch.correct(z, PARAMETER).unwrap();
        let c = branch.clamps_at(value);
        let p: Unknowns = z.fixed_rows::<6>(0).into();
        central_jacobian(&p, |q| {
            shooting_residual(
                &c,
                q.fixed_rows::<3>(0).into(),
                q.fixed_rows::<3>(3).into(),
                [3.0, 3.0],
                (Vector3::zeros(), &NaturalStrains::default()),
            )
            .unwrap()
        })
        .determinant()
    };
    let (below, above) = (det_at(s.value - 2e-8), det_at(s.value + 2e-8));
    assert!(
        below * above < 0.0,
        "det {below:.3e} at S − 2e-8, {above:.3e} at S + 2e-8"
    );
    // AUTO-07p's branch point is not there: the determinant has the sign
    // it has 1e-6 above S
    let auto = det_at(0.7509637535);
    assert!(auto * above > 0.0 && auto.abs() > 10.0 * above.abs());
}

#[test]
fn the_polish_is_reported_in_the_summary_json() {
    let (_, events) = polished_events(60);
    let json = serde_json::to_string(&events).unwrap();
    let back: Vec<Event> = serde_json::from_str(&json).unwrap();
    assert_eq!(back, events);
    assert!(json.contains("\"continuum\""));
    // a branch stopped at its first fold: nothing beyond it
    let folds = events.iter().filter(|e| e.kind == EventKind::Fold).count();
    assert_eq!(folds, 1, "{events:#?}");
}

#[test]
fn the_corrector_refuses_a_point_held_just_past_a_fold_where_no_solution_exists() {
    // honest convergence: past the fold F1 there is no equilibrium at that
    // parameter, and Newton's method stalls at a small residual there; it
    // must be refused, while the branch on the near side converges
    let (scene, events) = polished_events(60);
    let f = find(&events, "F1", EventKind::Fold)
        .continuum
        .clone()
        .unwrap();
    let model = scene.rod_model(Some(60));
    let clamps = knotrod::model::rod::Clamps::new(0.115, 0.05, f.value);
    let tolerance = 1e-10;
    let branch = ContinuumBranch::new(
        &model,
        clamps,
        knotrod::model::rod::Parameter::Phi,
        tolerance,
    )
    .unwrap();
    let mut fold = BranchPoint::zeros();
    fold.fixed_rows_mut::<6>(0)
        .copy_from(&Unknowns::from(f.unknowns));
    fold[PARAMETER] = f.value;
    // the side of the fold the branch lies on: step along its tangent
    // holding the unknown it moves along fastest (the fold is flat: the
    // parameter moves by about 4e-5 σ² at a distance σ)
    let t = branch.tangent(&fold).unwrap();
    let held = (0..6)
        .max_by(|&a, &b| t[a].abs().total_cmp(&t[b].abs()))
        .unwrap();
    let near = branch.correct(fold + 1e-2 * t, held).unwrap();
    let side = (near[PARAMETER] - f.value).signum();
    assert!((near[PARAMETER] - f.value).abs() > 1e-9);
    let mut past = fold;
    past[PARAMETER] = f.value - side * 1e-7;
    match branch.correct(past, PARAMETER) {
        Err(knotrod::solve::continuum::branch::BranchError::Corrector { residual, .. }) => {
            // small enough that a floor of 1e5 tolerances took it for a solution
            assert!(residual < 1e5 * tolerance, "residual {residual:.3e}");
            assert!(residual > 1e3 * tolerance, "residual {residual:.3e}");
        }
        other => panic!("past the fold: {other:?}"),
    }
}

/// The continuum Jacobian's parameter column, for a parameter of the s = 1
/// clamp alone taken on the one end state, equals central differences of
/// whole integrations at the two parameter values; parameters that change
/// the rod's equations or its start are not taken that way.
#[test]
fn an_end_clamp_parameters_column_is_that_of_whole_integrations() {
    use knotrod::model::rod::{Clamps, Parameter};
    let scene = Scene::load(Path::new("scenes/appendix_d.toml")).unwrap();
    let model = scene.rod_model(Some(60));
    let clamps = Clamps::new(0.115, 0.05, 0.802);
    // the Appendix D knot's shooting unknowns (scenes/fig7_island_kirchhoff.toml)
    let p = Unknowns::new(-24.743, 17.772, 37.145, 7.5317, -8.71, 4.529);
    for parameter in [
        Parameter::ZStar,
        Parameter::Delta,
        Parameter::Phi,
        Parameter::EndX,
        Parameter::EndTilt,
    ] {
        assert!(parameter.moves_end_only());
        let branch = ContinuumBranch::new(&model, clamps, parameter, 1e-12).unwrap();
        let value = parameter.value(&clamps);
        let mut z = BranchPoint::zeros();
        z.fixed_rows_mut::<6>(0).copy_from(&p);
        z[PARAMETER] = value;
        let column = branch
            .linearise(&z)
            .unwrap()
            .1
            .column(PARAMETER)
            .into_owned();
        let h = 1e-6 * (1.0 + value.abs());
        let at = |v: f64| branch.problem(v).unwrap().residual(&p).unwrap();
        let whole = (at(value + h) - at(value - h)) / (2.0 * h);
        let error = (column - whole).norm();
        assert!(
            error < 1e-5 * whole.norm().max(1.0),
            "{parameter:?}: {error:.2e} of {:.2e}",
            whole.norm()
        );
    }
    for parameter in [Parameter::StartTilt, Parameter::K3, Parameter::Weight] {
        assert!(!parameter.moves_end_only(), "{parameter:?}");
    }
}
