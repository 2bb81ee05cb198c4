//! The one classifier of an equilibrium, as coloured in the paper's figures
//! (good knot, stable knotted but not good, unknotted, unstable), and the one
//! good-knot predicate every study, plot and recording uses.

use crate::geometry::knot::alexander_of;
use serde::{Deserialize, Serialize};

/// Class of an equilibrium (or of a point of a map), as coloured in the paper.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Class {
    /// A good knot ([`GoodKnot`]).
    Good,
    /// Stable and knotted, not a good knot (not walled, or touching itself).
    StableUnwalled,
    /// Stable, not the asked knot.
    Unknotted,
    /// Unstable.
    Unstable,
    /// No equilibrium of the followed branch there.
    None,
}

impl Class {
    /// The class of an equilibrium that is `stable` or not, whose ray closure
    /// is the asked knot or not, and that is a good knot or not (a good knot
    /// is a stable knot of the asked type: `good` only decides among those).
    pub fn of(stable: bool, knotted: bool, good: bool) -> Class {
        match (stable, knotted, good) {
            (false, _, _) => Class::Unstable,
            (true, false, _) => Class::Unknotted,
            (true, true, true) => Class::Good,
            (true, true, false) => Class::StableUnwalled,
        }
    }
}

/// The trefoil's Alexander polynomial 1 − t + t².
pub const TREFOIL: [i64; 3] = [1, -1, 1];

/// Whether a ray closure with this Alexander polynomial is a trefoil.
pub fn is_trefoil(alexander: &[i64]) -> bool {
    alexander == TREFOIL
}

/// What "contact-free" asks of a good knot.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Clearance {
    /// The paper's (Sec. 2.2): the centreline does not pass through itself.
    #[default]
    Centreline,
    /// The rod, a tube of its diameter h, does not touch itself: every
    /// self-distance exceeds h.
    Diameter,
}

/// The good-knot predicate: walled ∧ ray closure of the asked knot type ∧
/// stable ∧ contact-free (by [`Clearance`]).
#[derive(Clone, Debug, PartialEq)]
pub struct GoodKnot {
    /// The knot asked for, e.g. "3_1" (a tabled knot or a sum, "3_1#4_1").
    pub knot: String,
    /// Its Alexander polynomial (the ray closure must have exactly this one).
    pub alexander: Vec<i64>,
    /// How far from itself the rod must stay.
    pub clearance: Clearance,
    /// The rod's diameter h.
    pub diameter: f64,
    /// A strip's width (0: none): the self-distance the predicate is given
    /// is then its ribbon's, which [`GoodKnot::describe`] says.
    pub strip_width: f64,
}

impl GoodKnot {
    /// The predicate for the knot named `knot`; None if it is not tabled.
    pub fn new(knot: &str, clearance: Clearance, diameter: f64) -> Option<GoodKnot> {
        Some(GoodKnot {
            knot: knot.to_string(),
            alexander: alexander_of(knot)?,
            clearance,
            diameter,
            strip_width: 0.0,
        })
    }

    /// The paper's: a trefoil, the centreline clear of itself.
    pub fn paper(diameter: f64) -> GoodKnot {
        GoodKnot::new("3_1", Clearance::Centreline, diameter).expect("3_1 is tabled")
    }

    /// Whether a ray closure with this Alexander polynomial (None: it has no
    /// knot type) is the asked knot.
    pub fn is_knot(&self, alexander: Option<&[i64]>) -> bool {
        alexander == Some(self.alexander.as_slice())
    }

    /// Whether an equilibrium is a good knot.
    pub fn holds(&self, walled: bool, knotted: bool, stable: bool, self_distance: f64) -> bool {
        let clear = match self.clearance {
            Clearance::Centreline => self_distance > 0.0,
            Clearance::Diameter => self_distance > self.diameter,
        };
        walled && knotted && stable && clear
    }

    /// The definition in words, for summaries and reports.
    pub fn describe(&self) -> String {
        let clear = match (self.clearance, self.strip_width > 0.0) {
            (Clearance::Centreline, false) => {
                "the centreline clear of itself (the paper's)".to_string()
            }
            (Clearance::Centreline, true) => {
                format!("its ribbon of width {} clear of itself", self.strip_width)
            }
            (Clearance::Diameter, false) => {
                format!("no closer to itself than h = {}", self.diameter)
            }
            (Clearance::Diameter, true) => format!(
                "its ribbon of width {} no closer to itself than h = {}",
                self.strip_width, self.diameter
            ),
        };
        format!("walled, ray closure {}, stable, {clear}", self.knot)
    }
}
