//! Constrained laws (u2 = 0): the elastic strip and the unbendable Kirchhoff
//! rod, solved by SQP (clarabel) and continued on the KKT system; stability
//! on the constraint tangent space; the double ring's stability criterion
//! (paper eq. 2.7); Figure 8.

use knotrod::analysis::event::EventKind;
use knotrod::linalg::eigen::lowest_eigenvalues;
use knotrod::linalg::sparse::Ldlt;
use knotrod::model::energy::RodEnergy;
use knotrod::model::rod::{Law, RodModel, RodState};
use knotrod::scene::Scene;
use knotrod::solve::minimizer::Minimizer;
use knotrod::solve::outcome::SolverSettings;
use knotrod::study::start::starting_equilibrium;
use nalgebra::DMatrix;

use crate::common;
use common::{run, scene_at};

/// The double ring (z* = δ = 0, φ = 2π) of `kind` at N segments, relaxed.
fn double_ring(kind: &str, segments: usize) -> (Minimizer, RodState) {
    let scene = Scene::parse(&format!(
        "[model]\nkind = \"{kind}\"\nsegments = {segments}\n[clamps]\nz_star = 0.0\ndelta = 0.0\nphi_over_2pi = 1.0\n[initial]\nshape = \"double_ring\"\nsteps = 1\n"
    ))
    .unwrap();
    let (newton, state, report) = starting_equilibrium(&scene, None).unwrap();
    assert!(report.converged);
    (newton, state)
}

/// Gradient norm and lowest Hessian eigenvalue of `model` at `state`.
fn lowest(model: RodModel, state: &RodState) -> (f64, f64, usize) {
    let energy = RodEnergy::new(model);
    let mut g = vec![0.0; energy.map.len()];
    let mut v = vec![0.0; energy.pattern.nnz()];
    energy.hessian(state, &mut g, &mut v);
    let mut ldlt = Ldlt::new(&energy.pattern);
    let sp = lowest_eigenvalues(&energy.pattern, &v, None, 1, &mut ldlt).unwrap();
    let gnorm = g.iter().map(|x| x * x).sum::<f64>().sqrt();
    (gnorm, sp.values[0], sp.negative_count)
}

fn kirchhoff(segments: usize, k2: f64, k3: f64, law: Law) -> RodModel {
    RodModel {
        weight: [0.0; 3],
        natural_strains: Default::default(),
        segments,
        k2,
        k3,
        stretching_stiffness: 640_000.0,
        law,
    }
}

#[test]
fn double_ring_stability_follows_the_criterion() {
    // the discrete double ring has u2 = u3 = 0, so it is an equilibrium for
    // every K2, K3; its stability is decided by sqrt(k2 k3) >= 1/2 (eq. 2.7)
    let (_, ring) = double_ring("kirchhoff", 100);
    let criterion = |k2: f64, k3: f64| ((k2 - 1.0) / k2 * (k3 - 1.0) / k3).sqrt();
    for (k2, k3) in [
        (1.9, 1.9),
        (2.1, 2.1),
        (3.0, 3.0),
        (1.5, 6.0),
        (6.0, 1.5),
        (1.5, 2.0),
        (10.0, 1.5),
        (10.0, 1.25),
        (1.3, 20.0),
    ] {
        let c = criterion(k2, k3);
        assert!((c - 0.5).abs() > 0.02, "pair too close to call: {c}");
        let (gnorm, lambda, negatives) = lowest(kirchhoff(100, k2, k3, Law::Kirchhoff), &ring);
        assert!(gnorm < 1e-6, "not an equilibrium for ({k2}, {k3}): {gnorm}");
        assert_eq!(
            lambda > 0.0,
            c >= 0.5,
            "K2 = {k2}, K3 = {k3}: criterion {c:.3}, lowest eigenvalue {lambda}"
        );
        assert_eq!(negatives == 0, c >= 0.5);
    }
}

#[test]
fn constrained_double_rings_are_stable_as_the_criterion_says() {
    // the strip's double ring is stable (paper Sec. 6); the unbendable rod
    // (K2 → ∞) needs sqrt((K3 − 1)/K3) >= 1/2, i.e. K3 >= 4/3
    let (newton, ring) = double_ring("strip", 60);
    let (_, lambda, negatives) = lowest(newton.energy.model.clone(), &ring);
    assert!(lambda > 0.0 && negatives == 0, "strip ring: {lambda}");
    let (_, ring) = double_ring("unbendable", 60);
    for (k3, stable) in [(1.2, false), (1.5, true), (3.0, true)] {
        let (_, lambda, negatives) = lowest(kirchhoff(60, 3.0, k3, Law::Unbendable), &ring);
        assert_eq!(lambda > 0.0, stable, "K3 = {k3}: {lambda}");
        assert_eq!(negatives == 0, stable);
    }
}

