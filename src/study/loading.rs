//! Quasi-static loading: what a hand does in the lab. The clamp moves along a
//! piecewise-linear path in (z*, δ, φ) in small steps; after each step the
//! energy is minimised from the previous equilibrium. When that state stops
//! being a minimum the rod jumps: the jump is detected (loss of stability of
//! the carried state, large change of shape or of link) and recorded.

use crate::analysis::equilibrium::{Equilibrium, Measure, analyse, analyse_from, walls};
use crate::analysis::event::{Event, EventKind};
use crate::linalg::eigen::lowest_eigenvalues;
use crate::model::rod::{Clamps, RodState};
use crate::scene::LoadingSpec;
use crate::solve::minimizer::Minimizer;
use crate::solve::outcome::{SolveError, SolveReport, SolverSettings};
use crate::solve::root::{Bracket, Probe, bisect};
use crate::study::error::{Context, Result, StudyError, fail};
use crate::study::observer::Observer;

/// A step is a jump when the minimiser lands farther than this (rod lengths)
/// from the first-order prediction (and than half the predicted move).
pub const JUMP_DISPLACEMENT: f64 = 0.02;
/// A link change beyond this (other than the clamp's own turn) is a crossing
/// of the centreline through itself.
pub const JUMP_LINK: f64 = 0.5;

/// Negative eigenvalue count and lowest mode of the Hessian at `state`.
fn inertia(newton: &mut Minimizer, state: &RodState, want_mode: bool) -> Result<(usize, Vec<f64>)> {
    let e = &newton.energy;
    let mut g = vec![0.0; e.map.len()];
    let mut v = vec![0.0; e.pattern.nnz()];
    e.hessian(state, &mut g, &mut v);
    let sp = lowest_eigenvalues(
        &e.pattern,
        &v,
        None,
        usize::from(want_mode),
        &mut newton.ldlt,
    )?;
    Ok((
        sp.negative_count,
        sp.vectors.into_iter().next().unwrap_or_default(),
    ))
}

/// The Newton iterations a loading step may still take
/// (`loading.step_iterations`), spent by every solve of the step: its move,
/// the escapes from saddles, the bisections that locate a jump, a wall or a
/// lost contact. A path that cannot settle stops with an error naming the
/// step instead of running on.
pub struct Allowance {
    left: usize,
    budget: usize,
}

impl Allowance {
    /// `budget` iterations.
    pub fn new(budget: usize) -> Self {
        Allowance {
            left: budget,
            budget,
        }
    }

    /// No budget beyond each solve's own `max_iterations`.
    pub fn unlimited() -> Self {
        Allowance::new(usize::MAX)
    }

    /// Minimise from `state` with at most the iterations left.
    fn minimize(
        &mut self,
        newton: &mut Minimizer,
        state: &mut RodState,
        settings: &SolverSettings,
    ) -> Result<SolveReport> {
        if self.left == 0 {
            return Err(self.spent());
        }
        let capped = settings.max_iterations > self.left;
        let within = SolverSettings {
            max_iterations: settings.max_iterations.min(self.left),
            ..*settings
        };
        match newton.minimize(state, &within) {
            Ok(r) => {
                self.left -= r.iterations.min(self.left);
                Ok(r)
            }
            Err(SolveError::NotConverged { .. }) if capped => {
                self.left = 0;
                Err(self.spent())
            }
            Err(e) => Err(e.into()),
        }
    }

    fn spent(&self) -> StudyError {
        StudyError::Failed(format!(
            "the step ran out of its budget of {} Newton iterations (loading.step_iterations, \
             default {} × solver.max_iterations) without settling",
            self.budget,
            LoadingSpec::DEFAULT_STEP_BUDGET
        ))
    }
}

/// Minimise from `state` and make sure the result is a minimum: from a saddle,
/// step off along the unstable mode (both ways tried, the lower energy kept).
pub fn minimize_to_stable(
    newton: &mut Minimizer,
    state: &mut RodState,
    settings: &SolverSettings,
) -> Result<SolveReport> {
    settle(newton, state, settings, &mut Allowance::unlimited())
}

