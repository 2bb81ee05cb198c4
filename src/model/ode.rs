//! The integrator the shooting ODEs share: classical RK4 on a uniform grid of
//! [0, 1], cubic Hermite interpolation between its samples, and the Jacobian
//! of the six s = 1 conditions in the six unknowns at s = 0.

use nalgebra::{Matrix6, SVector, Vector6};

/// Samples y(k / steps), k = 0..=steps, of y' = f(s, y) from y(0) = `y0` by
/// classical RK4.
pub fn rk4<const D: usize>(
    y0: SVector<f64, D>,
    steps: usize,
    f: impl Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
) -> Vec<SVector<f64, D>> {
    let mut y = y0;
    let ds = 1.0 / steps as f64;
    let mut samples = Vec::with_capacity(steps + 1);
    samples.push(y);
    for k in 0..steps {
        let s = k as f64 * ds;
        let a = f(s, &y);
        let b = f(s + 0.5 * ds, &(y + 0.5 * ds * a));
        let c = f(s + 0.5 * ds, &(y + 0.5 * ds * b));
        let d = f(s + ds, &(y + ds * c));
        y += ds / 6.0 * (a + 2.0 * b + 2.0 * c + d);
        samples.push(y);
    }
    samples
}

/// y(s) between the uniform `samples` of [0, 1] by cubic Hermite
/// interpolation with the exact derivative f(s, y) at both ends of its step
/// (fourth order, as RK4 itself).
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

/// The Jacobian of `res` at `p` by central differences (steps 1e-6 (1 + |p_c|)):
/// the shooting methods' Newton matrix (they are references, not solvers).
pub fn central_jacobian(
    p: &Vector6<f64>,
    res: impl Fn(&Vector6<f64>) -> Vector6<f64>,
) -> Matrix6<f64> {
    let mut jac = Matrix6::zeros();
    for c in 0..6 {
        let eps = 1e-6 * (1.0 + p[c].abs());
        let mut pp = *p;
        pp[c] += eps;
        let mut pm = *p;
        pm[c] -= eps;
        jac.set_column(c, &((res(&pp) - res(&pm)) / (2.0 * eps)));
    }
    jac
}

/// Why Newton shooting stopped without converging.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NewtonShootingFailure {
    /// The Jacobian was singular or not finite.
    Singular,
    /// The residual stayed above the tolerance (or became non-finite).
    NotConverged {
        /// Iterations made.
        iterations: usize,
        /// The last finite residual's norm.
        residual: f64,
    },
}

/// Newton's method on the six s = 1 conditions `res` from `p` (Jacobian
/// `jacobian`, e.g. [`central_jacobian`] of `res`; the step halved up to
/// `halvings` times while the residual does not fall): the unknowns, their
/// residual's norm and the iterations made, once the norm is below `tol`.
pub fn newton_shooting(
    mut p: Vector6<f64>,
    res: impl Fn(&Vector6<f64>) -> Vector6<f64>,
    jacobian: impl Fn(&Vector6<f64>) -> Matrix6<f64>,
    tol: f64,
    iterations: usize,
    halvings: usize,
) -> Result<(Vector6<f64>, f64, usize), NewtonShootingFailure> {
    let mut r = res(&p);
    for iteration in 0..iterations {
        if r.norm() < tol {
            return Ok((p, r.norm(), iteration));
        }
        let dp = jacobian(&p)
            .lu()
            .solve(&(-r))
            .filter(|d| d.iter().all(|v| v.is_finite()))
            .ok_or(NewtonShootingFailure::Singular)?;
        let mut t = 1.0;
        let mut next = p + dp;
        let mut rn = res(&next);
        for _ in 0..halvings {
            if rn.norm().is_finite() && rn.norm() < r.norm() {
                break;
            }
            t *= 0.5;
            next = p + t * dp;
            rn = res(&next);
        }
        if !rn.norm().is_finite() {
            return Err(NewtonShootingFailure::NotConverged {
                iterations: iteration + 1,
                residual: r.norm(),
            });
        }
        p = next;
        r = rn;
    }
    if r.norm() < tol {
        return Ok((p, r.norm(), iterations));
    }
    Err(NewtonShootingFailure::NotConverged {
        iterations,
        residual: r.norm(),
    })
}
