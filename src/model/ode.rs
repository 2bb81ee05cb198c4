//! The one integrator of the continuum equations: an adaptive eighth-order
//! Runge–Kutta method (Dormand–Prince 8(5,3), the `ode_solvers` crate, its
//! 12th-stage node fixed in vendor/ode_solvers) from s = 0 to given stops or
//! with dense output on a uniform grid, and cubic Hermite interpolation
//! between such samples. The shooting references (`model::shooting`,
//! `model::strip_shooting`) and the continuum check (`solve::continuum`)
//! integrate through it alike.

use nalgebra::SVector;
use ode_solvers::{Dop853, OutputType, System};

/// Steps of one integration before it counts as blown up (some hundred
/// suffice for a knot).
const MAX_STEPS: u32 = 20_000;

/// The tolerance (absolute and relative) the shooting references integrate to.
pub const REFERENCE_TOLERANCE: f64 = 1e-12;

/// Why an integration stopped before its end.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum IntegrationFailure {
    /// More than the step budget: the solution has blown up.
    #[error("more than {MAX_STEPS} steps")]
    TooManySteps,
    /// The step fell below what f64 resolves.
    #[error("the step size underflowed")]
    StepSizeUnderflow,
    /// The integrator's stiffness test fired.
    #[error("the equations became stiff")]
    Stiff,
    /// A component became NaN or infinite.
    #[error("the solution is not finite")]
    NotFinite,
    /// A stop outside [previous stop, 1].
    #[error("stop s = {0} is not between the previous stop and 1")]
    BadStop(f64),
    /// The dense output did not give the asked samples.
    #[error("the dense output gave {got} samples, not {asked}")]
    Samples {
        /// Samples made.
        got: usize,
        /// Samples asked.
        asked: usize,
    },
}

/// An integration that stopped before its end, with where.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("the equations could not be integrated past s = {s:.4}: {why}")]
pub struct IntegrationError {
    /// Where it stopped.
    pub s: f64,
    /// Why.
    pub why: IntegrationFailure,
}

struct Rhs<F>(F);

impl<F, const D: usize> System<f64, SVector<f64, D>> for Rhs<F>
where
    F: Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
{
    fn system(&self, s: f64, y: &SVector<f64, D>, dy: &mut SVector<f64, D>) {
        *dy = (self.0)(s, y);
    }
}

/// y(1), y at the asked uniform samples of [0, 1], and the steps taken.
#[derive(Clone, Debug)]
pub struct Integrated<const D: usize> {
    /// y(1), a step's own end.
    pub end: SVector<f64, D>,
    /// y(k / (samples − 1)), k = 0..samples (empty if fewer than 2 asked).
    pub samples: Vec<SVector<f64, D>>,
    /// Accepted steps.
    pub steps: u32,
}

/// y' = f(s, y) from y(0) = `y0` to s = 1 at `tolerance`, with y at
/// `samples` evenly spaced s if `samples` ≥ 2 (dense output of order 7).
pub fn integrate<const D: usize>(
    y0: SVector<f64, D>,
    f: impl Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
    tolerance: f64,
    samples: usize,
) -> Result<Integrated<D>, IntegrationError> {
    let (ends, steps) = integrate_stops(y0, &f, tolerance, &[1.0])?;
    let end = ends[0];
    if samples < 2 {
        return Ok(Integrated {
            end,
            samples: vec![],
            steps,
        });
    }
    let mut dense = integrate_dense(y0, &f, tolerance, samples)?;
    // the crate's dense output at s = 1 itself is an extrapolation (errors
    // of 1e-10 seen); the step's own y(1) is exact to the tolerance
    if let Some(last) = dense.last_mut() {
        *last = end;
    }
    Ok(Integrated {
        end,
        samples: dense,
        steps,
    })
}

