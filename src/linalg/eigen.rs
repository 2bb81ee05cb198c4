//! Stability of equilibria: the lowest eigenvalues and the inertia of the
//! Hessian on the free dofs, and of the generalised problem H v = ω² M v with
//! the lumped translational mass (material angles massless, eliminated by a
//! Schur complement), whose eigenvalues converge to the paper's ω² (eq. A.4).
//!
//! Eigenvalues come from a Lanczos iteration on the shift-inverted operator
//! W (H - σM)⁻¹ W (W = M^½ on the massive dofs), with σ below the spectrum so
//! that the largest eigenvalues of the operator are the lowest of the problem
//! (faer's dense eigensolver for small problems). Every step is a sparse
//! factorisation (faer LDLᵀ) or solve: O(N).

use crate::linalg::sparse::{Ldlt, SymmetricPattern};
use dyn_stack::{MemBuffer, MemStack};
use faer::matrix_free::LinOp;
use faer::{Mat, MatMut, MatRef, Par};
use serde::{Deserialize, Serialize};
use std::sync::Mutex;

/// The lowest eigenvalues of a problem and its count of negative eigenvalues.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Spectrum {
    /// Lowest eigenvalues, ascending.
    pub values: Vec<f64>,
    /// Number of negative eigenvalues (from the inertia of a factorisation).
    pub negative_count: usize,
    /// Eigenvectors (on the free dofs) of `values`, in the same order.
    #[serde(skip)]
    pub vectors: Vec<Vec<f64>>,
    /// The shift σ of the shift-invert iteration (below the lowest eigenvalue).
    #[serde(skip)]
    pub shift: f64,
}

/// Stability analysis failed.
#[derive(Debug, thiserror::Error)]
pub enum StabilityError {
    /// No shift below the spectrum was found.
    #[error("stability: no shift below the spectrum found (matrix singular or unbounded below)")]
    NoShift,
    /// The Hessian has a non-finite entry.
    #[error("stability: non-finite Hessian entry")]
    NonFinite,
}

struct ShiftInvert<'a> {
    ldlt: Mutex<&'a mut Ldlt>,
    /// Full dof index of each reduced dof.
    reduced: &'a [usize],
    /// √mass of each reduced dof.
    weight: &'a [f64],
    full_dim: usize,
}

impl std::fmt::Debug for ShiftInvert<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShiftInvert")
            .field("dim", &self.reduced.len())
            .finish()
    }
}

impl LinOp<f64> for ShiftInvert<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> dyn_stack::StackReq {
        dyn_stack::StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.reduced.len()
    }
    fn ncols(&self) -> usize {
        self.reduced.len()
    }
    fn apply(
        &self,
        mut out: MatMut<'_, f64>,
        rhs: MatRef<'_, f64>,
        _par: Par,
        _stack: &mut MemStack,
    ) {
        let mut ldlt = self.ldlt.lock().unwrap();
        let mut b = vec![0.0; self.full_dim];
        for c in 0..rhs.ncols() {
            b.iter_mut().for_each(|v| *v = 0.0);
            for (k, &d) in self.reduced.iter().enumerate() {
                b[d] = self.weight[k] * rhs[(k, c)];
            }
            ldlt.solve_in_place(&mut b);
            for (k, &d) in self.reduced.iter().enumerate() {
                out[(k, c)] = self.weight[k] * b[d];
            }
        }
    }
    fn conj_apply(
        &self,
        out: MatMut<'_, f64>,
        rhs: MatRef<'_, f64>,
        par: Par,
        stack: &mut MemStack,
    ) {
        self.apply(out, rhs, par, stack)
    }
}

