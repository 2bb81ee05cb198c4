//! `[map]` and `[map.slices]`: the parameter-space map of a scene.

use crate::model::rod::Parameter;
use serde::{Deserialize, Serialize};

/// The map settings of a scene: `[map]`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapSpec {
    /// The swept parameter (default z_star); each line is a branch in the
    /// `[continuation]`'s parameter at one value of it.
    #[serde(default = "default_sweep")]
    pub parameter: Parameter,
    /// Its values, evenly spaced from range[0] to range[1].
    #[serde(deserialize_with = "crate::scene::exact::array")]
    pub range: [f64; 2],
    /// Number of lines.
    pub lines: usize,
    /// Columns of the classified grid.
    #[serde(default = "default_columns")]
    pub grid_columns: usize,
    /// A known good knot (map parameter, continuation parameter; φ as φ/2π)
    /// the boundary walk starts from,
    /// reached from the scene's start in a straight line (default: the start).
    #[serde(default, deserialize_with = "crate::scene::exact::option")]
    pub trace_from: Option<[f64; 2]>,
    /// Largest step of the boundary walk in the (map parameter, continuation
    /// parameter) plane.
    #[serde(default = "default_trace_step")]
    pub trace_step: f64,
    /// Polish the traced boundary on the continuum (its points, corners and
    /// area, with error estimates).
    #[serde(default)]
    pub polish: bool,
    /// A 3D map: one such map per value of a third parameter.
    #[serde(default)]
    pub slices: Option<SliceSpec>,
}

/// `[map.slices]`: the slices of a 3D map (e.g. δ for Figure 9).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SliceSpec {
    /// The slicing parameter (default delta).
    #[serde(default = "default_slicing")]
    pub parameter: Parameter,
    /// Its values, increasing.
    pub values: Vec<f64>,
    /// φ/2π of each slice's starting equilibrium (default: the scene's).
    #[serde(default)]
    pub start_phi_over_2pi: Option<Vec<f64>>,
    /// Each slice's good knot to start the boundary walk from (`map.trace_from`).
    #[serde(default, deserialize_with = "crate::scene::exact::option_list")]
    pub trace_from: Option<Vec<[f64; 2]>>,
}

fn default_slicing() -> Parameter {
    Parameter::Delta
}

fn default_sweep() -> Parameter {
    Parameter::ZStar
}
fn default_trace_step() -> f64 {
    0.005
}
fn default_columns() -> usize {
    101
}

impl MapSpec {
    /// Value of line k.
    pub fn value(&self, k: usize) -> f64 {
        if self.lines == 1 {
            return self.range[0];
        }
        self.range[0] + (self.range[1] - self.range[0]) * k as f64 / (self.lines - 1) as f64
    }
}