/// y at `samples` (≥ 2) evenly spaced s in [0, 1] of y' = f(s, y) from
/// y(0) = `y0`, by one integration at `tolerance` and its dense output (of
/// order 7; at s = 1 an extrapolation, see [`integrate`]).
pub fn integrate_dense<const D: usize>(
    y0: SVector<f64, D>,
    f: impl Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
    tolerance: f64,
    samples: usize,
) -> Result<Vec<SVector<f64, D>>, IntegrationError> {
    let dx = 1.0 / (samples.max(2) - 1) as f64;
    // (Dense is the crate's default output)
    let mut solver = Dop853::new(Rhs(&f), 0.0, 1.0, dx, y0, tolerance, tolerance);
    solver.integrate().map_err(failure)?;
    let dense: Vec<SVector<f64, D>> = solver.y_out().to_vec();
    if dense.len() != samples {
        return Err(IntegrationError {
            s: 1.0,
            why: IntegrationFailure::Samples {
                got: dense.len(),
                asked: samples,
            },
        });
    }
    if dense.iter().flatten().any(|v| !v.is_finite()) {
        return Err(IntegrationError {
            s: 1.0,
            why: IntegrationFailure::NotFinite,
        });
    }
    Ok(dense)
}

/// The crate's failure, with where it stopped.
fn failure(e: ode_solvers::dop_shared::IntegrationError) -> IntegrationError {
    use ode_solvers::dop_shared::IntegrationError as E;
    match e {
        E::MaxNumStepReached { x, .. } => IntegrationError {
            s: x,
            why: IntegrationFailure::TooManySteps,
        },
        E::StepSizeUnderflow { x } => IntegrationError {
            s: x,
            why: IntegrationFailure::StepSizeUnderflow,
        },
        E::StiffnessDetected { x } => IntegrationError {
            s: x,
            why: IntegrationFailure::Stiff,
        },
    }
}

/// y at each of the increasing `stops` in (0, 1] of y' = f(s, y) from
/// y(0) = `y0`, to `tolerance`, and the steps taken: each piece is
/// integrated afresh from the last stop, so every stop is a step's own end
/// (no interpolation).
pub fn integrate_stops<const D: usize>(
    y0: SVector<f64, D>,
    f: impl Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
    tolerance: f64,
    stops: &[f64],
) -> Result<(Vec<SVector<f64, D>>, u32), IntegrationError> {
    integrate_stops_from(0.0, y0, &f, tolerance, stops)
}

/// DOP853 from y(`from`) = `y` to `to` with the crate's defaults but the step
/// budget, its output each accepted step's end.
fn sparse_solver<const D: usize, F>(
    f: &F,
    from: f64,
    to: f64,
    y: SVector<f64, D>,
    tolerance: f64,
) -> Dop853<f64, SVector<f64, D>, Rhs<&F>>
where
    F: Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
{
    Dop853::from_param(
        Rhs(f),
        from,
        to,
        to - from,
        y,
        tolerance,
        tolerance,
        0.9,
        0.0,
        0.333,
        6.0,
        to - from,
        0.0,
        MAX_STEPS,
        1000,
        OutputType::Sparse,
    )
}

/// [`integrate_stops`] from y(`from`) = `y`.
fn integrate_stops_from<const D: usize>(
    mut from: f64,
    mut y: SVector<f64, D>,
    f: &impl Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
    tolerance: f64,
    stops: &[f64],
) -> Result<(Vec<SVector<f64, D>>, u32), IntegrationError> {
    let mut out = Vec::with_capacity(stops.len());
    let mut steps = 0;
    for &to in stops {
        if !(to >= from && to <= 1.0) {
            return Err(IntegrationError {
                s: from,
                why: IntegrationFailure::BadStop(to),
            });
        }
        if to > from {
            let mut solver = sparse_solver(f, from, to, y, tolerance);
            steps += solver.integrate().map_err(failure)?.accepted_steps;
            // the crate's sparse output holds at least the end
            y = *solver.y_out().last().ok_or(IntegrationError {
                s: from,
                why: IntegrationFailure::TooManySteps,
            })?;
            if y.iter().any(|v| !v.is_finite()) {
                return Err(IntegrationError {
                    s: to,
                    why: IntegrationFailure::NotFinite,
                });
            }
        }
        out.push(y);
        from = to;
    }
    Ok((out, steps))
}

