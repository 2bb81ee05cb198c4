//! Continuation and quasi-static loading: folds, jumps, hysteresis, and the
//! paper's Figure 3 branch.

use knotrod::analysis::equilibrium::Equilibrium;
use knotrod::analysis::event::{Event, EventKind};
use knotrod::scene::Scene;

use crate::common;
use common::run;

/// Every state of a loading path a converged minimum; its jumps.
fn converged_minima_and_jumps<'a>(eqs: &[Equilibrium], events: &'a [Event]) -> Vec<&'a Event> {
    for e in eqs {
        assert!(
            e.converged && e.negative_eigenvalues == 0,
            "not a converged minimum at φ/2π = {}",
            e.phi_over_2pi
        );
    }
    events
        .iter()
        .filter(|e| e.kind == EventKind::Jump)
        .collect()
}

/// A paper scene at another N with extra TOML appended.
fn paper_scene(file: &str, segments: usize, extra: &str) -> Scene {
    let text = common::scene_text_at(file, segments);
    let text = text.split("[continuation]").next().unwrap().to_string();
    let mut scene = Scene::parse(&format!("{text}\n{extra}")).unwrap();
    scene.name = Some(file.into());
    scene
}

#[test]
fn rotating_the_clamp_down_past_s_jumps_and_does_not_come_back() {
    // the Appendix D knot, clamp rotated down past the subcritical pitchfork S
    // (φ/2π ≈ 0.751) and back up: one jump, and hysteresis
    let scene = paper_scene(
        "scenes/appendix_d.toml",
        100,
        "[[loading]]\nphi_over_2pi = 0.70\nsteps = 51\n[[loading]]\nphi_over_2pi = 0.802\nsteps = 50\n",
    );
    let (eqs, events) = run(&scene);
    assert_eq!(eqs.len(), 102);
    let jumps = converged_minima_and_jumps(&eqs, &events);
    assert_eq!(jumps.len(), 1, "{events:?}");
    assert_eq!(jumps[0].branch, 0, "the jump happens on the way down");
    assert!(
        (jumps[0].phi_over_2pi - 0.751).abs() < 0.005,
        "jump at {}",
        jumps[0].phi_over_2pi
    );
    // hysteresis: back at φ/2π = 0.80 the rod is not the knot it started as
    let (first, last) = (&eqs[0], eqs.last().unwrap());
    assert!((first.phi_over_2pi - last.phi_over_2pi).abs() < 1e-12);
    assert!(
        (first.link - last.link).abs() > 1.0,
        "link {} vs {}",
        first.link,
        last.link
    );
}

/// Continue the Appendix E knot (N = 100) down in φ: it meets a fold.
fn appendix_e_fold(step: f64) -> (Vec<Equilibrium>, Vec<Event>) {
    let scene = paper_scene(
        "scenes/appendix_e.toml",
        100,
        &format!(
            "[continuation]\nparameter = \"phi\"\nrange = [0.70, 0.80]\ndirection = \"down\"\nstep = {step}\nmax_points = 40\n"
        ),
    );
    run(&scene)
}

#[test]
fn continuation_locates_a_fold_and_continues_on_the_unstable_side() {
    let (points, events) = appendix_e_fold(0.005);
    let fold = events
        .iter()
        .find(|e| e.kind == EventKind::Fold)
        .expect("a fold");
    assert!(fold.detail.contains("0 → 1"), "{fold:?}");
    // the fold is the extreme φ of the branch
    let min_phi = points
        .iter()
        .map(|p| p.phi_over_2pi)
        .fold(f64::INFINITY, f64::min);
    assert!(
        fold.phi_over_2pi <= min_phi + 1e-9,
        "fold {} above a branch point at {min_phi}",
        fold.phi_over_2pi
    );
    // beyond it the branch has exactly one negative eigenvalue
    let k = points
        .iter()
        .position(|p| p.negative_eigenvalues > 0)
        .expect("unstable side reached");
    assert!(
        points[k..]
            .iter()
            .take(5)
            .all(|p| p.negative_eigenvalues == 1)
    );
    assert!(points[..k].iter().all(|p| p.negative_eigenvalues == 0));
    // located to 1e-6 in the parameter: independent of the step sequence
    let (_, again) = appendix_e_fold(0.0031);
    let fold2 = again
        .iter()
        .find(|e| e.kind == EventKind::Fold)
        .expect("fold found again");
    assert!(
        (fold.phi_over_2pi - fold2.phi_over_2pi).abs() < 1e-6,
        "{} vs {}",
        fold.phi_over_2pi,
        fold2.phi_over_2pi
    );
}

