//! Newton shooting of the reference solutions (`model::shooting`,
//! `model::strip_shooting`): the paper's own method, used to make references
//! and the `[initial] shape = "shooting"` start, never in the rod solver.

use crate::model::natural::NaturalStrains;
use crate::model::rod::Clamps;
use crate::model::shooting::shooting_residual;
use crate::model::strip_shooting::{StripProblem, StripShootingError, StripUnknowns};
use crate::solve::continuum::newton::{NewtonShootingFailure, central_jacobian, newton_shooting};
use nalgebra::{Vector3, Vector6};

/// Refine published shooting data (n(0), m(0)) by Newton's method on the six
/// boundary conditions at s = 1 to a residual below 1e-11 (Jacobian by
/// central differences: this is the paper's own method, used only to make a
/// reference, never in the rod solver).
pub fn refine_shooting(
    n0: Vector3<f64>,
    m0: Vector3<f64>,
    k2: f64,
    k3: f64,
    clamps: &Clamps,
) -> Option<(Vector3<f64>, Vector3<f64>)> {
    refine_shooting_loaded(
        n0,
        m0,
        k2,
        k3,
        (Vector3::zeros(), &NaturalStrains::default()),
        clamps,
    )
}

/// As `refine_shooting`, under a body force and with natural strains
/// (`(weight, natural)`).
pub fn refine_shooting_loaded(
    n0: Vector3<f64>,
    m0: Vector3<f64>,
    k2: f64,
    k3: f64,
    (weight, natural): (Vector3<f64>, &NaturalStrains),
    clamps: &Clamps,
) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let start = Vector6::new(n0[0], n0[1], n0[2], m0[0], m0[1], m0[2]);
    // a start the equations cannot be integrated from has no residual:
    // Newton counts it as a failed step
    let res = |p: &Vector6<f64>| {
        shooting_residual(
            clamps,
            p.fixed_rows::<3>(0).into(),
            p.fixed_rows::<3>(3).into(),
            [k2, k3],
            (weight, natural),
        )
        .unwrap_or_else(|_| Vector6::repeat(f64::NAN))
    };
    let (p, _, _) = newton_shooting(start, res, |q| central_jacobian(q, res), 1e-11, 30, 0).ok()?;
    Some((p.fixed_rows::<3>(0).into(), p.fixed_rows::<3>(3).into()))
}

impl StripProblem {
    /// Newton's method on the six s = 1 conditions from `start` (Jacobian by
    /// central differences, as for the rod: a reference, not a solver), to a
    /// residual below 1e-11.
    pub fn refine(&self, start: StripUnknowns) -> Result<StripUnknowns, StripShootingError> {
        self.residual(&start)?;
        // a step the equations cannot be integrated from is a failed step
        let res = |p: &Vector6<f64>| {
            self.residual(&StripUnknowns::from_vector(p))
                .unwrap_or_else(|_| Vector6::repeat(f64::NAN))
        };
        match newton_shooting(
            start.to_vector(),
            res,
            |q| central_jacobian(q, res),
            1e-11,
            30,
            8,
        ) {
            Ok((p, _, _)) => Ok(StripUnknowns::from_vector(&p)),
            Err(NewtonShootingFailure::Singular) => Err(StripShootingError::Singular),
            Err(NewtonShootingFailure::NotConverged {
                iterations,
                residual,
            }) => Err(StripShootingError::NotConverged {
                iterations,
                residual,
            }),
        }
    }
}
