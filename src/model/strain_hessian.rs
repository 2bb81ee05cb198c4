//! Closed-form gradient and Hessian of a vertex stencil's integrated strains
//! (κ1, κ2, m) in its 8 variables (e_{i-1}, e_i, θ_{i-1}, θ_i), at the state
//! the stencil's frames were taken from.
//!
//! The stencil Hessian is the hot path of every Newton step. Second-order jets
//! of the whole stencil (`energy::strain_jets`) carry 36 Hessian entries
//! through every operation; the derivatives below cost a small fraction of
//! that. The jets remain the oracle of the unit tests (and the fallback where
//! the derivation's assumption fails, see `energy::vertex_energy_hessian`).
//!
//! Derivation. Let R_k = [d1_k d2_k t_k] be the material frame of edge k
//! (k = 0, 1: edges i−1, i; orthonormal, d1 × d2 = t) and F = R_0ᵀ R_1 the
//! relative rotation, F_ab = f_a⁰·f_b¹ (1-based, f = (d1, d2, t)). Then
//! (t_0 × t_1)·d1⁰ = −F_23, (t_0 × t_1)·d1¹ = F_32 and likewise for d2, so
//!
//!   κ1 = (F_32 − F_23)/(1 + F_33),   κ2 = (F_13 − F_31)/(1 + F_33),
//!
//! and the twist m = θ_1 − θ_0 + reference twist is, up to 2π, the angle ψ
//! about t_1 from the parallel-transported d1⁰ to d1¹: the twist of the
//! swing–twist split F = S T_z(ψ) (the swing S takes t_0 to t_1 minimally,
//! which is the parallel transport). In the quaternion (w, x, y, z) of F:
//!
//!   κ1 = 2wx/(w² + z²),   κ2 = 2wy/(w² + z²),   ψ = 2 atan2(z, w),
//!
//! each homogeneous of degree 0 in (w, x, y, z).
//!
//! Along a straight line in the variables, e_k + ε δe_k, θ_k + ε δθ_k, with
//! δe_k = l_k (p_k d1_k + q_k d2_k + σ_k t_k), each frame moves to second order
//! as R_k(ε) = R_k exp([ε Ω_k + ε²/2 ν_k]×) with the body angular velocity and
//! acceleration
//!
//!   Ω_k = (−q_k, p_k, δθ_k),   ν_k = (2σ_k q_k + p_k δθ_k, q_k δθ_k − 2σ_k p_k, 0),
//!
//! The frame turns with its tangent, t' = p d1 + q d2, and spins about t
//! only by δθ, because the reference director is time-parallel transported
//! (d_α' = −(d_α·t') t + δθ-terms); ν is the rate of change of Ω along the
//! line, as the components of δe/l in the turning frame change and 1/l
//! changes with the edge's growth σ. The quaternion of F then moves as
//! exp(−Ω̂_0/2) q exp(Ω̂_1/2) (Ω̂ a pure quaternion), so for f(q):
//!
//!   f' = ∇f·Q Ω,
//!   f'' = Ωᵀ (Qᵀ ∇²f Q + C) Ω + (Qᵀ ∇f)·ν,
//!
//! Q the 4×6 map Ω ↦ −½ Ω̂_0 q + ½ q Ω̂_1 and C the off-diagonal blocks
//! C_{0i,1j} = −¼ ∇f·(ê_i q ê_j) (the terms −¼ |Ω_k|² q of q'' drop, as
//! ∇f·q = 0 by homogeneity). Finally (p_k, q_k, σ_k) = R_kᵀ δe_k / l_k.
//!
//! Assumption: each stored reference director is unit and normal to its
//! stored tangent, and the edges are at the stored tangents; then the
//! transported frames are rotations for all values of the variables, and F,
//! q and the formulas above describe the stencil exactly.

// index loops mirror the formulas (rows and columns of small dense blocks)
#![allow(clippy::needless_range_loop)]

use nalgebra::{Matrix3, Vector3};

/// Material frame of one edge of a vertex stencil at the evaluation point.
#[derive(Clone, Copy, Debug)]
pub struct EdgeFrame {
    /// First material director d1.
    pub d1: Vector3<f64>,
    /// Second material director d2 = t × d1.
    pub d2: Vector3<f64>,
    /// Unit tangent.
    pub t: Vector3<f64>,
    /// Edge length |e|.
    pub length: f64,
}

/// Gradient and Hessian of a function of the relative rotation's quaternion
/// (w, x, y, z), at the stencil's quaternion.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QuaternionDerivatives {
    /// ∇f.
    pub g: [f64; 4],
    /// ∇²f (symmetric).
    pub h: [[f64; 4]; 4],
}

