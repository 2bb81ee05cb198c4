//! Finite-width strips: the ribbon's self-distance against hand-computed
//! values, its convergence to the centreline's as the width goes to zero, the
//! width 0 path unchanged, and the scene field validated.

use crate::common;

use knotrod::analysis::equilibrium::{Conformation, Measure, self_approach, walls};
use knotrod::analysis::event::{Event, EventKind};
use knotrod::geometry::distance::min_self_distance;
use knotrod::geometry::ribbon::{Piece, Ribbon, piece_distance};
use knotrod::model::rod::RodState;
use knotrod::scene::Scene;
use knotrod::study::start::starting_equilibrium;
use nalgebra::Vector3;
use std::f64::consts::PI;

fn p(x: f64, y: f64, z: f64) -> Vector3<f64> {
    Vector3::new(x, y, z)
}

/// The distance of two pieces, checked to be the same both ways round.
fn distance(a: &Piece, b: &Piece) -> f64 {
    let (ab, ba) = (piece_distance(a, b), piece_distance(b, a));
    assert_eq!(ab.distance, ba.distance);
    // the closest points are that far apart
    assert!(((ab.on_a - ab.on_b).norm() - ab.distance).abs() < 1e-15);
    ab.distance
}

/// Two straight strands of `n` segments joined by a half circle, a
/// hairpin: the first along +x from the origin to x = 1, the second back
/// along −x at `offset` from it. `d1_of` gives each segment's director from
/// its unit tangent. Returns points, arc lengths, d1.
fn hairpin(
    n: usize,
    offset: Vector3<f64>,
    d1_of: &dyn Fn(&Vector3<f64>) -> Vector3<f64>,
) -> (Vec<Vector3<f64>>, Vec<f64>, Vec<Vector3<f64>>) {
    let r = 0.5 * offset.norm();
    let across = offset / (2.0 * r);
    let mut points: Vec<Vector3<f64>> = (0..=n).map(|k| p(k as f64 / n as f64, 0.0, 0.0)).collect();
    let turn = 16;
    for k in 1..turn {
        let a = PI * k as f64 / turn as f64;
        points.push(p(1.0, 0.0, 0.0) + r * (1.0 - a.cos()) * across + r * a.sin() * Vector3::x());
    }
    points.extend(
        (0..=n)
            .rev()
            .map(|k| p(k as f64 / n as f64, 0.0, 0.0) + offset),
    );
    let mut arc = vec![0.0];
    for w in points.windows(2) {
        arc.push(arc.last().unwrap() + (w[1] - w[0]).norm());
    }
    let d1 = points
        .windows(2)
        .map(|w| d1_of(&(w[1] - w[0]).normalize()))
        .collect();
    (points, arc, d1)
}

#[test]
fn parallel_ribbons_stacked_along_their_normal_are_their_offset_apart() {
    // flat ribbons in the planes z = 0 and z = d: every width gives d
    for (w, d) in [(0.01, 0.003), (0.1, 0.02), (0.3, 0.25)] {
        let a = Piece::new(&p(0.0, 0.0, 0.0), &p(1.0, 0.0, 0.0), &Vector3::y(), w);
        let b = Piece::new(&p(0.3, 0.0, d), &p(1.3, 0.0, d), &Vector3::y(), w);
        assert!((distance(&a, &b) - d).abs() < 1e-12, "w {w} d {d}");
        // narrower on top, shifted sideways by less than the half widths
        let c = Piece::new(
            &p(0.3, 0.2 * w, d),
            &p(1.3, 0.2 * w, d),
            &Vector3::y(),
            0.5 * w,
        );
        assert!((distance(&a, &c) - d).abs() < 1e-12);
    }
    // one ribbon folded back on itself: the same d, by the tree search
    for (w, d) in [(0.01, 0.003), (0.04, 0.01)] {
        let (points, arc, d1) = hairpin(40, p(0.0, 0.0, d), &|_| Vector3::y());
        let ribbon = Ribbon {
            points: &points,
            d1: &d1,
            width: w,
        };
        let a = ribbon.min_self_distance(&arc, 0.05).unwrap();
        assert!((a.distance - d).abs() < 1e-12, "w {w}: {a:?}");
        // every facing pair is d apart: the pair found may differ
        let brute = ribbon.min_self_distance_brute(&arc, 0.05).unwrap();
        assert_eq!(a.distance, brute.distance);
    }
}