/// One integration of y' = f(s, y) from s = 0 to 1 kept as the state at
/// each of its accepted steps' ends: y anywhere is then a short integration
/// from the step end before it, as exact as a step's own end (no
/// interpolation) at the cost of about one step instead of an integration
/// from s = 0.
#[derive(Clone, Debug)]
pub struct Steps<const D: usize> {
    /// s at the step ends, from 0 up.
    s: Vec<f64>,
    /// y there.
    y: Vec<SVector<f64, D>>,
}

/// [`Steps`] of y' = f(s, y) from y(0) = `y0` to s = 1 at `tolerance`.
pub fn integrate_steps<const D: usize>(
    y0: SVector<f64, D>,
    f: impl Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
    tolerance: f64,
) -> Result<Steps<D>, IntegrationError> {
    let mut solver = sparse_solver(&f, 0.0, 1.0, y0, tolerance);
    solver.integrate().map_err(failure)?;
    let (s, y) = (solver.x_out().clone(), solver.y_out().clone());
    if let Some(k) = y.iter().position(|v| v.iter().any(|c| !c.is_finite())) {
        return Err(IntegrationError {
            s: s[k],
            why: IntegrationFailure::NotFinite,
        });
    }
    Ok(Steps { s, y })
}

impl<const D: usize> Steps<D> {
    /// y at each of the increasing `stops` in [0, 1] (`f` and `tolerance`
    /// as integrated): from the step end at or before the first stop, then
    /// from stop to stop as [`integrate_stops`], so that stops close
    /// together (a central difference) come from one piece of integration.
    pub fn at(
        &self,
        stops: &[f64],
        f: impl Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
        tolerance: f64,
    ) -> Result<Vec<SVector<f64, D>>, IntegrationError> {
        let Some(&first) = stops.first() else {
            return Ok(vec![]);
        };
        if !(0.0..=1.0).contains(&first) {
            return Err(IntegrationError {
                s: 0.0,
                why: IntegrationFailure::BadStop(first),
            });
        }
        // the last step end at or before the first stop (s[0] = 0)
        let k = self.s.partition_point(|&s| s <= first).max(1) - 1;
        Ok(integrate_stops_from(self.s[k], self.y[k], &f, tolerance, stops)?.0)
    }
}