#[test]
fn augmented_hessian_gives_the_reduced_hessian_on_the_tangent_space() {
    // dense check: the null space Z of the constraint Jacobian, the reduced
    // Hessian Zᵀ W Z (its ρ JᵀJ part vanishes there) against the lowest
    // eigenvalues of W itself, for an unstable and a stable unbendable ring
    let (_, ring) = double_ring("unbendable", 24);
    for k3 in [1.2, 2.0] {
        let energy = RodEnergy::new(kirchhoff(24, 3.0, k3, Law::Unbendable));
        let n = energy.map.len();
        let mut g = vec![0.0; n];
        let mut v = vec![0.0; energy.pattern.nnz()];
        energy.hessian(&ring, &mut g, &mut v);
        let w = energy.pattern.to_dense(&v);
        let rows = energy.constraint_rows(&ring);
        let mut j = DMatrix::zeros(rows.len(), n);
        for (r, (_, grad)) in rows.iter().enumerate() {
            for (a, d) in energy.map.vertex_stencil(r + 1).iter().enumerate() {
                if let Some(d) = d {
                    j[(r, *d)] = grad[a];
                }
            }
        }
        let rank = j.clone().svd(false, false).rank(1e-9);
        assert_eq!(rank, rows.len(), "independent constraints");
        let jt = j.transpose();
        // complete the basis: null space from the eigenvectors of JᵀJ with 0
        let eig = (&jt * &j).symmetric_eigen();
        let null: Vec<usize> = (0..n)
            .filter(|&k| eig.eigenvalues[k].abs() < 1e-9)
            .collect();
        assert_eq!(null.len(), n - rank);
        let z = DMatrix::from_fn(n, null.len(), |r, c| eig.eigenvectors[(r, null[c])]);
        let reduced = z.transpose() * &w * &z;
        let mut red: Vec<f64> = reduced
            .symmetric_eigen()
            .eigenvalues
            .iter()
            .copied()
            .collect();
        red.sort_by(|a, b| a.total_cmp(b));
        let mut ldlt = Ldlt::new(&energy.pattern);
        let sp = lowest_eigenvalues(&energy.pattern, &v, None, 2, &mut ldlt).unwrap();
        let negatives = red.iter().filter(|x| **x < 0.0).count();
        assert_eq!(sp.negative_count, negatives, "inertia, K3 = {k3}");
        for (k, (a, r)) in sp.values.iter().zip(&red).enumerate() {
            assert!(
                (a - r).abs() < 1e-3 * r.abs().max(1.0),
                "K3 = {k3}: eigenvalue {k}: augmented {a} vs reduced {r}"
            );
        }
    }
}

#[test]
fn unbendable_rod_is_the_limit_of_large_k2() {
    // Appendix D's boundary conditions at N = 50: the u2 = 0 solution by SQP,
    // and Kirchhoff rods with K2 = 1e2, 1e3, 1e4 by Newton; they converge to
    // it as 1/K2
    let text = std::fs::read_to_string("scenes/appendix_d.toml").unwrap();
    let text = text
        .replace("segments = 200", "segments = 50")
        .replace("K2 = 3.0", "kind = \"unbendable\"\nK2 = 3.0");
    let text = text.split("[reference]").next().unwrap();
    let scene = Scene::parse(text).unwrap();
    let (newton, limit, report) = starting_equilibrium(&scene, None).unwrap();
    assert!(report.converged);
    assert!(max_u2(&newton.energy, &limit) < 1e-9);
    let mut gaps = Vec::new();
    for k2 in [1e2, 1e3, 1e4] {
        let mut state = limit.clone();
        let mut newton = Minimizer::new(RodEnergy::new(kirchhoff(50, k2, 3.0, Law::Kirchhoff)));
        let r = newton
            .minimize(&mut state, &SolverSettings::default())
            .unwrap();
        assert!(r.converged);
        let gap = state.largest_node_distance(&limit);
        gaps.push(gap);
    }
    for w in gaps.windows(2) {
        let ratio = w[1] / w[0];
        assert!(
            (0.07..0.14).contains(&ratio),
            "gap should fall as 1/K2: {gaps:?}"
        );
    }
}

fn max_u2(energy: &RodEnergy, state: &RodState) -> f64 {
    let h = energy.model.segment_length();
    energy
        .constraint_rows(state)
        .iter()
        .map(|r| (r.0 / h).abs())
        .fold(0.0, f64::max)
}

