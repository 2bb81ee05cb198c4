//! Sparse symmetric matrices with a fixed pattern (nalgebra-sparse, upper
//! triangle, CSC) and their LDLᵀ factorisation with faer, symbolic part reused.

use dyn_stack::{MemBuffer, MemStack};
use faer::Par;
use faer::linalg::cholesky::ldlt::factor::{LdltParams, LdltRegularization};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Side, Spec};
use nalgebra_sparse::{CooMatrix, CscMatrix};

/// Marker for "no slot" in stencil scatter tables.
pub const NO_SLOT: usize = usize::MAX;

/// A symmetric sparsity pattern (upper triangle) built from dense stencils, with
/// for each stencil the value slot of each local (a, b) pair.
#[derive(Clone, Debug)]
pub struct SymmetricPattern {
    /// The pattern with zero values (upper triangle, CSC, sorted rows).
    pub matrix: CscMatrix<f64>,
    /// Per stencil, row-major table of value slots (NO_SLOT where a dof is fixed).
    pub slots: Vec<Vec<usize>>,
    /// Slot of each diagonal entry.
    pub diagonal: Vec<usize>,
}

impl SymmetricPattern {
    /// Build the pattern of a matrix of dimension `n` whose entries come from
    /// dense stencils over the given dof lists (None = fixed dof).
    pub fn from_stencils(n: usize, stencils: &[Vec<Option<usize>>]) -> Self {
        let mut coo = CooMatrix::new(n, n);
        for d in 0..n {
            coo.push(d, d, 0.0);
        }
        for st in stencils {
            for a in st.iter().flatten() {
                for b in st.iter().flatten() {
                    if a <= b {
                        coo.push(*a, *b, 0.0);
                    }
                }
            }
        }
        let matrix = CscMatrix::from(&coo);
        let slot = |r: usize, c: usize| -> usize {
            let (r, c) = if r <= c { (r, c) } else { (c, r) };
            let start = matrix.col_offsets()[c];
            let end = matrix.col_offsets()[c + 1];
            start + matrix.row_indices()[start..end].binary_search(&r).unwrap()
        };
        let slots = stencils
            .iter()
            .map(|st| {
                let m = st.len();
                let mut s = vec![NO_SLOT; m * m];
                for a in 0..m {
                    for b in 0..m {
                        if let (Some(ga), Some(gb)) = (st[a], st[b]) {
                            s[a * m + b] = slot(ga, gb);
                        }
                    }
                }
                s
            })
            .collect();
        let diagonal = (0..n).map(|d| slot(d, d)).collect();
        SymmetricPattern {
            matrix,
            slots,
            diagonal,
        }
    }

    /// Dimension.
    pub fn dim(&self) -> usize {
        self.matrix.nrows()
    }

    /// Number of stored (upper) entries.
    pub fn nnz(&self) -> usize {
        self.matrix.nnz()
    }

    /// Value slot of entry (r, c) (either triangle), if it is in the pattern.
    pub fn slot(&self, r: usize, c: usize) -> Option<usize> {
        let (r, c) = if r <= c { (r, c) } else { (c, r) };
        let start = self.matrix.col_offsets()[c];
        let end = self.matrix.col_offsets()[c + 1];
        self.matrix.row_indices()[start..end]
            .binary_search(&r)
            .ok()
            .map(|k| start + k)
    }

    /// y = A x for the symmetric matrix with these upper-triangle values.
    pub fn mul_vec(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        let cp = self.matrix.col_offsets();
        let ri = self.matrix.row_indices();
        for c in 0..self.dim() {
            for k in cp[c]..cp[c + 1] {
                let r = ri[k];
                y[r] += values[k] * x[c];
                if r != c {
                    y[c] += values[k] * x[r];
                }
            }
        }
    }

    /// Largest |A_ii| of the matrix with these values (the scale of its
    /// stiffness: shifts and round-off floors are measured against it).
    pub fn max_abs_diagonal(&self, values: &[f64]) -> f64 {
        self.diagonal
            .iter()
            .map(|&s| values[s].abs())
            .fold(0.0, f64::max)
    }

    /// Dense copy of the symmetric matrix (tests and small diagnostics only).
    pub fn to_dense(&self, values: &[f64]) -> nalgebra::DMatrix<f64> {
        let n = self.dim();
        let mut m = nalgebra::DMatrix::zeros(n, n);
        let cp = self.matrix.col_offsets();
        let ri = self.matrix.row_indices();
        for c in 0..n {
            for k in cp[c]..cp[c + 1] {
                m[(ri[k], c)] = values[k];
                m[(c, ri[k])] = values[k];
            }
        }
        m
    }
}