/// y(s) between the uniform `samples` of [0, 1] by cubic Hermite
/// interpolation with the exact derivative f(s, y) at both ends of its
/// interval (fourth order in the spacing).
pub fn hermite<const D: usize>(
    samples: &[SVector<f64, D>],
    s: f64,
    f: impl Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
) -> SVector<f64, D> {
    let steps = samples.len() - 1;
    let x = s.clamp(0.0, 1.0) * steps as f64;
    let k = (x.floor() as usize).min(steps - 1);
    let t = x - k as f64;
    let ds = 1.0 / steps as f64;
    let (y0, y1) = (&samples[k], &samples[k + 1]);
    let (f0, f1) = (f(k as f64 * ds, y0), f((k + 1) as f64 * ds, y1));
    let h00 = 2.0 * t * t * t - 3.0 * t * t + 1.0;
    let h10 = t * t * t - 2.0 * t * t + t;
    let h01 = -2.0 * t * t * t + 3.0 * t * t;
    let h11 = t * t * t - t * t;
    h00 * y0 + h10 * ds * f0 + h01 * y1 + h11 * ds * f1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An equation that depends on s (as natural strains varying along the
    /// rod make the rod's): y' = (8 s⁷, cos s), integrated to 1e-12 in a few
    /// steps. The crate's DOP853 evaluated its 12th stage at the step's start
    /// (vendor/ode_solvers, c12 fixed): this took hundreds of steps or
    /// stopped as "stiff".
    #[test]
    fn an_equation_that_depends_on_s_is_integrated_to_its_tolerance() {
        let f = |s: f64, _: &SVector<f64, 2>| SVector::<f64, 2>::new(8.0 * s.powi(7), s.cos());
        let solved = integrate(SVector::<f64, 2>::zeros(), f, 1e-12, 5).unwrap();
        let end = solved.end;
        assert!((end[0] - 1.0).abs() < 1e-12, "{}", end[0] - 1.0);
        assert!(
            (end[1] - 1f64.sin()).abs() < 1e-12,
            "{}",
            end[1] - 1f64.sin()
        );
        assert!(solved.steps < 40, "{} steps", solved.steps);
        // the dense output at s = 0.5 too
        assert!((solved.samples[2][0] - 0.5f64.powi(8)).abs() < 1e-10);
        assert!((solved.samples[2][1] - 0.5f64.sin()).abs() < 1e-10);
    }

    #[test]
    fn a_blown_up_solution_is_an_error_with_where_it_stopped() {
        // y' = y² from y(0) = 2 blows up at s = 1/2
        let f = |_: f64, y: &SVector<f64, 1>| SVector::<f64, 1>::new(y[0] * y[0]);
        let e = integrate(SVector::<f64, 1>::new(2.0), f, 1e-10, 0).unwrap_err();
        assert!((e.s - 0.5).abs() < 1e-3, "{e}");
        let e = integrate_stops(SVector::<f64, 1>::new(0.0), f, 1e-10, &[0.5, 0.2]).unwrap_err();
        assert_eq!(e.why, IntegrationFailure::BadStop(0.2));
    }

    /// A state anywhere from one integration's step ends is as exact as an
    /// integration to it (y = (sin s, cos s) to 1e-12), costs a step or two,
    /// and does not depend on the stops asked after it.
    #[test]
    fn states_between_step_ends_are_integrated_from_the_step_before() {
        let f = |_: f64, y: &SVector<f64, 2>| SVector::<f64, 2>::new(y[1], -y[0]);
        let steps = integrate_steps(SVector::<f64, 2>::new(0.0, 1.0), f, 1e-12).unwrap();
        assert!(steps.s.len() > 3, "{} step ends", steps.s.len() - 1);
        let stops = [0.0, 0.3, 0.3 + 1e-5, 0.7, 1.0];
        let ys = steps.at(&stops, f, 1e-12).unwrap();
        for (y, &s) in ys.iter().zip(&stops) {
            assert!(
                (y[0] - s.sin()).abs() < 1e-12,
                "s = {s}: {}",
                y[0] - s.sin()
            );
            assert!(
                (y[1] - s.cos()).abs() < 1e-12,
                "s = {s}: {}",
                y[1] - s.cos()
            );
        }
        // the first stop's state is integrated from its own step end
        assert_eq!(
            steps.at(&[0.7], f, 1e-12).unwrap()[0],
            steps.at(&[0.7, 0.9], f, 1e-12).unwrap()[0]
        );
        // a stop between step ends: one short integration from the one before
        let k = steps.s.len() / 2;
        let middle = 0.5 * (steps.s[k] + steps.s[k + 1]);
        let (_, taken) =
            integrate_stops_from(steps.s[k], steps.y[k], &f, 1e-12, &[middle]).unwrap();
        assert!(taken <= 2, "{taken} steps");
        assert_eq!(
            steps.at(&[0.5, 0.4], f, 1e-12).unwrap_err().why,
            IntegrationFailure::BadStop(0.4)
        );
        assert_eq!(
            steps.at(&[-0.1], f, 1e-12).unwrap_err().why,
            IntegrationFailure::BadStop(-0.1)
        );
    }

    #[test]
    fn hermite_samples_interpolate_at_fourth_order() {
        // y = (sin s, cos s): the interpolation error falls 16-fold as the
        // spacing halves
        let f = |_: f64, y: &SVector<f64, 2>| SVector::<f64, 2>::new(y[1], -y[0]);
        let error = |n: usize| {
            let samples: Vec<_> = (0..=n)
                .map(|k| {
                    let s = k as f64 / n as f64;
                    SVector::<f64, 2>::new(s.sin(), s.cos())
                })
                .collect();
            let s = 0.5 / n as f64 + 0.3;
            (hermite(&samples, s, f)[0] - s.sin()).abs()
        };
        let ratio = error(20) / error(40);
        assert!((ratio - 16.0).abs() < 1.0, "{ratio}");
    }
}
