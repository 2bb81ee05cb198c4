//! Contact: a clamped beam pushed onto a point obstacle (beam theory), and
//! the trefoil tied around the rays (configurations A → B → C, Figures 3-5).

use knotrod::analysis::equilibrium::Equilibrium;
use knotrod::analysis::event::{Event, EventKind};
use knotrod::scene::Scene;
use knotrod::study::start::solve_scene;

use crate::common;
use common::run;

/// A straight clamped-clamped rod (z* = 1) whose midpoint is pushed sideways
/// by `deflection` by a segment obstacle across it.
fn beam(deflection: f64, segments: usize) -> Equilibrium {
    let h = 0.005;
    let x = h - deflection;
    let scene = Scene::parse(&format!(
        "[model]\nK2 = 3.0\nK3 = 3.0\nsegments = {segments}\nrod_diameter = {h}\n\
         [clamps]\nz_star = 1.0\ndelta = 0.0\nphi_over_2pi = 0.0\n\
         [contact]\nrays = false\nself_contact = false\n\
         obstacles = [[{x}, -0.1, 0.5, {x}, 0.1, 0.5]]\n\
         [stability]\neigenvalues = 1\n"
    ))
    .unwrap();
    solve_scene(&scene, None).unwrap()
}

#[test]
fn clamped_beam_on_a_point_obstacle_has_the_beam_theory_force() {
    // midpoint deflection w under a central point load P of a clamped-clamped
    // beam: w = P L³ / (192 B); the push is along d1 = e1, i.e. bending about
    // d2, stiffness B22 = K2 B11 = 3
    for (w, n) in [(1e-4, 100), (2e-4, 100), (1e-4, 200)] {
        let e = beam(w, n);
        assert!(e.converged);
        assert_eq!(e.contacts.len(), 1, "{:?}", e.contacts);
        let c = &e.contacts[0];
        assert_eq!(c.obstacle, "obstacle_0");
        assert!((c.s - 0.5).abs() < 1e-9, "contact at s = {}", c.s);
        assert!(c.gap.abs() < 1e-9, "gap {}", c.gap);
        let expected = 192.0 * 3.0 * w;
        assert!(
            (c.force - expected).abs() < 2e-3 * expected,
            "w = {w}, N = {n}: force {} vs {expected}",
            c.force
        );
        // the rod stops at distance h from the obstacle's axis
        let mid = e.state.nodes[n / 2].x;
        assert!((mid + w).abs() < 1e-8, "midpoint at x = {mid}");
    }
}

