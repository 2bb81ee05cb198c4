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
use crate::solve::outcome::{
    FloorProbe, SolveError, SolveReport, SolverSettings, armijo, floor_bound, judge,
};
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
    let mut sqp = Sqp::new(energy, ldlt, contact, state, settings);
    for it in 0..=settings.max_iterations {
        sqp.linearise(it)?;
        crate::linalg::counters::add_iteration();
        crate::linalg::counters::set_residual(sqp.res.rel);
        if sqp.converged() {
            return Ok(sqp.converged_report());
        }
        if it == settings.max_iterations {
            break;
        }
        sqp.assemble_hessian();
        sqp.convexify(it)?;
        sqp.solve_subproblem(it)?;
        sqp.polish_equality_step();
        sqp.polish_contact_step();
        sqp.exact_contact_step();
        sqp.update_forces();
        sqp.cap_step();
        let alpha = sqp.line_search(it)?;
        sqp.extend_step(alpha);
        sqp.accept();
    }
    Err(sqp.report.not_converged())
}

/// The QP's Hessian: the energy's (values from the linearisation), or with
/// contacts near the one widened by the contact couplings; either is shifted
/// in place by `convexify` and factored into its own `Ldlt`.
struct QpHessian<'a> {
    /// The energy Hessian's pattern.
    pattern: &'a SymmetricPattern,
    /// The energy Hessian's values.
    values: Vec<f64>,
    /// The energy Hessian's factorisation.
    ldlt: &'a mut Ldlt,
    /// The widened Hessian of the last contact set (pattern and symbolic
    /// factorisation reused while the set is unchanged).
    wide: Option<ContactHessian>,
    /// This iteration's QP uses `wide`.
    widened: bool,
}

impl QpHessian<'_> {
    /// The pattern, values and factorisation of this iteration's QP Hessian.
    fn parts(&mut self) -> (&SymmetricPattern, &mut [f64], &mut Ldlt) {
        match self.wide.as_mut() {
            Some(w) if self.widened => (&w.pattern, &mut w.values, &mut w.ldlt),
            _ => (self.pattern, &mut self.values, &mut *self.ldlt),
        }
    }
}

/// The residuals of the iterate.
#[derive(Default)]
struct Residuals {
    /// Largest |diagonal| of the energy Hessian.
    max_diag: f64,
    /// Relative Lagrangian gradient, and whether it passes the one
    /// convergence test (`judge`) at the solver's tolerance.
    rel: f64,
    at_floor: bool,
    /// Scratch of the measured round-off floor.
    floor: FloorProbe,
    /// Largest |u2|, and largest penetration.
    infeasibility: f64,
    penetration: f64,
}

/// One SQP solve: the problem, the work data (allocated once), the current
/// iterate's linearisation and its step. The iteration is a sequence of
/// phases, each a method (after Clarabel's solver loop).
struct Sqp<'a> {
    energy: &'a RodEnergy,
    contact: Option<&'a ContactModel>,
    settings: &'a SolverSettings,
    state: &'a mut RodState,
    report: SolveReport,
    // the problem's sizes
    /// Free dofs.
    n: usize,
    /// Segment length.
    h: f64,
    /// The law is constrained (u2 = 0 rows, penalty ρ).
    constrained: bool,
    penalty: f64,
    /// Number of equality rows.
    m_eq: usize,
    /// Largest translation of one step.
    step_cap: f64,
    // the linearisation at the iterate
    /// Energy gradient (in the line search: the merit's).
    grad: Vec<f64>,
    /// Equality rows: values c and gradients (vertex stencils).
    rows: Vec<(f64, [f64; 11])>,
    c: Vec<f64>,
    jacobian: ConstraintMatrix,
    jtc: Vec<f64>,
    /// Candidate contacts and their gradients.
    gaps: Vec<Gap>,
    gap_rows: Vec<Vec<(usize, f64)>>,
    lagrangian: Vec<f64>,
    res: Residuals,
    // the QP
    hessian: QpHessian<'a>,
    /// Diagonal shift that convexifies the QP Hessian.
    shift: f64,
    /// The QP's linear term.
    q: Vec<f64>,
    jtl: Vec<f64>,
    solver: Option<DefaultSolver<f64>>,
    kkt: Option<Kkt>,
    residual_kkt: Vec<f64>,
    // the step
    /// The step d, then capped.
    step: Vec<f64>,
    /// New multipliers of the equality rows, and contact forces, of the QP.
    lambda: Vec<f64>,
    z: Vec<f64>,
    /// Contact forces of the last QP, by (segments, obstacle kind).
    forces: Vec<(Gap, f64)>,
    /// This QP was solved exactly by the active-set iteration alone.
    exact_qp: bool,
    /// Largest translation of the uncapped step.
    largest: f64,
    /// Exact penalty weight of the contact gaps in the merit.
    mu: f64,
    // the line search
    trial_step: Vec<f64>,
    /// Scratch: a sub-step, or a Hessian product.
    part: Vec<f64>,
    trial: RodState,
    sub: RodState,
}

