//! Finite-difference checks of the exact gradient and Hessian of every energy
//! term and of the total, on random non-planar configurations.

use knotrod::model::energy::{RodEnergy, Terms};
use knotrod::model::natural::NaturalStrains;
use knotrod::model::rod::{Clamps, EndKind, Ends, Law, Parameter, RodModel, RodState};
use nalgebra::Vector3;

use crate::common;
use common::Lcg;

fn random_state(n: usize, seed: u64) -> (RodModel, RodState) {
    random_state_with(n, seed, Law::Kirchhoff)
}

fn random_state_with(n: usize, seed: u64, law: Law) -> (RodModel, RodState) {
    random_state_at(n, seed, law, Clamps::new(0.4, 0.1, 0.37))
}

/// General clamps: both tilted and rotated, the s = 0 one moved and turned.
fn general_clamps() -> Clamps {
    use knotrod::model::rod::Orientation;
    use nalgebra::UnitQuaternion;
    let mut c = Clamps::new(0.4, 0.1, 0.37);
    c.end.shift = [0.05, -0.03];
    c.end.orientation = Orientation {
        rotation: UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3),
        tilt: 0.35,
        tilt_azimuth: 0.8,
    };
    c.start.position = Vector3::new(0.02, -0.01, 0.03);
    c.start.orientation = Orientation {
        rotation: UnitQuaternion::from_euler_angles(-0.15, 0.1, 0.2),
        tilt: 0.25,
        tilt_azimuth: -0.6,
    };
    c.start.turn = 0.4;
    c
}

fn random_state_at(n: usize, seed: u64, law: Law, clamps: Clamps) -> (RodModel, RodState) {
    let model = RodModel {
        // a weight in a direction of no symmetry
        weight: [0.7, -1.9, 2.6],
        natural_strains: [0.4, -0.9, 1.3].into(),
        segments: n,
        k2: 2.3,
        k3: 1.7,
        stretching_stiffness: 50.0,
        law,
    };
    // a non-planar loop with large curvature plus noise
    let base = RodState::from_curve(
        n,
        clamps,
        |s| {
            Vector3::new(
                0.2 * (6.0 * s).sin(),
                0.15 * (1.0 - (5.0 * s).cos()),
                0.4 * s,
            )
        },
        |s| Vector3::new((3.0 * s).cos(), (3.0 * s).sin(), 0.0),
    );
    let mut model = model;
    if matches!(law, Law::Strip { .. }) {
        // the strip law has û1 only (its own tests below); here the straight
        // strip, as these checks were made before strips had one
        model.natural_strains = Default::default();
    }
    let map = RodEnergy::with_ends(model.clone(), Terms::ALL, clamps.ends).map;
    let mut rng = Lcg(seed);
    let dq: Vec<f64> = (0..map.len())
        .map(|d| if map.is_translation(d) { 0.01 } else { 0.5 } * rng.next())
        .collect();
    let mut state = base.displaced(&map, &dq);
    if law.constrained() {
        // multipliers of the augmented Lagrangian, which the energy then is
        state.multipliers = (0..=n).map(|_| 3.0 * rng.next()).collect();
    }
    (model, state)
}

fn rel(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt();
    let s: f64 = b.iter().map(|y| y * y).sum::<f64>().sqrt();
    d / s
}

fn check(terms: Terms, seed: u64) {
    check_law(terms, seed, Law::Kirchhoff, 2e-5)
}

/// FD check of one law; `hessian_step` is the step of the second differences.
fn check_law(terms: Terms, seed: u64, law: Law, hessian_step: f64) {
    let (model, state) = random_state_with(12, seed, law);
    check_at(terms, model, &state, hessian_step);
}

/// FD check of the energy of `model` at `state`.
fn check_model(terms: Terms, model: RodModel, state: RodState, hessian_step: f64) {
    check_at(terms, model, &state, hessian_step);
}