#[test]
fn trefoil_on_the_rays_a_to_b_to_c() {
    let scene = Scene::load(std::path::Path::new("scenes/trefoil_contact_start.toml")).unwrap();
    let (eqs, events) = run(&scene);
    let h = scene.model.rod_diameter;
    // nothing ever passes through anything: knot and link's integer part kept
    for e in &eqs {
        assert!(e.converged);
        assert_eq!(e.knot_determinant, 3, "at φ/2π = {}", e.phi_over_2pi);
        assert!(
            e.min_self_distance > h * (1.0 - 1e-6),
            "self-distance {} at φ/2π = {}",
            e.min_self_distance,
            e.phi_over_2pi
        );
        // a contact presses and touches: no residue of the QP solver on an
        // open pair (a force of 3e-9 on a gap of 0.015 once was one)
        assert!(
            e.contacts
                .iter()
                .all(|c| c.force > 0.0 && c.gap.abs() < 1e-6 * h),
            "at φ/2π = {}: {:?}",
            e.phi_over_2pi,
            e.contacts
        );
    }
    // A: the generated trefoil relaxed at φ = 0: two contacts, one with each
    // ray, at s ≈ 0.17 and 0.83
    let a = &eqs[0];
    assert!(a.phi_over_2pi.abs() < 1e-12);
    assert_eq!(a.contacts.len(), 2, "{:?}", a.contacts);
    let (lo, hi) = (&a.contacts[0], &a.contacts[1]);
    assert!(
        (lo.s - 0.17).abs() < 0.02 && (hi.s - 0.83).abs() < 0.02,
        "{:?}",
        a.contacts
    );
    assert!(lo.obstacle.starts_with("ray") && hi.obstacle.starts_with("ray"));
    assert_ne!(lo.obstacle, hi.obstacle);
    assert!((a.twist + 0.07).abs() < 0.02, "Tw = {}", a.twist);
    assert!((a.link - 3.0).abs() < 0.05, "link = {}", a.link);
    // B: the contact force reaches zero at φ/2π ≈ 0.768 and the rod jumps
    let lost = events
        .iter()
        .find(|e| e.kind == EventKind::ContactLost && e.branch == 0)
        .expect("contact lost on the way up");
    assert!(
        (lost.phi_over_2pi - 0.768).abs() < 0.01,
        "B at {}",
        lost.phi_over_2pi
    );
    let jump = events
        .iter()
        .find(|e| {
            e.kind == EventKind::Jump
                && e.branch == 0
                && (e.phi_over_2pi - lost.phi_over_2pi).abs() < 1e-3
        })
        .expect("a jump at B");
    let _ = jump;
    // C: contact-free, stable, and through the walls at Figure 3's W1, W2
    // (contact-free continuation of fig3_kirchhoff at N = 100: 0.77411, 0.81862)
    let walls: Vec<f64> = events
        .iter()
        .filter(|e| e.kind == EventKind::Wall && e.branch == 0)
        .map(|e| e.phi_over_2pi)
        .collect();
    assert_eq!(walls.len(), 2, "{events:?}");
    assert!(
        (walls[0] - 0.77411).abs() < 0.005 && (walls[1] - 0.81862).abs() < 0.005,
        "{walls:?}"
    );
    let c = eqs
        .iter()
        // (the first such state is on the way up: that leg comes first)
        .find(|e| e.phi_over_2pi > walls[0] + 0.005)
        .unwrap();
    assert!(c.contacts.is_empty() && c.stable && c.good_knot);
    // back down: no jump back to B, but at S (≈ 0.751)
    let down: Vec<&Event> = events
        .iter()
        .filter(|e| e.kind == EventKind::Jump && e.branch == 1)
        .collect();
    assert_eq!(down.len(), 1, "{events:?}");
    assert!((down[0].phi_over_2pi - 0.751).abs() < 0.005);
}

#[test]
fn twisted_loop_closes_on_itself_without_passing_through() {
    // a buckled rod (z* = 0.4) twisted at one clamp: past about 1.4 turns the
    // loop it forms wraps onto itself (self-contact). As the twist grows to
    // 2.5 turns the strands press harder but never interpenetrate, and every
    // state is a stable equilibrium with the contact held
    let h = 0.005;
    let scene = Scene::parse(&format!(
        "[model]\nK2 = 1.5\nK3 = 0.7\nsegments = 60\nrod_diameter = {h}\n\
         [clamps]\nz_star = 0.4\ndelta = 0.02\nphi_over_2pi = 0.0\n\
         [initial]\nshape = \"straight\"\nbump = [0.0, 0.15, 0.0]\n\
         [contact]\nrays = false\nself_contact = true\n\
         [[loading]]\nphi_over_2pi = 2.5\nsteps = 50\n\
         [stability]\neigenvalues = 1\n"
    ))
    .unwrap();
    let (eqs, _) = run(&scene);
    assert!((eqs.last().unwrap().phi_over_2pi - 2.5).abs() < 1e-9);
    let mut first_contact = None;
    let mut last_force = 0.0;
    for e in &eqs {
        assert!(e.converged);
        assert!(e.stable, "unstable at φ/2π = {}", e.phi_over_2pi);
        assert!(
            e.min_self_distance > h * (1.0 - 1e-6),
            "self-distance {} at φ/2π = {}",
            e.min_self_distance,
            e.phi_over_2pi
        );
        let force: f64 = e.contacts.iter().map(|c| c.force).sum();
        assert!(
            e.contacts
                .iter()
                .all(|c| c.obstacle == "self" && c.force > 0.0 && c.gap > -1e-6 * h)
        );
        if first_contact.is_none() && !e.contacts.is_empty() {
            first_contact = Some(e.phi_over_2pi);
        }
        if first_contact.is_some() {
            // in contact from then on, pressing harder as the twist grows
            assert!(
                !e.contacts.is_empty(),
                "contact lost at φ/2π = {}",
                e.phi_over_2pi
            );
            assert!(
                force > last_force,
                "force {force} after {last_force} at φ/2π = {}",
                e.phi_over_2pi
            );
            assert!((e.min_self_distance - h).abs() < 1e-6 * h);
            last_force = force;
        }
    }
    let first = first_contact.expect("the loop never closed");
    assert!(
        (1.3..1.6).contains(&first),
        "first contact at φ/2π = {first}"
    );
    assert!(
        last_force
            > 5.0
                * eqs
                    .iter()
                    .find(|e| !e.contacts.is_empty())
                    .unwrap()
                    .contacts[0]
                    .force
    );
}

