//! An equilibrium along its length: arc lengths, material frames, strains,
//! internal force and moment per node, edge or vertex, for programs (the
//! Python package) that plot or post-process a solution.

use crate::model::energy::{RodEnergy, Terms, vertex_strains};
use crate::model::rod::{RodModel, RodState};

/// The fields of one state along s, as plain arrays (index k of each array
/// belongs to the k-th entry of its arc lengths).
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    /// Arc length of each node x_0..x_{N+1}: (i − ½)h (the clamp nodes lie
    /// half a segment outside [0, 1]).
    pub s_nodes: Vec<f64>,
    /// Arc length of each edge's centre, jh for j = 0..=N.
    pub s_edges: Vec<f64>,
    /// Arc length of each interior vertex 1..=N, (i − ½)h.
    pub s_vertices: Vec<f64>,
    /// Material directors (d1, d2, d3) of each edge.
    pub directors: Vec<[[f64; 3]; 3]>,
    /// Strains (u1, u2, u3) at each interior vertex.
    pub strains: Vec<[f64; 3]>,
    /// Internal force n(s) at each edge's centre, in its material frame
    /// ([`RodEnergy::internal_loads`]).
    pub force: Vec<[f64; 3]>,
    /// Internal moment m(s) at each edge's centre, in its material frame.
    pub moment: Vec<[f64; 3]>,
}

impl Profile {
    /// The profile of `state`, a state of `model` (the scene's rod model at
    /// the state's N; the state's own ends and model scalars are used).
    pub fn of(model: &RodModel, state: &RodState) -> Profile {
        let n = state.segments();
        let h = 1.0 / n as f64;
        let model = RodModel {
            segments: n,
            ..model.clone()
        };
        let energy = RodEnergy::with_ends(model, Terms::ALL, state.clamps.ends);
        let loads = energy.internal_loads(state);
        let arr = |v: nalgebra::Vector3<f64>| [v[0], v[1], v[2]];
        Profile {
            s_nodes: (0..n + 2).map(|i| (i as f64 - 0.5) * h).collect(),
            s_edges: (0..=n).map(|j| j as f64 * h).collect(),
            s_vertices: (1..=n).map(|i| (i as f64 - 0.5) * h).collect(),
            directors: (0..=n).map(|j| state.directors(j).map(arr)).collect(),
            strains: (1..=n).map(|i| vertex_strains(state, i)).collect(),
            force: loads.iter().map(|l| arr(l.force)).collect(),
            moment: loads.iter().map(|l| arr(l.moment)).collect(),
        }
    }
}
