//! The continuum Kirchhoff equilibrium equations (A.2) integrated from s = 0,
//! used to build initial shapes from published shooting data (n(0), m(0)) and as
//! an independent reference (the paper's own method) in validation.

use crate::model::natural::NaturalStrains;
use crate::model::ode::{
    IntegrationError, REFERENCE_TOLERANCE, hermite, integrate, integrate_stops,
};
use crate::model::rod::{Clamps, EndKind, wrap};
use nalgebra::{SVector, Vector3, Vector6};
use std::f64::consts::PI;

/// State of (A.2): r, d1, d2, d3, n (material), m (material), and ∫u3 ds.
pub type OdeState = SVector<f64, 19>;

/// The k-th 3-vector of a state laid out as r, d1, d2, d3, n, m, … (the
/// rod's, the strip's, a perturbation's).
pub(crate) fn part(y: &(impl AsRef<[f64]> + ?Sized), k: usize) -> Vector3<f64> {
    let y = y.as_ref();
    Vector3::new(y[3 * k], y[3 * k + 1], y[3 * k + 2])
}

/// Right-hand side of (A.2) for K2, K3 (B11 = 1, no external force).
pub fn rhs(y: &OdeState, k2: f64, k3: f64) -> OdeState {
    rhs_loaded(y, k2, k3, &Vector3::zeros(), &Vector3::zeros())
}

/// Right-hand side of (A.2) with a body force `weight` = w g per unit length
/// (lab frame): n' = n × u − f in material components, f_i = w g·d_i; and
/// natural strains û (their value at this s): u = B⁻¹m + û.
pub fn rhs_loaded(
    y: &OdeState,
    k2: f64,
    k3: f64,
    weight: &Vector3<f64>,
    natural: &Vector3<f64>,
) -> OdeState {
    let m = part(y, 5);
    let u = Vector3::new(m[0], m[1] / k2, m[2] / k3) + natural;
    let mut f = OdeState::zeros();
    put_rates(&mut f, balance(y.as_slice(), &u, weight));
    f[18] = u[2];
    f
}

/// The rates r', d1', d2', d3', n', m' of (A.2) with strains u and a body
/// force `weight` (lab frame), from a state holding r, d1, d2, d3, n, m
/// first: the equations the rod and the strip share. n' = n × u − f and
/// m' = m × u + n × d3 in material components, f_i = w g·d_i.
pub fn balance(y: &[f64], u: &Vector3<f64>, weight: &Vector3<f64>) -> [Vector3<f64>; 6] {
    let (d1, d2, d3) = (part(y, 1), part(y, 2), part(y, 3));
    let (n, m) = (part(y, 4), part(y, 5));
    let load = Vector3::new(weight.dot(&d1), weight.dot(&d2), weight.dot(&d3));
    [
        d3,
        u[2] * d2 - u[1] * d3,
        u[0] * d3 - u[2] * d1,
        u[1] * d1 - u[0] * d2,
        n.cross(u) - load,
        m.cross(u) + Vector3::new(n[1], -n[0], 0.0),
    ]
}

/// The six rates of [`balance`] (or its derivative) into the first 18
/// entries of a state's rate.
pub fn put_rates<const D: usize>(f: &mut SVector<f64, D>, rates: [Vector3<f64>; 6]) {
    for (k, v) in rates.iter().enumerate() {
        f.fixed_rows_mut::<3>(3 * k).copy_from(v);
    }
}

/// The derivative of [`rhs_loaded`] in the state at `y` along `delta`,
/// exact ((A.2) is bilinear in the state).
pub fn rhs_loaded_derivative(
    y: &OdeState,
    delta: &OdeState,
    k2: f64,
    k3: f64,
    weight: &Vector3<f64>,
    natural: &Vector3<f64>,
) -> OdeState {
    let (m, dm) = (part(y, 5), part(delta, 5));
    let u = Vector3::new(m[0], m[1] / k2, m[2] / k3) + natural;
    let du = Vector3::new(dm[0], dm[1] / k2, dm[2] / k3);
    let mut f = OdeState::zeros();
    put_rates(
        &mut f,
        balance_derivative(y.as_slice(), &u, delta.as_slice(), &du, weight),
    );
    f[18] = du[2];
    f
}

