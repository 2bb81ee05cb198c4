//! The continuum elastic strip (paper Sec. 4) by shooting: the equilibrium
//! form of (A.1) with u2 = 0 (4.1) and the Sadowsky law (4.2) differentiated
//! along s as in (4.3), so that the strains are integrated rather than
//! recovered from the moments (whose inversion has several roots).
//!
//! The law is the DER's own (`energy::strip_energy` with h = 1): the density
//! W(a, u3) = ½ (a² + u3²)² / (a² + ε²) of a = u1 − û1(s), with the same
//! regularisation ε, so that m1 = ∂W/∂a, m3 = ∂W/∂u3 and (4.3) becomes
//! H (a', u3')ᵀ = (m1', m3')ᵀ with H the Hessian of W (ε = 0 and û1 = 0 give
//! the paper's (4.3) exactly). Integrating a = u1 − û1 rather than u1 keeps the
//! slope of a tabulated û1 out of the right-hand side: u1 = a + û1(s) is only
//! continuous where the table has a corner, never discontinuous. The weight
//! enters the force balance as in the rod's ODE (`shooting::rhs_loaded`).
//!
//! Like `shooting.rs` this is a reference (the paper's method), never part of
//! the rod solver; its start values come from a DER strip equilibrium
//! ([`StripUnknowns::from_der`]).

use crate::model::energy::{RodEnergy, vertex_strains};
use crate::model::natural::NaturalStrains;
use crate::model::ode::{
    IntegrationError, REFERENCE_TOLERANCE, hermite, integrate, integrate_stops,
};
use crate::model::rod::{Clamps, RodState};
use crate::model::shooting::{balance, balance_derivative, end_mismatch, part, put_rates};
use nalgebra::{Matrix2, SVector, Vector2, Vector3, Vector6};
use std::f64::consts::PI;

/// State of the strip ODE: r, d1, d2, d3, n (material), m (material) — the
/// paper's 18 — then a = u1 − û1 and u3 (its 19th and 20th, u1 shifted by
/// the natural curvature), and ∫u3 ds.
pub type StripOdeState = SVector<f64, 21>;

/// Index of a = u1 − û1 in [`StripOdeState`].
const A: usize = 18;
/// Index of u3.
const U3: usize = 19;
/// Index of ∫u3 ds.
const TWIST: usize = 20;

/// Why strip shooting failed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum StripShootingError {
    /// Newton did not bring the s = 1 residual below its tolerance.
    #[error(
        "strip shooting: Newton did not converge in {iterations} iterations (residual {residual:e})"
    )]
    NotConverged {
        /// Iterations made.
        iterations: usize,
        /// The last residual's norm.
        residual: f64,
    },
    /// The Jacobian of the s = 1 conditions was singular or not finite.
    #[error("strip shooting: singular or non-finite Jacobian of the s = 1 conditions")]
    Singular,
    /// The strip's equations could not be integrated from the unknowns.
    #[error("strip shooting: {0}")]
    Integration(#[from] IntegrationError),
}

/// The Sadowsky density W(a, u3) of the DER (`strip_energy` at h = 1): its
/// gradient (m1, m3) and Hessian, in closed form (W = S²/2D with S = a² + u3²,
/// D = a² + ε²; tested against the DER's density differentiated by jets).
pub fn sadowsky(a: f64, u3: f64, regularisation: f64) -> (Vector2<f64>, Matrix2<f64>) {
    let (a2, u2, e2) = (a * a, u3 * u3, regularisation * regularisation);
    let (s, d) = (a2 + u2, a2 + e2);
    let gradient = Vector2::new(a * s * (a2 + 2.0 * e2 - u2) / (d * d), 2.0 * u3 * s / d);
    let w_aa = (a2 * a2 * a2 + 3.0 * a2 * a2 * e2 + 6.0 * a2 * e2 * e2 - 6.0 * a2 * e2 * u2
        + 3.0 * a2 * u2 * u2
        + 2.0 * e2 * e2 * u2
        - e2 * u2 * u2)
        / (d * d * d);
    let w_au = -4.0 * a * u3 * (u2 - e2) / (d * d);
    let w_uu = 2.0 * (a2 + 3.0 * u2) / d;
    (gradient, Matrix2::new(w_aa, w_au, w_au, w_uu))
}

