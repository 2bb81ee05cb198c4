//! Sequential quadratic programming for rods with constraints (the strip's
//! u2 = 0, later contact): each step is a convex QP solved by clarabel.
//!
//! At an iterate q with multipliers λ, the step d solves
//!   min ½ dᵀ W d + (∇E + ρ Jᵀc)ᵀ d   subject to   J d = −c,
//! where W is the Hessian of the augmented Lagrangian E + λᵀc + ρ/2 |c|²
//! (positive on the normal space thanks to ρ JᵀJ, made positive on the
//! tangent space by a diagonal shift when needed, as clarabel wants a convex
//! QP). The penalty terms vanish on the QP's feasible set, so its multipliers
//! are the new λ. The step is accepted by an Armijo search on the augmented
//! Lagrangian with the new λ (no Maratos effect: full steps near the solution,
//! quadratic convergence).

use crate::model::rod::RodState;
use crate::solve::kkt::Kkt;
use crate::solve::newton::{Newton, NewtonReport, NewtonSettings, SolveError, residual};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT::ZeroConeT,
};

/// The constraint holds when |u2| ≤ this at every vertex (u2 = κ2 / h).
pub const CURVATURE_TOL: f64 = 1e-10;

/// The linearised constraints J (rows: vertices 1..=N, columns: free dofs) in
/// CSC with a fixed pattern: each row's stencil entries, zeros kept.
struct ConstraintMatrix {
    matrix: CscMatrix<f64>,
    /// For vertex row r and stencil position a: the slot in `matrix.nzval`.
    slots: Vec<[usize; 11]>,
}

impl ConstraintMatrix {
    fn new(newton: &Newton) -> Self {
        let map = newton.energy.map;
        let n = newton.energy.model.segments;
        let mut entries: Vec<(usize, usize, usize, usize)> = Vec::new(); // col, row, row, a
        for r in 0..n {
            for (a, d) in map.vertex_stencil(r + 1).iter().enumerate() {
                if let Some(d) = d {
                    entries.push((*d, r, r, a));
                }
            }
        }
        entries.sort_unstable();
        let cols = map.len();
        let mut colptr = vec![0usize; cols + 1];
        let mut rowval = Vec::with_capacity(entries.len());
        let mut slots = vec![[usize::MAX; 11]; n];
        for (k, &(col, row, _, a)) in entries.iter().enumerate() {
            colptr[col + 1] += 1;
            rowval.push(row);
            slots[row][a] = k;
        }
        for c in 0..cols {
            colptr[c + 1] += colptr[c];
        }
        let nzval = vec![0.0; rowval.len()];
        ConstraintMatrix {
            matrix: CscMatrix::new(n, cols, colptr, rowval, nzval),
            slots,
        }
    }

    fn fill(&mut self, rows: &[(f64, [f64; 11])]) {
        for (r, (_, g)) in rows.iter().enumerate() {
            for (a, &k) in self.slots[r].iter().enumerate() {
                if k != usize::MAX {
                    self.matrix.nzval[k] = g[a];
                }
            }
        }
    }

    /// y = J x.
    fn mul(&self, x: &[f64], y: &mut [f64]) {
        let m = &self.matrix;
        y.iter_mut().for_each(|v| *v = 0.0);
        for (c, xc) in x.iter().enumerate() {
            for k in m.colptr[c]..m.colptr[c + 1] {
                y[m.rowval[k]] += m.nzval[k] * xc;
            }
        }
    }

    /// y = Jᵀ x.
    fn transpose_mul(&self, x: &[f64], y: &mut [f64]) {
        let m = &self.matrix;
        for (c, yc) in y.iter_mut().enumerate() {
            *yc = (m.colptr[c]..m.colptr[c + 1])
                .map(|k| m.nzval[k] * x[m.rowval[k]])
                .sum();
        }
    }
}

/// Largest |u2| over the vertices.
pub fn max_normal_curvature(newton: &Newton, state: &RodState) -> f64 {
    let h = newton.energy.model.segment_length();
    newton
        .energy
        .constraint_rows(state)
        .iter()
        .map(|(c, _)| (c / h).abs())
        .fold(0.0, f64::max)
}

