//! The scene as plain data: model, clamps, initial shape, solver settings,
//! continuation, loading, map (`map.rs`), contact, outputs; validated section
//! by section (`validate.rs`), errors naming the field. Files are read in
//! `io::scene_file`.

mod budget;
pub(crate) mod exact;
mod limits;
mod map;
mod validate;

pub use limits::{
    BudgetSpec, Estimate, Job, MAX_ANGLE, MAX_NATURAL_STRAIN, MAX_POSITION, MAX_TURNS, MAX_WEIGHT,
    STIFFNESS_RATIO, human_time, parameter_range, short,
};
pub use map::{MapSpec, SliceSpec};

use crate::analysis::class::{Clearance, GoodKnot};
use crate::analysis::equilibrium::Measure;
use crate::model::contact::ContactModel;
use crate::model::natural::NaturalStrains;
use crate::model::rod::{
    Clamps, EndKind, Law, ModelScalars, Orientation, Parameter, RodModel, RodState, StartClamp,
};
use crate::solve::continuation::ContinuationSettings;
use crate::solve::outcome::SolverSettings;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A scene as written in TOML.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Short name (defaults to the file stem).
    #[serde(default)]
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// Rod model.
    pub model: ModelSpec,
    /// Clamp parameters.
    pub clamps: ClampSpec,
    /// Initial shape.
    #[serde(default)]
    pub initial: InitialSpec,
    /// Newton settings.
    #[serde(default)]
    pub solver: SolverSettings,
    /// Stability settings.
    #[serde(default)]
    pub stability: StabilitySpec,
    /// Continuation of the equilibrium in one parameter (a branch).
    #[serde(default)]
    pub continuation: Option<ContinuationSpec>,
    /// Repeat the continuation at several values of another parameter, each
    /// reached by continuation from the previous one.
    #[serde(default)]
    pub sweep: Option<SweepSpec>,
    /// Quasi-static loading: the clamp moved in steps, each followed by energy
    /// minimisation from the previous equilibrium (jumps detected).
    #[serde(default)]
    pub loading: Vec<LoadingSpec>,
    /// Parameter-space map (with `knotrod map`).
    #[serde(default)]
    pub map: Option<MapSpec>,
    /// Knot diagnostics settings.
    #[serde(default)]
    pub diagnostics: DiagnosticsSpec,
    /// `[contact]`: contact with the rays, obstacles and the rod itself.
    #[serde(default)]
    pub contact: Option<ContactSpec>,
    /// Published values to compare with (printed beside ours, never copied).
    #[serde(default)]
    pub reference: Option<ReferenceSpec>,
    /// Outputs.
    #[serde(default)]
    pub output: OutputSpec,
    /// `[load]`: the rod's weight.
    #[serde(default)]
    pub load: LoadSpec,
    /// `[budget]`: the largest predicted run started without `--allow-large`.
    #[serde(default)]
    pub budget: BudgetSpec,
}

/// `[model]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// Model kind: "kirchhoff" (default), "unbendable" or "strip".
    #[serde(default)]
    pub kind: ModelKind,
    /// B22/B11.
    #[serde(rename = "K2", default = "default_k")]
    pub k2: f64,
    /// B33/B11.
    #[serde(rename = "K3", default = "default_k")]
    pub k3: f64,
    /// Number of segments N.
    #[serde(default = "default_segments")]
    pub segments: i64,
    /// Strip law only: regularisation ε of 1/2 (u1² + u3²)² / (u1² + ε²), a
    /// curvature in units of 1/L.
    #[serde(default = "default_strip_regularisation")]
    pub strip_regularisation: f64,
    /// Rod diameter h (sets the default stretching stiffness 16/h²).
    #[serde(default = "default_diameter")]
    pub rod_diameter: f64,
    /// Stretching stiffness EA L²/B11 (overrides the one from the diameter).
    #[serde(default)]
    pub stretching_stiffness: Option<f64>,
    /// Natural strains (û1, û2, û3) in units of 1/L: constant along the rod,
    /// or a table of rows [s, û1, û2, û3] linearly interpolated in s (û2 = 0
    /// for the unbendable law, û2 = û3 = 0 for the strip), or
    /// `{ end_deflection = d }`: a plastified rod's uniform û1 whose
    /// stress-free arc, held at one end, ends d·L off its tangent.
    #[serde(default, deserialize_with = "exact::natural")]
    pub natural_strains: NaturalStrains,
    /// Strips only: width w/L of the ribbon along d1 on which the
    /// self-distance, crossings and walls are measured (0: the centreline).
    #[serde(default)]
    pub strip_width: f64,
}

