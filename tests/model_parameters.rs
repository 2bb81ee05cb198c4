//! The model's scalars (K2, K3, the weight, the scale of the natural strains)
//! as continuation parameters: their exact ∂p∇E against finite differences,
//! and a branch in K3 that finds Greenhill's twisting instability.

use knotrod::analysis::event::EventKind;
use knotrod::model::energy::RodEnergy;
use knotrod::model::rod::{Clamps, Law, ModelScalars, Parameter, RodModel, RodState};
use knotrod::report::analytic::greenhill_constant;
use knotrod::scene::Scene;
use nalgebra::Vector3;

use crate::common;
use common::run;

#[test]
fn the_model_scalars_derivative_of_the_gradient_matches_finite_differences() {
    let model = RodModel {
        weight: [0.7, -1.9, 2.6],
        natural_strains: [0.4, -0.9, 1.3].into(),
        segments: 12,
        k2: 2.3,
        k3: 1.7,
        stretching_stiffness: 50.0,
        law: Law::Kirchhoff,
    };
    let mut clamps = Clamps::new(0.4, 0.1, 0.37);
    clamps.scalars = ModelScalars::of(&model, [0.0, 0.0, -1.0]);
    let state = RodState::from_curve(
        12,
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
    let energy = RodEnergy::new(model);
    let n = energy.map.len();
    // the state carries the model's own values: the same energy as without them
    let mut bare = state.clone();
    bare.clamps.scalars = ModelScalars::default();
    assert!(
        (energy.energy(&state) - energy.energy(&bare)).abs() < 1e-12 * energy.energy(&bare).abs()
    );
    for p in Parameter::MODEL {
        let (mut exact, mut work) = (vec![0.0; n], vec![0.0; n]);
        energy.parameter_derivative(&state, p, &mut exact, &mut work);
        let v0 = p.value(&state.clamps);
        let eps = 1e-4 * v0.abs().max(1.0);
        let gradient_at = |v: f64| {
            let mut s = state.clone();
            s.clamps = p.with(&state.clamps, v);
            let mut g = vec![0.0; n];
            energy.gradient(&s, &mut g);
            g
        };
        let (plus, minus) = (gradient_at(v0 + eps), gradient_at(v0 - eps));
        let fd: Vec<f64> = plus
            .iter()
            .zip(&minus)
            .map(|(a, b)| (a - b) / (2.0 * eps))
            .collect();
        let diff: f64 = fd
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        let size: f64 = exact.iter().map(|b| b * b).sum::<f64>().sqrt();
        // ∇E is affine in each scalar: central differences are exact but for rounding
        assert!(size > 1e-3, "{p:?}: derivative vanishes");
        assert!(diff < 1e-8 * size, "{p:?}: relative error {}", diff / size);
    }
}

/// The straight rod twisted by one turn between clamps a length apart,
/// followed up in K3 at N segments: the located loss of stability.
fn k3_at_loss_of_stability(n: usize) -> f64 {
    let text = format!(
        "[model]\nsegments = {n}\nK2 = 1.0\nK3 = 1.0\n\
         [clamps]\nz_star = 1.0\ndelta = 0.0\nphi_over_2pi = 1.0\n\
         [continuation]\nparameter = \"K3\"\nrange = [1.0, 2.0]\ndirection = \"up\"\nstep = 0.02\nmax_step = 0.05\n\
         [stability]\neigenvalues = 2\n"
    );
    let scene = Scene::parse(&text).unwrap();
    let (eqs, events) = run(&scene);
    assert!(eqs.len() > 5);
    let lost = events
        .iter()
        .find(|e| e.kind == EventKind::Stability)
        .unwrap_or_else(|| panic!("no loss of stability: {events:?}"));
    let k3 = Parameter::K3.value(lost.clamps.as_ref().unwrap_or(&scene.clamps()));
    assert!(k3.is_finite(), "{lost:?}");
    k3
}

#[test]
fn a_branch_in_k3_finds_greenhill_s_twisting_instability_at_second_order() {
    // u3 = φ = 2π, so the twisting moment K3 φ reaches Greenhill's 2 x₁ at K3 = 2x₁/2π
    let expected = greenhill_constant() / (2.0 * std::f64::consts::PI);
    let found: Vec<f64> = [25, 50, 100]
        .into_iter()
        .map(k3_at_loss_of_stability)
        .collect();
    let err: Vec<f64> = found
        .iter()
        .map(|k| (k - expected).abs() / expected)
        .collect();
    eprintln!(
        "K3 at the loss of stability, N = 25, 50, 100: {found:?} vs {expected}: errors {err:?}"
    );
    assert!(err[2] < 2e-3, "{found:?} vs {expected}");
    for k in 0..2 {
        let order = (err[k] / err[k + 1]).log2();
        assert!(order > 1.8 && order < 2.3, "errors {err:?}, order {order}");
    }
}