/// [`minimize_to_stable`] within `allowance`.
fn settle(
    newton: &mut Minimizer,
    state: &mut RodState,
    settings: &SolverSettings,
    allowance: &mut Allowance,
) -> Result<SolveReport> {
    let mut report = allowance.minimize(newton, state, settings)?;
    for _ in 0..=8 {
        // held by contacts, it is a minimum of the constrained problem (its
        // stability is judged on the contacts' tangent space by `analyse`)
        if !report.contacts.is_empty() {
            return Ok(report);
        }
        let (neg, mode) = inertia(newton, state, true)?;
        if neg == 0 {
            return Ok(report);
        }
        let map = newton.energy.map;
        let largest = (0..mode.len())
            .filter(|&d| map.is_translation(d))
            .map(|d| mode[d].abs())
            .fold(0.0, f64::max);
        if largest == 0.0 {
            fail!("saddle with no translational unstable mode");
        }
        let mut best: Option<(f64, RodState, SolveReport)> = None;
        for sign in [1.0, -1.0] {
            let kick: Vec<f64> = mode.iter().map(|x| sign * 1e-3 * x / largest).collect();
            let mut trial = state.displaced(&map, &kick);
            let r = allowance.minimize(newton, &mut trial, settings)?;
            if best.as_ref().is_none_or(|b| r.energy < b.0) {
                best = Some((r.energy, trial, r));
            }
        }
        let (_, s, r) = best.unwrap();
        *state = s;
        report = r;
    }
    fail!("could not reach a stable equilibrium from a saddle")
}

fn eq_clamps(eq: &crate::analysis::equilibrium::Equilibrium) -> Clamps {
    eq.state.clamps
}

/// The equilibrium `state` moved to clamps `c` along its tangent (first order
/// in the clamp move); just the moved clamp if the Hessian is not definite.
fn predict(newton: &mut Minimizer, state: &RodState, c: Clamps) -> Result<RodState> {
    let e = &newton.energy;
    let n = e.map.len();
    let mut g = vec![0.0; n];
    let mut v = vec![0.0; e.pattern.nnz()];
    e.hessian(state, &mut g, &mut v);
    let velocity = state.clamps.velocity_to(&c, state);
    let mut dq = vec![0.0; n];
    e.gradient_parameter_derivative(state, &velocity, &mut dq);
    e.add_scalar_changes(state, &c, &mut dq);
    let mut moved = state.clone();
    moved.set_clamps(c);
    // with contact the free rod's tangent may run into an obstacle: only the
    // clamp moves, the minimiser (with the contact rows) does the rest
    if newton.contact.is_none()
        && newton.ldlt.factor(&v).is_ok()
        && newton.ldlt.negative_count() == 0
    {
        newton.ldlt.solve_in_place(&mut dq);
        dq.iter_mut().for_each(|x| *x = -*x);
        let map = newton.energy.map;
        Ok(moved.displaced(&map, &dq))
    } else {
        Ok(moved)
    }
}

/// Jumps are located along the path to this (clamp-parameter units: z*, δ in
/// rod lengths, φ in turns).
pub const JUMP_LOCATION: f64 = 1e-4;

/// One quasi-static step: the settled state, and whether it jumped.
pub struct Step {
    /// The settled state.
    pub state: RodState,
    /// How the minimiser got there.
    pub report: SolveReport,
    /// Distance from the first-order prediction.
    pub miss: f64,
    /// Whether it landed far from the prediction.
    pub jumped: bool,
}

/// Move the clamps of the equilibrium `state` to `c` and settle: first-order
/// prediction along the branch (dq = −H⁻¹ ∂_p∇E), then minimisation. A smooth
/// branch lands within second order of the prediction; a jump lands far away.
pub fn move_clamps(
    newton: &mut Minimizer,
    state: &RodState,
    c: Clamps,
    settings: &SolverSettings,
) -> Result<Step> {
    move_within(newton, state, c, settings, &mut Allowance::unlimited())
}

/// [`move_clamps`] within `allowance`.
fn move_within(
    newton: &mut Minimizer,
    state: &RodState,
    c: Clamps,
    settings: &SolverSettings,
    allowance: &mut Allowance,
) -> Result<Step> {
    let predicted = predict(newton, state, c)?;
    let predicted_move = predicted.largest_node_distance(state);
    let mut next = predicted.clone();
    let report = settle(newton, &mut next, settings, allowance)?;
    let miss = next.largest_node_distance(&predicted);
    Ok(Step {
        state: next,
        report,
        miss,
        jumped: miss > (0.5 * predicted_move).max(JUMP_DISPLACEMENT),
    })
}