fn default_strip_regularisation() -> f64 {
    STRIP_REGULARISATION
}

/// Default ε of the strip law: far below the curvatures of the paper's knots
/// (|u1| ~ 5–30), so it only matters at inflections of a twisted strip.
pub const STRIP_REGULARISATION: f64 = 0.05;

/// Kinds of rod model.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum ModelKind {
    /// The Kirchhoff rod (bending, twisting, stretching).
    #[default]
    Kirchhoff,
    /// Kirchhoff with u2 = 0 enforced (K2 → ∞).
    Unbendable,
    /// The Sadowsky elastic strip, u2 = 0 enforced.
    Strip,
}

impl ModelKind {
    /// The name used in scene files and summaries.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Kirchhoff => "kirchhoff",
            ModelKind::Unbendable => "unbendable",
            ModelKind::Strip => "strip",
        }
    }
}
fn default_k() -> f64 {
    3.0
}
fn default_segments() -> i64 {
    200
}
fn default_diameter() -> f64 {
    1.0 / 200.0
}

/// `[clamps]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClampSpec {
    /// End displacement z*.
    pub z_star: f64,
    /// End shift δ (≥ 0).
    #[serde(default)]
    pub delta: f64,
    /// End rotation φ/2π (continuous: 1.3 is one turn more than 0.3).
    #[serde(default)]
    pub phi_over_2pi: f64,
    /// Shift (x, y) of the s = 1 clamp's point, added to (−δ cos φ/2, −δ sin φ/2).
    #[serde(default, deserialize_with = "exact::option")]
    pub end_shift: Option<[f64; 2]>,
    /// Rotation of the s = 1 clamp before its tilt and its turn φ.
    #[serde(default)]
    pub end_rotation: Option<RotationSpec>,
    /// Tilt of the s = 1 clamp's tangent (radians) towards the azimuth
    /// `end_tilt_azimuth` (radians about e3).
    #[serde(default)]
    pub end_tilt: f64,
    /// Azimuth of the s = 1 tilt.
    #[serde(default)]
    pub end_tilt_azimuth: f64,
    /// The s = 0 clamp (default: the identity frame at the origin).
    #[serde(default)]
    pub start: Option<StartClampSpec>,
    /// Boundary condition at s = 1: "clamped" (default), "pinned" (the
    /// point r* fixed, the frame free: a ball joint) or "free" (z*, δ, φ and
    /// the end's placement then unused).
    #[serde(default, skip_serializing_if = "EndKind::is_clamped")]
    pub end: EndKind,
}

/// `[clamps.start]`: the s = 0 clamp's frame.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StartClampSpec {
    /// Position r(0).
    #[serde(deserialize_with = "exact::array")]
    pub position: [f64; 3],
    /// Rotation before the tilt and the turn.
    pub rotation: Option<RotationSpec>,
    /// Tilt of the tangent (radians).
    pub tilt: f64,
    /// Azimuth of the tilt (radians about e3).
    pub tilt_azimuth: f64,
    /// Turn of the material frame about the tangent, in turns.
    pub turn_over_2pi: f64,
    /// Boundary condition at s = 0: "clamped" (default), "pinned" or "free".
    #[serde(skip_serializing_if = "EndKind::is_clamped")]
    pub kind: EndKind,
}