fn qp_settings() -> DefaultSettings<f64> {
    DefaultSettings {
        verbose: false,
        presolve_enable: false,
        max_iter: 50,
        ..DefaultSettings::default()
    }
}

/// Minimise the energy of a constrained rod from `state` (updated in place);
/// its multipliers are updated with it.
pub fn minimize(
    newton: &mut Newton,
    state: &mut RodState,
    settings: &NewtonSettings,
) -> Result<NewtonReport, SolveError> {
    let map = newton.energy.map;
    let n = map.len();
    let h = newton.energy.model.segment_length();
    let penalty = newton.energy.penalty.expect("a constrained law");
    let segments = newton.energy.model.segments;
    state.multipliers.resize(segments + 1, 0.0);
    let nnz = newton.energy.pattern.nnz();
    let mut grad = vec![0.0; n];
    let mut values = vec![0.0; nnz];
    let mut jtc = vec![0.0; n];
    let mut jacobian = ConstraintMatrix::new(newton);
    let mut kkt = Kkt::new(&newton.energy);
    let p_pattern = &newton.energy.pattern.matrix;
    let (p_colptr, p_rowval) = (
        p_pattern.col_offsets().to_vec(),
        p_pattern.row_indices().to_vec(),
    );
    let mut solver: Option<DefaultSolver<f64>> = None;
    let mut report = NewtonReport::start();
    let mut trial = state.clone();
    let mut shift = 0.0f64;
    for it in 0..=settings.max_iterations {
        let info = newton.energy.hessian(state, &mut grad, &mut values);
        let rows = newton.energy.constraint_rows(state);
        let c: Vec<f64> = rows.iter().map(|r| r.0).collect();
        jacobian.fill(&rows);
        // Lagrangian gradient ∇E + Jᵀλ = ∇(augmented) − ρ Jᵀc
        jacobian.transpose_mul(&c, &mut jtc);
        let lagrangian: Vec<f64> = grad
            .iter()
            .zip(&jtc)
            .map(|(g, j)| g - penalty * j)
            .collect();
        let gnorm = lagrangian.iter().map(|x| x * x).sum::<f64>().sqrt();
        let max_diag = newton
            .energy
            .pattern
            .diagonal
            .iter()
            .map(|&s| values[s].abs())
            .fold(0.0, f64::max);
        let (rel, at_floor) = residual(&info, gnorm, max_diag, state, n);
        let infeasibility = c.iter().map(|x| (x / h).abs()).fold(0.0, f64::max);
        if !rel.is_finite() || !infeasibility.is_finite() {
            return Err(SolveError::NonFinite {
                step: "constrained gradient",
                iteration: it,
            });
        }
        report.record(it, rel.max(infeasibility), info.energy);
        if (rel <= settings.gradient_tol || at_floor) && infeasibility <= CURVATURE_TOL {
            report.converged = true;
            return Ok(report);
        }
        if it == settings.max_iterations {
            break;
        }
        // convexify: the smallest diagonal shift making W positive definite
        let previous = shift;
        shift = 0.0;
        loop {
            for &s in &newton.energy.pattern.diagonal {
                values[s] += shift;
            }
            report.factorizations += 1;
            if newton.ldlt.factor(&values).is_ok() && newton.ldlt.negative_count() == 0 {
                break;
            }
            for &s in &newton.energy.pattern.diagonal {
                values[s] -= shift;
            }
            shift = if shift == 0.0 {
                (0.1 * previous).max(1e-8 * max_diag)
            } else {
                10.0 * shift
            };
            if shift > 1e6 * max_diag {
                return Err(SolveError::NonFinite {
                    step: "SQP Hessian regularisation",
                    iteration: it,
                });
            }
        }
        // QP: linear term ∇E + ρ Jᵀc = ∇(augmented) − Jᵀλ
        let mut jtl = vec![0.0; n];
        jacobian.transpose_mul(&state.multipliers[1..], &mut jtl);
        let q: Vec<f64> = grad.iter().zip(&jtl).map(|(g, j)| g - j).collect();
        let b: Vec<f64> = c.iter().map(|x| -x).collect();
        let (mut d, mut new_lambda) = solve_qp(
            &mut solver,
            (&p_colptr, &p_rowval, &values),
            &q,
            &jacobian.matrix,
            &b,
        )
        .ok_or(SolveError::NonFinite {
            step: "SQP subproblem (clarabel)",
            iteration: it,
        })?;
        // polish: Newton on the QP's KKT conditions with the exact sparse
        // KKT factorisation (the active set is all rows: equalities)
        kkt.assemble(&values, &rows);
        if kkt.ldlt.factor(&kkt.values).is_ok() {
            report.factorizations += 1;
            for _ in 0..2 {
                let mut r = vec![0.0; n + segments];
                newton.energy.pattern.mul_vec(&values, &d, &mut r[..n]);
                jacobian.transpose_mul(&new_lambda, &mut jtl);
                for k in 0..n {
                    r[k] = -(r[k] + q[k] + jtl[k]);
                }
                jacobian.mul(&d, &mut r[n..]);
                for (rc, ck) in r[n..].iter_mut().zip(&c) {
                    *rc = -(*rc + ck);
                }
                kkt.ldlt.solve_in_place(&mut r);
                d.iter_mut().zip(&r[..n]).for_each(|(x, y)| *x += y);
                new_lambda
                    .iter_mut()
                    .zip(&r[n..])
                    .for_each(|(x, y)| *x += y);
            }
        }
        let mut step = d;
        let largest = (0..n)
            .filter(|&k| map.is_translation(k))
            .map(|k| step[k].abs())
            .fold(0.0, f64::max);
        if largest > settings.max_step {
            let f = settings.max_step / largest;
            step.iter_mut().for_each(|v| *v *= f);
        }
        // merit: the augmented Lagrangian with the new multipliers
        state.multipliers[1..].copy_from_slice(&new_lambda);
        let merit_info = newton.energy.gradient(state, &mut grad);
        let slope: f64 = step.iter().zip(&grad).map(|(s, g)| s * g).sum();
        let mut alpha = 1.0;
        let mut accepted = false;
        let mut trial_step = vec![0.0; n];
        for _ in 0..40 {
            for (t, v) in trial_step.iter_mut().zip(&step) {
                *t = alpha * v;
            }
            state.displace_into(&map, &trial_step, &mut trial);
            let e = newton.energy.energy(&trial);
            let tol = 1e-14 * merit_info.energy.abs().max(1.0);
            if e.is_finite() && e <= merit_info.energy + 1e-4 * alpha * slope.min(0.0) + tol {
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            return Err(SolveError::LineSearch {
                iteration: it,
                residual: rel,
            });
        }
        std::mem::swap(state, &mut trial);
    }
    Err(report.not_converged())
}

/// Solve the QP with clarabel (set up once, then only its data updated);
/// returns the step and the multipliers of the equality rows.
fn solve_qp(
    solver: &mut Option<DefaultSolver<f64>>,
    p: (&[usize], &[usize], &[f64]),
    q: &[f64],
    a: &CscMatrix<f64>,
    b: &[f64],
) -> Option<(Vec<f64>, Vec<f64>)> {
    let (colptr, rowval, values) = p;
    let n = q.len();
    match solver {
        Some(s) => {
            s.update_P(&values.to_vec()).ok()?;
            s.update_q(&q.to_vec()).ok()?;
            s.update_A(&a.nzval).ok()?;
            s.update_b(&b.to_vec()).ok()?;
        }
        None => {
            let pm = CscMatrix::new(n, n, colptr.to_vec(), rowval.to_vec(), values.to_vec());
            let cones = [ZeroConeT(b.len())];
            *solver = Some(DefaultSolver::new(&pm, q, a, b, &cones, qp_settings()).ok()?);
        }
    }
    let s = solver.as_mut()?;
    s.solve();
    match s.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {}
        // an interior-point solve stalls short of full accuracy on these
        // stiff QPs (ρ JᵀJ against bending): keep its iterate, the polish
        // below makes it exact
        _ => {}
    }
    let x = s.solution.x.clone();
    let z = s.solution.z.clone();
    if x.iter().chain(&z).any(|v| !v.is_finite()) {
        return None;
    }
    Some((x, z))
}
