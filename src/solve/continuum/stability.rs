//! Stability on the continuum, independent of the discrete rod: the
//! frequencies ω² of the linearised dynamics (A.4) about a Kirchhoff
//! equilibrium clamped at both ends, and of the strip's equations (A.1 with
//! 4.3) likewise. The six perturbations started at s = 0
//! by unit n̄(0), m̄(0) (r̄ = α = 0 there) are integrated with the
//! equilibrium (`Continuum::variational_rhs`); their block B(s) = [r̄; α]
//! is singular at s = 1 exactly when ω² is an eigenvalue (the shooting
//! determinant D(ω²) = det B(1)), and by the Morse index theorem the number
//! of eigenvalues below ω² is the number of conjugate points — zeros of
//! det B(s) — in (0, 1). The count brackets each eigenvalue, regula falsi on
//! D refines it, and the same at a 100 times looser tolerance is its error.

use crate::model::ode::integrate_stops;
use crate::model::rod::EndKind;
use crate::model::shooting::part;
use crate::solve::continuum::{
    Continuum, ContinuumError, ContinuumLaw, STRIP_VARIATIONAL, Unknowns, VARIATIONAL,
};
use nalgebra::{Matrix6, SVector, Vector3};

/// Samples of det B(s) in (0, 1] counted for sign changes.
const SAMPLES: usize = 400;
/// Bisections of a bracket on the count before the root is refined.
const BISECTIONS: usize = 60;
/// Regula falsi iterations on D(ω²).
const REFINEMENTS: usize = 100;

/// The lowest frequencies of a continuum equilibrium.
#[derive(Clone, Debug, PartialEq)]
pub struct ContinuumSpectrum {
    /// Eigenvalues ω² < 0: conjugate points of the static Jacobi equation.
    pub negative: usize,
    /// The lowest ω², increasing.
    pub values: Vec<f64>,
    /// Each one's error: its change at a 100 times looser tolerance.
    pub errors: Vec<f64>,
}

/// B = [r̄; α] of the six perturbations in `y` (the state, then each
/// perturbation, `core` entries each, r, d1, d2, d3 first), α = ½ Σ d_i × d̄_i
/// (the small rotation d̄_i = α × d_i).
fn block(y: &[f64], core: usize) -> Matrix6<f64> {
    let mut b = Matrix6::zeros();
    for c in 0..6 {
        let delta = &y[core * (c + 1)..core * (c + 2)];
        let r = part(delta, 0);
        let alpha = 0.5
            * (1..4)
                .map(|i| part(y, i).cross(&part(delta, i)))
                .fold(Vector3::zeros(), |a, v| a + v);
        for k in 0..3 {
            b[(k, c)] = r[k];
            b[(3 + k, c)] = alpha[k];
        }
    }
    b
}

impl Continuum {
    /// det B at each of the increasing `stops` for ω² = `lambda`.
    fn determinants(
        &self,
        p: &Unknowns,
        lambda: f64,
        stops: &[f64],
    ) -> Result<Vec<f64>, ContinuumError> {
        if self.clamps.ends.end != EndKind::Clamped || self.clamps.ends.start != EndKind::Clamped {
            return Err(ContinuumError::Unsupported(
                "the stability of a rod that is not clamped at both ends",
            ));
        }
        let dets = match self.law {
            ContinuumLaw::Kirchhoff { k2, k3 } => {
                let y0 = self.variational_start(p);
                let f = |s: f64, y: &SVector<f64, VARIATIONAL>| {
                    self.variational_rhs(s, y, k2, k3, lambda)
                };
                let (ys, _) = integrate_stops(y0, f, self.tolerance, stops)?;
                ys.iter()
                    .map(|y| block(y.as_slice(), 19).determinant())
                    .collect()
            }
            ContinuumLaw::Strip { regularisation } => {
                let y0 = self.strip_variational_start(p, regularisation);
                let f = |s: f64, y: &SVector<f64, STRIP_VARIATIONAL>| {
                    self.strip_variational_rhs(s, y, regularisation, lambda)
                };
                let (ys, _) = integrate_stops(y0, f, self.tolerance, stops)?;
                ys.iter()
                    .map(|y| block(y.as_slice(), 21).determinant())
                    .collect()
            }
        };
        Ok(dets)
    }

    /// The shooting determinant D(ω²) = det B(1): zero at an eigenvalue.
    pub fn frequency_determinant(&self, p: &Unknowns, lambda: f64) -> Result<f64, ContinuumError> {
        Ok(self.determinants(p, lambda, &[1.0])?[0])
    }