impl QuaternionDerivatives {
    /// Σ_a c_a f_a + ½ Σ_ab c_ab f_a f_b to second order around the stencil
    /// (the chain rule through a function of the strains): gradient
    /// Σ g_a ∇f_a, Hessian Σ g_a ∇²f_a + Σ h_ab ∇f_a ∇f_bᵀ.
    pub fn compose(strains: &[QuaternionDerivatives; 3], g: [f64; 3], h: [[f64; 3]; 3]) -> Self {
        let mut out = QuaternionDerivatives::default();
        for (a, s) in strains.iter().enumerate() {
            for r in 0..4 {
                out.g[r] += g[a] * s.g[r];
                for c in 0..4 {
                    out.h[r][c] += g[a] * s.h[r][c];
                }
            }
        }
        // Σ_ab h_ab ∇f_a ∇f_bᵀ = Σ_a ∇f_a (Σ_b h_ab ∇f_b)ᵀ
        for a in 0..3 {
            let mut w = [0.0; 4];
            for b in 0..3 {
                for c in 0..4 {
                    w[c] += h[a][b] * strains[b].g[c];
                }
            }
            for r in 0..4 {
                for c in 0..4 {
                    out.h[r][c] += strains[a].g[r] * w[c];
                }
            }
        }
        out
    }
}

/// Hamilton product of quaternions (w, x, y, z).
#[inline(always)]
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// The pure unit quaternion ê_i.
#[inline(always)]
fn unit(i: usize) -> [f64; 4] {
    let mut e = [0.0; 4];
    e[i + 1] = 1.0;
    e
}

