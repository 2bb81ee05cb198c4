//! Analytic cases: uniform twist, Euler buckling, torsional buckling of a
//! clamped-clamped rod, with convergence in N.

use knotrod::model::energy::RodEnergy;
use knotrod::model::rod::{Clamps, RodModel, RodState};
use knotrod::report::analytic::{
    self, euler_buckling_load, greenhill_constant, greenhill_twisting_moment,
};
use knotrod::solve::minimizer::Minimizer;
use std::f64::consts::PI;

fn model(n: usize, k2: f64, k3: f64) -> RodModel {
    RodModel {
        weight: [0.0; 3],
        natural_strains: Default::default(),
        segments: n,
        k2,
        k3,
        stretching_stiffness: 640_000.0,
        law: Default::default(),
    }
}

fn straight_equilibrium(newton: &mut Minimizer, clamps: Clamps) -> (RodState, usize) {
    analytic::straight_equilibrium(newton, clamps).expect("converges")
}

#[test]
fn straight_rod_twisted_by_phi_has_exact_twist_and_energy() {
    // twisting moments K3 φ = 5.7, 8.2, 7.1: all below the buckling moment 8.99
    for (n, phi_over_2pi, k3) in [(20, 0.3, 3.0), (50, 1.3, 1.0), (200, -0.75, 1.5)] {
        let mut newton = Minimizer::new(RodEnergy::new(model(n, 1.0, k3)));
        let clamps = Clamps::new(1.0, 0.0, phi_over_2pi);
        let (st, neg) = straight_equilibrium(&mut newton, clamps);
        let phi = 2.0 * PI * phi_over_2pi;
        let e = newton.energy.energy(&st);
        assert!(
            (st.twist() - phi_over_2pi).abs() < 1e-12,
            "Tw {} vs {}",
            st.twist(),
            phi_over_2pi
        );
        assert!(
            (e - k3 * phi * phi / 2.0).abs() < 1e-10 * (1.0 + e),
            "E {e} vs {}",
            k3 * phi * phi / 2.0
        );
        // below the torsional buckling moment (8.99) the straight rod is stable
        assert_eq!(neg, 0, "φ/2π = {phi_over_2pi} should be stable");
    }
}

#[test]
fn a_full_turn_of_the_clamp_is_a_different_state() {
    let n = 40;
    let energy = RodEnergy::new(model(n, 3.0, 3.0));
    let a = RodState::straight(n, Clamps::new(1.0, 0.0, 0.2));
    let b = RodState::straight(n, Clamps::new(1.0, 0.0, 1.2));
    assert!((b.twist() - a.twist() - 1.0).abs() < 1e-12);
    assert!(energy.energy(&b) > energy.energy(&a) + 1.0);
    // moving the clamp continuously by a full turn keeps the turn
    let mut c = a.clone();
    for k in 1..=20 {
        c.set_clamps(Clamps::new(1.0, 0.0, 0.2 + k as f64 / 20.0));
    }
    assert!((c.twist() - b.twist()).abs() < 1e-12);
}

#[test]
fn clamped_isotropic_rod_buckles_at_four_pi_squared_with_second_order_convergence() {
    let p_e = 4.0 * PI * PI;
    // the default stiffness of a rod of diameter 1/200
    let p = euler_buckling_load(200, 640_000.0).unwrap();
    assert!(
        (p - p_e).abs() / p_e < 0.01,
        "N=200: P = {p} vs 4π² = {p_e}"
    );
    // convergence study with a stiffness high enough that extensibility (a
    // relative correction of order P/S) does not mask the O(1/N²) error
    let loads: Vec<f64> = [50, 100, 200]
        .iter()
        .map(|&n| euler_buckling_load(n, 1e9).unwrap())
        .collect();
    let err: Vec<f64> = loads.iter().map(|p| (p - p_e).abs() / p_e).collect();
    for k in 1..3 {
        let order = (err[k - 1] / err[k]).log2();
        assert!(
            order > 1.8 && order < 2.3,
            "observed order {order} (errors {err:?})"
        );
    }
}

#[test]
fn clamped_rod_under_pure_twist_buckles_at_greenhill_moment() {
    // Clamped-clamped rod, no axial force: M L / B = 2 x1 with tan x1 = x1,
    // i.e. 8.9868 = 2.8606 π (Greenhill's problem; e.g. van der Heijden,
    // Neukirch, Goss & Thompson, Int. J. Mech. Sci. 45 (2003) 161-196).
    let m_cr = greenhill_constant();
    assert!((m_cr / PI - 2.8606).abs() < 1e-4);
    let moments: Vec<f64> = [50, 100, 200]
        .iter()
        .map(|&n| greenhill_twisting_moment(n, 3.0, 640_000.0).unwrap())
        .collect();
    let err: Vec<f64> = moments.iter().map(|m| (m - m_cr).abs() / m_cr).collect();
    assert!(err[2] < 0.01, "N=200: M = {} vs {m_cr}", moments[2]);
    for k in 1..3 {
        let order = (err[k - 1] / err[k]).log2();
        assert!(
            order > 1.8 && order < 2.3,
            "observed order {order} (errors {err:?})"
        );
    }
}

/// The midspan sag of a straight clamped-clamped rod (z* = 1) under a small
/// transverse weight w along −x (isotropic, B = 1), to compare with the
/// beam's w L⁴ / (384 B).
fn midspan_sag(n: usize, w: f64) -> f64 {
    let text = format!(
        "[model]\nsegments = {n}\nK2 = 1.0\nK3 = 1.0\n[clamps]\nz_star = 1.0\ndelta = 0.0\nphi_over_2pi = 0.0\n\
         [solver]\ngradient_tol = 1e-12\n[load]\nweight = {w}\ndirection = [-1.0, 0.0, 0.0]\n"
    );
    let scene = knotrod::scene::Scene::parse(&text).unwrap();
    let eq = knotrod::study::start::solve_scene(&scene, None).unwrap();
    let x = &eq.state.nodes;
    // nodes sit at s = (i − 1/2)/N: midspan between nodes N/2 and N/2 + 1
    0.5 * (x[n / 2].x + x[n / 2 + 1].x)
}

#[test]
fn a_clamped_clamped_rod_sags_under_its_weight_as_a_beam() {
    let w = 1e-2;
    let exact = -w / 384.0;
    let errors: Vec<f64> = [20, 40, 80]
        .iter()
        .map(|&n| (midspan_sag(n, w) - exact).abs() / exact.abs())
        .collect();
    eprintln!("sag vs w/384, N = 20, 40, 80: relative errors {errors:?}");
    // second order in N
    for k in 0..2 {
        let order = (errors[k] / errors[k + 1]).log2();
        assert!(order > 1.8, "errors {errors:?}, order {order}");
    }
    assert!(errors[2] < 1e-3, "errors {errors:?}");
}
