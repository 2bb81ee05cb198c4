//! The one entry point of energy minimisation: a [`Minimizer`] bound to one
//! energy runs Newton's method for unconstrained rods away from contact, and
//! SQP for constrained laws and once something is near contact.

use crate::linalg::sparse::Ldlt;
use crate::model::contact::ContactModel;
use crate::model::energy::RodEnergy;
use crate::model::rod::RodState;
use crate::solve::newton::Newton;
use crate::solve::outcome::{SolveError, SolveReport, SolverSettings};
use crate::solve::sqp;

/// A minimiser bound to one energy (its sparse pattern and symbolic
/// factorisation are reused across iterations and solves).
pub struct Minimizer {
    /// The energy being minimised.
    pub energy: RodEnergy,
    /// Factorisation workspace on the energy's pattern.
    pub ldlt: Ldlt,
    /// Contact with the rays, obstacles and itself (solved by SQP).
    pub contact: Option<ContactModel>,
    newton: Newton,
}

impl Minimizer {
    /// A minimiser for `energy`, without contact.
    pub fn new(energy: RodEnergy) -> Self {
        let ldlt = Ldlt::new(&energy.pattern);
        let newton = Newton::new(&energy);
        Minimizer {
            energy,
            ldlt,
            contact: None,
            newton,
        }
    }

    /// Minimise the energy from `state` (updated in place).
    pub fn minimize(
        &mut self,
        state: &mut RodState,
        settings: &SolverSettings,
    ) -> Result<SolveReport, SolveError> {
        if self.energy.penalty.is_some() {
            // constrained laws: SQP, each step a QP solved by clarabel
            return sqp::minimize(
                &self.energy,
                &mut self.ldlt,
                self.contact.as_ref(),
                state,
                settings,
            );
        }
        if let Some(model) = &self.contact {
            // Newton while nothing is near contact (steps capped so that no
            // pair can close the margin in one), SQP with contact rows once
            // something is
            let capped = SolverSettings {
                max_step: settings.max_step.min(0.5 * model.margin),
                ..*settings
            };
            let near = |s: &RodState| !model.gaps(s).is_empty();
            if !near(state) {
                let report = self.newton.minimize_until(
                    &self.energy,
                    &mut self.ldlt,
                    state,
                    &capped,
                    Some(&near),
                )?;
                if report.converged {
                    return Ok(report);
                }
            }
            return sqp::minimize(&self.energy, &mut self.ldlt, Some(model), state, settings);
        }
        self.newton
            .minimize_until(&self.energy, &mut self.ldlt, state, settings, None)
    }

    /// Newton's method on ∇E = 0 from `state` without line search or shift:
    /// converges to the nearby equilibrium whatever its stability (a saddle
    /// too), where [`Self::minimize`] would leave a saddle.
    pub fn find_equilibrium(
        &mut self,
        state: &mut RodState,
        settings: &SolverSettings,
    ) -> Result<SolveReport, SolveError> {
        self.newton
            .find_equilibrium(&self.energy, &mut self.ldlt, state, settings)
    }
}
