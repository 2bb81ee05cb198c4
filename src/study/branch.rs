//! Branches of equilibria: continuation of a scene's equilibrium in one clamp
//! parameter with its events located — folds, changes of stability, branch
//! points (S), walls touched (W), self-crossings (X) and knot changes — and the
//! bifurcating branches followed from branch points when asked.

use crate::analysis::equilibrium::{
    Conformation, Equilibrium, Measure, analyse_from, self_approach, walls,
};
use crate::analysis::event::{Event, EventKind};
use crate::model::rod::{Parameter, RodState};
use crate::solve::continuation::{
    Bracketed, ContinuationError, ContinuationSettings, Point, Tracer,
};
use crate::solve::minimizer::Minimizer;
use crate::solve::outcome::SolveReport;
use crate::study::error::{Context, Result};
use crate::study::observer::Observer;

/// The discrete values of the [`Vanishing`] quantities watched along a
/// branch: `wall` the wall gap, `knot` and `link` the strand gap (they jump
/// where two strands pass through each other), `touching` the ribbon gap;
/// the singularity is watched by the points' tangent and inertia.
///
/// [`Vanishing`]: crate::solve::event::Vanishing
#[derive(Clone, Debug)]
struct TestValues {
    wall: f64,
    knot: Vec<i64>,
    link: f64,
    /// A strip's ribbon touches or passes through itself (its self-distance
    /// is zero); always false for a centreline, whose passages show in the
    /// link and knot.
    touching: bool,
    /// The equilibrium they were measured on: states near it are measured
    /// from it (writhe carried, or jumped across one passage).
    at: Equilibrium,
}

impl TestValues {
    fn of(eq: &Equilibrium, measure: &Measure) -> TestValues {
        TestValues {
            wall: eq.wall_distance,
            knot: eq.alexander.clone(),
            link: eq.link,
            touching: ribbon_touches(eq.min_self_distance, measure),
            at: eq.clone(),
        }
    }
}

/// Alexander polynomial (empty: no knot type) and link of a state near the
/// measured equilibrium `from`.
fn knot_of(state: &RodState, measure: &Measure, from: &Equilibrium) -> (Vec<i64>, f64) {
    let shape = Conformation::continued(state, measure, from);
    let knot = shape.knot.map_or(vec![], |k| k.alexander);
    (knot, state.twist() + shape.writhe)
}

/// Whether a self-distance measured by `measure` is a ribbon touching
/// itself.
fn ribbon_touches(self_distance: f64, measure: &Measure) -> bool {
    measure.strip_width > 0.0 && self_distance <= 0.0
}

/// A knot for event details: its name, else its Alexander polynomial.
fn knot_label(alexander: &[i64]) -> String {
    if alexander.is_empty() {
        return "none".into();
    }
    let names = crate::geometry::knot::knot_names(alexander);
    if names.is_empty() {
        format!("Δ = {alexander:?}")
    } else {
        names.join(" or ")
    }
}

/// Options of a branch run.
#[derive(Clone, Debug)]
pub struct BranchOptions {
    /// Continuation parameter.
    pub parameter: Parameter,
    /// Stop when the parameter leaves [lo, hi].
    pub range: [f64; 2],
    /// Numerical settings.
    pub settings: ContinuationSettings,
    /// Locate events (otherwise only accepted points).
    pub locate_events: bool,
    /// Follow the branches that bifurcate at branch points.
    pub switch_branches: bool,
    /// What to measure at each point.
    pub measure: Measure,
    /// A direction stops at the first event of one of these kinds.
    pub stop_at: Vec<EventKind>,
}

/// Traces branches and collects events.
pub struct BranchRun<'a, 'r> {
    tracer: Tracer<'a>,
    options: BranchOptions,
    observer: &'r mut dyn Observer,
    /// Located events, in the order found.
    pub events: Vec<Event>,
    /// The equilibrium at each located event (`events[k]` at `located[k]`).
    pub located: Vec<RodState>,
    /// Branch points found (point, null vector), to switch onto.
    branch_points: Vec<(Point, Vec<f64>, usize)>,
    next_branch: usize,
    /// The last measured equilibrium (writhe and knot type carry over from it).
    previous: Option<Equilibrium>,
}

fn event(kind: EventKind, p: &Point, branch: usize, detail: String) -> Event {
    Event::at(kind, &p.state.clamps, p.state.twist(), branch, detail)
}

impl<'a, 'r> BranchRun<'a, 'r> {
    /// A run on `newton`'s rod; branches are numbered from `first_branch`.
    pub fn new(
        newton: &'a mut Minimizer,
        options: BranchOptions,
        observer: &'r mut dyn Observer,
        first_branch: usize,
    ) -> Self {
        BranchRun {
            tracer: Tracer::new(newton, options.parameter, options.settings.clone()),
            options,
            observer,
            events: Vec::new(),
            located: Vec::new(),
            branch_points: Vec::new(),
            next_branch: first_branch,
            previous: None,
        }
    }