/// The `k` largest eigenvalues (descending) and eigenvectors of the symmetric
/// positive operator `op` = (H − σM)⁻¹ on the massive dofs, by Lanczos with full
/// reorthogonalisation, restarted from the best Ritz vector. faer's partial
/// eigensolver keeps at least 64 Krylov vectors per restart; for the one to
/// four eigenvalues asked here, with σ just below the lowest eigenvalue (well
/// separated in the shift-inverted spectrum), 10–30 steps suffice: measured 20×
/// faster at N = 200 with the same eigenvalues to 1e-10 (tests/stability.rs).
fn lanczos_largest(op: &ShiftInvert<'_>, k: usize, min_steps: usize) -> Vec<(f64, Vec<f64>)> {
    let dim = op.reduced.len();
    let max_steps = (4 * k + 40).max(min_steps).min(dim);
    let mut b = vec![0.0; op.full_dim];
    let mut apply = |x: &[f64], y: &mut [f64]| {
        let mut ldlt = op.ldlt.lock().unwrap();
        b.iter_mut().for_each(|v| *v = 0.0);
        for (kk, &d) in op.reduced.iter().enumerate() {
            b[d] = op.weight[kk] * x[kk];
        }
        ldlt.solve_in_place(&mut b);
        for (kk, &d) in op.reduced.iter().enumerate() {
            y[kk] = op.weight[kk] * b[d];
        }
    };
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    // deterministic start vector with components on every mode
    let mut start: Vec<f64> = (0..dim)
        .map(|i| 1.0 + 0.5 * ((i as f64) * 0.754_877_666_2).sin())
        .collect();
    let mut best: Vec<(f64, Vec<f64>)> = Vec::new();
    for _restart in 0..20 {
        let s0 = norm(&start);
        let mut basis: Vec<Vec<f64>> = vec![start.iter().map(|x| x / s0).collect()];
        let (mut alpha, mut beta) = (Vec::new(), Vec::new());
        let mut w = vec![0.0; dim];
        let mut converged = false;
        for j in 0..max_steps {
            apply(&basis[j], &mut w);
            let a: f64 = w.iter().zip(&basis[j]).map(|(x, y)| x * y).sum();
            alpha.push(a);
            // full reorthogonalisation (twice is enough)
            for _ in 0..2 {
                for v in &basis {
                    let c: f64 = w.iter().zip(v).map(|(x, y)| x * y).sum();
                    w.iter_mut().zip(v).for_each(|(x, y)| *x -= c * y);
                }
            }
            let b = norm(&w);
            // Ritz values of the tridiagonal matrix and their residuals b |e_jᵀ s|
            let m = alpha.len();
            let t = nalgebra::DMatrix::from_fn(m, m, |r, c| {
                if r == c {
                    alpha[r]
                } else if r + 1 == c {
                    beta[r]
                } else if c + 1 == r {
                    beta[c]
                } else {
                    0.0
                }
            });
            let eig = t.symmetric_eigen();
            let mut order: Vec<usize> = (0..m).collect();
            order.sort_by(|&x, &y| eig.eigenvalues[y].total_cmp(&eig.eigenvalues[x]));
            let kk = k.min(m);
            let done = m >= kk.max(min_steps.min(dim))
                && order[..kk].iter().all(|&i| {
                    b * eig.eigenvectors[(m - 1, i)].abs() <= 1e-10 * eig.eigenvalues[i].abs()
                });
            if done || b < 1e-300 || j + 1 == max_steps {
                best = order[..kk]
                    .iter()
                    .map(|&i| {
                        let mut v = vec![0.0; dim];
                        for (r, q) in basis.iter().enumerate() {
                            let c = eig.eigenvectors[(r, i)];
                            v.iter_mut().zip(q).for_each(|(x, y)| *x += c * y);
                        }
                        let nv = norm(&v);
                        v.iter_mut().for_each(|x| *x /= nv);
                        (eig.eigenvalues[i], v)
                    })
                    .collect();
                converged = done || b < 1e-300;
                break;
            }
            beta.push(b);
            basis.push(w.iter().map(|x| x / b).collect());
        }
        if converged {
            break;
        }
        // restart from the sum of the current Ritz vectors
        start = vec![0.0; dim];
        for (_, v) in &best {
            start.iter_mut().zip(v).for_each(|(x, y)| *x += y);
        }
    }
    best
}

/// Factor H - σ M (M diagonal given per dof, or the identity) and return the
/// number of its negative eigenvalues, or None if singular.
fn inertia_at(
    pattern: &SymmetricPattern,
    values: &[f64],
    mass: Option<&[f64]>,
    sigma: f64,
    ldlt: &mut Ldlt,
    work: &mut Vec<f64>,
) -> Option<usize> {
    work.clear();
    work.extend_from_slice(values);
    for (d, &s) in pattern.diagonal.iter().enumerate() {
        work[s] -= sigma * mass.map_or(1.0, |m| m[d]);
    }
    ldlt.factor(work).ok()?;
    Some(ldlt.negative_count())
}