/// A clamp's rotation: a unit quaternion (w, x, y, z), an axis and an angle
/// (ax, ay, az, radians), or Euler angles (a, b, c) of R = Rz(a) Ry(b) Rx(c)
/// (intrinsic z–y′–x″, radians). It takes e3 to the clamp's tangent and e1 to
/// its reference director.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum RotationSpec {
    /// (w, x, y, z), of norm 1 within 1e-9.
    Quaternion(#[serde(deserialize_with = "exact::array")] [f64; 4]),
    /// (ax, ay, az, angle): a nonzero axis and an angle in radians.
    AxisAngle(#[serde(deserialize_with = "exact::array")] [f64; 4]),
    /// (a, b, c) in radians: R = Rz(a) Ry(b) Rx(c).
    EulerZyx(#[serde(deserialize_with = "exact::array")] [f64; 3]),
}

impl RotationSpec {
    /// The rotation, or why it is not one.
    pub fn quaternion(&self) -> Result<nalgebra::UnitQuaternion<f64>, String> {
        use nalgebra::{Quaternion, Unit, UnitQuaternion, Vector3};
        let all_finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        match *self {
            RotationSpec::Quaternion(q) => {
                if !all_finite(&q) {
                    return Err("quaternion components must be finite".into());
                }
                // its norm measured without overflow: 1e300 components are
                // refused, not taken for a quaternion of norm inf
                let norm = scaled_norm(&q);
                if (norm - 1.0).abs() > 1e-9 {
                    return Err(format!(
                        "a quaternion of norm {} is not a rotation (norm 1 within 1e-9)",
                        short(norm)
                    ));
                }
                let q = Quaternion::new(q[0], q[1], q[2], q[3]);
                Ok(UnitQuaternion::new_normalize(q))
            }
            RotationSpec::AxisAngle(a) => {
                if !all_finite(&a) {
                    return Err("axis and angle must be finite".into());
                }
                let axis =
                    unit_vector([a[0], a[1], a[2]]).map_err(|why| format!("the axis {why}"))?;
                angle("the angle", a[3])?;
                Ok(UnitQuaternion::from_axis_angle(
                    &Unit::new_unchecked(Vector3::from(axis)),
                    a[3],
                ))
            }
            RotationSpec::EulerZyx([a, b, c]) => {
                if !all_finite(&[a, b, c]) {
                    return Err("Euler angles must be finite".into());
                }
                for v in [a, b, c] {
                    angle("each Euler angle", v)?;
                }
                Ok(UnitQuaternion::from_euler_angles(c, b, a))
            }
        }
    }
}

/// An angle in radians within [`MAX_ANGLE`], or why not.
fn angle(what: &str, v: f64) -> Result<(), String> {
    if v.abs() <= MAX_ANGLE {
        Ok(())
    } else {
        Err(format!(
            "{what} must be within ±{} radians ({MAX_TURNS} turns), got {}",
            short(MAX_ANGLE),
            short(v)
        ))
    }
}

/// The largest |component| of `v`.
fn largest(v: &[f64]) -> f64 {
    v.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
}

/// The Euclidean norm of `v`, taken of `v` scaled by its largest component
/// so that no square overflows or underflows (inf only past f64's range).
fn scaled_norm(v: &[f64]) -> f64 {
    let m = largest(v);
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    m * v.iter().map(|x| (x / m) * (x / m)).sum::<f64>().sqrt()
}

/// `v` as a unit vector: a direction from input, scaled by its largest
/// component before its norm is taken, so that neither 1e300 components
/// overflow the norm nor 1e-300 ones underflow it; or why it is no direction
/// (zero, not finite, or subnormal: a largest component below 2.2e-308
/// holds too few digits to say where it points).
pub(crate) fn unit_vector<const N: usize>(v: [f64; N]) -> Result<[f64; N], &'static str> {
    if v.iter().any(|x| !x.is_finite()) {
        return Err("must be finite");
    }
    let m = largest(&v);
    if m == 0.0 {
        return Err("must be a non-zero vector");
    }
    if m < f64::MIN_POSITIVE {
        return Err(
            "is subnormal (every component below 2.2e-308): too small to give a \
                    direction to f64's precision; scale it up",
        );
    }
    let scaled = v.map(|x| x / m);
    let norm = scaled_norm(&scaled);
    Ok(scaled.map(|x| x / norm))
}

impl ClampSpec {
    /// Set a clamp parameter (φ and turns in turns, tilts in radians).
    pub fn set(&mut self, p: Parameter, v: f64) {
        let start = || StartClampSpec::default();
        match p {
            Parameter::ZStar => self.z_star = v,
            Parameter::Delta => self.delta = v,
            Parameter::Phi => self.phi_over_2pi = v,
            Parameter::EndX => self.end_shift.get_or_insert([0.0; 2])[0] = v,
            Parameter::EndY => self.end_shift.get_or_insert([0.0; 2])[1] = v,
            Parameter::EndTilt => self.end_tilt = v,
            Parameter::EndTiltAzimuth => self.end_tilt_azimuth = v,
            Parameter::StartX => self.start.get_or_insert_with(start).position[0] = v,
            Parameter::StartY => self.start.get_or_insert_with(start).position[1] = v,
            Parameter::StartZ => self.start.get_or_insert_with(start).position[2] = v,
            Parameter::StartTilt => self.start.get_or_insert_with(start).tilt = v,
            Parameter::StartTiltAzimuth => self.start.get_or_insert_with(start).tilt_azimuth = v,
            Parameter::StartTurn => self.start.get_or_insert_with(start).turn_over_2pi = v,
            // the model's scalars are the model's (`Scene::set`)
            Parameter::K2 | Parameter::K3 | Parameter::Weight | Parameter::NaturalScale => {}
        }
    }
}

/// `[initial]`
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// "straight" (default), "shooting", "file" or "double_ring".
    #[serde(default)]
    pub shape: InitialShape,
    /// Shooting data: n(0) in the material frame.
    #[serde(default, deserialize_with = "exact::option")]
    pub n0: Option<[f64; 3]>,
    /// Shooting data: m(0) in the material frame.
    #[serde(default, deserialize_with = "exact::option")]
    pub m0: Option<[f64; 3]>,
    /// Strip shooting data: u1(0), the curvature at s = 0 (the paper's
    /// unknowns for strips are n(0), u1(0), m2(0), u3(0)).
    #[serde(default)]
    pub u1_0: Option<f64>,
    /// Strip shooting data: m2(0), the moment about d2 (the multiplier of u2 = 0).
    #[serde(default)]
    pub m2_0: Option<f64>,
    /// Strip shooting data: u3(0), the twist rate at s = 0.
    #[serde(default)]
    pub u3_0: Option<f64>,
    /// Refine the shooting data by Newton on the s = 1 boundary conditions first.
    #[serde(default)]
    pub refine: bool,
    /// For "shooting", the intervals the integrated solution (adaptive, to
    /// 1e-12) is sampled at for the start (default 20 000); for "double_ring", the
    /// quasi-static steps that unfold it to the scene's clamps (default 40).
    #[serde(default)]
    pub steps: Option<i64>,
    /// A previous run's JSON summary.
    #[serde(default)]
    pub file: Option<PathBuf>,
    /// Which equilibrium of that file.
    #[serde(default)]
    pub index: usize,
    /// Start from a recorded state (MCAP written by `knotrod run`), `index`
    /// selecting which (its model's N must match `model.segments`).
    #[serde(default)]
    pub from_recording: Option<PathBuf>,
    /// Straight shape: add a clamped-clamped bump b (1 − cos 2πs)/2 to seed
    /// buckling (b in the lab frame).
    #[serde(default, deserialize_with = "exact::option")]
    pub bump: Option<[f64; 3]>,
    /// Trefoil: the integer part of the link (Tw + Wr of the ray closure,
    /// less φ/2π) to give it; default 3, the paper's configuration A.
    #[serde(default)]
    pub link: Option<i64>,
    /// The restart state of `file` or `from_recording`, read with the scene
    /// (`Scene::load`); not part of the scene's text.
    #[serde(skip)]
    pub state: Option<RodState>,
}

