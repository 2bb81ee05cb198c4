//! Second-order jets (value, gradient, packed Hessian) of a fixed number of
//! variables: forward-mode automatic differentiation for the energy stencils.
//!
//! Written here rather than taken from a general dual-number crate because the
//! stencil Hessian is the hot path of every Newton step: a flat, `Option`-free
//! value type with the Hessian stored once (its lower triangle) and every
//! operation inlined costs a fraction of a general hyper-dual number.

// index loops mirror the formulas (packed triangle k ↔ (i, j)); division is
// multiplication by the reciprocal's jet
#![allow(clippy::needless_range_loop, clippy::suspicious_arithmetic_impl)]

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

/// Scalar usable in the energy stencils: `f64`, [`Jet`] or [`Grad`].
pub trait Scalar:
    Copy
    + From<f64>
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + AddAssign
{
    /// 1/x.
    fn recip(self) -> Self;
    /// √x.
    fn sqrt(self) -> Self;
    /// (sin x, cos x).
    fn sin_cos(self) -> (Self, Self);
    /// The angle of the point (x, self).
    fn atan2(self, x: Self) -> Self;
}

impl Scalar for f64 {
    #[inline(always)]
    fn recip(self) -> Self {
        f64::recip(self)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        f64::sin_cos(self)
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        f64::atan2(self, x)
    }
}

/// Value, gradient and Hessian of a function of `N` variables; the Hessian's
/// lower triangle is packed row by row in `h` (`M` = N(N+1)/2 entries).
#[derive(Clone, Copy, Debug)]
pub struct Jet<const N: usize, const M: usize> {
    /// Value.
    pub v: f64,
    /// Gradient.
    pub g: [f64; N],
    /// Packed lower-triangular Hessian.
    pub h: [f64; M],
}

/// Jet of the 8 variables of a vertex stencil.
pub type Jet8 = Jet<8, 36>;
/// Jet of the 4 variables of one edge of a vertex stencil (edge vector, angle).
pub type Jet4 = Jet<4, 10>;
/// Jet of the 6 variables of both edges of a vertex stencil.
pub type Jet6 = Jet<6, 21>;
/// Jet of the 3 variables of an edge stencil.
pub type Jet3 = Jet<3, 6>;

impl<const N: usize, const M: usize> Jet<N, M> {
    const PACKED: () = assert!(M == N * (N + 1) / 2, "M must be N(N+1)/2");

    /// The k-th independent variable, with value `v`.
    pub fn variable(v: f64, k: usize) -> Self {
        let () = Self::PACKED;
        let mut g = [0.0; N];
        g[k] = 1.0;
        Jet { v, g, h: [0.0; M] }
    }

    /// The chain rule for f(self) given f, f', f''.
    #[inline(always)]
    fn chain(self, f0: f64, f1: f64, f2: f64) -> Self {
        let mut h = [0.0; M];
        let mut k = 0;
        for i in 0..N {
            let gi = f2 * self.g[i];
            for j in 0..=i {
                h[k] = f1 * self.h[k] + gi * self.g[j];
                k += 1;
            }
        }
        Jet {
            v: f0,
            g: self.g.map(|x| f1 * x),
            h,
        }
    }

    /// The same function seen as one of `N2` variables, its variable k being
    /// variable `slots[k]` there (slots increasing), written into `out` (a
    /// jet of zero derivatives).
    #[inline(always)]
    pub fn embed_into<const N2: usize, const M2: usize>(
        &self,
        out: &mut Jet<N2, M2>,
        slots: [usize; N],
    ) {
        out.v = self.v;
        let mut k = 0;
        for i in 0..N {
            out.g[slots[i]] = self.g[i];
            let row = slots[i] * (slots[i] + 1) / 2;
            for j in 0..=i {
                out.h[row + slots[j]] = self.h[k];
                k += 1;
            }
        }
    }

    /// The Hessian as a dense row-major N×N array.
    pub fn dense_hessian(&self) -> [[f64; N]; N] {
        let mut out = [[0.0; N]; N];
        let mut k = 0;
        for i in 0..N {
            for j in 0..=i {
                out[i][j] = self.h[k];
                out[j][i] = self.h[k];
                k += 1;
            }
        }
        out
    }
}

impl<const N: usize, const M: usize> From<f64> for Jet<N, M> {
    #[inline(always)]
    fn from(v: f64) -> Self {
        Jet {
            v,
            g: [0.0; N],
            h: [0.0; M],
        }
    }
}

impl<const N: usize, const M: usize> Add for Jet<N, M> {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, b: Self) -> Self {
        self += b;
        self
    }
}

