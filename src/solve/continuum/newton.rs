//! Newton shooting: Newton's method on the six s = 1 conditions in the six
//! unknowns at s = 0, with the Jacobian by central differences where the
//! variational equations are not integrated.

use nalgebra::{Matrix6, Vector6};

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