#[test]
fn parallel_ribbons_side_by_side_are_the_gap_between_their_edges_apart() {
    // in one plane, centrelines d apart: d − (w_a + w_b)/2
    for (wa, wb, d) in [(0.01, 0.01, 0.03), (0.1, 0.04, 0.2), (0.2, 0.3, 0.26)] {
        let a = Piece::new(&p(0.0, 0.0, 0.0), &p(1.0, 0.0, 0.0), &Vector3::y(), wa);
        let b = Piece::new(&p(0.5, d, 0.0), &p(1.5, d, 0.0), &Vector3::y(), wb);
        let want = d - 0.5 * (wa + wb);
        assert!((distance(&a, &b) - want).abs() < 1e-12, "{wa} {wb} {d}");
    }
    // a hairpin in its plane (d1 in the plane, normal to the tangent): d − w
    for (w, d) in [(0.01, 0.03), (0.005, 0.02)] {
        let (points, arc, d1) = hairpin(40, p(0.0, d, 0.0), &|t| Vector3::z().cross(t));
        let ribbon = Ribbon {
            points: &points,
            d1: &d1,
            width: w,
        };
        let a = ribbon.min_self_distance(&arc, 0.05).unwrap();
        assert!((a.distance - (d - w)).abs() < 1e-12, "w {w} d {d}: {a:?}");
        // the centreline is d apart, the ribbon's edges w closer
        let line = min_self_distance(&points, &arc, 0.05).unwrap();
        assert!((line.distance - d).abs() < 1e-12);
    }
}

#[test]
fn ribbons_crossing_at_an_angle_match_the_hand_computed_distance() {
    let (wa, wb, d) = (0.1, 0.06, 0.05);
    // A along x, flat (d1 = y), centred on the origin
    let flat_a = Piece::new(&p(-0.5, 0.0, 0.0), &p(0.5, 0.0, 0.0), &Vector3::y(), wa);
    // B along y at height d, flat: face over face, d
    let flat_b = Piece::new(&p(0.0, -0.5, d), &p(0.0, 0.5, d), &Vector3::x(), wb);
    assert!((distance(&flat_a, &flat_b) - d).abs() < 1e-12);
    // B standing edge-on (d1 = z): its lower edge over A's face, d − w_b/2
    let standing = Piece::new(&p(0.0, -0.5, d), &p(0.0, 0.5, d), &Vector3::z(), wb);
    assert!((distance(&flat_a, &standing) - (d - 0.5 * wb)).abs() < 1e-12);
    // both tilted about their own centrelines (by β and α), B higher at
    // h: edge over edge, h − (w_a/2)|sin β| − (w_b/2)|sin α|
    let h = 0.1;
    for (alpha, beta) in [(0.3, 0.0), (0.7, 0.4), (1.2, -0.9), (-0.5, 1.5)] {
        let a = Piece::new(
            &p(-0.5, 0.0, 0.0),
            &p(0.5, 0.0, 0.0),
            &p(0.0, f64::cos(beta), f64::sin(beta)),
            wa,
        );
        let b = Piece::new(
            &p(0.0, -0.5, h),
            &p(0.0, 0.5, h),
            &p(f64::cos(alpha), 0.0, f64::sin(alpha)),
            wb,
        );
        let want = h - 0.5 * wa * beta.sin().abs() - 0.5 * wb * alpha.sin().abs();
        assert!(
            (distance(&a, &b) - want).abs() < 1e-12,
            "α {alpha} β {beta}"
        );
    }
    // B tilted by α but starting at y0 beyond A's edge: its lowest corner
    // against A's long edge
    let alpha: f64 = 0.8;
    let tilt = p(alpha.cos(), 0.0, alpha.sin());
    for y0 in [0.06, 0.1, 0.3] {
        let b = Piece::new(&p(0.0, y0, d), &p(0.0, y0 + 0.5, d), &tilt, wb);
        let want = f64::hypot(y0 - 0.5 * wa, d - 0.5 * wb * alpha.sin());
        assert!((distance(&flat_a, &b) - want).abs() < 1e-12, "y0 {y0}");
        // and moved beyond A's end in x too: corner against corner
        let x0 = 0.55;
        let b = Piece::new(&p(x0, y0, d), &p(x0, y0 + 0.5, d), &tilt, wb);
        let dx = x0 - 0.5 * wb * alpha.cos() - 0.5;
        let want =
            (dx * dx + (y0 - 0.5 * wa).powi(2) + (d - 0.5 * wb * alpha.sin()).powi(2)).sqrt();
        assert!((distance(&flat_a, &b) - want).abs() < 1e-12, "y0 {y0}");
    }
    // tilted far enough to reach down through A: they meet
    let through = Piece::new(&p(0.0, -0.5, 0.02), &p(0.0, 0.5, 0.02), &tilt, wb);
    assert_eq!(distance(&flat_a, &through), 0.0);
    // crossing in one plane: they meet, found by edges crossing edges, whose
    // closest points carry the round-off of their solve (3e-17 here)
    let in_plane = Piece::new(&p(0.0, -0.5, 0.0), &p(0.0, 0.5, 0.0), &Vector3::x(), wb);
    assert!(distance(&flat_a, &in_plane) < 1e-16);
}