/// FD check of the energy of `model` at `state` (with its ends).
fn check_at(terms: Terms, model: RodModel, state: &RodState, hessian_step: f64) {
    let energy = RodEnergy::with_ends(model, terms, state.clamps.ends);
    let map = energy.map;
    let n = map.len();
    let mut g = vec![0.0; n];
    let mut vals = vec![0.0; energy.pattern.nnz()];
    energy.hessian(state, &mut g, &mut vals);
    let h = energy.pattern.to_dense(&vals);
    // All differences are taken in the chart of `state` (frames transported from
    // it), the chart in which the Hessian is defined; gradients evaluated at
    // displaced states live in other charts and differ by holonomy terms.
    let e = |dq: &[f64]| energy.energy(&state.displaced(&map, dq));
    let eps = 1e-6;
    let mut g_fd = vec![0.0; n];
    for d in 0..n {
        let mut dq = vec![0.0; n];
        dq[d] = eps;
        let ep = e(&dq);
        dq[d] = -eps;
        g_fd[d] = (ep - e(&dq)) / (2.0 * eps);
    }
    let eps = hessian_step;
    let mut h_fd = nalgebra::DMatrix::zeros(n, n);
    for a in 0..n {
        for b in a..n {
            let mut v = 0.0;
            for (sa, sb, w) in [
                (1.0, 1.0, 1.0),
                (1.0, -1.0, -1.0),
                (-1.0, 1.0, -1.0),
                (-1.0, -1.0, 1.0),
            ] {
                let mut dq = vec![0.0; n];
                dq[a] += sa * eps;
                dq[b] += sb * eps;
                v += w * e(&dq);
            }
            h_fd[(a, b)] = v / (4.0 * eps * eps);
            h_fd[(b, a)] = h_fd[(a, b)];
        }
    }
    let eg = rel(&g_fd, &g);
    assert!(eg < 1e-6, "{terms:?}: gradient relative error {eg:e}");
    if terms == Terms::GRAVITY {
        // a linear potential: an exactly zero Hessian, which the second
        // differences see as round-off only; a gradient that is there
        assert_eq!(h.norm(), 0.0);
        assert!(h_fd.amax() < 1e-5, "{terms:?}: FD Hessian {}", h_fd.amax());
        assert!(g.iter().any(|v| v.abs() > 1e-3));
        return;
    }
    let eh = (&h_fd - &h).norm() / h.norm();
    assert!(eh < 1e-6, "{terms:?}: Hessian relative error {eh:e}");
    // the finite differences are informative: the check is not vacuous
    assert!(h.norm() > 1e-3 && g.iter().any(|v| v.abs() > 1e-6));
}

#[test]
fn bending_derivatives_match_finite_differences() {
    for seed in 1..4 {
        check(Terms::BENDING, seed);
    }
}

#[test]
fn twisting_derivatives_match_finite_differences() {
    for seed in 1..4 {
        check(Terms::TWISTING, seed);
    }
}

#[test]
fn stretching_derivatives_match_finite_differences() {
    for seed in 1..4 {
        check(Terms::STRETCHING, seed);
    }
}

#[test]
fn gravity_derivatives_match_finite_differences() {
    for seed in [1, 2] {
        check(Terms::GRAVITY, seed);
    }
}

#[test]
fn total_derivatives_match_finite_differences() {
    for seed in 1..4 {
        check(Terms::ALL, seed);
    }
}

#[test]
fn strip_derivatives_match_finite_differences() {
    // Sadowsky law plus the augmented-Lagrangian terms λ κ2 + ρ/2 κ2², with
    // regularisations comparable to the curvatures so that it is exercised.
    // With ε = 0.05 the energy is sharp: the second differences need a finer
    // step (their error was measured to fall as step², 2.6e-5 → 4.1e-7 from
    // 4e-5 to 5e-6: truncation, not the AD derivatives).
    for (seed, eps, step) in [(2, 1.0, 2e-5), (3, 5.0, 2e-5), (1, 0.05, 5e-6)] {
        check_law(
            Terms::ALL,
            seed,
            Law::Strip {
                regularisation: eps,
            },
            step,
        );
    }
}