/// Number of negative eigenvalues of the block of H on the massless dofs, which
/// (material angles coupling only to neighbouring angles) is tridiagonal, or
/// banded where a free end's massless ghost node joins them.
fn massless_block_negatives(pattern: &SymmetricPattern, values: &[f64], mass: &[f64]) -> usize {
    let idx: Vec<usize> = (0..mass.len()).filter(|&d| mass[d] == 0.0).collect();
    let band = massless_bandwidth(pattern, mass, &idx);
    if band > 1 {
        return banded_negatives(pattern, values, &idx, band);
    }
    let mut negatives = 0;
    let mut d_prev = 0.0;
    for (k, &d) in idx.iter().enumerate() {
        let a = values[pattern.diagonal[d]];
        let b = if k > 0 {
            pattern.slot(idx[k - 1], d).map_or(0.0, |s| values[s])
        } else {
            0.0
        };
        let dk = if k > 0 { a - b * b / d_prev } else { a };
        if dk < 0.0 {
            negatives += 1;
        }
        d_prev = dk;
    }
    negatives
}

/// Bandwidth of the massless block in its own order (`idx`, ascending).
fn massless_bandwidth(pattern: &SymmetricPattern, mass: &[f64], idx: &[usize]) -> usize {
    let mut position = vec![usize::MAX; mass.len()];
    for (k, &d) in idx.iter().enumerate() {
        position[d] = k;
    }
    let (cp, ri) = (pattern.matrix.col_offsets(), pattern.matrix.row_indices());
    let mut band = 0;
    for (k, &d) in idx.iter().enumerate() {
        // upper triangle: rows r <= d, so position[r] <= k
        for &r in &ri[cp[d]..cp[d + 1]] {
            if position[r] != usize::MAX {
                band = band.max(k - position[r]);
            }
        }
    }
    band
}

/// Negative pivots of LDLᵀ (no pivoting) of the banded block of H on the
/// dofs `idx`, O(len · band²).
fn banded_negatives(
    pattern: &SymmetricPattern,
    values: &[f64],
    idx: &[usize],
    band: usize,
) -> usize {
    let entry = |j: usize, k: usize| pattern.slot(idx[j], idx[k]).map_or(0.0, |s| values[s]);
    // l[k * band + (k − j − 1)] = L_kj for k − band <= j < k
    let mut l = vec![0.0; idx.len() * band];
    let mut d = vec![0.0; idx.len()];
    let mut negatives = 0;
    for k in 0..idx.len() {
        let lo = k.saturating_sub(band);
        for j in lo..k {
            let mut v = entry(j, k);
            for i in lo.max(j.saturating_sub(band))..j {
                v -= l[k * band + (k - i - 1)] * d[i] * l[j * band + (j - i - 1)];
            }
            l[k * band + (k - j - 1)] = v / d[j];
        }
        let mut dk = entry(k, k);
        for i in lo..k {
            let lki = l[k * band + (k - i - 1)];
            dk -= lki * lki * d[i];
        }
        if dk < 0.0 {
            negatives += 1;
        }
        d[k] = dk;
    }
    negatives
}

/// The `k` lowest eigenvalues of the symmetric matrix (upper `values` on
/// `pattern`), of the pencil (H, diag(mass)) when `mass` is given, and the
/// count of negative eigenvalues. `ldlt` is a factorisation workspace for the
/// pattern (its previous content is overwritten).
pub fn lowest_eigenvalues(
    pattern: &SymmetricPattern,
    values: &[f64],
    mass: Option<&[f64]>,
    k: usize,
    ldlt: &mut Ldlt,
) -> Result<Spectrum, StabilityError> {
    lowest_with(pattern, values, mass, k, ldlt, None)
}

/// The Gram matrix zₚᵀ H z_q (row-major k×k) of the Hessian over k vectors
/// on the free dofs, evaluated without the assembled values (stencil by
/// stencil), so that it keeps the digits the assembled matrix loses.
pub type Gram<'a> = &'a dyn Fn(&[Vec<f64>]) -> Vec<f64>;

