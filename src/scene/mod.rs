//! Scene files (TOML): model, clamps, initial shape, solver settings, outputs.
//! Every field is checked; errors name the field.

use crate::model::rod::{Clamps, Law, Parameter, RodModel};
use crate::solve::outcome::SolverSettings;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

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
    pub map: Option<crate::study::map::MapSpec>,
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
}

/// `[model]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// Model kind: "kirchhoff" (default), "unbendable" (Kirchhoff with u2 = 0
    /// enforced, K2 → ∞) or "strip" (Sadowsky elastic strip, u2 = 0 enforced).
    #[serde(default = "default_kind")]
    pub kind: String,
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
}

fn default_strip_regularisation() -> f64 {
    STRIP_REGULARISATION
}

/// Default ε of the strip law: far below the curvatures of the paper's knots
/// (|u1| ~ 5–30), so it only matters at inflections of a twisted strip.
pub const STRIP_REGULARISATION: f64 = 0.05;

fn default_kind() -> String {
    "kirchhoff".into()
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
}

/// `[initial]`
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// "straight" (default), "shooting", "file" or "double_ring".
    #[serde(default)]
    pub shape: InitialShape,
    /// Shooting data: n(0) in the material frame.
    #[serde(default)]
    pub n0: Option<[f64; 3]>,
    /// Shooting data: m(0) in the material frame.
    #[serde(default)]
    pub m0: Option<[f64; 3]>,
    /// Refine the shooting data by Newton on the s = 1 boundary conditions first.
    #[serde(default)]
    pub refine: bool,
    /// RK4 steps for the shooting integration; for "double_ring", the
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
    #[serde(default)]
    pub bump: Option<[f64; 3]>,
    /// Trefoil: the integer part of the link (Tw + Wr of the ray closure,
    /// less φ/2π) to give it; default 3, the paper's configuration A.
    #[serde(default)]
    pub link: Option<i64>,
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
}

impl ContinuationSpec {
    /// The numerical continuation settings this spec asks for.
    pub fn settings(&self) -> crate::solve::continuation::ContinuationSettings {
        let defaults = crate::solve::continuation::ContinuationSettings::default();
        crate::solve::continuation::ContinuationSettings {
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
    /// Number of equal steps.
    pub steps: i64,
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
}

impl Default for DiagnosticsSpec {
    fn default() -> Self {
        DiagnosticsSpec {
            self_distance_gap: 0.05,
            ray_length: 1e6,
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

/// `[reference]`: published values for comparison.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// Source, e.g. "paper Appendix D".
    #[serde(default)]
    pub source: Option<String>,
    /// n(0).
    #[serde(default)]
    pub n0: Option<[f64; 3]>,
    /// m(0).
    #[serde(default)]
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
    #[error("cannot read scene {path}: {source}")]
    Io {
        /// Path.
        path: PathBuf,
        /// Cause.
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
}

fn invalid(field: &'static str, reason: impl Into<String>) -> SceneError {
    SceneError::Invalid {
        field,
        reason: reason.into(),
    }
}

fn finite(field: &'static str, v: f64) -> Result<f64, SceneError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(invalid(field, format!("must be a finite number, got {v}")))
    }
}

fn positive(field: &'static str, v: f64) -> Result<f64, SceneError> {
    finite(field, v)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(invalid(field, format!("must be > 0, got {v}")))
    }
}

impl Scene {
    /// Read and validate a scene file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            path: path.into(),
            source,
        })?;
        let mut scene = Scene::parse(&text).map_err(|e| match e {
            SceneError::Parse { message, .. } => SceneError::Parse {
                path: path.into(),
                message,
            },
            other => other,
        })?;
        if scene.name.is_none() {
            scene.name = path.file_stem().map(|s| s.to_string_lossy().into_owned());
        }
        // relative initial files are relative to the scene's folder
        if let Some(f) = &scene.initial.file
            && f.is_relative()
            && !f.exists()
            && let Some(dir) = path.parent()
        {
            scene.initial.file = Some(dir.join(f));
        }
        Ok(scene)
    }

    /// Parse and validate scene text.
    pub fn parse(text: &str) -> Result<Scene, SceneError> {
        let scene: Scene = toml::from_str(text).map_err(|e| SceneError::Parse {
            path: PathBuf::from("<text>"),
            message: e.to_string(),
        })?;
        scene.validate()?;
        Ok(scene)
    }