#[test]
fn naturally_curved_strip_derivatives_match_finite_differences() {
    // the strip law of u1 − û1: a constant û1 (the random state's 0.4 is
    // small beside its curvatures, so take one comparable to them) and a
    // table û1(s) sampled at each vertex's s = (i − ½)h
    let law = Law::Strip {
        regularisation: 1.0,
    };
    let table = NaturalStrains::Table(vec![
        [0.0, -3.0, 0.0, 0.0],
        [0.4, 6.0, 0.0, 0.0],
        [1.0, 2.0, 0.0, 0.0],
    ]);
    for (seed, natural) in [(4, NaturalStrains::from([5.0, 0.0, 0.0])), (5, table)] {
        let (mut model, state) = random_state_with(12, seed, law);
        model.natural_strains = natural;
        check_model(Terms::ALL, model, state, 2e-5);
    }
}

#[test]
fn natural_strain_table_derivatives_match_finite_differences() {
    // a Kirchhoff rod whose û1, û2, û3 all vary along it
    let table = NaturalStrains::Table(vec![
        [0.0, 2.0, -1.0, 1.0],
        [0.3, 2.5, 0.5, 0.0],
        [1.0, 3.0, 1.0, -2.0],
    ]);
    for seed in 1..3 {
        let (mut model, state) = random_state(12, seed);
        model.natural_strains = table.clone();
        check_model(Terms::ALL, model, state, 2e-5);
    }
}

#[test]
fn a_natural_strain_table_is_sampled_at_each_vertex() {
    // the energy with a table equals the sum of vertex energies with the
    // constant û of each vertex's s = (i − ½)h: the table is not smeared
    let table = NaturalStrains::Table(vec![[0.0, 2.0, -1.0, 1.0], [1.0, 3.0, 1.0, -2.0]]);
    let (mut model, state) = random_state(12, 3);
    model.natural_strains = table.clone();
    let energy = RodEnergy::with_terms(model.clone(), Terms::BENDING);
    let mut by_vertex = 0.0;
    for i in 1..=12 {
        let u = table.at((i as f64 - 0.5) / 12.0);
        let mut constant = model.clone();
        constant.natural_strains = u.into();
        let e = RodEnergy::with_terms(constant, Terms::BENDING);
        let (ei, _, _) = e.vertex_local(&state, i);
        by_vertex += ei;
    }
    let total = energy.energy(&state);
    assert!(
        (total - by_vertex).abs() < 1e-12 * total.abs(),
        "{total} vs {by_vertex}"
    );
}

#[test]
fn unbendable_derivatives_match_finite_differences() {
    for seed in 1..3 {
        check_law(Terms::ALL, seed, Law::Unbendable, 2e-5);
    }
}

#[test]
fn constraint_gradient_matches_finite_differences() {
    let (model, state) = random_state_with(
        12,
        5,
        Law::Strip {
            regularisation: 0.05,
        },
    );
    let energy = RodEnergy::new(model);
    let map = energy.map;
    let n = map.len();
    let rows = energy.constraint_rows(&state);
    let eps = 1e-6;
    let mut largest = 0.0f64;
    for d in 0..n {
        let mut dq = vec![0.0; n];
        dq[d] = eps;
        let plus = energy.constraint_rows(&state.displaced(&map, &dq));
        dq[d] = -eps;
        let minus = energy.constraint_rows(&state.displaced(&map, &dq));
        for (i, row) in rows.iter().enumerate() {
            let fd = (plus[i].0 - minus[i].0) / (2.0 * eps);
            let exact = map
                .vertex_stencil(i + 1)
                .iter()
                .position(|s| *s == Some(d))
                .map_or(0.0, |a| row.1[a]);
            assert!(
                (fd - exact).abs() < 1e-6 * (1.0 + exact.abs()),
                "∂κ2_{}/∂q_{d}: {fd} vs {exact}",
                i + 1
            );
            largest = largest.max(exact.abs());
        }
    }
    assert!(largest > 0.1, "the constraint depends on the dofs");
}

#[test]
fn hessian_is_symmetric_and_full_gradient_agrees() {
    let (model, state) = random_state(10, 7);
    let energy = RodEnergy::new(model);
    let n = energy.map.len();
    let mut g = vec![0.0; n];
    energy.gradient(&state, &mut g);
    let full = energy.full_gradient(&state);
    for i in 2..10 {
        let d = energy.map.node(i).unwrap();
        for c in 0..3 {
            assert!((full.nodes[i][c] - g[d + c]).abs() < 1e-12 * (1.0 + g[d + c].abs()));
        }
    }
}