/// Kinds of initial shape.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum InitialShape {
    /// Straight from clamp to clamp, uniformly twisted by φ.
    #[default]
    Straight,
    /// Integrate (A.2) from n(0), m(0).
    Shooting,
    /// A state from a previous run's JSON summary.
    File,
    /// The doubly covered ring (z* = δ = 0, φ = 2π; paper Sec. 6), with the
    /// clamps of the scene.
    #[serde(rename = "double_ring")]
    DoubleRing,
    /// An open trefoil tied around the rays (1.5 turns around the upper ray),
    /// uniformly twisted so that the ray closure's link is `initial.link`.
    Trefoil,
}

/// `[stability]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StabilitySpec {
    /// How many lowest eigenvalues to compute (0: inertia only).
    pub eigenvalues: i64,
}

impl Default for StabilitySpec {
    fn default() -> Self {
        StabilitySpec { eigenvalues: 4 }
    }
}

/// `[continuation]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContinuationSpec {
    /// "phi" (as φ/2π), "z_star" or "delta".
    pub parameter: Parameter,
    /// Stop when the parameter leaves [lo, hi].
    #[serde(deserialize_with = "exact::array")]
    pub range: [f64; 2],
    /// "up", "down" or "both" from the start.
    #[serde(default)]
    pub direction: Direction,
    /// Locate folds, stability changes, branch points, walls, crossings.
    #[serde(default = "yes")]
    pub locate_events: bool,
    /// Follow the branches bifurcating at branch points.
    #[serde(default)]
    pub switch_branches: bool,
    /// Initial arclength step.
    #[serde(default)]
    pub step: Option<f64>,
    /// Largest arclength step.
    #[serde(default)]
    pub max_step: Option<f64>,
    /// Most points per direction.
    #[serde(default)]
    pub max_points: Option<i64>,
    /// Stop following a direction at the first event of one of these kinds
    /// (e.g. ["fold"]: from the start to the first fold).
    #[serde(default)]
    pub stop_at: Vec<crate::analysis::event::EventKind>,
    /// Locate every event again on the continuum branch (shooting with an
    /// adaptive eighth-order integrator) and report both answers.
    #[serde(default)]
    pub polish: bool,
}