    fn measure(&mut self, p: &Point, branch: usize, leg: usize) -> Result<Equilibrium> {
        let energy = self.tracer.newton.energy.energy(&p.state);
        let report = SolveReport::of_corrector(p.iterations, p.residual, energy);
        let mut eq = analyse_from(
            self.tracer.newton,
            &p.state,
            &report,
            &self.options.measure,
            self.previous.as_ref(),
            Some(&p.hessian),
        )?;
        eq.branch = branch;
        eq.leg = leg;
        self.previous = Some(eq.clone());
        Ok(eq)
    }

    /// Keep an event at point `p` with its equilibrium.
    fn record(&mut self, kind: EventKind, p: &Point, branch: usize, detail: String) {
        self.events.push(event(kind, p, branch, detail));
        self.located.push(p.state.clone());
    }

    /// Record an event located by bisection, with its bracket.
    fn record_located(&mut self, kind: EventKind, b: &Bracketed, branch: usize, detail: String) {
        self.record(kind, &b.point, branch, detail);
        if let Some(e) = self.events.last_mut() {
            e.located_within = Some(b.within);
        }
    }

    fn in_range(&self, p: &Point) -> bool {
        let v = self.tracer.parameter_of(&p.state);
        v >= self.options.range[0] && v <= self.options.range[1]
    }

    /// Hand the events from `found` on to the observer, labelled as the
    /// events so far label them (provisionally: see [`Observer::event`]).
    fn report_events(&mut self, found: usize) -> Result<()> {
        if found == self.events.len() {
            return Ok(());
        }
        let mut labelled = self.events.clone();
        crate::analysis::event::label_events(&mut labelled);
        for e in &labelled[found..] {
            self.observer.event(e)?;
        }
        Ok(())
    }

    /// Number of the next branch to be traced.
    pub fn next_branch(&self) -> usize {
        self.next_branch
    }

    /// Follow the branch through `state` in both directions (or one: sign ±1),
    /// then, if asked, the branches bifurcating at its branch points.
    pub fn follow(&mut self, state: RodState, directions: &[f64]) -> Result<()> {
        let branch = self.next_branch;
        self.next_branch += 1;
        for (k, &sign) in directions.iter().enumerate() {
            let start = self
                .tracer
                .start(state.clone(), sign)
                .context("tangent at the start")?;
            // the start point is emitted once
            self.trace(start, branch, k, k == 0)?;
        }
        if self.options.switch_branches {
            let bps = std::mem::take(&mut self.branch_points);
            for (bp, null, _) in bps {
                for sign in [1.0, -1.0] {
                    let b = self.next_branch;
                    self.next_branch += 1;
                    let sigma = self.options.settings.step;
                    match self.tracer.switch(&bp, &null, sign, sigma) {
                        Ok(p) if self.in_range(&p) => self.trace(p, b, 0, true)?,
                        Ok(_) => {}
                        Err(e) => {
                            let found = self.events.len();
                            self.record(
                                EventKind::End,
                                &bp,
                                b,
                                format!("branch switch failed: {e}"),
                            );
                            self.report_events(found)?;
                        }
                    }
                }
            }
        }
        Ok(())
    }

    fn trace(&mut self, start: Point, branch: usize, leg: usize, emit_start: bool) -> Result<()> {
        let settings = self.options.settings.clone();
        let eq = self.measure(&start, branch, leg)?;
        let mut wa = TestValues::of(&eq, &self.options.measure);
        if emit_start {
            self.observer.equilibrium(eq)?;
        }
        let mut a = start;
        let mut step = settings.step_control();
        for _ in 0..settings.max_points {
            if !self.in_range(&a) {
                break;
            }
            let Some((b, ds)) = self.tracer.advance(&a, &mut step) else {
                let found = self.events.len();
                self.record(
                    EventKind::End,
                    &a,
                    branch,
                    "step below min_step: branch lost".into(),
                );
                self.report_events(found)?;
                break;
            };
            let eq = self.measure(&b, branch, leg)?;
            let wb = TestValues::of(&eq, &self.options.measure);
            let found = self.events.len();
            if self.options.locate_events {
                self.locate_events(&a, &b, &wa, &wb, ds, branch)?;
            }
            self.report_events(found)?;
            self.observer.equilibrium(eq)?;
            if self.events[found..]
                .iter()
                .any(|e| self.options.stop_at.contains(&e.kind))
            {
                break;
            }
            a = b;
            wa = wb;
        }
        Ok(())
    }

    /// The events between the consecutive points `a` and `b` (test values
    /// `wa`, `wb`, arclength `ds` apart), each located by bisection.
    fn locate_events(
        &mut self,
        a: &Point,
        b: &Point,
        wa: &TestValues,
        wb: &TestValues,
        ds: f64,
        branch: usize,
    ) -> Result<()> {
        let fold = a.tangent_p * b.tangent_p < 0.0;
        if fold {
            self.locate_fold(a, b, ds, branch)?;
        }
        if a.negative_count != b.negative_count {
            self.locate_stability_change(a, b, ds, branch, fold)?;
        }
        if (wa.wall > 0.0) != (wb.wall > 0.0) {
            self.locate_wall(a, wa, ds, branch)?;
        }
        if wa.knot != wb.knot || (wb.link - wa.link).abs() > 1.0 {
            self.locate_crossing(a, wa, wb, ds, branch)?;
        }
        if wa.touching != wb.touching {
            self.locate_ribbon_contact(a, wa, ds, branch)?;
        }
        Ok(())
    }

