//! The starting equilibrium of a scene: its initial shape (straight, shooting,
//! double ring, trefoil, or a restart state) relaxed by the minimiser.

use crate::analysis::class::is_trefoil;
use crate::analysis::equilibrium::{Conformation, Equilibrium, analyse};
use crate::model::energy::{RodEnergy, Terms};
use crate::model::rod::{Clamps, Law, RodModel, RodState};
use crate::model::shooting::ShootingSolution;
use crate::model::strip_shooting::{StripProblem, StripUnknowns};
use crate::scene::{InitialShape, InitialSpec, LoopFacing, Scene, SceneError};
use crate::solve::continuum::shooting::refine_shooting_loaded;
use crate::solve::minimizer::Minimizer;
use crate::solve::outcome::SolveReport;
use crate::study::error::{Context, Result, fail};
use nalgebra::Vector3;
use std::borrow::Cow;

/// The initial state a scene asks for, at N segments.
pub fn initial_state(scene: &Scene, model: &RodModel) -> Result<RodState> {
    let clamps = scene.clamps();
    let n = model.segments;
    let init = &scene.initial;
    if init.from_recording.is_some() {
        return restart_state(init, "initial.from_recording", n, clamps);
    }
    match init.shape {
        InitialShape::Straight => Ok(straight(n, clamps, init.bump)),
        InitialShape::DoubleRing => Ok(double_ring(n, clamps)),
        InitialShape::Trefoil => trefoil(scene, n, clamps),
        InitialShape::Shooting => shooting(init, model, clamps),
        InitialShape::File => restart_state(init, "initial.file", n, clamps),
    }
}

/// Straight from clamp to clamp, uniformly twisted by φ, with an optional
/// clamped-clamped bump b (1 − cos 2πs)/2 to seed buckling.
fn straight(n: usize, clamps: Clamps, bump: Option<[f64; 3]>) -> RodState {
    match bump {
        None => RodState::straight(n, clamps),
        Some(b) if !clamps.is_paper() => {
            let b = Vector3::from(b);
            RodState::from_curve(
                n,
                clamps,
                move |s| {
                    clamps.hermite(s) + b * (0.5 * (1.0 - (2.0 * std::f64::consts::PI * s).cos()))
                },
                move |s| clamps.blended_d1(s),
            )
        }
        Some(b) => {
            let (end, phi, b) = (clamps.end_point(), clamps.phi, Vector3::from(b));
            RodState::from_curve(
                n,
                clamps,
                move |s| end * s + b * (0.5 * (1.0 - (2.0 * std::f64::consts::PI * s).cos())),
                move |s| Vector3::new((phi * s).cos(), (phi * s).sin(), 0.0),
            )
        }
    }
}

/// A circle of circumference 1/2 traced twice in the (y, z) plane, bent
/// about d1 = e1 everywhere (paper Sec. 6); the clamps are the scene's, so
/// small z*, δ, 2π − φ start the unfolding directly.
fn double_ring(n: usize, clamps: Clamps) -> RodState {
    let r = 1.0 / (4.0 * std::f64::consts::PI);
    RodState::from_curve(
        n,
        clamps,
        move |s| {
            let a = 4.0 * std::f64::consts::PI * s;
            Vector3::new(0.0, -r * (1.0 - a.cos()), r * a.sin())
        },
        |_| Vector3::x(),
    )
}

/// The open trefoil tied around the rays, uniformly twisted with the whole
/// turns that give the asked link (`initial.link`, default 3); an error
/// naming the field where the guide curve is not a trefoil at these clamps.
fn trefoil(scene: &Scene, n: usize, clamps: Clamps) -> Result<RodState> {
    let mut state = RodState::from_curve(
        n,
        clamps,
        crate::model::trefoil::trefoil_centreline(clamps.end_point()),
        |_| Vector3::x(),
    );
    // m_i = c at every vertex, n c = φ + reference twist at the end
    let target = scene.initial.link.unwrap_or(3) as f64 + clamps.phi_over_2pi();
    let rt = state.reference_twist[n];
    let set = |state: &mut RodState, turns: f64| {
        let c = (clamps.phi + rt + 2.0 * std::f64::consts::PI * turns) / n as f64;
        for j in 1..n {
            state.theta[j] = j as f64 * c;
        }
        state.reference_twist[n] = rt + 2.0 * std::f64::consts::PI * turns;
    };
    set(&mut state, 0.0);
    let shape = Conformation::of(&state, &scene.measure());
    let alexander = shape.knot.as_ref().map(|k| k.alexander.clone());
    if !alexander.as_deref().is_some_and(is_trefoil) {
        return Err(SceneError::Invalid {
            field: "initial.shape",
            reason: format!(
                "\"trefoil\": at z* = {}, δ = {} the guide curve's ray closure is \
                 not a trefoil (Alexander polynomial {:?}); start from the paper's clamps \
                 (z* ≈ 0.115, δ ≈ 0.05) and load from there",
                clamps.z_star, clamps.delta, alexander
            ),
        }
        .into());
    }
    let turns = (target - state.twist() - shape.writhe).round();
    set(&mut state, turns);
    Ok(state)
}