/// The Sadowsky density's third derivatives (W_aaa, W_aau, W_auu, W_uuu):
/// how the Hessian of (4.3) moves with the strains, for the strip's
/// variational equations.
pub fn sadowsky_third(a: f64, u3: f64, regularisation: f64) -> [f64; 4] {
    let (a2, u2, e2) = (a * a, u3 * u3, regularisation * regularisation);
    let d = a2 + e2;
    [
        -12.0 * a * (a2 - e2) * (u2 - e2) * (u2 - e2) / (d * d * d * d),
        4.0 * u3 * (3.0 * a2 - e2) * (u2 - e2) / (d * d * d),
        -4.0 * a * (3.0 * u2 - e2) / (d * d),
        12.0 * u3 / d,
    ]
}

/// The paper's six shooting unknowns of the strip at s = 0 (Sec. 4):
/// n(0), u1(0), m2(0), u3(0) (components in the clamp's frame, the lab's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StripUnknowns {
    /// n(0).
    pub n0: Vector3<f64>,
    /// u1(0), the curvature about d1.
    pub u1: f64,
    /// m2(0), the moment about d2 (the multiplier of u2 = 0).
    pub m2: f64,
    /// u3(0), the twist rate.
    pub u3: f64,
}

impl StripUnknowns {
    pub(crate) fn to_vector(self) -> Vector6<f64> {
        Vector6::new(
            self.n0[0], self.n0[1], self.n0[2], self.u1, self.m2, self.u3,
        )
    }

    pub(crate) fn from_vector(p: &Vector6<f64>) -> Self {
        StripUnknowns {
            n0: p.fixed_rows::<3>(0).into(),
            u1: p[3],
            m2: p[4],
            u3: p[5],
        }
    }

    /// Start values from a DER strip equilibrium: n(0) and m2(0) from its
    /// clamp reactions, u1(0) and u3(0) extrapolated linearly to s = 0 from
    /// its first two vertices (at s = h/2 and 3h/2), all second order in h.
    pub fn from_der(energy: &RodEnergy, state: &RodState) -> Self {
        let reactions = energy.clamp_reactions(state);
        let (u, v) = (vertex_strains(state, 1), vertex_strains(state, 2));
        StripUnknowns {
            n0: reactions.force,
            u1: 1.5 * u[0] - 0.5 * v[0],
            m2: reactions.moment[1],
            u3: 1.5 * u[2] - 0.5 * v[2],
        }
    }
}

/// Right-hand side of the strip ODE at arc length s (B = 1): (A.2) with
/// u = (u1, 0, u3), u1 = a + û1(s), the weight `weight` = w g per unit length
/// (lab frame) in the force balance, and (a', u3') = H⁻¹ (m1', m3').
pub fn strip_rhs(
    s: f64,
    y: &StripOdeState,
    regularisation: f64,
    weight: &Vector3<f64>,
    natural: &NaturalStrains,
) -> StripOdeState {
    rates(s, y, regularisation, weight, natural).0
}

/// y' at (s, y) with the strains u = (u1, 0, u3) and H⁻¹ of (4.3) it used:
/// (A.2)'s frame, force and moment rates, ∫u3, and (a', u3') = H⁻¹ (m1',
/// m3'), NaN where the law's Hessian is singular (the integration then
/// stops as not finite).
fn rates(
    s: f64,
    y: &StripOdeState,
    regularisation: f64,
    weight: &Vector3<f64>,
    natural: &NaturalStrains,
) -> (StripOdeState, Vector3<f64>, Matrix2<f64>) {
    let u = Vector3::new(y[A] + natural.at(s)[0], 0.0, y[U3]);
    let mut f = StripOdeState::zeros();
    put_rates(&mut f, balance(y.as_slice(), &u, weight));
    f[TWIST] = u[2];
    // (4.3): the law's moments follow m1' and m3' through its Hessian
    let (_, h) = sadowsky(y[A], y[U3], regularisation);
    let inverse = h.try_inverse().unwrap_or(Matrix2::repeat(f64::NAN));
    let du = inverse * Vector2::new(f[15], f[17]);
    f[A] = du[0];
    f[U3] = du[1];
    (f, u, inverse)
}

/// The strip ODE's right-hand side at one (s, y) with what its derivative
/// in y needs: the strip's variational equations, exact (the law's third
/// derivatives move its Hessian in (4.3)).
#[derive(Clone, Debug)]
pub struct StripRhs {
    /// y' at (s, y).
    pub value: StripOdeState,
    state: StripOdeState,
    strains: Vector3<f64>,
    weight: Vector3<f64>,
    inverse_hessian: Matrix2<f64>,
    third: [f64; 4],
}