/// Bisect the clamp move from the equilibrium `from` (where `same` holds) to
/// `to` (where it fails) down to [`JUMP_LOCATION`]: the last state where it
/// holds and the first clamps where it fails.
fn locate_on_path(
    newton: &mut Minimizer,
    allowance: &mut Allowance,
    from: &RodState,
    to: Clamps,
    settings: &SolverSettings,
    same: &mut dyn FnMut(&mut Minimizer, &Step) -> Result<bool>,
) -> Result<(RodState, Clamps)> {
    // the path's fraction t from `from` (t = 0) to `to` (t = 1)
    let at = |t: f64| from.clamps.lerp(&to, t);
    let b = bisect(
        0.0,
        1.0,
        |lo, hi| at(lo).gap(&at(hi)) <= JUMP_LOCATION,
        |t, b: &Bracket<RodState, Clamps>| {
            let mid = at(t);
            let lo = b.holds.as_ref().unwrap_or(from);
            let trial = move_within(newton, lo, mid, settings, allowance)?;
            Ok::<_, StudyError>(if same(newton, &trial)? {
                Probe::Holds(t, trial.state)
            } else {
                Probe::Fails(t, mid)
            })
        },
    )?;
    Ok((
        b.holds.unwrap_or_else(|| from.clone()),
        b.fails.unwrap_or(to),
    ))
}

/// An event of a loading path at clamps `c` (its `branch` is the path's leg).
fn path_event(kind: EventKind, c: &Clamps, twist: f64, leg: usize, detail: String) -> Event {
    Event::at(kind, c, twist, leg, detail)
}

/// Link change between two equilibria beyond the clamp's own turn.
fn link_jump(
    a: &crate::analysis::equilibrium::Equilibrium,
    b: &crate::analysis::equilibrium::Equilibrium,
) -> f64 {
    b.link - a.link - (eq_clamps(b).phi - eq_clamps(a).phi) / (2.0 * std::f64::consts::PI)
}

/// Run the loading path from `state` (an equilibrium at its clamps): every
/// equilibrium goes to `observer`; returns the jumps.
pub fn run_loading(
    newton: &mut Minimizer,
    mut state: RodState,
    path: &[LoadingSpec],
    settings: &SolverSettings,
    measure: &Measure,
    observer: &mut dyn Observer,
) -> Result<Vec<Event>> {
    let report = minimize_to_stable(newton, &mut state, settings)?;
    let mut eq = analyse(newton, &state, &report, measure)?;
    observer.equilibrium(eq.clone())?;
    let mut hand = Hand {
        newton,
        settings,
        measure,
        events: Vec::new(),
        allowance: Allowance::unlimited(),
    };
    for (leg, stage) in path.iter().enumerate() {
        let c0 = state.clamps;
        let mut target = Clamps {
            z_star: stage.z_star.unwrap_or(c0.z_star),
            delta: stage.delta.unwrap_or(c0.delta),
            phi: stage
                .phi_over_2pi
                .map_or(c0.phi, |p| 2.0 * std::f64::consts::PI * p),
            ..c0
        };
        for (p, v) in &stage.targets {
            target = p.with(&target, *v);
        }
        let steps = stage.steps as usize;
        for k in 1..=steps {
            hand.allowance = Allowance::new(stage.step_budget(settings));
            let f = k as f64 / steps as f64;
            let c = c0.lerp(&target, f);
            let at = Leg {
                from: &state,
                eq: &eq,
                to: c,
                leg,
                k,
            };
            let found = hand.events.len();
            let (step, next) = hand.advance(&at)?;
            if eq.walled != next.walled && !step.jumped {
                hand.locate_wall(&at)?;
            }
            if !eq.contacts.is_empty() && next.contacts.is_empty() {
                hand.locate_contact_loss(&at)?;
            }
            // the path's events as located (labels provisional), then the
            // equilibrium past them
            let mut labelled = hand.events.clone();
            crate::analysis::event::label_events(&mut labelled);
            for e in &labelled[found..] {
                observer.event(e)?;
            }
            observer.equilibrium(next.clone())?;
            state = step.state;
            eq = next;
        }
    }
    Ok(hand.events)
}

/// The hand that moves the clamp, and the events it has seen.
struct Hand<'n> {
    newton: &'n mut Minimizer,
    settings: &'n SolverSettings,
    measure: &'n Measure,
    events: Vec<Event>,
    /// What is left of the current step's iteration budget.
    allowance: Allowance,
}

/// One step of a loading path: from the equilibrium `eq` (state `from`) to
/// the clamps `to`, step `k` of leg `leg`.
struct Leg<'s> {
    from: &'s RodState,
    eq: &'s Equilibrium,
    to: Clamps,
    leg: usize,
    k: usize,
}

impl Leg<'_> {
    fn context(&self) -> String {
        format!("loading leg {}, step {}", self.leg, self.k)
    }
}

