//! The sparse shift-invert eigenvalues and the inertia against dense
//! eigen-decompositions, for the plain Hessian and the lumped-mass pencil.

use knotrod::linalg::eigen::lowest_eigenvalues;
use knotrod::model::energy::RodEnergy;
use knotrod::model::rod::{Clamps, RodModel, RodState};
use knotrod::model::shooting::ShootingSolution;
use knotrod::solve::minimizer::Minimizer;
use knotrod::solve::outcome::SolverSettings;
use nalgebra::{DMatrix, Vector3};

fn dense_lowest(h: &DMatrix<f64>, mass: Option<&[f64]>) -> Vec<f64> {
    let mut vals: Vec<f64> = match mass {
        None => h
            .clone()
            .symmetric_eigen()
            .eigenvalues
            .iter()
            .copied()
            .collect(),
        Some(m) => {
            // Schur complement on the massive dofs, then M^-1/2 S M^-1/2
            let x: Vec<usize> = (0..m.len()).filter(|&d| m[d] > 0.0).collect();
            let t: Vec<usize> = (0..m.len()).filter(|&d| m[d] == 0.0).collect();
            let sub = |r: &[usize], c: &[usize]| {
                DMatrix::from_fn(r.len(), c.len(), |i, j| h[(r[i], c[j])])
            };
            let s = sub(&x, &x) - sub(&x, &t) * sub(&t, &t).try_inverse().unwrap() * sub(&t, &x);
            let w = DMatrix::from_fn(x.len(), x.len(), |i, j| {
                if i == j { 1.0 / m[x[i]].sqrt() } else { 0.0 }
            });
            (&w * s * &w)
                .symmetric_eigen()
                .eigenvalues
                .iter()
                .copied()
                .collect()
        }
    };
    vals.sort_by(|a, b| a.total_cmp(b));
    vals
}

fn check(energy: &RodEnergy, state: &RodState, expect_negative: bool) {
    let n = energy.map.len();
    let mut g = vec![0.0; n];
    let mut v = vec![0.0; energy.pattern.nnz()];
    energy.hessian(state, &mut g, &mut v);
    let h = energy.pattern.to_dense(&v);
    let mut ldlt = knotrod::linalg::sparse::Ldlt::new(&energy.pattern);
    let mass = energy.lumped_mass();
    for m in [None, Some(mass.as_slice())] {
        let dense = dense_lowest(&h, m);
        let sparse = lowest_eigenvalues(&energy.pattern, &v, m, 4, &mut ldlt).unwrap();
        let neg = dense.iter().filter(|x| **x < 0.0).count();
        assert_eq!(
            sparse.negative_count,
            neg,
            "inertia (mass: {})",
            m.is_some()
        );
        assert_eq!(neg > 0, expect_negative);
        for k in 0..4 {
            let scale = dense[k].abs().max(1e-3 * dense[3].abs());
            assert!(
                (sparse.values[k] - dense[k]).abs() < 1e-8 * scale,
                "eigenvalue {k}: sparse {} dense {} (mass: {})",
                sparse.values[k],
                dense[k],
                m.is_some()
            );
        }
    }
}

#[test]
fn stable_knot_spectrum_matches_dense() {
    // N = 24 takes the small dense path, N = 60 the Lanczos path
    for n in [24, 60] {
        stable_knot(n);
    }
}

fn stable_knot(n: usize) {
    // the Appendix D knot at a coarse N, relaxed
    let model = RodModel {
        weight: [0.0; 3],
        natural_strains: Default::default(),
        segments: n,
        k2: 3.0,
        k3: 3.0,
        stretching_stiffness: 640_000.0,
        law: Default::default(),
    };
    let clamps = Clamps::new(0.115, 0.05, 0.802);
    let sol = ShootingSolution::integrate(
        Vector3::new(-24.743, 17.772, 37.145),
        Vector3::new(7.5317, -8.7100, 4.529),
        3.0,
        3.0,
        4000,
    )
    .unwrap();
    let mut st = RodState::from_curve(n, clamps, |s| sol.position(s), |s| sol.d1(s));
    let mut newton = Minimizer::new(RodEnergy::new(model));
    newton
        .minimize(&mut st, &SolverSettings::default())
        .unwrap();
    check(&newton.energy, &st, false);
}