impl<'a> Sqp<'a> {
    fn new(
        energy: &'a RodEnergy,
        ldlt: &'a mut Ldlt,
        contact: Option<&'a ContactModel>,
        state: &'a mut RodState,
        settings: &'a SolverSettings,
    ) -> Self {
        let n = energy.map.len();
        let constrained = energy.penalty.is_some();
        let segments = energy.model.segments;
        if constrained {
            state.multipliers.resize(segments + 1, 0.0);
        }
        let m_eq = if constrained { segments } else { 0 };
        let step_cap = match &contact {
            Some(c) => settings.max_step.min(0.5 * c.margin),
            None => settings.max_step,
        };
        let sub = state.clone();
        let trial = state.clone();
        let hessian = QpHessian {
            pattern: &energy.pattern,
            values: vec![0.0; energy.pattern.nnz()],
            ldlt,
            wide: None,
            widened: false,
        };
        Sqp {
            energy,
            contact,
            settings,
            state,
            report: SolveReport::start(),
            n,
            h: energy.model.segment_length(),
            constrained,
            penalty: energy.penalty.unwrap_or(0.0),
            m_eq,
            step_cap,
            grad: vec![0.0; n],
            rows: Vec::new(),
            c: Vec::new(),
            jacobian: ConstraintMatrix::new(energy),
            jtc: vec![0.0; n],
            gaps: Vec::new(),
            gap_rows: Vec::new(),
            lagrangian: vec![0.0; n],
            res: Residuals::default(),
            hessian,
            shift: 0.0,
            q: vec![0.0; n],
            jtl: vec![0.0; n],
            solver: None,
            kkt: constrained.then(|| Kkt::new(energy)),
            residual_kkt: vec![0.0; n + m_eq],
            step: Vec::new(),
            lambda: Vec::new(),
            z: Vec::new(),
            forces: Vec::new(),
            exact_qp: false,
            largest: 0.0,
            mu: 0.0,
            trial_step: vec![0.0; n],
            part: vec![0.0; n],
            trial,
            sub,
        }
    }

    /// Energy Hessian, equality and contact rows, Lagrangian gradient and
    /// the residuals of the iterate (recorded in the report).
    fn linearise(&mut self, it: usize) -> Result<(), SolveError> {
        let energy = self.energy;
        let info = energy.hessian(self.state, &mut self.grad, &mut self.hessian.values);
        if self.constrained {
            energy.constraint_rows_into(self.state, &mut self.rows);
        }
        self.c.clear();
        self.c.extend(self.rows.iter().map(|r| r.0));
        self.jacobian.fill(&self.rows);
        (self.gaps, self.gap_rows) = contact_rows(energy, self.contact, self.state);
        self.lagrangian_gradient();
        let gnorm = self.lagrangian.iter().map(|x| x * x).sum::<f64>().sqrt();
        self.res.max_diag = energy.pattern.max_abs_diagonal(&self.hessian.values);
        // the floor of the Lagrangian gradient is that of ∇E: the rows'
        // rounding moves with the same coordinates
        let bound = floor_bound(&info, self.res.max_diag, self.state, self.n);
        let (floor, state) = (&mut self.res.floor, &*self.state);
        let judgement = judge(&info, gnorm, self.settings.gradient_tol, bound, || {
            floor.measure(energy, state)
        });
        (self.res.rel, self.res.at_floor) = (judgement.rel, judgement.converged);
        let h = self.h;
        self.res.infeasibility = self.c.iter().map(|x| (x / h).abs()).fold(0.0, f64::max);
        self.res.penetration = self.gaps.iter().map(|g| -g.gap).fold(0.0, f64::max);
        if !self.res.rel.is_finite() || !self.res.infeasibility.is_finite() {
            return Err(SolveError::NonFinite {
                step: "constrained gradient",
                iteration: it,
            });
        }
        self.report
            .record(it, self.res.rel.max(self.res.infeasibility), info.energy);
        Ok(())
    }