/// As [`lowest_eigenvalues`], the eigenpairs then refined by one step of
/// inverse iteration at the shift and a Rayleigh–Ritz step on the vectors
/// it gives, with the Hessian's form from `gram`. Shift-invert on the
/// assembled matrix finds the eigenvalues of a matrix perturbed by its
/// rounding, ε‖H‖ ≈ ε S/h² per unit mass for a stiff rod; the Rayleigh
/// quotient is stationary, so the vectors' error of that order costs only its
/// square, and the exact form keeps the rest (docs/validation.md, "Stiff
/// rods"). The vectors returned are then the refined ones on all the free
/// dofs (for the pencil with the massless angles at their minimising values).
/// One more factorisation and O(N k²).
pub fn lowest_eigenvalues_refined(
    pattern: &SymmetricPattern,
    values: &[f64],
    mass: Option<&[f64]>,
    k: usize,
    ldlt: &mut Ldlt,
    gram: Gram<'_>,
) -> Result<Spectrum, StabilityError> {
    lowest_with(pattern, values, mass, k, ldlt, Some(gram))
}

/// [`lowest_eigenvalues`], refined by [`rayleigh_ritz`] when `gram` is given.
/// σ strictly below the lowest eigenvalue and within a factor 4 of it, from
/// the counts of negatives `count(σ)` (None: singular at σ), the workspace
/// left factorised at the σ returned: grown ×4 from 1e-8 of the largest
/// diagonal until below it, and where that first σ is already below, moved
/// up ×4 (down to 1e-14 of it) while it stays below. A σ far below a
/// negative λ₁ near zero (σ = −92 for λ₁ ≈ −0.01, λ₂ ≈ 0.02 at N = 800)
/// makes μ₁ ≈ μ₂, and Lanczos restarted 20 times there: the branch's N⁵.
fn below_lowest(
    negative_count: usize,
    diag_scale: f64,
    count: &mut dyn FnMut(f64) -> Option<usize>,
) -> Result<f64, StabilityError> {
    let first = -1e-8 * diag_scale;
    let mut sigma = if negative_count == 0 { 0.0 } else { first };
    loop {
        match count(sigma) {
            Some(0) if sigma < 0.0 || negative_count == 0 => break,
            _ => {}
        }
        sigma = if sigma == 0.0 { first } else { sigma * 4.0 };
        if sigma < -1e3 * diag_scale {
            return Err(StabilityError::NoShift);
        }
    }
    if sigma == first {
        while sigma / 4.0 <= -1e-14 * diag_scale {
            if count(sigma / 4.0) == Some(0) {
                sigma /= 4.0;
            } else {
                // the workspace holds the factorisation at σ / 4: back to σ
                count(sigma).ok_or(StabilityError::NoShift)?;
                break;
            }
        }
    }
    Ok(sigma)
}