#[test]
fn unstable_state_spectrum_matches_dense() {
    // straight rod twisted well past the Greenhill moment: an unstable equilibrium
    for n in [20, 60] {
        let model = RodModel {
            weight: [0.0; 3],
            natural_strains: Default::default(),
            segments: n,
            k2: 1.0,
            k3: 1.0,
            stretching_stiffness: 1e4,
            law: Default::default(),
        };
        let st = RodState::straight(n, Clamps::new(1.0, 0.0, 2.5));
        check(&RodEnergy::new(model), &st, true);
    }
}

/// Appendix D at N segments and stretching stiffness `s`, Newton-polished
/// (a few plain steps, the least |∇E| kept: the study's stopping test may
/// stop above the gradient's floor) and measured: its lowest ω².
fn stiff_omega2(n: usize, s: f64) -> f64 {
    use knotrod::analysis::equilibrium::analyse;
    let mut scene =
        knotrod::scene::Scene::load(std::path::Path::new("scenes/appendix_d.toml")).expect("scene");
    scene.model.stretching_stiffness = Some(s);
    let (mut newton, mut state, report) =
        knotrod::study::start::starting_equilibrium(&scene, Some(n)).expect("equilibrium");
    let energy = newton.energy.clone();
    let mut g = vec![0.0; energy.map.len()];
    let mut v = vec![0.0; energy.pattern.nnz()];
    let gradient = |st: &RodState, g: &mut [f64], v: &mut [f64]| {
        energy.hessian(st, g, v);
        g.iter().map(|x| x * x).sum::<f64>().sqrt()
    };
    let (mut best, mut best_state) = (gradient(&state, &mut g, &mut v), state.clone());
    for _ in 0..5 {
        newton.ldlt.factor(&v).expect("factor");
        g.iter_mut().for_each(|x| *x = -*x);
        newton.ldlt.solve_in_place(&mut g);
        state = state.displaced(&energy.map, &g);
        let now = gradient(&state, &mut g, &mut v);
        if now < best {
            (best, best_state) = (now, state.clone());
        }
    }
    let eq = analyse(&mut newton, &best_state, &report, &scene.measure()).expect("analyse");
    eq.omega_squared[0]
}

#[test]
fn stiff_rod_keeps_the_lowest_omega2() {
    // ω² is smooth in 1/S (a finite stiffness's model error); the quadratic
    // in 1/S through S = 1e5, 2e5, 4e5, where the assembled Hessian still
    // holds ω² to ~1e-8, predicts S = 1e8 to ~2e-9 at the same N. Shift-invert
    // on the assembled matrices alone is off by ε S/h²/ω² ≈ 5e-7 there.
    let n = 800;
    let trend: Vec<(f64, f64)> = [1e5, 2e5, 4e5]
        .iter()
        .map(|&s| (1.0 / s, stiff_omega2(n, s)))
        .collect();
    let at = |x: f64| -> f64 {
        (0..3)
            .map(|i| {
                trend[i].1
                    * (0..3)
                        .filter(|&j| j != i)
                        .map(|j| (x - trend[j].0) / (trend[i].0 - trend[j].0))
                        .product::<f64>()
            })
            .sum()
    };
    let s = 1e8;
    let (omega2, predicted) = (stiff_omega2(n, s), at(1.0 / s));
    let rel = ((omega2 - predicted) / predicted).abs();
    assert!(
        rel < 5e-8,
        "N = {n}, S = {s:e}: ω² = {omega2:.10}, the S-trend {predicted:.10} (relative {rel:.1e})"
    );
}