/// The continuum solution integrated (A.2) from n(0), m(0), refined first on
/// the s = 1 boundary conditions if asked.
fn shooting(init: &InitialSpec, model: &RodModel, clamps: Clamps) -> Result<RodState> {
    if let Law::Strip { regularisation } = model.law {
        return strip_shooting(init, model, clamps, regularisation);
    }
    let (mut n0, mut m0) = (
        Vector3::from(init.n0.context("initial.n0 missing")?),
        Vector3::from(init.m0.context("initial.m0 missing")?),
    );
    let intervals = init.steps.map_or(20_000, |s| s as usize);
    let (weight, natural) = (Vector3::from(model.weight), &model.natural_strains);
    if init.refine {
        (n0, m0) = refine_shooting_loaded(n0, m0, model.k2, model.k3, (weight, natural), &clamps)
            .context("initial.refine: shooting refinement did not converge")?;
    }
    let sol = ShootingSolution::integrate_from(
        &clamps,
        n0,
        m0,
        [model.k2, model.k3],
        (weight, natural.clone()),
        intervals,
    )
    .context("initial.n0, initial.m0: integrating the shooting data")?;
    Ok(RodState::from_curve(
        model.segments,
        clamps,
        |s| sol.position(s),
        |s| sol.d1(s),
    ))
}

/// The strip's continuum solution (A.1 with 4.1 and 4.3) integrated from the
/// paper's unknowns n(0), u1(0), m2(0), u3(0), refined first if asked.
fn strip_shooting(
    init: &InitialSpec,
    model: &RodModel,
    clamps: Clamps,
    regularisation: f64,
) -> Result<RodState> {
    let missing = |field: &'static str| SceneError::Invalid {
        field,
        reason: "required for shape = \"shooting\" of a strip".into(),
    };
    let mut p = StripUnknowns {
        n0: Vector3::from(init.n0.ok_or_else(|| missing("initial.n0"))?),
        u1: init.u1_0.ok_or_else(|| missing("initial.u1_0"))?,
        m2: init.m2_0.ok_or_else(|| missing("initial.m2_0"))?,
        u3: init.u3_0.ok_or_else(|| missing("initial.u3_0"))?,
    };
    let problem = StripProblem {
        regularisation,
        weight: Vector3::from(model.weight),
        natural: model.natural_strains.clone(),
        clamps,
        intervals: init.steps.map_or(20_000, |s| s as usize),
    };
    if init.refine {
        p = problem
            .refine(p)
            .context("initial.refine: strip shooting refinement")?;
    }
    let sol = problem
        .integrate(&p)
        .context("initial.n0, initial.u1_0, initial.m2_0, initial.u3_0: integrating the strip's shooting data")?;
    Ok(RodState::from_curve(
        model.segments,
        clamps,
        |s| sol.position(s),
        |s| sol.d1(s),
    ))
}

/// The restart state of `[initial]` (read from `field`'s file when the scene
/// was loaded) at the scene's clamps, checked to have N segments.
fn restart_state(
    init: &InitialSpec,
    field: &'static str,
    n: usize,
    clamps: Clamps,
) -> Result<RodState> {
    let Some(state) = &init.state else {
        fail!(
            "{field}: the state was not read (scenes with restart states are read by Scene::load)"
        );
    };
    if state.segments() != n
        || state.theta.len() != n + 1
        || state.reference.len() != n + 1
        || state.reference_twist.len() != n + 1
    {
        fail!(
            "{field}: state has {} segments, model.segments is {n}",
            state.segments()
        );
    }
    let mut state = state.clone();
    state.set_clamps(clamps);
    Ok(state)
}