fn lowest_with(
    pattern: &SymmetricPattern,
    values: &[f64],
    mass: Option<&[f64]>,
    k: usize,
    ldlt: &mut Ldlt,
    gram: Option<Gram<'_>>,
) -> Result<Spectrum, StabilityError> {
    if values.iter().any(|v| !v.is_finite()) {
        return Err(StabilityError::NonFinite);
    }
    let n = pattern.dim();
    let massless_neg = mass.map_or(0, |m| massless_block_negatives(pattern, values, m));
    let mut work = Vec::with_capacity(values.len());
    // negatives of H (pencil: of S - σ M_x, by Sylvester on the Schur complement)
    let count = |sigma: f64, ldlt: &mut Ldlt, work: &mut Vec<f64>| {
        inertia_at(pattern, values, mass, sigma, ldlt, work).map(|c| c.saturating_sub(massless_neg))
    };
    let diag_scale = pattern.max_abs_diagonal(values).max(1e-300);
    let negative_count = match count(0.0, ldlt, &mut work) {
        Some(c) => c,
        // singular at 0: count at a tiny negative shift (zero modes are not negative)
        None => count(-1e-12 * diag_scale, ldlt, &mut work).ok_or(StabilityError::NoShift)?,
    };
    let sigma = below_lowest(negative_count, diag_scale, &mut |sigma| {
        count(sigma, ldlt, &mut work)
    })?;
    // reduced space: dofs with mass (all dofs for the plain problem)
    let (reduced, weight): (Vec<usize>, Vec<f64>) = match mass {
        Some(m) => (0..n)
            .filter(|&d| m[d] > 0.0)
            .map(|d| (d, m[d].sqrt()))
            .unzip(),
        None => ((0..n).collect(), vec![1.0; n]),
    };
    let dim = reduced.len();
    let k = k.min(dim);
    if k == 0 {
        return Ok(Spectrum {
            negative_count,
            shift: sigma,
            ..Default::default()
        });
    }
    let mu: Vec<(f64, Vec<f64>)> = if dim <= 128 {
        let op = ShiftInvert {
            ldlt: Mutex::new(&mut *ldlt),
            reduced: &reduced,
            weight: &weight,
            full_dim: n,
        };
        // small problems: the operator as a dense matrix
        let mut a = Mat::<f64>::zeros(dim, dim);
        op.apply(
            a.as_mut(),
            Mat::<f64>::identity(dim, dim).as_ref(),
            Par::Seq,
            MemStack::new(&mut MemBuffer::new(dyn_stack::StackReq::EMPTY)),
        );
        let a = Mat::<f64>::from_fn(dim, dim, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
        let evd = a
            .self_adjoint_eigen(faer::Side::Lower)
            .map_err(|_| StabilityError::NonFinite)?;
        let mut all: Vec<(f64, Vec<f64>)> = (0..dim)
            .map(|i| (evd.S()[i], (0..dim).map(|r| evd.U()[(r, i)]).collect()))
            .collect();
        all.sort_by(|x, y| y.0.total_cmp(&x.0));
        all.truncate(k);
        all
    } else {
        // Lanczos, checked by Sylvester's law: exactly k eigenvalues lie at or
        // below the k-th found (else one was missed: more steps)
        let mut steps = 2 * k + 10;
        let mut found = Vec::new();
        for attempt in 0..3 {
            if attempt > 0 {
                count(sigma, ldlt, &mut work).ok_or(StabilityError::NoShift)?;
            }
            {
                let op = ShiftInvert {
                    ldlt: Mutex::new(&mut *ldlt),
                    reduced: &reduced,
                    weight: &weight,
                    full_dim: n,
                };
                found = lanczos_largest(&op, k, steps);
            }
            let top = found
                .iter()
                .map(|(m, _)| sigma + 1.0 / m)
                .fold(f64::NEG_INFINITY, f64::max);
            let tol = 1e-9 * top.abs().max(1e-6 * diag_scale);
            match count(top + tol, ldlt, &mut work) {
                Some(c) if c <= k => break,
                _ => steps *= 2,
            }
        }
        found
    };
    // back to eigenvalues of the problem and eigenvectors on the full dofs
    // (for the pencil, v = W y scaled back: v = (H - σM)⁻¹ W y up to a factor;
    // the massive components M^{-1/2} y suffice to show the mode's shape)
    let mut modes: Vec<(f64, Vec<f64>)> = mu
        .into_iter()
        .filter(|(m, _)| *m != 0.0)
        .map(|(m, y)| {
            let mut v = vec![0.0; n];
            for (k, &d) in reduced.iter().enumerate() {
                v[d] = y[k] / weight[k];
            }
            (sigma + 1.0 / m, v)
        })
        .collect();
    modes.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let Some(gram) = gram {
        let shifted = Shifted {
            pattern,
            values,
            mass,
            sigma,
        };
        if let Some(refined) = rayleigh_ritz(&shifted, &modes, ldlt, gram)? {
            modes = refined;
        }
    }
    Ok(Spectrum {
        values: modes.iter().map(|m| m.0).collect(),
        vectors: modes.into_iter().map(|m| m.1).collect(),
        negative_count,
        shift: sigma,
    })
}

/// Eigenpairs (value, vector on the free dofs), ascending.
type Modes = Vec<(f64, Vec<f64>)>;

/// The matrix H − σM of the problem at its shift.
struct Shifted<'a> {
    pattern: &'a SymmetricPattern,
    values: &'a [f64],
    mass: Option<&'a [f64]>,
    sigma: f64,
}