    /// The parameter turns back: a fold, or a symmetric branch point.
    fn locate_fold(&mut self, a: &Point, b: &Point, ds: f64, branch: usize) -> Result<()> {
        let s = a.tangent_p.signum();
        let located = self
            .locate(a, ds, &mut |_, p| p.tangent_p.signum() == s)
            .context("locating a fold")?;
        let detail = format!(
            "negative eigenvalues {} → {}",
            a.negative_count, b.negative_count
        );
        if a.negative_count == b.negative_count {
            // φ extremal while no eigenvalue changes sign: an eigenvalue
            // touches zero where an asymmetric branch meets the symmetric
            // one, and the path goes on along the mirror image (same
            // φ, Tw, walls): a symmetric branch point, not a fold
            let detail =
                format!("{detail}; through a symmetric branch point onto the mirror branch");
            self.record_located(EventKind::BranchPoint, &located, branch, detail);
        } else {
            self.record_located(EventKind::Fold, &located, branch, detail);
        }
        Ok(())
    }

    /// An eigenvalue changes sign; without a fold it is a branch point,
    /// whose null vector is kept to switch onto the bifurcating branches.
    fn locate_stability_change(
        &mut self,
        a: &Point,
        b: &Point,
        ds: f64,
        branch: usize,
        fold: bool,
    ) -> Result<()> {
        let na = a.negative_count;
        let located = self
            .locate(a, ds, &mut |_, p| p.negative_count == na)
            .context("locating a change of stability")?;
        let detail = format!("negative eigenvalues {} → {}", na, b.negative_count);
        self.record_located(EventKind::Stability, &located, branch, detail.clone());
        if !fold {
            let (lambda, null) = self.tracer.lowest_mode(&located.point)?;
            self.record_located(
                EventKind::BranchPoint,
                &located,
                branch,
                format!("{detail}; eigenvalue there {lambda:.2e}"),
            );
            self.branch_points.push((located.point, null, branch));
        }
        Ok(())
    }

    /// The rod enters or leaves the walls.
    fn locate_wall(&mut self, a: &Point, wa: &TestValues, ds: f64, branch: usize) -> Result<()> {
        let inside = wa.wall > 0.0;
        let width = self.options.measure.strip_width;
        let located = self
            .locate(a, ds, &mut |_, p| {
                (walls(&p.state, width).clearance > 0.0) == inside
            })
            .context("locating a wall")?;
        let detail = if inside {
            "leaves the walls"
        } else {
            "enters the walls"
        };
        self.record_located(EventKind::Wall, &located, branch, detail.into());
        Ok(())
    }

    /// The centreline passes through itself (the link jumps by ±2), and the
    /// knot type may change there.
    fn locate_crossing(
        &mut self,
        a: &Point,
        wa: &TestValues,
        wb: &TestValues,
        ds: f64,
        branch: usize,
    ) -> Result<()> {
        let measure = self.options.measure.clone();
        let (ka, la) = (wa.knot.clone(), wa.link);
        let located = self
            .locate(a, ds, &mut |_, p| {
                let (knot, link) = knot_of(&p.state, &measure, &wa.at);
                knot == ka && (link - la).abs() < 1.0
            })
            .context("locating a crossing")?;
        let detail = format!(
            "knot {} → {}, link {:.3} → {:.3}",
            knot_label(&wa.knot),
            knot_label(&wb.knot),
            wa.link,
            wb.link
        );
        self.record_located(EventKind::Crossing, &located, branch, detail.clone());
        if wa.knot != wb.knot {
            self.record_located(EventKind::KnotChange, &located, branch, detail);
        }
        Ok(())
    }

    /// A strip's ribbon comes to touch itself, or comes clear of itself: its
    /// surface's self-distance reaches zero (the crossing X of a ribbon,
    /// which comes before its centreline passes through itself).
    fn locate_ribbon_contact(
        &mut self,
        a: &Point,
        wa: &TestValues,
        ds: f64,
        branch: usize,
    ) -> Result<()> {
        let measure = self.options.measure.clone();
        let touching = wa.touching;
        let located = self
            .locate(a, ds, &mut |_, p| {
                let d = self_approach(&p.state, &measure).map_or(f64::INFINITY, |a| a.distance);
                ribbon_touches(d, &measure) == touching
            })
            .context("locating where the ribbon touches itself")?;
        let detail = if touching {
            "the ribbon comes clear of itself"
        } else {
            "the ribbon touches itself"
        };
        self.record_located(EventKind::RibbonContact, &located, branch, detail.into());
        Ok(())
    }

    fn locate(
        &mut self,
        from: &Point,
        sigma: f64,
        same: &mut dyn FnMut(&mut Tracer<'a>, &Point) -> bool,
    ) -> Result<Bracketed, ContinuationError> {
        self.tracer.locate_bracketed(from, sigma, same)
    }
}