impl Hand<'_> {
    /// Move the clamps one step and settle; where the rod jumps, follow it
    /// (see [`Hand::follow_jump`]).
    fn advance(&mut self, at: &Leg) -> Result<(Step, Equilibrium)> {
        let (newton, measure) = (&mut *self.newton, self.measure);
        let step = move_within(newton, at.from, at.to, self.settings, &mut self.allowance)
            .with_context(|| at.context())?;
        let next = analyse_from(
            newton,
            &step.state,
            &step.report,
            measure,
            Some(at.eq),
            None,
        )?;
        if step.jumped || link_jump(at.eq, &next).abs() > JUMP_LINK {
            return self.follow_jump(at, step, next);
        }
        Ok((step, next))
    }

    /// A hand moves slowly: the rod jumps where its branch ends, not where a
    /// finite step happened to overshoot. Locate the end on the path, record
    /// the jump (or the crossing), and move on from where the rod landed.
    fn follow_jump(
        &mut self,
        at: &Leg,
        step: Step,
        next: Equilibrium,
    ) -> Result<(Step, Equilibrium)> {
        let (settings, measure) = (self.settings, self.measure);
        let mut lo_eq = at.eq.clone();
        let allowance = &mut self.allowance;
        let (lo_state, hi) = locate_on_path(
            self.newton,
            allowance,
            at.from,
            at.to,
            settings,
            &mut |nw, t| {
                let t_eq = analyse_from(nw, &t.state, &t.report, measure, Some(&lo_eq), None)?;
                let same = !t.jumped && link_jump(&lo_eq, &t_eq).abs() <= JUMP_LINK;
                if same {
                    lo_eq = t_eq;
                }
                Ok(same)
            },
        )
        .with_context(|| at.context())?;
        // the last step from the end of the branch jumps; the rod then
        // moves on from where it landed to this step's clamps
        let newton = &mut *self.newton;
        let landed = move_within(newton, &lo_state, hi, settings, allowance)
            .with_context(|| at.context())?;
        let landed_eq = analyse_from(
            newton,
            &landed.state,
            &landed.report,
            measure,
            Some(&lo_eq),
            None,
        )?;
        if !(landed.jumped || link_jump(&lo_eq, &landed_eq).abs() > JUMP_LINK) {
            return Ok((step, next));
        }
        self.events.push(path_event(
            // the link changes by ±2 without a jump when the centreline
            // passes through itself (no contact model)
            if landed.jumped {
                EventKind::Jump
            } else {
                EventKind::Crossing
            },
            &hi,
            lo_eq.twist,
            at.leg,
            format!(
                "lands {:.4} from the prediction, link {:.3} → {:.3}, twist {:.3} → {:.3}",
                landed.miss, lo_eq.link, landed_eq.link, lo_eq.twist, landed_eq.twist
            ),
        ));
        let step = move_within(newton, &landed.state, at.to, settings, allowance)
            .with_context(|| at.context())?;
        let next = analyse_from(
            newton,
            &step.state,
            &step.report,
            measure,
            Some(&landed_eq),
            None,
        )?;
        Ok((step, next))
    }

    /// Entering or leaving the walls: locate it on the branch.
    fn locate_wall(&mut self, at: &Leg) -> Result<()> {
        let inside = at.eq.walled;
        let width = self.measure.strip_width;
        let (_, hi) = locate_on_path(
            self.newton,
            &mut self.allowance,
            at.from,
            at.to,
            self.settings,
            &mut |_, t| Ok(walls(&t.state, width).walled == inside),
        )
        .with_context(|| at.context())?;
        let detail = if inside {
            "leaves the walls"
        } else {
            "enters the walls"
        };
        self.events.push(path_event(
            EventKind::Wall,
            &hi,
            at.eq.twist,
            at.leg,
            detail.into(),
        ));
        Ok(())
    }

    /// The last contact opens: locate where its force reaches zero.
    fn locate_contact_loss(&mut self, at: &Leg) -> Result<()> {
        let (_, hi) = locate_on_path(
            self.newton,
            &mut self.allowance,
            at.from,
            at.to,
            self.settings,
            &mut |_, t| Ok(!t.report.contacts.is_empty()),
        )
        .with_context(|| at.context())?;
        let names: Vec<&str> = at.eq.contacts.iter().map(|c| c.obstacle.as_str()).collect();
        let detail = format!(
            "contacts {} → none (total force {:.3} before)",
            names.join(", "),
            at.eq.contact_force
        );
        self.events.push(path_event(
            EventKind::ContactLost,
            &hi,
            at.eq.twist,
            at.leg,
            detail,
        ));
        Ok(())
    }
}
