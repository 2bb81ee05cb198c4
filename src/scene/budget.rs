//! The work and memory a scene asks for, predicted before it runs, and the
//! budget past which it is refused unless the user says it is meant
//! (`--allow-large` or `[budget]`).
//!
//! The rates are measured on a 2-core machine (the CI kind): a continuation
//! point with its stability and diagnostics costs about 80 µs per segment; the
//! first Newton solve from a start grows faster than N (about 0.02 s at
//! N = 200, 26 s at N = 20000, 11 min at N = 80000); the solver's workspace
//! is about 5 KB per segment. The estimates are upper bounds in the counts
//! (every branch runs to `max_points`) and rough in the rates: they tell a
//! minute from an hour from a day, which is what a budget needs.

use crate::scene::{Direction, Estimate, InitialShape, Job, Scene, SceneError, human_time};

/// Solver workspace per segment (sparse Hessian, its factorisation, states).
const WORKSPACE_BYTES: f64 = 6000.0;
/// One equilibrium kept for the summary and recording, per segment.
const STATE_BYTES: f64 = 100.0;
/// A continuation point (corrector, stability, diagnostics), per segment.
const POINT_SECONDS: f64 = 8e-5;
/// One cell of a map's classified grid (and its JSON).
const CELL_BYTES: f64 = 32.0;

/// The first Newton solve from a start shape at N segments: its iterations
/// grow with N (fitted to 0.02 s, 26 s and 676 s at N = 200, 2e4, 8e4).
fn start_seconds(n: f64) -> f64 {
    1e-4 * n * (1.0 + (n / 4000.0).powf(1.4))
}

impl Scene {
    /// The predicted memory and CPU time of `job` at N segments (the
    /// scene's if None).
    pub fn estimate(&self, job: Job, segments: Option<usize>) -> Estimate {
        let n = segments.unwrap_or(self.model.segments as usize) as f64;
        let start = start_seconds(n);
        // a start that is unfolded (double ring) takes one solve per step
        let unfold = match self.initial.shape {
            InitialShape::DoubleRing => self.initial.steps.unwrap_or(40) as f64,
            _ => 0.0,
        };
        let directions = match self.continuation.as_ref().map(|c| c.direction) {
            Some(Direction::Both) => 2.0,
            _ => 1.0,
        };
        let per_branch = self.continuation.as_ref().map_or(0.0, |c| {
            let points = c.settings().max_points as f64 * directions;
            // a switched branch is followed as far again from each branch point
            if c.switch_branches {
                3.0 * points
            } else {
                points
            }
        });
        let workspace = WORKSPACE_BYTES * n;
        let (points, held, work_from, memory_from, grid) = match job {
            Job::Run => {
                let (points, what) = if !self.loading.is_empty() {
                    let steps: f64 = self.loading.iter().map(|l| l.steps as f64).sum();
                    (steps, format!("{steps} loading steps"))
                } else if self.continuation.is_some() {
                    let sweeps = self.sweep.as_ref().map_or(1.0, |s| s.values.len() as f64);
                    (
                        sweeps * per_branch,
                        format!("{sweeps} × up to {per_branch} continuation points"),
                    )
                } else {
                    (1.0, "one equilibrium".to_string())
                };
                (
                    points + unfold,
                    points + unfold,
                    what.clone(),
                    format!("{what} kept"),
                    0.0,
                )
            }
            Job::Map => {
                let m = self.map.as_ref();
                let lines = m.map_or(0.0, |m| m.lines as f64);
                let slices = m
                    .and_then(|m| m.slices.as_ref())
                    .map_or(1.0, |s| s.values.len() as f64);
                let columns = m.map_or(0.0, |m| m.grid_columns as f64);
                (
                    slices * lines * (per_branch + unfold),
                    // lines run one per thread: a few branches in flight
                    per_branch * rayon::current_num_threads().max(1) as f64,
                    format!(
                        "{slices} slice(s) × {lines} lines (map.lines) × up to {per_branch} points"
                    ),
                    format!("{lines} lines × {columns} grid columns (map.grid_columns)"),
                    slices * lines * columns * CELL_BYTES,
                )
            }
        };
        Estimate {
            memory_bytes: workspace + held * STATE_BYTES * n + grid,
            memory_from: format!("N = {n} segments (model.segments), {memory_from}"),
            // `points` holds the unfolding steps already
            seconds: start + points * POINT_SECONDS * n,
            work_from: format!("{work_from} at N = {n} segments"),
        }
    }

    /// Refuse `job` at N segments when its estimate exceeds `[budget]`,
    /// unless `allow_large`; the error gives the estimate and how to raise
    /// the limit.
    pub fn check_budget(
        &self,
        job: Job,
        segments: Option<usize>,
        allow_large: bool,
    ) -> Result<Estimate, SceneError> {
        let e = self.estimate(job, segments);
        if allow_large {
            return Ok(e);
        }
        let b = &self.budget;
        if e.memory_bytes > b.memory_gb * 1e9 {
            return Err(SceneError::TooLarge {
                what: "memory",
                estimate: format!("{:.3} GB", e.memory_bytes / 1e9),
                drivers: e.memory_from,
                limit: format!("{} GB", crate::scene::short(b.memory_gb)),
                key: "budget.memory_gb",
            });
        }
        if e.seconds > b.hours * 3600.0 {
            return Err(SceneError::TooLarge {
                what: "CPU time",
                estimate: human_time(e.seconds),
                drivers: e.work_from,
                limit: human_time(b.hours * 3600.0),
                key: "budget.hours",
            });
        }
        Ok(e)
    }

    /// `[budget]`: positive, finite limits.
    pub(crate) fn check_budget_spec(&self) -> Result<(), SceneError> {
        crate::scene::positive("budget.memory_gb", self.budget.memory_gb)?;
        crate::scene::positive("budget.hours", self.budget.hours)?;
        Ok(())
    }
}
