//! The recording's topics and its JSON messages (scalars for plots, the
//! full state for restarts), with their schemas.

use crate::analysis::class::Class;
use crate::analysis::equilibrium::Equilibrium;
use crate::io::plot::{PlotPoint, colour_of};
use crate::model::rod::{RodModel, RodState};
use serde::{Deserialize, Serialize};

/// Channel names.
pub const SCENE_TOPIC: &str = "/rod/scene";
/// Frame transform channel.
pub const TF_TOPIC: &str = "/tf";
/// Plot-friendly scalars.
pub const SCALARS_TOPIC: &str = "/rod/scalars";
/// Full state for restarts.
pub const STATE_TOPIC: &str = "/rod/state";
/// Located events.
pub const EVENTS_TOPIC: &str = "/events";

/// The scalars of one equilibrium (JSON on `/rod/scalars`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Scalars {
    /// Index of the state in the run.
    pub index: u64,
    /// Branch (or loading leg).
    pub branch: usize,
    /// Leg of the branch.
    pub leg: usize,
    /// z*.
    pub z_star: f64,
    /// δ.
    pub delta: f64,
    /// φ/2π.
    pub phi_over_2pi: f64,
    /// Elastic energy.
    pub energy: f64,
    /// Tw.
    pub twist: f64,
    /// Wr of the ray closure.
    pub writhe: f64,
    /// Tw + Wr.
    pub link: f64,
    /// |Δ(−1)|.
    pub knot_determinant: u64,
    /// The ray closure is the scene's good-knot type (absent in recordings
    /// before it was kept: read as a trefoil by determinant 3).
    #[serde(default)]
    pub knotted: Option<bool>,
    /// Lowest interior z.
    pub min_z: f64,
    /// Highest interior z.
    pub max_z: f64,
    /// Wall clearance.
    #[serde(deserialize_with = "null_as_nan")]
    pub wall_distance: f64,
    /// Minimum self-distance.
    #[serde(deserialize_with = "null_as_nan")]
    pub min_self_distance: f64,
    /// Lowest Hessian eigenvalue.
    #[serde(deserialize_with = "null_as_nan")]
    pub lowest_eigenvalue: f64,
    /// Lowest ω².
    #[serde(deserialize_with = "null_as_nan")]
    pub lowest_omega_squared: f64,
    /// Negative eigenvalues.
    pub negative_eigenvalues: usize,
    /// Stable.
    pub stable: bool,
    /// Good knot.
    pub good_knot: bool,
    /// Newton/corrector iterations.
    pub iterations: usize,
    /// Total contact force.
    pub contact_force: f64,
}

/// JSON has no NaN or infinity: serde_json writes them as null (e.g. the wall
/// clearance of a rod with no interior extremum); read null back as NaN.
fn null_as_nan<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    use serde::Deserialize;
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

impl Scalars {
    /// The scalars of an equilibrium.
    pub fn of(index: u64, e: &Equilibrium) -> Self {
        let nan_if_none = |v: Option<&f64>| v.copied().unwrap_or(f64::NAN);
        Scalars {
            index,
            branch: e.branch,
            leg: e.leg,
            z_star: e.z_star,
            delta: e.delta,
            phi_over_2pi: e.phi_over_2pi,
            energy: e.energy,
            twist: e.twist,
            writhe: e.writhe,
            link: e.link,
            knot_determinant: e.knot_determinant,
            knotted: Some(e.knotted),
            min_z: e.min_z,
            max_z: e.max_z,
            wall_distance: e.wall_distance,
            min_self_distance: e.min_self_distance,
            lowest_eigenvalue: nan_if_none(e.lowest_eigenvalues.first()),
            lowest_omega_squared: nan_if_none(e.omega_squared.first()),
            negative_eigenvalues: e.negative_eigenvalues,
            stable: e.stable,
            good_knot: e.good_knot,
            iterations: e.iterations,
            contact_force: e.contact_force,
        }
    }
}

/// The full state message (JSON on `/rod/state`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StateMessage {
    /// Index of the state in the run.
    pub index: u64,
    /// The rod model.
    pub model: RodModel,
    /// The state.
    pub state: RodState,
}

pub(super) const SCALARS_SCHEMA: &str = r#"{"title":"knotrod.Scalars","type":"object","properties":{"index":{"type":"integer"},"branch":{"type":"integer"},"leg":{"type":"integer"},"z_star":{"type":"number"},"delta":{"type":"number"},"phi_over_2pi":{"type":"number"},"energy":{"type":"number"},"twist":{"type":"number"},"writhe":{"type":"number"},"link":{"type":"number"},"knot_determinant":{"type":"integer"},"knotted":{"type":"boolean"},"min_z":{"type":"number"},"max_z":{"type":"number"},"wall_distance":{"type":"number"},"min_self_distance":{"type":"number"},"lowest_eigenvalue":{"type":"number"},"lowest_omega_squared":{"type":"number"},"negative_eigenvalues":{"type":"integer"},"stable":{"type":"boolean"},"good_knot":{"type":"boolean"},"iterations":{"type":"integer"},"contact_force":{"type":"number"}}}"#;
pub(super) const STATE_SCHEMA: &str = r#"{"title":"knotrod.RodState","type":"object","properties":{"index":{"type":"integer"},"model":{"type":"object"},"state":{"type":"object","properties":{"clamps":{"type":"object"},"nodes":{"type":"array"},"theta":{"type":"array"},"reference":{"type":"array"},"reference_twist":{"type":"array"}}}}}"#;
pub(super) const EVENT_SCHEMA: &str = r#"{"title":"knotrod.Event","type":"object","properties":{"kind":{"type":"string"},"label":{"type":"string"},"phi_over_2pi":{"type":"number"},"z_star":{"type":"number"},"delta":{"type":"number"},"twist":{"type":"number"},"branch":{"type":"integer"},"detail":{"type":"string"}}}"#;

// a recording is plotted as a summary is
impl From<&Scalars> for PlotPoint {
    fn from(e: &Scalars) -> Self {
        PlotPoint {
            phi_over_2pi: e.phi_over_2pi,
            twist: e.twist,
            stable: e.stable,
            colour: colour_of(Class::of(
                e.stable,
                e.knotted.unwrap_or(e.knot_determinant == 3),
                e.good_knot,
            )),
            omega_squared: Some(e.lowest_omega_squared).filter(|v| v.is_finite()),
            min_self_distance: e.min_self_distance,
            branch: e.branch,
            leg: e.leg,
            z_star: e.z_star,
            delta: e.delta,
        }
    }
}
