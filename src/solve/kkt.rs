//! The KKT matrix of a constrained rod, [W Jᵀ; J 0] with W the Hessian of the
//! augmented Lagrangian and J the constraint gradients (rows: vertices), on a
//! fixed sparse pattern, factorised by LDLᵀ without pivoting: each multiplier
//! is eliminated right after the last dof of its vertex stencil, so the factor
//! stays banded (O(N)) and its pivot, −J W⁻¹ Jᵀ ≈ −1/ρ, is safely nonzero.
//! The inertia gives the stability on the constraint tangent space:
//! negatives(KKT) = negatives(reduced Hessian) + number of constraints.

use crate::linalg::sparse::{Ldlt, NO_SLOT, SymmetricPattern};
use crate::model::energy::RodEnergy;

/// KKT system of one constrained rod (unknowns: free dofs, then the N
/// multipliers of vertices 1..=N).
pub struct Kkt {
    /// Pattern of dimension dofs + N.
    pub pattern: SymmetricPattern,
    /// Factorisation (multipliers interleaved in the elimination order).
    pub ldlt: Ldlt,
    /// Values on `pattern`.
    pub values: Vec<f64>,
    /// Number of free dofs.
    pub dofs: usize,
    /// Number of constraints.
    pub constraints: usize,
    /// Energy-pattern slot → KKT slot.
    energy_slots: Vec<usize>,
    /// Per constraint row, per stencil position: the KKT slot of J.
    jacobian_slots: Vec<[usize; 11]>,
}

impl Kkt {
    /// The KKT system of `energy` (whose law is constrained).
    pub fn new(energy: &RodEnergy) -> Self {
        let map = energy.map;
        let n = map.len();
        let m = energy.model.segments;
        let mut stencils: Vec<Vec<Option<usize>>> = Vec::with_capacity(2 * m);
        for i in 1..=m {
            let mut st = map.vertex_stencil(i).to_vec();
            st.push(Some(n + i - 1));
            stencils.push(st);
        }
        for j in 1..m {
            stencils.push(map.edge_stencil(j).to_vec());
        }
        let pattern = SymmetricPattern::from_stencils(n + m, &stencils);
        // elimination order: each multiplier after the last dof of its stencil
        let last: Vec<usize> = (1..=m)
            .map(|i| {
                map.vertex_stencil(i)
                    .iter()
                    .flatten()
                    .copied()
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let mut after: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (r, &d) in last.iter().enumerate() {
            after[d].push(n + r);
        }
        let mut order = Vec::with_capacity(n + m);
        for (d, extra) in after.iter().enumerate() {
            order.push(d);
            order.extend(extra);
        }
        let ldlt = Ldlt::with_order(&pattern, Some(&order));
        let ep = &energy.pattern.matrix;
        let mut energy_slots = Vec::with_capacity(ep.nnz());
        for c in 0..n {
            for &r in &ep.row_indices()[ep.col_offsets()[c]..ep.col_offsets()[c + 1]] {
                energy_slots.push(pattern.slot(r, c).expect("energy entry in the KKT pattern"));
            }
        }
        let jacobian_slots = (1..=m)
            .map(|i| {
                let mut s = [NO_SLOT; 11];
                for (a, d) in map.vertex_stencil(i).iter().enumerate() {
                    if let Some(d) = d {
                        s[a] = pattern.slot(*d, n + i - 1).expect("J entry in the pattern");
                    }
                }
                s
            })
            .collect();
        let values = vec![0.0; pattern.nnz()];
        Kkt {
            pattern,
            ldlt,
            values,
            dofs: n,
            constraints: m,
            energy_slots,
            jacobian_slots,
        }
    }

    /// Fill the values from the augmented Hessian (on the energy's pattern) and
    /// the constraint rows (value, 11-gradient on the vertex stencil).
    pub fn assemble(&mut self, hessian: &[f64], rows: &[(f64, [f64; 11])]) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        for (&s, &v) in self.energy_slots.iter().zip(hessian) {
            self.values[s] = v;
        }
        for (slots, (_, g)) in self.jacobian_slots.iter().zip(rows) {
            for (&s, &v) in slots.iter().zip(g) {
                if s != NO_SLOT {
                    self.values[s] += v;
                }
            }
        }
    }

    /// Negative eigenvalues of the Hessian reduced to the constraint tangent
    /// space, from the last factorisation's inertia.
    pub fn reduced_negative_count(&self) -> usize {
        self.ldlt.negative_count().saturating_sub(self.constraints)
    }
}
