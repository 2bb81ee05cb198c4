//! Stability of equilibria: the lowest eigenvalues and the inertia of the
//! Hessian on the free dofs, and of the generalised problem H v = ω² M v with
//! the lumped translational mass (material angles massless, eliminated by a
//! Schur complement), whose eigenvalues converge to the paper's ω² (eq. A.4).
//!
//! Eigenvalues come from faer's Lanczos applied to the shift-inverted operator
//! W (H - σM)⁻¹ W (W = M^½ on the massive dofs), with σ below the spectrum so
//! that the largest eigenvalues of the operator are the lowest of the problem.
//! Every step is a sparse factorisation or solve: O(N).

use crate::solve::sparse::{Ldlt, SymmetricPattern};
use dyn_stack::{MemBuffer, MemStack};
use faer::matrix_free::LinOp;
use faer::matrix_free::eigen::{
    PartialEigenParams, partial_self_adjoint_eigen, partial_self_adjoint_eigen_scratch,
};
use faer::{Col, Mat, MatMut, MatRef, Par};
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
/// (material angles coupling only to neighbouring angles) is tridiagonal.
fn massless_block_negatives(pattern: &SymmetricPattern, values: &[f64], mass: &[f64]) -> usize {
    let idx: Vec<usize> = (0..mass.len()).filter(|&d| mass[d] == 0.0).collect();
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
    let diag_scale = pattern
        .diagonal
        .iter()
        .map(|&s| values[s].abs())
        .fold(0.0, f64::max)
        .max(1e-300);
    let negative_count = match count(0.0, ldlt, &mut work) {
        Some(c) => c,
        // singular at 0: count at a tiny negative shift (zero modes are not negative)
        None => count(-1e-12 * diag_scale, ldlt, &mut work).ok_or(StabilityError::NoShift)?,
    };
    // σ strictly below the lowest eigenvalue
    let mut sigma = if negative_count == 0 {
        0.0
    } else {
        -1e-8 * diag_scale
    };
    loop {
        match count(sigma, ldlt, &mut work) {
            Some(0) if sigma < 0.0 || negative_count == 0 => break,
            _ => {}
        }
        sigma = if sigma == 0.0 {
            -1e-8 * diag_scale
        } else {
            sigma * 4.0
        };
        if sigma < -1e3 * diag_scale {
            return Err(StabilityError::NoShift);
        }
    }
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
            ..Default::default()
        });
    }
    let op = ShiftInvert {
        ldlt: Mutex::new(ldlt),
        reduced: &reduced,
        weight: &weight,
        full_dim: n,
    };
    let mu: Vec<(f64, Vec<f64>)> = if dim <= 128 {
        // small problems: the operator as a dense matrix (faer's Lanczos needs
        // a subspace smaller than the space)
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
        let params = PartialEigenParams {
            max_dim: (4 * k).max(80),
            ..Default::default()
        };
        let mut buf = MemBuffer::new(partial_self_adjoint_eigen_scratch::<f64>(
            &op,
            k,
            Par::Seq,
            params,
        ));
        let mut vecs = Mat::<f64>::zeros(dim, k);
        let mut mu = vec![0.0; k];
        // deterministic start vector with components on every mode
        let v0 = Col::<f64>::from_fn(dim, |i| 1.0 + 0.5 * ((i as f64) * 0.7548776662).sin());
        partial_self_adjoint_eigen(
            vecs.as_mut(),
            &mut mu,
            &op,
            v0.as_ref(),
            1e-12,
            Par::Seq,
            MemStack::new(&mut buf),
            params,
        );
        mu.iter()
            .enumerate()
            .map(|(c, m)| (*m, (0..dim).map(|r| vecs[(r, c)]).collect()))
            .collect()
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
    Ok(Spectrum {
        values: modes.iter().map(|m| m.0).collect(),
        vectors: modes.into_iter().map(|m| m.1).collect(),
        negative_count,
    })
}