    /// Check every value's range.
    pub fn validate(&self) -> Result<(), SceneError> {
        let m = &self.model;
        if !["kirchhoff", "unbendable", "strip"].contains(&m.kind.as_str()) {
            return Err(invalid(
                "model.kind",
                format!(
                    "unknown model `{}` (known: kirchhoff, unbendable, strip)",
                    m.kind
                ),
            ));
        }
        positive("model.strip_regularisation", m.strip_regularisation)?;
        positive("model.K2", m.k2)?;
        positive("model.K3", m.k3)?;
        if m.segments < 4 || m.segments > 1_000_000 {
            return Err(invalid(
                "model.segments",
                format!("must be an integer in 4..=1000000, got {}", m.segments),
            ));
        }
        positive("model.rod_diameter", m.rod_diameter)?;
        if let Some(s) = m.stretching_stiffness {
            positive("model.stretching_stiffness", s)?;
        }
        let c = &self.clamps;
        finite("clamps.z_star", c.z_star)?;
        finite("clamps.delta", c.delta)?;
        finite("clamps.phi_over_2pi", c.phi_over_2pi)?;
        if c.delta < 0.0 {
            return Err(invalid(
                "clamps.delta",
                format!("must be >= 0, got {}", c.delta),
            ));
        }
        if c.z_star.abs() > 1.0 {
            return Err(invalid(
                "clamps.z_star",
                format!("|z*| must be <= 1 (the rod has length 1), got {}", c.z_star),
            ));
        }
        if (c.z_star * c.z_star + c.delta * c.delta).sqrt() > 1.0 {
            return Err(invalid(
                "clamps.delta",
                "the clamps are farther apart than the rod's length: sqrt(z*² + δ²) > 1",
            ));
        }
        let i = &self.initial;
        if i.shape == InitialShape::Shooting {
            let n0 =
                i.n0.ok_or_else(|| invalid("initial.n0", "required for shape = \"shooting\""))?;
            let m0 =
                i.m0.ok_or_else(|| invalid("initial.m0", "required for shape = \"shooting\""))?;
            for v in n0 {
                finite("initial.n0", v)?;
            }
            for v in m0 {
                finite("initial.m0", v)?;
            }
        }
        // RK4 steps of a shooting start, or unfolding steps of the double ring
        let least = if i.shape == InitialShape::DoubleRing {
            1
        } else {
            10
        };
        if let Some(s) = i.steps
            && !(least..=10_000_000).contains(&s)
        {
            return Err(invalid(
                "initial.steps",
                format!("must be in {least}..=10000000, got {s}"),
            ));
        }
        if i.shape == InitialShape::File && i.file.is_none() {
            return Err(invalid("initial.file", "required for shape = \"file\""));
        }
        let s = &self.solver;
        positive("solver.gradient_tol", s.gradient_tol)?;
        positive("solver.max_step", s.max_step)?;
        if s.max_iterations == 0 {
            return Err(invalid("solver.max_iterations", "must be >= 1"));
        }
        if let Some(c) = &self.continuation {
            finite("continuation.range", c.range[0])?;
            finite("continuation.range", c.range[1])?;
            if c.range[0] >= c.range[1] {
                return Err(invalid(
                    "continuation.range",
                    "must be [lo, hi] with lo < hi",
                ));
            }
            let start = c.parameter.value(&self.clamps());
            if start < c.range[0] || start > c.range[1] {
                return Err(invalid(
                    "continuation.range",
                    format!("does not contain the start value {start}"),
                ));
            }
            for (field, v) in [
                ("continuation.step", c.step),
                ("continuation.max_step", c.max_step),
            ] {
                if let Some(v) = v {
                    positive(field, v)?;
                }
            }
            if let Some(m) = c.max_points
                && m < 1
            {
                return Err(invalid("continuation.max_points", "must be >= 1"));
            }
        }
        if !self.loading.is_empty() && self.continuation.is_some() {
            return Err(invalid(
                "loading",
                "a scene has either [[loading]] or [continuation], not both",
            ));
        }
        for l in &self.loading {
            if l.steps < 1 || l.steps > 1_000_000 {
                return Err(invalid(
                    "loading.steps",
                    format!("must be in 1..=1000000, got {}", l.steps),
                ));
            }
            for (field, v) in [
                ("loading.z_star", l.z_star),
                ("loading.delta", l.delta),
                ("loading.phi_over_2pi", l.phi_over_2pi),
            ] {
                if let Some(v) = v {
                    finite(field, v)?;
                }
            }
            if l.z_star.is_some_and(|z| z.abs() > 1.0) {
                return Err(invalid("loading.z_star", "|z*| must be <= 1"));
            }
            if l.delta.is_some_and(|d| d < 0.0) {
                return Err(invalid("loading.delta", "must be >= 0"));
            }
        }
        if let Some(sw) = &self.sweep {
            if self.continuation.is_none() {
                return Err(invalid("sweep", "needs a [continuation] to repeat"));
            }
            if sw.values.is_empty() {
                return Err(invalid("sweep.values", "must not be empty"));
            }
            for v in &sw.values {
                finite("sweep.values", *v)?;
            }
            if Some(sw.parameter) == self.continuation.as_ref().map(|c| c.parameter) {
                return Err(invalid(
                    "sweep.parameter",
                    "must differ from continuation.parameter",
                ));
            }
        }
        if let Some(m) = &self.map {
            if self.continuation.is_none() {
                return Err(invalid("map", "needs a [continuation] giving the branches"));
            }
            finite("map.range", m.range[0])?;
            finite("map.range", m.range[1])?;
            if m.lines == 0 || m.lines > 100_000 {
                return Err(invalid("map.lines", "must be in 1..=100000"));
            }
            if m.grid_columns < 2 {
                return Err(invalid("map.grid_columns", "must be >= 2"));
            }
            positive("map.trace_step", m.trace_step)?;
            for v in m.trace_from.iter().flatten() {
                finite("map.trace_from", *v)?;
            }
            if let Some(sl) = &m.slices {
                if sl.values.is_empty() || sl.values.iter().any(|v| !v.is_finite()) {
                    return Err(invalid("map.slices.values", "must be finite and non-empty"));
                }
                if sl.values.windows(2).any(|w| w[1] <= w[0]) {
                    return Err(invalid("map.slices.values", "must be increasing"));
                }
                if sl.parameter == m.parameter
                    || Some(sl.parameter) == self.continuation.as_ref().map(|c| c.parameter)
                {
                    return Err(invalid(
                        "map.slices.parameter",
                        "must differ from map.parameter and continuation.parameter",
                    ));
                }
                if let Some(p) = &sl.start_phi_over_2pi
                    && p.len() != sl.values.len()
                {
                    return Err(invalid(
                        "map.slices.start_phi_over_2pi",
                        "needs one value per slice",
                    ));
                }
                for v in sl.trace_from.iter().flatten().flatten() {
                    finite("map.slices.trace_from", *v)?;
                }
                if let Some(p) = &sl.trace_from
                    && p.len() != sl.values.len()
                {
                    return Err(invalid(
                        "map.slices.trace_from",
                        "needs one point per slice",
                    ));
                }
            }
        }
        if let Some(c) = &self.contact {
            positive("contact.margin", c.margin)?;
            for o in &c.obstacles {
                for v in o {
                    finite("contact.obstacles", *v)?;
                }
            }
        }
        let d = &self.diagnostics;
        positive("diagnostics.self_distance_gap", d.self_distance_gap)?;
        if d.self_distance_gap >= 0.5 {
            return Err(invalid(
                "diagnostics.self_distance_gap",
                "must be < 0.5 (half the rod)",
            ));
        }
        positive("diagnostics.ray_length", d.ray_length)?;
        if self.stability.eigenvalues < 0 || self.stability.eigenvalues > 100 {
            return Err(invalid(
                "stability.eigenvalues",
                format!("must be in 0..=100, got {}", self.stability.eigenvalues),
            ));
        }
        Ok(())
    }

    /// The rod model (with N replaced if `segments` is given).
    pub fn rod_model(&self, segments: Option<usize>) -> RodModel {
        let m = &self.model;
        RodModel {
            segments: segments.unwrap_or(m.segments as usize),
            k2: m.k2,
            k3: m.k3,
            stretching_stiffness: m
                .stretching_stiffness
                .unwrap_or_else(|| RodModel::circular_stretching_stiffness(m.rod_diameter)),
            law: match m.kind.as_str() {
                "unbendable" => Law::Unbendable,
                "strip" => Law::Strip {
                    regularisation: m.strip_regularisation,
                },
                _ => Law::Kirchhoff,
            },
        }
    }

    /// The contact model, if the scene has a `[contact]` section.
    pub fn contact_model(&self) -> Option<crate::model::contact::ContactModel> {
        self.contact
            .as_ref()
            .map(|c| crate::model::contact::ContactModel {
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

    /// The clamps.
    pub fn clamps(&self) -> Clamps {
        Clamps::new(
            self.clamps.z_star,
            self.clamps.delta,
            self.clamps.phi_over_2pi,
        )
    }
}
