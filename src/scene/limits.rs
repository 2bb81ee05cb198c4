//! The limits a scene's values are checked against, each declared once:
//! every parameter's range (wherever its value comes from), and `[budget]`
//! with the estimate it is checked against (the estimate itself is
//! `Scene::estimate`, in budget.rs).

use crate::model::rod::Parameter;
use serde::{Deserialize, Serialize};

/// `[budget]`: the largest run the scene may start without `--allow-large`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BudgetSpec {
    /// Most memory, in GB (10⁹ bytes).
    #[serde(default = "default_memory_gb")]
    pub memory_gb: f64,
    /// Most CPU time, in hours.
    #[serde(default = "default_hours")]
    pub hours: f64,
}

impl Default for BudgetSpec {
    fn default() -> Self {
        BudgetSpec {
            memory_gb: default_memory_gb(),
            hours: default_hours(),
        }
    }
}

fn default_memory_gb() -> f64 {
    2.0
}
fn default_hours() -> f64 {
    1.0
}

/// Which command the work is for: a run follows the scene's branches or
/// loading path, a map one branch per line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Job {
    /// `knotrod run` (and `convergence`, once per N).
    Run,
    /// `knotrod map`.
    Map,
}

/// The predicted cost of a scene, with what drives it.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// Peak memory, bytes.
    pub memory_bytes: f64,
    /// What the memory is made of (settings and counts).
    pub memory_from: String,
    /// CPU time, seconds.
    pub seconds: f64,
    /// What the work is made of.
    pub work_from: String,
}

/// Seconds as the largest sensible unit.
pub fn human_time(s: f64) -> String {
    if s < 120.0 {
        format!("{s:.0} s")
    } else if s < 7200.0 {
        format!("{:.0} min", s / 60.0)
    } else if s < 2.0 * 86400.0 {
        format!("{:.1} h", s / 3600.0)
    } else {
        format!("{} days", short((s / 86400.0).round()))
    }
}

/// Most turns a clamp may be given (|φ/2π|, |start_turn_over_2pi|): a
/// thousand turns of a rod of length 1 is already far past what its N
/// segments resolve (a turn per segment at N = 1000); past it f64's angle
/// loses its turns' digits. Checked where a scene names a turn.
pub const MAX_TURNS: f64 = 1e3;

/// Largest angle in radians (tilts, their azimuths, Euler angles, the angle
/// of an axis–angle rotation): [`MAX_TURNS`] turns.
pub const MAX_ANGLE: f64 = 2.0 * std::f64::consts::PI * MAX_TURNS;

/// Largest clamp coordinate, in rod lengths (z*, δ, the shifts, the s = 0
/// clamp's position, obstacles): the reachable clamps are within a rod
/// length of each other; this bounds them where no end holds the other.
pub const MAX_POSITION: f64 = 1e3;

/// Range of the stiffness ratios K2, K3: past it the Hessian's condition
/// number exceeds what f64 resolves.
pub const STIFFNESS_RATIO: [f64; 2] = [1e-6, 1e6];

/// Largest |w L³ / B|.
pub const MAX_WEIGHT: f64 = 1e4;

/// Largest |û_i| (per rod length), of the scene's natural strains and of
/// them scaled by a varied `natural_scale`.
pub const MAX_NATURAL_STRAIN: f64 = 1e3;

/// The admissible values of a parameter, wherever they come from (the
/// scene's field, a loading target, a continuation's range, a sweep's
/// values, a map's axes); `natural_strain` is the scene's largest |û_i|,
/// which bounds `natural_scale`.
pub fn parameter_range(p: Parameter, natural_strain: f64) -> (f64, f64, &'static str) {
    use Parameter::*;
    match p {
        ZStar | Delta | EndX | EndY | StartX | StartY | StartZ => {
            (-MAX_POSITION, MAX_POSITION, "rod lengths")
        }
        Phi | StartTurn => (-MAX_TURNS, MAX_TURNS, "turns"),
        EndTilt | EndTiltAzimuth | StartTilt | StartTiltAzimuth => {
            (-MAX_ANGLE, MAX_ANGLE, "radians, a thousand turns")
        }
        K2 | K3 => (
            STIFFNESS_RATIO[0],
            STIFFNESS_RATIO[1],
            "the stiffness ratio",
        ),
        Weight => (-MAX_WEIGHT, MAX_WEIGHT, "w L³ / B"),
        NaturalScale => {
            let most = if natural_strain > 0.0 {
                (MAX_NATURAL_STRAIN / natural_strain).min(MAX_NATURAL_STRAIN)
            } else {
                MAX_NATURAL_STRAIN
            };
            (-most, most, "the scaled |û_i| at most 1e3 per rod length")
        }
    }
}

/// `v` as `{}` where that is short, else as `{:e}` (an error never prints
/// 1e308's 309 digits).
pub fn short(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e7).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}