impl<const N: usize, const M: usize> AddAssign for Jet<N, M> {
    #[inline(always)]
    fn add_assign(&mut self, b: Self) {
        self.v += b.v;
        for i in 0..N {
            self.g[i] += b.g[i];
        }
        for k in 0..M {
            self.h[k] += b.h[k];
        }
    }
}

impl<const N: usize, const M: usize> Sub for Jet<N, M> {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, b: Self) -> Self {
        self.v -= b.v;
        for i in 0..N {
            self.g[i] -= b.g[i];
        }
        for k in 0..M {
            self.h[k] -= b.h[k];
        }
        self
    }
}

impl<const N: usize, const M: usize> Neg for Jet<N, M> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self * -1.0
    }
}

impl<const N: usize, const M: usize> Mul for Jet<N, M> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, b: Self) -> Self {
        let a = self;
        let mut h = [0.0; M];
        let mut k = 0;
        for i in 0..N {
            let (ai, bi) = (a.g[i], b.g[i]);
            for j in 0..=i {
                h[k] = a.v * b.h[k] + b.v * a.h[k] + ai * b.g[j] + bi * a.g[j];
                k += 1;
            }
        }
        let mut g = [0.0; N];
        for i in 0..N {
            g[i] = a.v * b.g[i] + b.v * a.g[i];
        }
        Jet { v: a.v * b.v, g, h }
    }
}

impl<const N: usize, const M: usize> Div for Jet<N, M> {
    type Output = Self;
    #[inline(always)]
    fn div(self, b: Self) -> Self {
        self * b.recip()
    }
}

impl<const N: usize, const M: usize> Add<f64> for Jet<N, M> {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, b: f64) -> Self {
        self.v += b;
        self
    }
}

impl<const N: usize, const M: usize> Sub<f64> for Jet<N, M> {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, b: f64) -> Self {
        self.v -= b;
        self
    }
}

impl<const N: usize, const M: usize> Mul<f64> for Jet<N, M> {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, s: f64) -> Self {
        self.v *= s;
        self.g.iter_mut().for_each(|x| *x *= s);
        self.h.iter_mut().for_each(|x| *x *= s);
        self
    }
}

impl<const N: usize, const M: usize> Scalar for Jet<N, M> {
    #[inline(always)]
    fn recip(self) -> Self {
        let r = 1.0 / self.v;
        self.chain(r, -r * r, 2.0 * r * r * r)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        self.chain(s, 0.5 / s, -0.25 / (s * self.v))
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        (self.chain(s, c, -s), self.chain(c, -s, -c))
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        // f(y, x) = atan2(y, x): f_y = x/r², f_x = −y/r², f_yy = −2xy/r⁴,
        // f_xx = 2xy/r⁴, f_xy = (y² − x²)/r⁴
        let y = self;
        let r2 = y.v * y.v + x.v * x.v;
        let (fy, fx) = (x.v / r2, -y.v / r2);
        let r4 = r2 * r2;
        let (fyy, fxx, fxy) = (
            -2.0 * x.v * y.v / r4,
            2.0 * x.v * y.v / r4,
            (y.v * y.v - x.v * x.v) / r4,
        );
        let mut h = [0.0; M];
        let mut k = 0;
        for i in 0..N {
            let (yi, xi) = (y.g[i], x.g[i]);
            for j in 0..=i {
                let (yj, xj) = (y.g[j], x.g[j]);
                h[k] = fy * y.h[k]
                    + fx * x.h[k]
                    + fyy * yi * yj
                    + fxx * xi * xj
                    + fxy * (yi * xj + xi * yj);
                k += 1;
            }
        }
        let mut g = [0.0; N];
        for i in 0..N {
            g[i] = fy * y.g[i] + fx * x.g[i];
        }
        Jet {
            v: y.v.atan2(x.v),
            g,
            h,
        }
    }
}

/// Value and gradient of a function of `N` variables (first-order jet).
#[derive(Clone, Copy, Debug)]
pub struct Grad<const N: usize> {
    /// Value.
    pub v: f64,
    /// Gradient.
    pub g: [f64; N],
}

impl<const N: usize> Grad<N> {
    /// The k-th independent variable, with value `v`.
    pub fn variable(v: f64, k: usize) -> Self {
        let mut g = [0.0; N];
        g[k] = 1.0;
        Grad { v, g }
    }

    #[inline(always)]
    fn chain(self, f0: f64, f1: f64) -> Self {
        Grad {
            v: f0,
            g: self.g.map(|x| f1 * x),
        }
    }
}