/// The scene's starting equilibrium at N segments (the scene's if None): its
/// initial shape relaxed by the minimiser, with the minimiser that found it.
pub fn starting_equilibrium(
    scene: &Scene,
    segments: Option<usize>,
) -> Result<(Minimizer, RodState, SolveReport)> {
    let lab = in_the_lab(scene, segments)?;
    let scene = &*lab;
    let (model, mut newton) = minimizer(scene, segments);
    if scene.initial.shape == InitialShape::DoubleRing {
        // unfold the double ring quasi-statically: straight from its own
        // clamps (0, 0, 2π) to the scene's
        let ring = Clamps::new(0.0, 0.0, 1.0);
        let target = scene.clamps();
        let mut state = initial_state(scene, &model)?;
        state.set_clamps(ring);
        // traced with the scene's clamps, the ring carries their φ as twist:
        // far from its own φ/2π = 1 it does not relax
        let mut report = newton
            .minimize(&mut state, &scene.solver)
            .with_context(|| {
                format!(
                    "the double ring (z* = δ = 0, φ/2π = 1) did not relax from the twist of \
                     clamps.phi_over_2pi = {}: it is unfolded only to clamps near its own \
                     (start nearer, or from another shape)",
                    target.phi_over_2pi()
                )
            })?;
        let steps = scene.initial.steps.map_or(40, |s| s as usize);
        for k in 1..=steps {
            let f = k as f64 / steps as f64;
            let c = Clamps {
                z_star: f * target.z_star,
                delta: f * target.delta,
                phi: ring.phi + f * (target.phi - ring.phi),
                scalars: target.scalars,
                ..ring
            };
            let step = crate::study::loading::move_clamps(&mut newton, &state, c, &scene.solver)
                .with_context(|| {
                    format!(
                        "unfolding the double ring (z* = δ = 0, φ/2π = 1) to clamps.z_star = {}, \
                         clamps.delta = {}, clamps.phi_over_2pi = {}: step {k} of {steps} failed \
                         (the ring may not unfold that far: start nearer, or from another shape)",
                        target.z_star,
                        target.delta,
                        target.phi_over_2pi()
                    )
                })?;
            (state, report) = (step.state, step.report);
        }
        return Ok((newton, state, report));
    }
    let mut state = initial_state(scene, &model)?;
    check_start(scene, &newton.energy, &state)?;
    let report = newton
        .minimize(&mut state, &scene.solver)
        .context("Newton minimisation")?;
    Ok((newton, state, report))
}

/// The scene with its gravity fixed in the lab: where `[load] major_loop`
/// asks for gravity along (down) or against (up) the knot's major loop, its
/// direction is measured once on the weightless start at the scene's
/// clamps ([`major_loop_direction`]) and written into `load.direction`, so
/// that it stays fixed while the clamps move (the lab's gravity does not
/// turn with the knot). Any other scene is returned as it is.
pub fn in_the_lab(scene: &Scene, segments: Option<usize>) -> Result<Cow<'_, Scene>> {
    let Some(facing) = scene.load.major_loop else {
        return Ok(Cow::Borrowed(scene));
    };
    let mut weightless = scene.clone();
    weightless.load.weight = 0.0;
    weightless.load.major_loop = None;
    let (_, state, _) = starting_equilibrium(&weightless, segments)
        .context("the weightless start, whose major loop gives gravity's direction")?;
    let Some(u) = major_loop_direction(&state) else {
        fail!(
            "load.major_loop: the weightless start's centreline has its centroid on the \
             clamps' axis, so no major loop points anywhere (use load.direction)"
        );
    };
    let g = match facing {
        LoopFacing::Down => u,
        LoopFacing::Up => -u,
    };
    let mut lab = scene.clone();
    lab.load.direction = g.into();
    lab.load.major_loop = None;
    Ok(Cow::Owned(lab))
}

/// The direction of a knot's major loop: the unit vector from the clamps'
/// axis (the line through the two clamps' points) to the centroid of the
/// centreline, normal to the axis; None where the centroid lies on it.
pub fn major_loop_direction(state: &RodState) -> Option<Vector3<f64>> {
    let (points, _) = state.centreline();
    let (mut sum, mut length) = (Vector3::zeros(), 0.0);
    for w in points.windows(2) {
        let l = (w[1] - w[0]).norm();
        sum += 0.5 * l * (w[0] + w[1]);
        length += l;
    }
    let centroid = sum / length;
    let (a, b) = (state.start_point(), state.end_point());
    let axis = (b - a).try_normalize(1e-12).unwrap_or_else(Vector3::z);
    let off = centroid - a;
    let across = off - off.dot(&axis) * axis;
    across.try_normalize(1e-9 * length)
}

/// The scene field a start shape comes from.
fn start_field(scene: &Scene) -> &'static str {
    let init = &scene.initial;
    if init.from_recording.is_some() {
        return "initial.from_recording";
    }
    match init.shape {
        InitialShape::Straight if init.bump.is_some() => "initial.bump",
        InitialShape::Straight | InitialShape::DoubleRing | InitialShape::Trefoil => {
            "initial.shape"
        }
        InitialShape::Shooting if scene.model.kind == crate::scene::ModelKind::Strip => {
            "initial.n0, initial.u1_0, initial.m2_0, initial.u3_0"
        }
        InitialShape::Shooting => "initial.n0, initial.m0",
        InitialShape::File => "initial.file",
    }
}