/// Sparse LDLᵀ factorisation (no pivoting, simplicial) of matrices sharing one
/// pattern. Symbolic analysis and workspace are made once.
pub struct Ldlt {
    symbolic: SymbolicCholesky<usize>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    factor: Vec<f64>,
    buffer: MemBuffer,
    factored: bool,
}

impl std::fmt::Debug for Ldlt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ldlt")
            .field("dim", &self.col_ptr.len().saturating_sub(1))
            .finish()
    }
}

/// The factorisation met a zero pivot (the matrix is singular to working precision).
#[derive(Debug, Clone, Copy)]
pub struct SingularPivot;

impl Ldlt {
    /// Symbolic analysis of the pattern (natural order: our dofs are banded).
    pub fn new(pattern: &SymmetricPattern) -> Self {
        Self::with_order(pattern, None)
    }

    /// Symbolic analysis with the unknowns eliminated in the given order
    /// (`order[k]` is the unknown eliminated k-th), e.g. each multiplier of a
    /// KKT matrix right after the unknowns of its constraint, which keeps the
    /// factor banded and every pivot nonzero without pivoting.
    pub fn with_order(pattern: &SymmetricPattern, order: Option<&[usize]>) -> Self {
        let n = pattern.dim();
        let col_ptr = pattern.matrix.col_offsets().to_vec();
        let row_idx = pattern.matrix.row_indices().to_vec();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
            ..Default::default()
        };
        let symbolic = match order {
            None => {
                factorize_symbolic_cholesky(sym, Side::Upper, SymmetricOrdering::Identity, params)
            }
            Some(order) => {
                let fwd = order.to_vec();
                let mut inv = vec![0usize; n];
                for (k, &o) in fwd.iter().enumerate() {
                    inv[o] = k;
                }
                let perm = faer::perm::PermRef::new_checked(&fwd, &inv, n);
                factorize_symbolic_cholesky(
                    sym,
                    Side::Upper,
                    SymmetricOrdering::Custom(perm),
                    params,
                )
            }
        }
        .expect("symbolic Cholesky of a valid pattern");
        let factor = vec![0.0; symbolic.len_val()];
        let req = symbolic
            .factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Spec::<LdltParams, f64>::default())
            .or(faer::linalg::temp_mat_scratch::<f64>(n, 1));
        Ldlt {
            symbolic,
            col_ptr,
            row_idx,
            factor,
            buffer: MemBuffer::new(req),
            factored: false,
        }
    }

    /// Factor A (upper values on the pattern). Err on a zero pivot.
    pub fn factor(&mut self, values: &[f64]) -> Result<(), SingularPivot> {
        crate::linalg::counters::add_factorization();
        let n = self.col_ptr.len() - 1;
        let a = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx),
            values,
        );
        let stack = MemStack::new(&mut self.buffer);
        let res = self.symbolic.factorize_numeric_ldlt(
            &mut self.factor,
            a,
            Side::Upper,
            LdltRegularization::default(),
            Par::Seq,
            stack,
            Spec::<LdltParams, f64>::default(),
        );
        self.factored = res.is_ok();
        let ok = res.is_ok() && self.pivots().all(|d| d.is_finite() && d != 0.0);
        self.factored = ok;
        if ok { Ok(()) } else { Err(SingularPivot) }
    }

    /// Diagonal D of the last factorisation.
    pub fn diagonal(&self) -> Vec<f64> {
        self.pivots().collect()
    }

    /// The pivots (D's diagonal) of the last factorisation, without
    /// collecting them (each factorisation checks them).
    fn pivots(&self) -> impl Iterator<Item = f64> + '_ {
        let cp = match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => s.col_ptr(),
            SymbolicCholeskyRaw::Supernodal(_) => unreachable!("simplicial forced"),
        };
        cp[..cp.len() - 1].iter().map(|&k| self.factor[k])
    }

    /// Number of negative pivots = number of negative eigenvalues (Sylvester).
    pub fn negative_count(&self) -> usize {
        self.pivots().filter(|d| *d < 0.0).count()
    }

    /// Solve A x = b in place.
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        assert!(self.factored, "solve before a successful factorisation");
        let n = b.len();
        let ldlt = faer::sparse::linalg::cholesky::LdltRef::new(&self.symbolic, &self.factor);
        let stack = MemStack::new(&mut self.buffer);
        let rhs = MatMut::from_column_major_slice_mut(b, n, 1);
        ldlt.solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack);
    }
}