/// The Figure 8 strip's starting equilibrium (the unfolded double ring) at
/// N = 40.
fn fig8_start() -> (Scene, RodState) {
    let scene = common::scene_at("scenes/fig8_strip.toml", 40);
    let (_, state, report) = starting_equilibrium(&scene, None).unwrap();
    assert!(report.converged);
    (scene, state)
}

fn with_width(measure: &Measure, strip_width: f64) -> Measure {
    Measure {
        strip_width,
        ..measure.clone()
    }
}

#[test]
fn a_thin_ribbon_converges_to_the_centreline_linearly_in_its_width() {
    let (scene, state) = fig8_start();
    let measure = scene.measure();
    let line = self_approach(&state, &measure).unwrap();
    let gaps: Vec<f64> = [1e-2, 1e-3, 1e-4]
        .iter()
        .map(|&w| {
            let ribbon = self_approach(&state, &with_width(&measure, w)).unwrap();
            // the centreline lies in the ribbon
            assert!(ribbon.distance < line.distance);
            (line.distance - ribbon.distance) / w
        })
        .collect();
    println!("centreline {line:?}; (line − ribbon)/w at w = 1e-2, 1e-3, 1e-4: {gaps:?}");
    // line − ribbon = c w + O(w²): c at most 1 (each side's half width),
    // each estimate of c off by O(w), so ten times closer per decade of w
    // (measured: 0.8506, 0.8294667585129235, 0.8294667585129201 — between
    // 1e-3 and 1e-4 the closest points are an edge over a face, where the
    // distance is exactly linear in w)
    assert!(gaps[2] > 0.0 && gaps[2] <= 1.0);
    assert!((gaps[0] - gaps[2]).abs() < 0.05 * gaps[2], "{gaps:?}");
    assert!(
        (gaps[1] - gaps[2]).abs() <= 0.1 * (gaps[0] - gaps[2]).abs() + 1e-12,
        "{gaps:?}"
    );
    // the walls too: the ribbon reaches further than the centreline
    let centre = walls(&state, 0.0);
    for w in [1e-2, 1e-3, 1e-4] {
        let ribbon = walls(&state, w);
        assert!(ribbon.min_z <= centre.min_z && ribbon.max_z >= centre.max_z);
        assert!(centre.min_z - ribbon.min_z <= 0.5 * w);
    }
}

#[test]
fn width_zero_measures_the_centreline_exactly_as_before() {
    let (scene, state) = fig8_start();
    let measure = scene.measure();
    assert_eq!(measure.strip_width, 0.0);
    let shape = Conformation::of(&state, &measure);
    let (points, arc) = state.centreline();
    let line = min_self_distance(&points, &arc, measure.self_distance_gap);
    assert!(line.is_some());
    assert_eq!(shape.self_approach, line);
    assert_eq!(
        shape.wall_distance.to_bits(),
        state.wall_clearance().to_bits()
    );
    let w = walls(&state, 0.0);
    assert_eq!((w.min_z, w.max_z), state.z_range());
    assert_eq!(w.walled, state.walled());
    // a scene giving the width 0 explicitly reads the same
    let text = common::scene_text_at("scenes/fig8_strip.toml", 40)
        .replace("kind = \"strip\"", "kind = \"strip\"\nstrip_width = 0.0");
    let explicit = Scene::parse(&text).unwrap();
    assert_eq!(explicit.measure().strip_width, 0.0);
    assert_eq!(explicit.good_knot(), scene.good_knot());
}

#[test]
fn a_ribbon_equilibrium_reports_its_surface() {
    let text = common::scene_text_at("scenes/fig8_strip.toml", 40)
        .replace("kind = \"strip\"", "kind = \"strip\"\nstrip_width = 0.01");
    let scene = Scene::parse(&text).unwrap();
    let eq = knotrod::study::start::solve_scene(&scene, None).unwrap();
    let (_, state) = fig8_start();
    let ribbon = self_approach(&state, &scene.measure()).unwrap();
    assert_eq!(eq.min_self_distance, ribbon.distance);
    assert_eq!(eq.min_self_distance_s, ribbon.s);
    assert_eq!(eq.wall_distance, walls(&state, 0.01).clearance);
    assert!(
        scene
            .good_knot()
            .describe()
            .contains("ribbon of width 0.01")
    );
}