/// A start the solver can begin from: finite coordinates (else the start's
/// field is named) and a finite energy and gradient (else the stiffnesses
/// that scale them are), so that no NaN surfaces later as a solver failure
/// naming no input.
fn check_start(scene: &Scene, energy: &RodEnergy, state: &RodState) -> Result<()> {
    let finite = state.nodes.iter().all(|x| x.iter().all(|v| v.is_finite()))
        && state.theta.iter().all(|v| v.is_finite())
        && state
            .reference
            .iter()
            .all(|x| x.iter().all(|v| v.is_finite()))
        && state.reference_twist.iter().all(|v| v.is_finite())
        && state.multipliers.iter().all(|v| v.is_finite());
    if !finite {
        fail!(
            "{}: the start shape has non-finite coordinates (an integration or a file past \
             f64's range): give smaller values",
            start_field(scene)
        );
    }
    let mut gradient = vec![0.0; energy.map.len()];
    let mut hessian = vec![0.0; energy.pattern.nnz()];
    let e = energy.hessian(state, &mut gradient, &mut hessian).energy;
    // the norm too: finite entries can still square past f64's range
    let norm = gradient.iter().map(|g| g * g).sum::<f64>();
    if !e.is_finite()
        || !norm.is_finite()
        || gradient.iter().any(|g| !g.is_finite())
        || hessian.iter().any(|h| !h.is_finite())
    {
        let m = &scene.model;
        fail!(
            "the start ({}) has a non-finite energy, gradient or Hessian with model.K2 = {}, model.K3 = {}, \
             stretching stiffness {:.3e} (model.stretching_stiffness or model.rod_diameter): \
             the start is too far stretched or the stiffnesses too large for f64",
            start_field(scene),
            m.k2,
            m.k3,
            energy.model.stretching_stiffness
        );
    }
    Ok(())
}

/// The scene's model at N segments and the minimiser of its energy (with
/// its contact, if any).
fn minimizer(scene: &Scene, segments: Option<usize>) -> (RodModel, Minimizer) {
    let model = scene.rod_model(segments);
    let mut newton = Minimizer::new(RodEnergy::with_ends(
        model.clone(),
        Terms::ALL,
        scene.clamps().ends,
    ));
    newton.contact = scene.contact_model();
    (model, newton)
}

/// The equilibrium nearest the scene's initial shape at N segments, by
/// Newton's method on ∇E = 0 for a Kirchhoff rod (a saddle too: an unstable
/// solution given as a start stays itself, where minimisation would leave
/// it); by minimisation if Newton does not converge from there, and for the
/// laws with the constraint u2 = 0 (their SQP).
pub fn equilibrium_near_start(scene: &Scene, segments: Option<usize>) -> Result<Equilibrium> {
    let (mut newton, state, report) = state_near_start(scene, segments, true)?;
    Ok(analyse(&mut newton, &state, &report, &scene.measure())?)
}

/// The equilibrium nearest the scene's initial shape, with the solver that
/// found it: by Newton on ∇E = 0 for a Kirchhoff rod, then (if `minimise`
/// allows it) by minimisation, which may slide off a saddle to another
/// equilibrium; by the SQP for the laws with the constraint u2 = 0.
pub fn state_near_start(
    scene: &Scene,
    segments: Option<usize>,
    minimise: bool,
) -> Result<(Minimizer, RodState, SolveReport)> {
    let (model, mut newton) = minimizer(scene, segments);
    let start = initial_state(scene, &model)?;
    check_start(scene, &newton.energy, &start)?;
    let mut state = start.clone();
    // the constrained laws (u2 = 0) converge by their SQP, not by Newton
    let free = model.law == Law::Kirchhoff && newton.contact.is_none();
    let newton_result = free.then(|| newton.find_equilibrium(&mut state, &scene.solver));
    let report = match newton_result {
        Some(Ok(r)) if r.converged => r,
        Some(Err(e)) if !minimise => return Err(e).context("Newton on the gradient"),
        Some(Ok(r)) if !minimise => fail!(
            "Newton on the gradient did not converge (relative gradient {:.3e})",
            r.gradient_norm
        ),
        _ => {
            state = start;
            newton
                .minimize(&mut state, &scene.solver)
                .context("Newton minimisation")?
        }
    };
    Ok((newton, state, report))
}

/// Solve a scene's single equilibrium at N segments (the scene's own N if None).
pub fn solve_scene(scene: &Scene, segments: Option<usize>) -> Result<Equilibrium> {
    let (mut newton, state, report) = starting_equilibrium(scene, segments)?;
    Ok(analyse(&mut newton, &state, &report, &scene.measure())?)
}