impl ContinuationSpec {
    /// The numerical continuation settings this spec asks for.
    pub fn settings(&self) -> ContinuationSettings {
        let defaults = ContinuationSettings::default();
        ContinuationSettings {
            step: self.step.unwrap_or(defaults.step),
            max_step: self.max_step.unwrap_or(defaults.max_step),
            max_points: self.max_points.map_or(defaults.max_points, |m| m as usize),
            ..defaults
        }
    }
}

fn yes() -> bool {
    true
}

/// Direction of a continuation from its start.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Increasing parameter.
    Up,
    /// Decreasing parameter.
    Down,
    /// Both, one after the other.
    #[default]
    Both,
}

/// `[[loading]]`: one leg of a loading path.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadingSpec {
    /// Target end displacement (unchanged if absent).
    #[serde(default)]
    pub z_star: Option<f64>,
    /// Target end shift.
    #[serde(default)]
    pub delta: Option<f64>,
    /// Target end rotation φ/2π (continuous).
    #[serde(default)]
    pub phi_over_2pi: Option<f64>,
    /// Targets of any other clamp parameter (`targets = { end_tilt = 0.3 }`;
    /// tilts in radians, turns in turns), unchanged if absent.
    #[serde(default)]
    pub targets: std::collections::BTreeMap<Parameter, f64>,
    /// Number of equal steps.
    pub steps: i64,
    /// Newton iterations each step may take in all, the location of a jump,
    /// a wall or a lost contact on it included (default
    /// [`LoadingSpec::DEFAULT_STEP_BUDGET`] × `solver.max_iterations`).
    #[serde(default)]
    pub step_iterations: Option<i64>,
}

impl LoadingSpec {
    /// Default budget of a step, in `solver.max_iterations`: the jump of
    /// scenes/loading_hysteresis.toml (located by some 27 bisections, then
    /// the landing) takes 3000–5000 iterations in all, the other shipped
    /// paths' steps fewer; 50 000 at the default 1000 is ten times that, and
    /// still stops a path that cannot settle.
    pub const DEFAULT_STEP_BUDGET: usize = 50;

    /// The Newton iterations each step of this leg may take in all.
    pub fn step_budget(&self, settings: &SolverSettings) -> usize {
        self.step_iterations.map_or_else(
            || Self::DEFAULT_STEP_BUDGET.saturating_mul(settings.max_iterations),
            |n| n as usize,
        )
    }
}

/// `[sweep]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// The swept parameter.
    pub parameter: Parameter,
    /// Its values, in order (each reached by continuation from the previous).
    pub values: Vec<f64>,
}

/// `[diagnostics]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DiagnosticsSpec {
    /// Self-distance ignores pairs of points closer than this along the rod.
    pub self_distance_gap: f64,
    /// Length of the rays closing the curve for the writhe (its error ∝ 1/length).
    pub ray_length: f64,
    /// The knot a good knot's ray closure must be: a tabled knot ("3_1",
    /// "4_1", … up to 10 crossings) or a sum of them ("3_1#3_1").
    pub knot: String,
    /// What "contact-free" asks of a good knot: "centreline" (the paper's:
    /// the centreline does not pass through itself) or "diameter" (every
    /// self-distance above the rod's diameter).
    pub clearance: Clearance,
}

impl Default for DiagnosticsSpec {
    fn default() -> Self {
        DiagnosticsSpec {
            self_distance_gap: 0.05,
            ray_length: 1e6,
            knot: "3_1".into(),
            clearance: Clearance::Centreline,
        }
    }
}