/// [`balance`] differentiated along a perturbation `delta` of the state
/// (r, d1, d2, d3, n, m first, as `y`) and `du` of the strains: the
/// variational equations the rod and the strip share.
pub fn balance_derivative(
    y: &[f64],
    u: &Vector3<f64>,
    delta: &[f64],
    du: &Vector3<f64>,
    weight: &Vector3<f64>,
) -> [Vector3<f64>; 6] {
    let (d1, d2, d3) = (part(y, 1), part(y, 2), part(y, 3));
    let (e1, e2, e3) = (part(delta, 1), part(delta, 2), part(delta, 3));
    let (n, m) = (part(y, 4), part(y, 5));
    let (dn, dm) = (part(delta, 4), part(delta, 5));
    let load = Vector3::new(weight.dot(&e1), weight.dot(&e2), weight.dot(&e3));
    [
        e3,
        u[2] * e2 + du[2] * d2 - u[1] * e3 - du[1] * d3,
        u[0] * e3 + du[0] * d3 - u[2] * e1 - du[2] * d1,
        u[1] * e1 + du[1] * d1 - u[0] * e2 - du[0] * d2,
        dn.cross(u) + n.cross(du) - load,
        dm.cross(u) + m.cross(du) + Vector3::new(dn[1], -dn[0], 0.0),
    ]
}

/// A solution of (A.2) on [0, 1], integrated to [`REFERENCE_TOLERANCE`] and
/// sampled on a uniform grid (the integrator's dense output).
#[derive(Clone, Debug)]
pub struct ShootingSolution {
    /// Samples at s = k / intervals.
    pub samples: Vec<OdeState>,
    /// Bending ratios.
    pub k2: f64,
    /// Twisting ratio.
    pub k3: f64,
    /// Body force per unit length (lab frame).
    pub weight: Vector3<f64>,
    /// Natural strains û(s).
    pub natural: NaturalStrains,
}

impl ShootingSolution {
    /// Integrate from r = 0, d_i = e_i, with n(0), m(0) in the material
    /// frame, sampled at `intervals` + 1 points.
    pub fn integrate(
        n0: Vector3<f64>,
        m0: Vector3<f64>,
        k2: f64,
        k3: f64,
        intervals: usize,
    ) -> Result<Self, IntegrationError> {
        let straight = NaturalStrains::default();
        Self::integrate_loaded(n0, m0, k2, k3, Vector3::zeros(), straight, intervals)
    }

    /// As `integrate`, under a body force `weight` per unit length (lab
    /// frame), for a rod of natural strains `natural`.
    pub fn integrate_loaded(
        n0: Vector3<f64>,
        m0: Vector3<f64>,
        k2: f64,
        k3: f64,
        weight: Vector3<f64>,
        natural: NaturalStrains,
        intervals: usize,
    ) -> Result<Self, IntegrationError> {
        Self::integrate_from(
            &Clamps::new(0.0, 0.0, 0.0),
            n0,
            m0,
            [k2, k3],
            (weight, natural),
            intervals,
        )
    }

    /// As `integrate_loaded`, from the s = 0 clamp of `clamps` (r(0) at its
    /// point, the directors its material frame; n(0), m(0) in that frame).
    pub fn integrate_from(
        clamps: &Clamps,
        n0: Vector3<f64>,
        m0: Vector3<f64>,
        [k2, k3]: [f64; 2],
        (weight, natural): (Vector3<f64>, NaturalStrains),
        intervals: usize,
    ) -> Result<Self, IntegrationError> {
        let f = |s: f64, y: &OdeState| rhs_loaded(y, k2, k3, &weight, &natural.vector_at(s));
        let y0 = start_state(clamps, n0, m0);
        let samples = integrate(y0, f, REFERENCE_TOLERANCE, intervals.max(1) + 1)?.samples;
        Ok(ShootingSolution {
            samples,
            k2,
            k3,
            weight,
            natural,
        })
    }

    /// State at s by cubic Hermite interpolation with the exact derivative (A.2).
    pub fn at(&self, s: f64) -> OdeState {
        hermite(&self.samples, s, |s, y| {
            rhs_loaded(
                y,
                self.k2,
                self.k3,
                &self.weight,
                &self.natural.vector_at(s),
            )
        })
    }

    /// Centreline r(s).
    pub fn position(&self, s: f64) -> Vector3<f64> {
        part(&self.at(s), 0)
    }

    /// Director d1(s).
    pub fn d1(&self, s: f64) -> Vector3<f64> {
        part(&self.at(s), 1)
    }

    /// The end state at s = 1.
    pub fn end(&self) -> &OdeState {
        self.samples.last().unwrap()
    }

    /// Total twist (1/2π) ∫ u3 ds.
    pub fn twist(&self) -> f64 {
        self.end()[18] / (2.0 * PI)
    }

    /// Mismatch of the s = 1 boundary conditions (2.10)-(2.11) for `clamps`:
    /// r(1) - r*, d3x(1), d3y(1), and the angle of d1 minus φ (mod 2π), for a
    /// clamped end.
    ///
    /// At a pinned end: r(1) − r* and m(1); at a free end: n(1) and m(1)
    /// (the natural conditions, in material components).
    pub fn boundary_residual(&self, clamps: &Clamps) -> Vector6<f64> {
        end_residual(self.end(), clamps)
    }
}

