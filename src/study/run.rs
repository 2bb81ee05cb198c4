//! Running a scene: one equilibrium, or branches of equilibria (continuation,
//! optionally swept over a second parameter).

use crate::analysis::equilibrium::analyse;
use crate::analysis::event::{Event, label_events};
use crate::model::rod::{Parameter, RodState};
use crate::scene::{Direction, Scene};
use crate::solve::continuation::{ContinuationSettings, Tracer};
use crate::solve::minimizer::Minimizer;
use crate::study::branch::{BranchOptions, BranchRun};
use crate::study::error::{Context, Result, fail};
use crate::study::loading::run_loading;
use crate::study::observer::Observer;
use crate::study::start::starting_equilibrium;

/// Move an equilibrium to `parameter = target` by continuation in that
/// parameter (through folds if need be), ending with a Newton solve at exactly
/// the target.
pub fn continue_to(
    newton: &mut Minimizer,
    state: RodState,
    parameter: Parameter,
    target: f64,
    settings: &ContinuationSettings,
) -> Result<RodState> {
    let mut tracer = Tracer::new(newton, parameter, settings.clone());
    let now = parameter.value(&state.clamps);
    if (target - now).abs() < 1e-14 {
        return Ok(state);
    }
    let sign = (target - now).signum();
    let mut a = tracer.start(state, sign).context("tangent at the start")?;
    let mut step = settings.step_control();
    for _ in 0..settings.max_points {
        let pa = tracer.parameter_of(&a.state);
        // the one step rule of branches: a hairpin is refused, so the
        // path turns back at a fold as a branch does
        let Some((b, ds)) = tracer.advance(&a, &mut step) else {
            fail!(
                "could not reach {} = {target}: branch lost at {pa}",
                parameter.name()
            );
        };
        let pb = tracer.parameter_of(&b.state);
        if (pb - target) * (pa - target) <= 0.0 {
            // the point of the branch nearest the target, then Newton at fixed
            // parameter: a corrector along the parameter axis
            let below = (pa - target).signum();
            let near = tracer
                .locate(&a, ds, &mut |t, p| {
                    (t.parameter_of(&p.state) - target).signum() == below
                })
                .context("locating the target value")?;
            let p = tracer
                .settle_at_parameter(&near, target)
                .context("Newton at the target value")?;
            return Ok(p.state);
        }
        a = b;
    }
    fail!(
        "could not reach {} = {target} within {} steps",
        parameter.name(),
        settings.max_points
    )
}

/// Run a scene at N segments (the scene's if None): every equilibrium and
/// event goes to `observer` as soon as it is computed; returns the labelled
/// events.
pub fn run_scene(
    scene: &Scene,
    segments: Option<usize>,
    observer: &mut dyn Observer,
) -> Result<Vec<Event>> {
    let (mut newton, mut state, report) = starting_equilibrium(scene, segments)?;
    let measure = scene.measure();
    if !scene.loading.is_empty() {
        let mut events = run_loading(
            &mut newton,
            state,
            &scene.loading,
            &scene.solver,
            &measure,
            observer,
        )?;
        label_events(&mut events);
        return Ok(events);
    }
    let Some(spec) = &scene.continuation else {
        observer.equilibrium(analyse(&mut newton, &state, &report, &measure)?)?;
        return Ok(vec![]);
    };
    if !spec.parameter.value(&state.clamps).is_finite() {
        // a state that does not carry the model scalar the branch follows
        fail!(
            "continuation.parameter: the start state has no value of {} (a start that dropped the scene's model scalars)",
            spec.parameter.name()
        );
    }
    let settings = spec.settings();
    let options = BranchOptions {
        parameter: spec.parameter,
        range: spec.range,
        settings: settings.clone(),
        locate_events: spec.locate_events,
        switch_branches: spec.switch_branches,
        measure,
        stop_at: spec.stop_at.clone(),
    };
    let directions: &[f64] = match spec.direction {
        Direction::Up => &[1.0],
        Direction::Down => &[-1.0],
        Direction::Both => &[1.0, -1.0],
    };
    let stops: Vec<Option<(Parameter, f64)>> = match &scene.sweep {
        Some(sw) => sw.values.iter().map(|v| Some((sw.parameter, *v))).collect(),
        None => vec![None],
    };
    let newton_model = newton.energy.model.clone();
    let mut events = Vec::new();
    let mut first_branch = 0;
    for stop in stops {
        if let Some((parameter, value)) = stop {
            state = continue_to(&mut newton, state, parameter, value, &settings)
                .with_context(|| format!("reaching {} = {value}", parameter.name()))?;
        }
        let mut run = BranchRun::new(&mut newton, options.clone(), &mut *observer, first_branch);
        run.follow(state.clone(), directions)?;
        first_branch = run.next_branch();
        if spec.polish {
            crate::study::polish::polish_events(
                &newton_model,
                spec.parameter,
                &options.measure,
                &mut run.events,
                &run.located,
            );
        }
        events.extend(run.events);
    }
    label_events(&mut events);
    Ok(events)
}