#[test]
fn gap_hessian_matches_finite_differences() {
    use knotrod::model::contact::gap_hessian;
    use nalgebra::Vector3;
    // interior closest points, a closest point at an end, and both at ends
    let cases = [
        [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.1, 0.0),
            Vector3::new(0.4, -0.5, 0.3),
            Vector3::new(0.6, 0.5, 0.35),
        ],
        [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(1.3, -0.5, 0.2),
            Vector3::new(1.4, 0.5, 0.25),
        ],
        [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(1.3, 0.2, 0.2),
            Vector3::new(1.8, 0.5, 0.25),
        ],
    ];
    let distance = |p: &[Vector3<f64>; 4]| {
        knotrod::geometry::distance::segment_distance(&p[0], &p[1], &p[2], &p[3]).0
    };
    let gradient = |p: &[Vector3<f64>; 4]| {
        let step = 1e-6;
        let mut g = [0.0; 12];
        for (k, gk) in g.iter_mut().enumerate() {
            let (mut a, mut b) = (*p, *p);
            a[k / 3][k % 3] += step;
            b[k / 3][k % 3] -= step;
            *gk = (distance(&a) - distance(&b)) / (2.0 * step);
        }
        g
    };
    for p in &cases {
        let h = gap_hessian(p);
        let step = 1e-4;
        for k in 0..12 {
            let (mut a, mut b) = (*p, *p);
            a[k / 3][k % 3] += step;
            b[k / 3][k % 3] -= step;
            let (ga, gb) = (gradient(&a), gradient(&b));
            for j in 0..12 {
                let fd = (ga[j] - gb[j]) / (2.0 * step);
                assert!(
                    (fd - h[k][j]).abs() < 1e-5 * (1.0 + fd.abs()),
                    "H[{k}][{j}] = {} vs {fd}",
                    h[k][j]
                );
            }
        }
        // a rigid translation changes nothing
        for (k, hk) in h.iter().enumerate() {
            let row: f64 = (0..4).map(|n| hk[3 * n]).sum();
            assert!(row.abs() < 1e-9, "translation row {k}: {row}");
        }
    }
}

#[test]
fn trefoil_generator_is_a_trefoil_or_says_why_not() {
    // at the paper's clamps the generated curve's ray closure is a trefoil
    // with link 3; where the guide curve does not close into one, a clear
    // error rather than some other knot
    let text = |z: f64| {
        format!(
            "[model]\nK2 = 3.0\nK3 = 3.0\nsegments = 60\n\
             [clamps]\nz_star = {z}\ndelta = 0.05\nphi_over_2pi = 0.0\n\
             [initial]\nshape = \"trefoil\"\n"
        )
    };
    let scene = Scene::parse(&text(0.115)).unwrap();
    let model = scene.rod_model(None);
    let state = knotrod::study::start::initial_state(&scene, &model).unwrap();
    let shape = knotrod::analysis::equilibrium::Conformation::of(&state, &scene.measure());
    assert_eq!(shape.knot.unwrap().determinant, 3);
    assert!((state.twist() + shape.writhe - 3.0).abs() < 1e-9);
    let err = solve_scene(&Scene::parse(&text(0.3)).unwrap(), None).unwrap_err();
    assert!(
        matches!(
            err,
            knotrod::StudyError::Scene(knotrod::SceneError::Invalid {
                field: "initial.shape",
                ..
            })
        ),
        "{err}"
    );
}