/// `[contact]`: the rod as a tube of diameter `model.rod_diameter` that
/// cannot pass through the clamps' rays, fixed obstacles or itself.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactSpec {
    /// Contact with the two rays continuing the clamps along e3.
    pub rays: bool,
    /// Self-contact (parts at least `diagnostics.self_distance_gap` apart).
    pub self_contact: bool,
    /// Fixed segment obstacles [x0, y0, z0, x1, y1, z1] (radius h/2).
    #[serde(default, deserialize_with = "exact::list")]
    pub obstacles: Vec<[f64; 6]>,
    /// Pairs closer than h + margin become constraints; no node moves more
    /// than margin/2 per step, so none can pass through another.
    pub margin: f64,
}

impl Default for ContactSpec {
    fn default() -> Self {
        ContactSpec {
            rays: true,
            self_contact: true,
            obstacles: Vec::new(),
            margin: 0.02,
        }
    }
}

/// `[load]`: the rod's weight per unit length, w L³ / B11 (for strips
/// w L³ / B), acting along `direction`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// w L³ / B11 (0: no weight).
    #[serde(default)]
    pub weight: f64,
    /// The direction of gravity (normalised; default −e3).
    #[serde(default = "default_gravity", deserialize_with = "exact::array")]
    pub direction: [f64; 3],
    /// Gravity across the clamps' axis, along or against the direction of
    /// the knot's major loop in the weightless start (the lab's strips
    /// facing "down" or "up", paper Sec. 5), fixed from then on: replaces
    /// `direction` once the start is known (`study::start::in_the_lab`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub major_loop: Option<LoopFacing>,
}

/// Which way a knot's major loop points in the lab.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum LoopFacing {
    /// The major loop points downwards: gravity along its direction (the
    /// paper's photographed knot).
    Down,
    /// The major loop points upwards: gravity against its direction.
    Up,
}

impl LoopFacing {
    /// The name used in scenes.
    pub fn name(self) -> &'static str {
        match self {
            LoopFacing::Down => "down",
            LoopFacing::Up => "up",
        }
    }
}

impl Default for LoadSpec {
    fn default() -> Self {
        LoadSpec {
            weight: 0.0,
            direction: default_gravity(),
            major_loop: None,
        }
    }
}

fn default_gravity() -> [f64; 3] {
    [0.0, 0.0, -1.0]
}

impl LoadSpec {
    /// The body force per unit length, w g.
    pub fn weight_vector(&self) -> [f64; 3] {
        if self.weight == 0.0 {
            return [0.0; 3];
        }
        // validation refused a direction that is none where the weight is not 0
        self.unit_direction().map(|d| self.weight * d)
    }

    /// The direction of gravity as a unit vector (−e3 where it is none:
    /// validation refuses that wherever the weight can be non-zero).
    pub fn unit_direction(&self) -> [f64; 3] {
        unit_vector(self.direction).unwrap_or([0.0, 0.0, -1.0])
    }
}

/// `[reference]`: published values for comparison.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// Source, e.g. "paper Appendix D".
    #[serde(default)]
    pub source: Option<String>,
    /// n(0).
    #[serde(default, deserialize_with = "exact::option")]
    pub n0: Option<[f64; 3]>,
    /// m(0).
    #[serde(default, deserialize_with = "exact::option")]
    pub m0: Option<[f64; 3]>,
    /// Tw.
    #[serde(default)]
    pub twist: Option<f64>,
    /// Link Tw + Wp*.
    #[serde(default)]
    pub link: Option<f64>,
    /// Knot determinant.
    #[serde(default)]
    pub knot_determinant: Option<u64>,
    /// Walled or not.
    #[serde(default)]
    pub walled: Option<bool>,
    /// Stable or not.
    #[serde(default)]
    pub stable: Option<bool>,
}

/// `[output]`
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Where to write the JSON summary (the command line `--json` wins).
    #[serde(default)]
    pub json: Option<PathBuf>,
}

/// A scene that could not be used.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("cannot read scene {path}")]
    Io {
        /// Path.
        path: PathBuf,
        /// Cause.
        #[source]
        source: std::io::Error,
    },
    /// TOML syntax or an unknown/mistyped field.
    #[error("scene {path}: {message}")]
    Parse {
        /// Path.
        path: PathBuf,
        /// The parser's message (names the field and line).
        message: String,
    },
    /// A value out of its admissible range.
    #[error("scene field `{field}`: {reason}")]
    Invalid {
        /// Dotted field name.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// The predicted work or memory exceeds the scene's budget.
    #[error(
        "this scene would need about {estimate} of {what} ({drivers}), over the budget of \
         {limit}: pass --allow-large to run it anyway, or raise `{key}` in the scene"
    )]
    TooLarge {
        /// "memory" or "CPU time".
        what: &'static str,
        /// The estimate, with its unit.
        estimate: String,
        /// The settings and counts it comes from.
        drivers: String,
        /// The limit, with its unit.
        limit: String,
        /// The scene key that raises the limit.
        key: &'static str,
    },
}