#[test]
fn a_bad_strip_width_names_the_field() {
    let base = common::scene_text_at("scenes/fig8_strip.toml", 40);
    for (model, why) in [
        (
            "kind = \"strip\"\nstrip_width = -0.01",
            "must be in [0, 0.5)",
        ),
        (
            "kind = \"strip\"\nstrip_width = 0.5",
            "narrow beside its length",
        ),
        ("kind = \"strip\"\nstrip_width = nan", "finite"),
        ("kind = \"strip\"\nstrip_width = inf", "finite"),
        (
            "kind = \"kirchhoff\"\nstrip_width = 0.01",
            "circular section",
        ),
    ] {
        let text = base.replace("kind = \"strip\"", model);
        let e = Scene::parse(&text).unwrap_err().to_string();
        assert!(e.contains("model.strip_width"), "{model}: {e}");
        assert!(e.contains(why), "{model}: {e}");
    }
    // an unbendable rod may have one, and a map; contact with one may not
    let unbendable = base.replace(
        "kind = \"strip\"",
        "kind = \"unbendable\"\nstrip_width = 0.01",
    );
    assert!(Scene::parse(&unbendable).is_ok());
    let wide = base.replace("kind = \"strip\"", "kind = \"strip\"\nstrip_width = 0.01");
    let map = "[map]\nparameter = \"z_star\"\nrange = [0.1, 0.2]\nlines = 3\ngrid_columns = 5\n";
    Scene::parse(&format!("{wide}\n{map}")).unwrap();
    let e = Scene::parse(&format!("{wide}\n[contact]\nrays = true\n"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("model.strip_width"), "{e}");
}

/// The Figure 8 strip's branch in φ at z* = 0.115 and N = 40, of a ribbon
/// of width `w`: its equilibria and events.
fn fig8_branch(w: f64) -> (Vec<knotrod::analysis::equilibrium::Equilibrium>, Vec<Event>) {
    let text = common::scene_text_at("scenes/fig8_strip.toml", 40)
        .replace(
            "kind = \"strip\"",
            &format!("kind = \"strip\"\nstrip_width = {w}"),
        )
        .replace(
            "values = [0.115, 0.150, 0.180, 0.200, 0.215]",
            "values = [0.115]",
        );
    common::run(&Scene::parse(&text).unwrap())
}

#[test]
fn a_branch_locates_where_the_ribbon_touches_itself() {
    // rotating the clamp up from φ/2π = 0.94, the ribbon of width 0.03
    // touches itself (between the points at 0.9470, 0.0008 apart, and
    // 0.9526, touching) well before its centreline passes through itself
    // (the knot change at 0.9775)
    let (eqs, events) = fig8_branch(0.03);
    let touch: Vec<&Event> = events
        .iter()
        .filter(|e| e.detail == "the ribbon touches itself")
        .collect();
    assert_eq!(touch.len(), 1, "{events:?}");
    let at = touch[0].phi_over_2pi;
    let before: Vec<_> = eqs
        .iter()
        .filter(|e| e.phi_over_2pi < at && e.phi_over_2pi > 0.94)
        .collect();
    assert!(!before.is_empty() && before.iter().all(|e| e.min_self_distance > 0.0));
    let after: Vec<_> = eqs
        .iter()
        .filter(|e| e.phi_over_2pi > at && e.leg == 0)
        .collect();
    assert!(!after.is_empty());
    assert!(
        after
            .iter()
            .all(|e| e.min_self_distance == 0.0 && !e.good_knot)
    );
    let passes = events
        .iter()
        .find(|e| e.kind == EventKind::KnotChange && e.phi_over_2pi > 0.94)
        .unwrap();
    assert!(at < passes.phi_over_2pi - 0.02, "{at} {passes:?}");
    // the centreline itself never touches: no such event at width 0
    let (_, events) = fig8_branch(0.0);
    assert!(events.iter().all(|e| !e.detail.contains("ribbon")));
    assert!(
        events.iter().any(|e| e.kind == EventKind::KnotChange
            && (e.phi_over_2pi - passes.phi_over_2pi).abs() < 1e-3),
        "{events:?}"
    );
}

/// The ribbon's first touch on the Figure 8 branch, located again on the
/// continuum (its edges r ± (w/2) d1 crossing): the polished φ is the same
/// from N = 40 and N = 80 to the polish's bars, and the discrete events
/// converge to it at second order in N.
#[test]
fn the_ribbon_s_touch_is_polished_on_the_continuum_the_same_from_either_n() {
    let touch_at = |n: usize| {
        let text = common::scene_text_at("scenes/fig8_strip.toml", n)
            .replace("kind = \"strip\"", "kind = \"strip\"\nstrip_width = 0.03")
            .replace(
                "values = [0.115, 0.150, 0.180, 0.200, 0.215]",
                "values = [0.115]",
            )
            .replace("max_step = 0.01", "max_step = 0.01\npolish = true");
        let (_, events) = common::run(&Scene::parse(&text).unwrap());
        let e = events
            .into_iter()
            .find(|e| e.detail == "the ribbon touches itself")
            .expect("a touch");
        let c = e.continuum.clone().unwrap_or_else(|| panic!("{e:?}"));
        (e.phi_over_2pi, c.value, c.error)
    };
    let (d40, c40, e40) = touch_at(40);
    let (d80, c80, e80) = touch_at(80);
    assert!(
        (c40 - c80).abs() < 1e-6 + 2.0 * (e40 + e80),
        "{c40} ± {e40} vs {c80} ± {e80}"
    );
    // second order in N: the error falls about fourfold (measured 3.6:
    // 2.05e-3 at N = 40, 5.6e-4 at N = 80, against 0.9458127 ± 6e-11)
    let ratio = (d40 - c40).abs() / (d80 - c80).abs();
    assert!(
        ratio > 3.0 && ratio < 5.0,
        "{d40} {d80} → {c80}: ratio {ratio}"
    );
    assert!((d40 - c40).abs() < 0.01, "{d40} → {c40}");
}

/// `[load] major_loop`: gravity across the clamps' axis, along the major
/// loop of the weightless start ("down", the photographed knot) or against
/// it ("up"), measured once and written into the scene; the weighted start
/// sags along it; a facing that is neither is refused naming the field.
#[test]
fn gravity_along_the_major_loop_is_across_the_clamps_axis_and_fixed() {
    use knotrod::study::start::{in_the_lab, major_loop_direction};
    let at = |facing: &str| {
        let text = common::scene_text_at("scenes/fig10_island_down.toml", 40).replace(
            "major_loop = \"down\"",
            &format!("major_loop = \"{facing}\""),
        );
        Scene::parse(&text).unwrap()
    };
    let (down, up) = (at("down"), at("up"));
    let lab_down = in_the_lab(&down, None).unwrap().into_owned();
    let lab_up = in_the_lab(&up, None).unwrap().into_owned();
    let g = Vector3::from(lab_down.load.direction);
    assert!((g.norm() - 1.0).abs() < 1e-12, "{g}");
    assert!((g + Vector3::from(lab_up.load.direction)).norm() < 1e-15);
    assert!(lab_down.load.major_loop.is_none());
    // across the axis through the clamps' points, towards the centroid
    let mut weightless = down.clone();
    weightless.load.weight = 0.0;
    weightless.load.major_loop = None;
    let (_, free, _) = starting_equilibrium(&weightless, None).unwrap();
    let axis = (free.end_point() - free.start_point()).normalize();
    assert!(g.dot(&axis).abs() < 1e-12, "{g} {axis}");
    assert_eq!(major_loop_direction(&free), Some(g));
    // resolved once: the resolved scene is its own lab
    assert!(matches!(
        in_the_lab(&lab_down, None).unwrap(),
        std::borrow::Cow::Borrowed(_)
    ));
    // the weighted start's centroid moves along gravity, down and up alike
    let centroid = |s: &RodState| {
        let (points, _) = s.centreline();
        points.iter().sum::<Vector3<f64>>() / points.len() as f64
    };
    for lab in [&lab_down, &lab_up] {
        let (_, heavy, _) = starting_equilibrium(lab, None).unwrap();
        let sag = centroid(&heavy) - centroid(&free);
        let along = Vector3::from(lab.load.direction);
        assert!(sag.dot(&along) > 0.5 * sag.norm(), "{sag} {along}");
    }
    let e = Scene::parse(
        &common::scene_text_at("scenes/fig10_island_down.toml", 40)
            .replace("major_loop = \"down\"", "major_loop = \"sideways\""),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("major_loop"), "{e}");
}