#[test]
fn figure_3_events_at_n_200() {
    let scene = paper_scene(
        "scenes/appendix_d.toml",
        200,
        "[continuation]\nparameter = \"phi\"\nrange = [0.745, 0.99]\ndirection = \"both\"\n",
    );
    let (_, events) = run(&scene);
    let find = |kind: EventKind, near: f64| {
        events
            .iter()
            .filter(|e| e.kind == kind && e.branch == 0)
            .map(|e| e.phi_over_2pi)
            .min_by(|a, b| (a - near).abs().total_cmp(&(b - near).abs()))
            .unwrap_or_else(|| panic!("no {kind} event: {events:?}"))
    };
    let (w1, w2, x, s) = (
        find(EventKind::Wall, 0.774),
        find(EventKind::Wall, 0.82),
        find(EventKind::Crossing, 0.96),
        find(EventKind::BranchPoint, 0.75),
    );
    assert!((w1 - 0.774).abs() < 0.005, "W1 at {w1}");
    assert!((w2 - 0.82).abs() < 0.01, "W2 at {w2}");
    assert!((x - 0.96).abs() < 0.01, "X at {x}");
    assert!(s < w1 && s > 0.745, "S at {s}");
    let bp = events
        .iter()
        .find(|e| e.kind == EventKind::BranchPoint)
        .unwrap();
    assert!(
        bp.detail.starts_with("negative eigenvalues 0 → 1"),
        "{bp:?}"
    );
    // every bisected event says how closely: φ/2π within the locate
    // tolerance's worth (1e-9 in arclength), a fold to second order
    for e in events.iter().filter(|e| e.kind != EventKind::End) {
        let within = e
            .located_within
            .unwrap_or_else(|| panic!("{e:?} has no bracket"));
        assert!(
            within < 1e-8,
            "{} at {} within {within:.1e}",
            e.kind,
            e.phi_over_2pi
        );
    }
}

#[test]
fn two_mirror_branches_leave_the_pitchfork() {
    let scene = paper_scene(
        "scenes/appendix_d.toml",
        60,
        "[continuation]\nparameter = \"phi\"\nrange = [0.70, 0.81]\ndirection = \"down\"\nswitch_branches = true\nmax_points = 60\n",
    );
    let (eqs, events) = run(&scene);
    assert!(
        events.iter().any(|e| e.kind == EventKind::BranchPoint),
        "{events:?}"
    );
    let branch = |b: usize| -> Vec<&Equilibrium> { eqs.iter().filter(|e| e.branch == b).collect() };
    let (b1, b2) = (branch(1), branch(2));
    assert!(
        b1.len() > 3 && b2.len() > 3,
        "bifurcating branches not followed"
    );
    // not flip-symmetric, unstable, and the two share their (φ, Tw) projection
    // (mirror images of each other under the flip)
    // (the lowest eigenvalue leaves 0 slowly: check stability farther out)
    for p in b1.iter().chain(&b2).skip(8).take(4) {
        assert!(
            p.negative_eigenvalues > 0,
            "stable point on a bifurcating branch at φ/2π = {}",
            p.phi_over_2pi
        );
    }
    assert!(b1.len() > 12 && b2.len() > 12);
    // every point of one lies on the other's polyline in the (φ/2π, Tw) plane
    let on_b1 = |q: &Equilibrium| {
        b1.windows(2)
            .map(|w| {
                let (a, b) = (
                    (w[0].phi_over_2pi, w[0].twist),
                    (w[1].phi_over_2pi, w[1].twist),
                );
                let (dx, dy) = (b.0 - a.0, b.1 - a.1);
                let t = (((q.phi_over_2pi - a.0) * dx + (q.twist - a.1) * dy)
                    / (dx * dx + dy * dy))
                    .clamp(0.0, 1.0);
                ((q.phi_over_2pi - a.0 - t * dx).powi(2) + (q.twist - a.1 - t * dy).powi(2)).sqrt()
            })
            .fold(f64::INFINITY, f64::min)
    };
    for q in b2.iter().take(12) {
        assert!(
            on_b1(q) < 1e-4,
            "({}, {}) off the mirror branch by {}",
            q.phi_over_2pi,
            q.twist,
            on_b1(q)
        );
    }
    for (p, q) in b1.iter().zip(&b2).take(12) {
        let d: f64 = p.state.largest_node_distance(&q.state);
        assert!(d > 1e-3, "the two branches coincide");
    }
}