impl StripRhs {
    /// The right-hand side of [`strip_rhs`] at (s, y) and its linearisation
    /// there.
    pub fn at(
        s: f64,
        y: &StripOdeState,
        regularisation: f64,
        weight: &Vector3<f64>,
        natural: &NaturalStrains,
    ) -> Self {
        let (value, strains, inverse_hessian) = rates(s, y, regularisation, weight, natural);
        StripRhs {
            value,
            state: *y,
            strains,
            weight: *weight,
            inverse_hessian,
            third: sadowsky_third(y[A], y[U3], regularisation),
        }
    }

    /// The right-hand side's derivative in y along `delta`.
    pub fn derivative(&self, delta: &StripOdeState) -> StripOdeState {
        let du = Vector3::new(delta[A], 0.0, delta[U3]);
        let mut f = StripOdeState::zeros();
        put_rates(
            &mut f,
            balance_derivative(
                self.state.as_slice(),
                &self.strains,
                delta.as_slice(),
                &du,
                &self.weight,
            ),
        );
        f[TWIST] = du[2];
        // H (a', u3')ᵀ = (m1', m3')ᵀ differentiated: H δ(a', u3') + δH (a', u3') = δ(m1', m3')
        let [w_aaa, w_aau, w_auu, w_uuu] = self.third;
        let (x, z) = (delta[A], delta[U3]);
        let off = w_aau * x + w_auu * z;
        let dh = Matrix2::new(w_aaa * x + w_aau * z, off, off, w_auu * x + w_uuu * z);
        let rates = Vector2::new(self.value[A], self.value[U3]);
        let d_rates = self.inverse_hessian * (Vector2::new(f[15], f[17]) - dh * rates);
        f[A] = d_rates[0];
        f[U3] = d_rates[1];
        f
    }
}

/// A solution of the strip ODE on [0, 1], integrated to
/// [`REFERENCE_TOLERANCE`] and sampled on a uniform grid (the integrator's
/// dense output).
#[derive(Clone, Debug)]
pub struct StripSolution {
    /// Samples at s = k / intervals.
    pub samples: Vec<StripOdeState>,
    /// ε of the Sadowsky law.
    pub regularisation: f64,
    /// Body force per unit length (lab frame).
    pub weight: Vector3<f64>,
    /// Natural strains (only û1 enters the strip law).
    pub natural: NaturalStrains,
}

impl StripSolution {
    /// Integrate from r = 0, d_i = e_i with the unknowns `p`, sampled at
    /// `intervals` + 1 points; m1(0), m3(0) follow from the law (4.2) at
    /// s = 0.
    pub fn integrate(
        p: &StripUnknowns,
        regularisation: f64,
        weight: Vector3<f64>,
        natural: NaturalStrains,
        intervals: usize,
    ) -> Result<Self, IntegrationError> {
        let y0 = strip_start(p, regularisation, &natural);
        let f = |s: f64, y: &StripOdeState| strip_rhs(s, y, regularisation, &weight, &natural);
        let samples = integrate(y0, f, REFERENCE_TOLERANCE, intervals.max(1) + 1)?.samples;
        Ok(StripSolution {
            samples,
            regularisation,
            weight,
            natural,
        })
    }

    /// State at s by cubic Hermite interpolation with the exact derivative.
    pub fn at(&self, s: f64) -> StripOdeState {
        hermite(&self.samples, s, |s, y| {
            strip_rhs(s, y, self.regularisation, &self.weight, &self.natural)
        })
    }

    /// Centreline r(s).
    pub fn position(&self, s: f64) -> Vector3<f64> {
        part(&self.at(s), 0)
    }

    /// Director d1(s) (across the strip's width).
    pub fn d1(&self, s: f64) -> Vector3<f64> {
        part(&self.at(s), 1)
    }

    /// The strains (u1, u3) at s.
    pub fn strains(&self, s: f64) -> (f64, f64) {
        let y = self.at(s);
        (y[A] + self.natural.at(s)[0], y[U3])
    }

    /// n(0) and m(0) (material components, the lab's at s = 0).
    pub fn reactions(&self) -> (Vector3<f64>, Vector3<f64>) {
        let y = &self.samples[0];
        (part(y, 4), part(y, 5))
    }

    /// The end state at s = 1.
    pub fn end(&self) -> &StripOdeState {
        self.samples.last().unwrap_or(&self.samples[0])
    }