#[test]
fn figure_8_strip_branches_at_n_100() {
    let scene = scene_at("scenes/fig8_strip.toml", 100);
    let (eqs, events) = run(&scene);
    assert!(eqs.len() > 400, "{} points", eqs.len());
    for e in &eqs {
        assert!(e.converged);
        let u2 = e.max_u2.expect("strip results report u2");
        assert!(
            u2 < 1e-9,
            "|u2| = {u2} at z* = {}, φ/2π = {}",
            e.z_star,
            e.phi_over_2pi
        );
        assert_eq!(e.regularised, Some(false), "away from the singularity");
        // no pitchfork, no fold: every branch is stable over φ/2π ∈ [0.45, 1]
        assert!(
            e.stable,
            "unstable at z* = {}, φ/2π = {}",
            e.z_star, e.phi_over_2pi
        );
    }
    for kind in [
        EventKind::Fold,
        EventKind::BranchPoint,
        EventKind::Stability,
    ] {
        assert!(!events.iter().any(|e| e.kind == kind), "{kind}: {events:?}");
    }
    // the five branches cover φ/2π from below 0.5 to 1
    for z in [0.115, 0.150, 0.180, 0.200, 0.215] {
        let phis: Vec<f64> = eqs
            .iter()
            .filter(|e| (e.z_star - z).abs() < 1e-9)
            .map(|e| e.phi_over_2pi)
            .collect();
        let lo = phis.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = phis.iter().copied().fold(0.0, f64::max);
        assert!(lo < 0.5 && hi > 0.99, "z* = {z}: φ/2π in [{lo}, {hi}]");
    }
    // a stable walled knotted strip without self-contact at z* = 0.215 near
    // φ/2π = 0.94 (Figure 8-right)
    let good: Vec<f64> = eqs
        .iter()
        .filter(|e| (e.z_star - 0.215).abs() < 1e-9 && e.good_knot)
        .map(|e| e.phi_over_2pi)
        .collect();
    assert!(
        good.iter().any(|p| (p - 0.94).abs() <= 0.02),
        "good knots at z* = 0.215: {good:?}"
    );
    // every good interval of every branch ends at an event of that branch
    // (walls W1/W2, crossings X, stability S), not between samples
    use knotrod::study::map::branch_intervals;
    for z in [0.115, 0.150, 0.180, 0.200, 0.215] {
        let at_z = |v: f64| (v - z).abs() < 1e-9;
        let here: Vec<_> = eqs.iter().filter(|e| at_z(e.z_star)).cloned().collect();
        let here_events: Vec<_> = events.iter().filter(|e| at_z(e.z_star)).cloned().collect();
        let intervals = branch_intervals(&here, &here_events);
        assert!(!intervals.is_empty(), "z* = {z}: no good knot");
        for iv in &intervals {
            for label in [&iv.lo_label, &iv.hi_label] {
                assert!(
                    ["W1", "W2", "X", "S"].contains(&label.as_str()),
                    "z* = {z}: interval {iv} ends at no event"
                );
            }
        }
    }
    // z* = 0.215: the paper's good knot lies between the two crossings X
    let here: Vec<_> = eqs
        .iter()
        .filter(|e| (e.z_star - 0.215).abs() < 1e-9)
        .cloned()
        .collect();
    let here_events: Vec<_> = events
        .iter()
        .filter(|e| (e.z_star - 0.215).abs() < 1e-9)
        .cloned()
        .collect();
    let iv = branch_intervals(&here, &here_events);
    assert!(
        iv.iter()
            .any(|i| i.lo_label == "X" && i.hi_label == "X" && i.lo < 0.94 && i.hi > 0.94),
        "{iv:?}"
    );
}

#[test]
fn one_contact_curves_approach_the_asymptotics() {
    use knotrod::study::asymptotics::{curve_i, curve_ii, one_contact_shifts};
    // along Δφ = 0.8 z* → 0 (β fixed): δ_I's relative error is O(z*²) (the
    // expansion is to second order), δ_II's is O(z*) (leading order only)
    let mut errors = Vec::new();
    for z in [0.08, 0.04, 0.02] {
        let dphi = 0.8 * z;
        let (d2, d1) = one_contact_shifts(200, z, dphi).unwrap();
        let e1 = (d1 - curve_i(z, dphi)) / curve_i(z, dphi);
        let e2 = (d2 - curve_ii(z, dphi)) / curve_ii(z, dphi);
        errors.push((e1, e2));
    }
    let (i, ii): (Vec<f64>, Vec<f64>) = errors.iter().copied().unzip();
    assert!(i[0].abs() < 0.05 && i[2].abs() < 0.005, "curve I: {i:?}");
    assert!(
        i[1].abs() < i[0].abs() / 3.0,
        "curve I error falls faster than z*: {i:?}"
    );
    for w in ii.windows(2) {
        let ratio = w[1] / w[0];
        assert!((0.4..0.7).contains(&ratio), "curve II error ∝ z*: {ii:?}");
    }
}

#[test]
fn one_contact_curve_reaches_the_self_contacting_elastica() {
    // as δ → 0 the largest z* on the one-contact curve tends to 0.223, the end
    // distance of the self-contacting planar elastica (paper eqs. 6.19–6.20)
    let z = knotrod::study::asymptotics::max_one_contact_z_star(100, 0.001, 0.002).unwrap();
    assert!((z - 0.223).abs() < 0.01, "max z* = {z}");
}
