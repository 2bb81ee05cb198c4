//! The double ring's stability (criterion 2.7): where its lowest Hessian
//! eigenvalue changes sign in K.

use crate::model::energy::RodEnergy;
use crate::model::rod::{Law, RodModel};
use crate::report::error::Result;
use crate::scene::Scene;
use crate::solve::root::bisect_predicate;
use std::fmt::Write;

/// The section "The double ring's stability".
pub(super) fn section() -> Result<String> {
    let mut s = String::new();
    writeln!(s, "\n## The double ring's stability (criterion 2.7)\n")?;
    writeln!(
        s,
        "The Kirchhoff double ring (z* = δ = 0, φ = 2π) is stable iff sqrt((K2 − 1)/K2 · (K3 − 1)/K3) ≥ 1/2, i.e. K ≥ 2 for K2 = K3 = K. The sign change of its lowest Hessian eigenvalue, located by bisection in K:\n"
    )?;
    s += &double_ring_table()?;
    Ok(s)
}

/// The sign change in K at N = 50, 100, 200, against 2.
fn double_ring_table() -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "| N | K at which the double ring's lowest eigenvalue changes sign (K2 = K3 = K) | error against 2 |\n|---|---|---|"
    )?;
    for n in [50, 100, 200] {
        let k = critical_k(n)?;
        writeln!(s, "| {n} | {k:.6} | {:.2e} |", k - 2.0)?;
    }
    Ok(s)
}

/// The K2 = K3 = K at which the double ring's lowest eigenvalue changes sign
/// at N, by bisection in [1.5, 2.5].
fn critical_k(n: usize) -> Result<f64> {
    let scene = Scene::parse(&format!(
        "[model]\nsegments = {n}\n[clamps]\nz_star = 0.0\ndelta = 0.0\nphi_over_2pi = 1.0\n[initial]\nshape = \"double_ring\"\nsteps = 1\n"
    ))?;
    let (_, ring, _) = crate::study::start::starting_equilibrium(&scene, None)?;
    let lowest = |k: f64| -> Result<f64> {
        let energy = RodEnergy::new(RodModel {
            weight: [0.0; 3],
            natural_strains: Default::default(),
            segments: n,
            k2: k,
            k3: k,
            stretching_stiffness: 640_000.0,
            law: Law::Kirchhoff,
        });
        let mut g = vec![0.0; energy.map.len()];
        let mut v = vec![0.0; energy.pattern.nnz()];
        energy.hessian(&ring, &mut g, &mut v);
        let mut ldlt = crate::linalg::sparse::Ldlt::new(&energy.pattern);
        let sp = crate::linalg::eigen::lowest_eigenvalues(&energy.pattern, &v, None, 1, &mut ldlt)?;
        Ok(sp.values[0])
    };
    // 40 halvings of [1.5, 2.5]
    bisect_predicate(
        1.5,
        2.5,
        |lo, hi| hi - lo <= 1e-12,
        |k| Ok(lowest(k)? <= 0.0),
    )
}