    /// Total twist (1/2π) ∫ u3 ds.
    pub fn twist(&self) -> f64 {
        self.end()[TWIST] / (2.0 * PI)
    }

    /// Mismatch of the s = 1 conditions (2.10)–(2.11) for `clamps`, as for
    /// the rod: r(1) − r*, d3x(1), d3y(1), and the angle of d1 minus φ (mod 2π).
    pub fn boundary_residual(&self, clamps: &Clamps) -> Vector6<f64> {
        let y = self.end();
        end_mismatch([part(y, 0), part(y, 1), part(y, 3)], clamps)
    }
}

/// The strip's state at s = 0 from the unknowns `p`: r = 0, d_i = e_i,
/// m1(0), m3(0) from the law (4.2).
fn strip_start(p: &StripUnknowns, regularisation: f64, natural: &NaturalStrains) -> StripOdeState {
    let a0 = p.u1 - natural.at(0.0)[0];
    let (m13, _) = sadowsky(a0, p.u3, regularisation);
    let mut y = StripOdeState::zeros();
    y[3] = 1.0;
    y[7] = 1.0;
    y[11] = 1.0;
    y.fixed_rows_mut::<3>(12).copy_from(&p.n0);
    y.fixed_rows_mut::<3>(15)
        .copy_from(&Vector3::new(m13[0], p.m2, m13[1]));
    y[A] = a0;
    y[U3] = p.u3;
    y
}

/// The strip problem to shoot: its law, load, natural strains, clamps and
/// the samples of its solutions.
#[derive(Clone, Debug)]
pub struct StripProblem {
    /// ε of the Sadowsky law.
    pub regularisation: f64,
    /// Body force per unit length (lab frame).
    pub weight: Vector3<f64>,
    /// Natural strains (û1 only for strips).
    pub natural: NaturalStrains,
    /// The s = 1 clamp.
    pub clamps: Clamps,
    /// Intervals of [0, 1] a solution is sampled at.
    pub intervals: usize,
}

impl StripProblem {
    /// The solution from the unknowns `p`.
    pub fn integrate(&self, p: &StripUnknowns) -> Result<StripSolution, IntegrationError> {
        StripSolution::integrate(
            p,
            self.regularisation,
            self.weight,
            self.natural.clone(),
            self.intervals,
        )
    }

