//! The Hessian of the Lagrangian with contacts: the energy's pattern widened
//! by the couplings of each contact (a self-contact couples distant nodes),
//! with each contact's curvature and an optional holding penalty.

use crate::linalg::sparse::{Ldlt, SymmetricPattern};
use crate::model::contact::{ContactModel, Gap, Obstacle, gap_hessian};
use crate::model::energy::RodEnergy;
use crate::model::rod::RodState;

/// A Hessian on the energy's pattern widened by contact couplings (a
/// self-contact couples distant nodes), with the contacts' terms added: the
/// Lagrangian's curvature −z ∇²g of each contact with force z, and a penalty
/// ρ ∇g ∇gᵀ (ρ > 0 holds the contacts in a stability analysis). The pattern
/// and the symbolic factorisation depend only on which node groups touch, so
/// they are kept while the contact set stays the same.
pub struct ContactHessian {
    /// The widened pattern.
    pub pattern: SymmetricPattern,
    /// Values on it.
    pub values: Vec<f64>,
    /// Its factorisation workspace.
    pub ldlt: Ldlt,
    /// The nodes of each contact stencil it was built for.
    contacts: Vec<Vec<usize>>,
    /// Slot in the widened pattern of each slot of the energy's pattern.
    energy_slots: Vec<usize>,
}

/// Nodes whose positions a contact's gap depends on.
fn contact_nodes(g: &Gap) -> Vec<usize> {
    let [i, j] = g.segments;
    if matches!(g.obstacle, Obstacle::SelfAt(_)) {
        vec![i, i + 1, j, j + 1]
    } else {
        vec![i, i + 1]
    }
}

impl ContactHessian {
    /// The widened pattern (and its symbolic factorisation) for `gaps`.
    pub fn new(energy: &RodEnergy, gaps: &[&Gap]) -> Self {
        let map = energy.map;
        let n = energy.model.segments;
        let contacts: Vec<Vec<usize>> = gaps.iter().map(|g| contact_nodes(g)).collect();
        let mut stencils: Vec<Vec<Option<usize>>> = (1..=n)
            .map(|i| map.vertex_stencil(i).to_vec())
            .chain(map.stretched_edges().map(|j| map.edge_stencil(j).to_vec()))
            .collect();
        for nodes in &contacts {
            stencils.push(nodes.iter().flat_map(|&k| node_dofs(energy, k)).collect());
        }
        let pattern = SymmetricPattern::from_stencils(map.len(), &stencils);
        let old = &energy.pattern.matrix;
        let mut energy_slots = Vec::with_capacity(old.nnz());
        for c in 0..old.ncols() {
            for &r in &old.row_indices()[old.col_offsets()[c]..old.col_offsets()[c + 1]] {
                energy_slots.push(pattern.slot(r, c).expect("widened pattern holds the old"));
            }
        }
        let ldlt = Ldlt::new(&pattern);
        ContactHessian {
            values: vec![0.0; pattern.nnz()],
            pattern,
            ldlt,
            contacts,
            energy_slots,
        }
    }

    /// Whether this pattern was built for exactly these contacts.
    pub fn fits(&self, gaps: &[&Gap]) -> bool {
        self.contacts.len() == gaps.len()
            && self
                .contacts
                .iter()
                .zip(gaps)
                .all(|(c, g)| *c == contact_nodes(g))
    }

    /// Fill with the energy Hessian `values` and the contacts' terms; the
    /// contacts `(gap, force)` are those it was built for, in order.
    pub fn fill<'g>(
        &mut self,
        energy: &RodEnergy,
        values: &[f64],
        model: &ContactModel,
        state: &RodState,
        contacts: impl Iterator<Item = (&'g Gap, f64)>,
        rho: f64,
    ) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        for (&slot, v) in self.energy_slots.iter().zip(values) {
            self.values[slot] += v;
        }
        let (points, _) = state.centreline();
        for (g, z) in contacts {
            let local: Vec<Option<usize>> = contact_nodes(g)
                .into_iter()
                .flat_map(|k| node_dofs(energy, k))
                .collect();
            let curvature = (z > 0.0).then(|| gap_hessian(&model.pair_points(&points, g)));
            let gradient: Vec<f64> = g
                .gradient
                .iter()
                .flat_map(|(_, v)| [v.x, v.y, v.z])
                .collect();
            for (a, da) in local.iter().enumerate() {
                for (b, db) in local.iter().enumerate() {
                    let (Some(da), Some(db)) = (da, db) else {
                        continue;
                    };
                    if da > db {
                        continue;
                    }
                    let mut v = 0.0;
                    if let Some(h) = &curvature {
                        v -= z * h[a][b];
                    }
                    if rho > 0.0 {
                        v += rho * gradient[a] * gradient[b];
                    }
                    let slot = self
                        .pattern
                        .slot(*da, *db)
                        .expect("contact stencil in pattern");
                    self.values[slot] += v;
                }
            }
        }
    }
}

/// The 3 translational dofs of node k (None where it is clamped).
fn node_dofs(energy: &RodEnergy, k: usize) -> [Option<usize>; 3] {
    match energy.map.node(k) {
        Some(d) => [Some(d), Some(d + 1), Some(d + 2)],
        None => [None; 3],
    }
}
