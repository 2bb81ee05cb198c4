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

use crate::linalg::eigen::lowest_eigenvalues;
use crate::linalg::sparse::{Ldlt, SymmetricPattern};
use crate::model::contact::{ContactForce, ContactModel, Gap, Obstacle};
use crate::model::contact_hessian::ContactHessian;
use crate::model::energy::RodEnergy;
use crate::model::rod::RodState;
use crate::solve::kkt::Kkt;
use crate::solve::outcome::{SolveError, SolveReport, SolverSettings, armijo, residual};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSolver, IPSolver, SolverStatus,
    SupportedConeT::{NonnegativeConeT, ZeroConeT},
};

/// Relative KKT residual accepted with active contacts.
pub const CONTACT_TOL: f64 = 1e-7;

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
    fn new(energy: &RodEnergy) -> Self {
        let map = energy.map;
        let n = energy.model.segments;
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

fn qp_settings() -> DefaultSettings<f64> {
    DefaultSettings {
        verbose: false,
        presolve_enable: false,
        max_iter: 200,
        ..DefaultSettings::default()
    }
}

/// Contact rows of one iterate: candidate gaps and their gradients on the
/// free dofs (row-major, sparse).
fn contact_rows(
    energy: &RodEnergy,
    contact: Option<&ContactModel>,
    state: &RodState,
) -> (Vec<Gap>, Vec<Vec<(usize, f64)>>) {
    let Some(model) = contact else {
        return (Vec::new(), Vec::new());
    };
    let map = energy.map;
    let gaps = model.gaps(state);
    let rows = gaps
        .iter()
        .map(|g| {
            let mut row = Vec::new();
            for (k, grad) in &g.gradient {
                // centreline point k is node k (points 0 and N+1 are the
                // clamps' end points, fixed)
                if let Some(d) = map.node(*k) {
                    for c in 0..3 {
                        row.push((d + c, grad[c]));
                    }
                }
            }
            row
        })
        .collect();
    (gaps, rows)
}

/// Minimise the energy of a rod with constraints (u2 = 0 of a constrained
/// law, contact inequalities) from `state` (updated in place, with its
/// multipliers).
pub fn minimize(
    energy: &RodEnergy,
    ldlt: &mut Ldlt,
    contact: Option<&ContactModel>,
    state: &mut RodState,
    settings: &SolverSettings,
) -> Result<SolveReport, SolveError> {
    let map = energy.map;
    let n = map.len();
    let h = energy.model.segment_length();
    let constrained = energy.penalty.is_some();
    let penalty = energy.penalty.unwrap_or(0.0);
    let segments = energy.model.segments;
    if constrained {
        state.multipliers.resize(segments + 1, 0.0);
    }
    let m_eq = if constrained { segments } else { 0 };
    let nnz = energy.pattern.nnz();
    let mut grad = vec![0.0; n];
    let mut values = vec![0.0; nnz];
    let mut jtc = vec![0.0; n];
    let mut jtl = vec![0.0; n];
    // per-iteration work vectors, allocated once
    let mut lagrangian = vec![0.0; n];
    let mut q = vec![0.0; n];
    let mut residual_kkt = vec![0.0; n + m_eq];
    let mut trial_step = vec![0.0; n];
    let mut part = vec![0.0; n];
    let mut sub = state.clone();
    let mut jacobian = ConstraintMatrix::new(energy);
    let mut kkt = constrained.then(|| Kkt::new(&energy));
    let step_cap = match &contact {
        Some(c) => settings.max_step.min(0.5 * c.margin),
        None => settings.max_step,
    };
    let mut solver: Option<DefaultSolver<f64>> = None;
    // the widened Hessian of the last contact set (pattern and symbolic
    // factorisation reused while the set is unchanged)
    let mut wide: Option<ContactHessian> = None;
    let mut report = SolveReport::start();
    let mut trial = state.clone();
    let mut shift;
    // contact forces of the last QP, by (segments, obstacle kind)
    let mut forces: Vec<(Gap, f64)> = Vec::new();
    for it in 0..=settings.max_iterations {
        let info = energy.hessian(state, &mut grad, &mut values);
        let rows = if constrained {
            energy.constraint_rows(state)
        } else {
            Vec::new()
        };
        let c: Vec<f64> = rows.iter().map(|r| r.0).collect();
        jacobian.fill(&rows);
        let (gaps, gap_rows) = contact_rows(energy, contact, state);
        // Lagrangian gradient ∇E + Jᵀλ − Σ z ∇g = ∇(augmented) − ρ Jᵀc − Σ z ∇g
        lagrangian.copy_from_slice(&grad);
        if constrained {
            jacobian.transpose_mul(&c, &mut jtc);
            lagrangian
                .iter_mut()
                .zip(&jtc)
                .for_each(|(l, j)| *l -= penalty * j);
        }
        for (g, z) in &forces {
            if let Some(k) = gaps.iter().position(|x| same_pair(x, g)) {
                for &(d, v) in &gap_rows[k] {
                    lagrangian[d] -= z * v;
                }
            }
        }
        let gnorm = lagrangian.iter().map(|x| x * x).sum::<f64>().sqrt();
        let max_diag = energy.pattern.max_abs_diagonal(&values);
        let (rel, at_floor) = residual(&info, gnorm, max_diag, state, n);
        let infeasibility = c.iter().map(|x| (x / h).abs()).fold(0.0, f64::max);
        let penetration = gaps.iter().map(|g| -g.gap).fold(0.0, f64::max);
        if !rel.is_finite() || !infeasibility.is_finite() {
            return Err(SolveError::NonFinite {
                step: "constrained gradient",
                iteration: it,
            });
        }
        report.record(it, rel.max(infeasibility), info.energy);
        let contact_ok = contact
            .as_ref()
            .is_none_or(|m| penetration <= 1e-6 * m.diameter);
        // with contacts the KKT residual stalls near 1e-8: the closest points
        // of a rod lying along an obstacle are not smooth functions of the
        // nodes (and the interior-point duals carry that accuracy)
        let tol = if forces.iter().any(|f| f.1 > 0.0) {
            settings.gradient_tol.max(CONTACT_TOL)
        } else {
            settings.gradient_tol
        };
        if (rel <= tol || at_floor) && infeasibility <= CURVATURE_TOL && contact_ok {
            report.converged = true;
            let rows: Vec<ContactForce> = forces
                .iter()
                .filter(|(_, z)| *z > 0.0)
                .filter_map(|(g, z)| {
                    let now = gaps.iter().find(|x| same_pair(x, g))?;
                    Some(ContactForce {
                        s: now.s,
                        obstacle: now.obstacle.name(),
                        force: *z,
                        gap: now.gap,
                    })
                })
                .collect();
            report.contacts = merge_contacts(rows, 1.5 * h);
            report.contact_rows = forces
                .iter()
                .filter(|(_, z)| *z > 0.0)
                .filter_map(|(g, z)| Some((gaps.iter().find(|x| same_pair(x, g))?.clone(), *z)))
                .collect();
            return Ok(report);
        }
        if it == settings.max_iterations {
            break;
        }
        // with contacts the QP's Hessian is that of the Lagrangian E − Σ z g
        // (the contacts' curvature, forces from the last QP), on the energy's
        // pattern widened by the contact couplings
        let widened = match &contact {
            Some(model) if !gaps.is_empty() => {
                let refs: Vec<&Gap> = gaps.iter().collect();
                if !wide.as_ref().is_some_and(|w| w.fits(&refs)) {
                    wide = Some(ContactHessian::new(&energy, &refs));
                }
                let z = |g: &Gap| {
                    forces
                        .iter()
                        .find(|f| same_pair(&f.0, g))
                        .map_or(0.0, |f| f.1)
                };
                let w = wide.as_mut().expect("built above");
                w.fill(
                    &energy,
                    &values,
                    model,
                    state,
                    gaps.iter().map(|g| (g, z(g))),
                    0.0,
                );
                true
            }
            _ => false,
        };
        let (pat, vals, ldlt): (&SymmetricPattern, &mut Vec<f64>, &mut Ldlt) = match wide.as_mut() {
            Some(w) if widened => (&w.pattern, &mut w.values, &mut w.ldlt),
            _ => (&energy.pattern, &mut values, ldlt),
        };
        // convexify: W + shift I positive definite, the shift just beyond the
        // lowest eigenvalue (a larger one would make a falling rod creep)
        shift = 0.0;
        loop {
            for &s in &pat.diagonal {
                vals[s] += shift;
            }
            report.factorizations += 1;
            if ldlt.factor(vals).is_ok() && ldlt.negative_count() == 0 {
                break;
            }
            for &s in &pat.diagonal {
                vals[s] -= shift;
            }
            shift = if shift == 0.0 {
                let lowest = lowest_eigenvalues(pat, vals, None, 1, ldlt)
                    .ok()
                    .and_then(|sp| sp.values.first().copied())
                    .unwrap_or(-1e-8 * max_diag);
                1.5 * lowest.abs() + 1e-8 * max_diag
            } else {
                2.0 * shift
            };
            if shift > 1e6 * max_diag {
                return Err(SolveError::NonFinite {
                    step: "SQP Hessian regularisation",
                    iteration: it,
                });
            }
        }
        // QP: linear term ∇E + ρ Jᵀc = ∇(augmented) − Jᵀλ
        q.copy_from_slice(&grad);
        if constrained {
            jacobian.transpose_mul(&state.multipliers[1..], &mut jtl);
            q.iter_mut().zip(&jtl).for_each(|(g, j)| *g -= j);
        }
        let (mut d, mut new_lambda, z) = if m_eq == 0 && gaps.is_empty() {
            // nothing to constrain here: the (shifted) Newton step
            let mut d: Vec<f64> = q.iter().map(|x| -x).collect();
            ldlt.solve_in_place(&mut d);
            (d, Vec::new(), Vec::new())
        } else {
            let (a, b) = stack_rows(&jacobian.matrix, &c, &gap_rows, &gaps, n);
            if !gaps.is_empty() {
                // the contact rows change from step to step
                solver = None;
            }
            let (d, duals) = solve_qp(
                &mut solver,
                (pat.matrix.col_offsets(), pat.matrix.row_indices(), vals),
                &q,
                &a,
                &b,
                m_eq,
            )
            .ok_or(SolveError::NonFinite {
                step: "SQP subproblem (clarabel)",
                iteration: it,
            })?;
            let (l, z) = duals.split_at(m_eq);
            (d, l.to_vec(), z.to_vec())
        };
        // polish (equality rows only): Newton on the QP's KKT conditions with
        // the exact sparse KKT factorisation
        if let Some(kkt) = kkt.as_mut().filter(|_| gaps.is_empty()) {
            kkt.assemble(vals, &rows);
            if kkt.ldlt.factor(&kkt.values).is_ok() {
                report.factorizations += 1;
                for _ in 0..2 {
                    let r = &mut residual_kkt;
                    pat.mul_vec(vals, &d, &mut r[..n]);
                    jacobian.transpose_mul(&new_lambda, &mut jtl);
                    for k in 0..n {
                        r[k] = -(r[k] + q[k] + jtl[k]);
                    }
                    jacobian.mul(&d, &mut r[n..]);
                    for (rc, ck) in r[n..].iter_mut().zip(&c) {
                        *rc = -(*rc + ck);
                    }
                    kkt.ldlt.solve_in_place(r);
                    d.iter_mut().zip(&r[..n]).for_each(|(x, y)| *x += y);
                    new_lambda
                        .iter_mut()
                        .zip(&r[n..])
                        .for_each(|(x, y)| *x += y);
                }
            }
        }
        // polish (contacts, no equality rows): the exact QP solution by an
        // active-set iteration from the interior point's duals
        let mut z = z;
        if m_eq == 0
            && !gaps.is_empty()
            && let Some((dp, zp)) = polish_contacts(ldlt, &q, &gap_rows, &gaps, &z, None)
        {
            // keep the polish unless the interior point's step is feasible
            // and better (an inexact interior point can miss the active set,
            // or stop outside the linearised constraints)
            let mut objective = |x: &[f64]| {
                pat.mul_vec(vals, x, &mut part);
                0.5 * x.iter().zip(&part).map(|(a, b)| a * b).sum::<f64>()
                    + x.iter().zip(&q).map(|(a, b)| a * b).sum::<f64>()
            };
            let feasible = gaps
                .iter()
                .zip(&gap_rows)
                .all(|(g, r)| g.gap + r.iter().map(|&(k, v)| v * d[k]).sum::<f64>() >= -1e-9 * h);
            if !feasible || objective(&dp) <= objective(&d) + 1e-12 * objective(&d).abs() {
                d = dp;
                z = zp;
            }
        }
        // the convexified QP converges only linearly; where the true Hessian
        // is positive definite on the active contacts' tangent space, the
        // exact SQP step (same active set, unshifted Hessian) restores
        // Newton's quadratic convergence
        if m_eq == 0 && shift > 0.0 && z.iter().any(|v| *v > 0.0) {
            report.factorizations += 1;
            for &s in &pat.diagonal {
                vals[s] -= shift;
            }
            if ldlt.factor(vals).is_ok() {
                let k = ldlt.negative_count();
                if let Some((dp, zp)) = polish_contacts(ldlt, &q, &gap_rows, &gaps, &z, Some(k)) {
                    d = dp;
                    z = zp;
                }
            }
        }
        forces = gaps
            .iter()
            .cloned()
            .zip(z.iter().map(|v| v.max(0.0)))
            .collect();
        let mut step = d;
        let largest = (0..n)
            .filter(|&k| map.is_translation(k))
            .map(|k| step[k].abs())
            .fold(0.0, f64::max);
        if largest > step_cap {
            let f = step_cap / largest;
            step.iter_mut().for_each(|v| *v *= f);
        }
        // merit: the augmented Lagrangian with the new multipliers, plus an
        // exact penalty on the contact gaps
        if constrained {
            state.multipliers[1..].copy_from_slice(&new_lambda);
        }
        let mu = 2.0 * z.iter().fold(0.0f64, |a, b| a.max(*b)) + 1.0;
        let contact_penalty = |s: &RodState| -> f64 {
            match &contact {
                Some(m) if !gaps.is_empty() => {
                    let (points, _) = s.centreline();
                    gaps.iter()
                        .map(|g| (-m.gap_at(&points, g)).max(0.0))
                        .sum::<f64>()
                        * mu
                }
                _ => 0.0,
            }
        };
        let merit_info = energy.gradient(state, &mut grad);
        let merit0 = merit_info.energy + contact_penalty(state);
        let violation = mu * gaps.iter().map(|g| (-g.gap).max(0.0)).sum::<f64>();
        let slope: f64 = step.iter().zip(&grad).map(|(s, g)| s * g).sum::<f64>() - violation;
        if slope >= 0.0 && rel > 1e3 * settings.gradient_tol {
            // not a descent direction (an inexact QP solution with a wrong
            // active set): say so now rather than creep
            return Err(SolveError::LineSearch {
                iteration: it,
                residual: rel,
            });
        }
        let mut merit_at = |alpha: f64| {
            for (t, v) in trial_step.iter_mut().zip(&step) {
                *t = alpha * v;
            }
            state.displace_into(&map, &trial_step, &mut trial);
            // continuous collision check: no candidate pair may pass through
            // contact along the step (sub-steps finer than half a diameter;
            // pairs beyond the margin cannot close it in one step)
            if let Some(m) = &contact
                && !gaps.is_empty()
            {
                let largest_move = alpha * largest.min(step_cap);
                let pieces = ((4.0 * largest_move / m.diameter).ceil() as usize).clamp(1, 64);
                for k in 1..=pieces {
                    let f = k as f64 / pieces as f64;
                    part.iter_mut()
                        .zip(&trial_step)
                        .for_each(|(p, x)| *p = f * x);
                    state.displace_into(&map, &part, &mut sub);
                    let (points, _) = sub.centreline();
                    if gaps
                        .iter()
                        .any(|g| m.gap_at(&points, g) < -0.5 * m.diameter)
                    {
                        return None;
                    }
                }
            }
            Some(energy.energy(&trial) + contact_penalty(&trial))
        };
        let alpha = armijo(merit0, slope, &mut merit_at).ok_or(SolveError::LineSearch {
            iteration: it,
            residual: rel,
        })?;
        // on a convexified (shifted) step near a saddle the full step can be
        // far too short: the shift set by the unconstrained Hessian's lowest
        // eigenvalue damps a direction that is only slightly unstable on the
        // contacts' tangent space, and the rod would creep away. Extend the
        // step while the merit keeps falling (up to the step cap)
        if alpha == 1.0 && shift > 0.0 && m_eq == 0 {
            let room = step_cap / largest.min(step_cap).max(1e-300);
            let mut best = (1.0, merit_at(1.0).unwrap_or(f64::INFINITY));
            let mut a = 2.0;
            while a <= room.min(1024.0) {
                match merit_at(a) {
                    Some(m) if m < best.1 => best = (a, m),
                    _ => break,
                }
                a *= 2.0;
            }
            merit_at(best.0);
        }
        std::mem::swap(state, &mut trial);
    }
    Err(report.not_converged())
}

/// The QP with contact rows only, solved exactly by a primal-dual active-set
/// iteration started from the interior-point duals `z` (P factored in
/// `ldlt`): each trial active set is solved as equalities through the
/// small Schur complement G P⁻¹ Gᵀ (one sparse solve per row), a row with a
/// negative force leaves it, the most violated other row joins it. Returns
/// the step and the contact forces, or None if it does not settle.
///
/// With `indefinite = Some(k)` the factored matrix is the true Hessian with
/// k negative eigenvalues, and the answer is kept only if the Hessian is
/// positive definite on the tangent space of the active contacts: by
/// Haynsworth, the KKT matrix has inertia In(W) + In(−S), which must hold
/// exactly m negative eigenvalues, so S needs m − k positive ones.
fn polish_contacts(
    ldlt: &mut Ldlt,
    q: &[f64],
    gap_rows: &[Vec<(usize, f64)>],
    gaps: &[Gap],
    z: &[f64],
    indefinite: Option<usize>,
) -> Option<(Vec<f64>, Vec<f64>)> {
    let n = q.len();
    let zmax = z.iter().fold(0.0f64, |a, b| a.max(*b));
    let mut active: Vec<usize> = (0..gaps.len())
        .filter(|&k| zmax > 0.0 && z[k] > 1e-3 * zmax)
        .collect();
    let dot = |row: &[(usize, f64)], v: &[f64]| row.iter().map(|&(d, x)| x * v[d]).sum::<f64>();
    let mut pq = q.to_vec();
    ldlt.solve_in_place(&mut pq);
    // P⁻¹ gᵀ per row, computed when the row first joins
    let mut pg: Vec<Option<Vec<f64>>> = vec![None; gaps.len()];
    let tol = 1e-12 * gaps.iter().map(|g| g.gap.abs()).fold(1e-3, f64::max);
    for _ in 0..4 * gaps.len() + 4 {
        for &k in &active {
            if pg[k].is_none() {
                let mut v = vec![0.0; n];
                for &(d, x) in &gap_rows[k] {
                    v[d] += x;
                }
                ldlt.solve_in_place(&mut v);
                pg[k] = Some(v);
            }
        }
        let m = active.len();
        let column = |i: usize| pg[active[i]].as_deref().unwrap();
        let s = nalgebra::DMatrix::from_fn(m, m, |i, j| dot(&gap_rows[active[i]], column(j)));
        let rhs = nalgebra::DVector::from_fn(m, |i, _| {
            dot(&gap_rows[active[i]], &pq) - gaps[active[i]].gap
        });
        let zs = if m > 0 {
            s.clone().lu().solve(&rhs)?
        } else {
            nalgebra::DVector::zeros(0)
        };
        if let Some(i) = (0..m)
            .filter(|&i| zs[i] < 0.0)
            .min_by(|&a, &b| zs[a].total_cmp(&zs[b]))
        {
            active.remove(i);
            continue;
        }
        let mut d: Vec<f64> = pq.iter().map(|x| -x).collect();
        for i in 0..m {
            d.iter_mut()
                .zip(column(i))
                .for_each(|(x, y)| *x += zs[i] * y);
        }
        // the other contacts must stay open (linearised)
        let violated = (0..gaps.len())
            .filter(|k| !active.contains(k))
            .map(|k| (k, gaps[k].gap + dot(&gap_rows[k], &d)))
            .filter(|&(_, g)| g < -tol)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((k, _)) = violated {
            active.push(k);
            continue;
        }
        if let Some(k) = indefinite {
            let positive = if m == 0 {
                0
            } else {
                s.symmetric_eigenvalues()
                    .iter()
                    .filter(|v| **v > 0.0)
                    .count()
            };
            if k > m || positive != m - k {
                return None;
            }
        }
        let mut full = vec![0.0; gaps.len()];
        for (i, &k) in active.iter().enumerate() {
            full[k] = zs[i];
        }
        return Some((d, full));
    }
    None
}

/// One contact per touching region: rows of neighbouring segments (within
/// `reach` in arc length) pressing on the same obstacle are one contact, at
/// their force-weighted arc length, with their total force; negligible rows
/// (below 1e-6 of the largest force: interior-point residue) are dropped.
fn merge_contacts(mut rows: Vec<ContactForce>, reach: f64) -> Vec<ContactForce> {
    let largest = rows.iter().map(|c| c.force).fold(0.0, f64::max);
    rows.retain(|c| c.force > 1e-6 * largest);
    rows.sort_by(|a, b| a.obstacle.cmp(&b.obstacle).then(a.s.total_cmp(&b.s)));
    let mut out: Vec<(ContactForce, f64)> = Vec::new(); // contact, last s
    for c in rows {
        if let Some((m, last)) = out.last_mut()
            && m.obstacle == c.obstacle
            && c.s - *last <= reach
        {
            let f = m.force + c.force;
            m.s = (m.s * m.force + c.s * c.force) / f;
            m.force = f;
            m.gap = m.gap.min(c.gap);
            *last = c.s;
            continue;
        }
        let s = c.s;
        out.push((c, s));
    }
    let mut merged: Vec<ContactForce> = out.into_iter().map(|(c, _)| c).collect();
    merged.sort_by(|a, b| a.s.total_cmp(&b.s));
    merged
}

/// The same contact pair (segments and kind of obstacle).
fn same_pair(a: &Gap, b: &Gap) -> bool {
    a.segments == b.segments
        && std::mem::discriminant(&a.obstacle) == std::mem::discriminant(&b.obstacle)
        && match (a.obstacle, b.obstacle) {
            (Obstacle::Fixed(x), Obstacle::Fixed(y)) => x == y,
            _ => true,
        }
}

/// The QP's constraint matrix and right-hand side: equality rows J d = −c,
/// then contact rows −∇g d + s = g, s ≥ 0.
fn stack_rows(
    jacobian: &CscMatrix<f64>,
    c: &[f64],
    gap_rows: &[Vec<(usize, f64)>],
    gaps: &[Gap],
    n: usize,
) -> (CscMatrix<f64>, Vec<f64>) {
    let m_eq = c.len();
    let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    if m_eq > 0 {
        for (col, entries) in cols.iter_mut().enumerate() {
            for k in jacobian.colptr[col]..jacobian.colptr[col + 1] {
                entries.push((jacobian.rowval[k], jacobian.nzval[k]));
            }
        }
    }
    for (r, row) in gap_rows.iter().enumerate() {
        for &(d, v) in row {
            cols[d].push((m_eq + r, -v));
        }
    }
    let mut colptr = vec![0usize];
    let (mut rowval, mut nzval) = (Vec::new(), Vec::new());
    for mut entries in cols {
        entries.sort_by_key(|e| e.0);
        // merge duplicates (a self pair's two segments can share a dof)
        let mut last: Option<usize> = None;
        for (r, v) in entries {
            if last == Some(r) {
                *nzval.last_mut().unwrap() += v;
            } else {
                rowval.push(r);
                nzval.push(v);
                last = Some(r);
            }
        }
        colptr.push(rowval.len());
    }
    let rows = m_eq + gaps.len();
    let mut b: Vec<f64> = c.iter().map(|x| -x).collect();
    b.extend(gaps.iter().map(|g| g.gap));
    (CscMatrix::new(rows, n, colptr, rowval, nzval), b)
}

/// Solve the QP with clarabel (set up once, then only its data updated);
/// returns the step and the multipliers of the equality rows.
fn solve_qp(
    solver: &mut Option<DefaultSolver<f64>>,
    p: (&[usize], &[usize], &[f64]),
    q: &[f64],
    a: &CscMatrix<f64>,
    b: &[f64],
    m_eq: usize,
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
            let mut cones = Vec::new();
            if m_eq > 0 {
                cones.push(ZeroConeT(m_eq));
            }
            if b.len() > m_eq {
                cones.push(NonnegativeConeT(b.len() - m_eq));
            }
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
        SolverStatus::MaxIterations | SolverStatus::InsufficientProgress => {}
        // infeasible linearised contacts (or worse): no step to take
        _ => return None,
    }
    let x = s.solution.x.clone();
    let z = s.solution.z.clone();
    if x.iter().chain(&z).any(|v| !v.is_finite()) {
        return None;
    }
    Some((x, z))
}