    /// The number of eigenvalues ω² below `lambda`: the sign changes of
    /// det B(s) over (0, 1) (conjugate points of (A.4) at ω² = `lambda`).
    pub fn frequencies_below(&self, p: &Unknowns, lambda: f64) -> Result<usize, ContinuumError> {
        let stops: Vec<f64> = (1..=SAMPLES).map(|k| k as f64 / SAMPLES as f64).collect();
        let dets = self.determinants(p, lambda, &stops)?;
        if dets.iter().any(|d| !d.is_finite()) {
            return Err(ContinuumError::Singular);
        }
        // a conjugate point in the last interval (SAMPLES − 1)/SAMPLES..1 is
        // below `lambda` too (an eigenvalue just below it puts its conjugate
        // point just short of s = 1); only a zero at s = 1 itself is the
        // eigenvalue, not below it
        let counted = if dets[SAMPLES - 1] == 0.0 {
            &dets[..SAMPLES - 1]
        } else {
            &dets[..]
        };
        Ok(counted
            .windows(2)
            .filter(|w| (w[0] > 0.0) != (w[1] > 0.0))
            .count())
    }

    /// The lowest `count` eigenvalues ω² with their errors, and the number
    /// of negative ones. `scale` is a typical size of the lowest ones (the
    /// discrete rod's lowest |ω²| serves), from which brackets widen.
    pub fn lowest_frequencies(
        &self,
        p: &Unknowns,
        count: usize,
        scale: f64,
    ) -> Result<ContinuumSpectrum, ContinuumError> {
        let negative = self.frequencies_below(p, 0.0)?;
        let loose = Continuum {
            tolerance: 100.0 * self.tolerance,
            ..self.clone()
        };
        let mut values = Vec::with_capacity(count);
        let mut errors = Vec::with_capacity(count);
        for k in 1..=count {
            let lambda = self.eigenvalue(p, k, scale)?;
            let rough = loose.eigenvalue(p, k, scale)?;
            values.push(lambda);
            errors.push((lambda - rough).abs());
        }
        Ok(ContinuumSpectrum {
            negative,
            values,
            errors,
        })
    }

    /// The k-th lowest eigenvalue (k ≥ 1): a bracket [a, b] with k − 1
    /// eigenvalues below a and k below b, narrowed on the count until D
    /// changes sign across it alone, then regula falsi (Illinois) on D.
    fn eigenvalue(&self, p: &Unknowns, k: usize, scale: f64) -> Result<f64, ContinuumError> {
        let width = scale.abs().max(1.0);
        let (mut a, mut b) = (-width, width);
        let mut widened = 0;
        while self.frequencies_below(p, a)? >= k {
            a -= width * 4f64.powi(widened);
            widened += 1;
            if widened > 30 {
                return Err(ContinuumError::Singular);
            }
        }
        widened = 0;
        while self.frequencies_below(p, b)? < k {
            b += width * 4f64.powi(widened);
            widened += 1;
            if widened > 30 {
                return Err(ContinuumError::Singular);
            }
        }
        // narrow until the bracket holds the k-th eigenvalue alone
        for _ in 0..BISECTIONS {
            if self.frequencies_below(p, a)? == k - 1 && self.frequencies_below(p, b)? == k {
                break;
            }
            let mid = 0.5 * (a + b);
            if self.frequencies_below(p, mid)? >= k {
                b = mid;
            } else {
                a = mid;
            }
        }
        let (mut fa, mut fb) = (
            self.frequency_determinant(p, a)?,
            self.frequency_determinant(p, b)?,
        );
        if fa == 0.0 {
            return Ok(a);
        }
        if (fa > 0.0) == (fb > 0.0) {
            return Err(ContinuumError::Singular);
        }
        let mut side = 0i8;
        for _ in 0..REFINEMENTS {
            let c = (a * fb - b * fa) / (fb - fa);
            let fc = self.frequency_determinant(p, c)?;
            if fc == 0.0 || (b - a).abs() <= 1e-13 * c.abs().max(1.0) {
                return Ok(c);
            }
            if (fc > 0.0) == (fb > 0.0) {
                (b, fb) = (c, fc);
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            } else {
                (a, fa) = (c, fc);
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            }
        }
        Ok((a * fb - b * fa) / (fb - fa))
    }
}
