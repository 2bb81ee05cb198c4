//! The one classifier of an equilibrium, as coloured in the paper's figures:
//! good knot, stable knotted but not good, unknotted, unstable.

use serde::{Deserialize, Serialize};

/// Class of an equilibrium (or of a point of a map), as coloured in the paper.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Class {
    /// A good knot: stable, knotted, walled (and, for `good_knot`, clear of itself).
    Good,
    /// Stable and knotted, not a good knot (not walled, or touching itself).
    StableUnwalled,
    /// Stable, not knotted.
    Unknotted,
    /// Unstable.
    Unstable,
    /// No equilibrium of the followed branch there.
    None,
}

impl Class {
    /// The class of an equilibrium that is `stable` or not, whose ray closure
    /// is a trefoil or not, and that meets the good-knot test or not (a good
    /// knot is a stable trefoil: `good` only decides among those).
    pub fn of(stable: bool, trefoil: bool, good: bool) -> Class {
        match (stable, trefoil, good) {
            (false, _, _) => Class::Unstable,
            (true, false, _) => Class::Unknotted,
            (true, true, true) => Class::Good,
            (true, true, false) => Class::StableUnwalled,
        }
    }
}

/// The knot determinant of a trefoil, |Δ(−1)| = 3.
pub const TREFOIL_DETERMINANT: u64 = 3;

/// Whether a ray closure with this knot determinant is a trefoil.
pub fn is_trefoil(knot_determinant: u64) -> bool {
    knot_determinant == TREFOIL_DETERMINANT
}

/// The summaries' good knot: walled, an unambiguous trefoil, stable, and no
/// closer to itself than the rod's diameter. (The maps' boundaries are the
/// paper's curves: walled, trefoil and stable, the self-distance not asked.)
pub fn good_knot(
    walled: bool,
    trefoil: bool,
    ambiguous: bool,
    stable: bool,
    self_distance: f64,
    diameter: f64,
) -> bool {
    walled && trefoil && !ambiguous && stable && self_distance > diameter
}