pub(crate) fn invalid(field: &'static str, reason: impl Into<String>) -> SceneError {
    SceneError::Invalid {
        field,
        reason: reason.into(),
    }
}

pub(crate) fn finite(field: &'static str, v: f64) -> Result<f64, SceneError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(invalid(field, format!("must be a finite number, got {v}")))
    }
}

pub(crate) fn positive(field: &'static str, v: f64) -> Result<f64, SceneError> {
    finite(field, v)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(invalid(field, format!("must be > 0, got {}", short(v))))
    }
}

/// The parser's message with its line and column and at most 120
/// characters of the line around the column (a long line is not echoed).
fn parse_message(text: &str, e: &toml::de::Error) -> String {
    let Some(span) = e.span() else {
        return e.message().to_string();
    };
    let start = span.start.min(text.len());
    let before = text.get(..start).unwrap_or("");
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[line_start..].chars().count() + 1;
    let whole: Vec<char> = text[line_start..]
        .lines()
        .next()
        .unwrap_or("")
        .chars()
        .collect();
    let (from, to) = if whole.len() <= 120 {
        (0, whole.len())
    } else {
        let from = column.saturating_sub(40).min(whole.len());
        (from, (from + 120).min(whole.len()))
    };
    let snippet: String = whole[from..to].iter().collect();
    format!(
        "line {line}, column {column}: {}\n  {}{snippet}{}",
        e.message().trim_end(),
        if from > 0 { "…" } else { "" },
        if to < whole.len() { "…" } else { "" }
    )
}

