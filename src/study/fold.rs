//! The discrete rod's own fold (limit point) near a given shape: where a
//! branch of equilibria turns back in a parameter. A continuum fold and the
//! discrete rod's lie O(h²) apart, so at the continuum fold's parameter value
//! the discrete rod may have no equilibrium at all; the discrete fold is
//! found instead by following the discrete branch from a nearby equilibrium
//! until the parameter turns back, located by bisection in arclength. Its
//! parameter value then converges as h², like any other quantity.

use crate::analysis::equilibrium::{Equilibrium, Measure, analyse};
use crate::analysis::event::EventKind;
use crate::model::rod::{Law, Parameter, RodState};
use crate::scene::Scene;
use crate::solve::continuation::ContinuationSettings;
use crate::solve::outcome::{FloorCheck, SolveReport};
use crate::study::branch::{BranchOptions, BranchRun};
use crate::study::error::{Context, Result, fail};
use crate::study::start::state_near_start;

/// Offsets of the parameter (relative to 1 + |value|) tried in turn for an
/// equilibrium of the discrete rod near the fold: its fold may lie on either
/// side of the given value, by up to its discretisation error.
const OFFSETS: [f64; 11] = [
    0.0, 1e-4, -1e-4, 3e-4, -3e-4, 1e-3, -1e-3, 3e-3, -3e-3, 1e-2, -1e-2,
];
/// Half the width of the parameter window searched for the fold (relative).
const WINDOW: f64 = 0.03;

/// A discrete rod at its fold.
#[derive(Clone, Debug)]
pub struct DiscreteFold {
    /// The parameter in which the branch turns back.
    pub parameter: Parameter,
    /// Its value at the fold.
    pub value: f64,
    /// The state there.
    pub state: RodState,
    /// The equilibrium there (its eigenvalues at the scene's
    /// `[stability] eigenvalues`; one of them vanishes).
    pub equilibrium: Equilibrium,
}

/// The fold in `parameter` of the discrete rod at `segments` (the scene's own
/// N if None) nearest the scene's parameter value, from the scene's initial
/// shape: an equilibrium is solved at that value (or, where there is none,
/// a little to either side), and its branch followed both ways within a
/// window of ±3 % until the parameter turns back.
pub fn fold_near(
    scene: &Scene,
    segments: Option<usize>,
    parameter: Parameter,
) -> Result<DiscreteFold> {
    let given = parameter.value(&scene.clamps());
    if !given.is_finite() {
        fail!(
            "the fold's parameter {}: the scene does not set it",
            parameter.name()
        );
    }
    let scale = 1.0 + given.abs();
    // Newton only: minimisation would slide off the saddle side of a fold
    let mut found = None;
    let mut last_error = None;
    for offset in OFFSETS {
        let mut near = scene.clone();
        near.set(parameter, given + offset * scale);
        match state_near_start(&near, segments, false) {
            // Newton from a shape with no equilibrium near it may wander to
            // another branch: only an equilibrium near the shape will do
            Ok(x) if near_start(scene, &x.0, &x.1) => {
                found = Some(x);
                break;
            }
            Ok(_) => {}
            Err(e) => last_error = Some(e),
        }
    }
    let Some((mut newton, state, _)) = found else {
        return match last_error {
            Some(e) => Err(e).context("no equilibrium of the discrete rod near the fold"),
            None => fail!("no equilibrium of the discrete rod near the fold's shape"),
        };
    };
    let settings = match &scene.continuation {
        Some(c) if c.parameter == parameter => c.settings(),
        _ => ContinuationSettings::default(),
    };
    let measure = scene.measure();
    let options = BranchOptions {
        parameter,
        range: [given - WINDOW * scale, given + WINDOW * scale],
        settings,
        locate_events: true,
        switch_branches: false,
        // the accepted points need no spectrum: only the fold's is measured
        measure: Measure {
            eigenvalues: 0,
            ..measure.clone()
        },
        stop_at: vec![EventKind::Fold],
    };
    let settings_tolerance = options.settings.tolerance;
    let mut reached = 0usize;
    let mut ignore = crate::study::observer::equilibria(|_: Equilibrium| {
        reached += 1;
        Ok(())
    });
    let mut run = BranchRun::new(&mut newton, options, &mut ignore, 0);
    run.follow(state, &[1.0, -1.0])
        .context("following the discrete branch to its fold")?;
    let nearest = run
        .events
        .iter()
        .zip(&run.located)
        .filter(|(e, _)| e.kind == EventKind::Fold)
        .min_by(|a, b| {
            let d = |s: &RodState| (parameter.value(&s.clamps) - given).abs();
            d(a.1).total_cmp(&d(b.1))
        })
        .map(|(_, s)| s.clone());
    let kinds: Vec<String> = run
        .events
        .iter()
        .map(|e| format!("{} ({})", e.kind.name(), e.detail))
        .collect();
    drop(run);
    let Some(at) = nearest else {
        fail!(
            "the discrete branch has no fold in {} within {} ± {:.0e} ({reached} points followed; events [{}])",
            parameter.name(),
            given,
            WINDOW * scale,
            kinds.join(", ")
        );
    };
    // the located point is the corrector's, converged by the one test of
    // convergence (for the constrained laws on the KKT residual, whose
    // constraint forces the energy's gradient alone does not see)
    let check = FloorCheck::at(&newton.energy, &at);
    if newton.energy.model.law == Law::Kirchhoff && !check.passes(settings_tolerance) {
        fail!(
            "the located fold is no equilibrium: relative gradient {:.3e}",
            check.rel
        );
    }
    let report = SolveReport::of_corrector(0, check.rel, newton.energy.energy(&at));
    let equilibrium = analyse(&mut newton, &at, &report, &measure)?;
    Ok(DiscreteFold {
        parameter,
        value: parameter.value(&at.clamps),
        state: at,
        equilibrium,
    })
}

/// Relative distance of an equilibrium's shooting unknowns from the start's
/// within which it is taken for the start's branch near its fold (there the
/// state moves as the square root of the parameter's offset).
const NEAR_START: f64 = 0.15;

/// Whether the equilibrium `state` lies near the scene's shooting start.
fn near_start(
    scene: &Scene,
    newton: &crate::solve::minimizer::Minimizer,
    state: &RodState,
) -> bool {
    distance_from_start(scene, newton, state) <= NEAR_START
}

fn distance_from_start(
    scene: &Scene,
    newton: &crate::solve::minimizer::Minimizer,
    state: &RodState,
) -> f64 {
    let i = &scene.initial;
    let start: Option<[f64; 6]> = match (i.n0, i.m0, i.u1_0, i.m2_0, i.u3_0) {
        (Some(n), Some(m), _, _, _) => Some([n[0], n[1], n[2], m[0], m[1], m[2]]),
        (Some(n), None, Some(a), Some(b), Some(c)) => Some([n[0], n[1], n[2], a, b, c]),
        _ => None,
    };
    let Some(start) = start else {
        return 0.0;
    };
    let found = crate::study::polish::discrete_unknowns(&newton.energy.model, state);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let diff: Vec<f64> = (0..6).map(|k| found[k] - start[k]).collect();
    norm(&diff) / norm(&start)
}