/// The s = 1 residual of the solution of (A.2) from n(0), m(0) at the s = 0
/// clamp of `clamps` (as [`ShootingSolution::boundary_residual`], integrated
/// to its end only).
pub fn shooting_residual(
    clamps: &Clamps,
    n0: Vector3<f64>,
    m0: Vector3<f64>,
    [k2, k3]: [f64; 2],
    (weight, natural): (Vector3<f64>, &NaturalStrains),
) -> Result<Vector6<f64>, IntegrationError> {
    let f = |s: f64, y: &OdeState| rhs_loaded(y, k2, k3, &weight, &natural.vector_at(s));
    let (ends, _) = integrate_stops(start_state(clamps, n0, m0), f, REFERENCE_TOLERANCE, &[1.0])?;
    Ok(end_residual(&ends[0], clamps))
}

fn start_state(clamps: &Clamps, n0: Vector3<f64>, m0: Vector3<f64>) -> OdeState {
    let mut y = start_frame(clamps);
    for c in 0..3 {
        y[12 + c] = n0[c];
        y[15 + c] = m0[c];
    }
    y
}

fn end_residual(y: &OdeState, clamps: &Clamps) -> Vector6<f64> {
    end_conditions(
        [part(y, 0), part(y, 1), part(y, 3)],
        (part(y, 4), part(y, 5)),
        clamps,
    )
}

/// The s = 1 conditions of `clamps` at an end r, d1, d3 with force and
/// moment n, m (material components): clamped, [`end_mismatch`]; pinned,
/// r(1) − r* and m(1); free, n(1) and m(1) (the natural conditions).
pub fn end_conditions(
    rd: [Vector3<f64>; 3],
    (n1, m1): (Vector3<f64>, Vector3<f64>),
    clamps: &Clamps,
) -> Vector6<f64> {
    match clamps.ends.end {
        EndKind::Clamped => end_mismatch(rd, clamps),
        EndKind::Pinned => {
            let r = rd[0] - clamps.end_point();
            Vector6::new(r[0], r[1], r[2], m1[0], m1[1], m1[2])
        }
        EndKind::Free => Vector6::new(n1[0], n1[1], n1[2], m1[0], m1[1], m1[2]),
    }
}

/// The s = 1 conditions (2.10)-(2.11) for `clamps` at an end r, d1, d3 (the
/// rod's and the strip's): r − r*, d3x, d3y, and the angle of d1 minus φ
/// (mod 2π).
pub fn end_mismatch([r, mut d1, mut d3]: [Vector3<f64>; 3], clamps: &Clamps) -> Vector6<f64> {
    let r = r - clamps.end_point();
    let o = &clamps.end.orientation;
    if !o.is_identity() {
        // components in the clamp's frame before its turn φ
        let back = o.matrix().inverse();
        d1 = back * d1;
        d3 = back * d3;
    }
    Vector6::new(
        r[0],
        r[1],
        r[2],
        d3[0],
        d3[1],
        wrap(d1[1].atan2(d1[0]) - clamps.phi),
    )
}

/// The ODE state at s = 0 of the clamps' s = 0 frame: r(0) at its point, the
/// directors its material frame (the identity at the origin for the paper's),
/// forces and moments zero.
pub fn start_frame(clamps: &Clamps) -> OdeState {
    let mut y = OdeState::zeros();
    if clamps.start.is_default() {
        y[3] = 1.0;
        y[7] = 1.0;
        y[11] = 1.0;
        return y;
    }
    let frame = clamps.start_frame();
    let r = clamps.start_point();
    for c in 0..3 {
        y[c] = r[c];
        for k in 0..3 {
            y[3 * (k + 1) + c] = frame[(c, k)];
        }
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SMatrix;

    #[test]
    fn the_variational_equations_are_the_right_hand_sides_derivative() {
        let (k2, k3) = (2.5, 0.7);
        let weight = Vector3::new(0.3, -1.2, 0.8);
        let natural = Vector3::new(0.4, -0.3, 0.2);
        let f = |y: &OdeState| rhs_loaded(y, k2, k3, &weight, &natural);
        for t in [0.3, 1.1, 2.9] {
            let y = OdeState::from_fn(|i, _| ((i as f64 + 0.4) * t).sin() * 3.0);
            let mut exact = SMatrix::<f64, 19, 19>::zeros();
            let mut fd = SMatrix::<f64, 19, 19>::zeros();
            for c in 0..19 {
                let mut e = OdeState::zeros();
                e[c] = 1.0;
                exact.set_column(c, &rhs_loaded_derivative(&y, &e, k2, k3, &weight, &natural));
                // a central difference is exact for a quadratic, up to round-off
                let h = 1e-3;
                fd.set_column(c, &((f(&(y + h * e)) - f(&(y - h * e))) / (2.0 * h)));
            }
            let err = (exact - fd).norm() / exact.norm();
            assert!(err < 1e-12, "relative difference {err:.1e}");
        }
    }
}