/// `state` with its clamp parameter set to `value` and free dofs moved by `dq`,
/// all frames transported in one step from `state` (the chart of the
/// derivatives).
fn moved(
    state: &RodState,
    p: knotrod::model::rod::Parameter,
    value: f64,
    dq: &[f64],
    map: &knotrod::model::rod::DofMap,
) -> RodState {
    let clamps = p.with(&state.clamps, value);
    let mut next = state.clone();
    state.move_into(map, dq, clamps, &mut next);
    next
}

#[test]
fn parameter_derivative_of_the_gradient_matches_finite_differences() {
    for law in [
        Law::Kirchhoff,
        Law::Strip {
            regularisation: 0.05,
        },
    ] {
        parameter_derivative_of_the_gradient(law, Clamps::new(0.4, 0.1, 0.37));
        parameter_derivative_of_the_gradient(law, general_clamps());
    }
}

fn parameter_derivative_of_the_gradient(law: Law, clamps: Clamps) {
    let (model, state) = random_state_at(12, 5, law, clamps);
    let energy = RodEnergy::with_ends(model, Terms::ALL, clamps.ends);
    let map = energy.map;
    let n = map.len();
    let parameters: &[Parameter] = if clamps.is_paper() {
        &Parameter::ALL[..3]
    } else {
        &Parameter::ALL
    };
    // a pinned end feels its point only, a free one nothing (scenes refuse
    // the others)
    let felt = |p: &Parameter| match if p.moves_start() {
        clamps.ends.start
    } else {
        clamps.ends.end
    } {
        EndKind::Clamped => true,
        EndKind::Pinned => !p.only_turns(),
        EndKind::Free => false,
    };
    for &p in parameters.iter().filter(|p| felt(p)) {
        let mut exact = vec![0.0; n];
        energy.gradient_parameter_derivative(&state, &p.velocity(&state), &mut exact);
        let v0 = p.value(&state.clamps);
        // mixed central differences of the energy with the clamps moved as the
        // solvers move them (frames transported, clamp angles continued), at
        // two parameter steps combined by Richardson to remove the O(ε²) term
        let mixed = |ep: f64| {
            let eq = 2e-5;
            (0..n)
                .map(|d| {
                    let mut v = 0.0;
                    for (sq, sp, w) in [
                        (1.0, 1.0, 1.0),
                        (1.0, -1.0, -1.0),
                        (-1.0, 1.0, -1.0),
                        (-1.0, -1.0, 1.0),
                    ] {
                        let mut dq = vec![0.0; n];
                        dq[d] = sq * eq;
                        v += w * energy.energy(&moved(&state, p, v0 + sp * ep, &dq, &map));
                    }
                    v / (4.0 * eq * ep)
                })
                .collect::<Vec<f64>>()
        };
        let (coarse, fine) = (mixed(2e-4), mixed(1e-4));
        let fd: Vec<f64> = coarse
            .iter()
            .zip(&fine)
            .map(|(c, f)| (4.0 * f - c) / 3.0)
            .collect();
        let e = rel(&fd, &exact);
        assert!(e < 1e-6, "{p:?}: relative error {e:e}");
        assert!(
            exact.iter().any(|v| v.abs() > 1e-3),
            "{p:?}: derivative vanishes"
        );
    }
}

#[test]
fn parameter_derivative_of_the_constraints_matches_finite_differences() {
    use knotrod::model::rod::Parameter;
    let (model, state) = random_state_at(
        12,
        6,
        Law::Strip {
            regularisation: 0.05,
        },
        general_clamps(),
    );
    let energy = RodEnergy::new(model);
    let map = energy.map;
    let zero = vec![0.0; map.len()];
    let rows = energy.constraint_rows(&state);
    for p in Parameter::ALL {
        let mut exact = vec![0.0; rows.len()];
        energy.constraint_parameter_derivative(&rows, &p.velocity(&state), &mut exact);
        let v0 = p.value(&state.clamps);
        let eps = 1e-6;
        let plus = energy.constraint_rows(&moved(&state, p, v0 + eps, &zero, &map));
        let minus = energy.constraint_rows(&moved(&state, p, v0 - eps, &zero, &map));
        let fd: Vec<f64> = plus
            .iter()
            .zip(&minus)
            .map(|(a, b)| (a.0 - b.0) / (2.0 * eps))
            .collect();
        let e = rel(&fd, &exact);
        assert!(e < 1e-6, "{p:?}: relative error {e:e}");
    }
}

