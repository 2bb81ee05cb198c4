//! The Hessian's quadratic form evaluated stencil by stencil in each
//! stencil's own variables (edge vectors and angles), never through the
//! assembled matrix.
//!
//! A stiff rod's assembled Hessian carries node entries of size S/h
//! (stretching) and 1/h³ (bending) whose sum over a smooth mode cancels to
//! O(1): rounding each entry, and each sum of stencils into one slot, leaves
//! an error of ε S/h² in vᵀHv for a mode of unit mass norm, 1.5e-4 of the
//! lowest ω² at S = 1e8, N = 1600. Differences of the mode's nodes are formed
//! first here, as the stencils see them, so the form keeps the digits of the
//! mode's own (bending) energy (docs/validation.md, "Stiff rods").

use crate::model::energy::RodEnergy;
use crate::model::rod::{DofMap, RodState};

/// Displacement of node `i` in the free-dof vector `z`: its own dofs, minus
/// those of the node a pinned end's ghost is placed from (x_g = 2p − x), or
/// zero at a clamp.
fn node_displacement(map: &DofMap, i: usize, z: &[f64]) -> [f64; 3] {
    let from = |d: usize, sign: f64| [sign * z[d], sign * z[d + 1], sign * z[d + 2]];
    match (map.node(i), map.dependent(i).and_then(|k| map.node(k))) {
        (Some(d), _) => from(d, 1.0),
        (None, Some(d)) => from(d, -1.0),
        (None, None) => [0.0; 3],
    }
}

/// Difference b − a of two node displacements (an edge vector's change).
fn difference(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [b[0] - a[0], b[1] - a[1], b[2] - a[2]]
}

/// Add wᵀ K w' for every pair of the local vectors `local` (row-major k×k).
fn add_pairs<const M: usize>(gram: &mut [f64], local: &[[f64; M]], k_mat: &[[f64; M]; M]) {
    let k = local.len();
    for p in 0..k {
        let kp: [f64; M] = std::array::from_fn(|b| (0..M).map(|a| local[p][a] * k_mat[a][b]).sum());
        for q in p..k {
            let v: f64 = (0..M).map(|b| kp[b] * local[q][b]).sum();
            gram[p * k + q] += v;
            if q != p {
                gram[q * k + p] += v;
            }
        }
    }
}

impl RodEnergy {
    /// The Gram matrix zₚᵀ H zₒ (row-major k×k) of the Hessian at `state`
    /// over the free-dof vectors `vectors`, summed stencil by stencil in the
    /// stencils' own variables: the digits of a soft mode's energy survive
    /// a stiff stretching (see the module's note). O(N k²).
    pub fn hessian_gram(&self, state: &RodState, vectors: &[Vec<f64>]) -> Vec<f64> {
        let k = vectors.len();
        let map = self.map;
        let model = self.model_at(state);
        let mut gram = vec![0.0; k * k];
        let mut local8 = vec![[0.0; 8]; k];
        if self.terms.bending || self.terms.twisting {
            for i in 1..=map.n {
                let (_, _, h8) = self.vertex_hessian8(state, i, &model);
                for (v, z) in local8.iter_mut().zip(vectors) {
                    let [a, b, c] = [i - 1, i, i + 1].map(|n| node_displacement(&map, n, z));
                    let angle = |j: usize| map.theta(j).map_or(0.0, |d| z[d]);
                    let (e0, e1) = (difference(a, b), difference(b, c));
                    *v = [
                        e0[0],
                        e0[1],
                        e0[2],
                        e1[0],
                        e1[1],
                        e1[2],
                        angle(i - 1),
                        angle(i),
                    ];
                }
                add_pairs(&mut gram, &local8, &h8);
            }
        }
        if self.terms.stretching {
            let mut local3 = vec![[0.0; 3]; k];
            for j in map.stretched_edges() {
                // the edge's 6×6 node block is ±(its 3×3 edge-vector block)
                let (_, _, h) = self.edge_local(state, j);
                let h3: [[f64; 3]; 3] =
                    std::array::from_fn(|a| std::array::from_fn(|b| h[a * 6 + b]));
                for (v, z) in local3.iter_mut().zip(vectors) {
                    *v = difference(
                        node_displacement(&map, j, z),
                        node_displacement(&map, j + 1, z),
                    );
                }
                add_pairs(&mut gram, &local3, &h3);
            }
        }
        gram
    }
}