/// The buckled strip-like rod of scenes/loading_twist_snap.toml, its clamp
/// turned up to 1.2 turns and back to 0.5 in `up` and `down` steps.
fn twist_snap(up: usize, down: usize) -> (Vec<Equilibrium>, Vec<Event>) {
    let text = std::fs::read_to_string("scenes/loading_twist_snap.toml").unwrap();
    let text = text
        .replace("steps = 60", &format!("steps = {up}"))
        .replace("steps = 35", &format!("steps = {down}"));
    let text = text.split("[output]").next().unwrap();
    run(&Scene::parse(text).unwrap())
}

#[test]
fn twisting_a_buckled_rod_snaps_at_two_different_angles() {
    let (eqs, events) = twist_snap(60, 35);
    assert_eq!(eqs.len(), 96);
    let jumps = converged_minima_and_jumps(&eqs, &events);
    assert_eq!(jumps.len(), 2, "{events:?}");
    let (up, down) = (jumps[0], jumps[1]);
    assert_eq!((up.branch, down.branch), (0, 1), "one jump each way");
    // the loop: it snaps forward near one turn and back well below that
    assert!(
        up.phi_over_2pi - down.phi_over_2pi > 0.1,
        "{} vs {}",
        up.phi_over_2pi,
        down.phi_over_2pi
    );
    // between the two, the rod is in different states going up and down
    let at = |leg: usize| {
        let (up, down) = eqs.split_at(61);
        [up, down][leg]
            .iter()
            .min_by(|a, b| {
                (a.phi_over_2pi - 0.9)
                    .abs()
                    .total_cmp(&(b.phi_over_2pi - 0.9).abs())
            })
            .unwrap()
    };
    assert!((at(0).twist - at(1).twist).abs() > 0.1);
    // jumps are located where the branch ends, not where a step overshoots
    let (_, again) = twist_snap(47, 29);
    let again: Vec<&Event> = again.iter().filter(|e| e.kind == EventKind::Jump).collect();
    assert_eq!(again.len(), 2);
    for (a, b) in [(up, again[0]), (down, again[1])] {
        assert!(
            (a.phi_over_2pi - b.phi_over_2pi).abs() < 1e-3,
            "{} vs {}",
            a.phi_over_2pi,
            b.phi_over_2pi
        );
    }
}

/// Newton at fixed clamps (the boundary walk's equilibrium solve) moved in
/// both parameters at once lands on the equilibrium that continuation in z*,
/// then in φ, reaches along another path.
#[test]
fn settling_at_new_clamps_finds_the_equilibrium_continuation_reaches() {
    use knotrod::model::rod::{Clamps, Parameter};
    use knotrod::solve::continuation::Tracer;
    use knotrod::study::run::continue_to;
    use knotrod::study::start::starting_equilibrium;
    let scene = Scene::load(std::path::Path::new("scenes/fig7_island_kirchhoff.toml")).unwrap();
    let settings = scene.continuation.as_ref().unwrap().settings();
    let (mut newton, start, _) = starting_equilibrium(&scene, Some(60)).unwrap();
    let target = Clamps::new(0.125, 0.05, 0.815);
    let by_path = {
        let s = continue_to(
            &mut newton,
            start.clone(),
            Parameter::ZStar,
            0.125,
            &settings,
        )
        .unwrap();
        continue_to(&mut newton, s, Parameter::Phi, 0.815, &settings).unwrap()
    };
    let mut tracer = Tracer::new(&mut newton, Parameter::Phi, settings);
    let settled = tracer.settle_at(&start, target).unwrap();
    assert!(settled.iterations <= 6, "{} iterations", settled.iterations);
    assert!(settled.residual <= 1e-10);
    assert_eq!(settled.state.clamps, target);
    assert_eq!(settled.negative_count, 0);
    let gap = settled.state.largest_node_distance(&by_path);
    assert!(gap < 1e-8, "nodes differ by {gap:.2e}");
    // a clamp move too far for one Newton solve is refused, not jumped
    let far = Clamps::new(0.3, 0.05, 1.1);
    assert!(tracer.settle_at(&start, far).is_err());
}