impl Scene {
    /// Parse and validate scene text (a leading byte-order mark ignored).
    pub fn parse(text: &str) -> Result<Scene, SceneError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let scene: Scene = toml::from_str(text).map_err(|e| SceneError::Parse {
            path: PathBuf::from("<text>"),
            message: parse_message(text, &e),
        })?;
        scene.validate()?;
        Ok(scene)
    }

    /// The rod model (with N replaced if `segments` is given).
    pub fn rod_model(&self, segments: Option<usize>) -> RodModel {
        let m = &self.model;
        RodModel {
            weight: self.load.weight_vector(),
            natural_strains: self.model.natural_strains.clone(),
            segments: segments.unwrap_or(m.segments as usize),
            k2: m.k2,
            k3: m.k3,
            stretching_stiffness: m
                .stretching_stiffness
                .unwrap_or_else(|| RodModel::circular_stretching_stiffness(m.rod_diameter)),
            law: match m.kind {
                ModelKind::Kirchhoff => Law::Kirchhoff,
                ModelKind::Unbendable => Law::Unbendable,
                ModelKind::Strip => Law::Strip {
                    regularisation: m.strip_regularisation,
                },
            },
        }
    }

    /// The contact model, if the scene has a `[contact]` section.
    pub fn contact_model(&self) -> Option<ContactModel> {
        self.contact.as_ref().map(|c| ContactModel {
            diameter: self.model.rod_diameter,
            rays: c.rays,
            self_contact: c.self_contact,
            gap: self.diagnostics.self_distance_gap,
            obstacles: c
                .obstacles
                .iter()
                .map(|o| {
                    [
                        nalgebra::Vector3::new(o[0], o[1], o[2]),
                        nalgebra::Vector3::new(o[3], o[4], o[5]),
                    ]
                })
                .collect(),
            margin: c.margin,
            ray_length: 10.0,
        })
    }

    /// Its good-knot predicate (the knot was checked by validation; an
    /// untabled one falls back to the paper's trefoil).
    pub fn good_knot(&self) -> GoodKnot {
        let d = &self.diagnostics;
        let good = GoodKnot::new(&d.knot, d.clearance, self.model.rod_diameter)
            .unwrap_or_else(|| GoodKnot::paper(self.model.rod_diameter));
        GoodKnot {
            strip_width: self.model.strip_width,
            ..good
        }
    }

    /// Its name as a file name under `recordings/`: letters, digits, `-`,
    /// `_` and inner dots kept, anything else (a `/`, `..`) made `_`, so a
    /// name cannot point outside the folder; `default` if it has none.
    pub fn file_stem(&self, default: &str) -> String {
        let name = self.name.as_deref().unwrap_or(default);
        let safe: String = name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let safe = safe.trim_start_matches('.').to_string();
        if safe.is_empty() {
            default.to_string()
        } else {
            safe
        }
    }

    /// The measurement settings of its equilibria.
    pub fn measure(&self) -> Measure {
        Measure {
            eigenvalues: self.stability.eigenvalues as usize,
            good: self.good_knot(),
            self_distance_gap: self.diagnostics.self_distance_gap,
            ray_length: self.diagnostics.ray_length,
            strip_width: self.model.strip_width,
        }
    }

    /// Set a parameter in the scene's own sections ([clamps], or [model] and
    /// [load] for the model's scalars).
    pub fn set(&mut self, p: Parameter, v: f64) {
        match p {
            Parameter::K2 => self.model.k2 = v,
            Parameter::K3 => self.model.k3 = v,
            Parameter::Weight => self.load.weight = v,
            Parameter::NaturalScale => {
                self.model.natural_strains = self.model.natural_strains.scaled(v)
            }
            _ => self.clamps.set(p, v),
        }
    }

    /// Every parameter the scene varies: its branch's, its sweep's, its map's
    /// and slices', its loading targets.
    pub fn varied(&self) -> Vec<Parameter> {
        let mut v: Vec<Parameter> = Vec::new();
        v.extend(self.continuation.as_ref().map(|c| c.parameter));
        v.extend(self.sweep.as_ref().map(|s| s.parameter));
        if let Some(m) = &self.map {
            v.push(m.parameter);
            v.extend(m.slices.as_ref().map(|s| s.parameter));
        }
        for l in &self.loading {
            v.extend(l.targets.keys().copied());
        }
        v
    }

    /// The clamps.
    pub fn clamps(&self) -> Clamps {
        let c = &self.clamps;
        let mut clamps = Clamps::new(c.z_star, c.delta, c.phi_over_2pi);
        let rotation = |r: &Option<RotationSpec>| {
            r.and_then(|r| r.quaternion().ok())
                .unwrap_or_else(nalgebra::UnitQuaternion::identity)
        };
        clamps.end.shift = c.end_shift.unwrap_or([0.0; 2]);
        clamps.end.orientation = Orientation {
            rotation: rotation(&c.end_rotation),
            tilt: c.end_tilt,
            tilt_azimuth: c.end_tilt_azimuth,
        };
        if self.varied().iter().any(Parameter::is_model) {
            // the states carry the model's scalars the scene varies
            clamps.scalars = ModelScalars::of(&self.rod_model(None), self.load.unit_direction());
        }
        if let Some(st) = &c.start {
            clamps.start = StartClamp {
                position: nalgebra::Vector3::from(st.position),
                orientation: Orientation {
                    rotation: rotation(&st.rotation),
                    tilt: st.tilt,
                    tilt_azimuth: st.tilt_azimuth,
                },
                turn: 2.0 * std::f64::consts::PI * st.turn_over_2pi,
            };
            clamps.ends.start = st.kind;
        }
        clamps.ends.end = c.end;
        clamps
    }
}

// a slice of a 3D map is a scene: built here, where scenes are
impl SliceSpec {
    /// The scene of slice k: its parameter set, its start φ.
    pub fn scene(&self, scene: &Scene, k: usize) -> Scene {
        let mut s = scene.clone();
        let c = self.parameter.with(&scene.clamps(), self.values[k]);
        s.clamps.z_star = c.z_star;
        s.clamps.delta = c.delta;
        s.clamps.phi_over_2pi = c.phi_over_2pi();
        if !matches!(
            self.parameter,
            Parameter::ZStar | Parameter::Delta | Parameter::Phi
        ) {
            s.set(self.parameter, self.values[k]);
        }
        if let Some(p) = &self.start_phi_over_2pi {
            s.clamps.phi_over_2pi = p[k];
        }
        if let Some(m) = s.map.as_mut() {
            m.slices = None;
            if let Some(t) = &self.trace_from {
                m.trace_from = Some(t[k]);
            }
        }
        s
    }
}