impl<const N: usize> From<f64> for Grad<N> {
    #[inline(always)]
    fn from(v: f64) -> Self {
        Grad { v, g: [0.0; N] }
    }
}

impl<const N: usize> Add for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, b: Self) -> Self {
        self += b;
        self
    }
}

impl<const N: usize> AddAssign for Grad<N> {
    #[inline(always)]
    fn add_assign(&mut self, b: Self) {
        self.v += b.v;
        for i in 0..N {
            self.g[i] += b.g[i];
        }
    }
}

impl<const N: usize> Sub for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, b: Self) -> Self {
        self.v -= b.v;
        for i in 0..N {
            self.g[i] -= b.g[i];
        }
        self
    }
}

impl<const N: usize> Neg for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self * -1.0
    }
}

impl<const N: usize> Mul for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, b: Self) -> Self {
        let mut g = [0.0; N];
        for i in 0..N {
            g[i] = self.v * b.g[i] + b.v * self.g[i];
        }
        Grad { v: self.v * b.v, g }
    }
}

impl<const N: usize> Div for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn div(self, b: Self) -> Self {
        self * b.recip()
    }
}

impl<const N: usize> Add<f64> for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, b: f64) -> Self {
        self.v += b;
        self
    }
}

impl<const N: usize> Sub<f64> for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, b: f64) -> Self {
        self.v -= b;
        self
    }
}

impl<const N: usize> Mul<f64> for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, s: f64) -> Self {
        self.v *= s;
        self.g.iter_mut().for_each(|x| *x *= s);
        self
    }
}

impl<const N: usize> Scalar for Grad<N> {
    #[inline(always)]
    fn recip(self) -> Self {
        let r = 1.0 / self.v;
        self.chain(r, -r * r)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        self.chain(s, 0.5 / s)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        (self.chain(s, c), self.chain(c, -s))
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        let r2 = self.v * self.v + x.v * x.v;
        let (fy, fx) = (x.v / r2, -self.v / r2);
        let mut g = [0.0; N];
        for i in 0..N {
            g[i] = fy * self.g[i] + fx * x.g[i];
        }
        Grad {
            v: self.v.atan2(x.v),
            g,
        }
    }
}

/// Value, gradient and dense row-major Hessian of `f` at `q`.
pub fn hessian<const N: usize, const M: usize>(
    q: [f64; N],
    f: impl Fn(&[Jet<N, M>; N]) -> Jet<N, M>,
) -> (f64, [f64; N], [[f64; N]; N]) {
    let vars: [Jet<N, M>; N] = std::array::from_fn(|k| Jet::variable(q[k], k));
    let y = f(&vars);
    (y.v, y.g, y.dense_hessian())
}

/// Value and gradient of `f` at `q`.
pub fn gradient<const N: usize>(
    q: [f64; N],
    f: impl Fn(&[Grad<N>; N]) -> Grad<N>,
) -> (f64, [f64; N]) {
    let vars: [Grad<N>; N] = std::array::from_fn(|k| Grad::variable(q[k], k));
    let y = f(&vars);
    (y.v, y.g)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A function using every operation, its gradient and Hessian against
    /// central differences of the f64 version.
    fn f<T: Scalar>(x: &[T]) -> T {
        let (s, c) = (x[0] * x[1]).sin_cos();
        let r = (x[0] * x[0] + x[2] * x[2] + 1.0).sqrt();
        (s * r + c / (x[2] + 3.0)) - x[1].atan2(x[0] + 2.0) * 0.7 + (-x[2]).recip()
    }

    #[test]
    fn jets_agree_with_finite_differences() {
        let q = [0.3, -0.8, 1.1];
        let (v, g, h) = hessian::<3, 6>(q, |x| f(x));
        let (v1, g1) = gradient::<3>(q, |x| f(x));
        assert_eq!(v, f(&q));
        assert_eq!(v1, v);
        let step = 1e-5;
        for i in 0..3 {
            let (mut p, mut m) = (q, q);
            p[i] += step;
            m[i] -= step;
            let fd = (f(&p) - f(&m)) / (2.0 * step);
            assert!((fd - g[i]).abs() < 1e-8, "g[{i}]: {} vs {fd}", g[i]);
            assert!((g1[i] - g[i]).abs() < 1e-14);
            let gp = gradient::<3>(p, |x| f(x)).1;
            let gm = gradient::<3>(m, |x| f(x)).1;
            for j in 0..3 {
                let fd = (gp[j] - gm[j]) / (2.0 * step);
                assert!(
                    (fd - h[i][j]).abs() < 1e-8,
                    "h[{i}][{j}]: {} vs {fd}",
                    h[i][j]
                );
            }
        }
    }
}