/// `continue_to` follows the branch through its turns as a branch does. The
/// Appendix E knot (N = 100, φ/2π = 0.785) followed up in φ: φ rises to a
/// symmetric branch point (0.7943), where the path turns back onto the mirror
/// branch, falls to the fold F2 (0.7843, 0 → 1 negative eigenvalues) and rises
/// again, unstable and unknotted past the crossing X. Asked for φ/2π = 0.80,
/// which the stable knot never reaches, `continue_to` must take that S-path
/// (two hairpins in φ) and end on its third leg: unstable, unknotted, with the
/// branch's twist there — not a jump across either hairpin.
#[test]
fn continue_to_turns_back_at_a_hairpin_as_a_branch_does() {
    use knotrod::analysis::equilibrium::analyse;
    use knotrod::model::rod::Parameter;
    use knotrod::solve::outcome::SolveReport;
    use knotrod::study::run::continue_to;
    use knotrod::study::start::starting_equilibrium;
    let extra = "[continuation]\nparameter = \"phi\"\nrange = [0.5, 0.805]\ndirection = \"up\"\nswitch_branches = false\nstep = 0.02\nmax_step = 0.05\n";
    let scene = paper_scene("scenes/appendix_e.toml", 100, extra);
    let (points, events) = run(&scene);
    let kinds: Vec<EventKind> = events.iter().map(|e| e.kind).collect();
    let turn = kinds.iter().position(|k| *k == EventKind::BranchPoint);
    let fold = kinds.iter().position(|k| *k == EventKind::Fold);
    assert!(
        matches!((turn, fold), (Some(t), Some(f)) if t < f),
        "the S-path: a turn, then a fold: {kinds:?}"
    );
    // the branch crosses 0.80 once, on its third leg: interpolate its twist
    let crossings: Vec<usize> = (1..points.len())
        .filter(|&k| (points[k - 1].phi_over_2pi - 0.80) * (points[k].phi_over_2pi - 0.80) <= 0.0)
        .collect();
    assert_eq!(crossings.len(), 1, "φ = 0.80 met once along the branch");
    let (a, b) = (&points[crossings[0] - 1], &points[crossings[0]]);
    let w = (0.80 - a.phi_over_2pi) / (b.phi_over_2pi - a.phi_over_2pi);
    let twist_on_branch = a.twist + w * (b.twist - a.twist);
    // continue_to from the same start, straight to 0.80
    let settings = scene.continuation.as_ref().unwrap().settings();
    let (mut newton, start, _) = starting_equilibrium(&scene, None).unwrap();
    let end = continue_to(&mut newton, start, Parameter::Phi, 0.80, &settings).unwrap();
    let report = SolveReport::of_corrector(0, 0.0, 0.0);
    let eq = analyse(&mut newton, &end, &report, &scene.measure()).unwrap();
    assert!((eq.phi_over_2pi - 0.80).abs() < 1e-12);
    assert_eq!(eq.negative_eigenvalues, 1, "the unstable third leg");
    assert!(!eq.knotted, "past the crossing X: unknotted");
    // the chord's error between branch points (steps ≤ 0.05) bounds the gap
    let chord = (b.twist - a.twist).abs();
    assert!(
        (eq.twist - twist_on_branch).abs() < 0.05 * chord.max(1e-3),
        "Tw {} vs the branch's {twist_on_branch} (chord {chord})",
        eq.twist
    );
    assert_eq!((a.negative_eigenvalues, b.negative_eigenvalues), (1, 1));
}