/// One step of inverse iteration at σ from each mode, z = (H − σM)⁻¹ M x
/// (which puts the massless dofs at their minimising values, so the form
/// is the Schur complement's), then the Rayleigh–Ritz pairs of (Gram, zᵀMz)
/// on their span, ascending. None (keep the modes) when the vectors are not
/// independent in the mass norm; an error when the form is not finite.
fn rayleigh_ritz(
    a: &Shifted<'_>,
    modes: &Modes,
    ldlt: &mut Ldlt,
    gram: Gram<'_>,
) -> Result<Option<Modes>, StabilityError> {
    let k = modes.len();
    if k == 0 {
        return Ok(None);
    }
    let mut work = Vec::with_capacity(a.values.len());
    inertia_at(a.pattern, a.values, a.mass, a.sigma, ldlt, &mut work)
        .ok_or(StabilityError::NoShift)?;
    let m = |d: usize| a.mass.map_or(1.0, |m| m[d]);
    let m_dot = |x: &[f64], y: &[f64]| -> f64 {
        x.iter()
            .zip(y)
            .enumerate()
            .map(|(d, (p, q))| m(d) * p * q)
            .sum()
    };
    let z: Vec<Vec<f64>> = modes
        .iter()
        .map(|(_, x)| {
            let mut b: Vec<f64> = x.iter().enumerate().map(|(d, v)| m(d) * v).collect();
            ldlt.solve_in_place(&mut b);
            let norm = m_dot(&b, &b).sqrt();
            b.iter_mut().for_each(|v| *v /= norm);
            b
        })
        .collect();
    let form = gram(&z);
    if form.len() != k * k || form.iter().any(|v| !v.is_finite()) {
        return Err(StabilityError::NonFinite);
    }
    let h = nalgebra::DMatrix::from_fn(k, k, |p, q| 0.5 * (form[p * k + q] + form[q * k + p]));
    let b = nalgebra::DMatrix::from_fn(k, k, |p, q| m_dot(&z[p], &z[q]));
    // B = L Lᵀ; the pairs of L⁻¹ H L⁻ᵀ, their vectors L⁻ᵀ u
    let Some(chol) = b.cholesky() else {
        return Ok(None);
    };
    let l = chol.l();
    let (Some(l_inv), true) = (l.clone().try_inverse(), l.iter().all(|v| v.is_finite())) else {
        return Ok(None);
    };
    let reduced = &l_inv * h * l_inv.transpose();
    let eig = reduced.symmetric_eigen();
    let coefficients = l_inv.transpose() * &eig.eigenvectors;
    let mut pairs: Vec<(f64, Vec<f64>)> = (0..k)
        .map(|i| {
            let mut v = vec![0.0; z[0].len()];
            for (p, zp) in z.iter().enumerate() {
                let c = coefficients[(p, i)];
                v.iter_mut().zip(zp).for_each(|(x, y)| *x += c * y);
            }
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            v.iter_mut().for_each(|x| *x /= norm);
            (eig.eigenvalues[i], v)
        })
        .collect();
    pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
    Ok(Some(pairs))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A negative lowest eigenvalue near zero beside large ones (a stiff rod
    /// near a loss of stability): the shift lies within a factor 4 below it,
    /// not at a fraction of the largest diagonal (−100 here, where μ₁ ≈ μ₂
    /// and Lanczos restarted without end on the rod).
    #[test]
    fn the_shift_is_near_a_small_negative_lowest_eigenvalue() {
        let n = 300;
        let stencils: Vec<Vec<Option<usize>>> =
            (0..n - 1).map(|i| vec![Some(i), Some(i + 1)]).collect();
        let pattern = SymmetricPattern::from_stencils(n, &stencils);
        let mut values = vec![0.0; pattern.nnz()];
        for i in 0..n {
            let d = match i {
                0 => -0.01,
                1 => 0.02,
                _ => 1e10 * (1.0 + i as f64 / n as f64),
            };
            values[pattern.slot(i, i).unwrap()] = d;
        }
        let mut ldlt = Ldlt::new(&pattern);
        let spectrum = lowest_eigenvalues(&pattern, &values, None, 2, &mut ldlt).unwrap();
        assert_eq!(spectrum.negative_count, 1);
        assert!(
            spectrum.shift < -0.01 && spectrum.shift >= -0.04,
            "shift {}",
            spectrum.shift
        );
        assert!(
            (spectrum.values[0] + 0.01).abs() < 1e-12,
            "{:?}",
            spectrum.values
        );
        assert!(
            (spectrum.values[1] - 0.02).abs() < 1e-12,
            "{:?}",
            spectrum.values
        );
    }
}