    /// Lagrangian gradient ∇E + Jᵀλ − Σ z ∇g = ∇(augmented) − ρ Jᵀc − Σ z ∇g
    /// (forces of the last QP).
    fn lagrangian_gradient(&mut self) {
        self.lagrangian.copy_from_slice(&self.grad);
        if self.constrained {
            self.jacobian.transpose_mul(&self.c, &mut self.jtc);
            let penalty = self.penalty;
            self.lagrangian
                .iter_mut()
                .zip(&self.jtc)
                .for_each(|(l, j)| *l -= penalty * j);
        }
        for (g, z) in &self.forces {
            if let Some(k) = self.gaps.iter().position(|x| same_pair(x, g)) {
                for &(d, v) in &self.gap_rows[k] {
                    self.lagrangian[d] -= z * v;
                }
            }
        }
    }

    /// The iterate is a KKT point: small residual, feasible, no penetration.
    fn converged(&self) -> bool {
        let contact_ok = self
            .contact
            .is_none_or(|m| self.res.penetration <= 1e-6 * m.diameter);
        // with contacts the KKT residual stalls near 1e-8: the closest points
        // of a rod lying along an obstacle are not smooth functions of the
        // nodes (and the interior-point duals carry that accuracy)
        let tol = if self.forces.iter().any(|f| f.1 > 0.0) {
            self.settings.gradient_tol.max(CONTACT_TOL)
        } else {
            self.settings.gradient_tol
        };
        (self.res.rel <= tol || self.res.at_floor)
            && self.res.infeasibility <= CURVATURE_TOL
            && contact_ok
    }

    /// The report of a converged solve, with its contacts.
    fn converged_report(mut self) -> SolveReport {
        self.report.converged = true;
        let gaps = &self.gaps;
        let rows: Vec<ContactForce> = self
            .forces
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
        self.report.contacts = merge_contacts(rows, 1.5 * self.h);
        self.report.contact_rows = self
            .forces
            .iter()
            .filter(|(_, z)| *z > 0.0)
            .filter_map(|(g, z)| Some((gaps.iter().find(|x| same_pair(x, g))?.clone(), *z)))
            .collect();
        self.report
    }

    /// The QP Hessian. With contacts it is that of the Lagrangian E − Σ z g
    /// (the contacts' curvature, forces from the last QP), on the energy's
    /// pattern widened by the contact couplings.
    fn assemble_hessian(&mut self) {
        let hessian = &mut self.hessian;
        hessian.widened = match self.contact {
            Some(model) if !self.gaps.is_empty() => {
                let refs: Vec<&Gap> = self.gaps.iter().collect();
                if !hessian.wide.as_ref().is_some_and(|w| w.fits(&refs)) {
                    hessian.wide = Some(ContactHessian::new(self.energy, &refs));
                }
                let forces = &self.forces;
                let z = |g: &Gap| last_force(forces, g);
                let w = hessian.wide.as_mut().expect("built above");
                w.fill(
                    self.energy,
                    &hessian.values,
                    model,
                    self.state,
                    self.gaps.iter().map(|g| (g, z(g))),
                    0.0,
                );
                true
            }
            _ => false,
        };
    }