#[inline(always)]
fn dot4(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// The quaternion of the rotation matrix `f` (Shepperd's method: divide by
/// the largest of the four candidates, so no cancellation near any angle).
fn quaternion(f: &Matrix3<f64>) -> [f64; 4] {
    let trace = f[(0, 0)] + f[(1, 1)] + f[(2, 2)];
    if trace >= f[(0, 0)] && trace >= f[(1, 1)] && trace >= f[(2, 2)] {
        let s = 2.0 * (1.0 + trace).sqrt();
        [
            0.25 * s,
            (f[(2, 1)] - f[(1, 2)]) / s,
            (f[(0, 2)] - f[(2, 0)]) / s,
            (f[(1, 0)] - f[(0, 1)]) / s,
        ]
    } else if f[(0, 0)] >= f[(1, 1)] && f[(0, 0)] >= f[(2, 2)] {
        let s = 2.0 * (1.0 + f[(0, 0)] - f[(1, 1)] - f[(2, 2)]).sqrt();
        [
            (f[(2, 1)] - f[(1, 2)]) / s,
            0.25 * s,
            (f[(0, 1)] + f[(1, 0)]) / s,
            (f[(0, 2)] + f[(2, 0)]) / s,
        ]
    } else if f[(1, 1)] >= f[(2, 2)] {
        let s = 2.0 * (1.0 + f[(1, 1)] - f[(0, 0)] - f[(2, 2)]).sqrt();
        [
            (f[(0, 2)] - f[(2, 0)]) / s,
            (f[(0, 1)] + f[(1, 0)]) / s,
            0.25 * s,
            (f[(1, 2)] + f[(2, 1)]) / s,
        ]
    } else {
        let s = 2.0 * (1.0 + f[(2, 2)] - f[(0, 0)] - f[(1, 1)]).sqrt();
        [
            (f[(1, 0)] - f[(0, 1)]) / s,
            (f[(0, 2)] + f[(2, 0)]) / s,
            (f[(1, 2)] + f[(2, 1)]) / s,
            0.25 * s,
        ]
    }
}

/// Where each body angular-velocity component Ω_k sits among the local
/// variables y = (p_0, q_0, σ_0, p_1, q_1, σ_1, δθ_0, δθ_1), with its sign:
/// Ω_k = (−q_k, p_k, δθ_k).
const OMEGA_SLOTS: [(usize, f64); 6] =
    [(1, -1.0), (0, 1.0), (6, 1.0), (4, -1.0), (3, 1.0), (7, 1.0)];

/// The frames of a vertex stencil and the quaternion of their relative
/// rotation, with its first-order motions under the six body rotations.
#[derive(Clone, Copy, Debug)]
pub struct VertexChart {
    frames: [EdgeFrame; 2],
    /// Quaternion of F = R_0ᵀ R_1.
    q: [f64; 4],
    /// Columns of Q: ∂q/∂Ω_{0i} = −½ ê_i q, ∂q/∂Ω_{1i} = ½ q ê_i.
    generators: [[f64; 4]; 6],
}

impl VertexChart {
    /// The chart of the two edge frames (edge i−1, edge i).
    pub fn new(frames: [EdgeFrame; 2]) -> Self {
        let basis = |f: &EdgeFrame| Matrix3::from_columns(&[f.d1, f.d2, f.t]);
        let f = basis(&frames[0]).transpose() * basis(&frames[1]);
        let q = quaternion(&f);
        let mut generators = [[0.0; 4]; 6];
        for i in 0..3 {
            generators[i] = mul(unit(i), q).map(|v| -0.5 * v);
            generators[3 + i] = mul(q, unit(i)).map(|v| 0.5 * v);
        }
        VertexChart {
            frames,
            q,
            generators,
        }
    }

    /// Quaternion gradients of the three strains (κ1, κ2, ψ) as functions of
    /// the relative rotation (formulas in the module notes).
    pub fn strain_gradients(&self) -> [[f64; 4]; 3] {
        let [w, x, y, z] = self.q;
        let (r1, r2) = (1.0 / (w * w + z * z), 1.0 / (w * w + z * z).powi(2));
        // κ = 2 w v / ρ with v = x (κ1) or y (κ2), a = 2v
        let curvature = |a: f64, slot: usize| {
            let mut g = [0.0; 4];
            g[0] = a * (z * z - w * w) * r2;
            g[slot] = 2.0 * w * r1;
            g[3] = -2.0 * a * w * z * r2;
            g
        };
        [
            curvature(2.0 * x, 1),
            curvature(2.0 * y, 2),
            [-2.0 * z * r1, 0.0, 0.0, 2.0 * w * r1],
        ]
    }

    /// Quaternion gradients and Hessians of the three strains (κ1, κ2, ψ)
    /// as functions of the relative rotation (formulas in the module notes).
    pub fn strains(&self) -> [QuaternionDerivatives; 3] {
        let [w, x, y, z] = self.q;
        let rho = w * w + z * z;
        let (r2, r3) = (1.0 / (rho * rho), 1.0 / (rho * rho * rho));
        let [g1, g2, g3] = self.strain_gradients();
        // κ = 2 w v / ρ with v = x (κ1) or y (κ2), a = 2v
        let curvature = |g: [f64; 4], v: f64, slot: usize| {
            let a = 2.0 * v;
            let mut h = [[0.0; 4]; 4];
            let hww = 2.0 * a * w * (w * w - 3.0 * z * z) * r3;
            let hwz = 2.0 * a * z * (3.0 * w * w - z * z) * r3;
            let hvw = 2.0 * (z * z - w * w) * r2;
            let hvz = -4.0 * w * z * r2;
            h[0][0] = hww;
            h[3][3] = -hww;
            h[0][3] = hwz;
            h[3][0] = hwz;
            h[slot][0] = hvw;
            h[0][slot] = hvw;
            h[slot][3] = hvz;
            h[3][slot] = hvz;
            QuaternionDerivatives { g, h }
        };
        let mut twist = QuaternionDerivatives {
            g: g3,
            h: [[0.0; 4]; 4],
        };
        twist.h[0][0] = 4.0 * w * z * r2;
        twist.h[3][3] = -4.0 * w * z * r2;
        twist.h[0][3] = 2.0 * (z * z - w * w) * r2;
        twist.h[3][0] = twist.h[0][3];
        [curvature(g1, x, 1), curvature(g2, y, 2), twist]
    }

    /// Gradient in the local variables y = (p_0, q_0, σ_0, p_1, q_1, σ_1,
    /// δθ_0, δθ_1) of a function of the quaternion, and its gradient in the
    /// body rotations Ω (which the Hessian's ν terms need).
    fn local_gradient(&self, g_q: &[f64; 4]) -> ([f64; 8], [f64; 6]) {
        let omega = self.generators.map(|col| dot4(&col, g_q));
        let mut g = [0.0; 8];
        for (i, &(slot, sign)) in OMEGA_SLOTS.iter().enumerate() {
            g[slot] = sign * omega[i];
        }
        (g, omega)
    }

    /// Gradient and Hessian in the local variables y of a function of the
    /// quaternion.
    fn local(&self, d: &QuaternionDerivatives) -> ([f64; 8], [[f64; 8]; 8]) {
        let (g, omega) = self.local_gradient(&d.g);
        // Qᵀ ∇²f Q
        let hq = self.generators.map(|col| {
            let mut v = [0.0; 4];
            for r in 0..4 {
                v[r] = dot4(&d.h[r], &col);
            }
            v
        });
        let mut h_omega = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in i..6 {
                let v = dot4(&self.generators[i], &hq[j]);
                h_omega[i][j] = v;
                h_omega[j][i] = v;
            }
        }
        // the mixed term of q'': −½ Ω̂_0 q Ω̂_1, as −¼ ∇f·(ê_i q ê_j) per
        // entry on both sides of the diagonal. Right multiplication by a unit
        // quaternion is orthogonal, so ∇f·(a ê_j) = (∇f ê_j*)·a = −(∇f ê_j)·a,
        // and ê_i q = −2 ∂q/∂Ω_{0i}: the entry is −½ (∇f ê_j)·∂q/∂Ω_{0i}
        for j in 0..3 {
            let right = mul(d.g, unit(j));
            for i in 0..3 {
                let c = -0.5 * dot4(&right, &self.generators[i]);
                h_omega[i][3 + j] += c;
                h_omega[3 + j][i] += c;
            }
        }
        let mut h = [[0.0; 8]; 8];
        for (i, &(a, sa)) in OMEGA_SLOTS.iter().enumerate() {
            for (j, &(b, sb)) in OMEGA_SLOTS.iter().enumerate() {
                h[a][b] = sa * sb * h_omega[i][j];
            }
        }
        // the body angular acceleration ν_k = (2σq + p δθ, q δθ − 2σp, 0)
        // against ∂f/∂Ω_k
        for k in 0..2 {
            let (p, q, s, th) = (3 * k, 3 * k + 1, 3 * k + 2, 6 + k);
            let (g1, g2) = (omega[3 * k], omega[3 * k + 1]);
            for (a, b, v) in [
                (s, q, g1),
                (s, p, -g2),
                (p, th, 0.5 * g1),
                (q, th, 0.5 * g2),
            ] {
                h[a][b] += v;
                h[b][a] += v;
            }
        }
        (g, h)
    }

    /// Gradient in the stencil variables (e_{i-1}, e_i, θ_{i-1}, θ_i) of a
    /// function of the quaternion with quaternion gradient `g_q`.
    pub fn gradient(&self, g_q: &[f64; 4]) -> [f64; 8] {
        let (gy, _) = self.local_gradient(g_q);
        self.gradient_to_stencil(&gy)
    }

    /// From local to stencil variables: (p_k, q_k, σ_k) = R_kᵀ δe_k / l_k.
    fn gradient_to_stencil(&self, gy: &[f64; 8]) -> [f64; 8] {
        let mut g = [0.0; 8];
        for (k, f) in self.frames.iter().enumerate() {
            let v = (f.d1 * gy[3 * k] + f.d2 * gy[3 * k + 1] + f.t * gy[3 * k + 2]) / f.length;
            g[3 * k..3 * k + 3].copy_from_slice(v.as_slice());
        }
        g[6] = gy[6];
        g[7] = gy[7];
        g
    }

    /// Gradient and Hessian (row-major 8×8) in the stencil variables of a
    /// function of the quaternion.
    pub fn hessian(&self, d: &QuaternionDerivatives) -> ([f64; 8], [[f64; 8]; 8]) {
        let (gy, hy) = self.local(d);
        let g = self.gradient_to_stencil(&gy);
        // y_k = (R_k / l_k)ᵀ δe_k
        let maps = self
            .frames
            .map(|f| Matrix3::from_columns(&[f.d1, f.d2, f.t]) / f.length);
        let block = |a: usize, b: usize| Matrix3::from_fn(|r, c| hy[3 * a + r][3 * b + c]);
        let mut h = [[0.0; 8]; 8];
        for a in 0..2 {
            for b in a..2 {
                let m = maps[a] * block(a, b) * maps[b].transpose();
                for r in 0..3 {
                    for c in 0..3 {
                        h[3 * a + r][3 * b + c] = m[(r, c)];
                        h[3 * b + c][3 * a + r] = m[(r, c)];
                    }
                }
            }
            // edge–angle columns
            for th in 6..8 {
                let col = Vector3::new(hy[3 * a][th], hy[3 * a + 1][th], hy[3 * a + 2][th]);
                let v = maps[a] * col;
                for r in 0..3 {
                    h[3 * a + r][th] = v[r];
                    h[th][3 * a + r] = v[r];
                }
            }
        }
        for a in 6..8 {
            for b in 6..8 {
                h[a][b] = hy[a][b];
            }
        }
        (g, h)
    }
}
