//! Knot diagnostics of the paper's equilibria, self-distance against brute
//! force, and the convergence of the writhe as the closing rays grow.

use knotrod::geometry::closure::ray_closure;
use knotrod::geometry::distance::{min_self_distance, min_self_distance_brute};
use knotrod::geometry::writhe::writhe_closed;
use knotrod::scene::Scene;
use knotrod::study::start::solve_scene;
use nalgebra::Vector3;
use std::path::Path;

#[test]
fn appendix_d_is_a_good_knot_with_the_papers_link() {
    let scene = Scene::load(Path::new("scenes/appendix_d.toml")).unwrap();
    let e = solve_scene(&scene, Some(200)).unwrap();
    assert_eq!(e.knot_determinant, 3);
    assert_eq!(e.alexander, vec![1, -1, 1]);
    assert!(!e.knot_undefined && e.knotted);
    assert!((e.link - 3.802).abs() < 0.02, "link {}", e.link);
    assert!(e.walled && e.wall_distance > 0.0);
    assert!(e.min_self_distance > 0.005, "{}", e.min_self_distance);
    assert!(e.good_knot);
}

#[test]
fn the_good_knot_predicate_follows_the_scene() {
    use knotrod::analysis::class::{Clearance, GoodKnot};
    let mut scene = Scene::load(Path::new("scenes/appendix_d.toml")).unwrap();
    scene.diagnostics.knot = "4_1".into();
    let e = solve_scene(&scene, Some(100)).unwrap();
    assert!(e.walled && e.stable && !e.knotted && !e.good_knot);
    // the paper's clearance asks only that the centreline miss itself; the
    // diameter clearance asks the self-distance to exceed h
    let d = e.min_self_distance;
    let paper = GoodKnot::new("3_1", Clearance::Centreline, 2.0 * d).unwrap();
    let thick = GoodKnot::new("3_1", Clearance::Diameter, 2.0 * d).unwrap();
    let thin = GoodKnot::new("3_1", Clearance::Diameter, 0.5 * d).unwrap();
    assert!(paper.holds(true, true, true, d) && thin.holds(true, true, true, d));
    assert!(!thick.holds(true, true, true, d));
    assert!(!paper.holds(true, true, true, 0.0));
    assert!(paper.describe().contains("paper") && thick.describe().contains("h ="));
}

#[test]
fn appendix_e_is_knotted_but_not_walled() {
    let scene = Scene::load(Path::new("scenes/appendix_e.toml")).unwrap();
    let e = solve_scene(&scene, Some(200)).unwrap();
    assert_eq!(e.knot_determinant, 3);
    assert!((e.link - 3.784).abs() < 0.02, "link {}", e.link);
    assert!(!e.walled && e.wall_distance < 0.0);
    assert!(!e.good_knot);
}

#[test]
fn writhe_of_the_ray_closure_converges_as_one_over_ray_length() {
    let scene = Scene::load(Path::new("scenes/appendix_d.toml")).unwrap();
    let e = solve_scene(&scene, Some(100)).unwrap();
    let (p, _) = e.state.centreline();
    let w: Vec<f64> = [1e1, 1e2, 1e3, 1e4]
        .iter()
        .map(|&r| writhe_closed(&ray_closure(&p, -Vector3::z(), Vector3::z(), r)))
        .collect();
    for k in 1..3 {
        let ratio = (w[k] - w[k - 1]) / (w[k + 1] - w[k]);
        assert!(
            (ratio - 10.0).abs() < 1.0,
            "error ratio per decade {ratio}: {w:?}"
        );
    }
}

use crate::common;
use common::Lcg;

#[test]
fn self_distance_matches_brute_force_on_random_curves() {
    let mut rng = Lcg(3);
    for trial in 0..20 {
        let n = 50 + 40 * trial;
        // a random walk with persistence: curls back near itself often
        let mut dir = Vector3::new(1.0, 0.0, 0.0);
        let mut p = Vector3::zeros();
        let mut points = vec![p];
        for _ in 0..n {
            dir = (dir + 0.8 * Vector3::new(rng.next(), rng.next(), rng.next())).normalize();
            p += dir / n as f64;
            points.push(p);
        }
        let arc: Vec<f64> = (0..=n).map(|k| k as f64 / n as f64).collect();
        for gap in [0.02, 0.05, 0.2] {
            let fast = min_self_distance(&points, &arc, gap).unwrap();
            let brute = min_self_distance_brute(&points, &arc, gap).unwrap();
            assert!(
                (fast.distance - brute.distance).abs() < 1e-12,
                "n {n} gap {gap}: {fast:?} vs {brute:?}"
            );
            assert!(fast.s[1] - fast.s[0] >= gap - 1e-12);
        }
    }
}

#[test]
fn writhe_carried_along_a_branch_equals_the_full_writhe() {
    // Figure 3's branch at N = 100: every accepted point's writhe was carried
    // over from the previous one (Lk = n + φ/2π) unless a strand came near
    // another; recompute each from scratch and compare
    use knotrod::analysis::equilibrium::Conformation;
    let mut scene = common::scene_at("scenes/fig3_kirchhoff.toml", 100);
    if let Some(c) = scene.continuation.as_mut() {
        c.switch_branches = false;
    }
    let (eqs, _) = common::run(&scene);
    assert!(eqs.len() > 50);
    let measure = scene.measure();
    let mut largest = 0.0f64;
    for e in &eqs {
        let full = Conformation::of(&e.state, &measure);
        largest = largest.max((full.writhe - e.writhe).abs());
        assert_eq!(
            full.knot.as_ref().unwrap().determinant,
            e.knot_determinant,
            "at φ/2π = {}",
            e.phi_over_2pi
        );
    }
    // the full writhe closes the rays at length 1e6: it differs by O(1e-6)
    assert!(largest < 1e-5, "largest writhe difference {largest:e}");
    // step by step, as the branch measured them: across the crossing X the
    // writhe comes from the exact ±2 jump, and it equals the full one
    use knotrod::analysis::equilibrium::Measured;
    let (mut passages, mut jumps) = (0, 0);
    for pair in eqs.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if a.branch != b.branch || a.leg != b.leg {
            continue;
        }
        let step = Conformation::continued(&b.state, &measure, a);
        let full = Conformation::of(&b.state, &measure);
        assert!(
            (step.writhe - full.writhe).abs() < 1e-5,
            "φ/2π = {}: {:?} writhe {} vs full {}",
            b.phi_over_2pi,
            step.how,
            step.writhe,
            full.writhe
        );
        assert_eq!(
            step.knot.map(|k| k.alexander),
            full.knot.map(|k| k.alexander)
        );
        if step.how == Measured::Passage {
            passages += 1;
            jumps += usize::from((b.writhe - a.writhe).abs() > 1.0);
        }
    }
    assert!(
        passages >= 1 && jumps >= 1,
        "{passages} passages, {jumps} jumps"
    );
}