    /// Convexify: W + shift I positive definite (and factored), the shift
    /// just beyond the lowest eigenvalue (a larger one would make a falling
    /// rod creep).
    fn convexify(&mut self, it: usize) -> Result<(), SolveError> {
        let max_diag = self.res.max_diag;
        let (pat, vals, ldlt) = self.hessian.parts();
        let mut shift = 0.0;
        loop {
            for &s in &pat.diagonal {
                vals[s] += shift;
            }
            self.report.factorizations += 1;
            if ldlt.factor(vals).is_ok() && ldlt.negative_count() == 0 {
                self.shift = shift;
                return Ok(());
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
    }

    /// The step: the QP's with its multipliers and contact forces (contact
    /// rows alone by the exact active-set iteration where it settles, else
    /// clarabel's interior point), or with nothing to constrain the
    /// (shifted) Newton step.
    fn solve_subproblem(&mut self, it: usize) -> Result<(), SolveError> {
        // QP: linear term ∇E + ρ Jᵀc = ∇(augmented) − Jᵀλ
        self.q.copy_from_slice(&self.grad);
        if self.constrained {
            self.jacobian
                .transpose_mul(&self.state.multipliers[1..], &mut self.jtl);
            self.q.iter_mut().zip(&self.jtl).for_each(|(g, j)| *g -= j);
        }
        self.exact_qp = false;
        if self.m_eq > 0 && self.gaps.is_empty() {
            // equality rows only: the QP is its KKT system, solved exactly
            self.step.clear();
            self.step.resize(self.n, 0.0);
            self.lambda.clear();
            self.lambda.resize(self.m_eq, 0.0);
            self.z.clear();
            if self.kkt_newton() {
                self.exact_qp = true;
                return Ok(());
            }
        }
        let (pat, vals, ldlt) = self.hessian.parts();
        if self.m_eq == 0 && self.gaps.is_empty() {
            self.step = self.q.iter().map(|x| -x).collect();
            ldlt.solve_in_place(&mut self.step);
            self.lambda = Vec::new();
            self.z = Vec::new();
            return Ok(());
        }
        if self.m_eq == 0 {
            // contact rows only: the exact active-set solution from the last
            // QP's forces on the same pairs (none at first), which settles in
            // a step or two once the contacts do; the interior point only
            // where it does not
            let guess: Vec<f64> = self
                .gaps
                .iter()
                .map(|g| last_force(&self.forces, g))
                .collect();
            if let Some((d, z)) =
                polish_contacts(ldlt, &self.q, &self.gap_rows, &self.gaps, &guess, None)
            {
                self.step = d;
                self.lambda = Vec::new();
                self.z = z;
                self.exact_qp = true;
                return Ok(());
            }
        }
        let (a, b) = stack_rows(
            &self.jacobian.matrix,
            &self.c,
            &self.gap_rows,
            &self.gaps,
            self.n,
        );
        if !self.gaps.is_empty() {
            // the contact rows change from step to step
            self.solver = None;
        }
        let (d, duals) = solve_qp(
            &mut self.solver,
            (pat.matrix.col_offsets(), pat.matrix.row_indices(), vals),
            &self.q,
            &a,
            &b,
            self.m_eq,
        )
        .ok_or(SolveError::NonFinite {
            step: "SQP subproblem (clarabel)",
            iteration: it,
        })?;
        let (l, z) = duals.split_at(self.m_eq);
        self.step = d;
        self.lambda = l.to_vec();
        self.z = z.to_vec();
        Ok(())
    }

    /// Polish (equality rows only): Newton on the QP's KKT conditions, unless
    /// the QP was solved exactly.
    fn polish_equality_step(&mut self) {
        if !self.exact_qp {
            self.kkt_newton();
        }
    }

    /// Equality rows only: two Newton steps on the QP's KKT conditions from
    /// the step and multipliers at hand, with the exact sparse KKT
    /// factorisation (from zero, the first solves the QP; the second
    /// refines). False if there is no KKT system or it cannot be factored.
    fn kkt_newton(&mut self) -> bool {
        let Some(kkt) = self.kkt.as_mut().filter(|_| self.gaps.is_empty()) else {
            return false;
        };
        let (pat, vals, _) = self.hessian.parts();
        kkt.assemble(vals, &self.rows);
        if kkt.ldlt.factor(&kkt.values).is_err() {
            return false;
        }
        self.report.factorizations += 1;
        let n = self.n;
        for _ in 0..2 {
            let r = &mut self.residual_kkt;
            pat.mul_vec(vals, &self.step, &mut r[..n]);
            self.jacobian.transpose_mul(&self.lambda, &mut self.jtl);
            for ((rk, qk), jk) in r[..n].iter_mut().zip(&self.q).zip(&self.jtl) {
                *rk = -(*rk + qk + jk);
            }
            self.jacobian.mul(&self.step, &mut r[n..]);
            for (rc, ck) in r[n..].iter_mut().zip(&self.c) {
                *rc = -(*rc + ck);
            }
            kkt.ldlt.solve_in_place(r);
            self.step.iter_mut().zip(&r[..n]).for_each(|(x, y)| *x += y);
            self.lambda
                .iter_mut()
                .zip(&r[n..])
                .for_each(|(x, y)| *x += y);
        }
        self.step.iter().chain(&self.lambda).all(|v| v.is_finite())
    }

    /// Polish (contacts, no equality rows): the exact QP solution by an
    /// active-set iteration from the interior point's duals.
    fn polish_contact_step(&mut self) {
        if self.m_eq != 0 || self.gaps.is_empty() || self.exact_qp {
            return;
        }
        let (pat, vals, ldlt) = self.hessian.parts();
        let Some((dp, zp)) =
            polish_contacts(ldlt, &self.q, &self.gap_rows, &self.gaps, &self.z, None)
        else {
            return;
        };
        // keep the polish unless the interior point's step is feasible
        // and better (an inexact interior point can miss the active set,
        // or stop outside the linearised constraints)
        let (q, part) = (&self.q, &mut self.part);
        let mut objective = |x: &[f64]| {
            pat.mul_vec(vals, x, part);
            0.5 * x.iter().zip(part.iter()).map(|(a, b)| a * b).sum::<f64>()
                + x.iter().zip(q).map(|(a, b)| a * b).sum::<f64>()
        };
        let (h, d) = (self.h, &self.step);
        let feasible = self
            .gaps
            .iter()
            .zip(&self.gap_rows)
            .all(|(g, r)| g.gap + r.iter().map(|&(k, v)| v * d[k]).sum::<f64>() >= -1e-9 * h);
        if !feasible || objective(&dp) <= objective(d) + 1e-12 * objective(d).abs() {
            self.step = dp;
            self.z = zp;
        }
    }

    /// The convexified QP converges only linearly; where the true Hessian
    /// is positive definite on the active contacts' tangent space, the
    /// exact SQP step (same active set, unshifted Hessian) restores
    /// Newton's quadratic convergence.
    fn exact_contact_step(&mut self) {
        if !(self.m_eq == 0 && self.shift > 0.0 && self.z.iter().any(|v| *v > 0.0)) {
            return;
        }
        self.report.factorizations += 1;
        let (pat, vals, ldlt) = self.hessian.parts();
        for &s in &pat.diagonal {
            vals[s] -= self.shift;
        }
        if ldlt.factor(vals).is_ok() {
            let k = ldlt.negative_count();
            if let Some((dp, zp)) =
                polish_contacts(ldlt, &self.q, &self.gap_rows, &self.gaps, &self.z, Some(k))
            {
                self.step = dp;
                self.z = zp;
            }
        }
    }

    /// The contact forces of this QP (for the next Lagrangian).
    fn update_forces(&mut self) {
        self.forces = self
            .gaps
            .iter()
            .cloned()
            .zip(self.z.iter().map(|v| v.max(0.0)))
            .collect();
    }

    /// Scale the step down to the step cap (on its largest translation).
    fn cap_step(&mut self) {
        let map = &self.energy.map;
        let step = &self.step;
        self.largest = (0..self.n)
            .filter(|&k| map.is_translation(k))
            .map(|k| step[k].abs())
            .fold(0.0, f64::max);
        if self.largest > self.step_cap {
            let f = self.step_cap / self.largest;
            self.step.iter_mut().for_each(|v| *v *= f);
        }
    }

    /// Armijo search on the merit: the augmented Lagrangian with the new
    /// multipliers, plus an exact penalty on the contact gaps. Returns the
    /// accepted step length (the trial state is at it).
    fn line_search(&mut self, it: usize) -> Result<f64, SolveError> {
        if self.constrained {
            self.state.multipliers[1..].copy_from_slice(&self.lambda);
        }
        self.mu = 2.0 * self.z.iter().fold(0.0f64, |a, b| a.max(*b)) + 1.0;
        let merit_info = self.energy.gradient(self.state, &mut self.grad);
        let merit0 = merit_info.energy + self.contact_penalty(self.state);
        let violation = self.mu * self.gaps.iter().map(|g| (-g.gap).max(0.0)).sum::<f64>();
        let slope: f64 = self
            .step
            .iter()
            .zip(&self.grad)
            .map(|(s, g)| s * g)
            .sum::<f64>()
            - violation;
        let failed = SolveError::LineSearch {
            iteration: it,
            residual: self.res.rel,
        };
        if slope >= 0.0 && self.res.rel > 1e3 * self.settings.gradient_tol {
            // not a descent direction (an inexact QP solution with a wrong
            // active set): say so now rather than creep
            return Err(failed);
        }
        armijo(merit0, slope, |alpha| self.merit_at(alpha)).ok_or(failed)
    }

    /// The exact penalty on the gaps of this iteration's contact pairs.
    fn contact_penalty(&self, s: &RodState) -> f64 {
        match &self.contact {
            Some(m) if !self.gaps.is_empty() => {
                let (points, _) = s.centreline();
                self.gaps
                    .iter()
                    .map(|g| (-m.gap_at(&points, g)).max(0.0))
                    .sum::<f64>()
                    * self.mu
            }
            _ => 0.0,
        }
    }

    /// The merit at `alpha` times the step (the trial state moved there), or
    /// None if the step passes through a contact.
    fn merit_at(&mut self, alpha: f64) -> Option<f64> {
        for (t, v) in self.trial_step.iter_mut().zip(&self.step) {
            *t = alpha * v;
        }
        self.state
            .displace_into(&self.energy.map, &self.trial_step, &mut self.trial);
        if self.collides(alpha) {
            return None;
        }
        Some(self.energy.energy(&self.trial) + self.contact_penalty(&self.trial))
    }

    /// Continuous collision check: no candidate pair may pass through
    /// contact along the trial step (sub-steps finer than half a diameter;
    /// pairs beyond the margin cannot close it in one step).
    fn collides(&mut self, alpha: f64) -> bool {
        let Some(m) = self.contact else {
            return false;
        };
        if self.gaps.is_empty() {
            return false;
        }
        let largest_move = alpha * self.largest.min(self.step_cap);
        let pieces = ((4.0 * largest_move / m.diameter).ceil() as usize).clamp(1, 64);
        for k in 1..=pieces {
            let f = k as f64 / pieces as f64;
            self.part
                .iter_mut()
                .zip(&self.trial_step)
                .for_each(|(p, x)| *p = f * x);
            self.state
                .displace_into(&self.energy.map, &self.part, &mut self.sub);
            let (points, _) = self.sub.centreline();
            if self
                .gaps
                .iter()
                .any(|g| m.gap_at(&points, g) < -0.5 * m.diameter)
            {
                return true;
            }
        }
        false
    }

    /// On a convexified (shifted) step near a saddle the full step can be
    /// far too short: the shift set by the unconstrained Hessian's lowest
    /// eigenvalue damps a direction that is only slightly unstable on the
    /// contacts' tangent space, and the rod would creep away. Extend the
    /// step while the merit keeps falling (up to the step cap).
    fn extend_step(&mut self, alpha: f64) {
        if !(alpha == 1.0 && self.shift > 0.0 && self.m_eq == 0) {
            return;
        }
        let room = self.step_cap / self.largest.min(self.step_cap).max(1e-300);
        let mut best = (1.0, self.merit_at(1.0).unwrap_or(f64::INFINITY));
        let mut a = 2.0;
        while a <= room.min(1024.0) {
            match self.merit_at(a) {
                Some(m) if m < best.1 => best = (a, m),
                _ => break,
            }
            a *= 2.0;
        }
        self.merit_at(best.0);
    }

    /// The trial state becomes the iterate.
    fn accept(&mut self) {
        std::mem::swap(self.state, &mut self.trial);
    }
}

/// The QP with contact rows only, solved exactly by a primal-dual active-set
/// iteration started from the forces `z` (the last QP's, or the interior
/// point's duals; P factored in `ldlt`): each trial active set is solved as equalities through the
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

/// The force of the last QP on the pair of `g` (0 if it had none).
fn last_force(forces: &[(Gap, f64)], g: &Gap) -> f64 {
    forces
        .iter()
        .find(|f| same_pair(&f.0, g))
        .map_or(0.0, |f| f.1)
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
