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
    );
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