/// The general clamps with these ends.
fn with_ends(start: EndKind, end: EndKind) -> Clamps {
    let mut c = general_clamps();
    c.ends = Ends { start, end };
    c
}

#[test]
fn derivatives_with_pinned_and_free_ends_match_finite_differences() {
    use EndKind::{Clamped, Free, Pinned};
    for (start, end) in [
        (Clamped, Free),
        (Clamped, Pinned),
        (Free, Clamped),
        (Pinned, Clamped),
    ] {
        let clamps = with_ends(start, end);
        let (model, state) = random_state_at(12, 3, Law::Kirchhoff, clamps);
        // a pinned end's ghost node sits opposite its neighbour across the pin
        let [(a, b), (c, d)] = [(0, 1), (12, 13)].map(|(i, j)| (state.nodes[i], state.nodes[j]));
        if start == Pinned {
            assert!((0.5 * (a + b) - clamps.start_point()).norm() < 1e-15);
        }
        if end == Pinned {
            assert!((0.5 * (c + d) - clamps.end_point()).norm() < 1e-15);
        }
        check_at(Terms::ALL, model, &state, 2e-5);
    }
}

#[test]
fn parameter_derivative_with_pinned_ends_matches_finite_differences() {
    // the pin moves and its edge translates with it; its angle stays free
    use EndKind::{Clamped, Pinned};
    parameter_derivative_of_the_gradient(Law::Kirchhoff, with_ends(Clamped, Pinned));
    parameter_derivative_of_the_gradient(Law::Kirchhoff, with_ends(Pinned, Clamped));
}

#[test]
fn hessian_gram_matches_the_assembled_form() {
    // the stencil-by-stencil form zₚᵀ H z_q of the stability refinement is
    // the assembled Hessian's, at every kind of end and for a constrained law
    use EndKind::{Clamped, Free, Pinned};
    let cases = [
        (Clamped, Clamped, Law::Kirchhoff),
        (Clamped, Free, Law::Kirchhoff),
        (Pinned, Clamped, Law::Kirchhoff),
        (Free, Pinned, Law::Kirchhoff),
        (Clamped, Clamped, Law::Unbendable),
    ];
    for (seed, (start, end, law)) in cases.into_iter().enumerate() {
        let (model, state) = random_state_at(12, 7 + seed as u64, law, with_ends(start, end));
        let energy = RodEnergy::with_ends(model, Terms::ALL, state.clamps.ends);
        let n = energy.map.len();
        let mut g = vec![0.0; n];
        let mut vals = vec![0.0; energy.pattern.nnz()];
        energy.hessian(&state, &mut g, &mut vals);
        let h = energy.pattern.to_dense(&vals);
        let mut rng = Lcg(seed as u64);
        let z: Vec<Vec<f64>> = (0..3)
            .map(|_| (0..n).map(|_| rng.next()).collect())
            .collect();
        let gram = energy.hessian_gram(&state, &z);
        let habs = h.abs();
        for p in 0..3 {
            for q in 0..3 {
                let (zp, zq) = (
                    nalgebra::DVector::from_column_slice(&z[p]),
                    nalgebra::DVector::from_column_slice(&z[q]),
                );
                let exact = zp.dot(&(&h * &zq));
                let scale = zp.abs().dot(&(&habs * zq.abs()));
                assert!(
                    (gram[p * 3 + q] - exact).abs() < 1e-12 * scale,
                    "{start:?}-{end:?} {law:?} ({p}, {q}): gram {} assembled {exact}",
                    gram[p * 3 + q]
                );
            }
        }
    }
}