    /// The s = 1 residual of the solution from `p` (integrated to its end
    /// only).
    pub fn residual(&self, p: &StripUnknowns) -> Result<Vector6<f64>, IntegrationError> {
        let (r, w, natural) = (self.regularisation, &self.weight, &self.natural);
        let f = |s: f64, y: &StripOdeState| strip_rhs(s, y, r, w, natural);
        let y0 = strip_start(p, r, natural);
        let (ends, _) = integrate_stops(y0, f, REFERENCE_TOLERANCE, &[1.0])?;
        let y = &ends[0];
        Ok(end_mismatch(
            [part(y, 0), part(y, 1), part(y, 3)],
            &self.clamps,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::jet;
    use crate::model::energy::strip_energy;
    use nalgebra::SMatrix;

    /// States of the strip with every component in play, a weight and a
    /// varying natural curvature.
    fn samples() -> Vec<(f64, StripOdeState, f64)> {
        (0..6)
            .map(|k| {
                let t = k as f64;
                let y = StripOdeState::from_fn(|i, _| ((i as f64 + 1.3) * (t + 0.7)).sin());
                (0.1 + 0.15 * t, y, [0.0, 0.02, 0.3][k % 3])
            })
            .collect()
    }

    #[test]
    fn the_closed_form_law_is_the_ders_density_differentiated() {
        for (_, y, eps) in samples() {
            let (a, u3) = (y[A], y[U3]);
            let (_, g, h) = jet::hessian::<2, 3>([a, u3], |v| strip_energy(v[0], v[1], eps, 1.0));
            let (m, hh) = sadowsky(a, u3, eps);
            let scale = 1.0 + g[0].abs().max(g[1].abs());
            assert!(
                (m - Vector2::new(g[0], g[1])).norm() < 1e-13 * scale,
                "{m} {g:?}"
            );
            let dense = Matrix2::new(h[0][0], h[0][1], h[1][0], h[1][1]);
            assert!(
                (hh - dense).norm() < 1e-12 * (1.0 + dense.norm()),
                "{hh} {dense}"
            );
            // the third derivatives: central differences of the Hessian
            let [w_aaa, w_aau, w_auu, w_uuu] = sadowsky_third(a, u3, eps);
            let step = 1e-5;
            let da = (sadowsky(a + step, u3, eps).1 - sadowsky(a - step, u3, eps).1) / (2.0 * step);
            let du = (sadowsky(a, u3 + step, eps).1 - sadowsky(a, u3 - step, eps).1) / (2.0 * step);
            let exact_a = Matrix2::new(w_aaa, w_aau, w_aau, w_auu);
            let exact_u = Matrix2::new(w_aau, w_auu, w_auu, w_uuu);
            for (fd, exact) in [(da, exact_a), (du, exact_u)] {
                let err = (fd - exact).norm() / (1.0 + exact.norm());
                assert!(err < 1e-7, "{fd} against {exact}: {err:.1e}");
            }
        }
    }

    #[test]
    fn the_variational_equations_are_the_right_hand_sides_derivative() {
        let weight = Vector3::new(0.3, -0.7, 1.1);
        let natural = NaturalStrains::Constant([0.4, 0.0, 0.0]);
        for (s, y, eps) in samples() {
            let rhs = StripRhs::at(s, &y, eps, &weight, &natural);
            assert_eq!(rhs.value, strip_rhs(s, &y, eps, &weight, &natural));
            let mut jacobian = SMatrix::<f64, 21, 21>::zeros();
            let mut fd = SMatrix::<f64, 21, 21>::zeros();
            for c in 0..21 {
                let mut e = StripOdeState::zeros();
                e[c] = 1.0;
                jacobian.set_column(c, &rhs.derivative(&e));
                let h = 1e-6;
                let f = |y: &StripOdeState| strip_rhs(s, y, eps, &weight, &natural);
                fd.set_column(c, &((f(&(y + h * e)) - f(&(y - h * e))) / (2.0 * h)));
            }
            let err = (jacobian - fd).norm() / jacobian.norm();
            assert!(
                err < 1e-8,
                "at s = {s}, ε = {eps}: relative difference {err:.1e}"
            );
            // linear in the direction
            let (e, f) = (y.map(|v| v.cos()), y.map(|v| (2.0 * v).sin()));
            let sum = rhs.derivative(&(2.0 * e - f));
            let parts = 2.0 * rhs.derivative(&e) - rhs.derivative(&f);
            assert!((sum - parts).norm() < 1e-12 * (1.0 + sum.norm()));
        }
    }

    #[test]
    fn the_law_is_the_papers_at_zero_regularisation() {
        // (4.2): m1 = u1 (1 − u3⁴/u1⁴), m3 = 2 u3 (1 + u3²/u1²)
        let (u1, u3) = (1.7, -0.6);
        let (m, h) = sadowsky(u1, u3, 0.0);
        assert!((m[0] - u1 * (1.0 - u3.powi(4) / u1.powi(4))).abs() < 1e-12);
        assert!((m[1] - 2.0 * u3 * (1.0 + u3 * u3 / (u1 * u1))).abs() < 1e-12);
        // and its Hessian inverts (4.3): det H = 2 (1 + t²)³, t = u3/u1
        let t = u3 / u1;
        assert!((h.determinant() - 2.0 * (1.0 + t * t).powi(3)).abs() < 1e-10);
    }

    #[test]
    fn the_double_ring_is_an_exact_solution() {
        // u1 = 4π, û1 = 1, nothing else: with n = 0 the moment m = (m1, 0, 0)
        // is constant (m × u = 0) and the strip is the doubly covered ring
        // (paper Sec. 6), back at the origin along e3 turned by 2π. (The
        // relaxed ring u1 = û1 is no test: the law is quartic at rest, its
        // Hessian zero there, and the ODE singular.)
        let p = StripUnknowns {
            n0: Vector3::zeros(),
            u1: 4.0 * PI,
            m2: 0.0,
            u3: 0.0,
        };
        let natural = NaturalStrains::from([1.0, 0.0, 0.0]);
        let sol = StripSolution::integrate(&p, 0.05, Vector3::zeros(), natural, 20_000).unwrap();
        let ring = Clamps::new(0.0, 0.0, 1.0);
        assert!(sol.boundary_residual(&ring).norm() < 1e-10);
        let r = sol.position(0.125);
        let radius = 1.0 / (4.0 * PI);
        assert!((r - Vector3::new(0.0, -radius, radius)).norm() < 1e-10);
        assert!((sol.strains(0.7).0 - 4.0 * PI).abs() < 1e-10);
    }
}
