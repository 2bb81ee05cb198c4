//! The discrete Kirchhoff rod: parameters, clamps, degrees of freedom and state.
//!
//! Discretisation (N segments, h = 1/N): nodes x_0..x_{N+1} at arc lengths
//! s = (i - 1/2) h, edges e_j = x_{j+1} - x_j centred at s = j h. Edge 0 and edge
//! N are the clamps: each is centred on its end point, half outside the rod, so
//! that the N interior vertices (1..=N, curvature and twist) sample [0, 1] by the
//! midpoint rule and the scheme stays second order. Fixed between two clamps:
//! nodes 0, 1, N, N+1 and the material angles of edges 0 and N. A pinned end
//! keeps its edge's midpoint at the pin (the node beyond the end placed
//! opposite its neighbour) with its angle free; a free end fixes nothing, the
//! ghost half of its edge beyond s ∈ [0, 1] carrying no weight. Either way
//! the discrete moment at the last vertex is the continuum's at h/2 from the
//! end, which the natural condition m = 0 makes O(h²).

use crate::geometry::walls::wall_clearance;
use crate::model::frames::{self, V3};
use crate::model::natural::NaturalStrains;
use nalgebra::{Rotation3, Unit, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Velocity of the clamps' dofs with respect to a loading parameter: the four
/// clamp nodes (0, 1 at s = 0; N, N+1 at s = 1) and the two clamp angles
/// (θ_0, θ_N).
#[derive(Clone, Copy, Debug, Default)]
pub struct ClampVelocity {
    /// d(node)/dp of nodes 0, 1, N, N+1.
    pub nodes: [Vector3<f64>; 4],
    /// dθ_0/dp and dθ_N/dp.
    pub theta: [f64; 2],
}

impl ClampVelocity {
    /// Only the s = 1 clamp moves: both its nodes translate by `end`, its angle
    /// turns by `theta`.
    pub fn end(end: Vector3<f64>, theta: f64) -> Self {
        let z = Vector3::zeros();
        ClampVelocity {
            nodes: [z, z, end, end],
            theta: [0.0, theta],
        }
    }

    /// The velocity of the dofs that stay fixed at these ends: a pinned end's
    /// edge translates with its pin point (the free dof is the node's offset
    /// from the pin, so the edge's midpoint velocity moves both nodes and the
    /// angle is free); a free end's nodes and angle are all free dofs.
    pub fn for_ends(mut self, ends: Ends) -> Self {
        for (kind, [a, b], k) in [(ends.start, [0, 1], 0), (ends.end, [2, 3], 1)] {
            match kind {
                EndKind::Clamped => {}
                EndKind::Pinned => {
                    let v = 0.5 * (self.nodes[a] + self.nodes[b]);
                    self.nodes[a] = v;
                    self.nodes[b] = v;
                    self.theta[k] = 0.0;
                }
                EndKind::Free => {
                    self.nodes[a] = Vector3::zeros();
                    self.nodes[b] = Vector3::zeros();
                    self.theta[k] = 0.0;
                }
            }
        }
        self
    }

    /// Whether the s = 0 clamp moves (its stencils then enter ∂p∇E).
    pub fn moves_start(&self) -> bool {
        self.nodes[0] != Vector3::zeros()
            || self.nodes[1] != Vector3::zeros()
            || self.theta[0] != 0.0
    }
}

/// Material and discretisation parameters of a rod.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct RodModel {
    /// Number of segments N (the rod is [0, 1], segment length 1/N).
    pub segments: usize,
    /// K2 = B22 / B11: bending stiffness for curvature along d2.
    pub k2: f64,
    /// K3 = B33 / B11: twisting stiffness.
    pub k3: f64,
    /// Stretching stiffness EA L^2 / B11 (near-inextensibility penalty).
    pub stretching_stiffness: f64,
    /// Constitutive law of bending and twisting.
    #[serde(default)]
    pub law: Law,
    /// Body force per unit length, w g (in units of B11 / L³): the weight of
    /// the rod with its direction; potential energy −∫ w g·r ds.
    #[serde(default)]
    pub weight: [f64; 3],
    /// Natural strains (û1, û2, û3), constant or a table in s: the energy is
    /// ½ ∫ B_i (u_i − û_i)² (zero: a naturally straight, untwisted rod); the
    /// strip law takes u1 − û1 in place of u1.
    #[serde(default)]
    pub natural_strains: NaturalStrains,
}

/// Constitutive law of bending and twisting (energy per unit length, in units
/// of the soft bending stiffness B).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum Law {
    /// Kirchhoff rod: 1/2 (u1² + K2 u2² + K3 u3²).
    #[default]
    Kirchhoff,
    /// Kirchhoff rod with K2 → ∞: u2 = 0 enforced as a constraint,
    /// energy 1/2 (u1² + K3 u3²).
    Unbendable,
    /// Elastic strip (Sadowsky, paper eq. 4.2): u2 = 0 enforced,
    /// energy 1/2 (u1² + u3²)² / (u1² + ε²). The regularisation ε (a
    /// curvature, in units of 1/L) keeps the energy finite where u1 → 0 with
    /// u3 ≠ 0; it changes the law only where |u1| is comparable to ε.
    Strip {
        /// ε.
        regularisation: f64,
    },
}

impl Law {
    /// Whether u2 = 0 is a constraint (solved by SQP rather than Newton).
    pub fn constrained(&self) -> bool {
        !matches!(self, Law::Kirchhoff)
    }

    /// Short name.
    pub fn name(&self) -> &'static str {
        match self {
            Law::Kirchhoff => "Kirchhoff rod",
            Law::Unbendable => "Kirchhoff rod with u2 = 0",
            Law::Strip { .. } => "elastic strip",
        }
    }
}

impl RodModel {
    /// Segment length h = 1/N (also the rest length of every edge).
    pub fn segment_length(&self) -> f64 {
        1.0 / self.segments as f64
    }

    /// One line naming the law and its stiffness ratios.
    pub fn describe(&self) -> String {
        let law = match self.law {
            Law::Kirchhoff => format!("Kirchhoff rod, K2 = {}, K3 = {}", self.k2, self.k3),
            Law::Unbendable => format!("Kirchhoff rod with u2 = 0 (K2 → ∞), K3 = {}", self.k3),
            Law::Strip { regularisation } => {
                format!("elastic strip (Sadowsky, u2 = 0), ε = {regularisation}")
            }
        };
        let mut out = law;
        if !self.natural_strains.is_zero() {
            out += &format!(", natural strains {}", self.natural_strains.describe());
        }
        let w = Vector3::from(self.weight);
        if w != Vector3::zeros() {
            let g = w.normalize();
            out += &format!(
                ", weight w L³/B = {} along ({:.3}, {:.3}, {:.3})",
                w.norm(),
                g.x,
                g.y,
                g.z
            );
        }
        out
    }

    /// Stretching stiffness of a solid circular rod of the given diameter: 16/d².
    pub fn circular_stretching_stiffness(diameter: f64) -> f64 {
        16.0 / (diameter * diameter)
    }
}

/// Boundary condition at one end of the rod.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "snake_case")]
pub enum EndKind {
    /// Position and material frame fixed: a clamp.
    #[default]
    Clamped,
    /// Position fixed, frame free to rotate (a ball joint): the end edge
    /// turns about its midpoint, the pin point, and its angle is free.
    Pinned,
    /// Nothing fixed: the end edge's nodes and angle are free.
    Free,
}

impl EndKind {
    /// Whether it is a clamp.
    pub fn is_clamped(&self) -> bool {
        *self == EndKind::Clamped
    }

    /// Name as in scenes.
    pub fn name(&self) -> &'static str {
        match self {
            EndKind::Clamped => "clamped",
            EndKind::Pinned => "pinned",
            EndKind::Free => "free",
        }
    }
}

/// The boundary conditions at s = 0 and s = 1.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq, Hash)]
pub struct Ends {
    /// At s = 0.
    pub start: EndKind,
    /// At s = 1.
    pub end: EndKind,
}

impl Ends {
    /// Both ends clamped (the paper's problem).
    pub const CLAMPED: Ends = Ends {
        start: EndKind::Clamped,
        end: EndKind::Clamped,
    };

    /// Whether both ends are clamped.
    pub fn both_clamped(&self) -> bool {
        *self == Ends::CLAMPED
    }
}

/// Orientation of a clamp before its turn about its own tangent: a fixed
/// rotation, then a tilt of the tangent. The clamp's tangent is `matrix()·e3`
/// and its reference director `matrix()·e1`; the identity is the paper's clamp
/// along e3.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(default)]
pub struct Orientation {
    /// Rotation taking (e1, e2, e3) to the clamp's frame before the tilt.
    pub rotation: UnitQuaternion<f64>,
    /// Tilt angle (radians): a rotation by this angle about the lab axis
    /// (−sin ψ, cos ψ, 0), applied after `rotation`; it takes e3 to
    /// (sin t cos ψ, sin t sin ψ, cos t).
    pub tilt: f64,
    /// Azimuth ψ of the tilt's direction about e3 (radians).
    pub tilt_azimuth: f64,
}

impl Default for Orientation {
    fn default() -> Self {
        Orientation {
            rotation: UnitQuaternion::identity(),
            tilt: 0.0,
            tilt_azimuth: 0.0,
        }
    }
}

impl Orientation {
    /// The paper's orientation (tangent e3, reference e1).
    pub fn is_identity(&self) -> bool {
        *self == Orientation::default()
    }

    /// Axis of the tilt (lab frame).
    fn tilt_axis(&self) -> Vector3<f64> {
        Vector3::new(-self.tilt_azimuth.sin(), self.tilt_azimuth.cos(), 0.0)
    }

    /// The rotation (tilt after `rotation`).
    pub fn matrix(&self) -> Rotation3<f64> {
        Rotation3::from_axis_angle(&Unit::new_unchecked(self.tilt_axis()), self.tilt)
            * self.rotation.to_rotation_matrix()
    }

    /// Unit tangent of the clamp (exactly e3 for the identity).
    pub fn tangent(&self) -> Vector3<f64> {
        if self.is_identity() {
            return Vector3::z();
        }
        self.matrix() * Vector3::z()
    }

    /// Reference director of the clamp (exactly e1 for the identity); the
    /// material director d1 is it turned about the tangent by the clamp's turn.
    pub fn reference(&self) -> Vector3<f64> {
        if self.is_identity() {
            return Vector3::x();
        }
        self.matrix() * Vector3::x()
    }

    /// Angular velocity (lab frame) of the frame per unit change of the tilt
    /// and of its azimuth.
    fn tilt_rates(&self) -> [Vector3<f64>; 2] {
        let tilted = Rotation3::from_axis_angle(&Unit::new_unchecked(self.tilt_axis()), self.tilt);
        // R(ψ) = Rz(ψ) R(0) Rz(−ψ): dR/dψ Rᵀ = ê3 − (R e3)^
        [self.tilt_axis(), Vector3::z() - tilted * Vector3::z()]
    }
}

/// The s = 0 clamp: a rigid frame (the paper's is the identity at the origin).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(default)]
pub struct StartClamp {
    /// Position of the rod's end r(0).
    pub position: Vector3<f64>,
    /// Orientation before the turn.
    pub orientation: Orientation,
    /// Turn of the material frame about the tangent (radians, continuous).
    pub turn: f64,
}

impl StartClamp {
    /// The paper's s = 0 clamp.
    pub fn is_default(&self) -> bool {
        *self == StartClamp::default()
    }
}

/// General placement of the s = 1 clamp beyond the paper's (z*, δ, φ): a shift
/// of its point in (x, y) and its orientation before the turn φ.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(default)]
pub struct EndPlacement {
    /// Added to (x*, y*).
    pub shift: [f64; 2],
    /// Orientation before the turn φ.
    pub orientation: Orientation,
}

impl EndPlacement {
    /// The paper's placement (no shift, clamp along e3).
    pub fn is_default(&self) -> bool {
        *self == EndPlacement::default()
    }
}

/// Scalars of the model that a study may vary along a branch, a loading
/// path, a sweep or a map, carried by each state with its clamps; None: the
/// model's own value.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(default)]
pub struct ModelScalars {
    /// K2 = B22/B11.
    pub k2: Option<f64>,
    /// K3 = B33/B11.
    pub k3: Option<f64>,
    /// Weight w L³/B11 along `weight_direction`.
    pub weight: Option<f64>,
    /// Unit direction of the weight (used with `weight`).
    pub weight_direction: [f64; 3],
    /// Factor on the natural strains û.
    pub natural_scale: Option<f64>,
}

impl ModelScalars {
    /// No scalar set: the model's own throughout.
    pub fn is_unset(&self) -> bool {
        self.k2.is_none()
            && self.k3.is_none()
            && self.weight.is_none()
            && self.natural_scale.is_none()
    }

    /// The model with these scalars.
    pub fn apply(&self, model: &RodModel) -> RodModel {
        let mut m = model.clone();
        if let Some(v) = self.k2 {
            m.k2 = v;
        }
        if let Some(v) = self.k3 {
            m.k3 = v;
        }
        if let Some(w) = self.weight {
            m.weight = self.weight_direction.map(|d| w * d);
        }
        if let Some(f) = self.natural_scale {
            m.natural_strains = model.natural_strains.scaled(f);
        }
        m
    }

    /// Every scalar set to the model's own value (the weight's direction from
    /// `direction` when the model is weightless).
    pub fn of(model: &RodModel, direction: [f64; 3]) -> ModelScalars {
        let w = Vector3::from(model.weight);
        let (weight, dir) = if w.norm() > 0.0 {
            (w.norm(), (w / w.norm()).into())
        } else {
            (0.0, direction)
        };
        ModelScalars {
            k2: Some(model.k2),
            k3: Some(model.k3),
            weight: Some(weight),
            weight_direction: dir,
            natural_scale: Some(1.0),
        }
    }
}

/// The two clamps. The s = 1 clamp sits at (x − δ cos φ/2, y − δ sin φ/2, z*)
/// (eq. 2.13 when the shift (x, y) is zero), oriented by `end.orientation` and
/// turned by φ about its tangent; the s = 0 clamp is `start` (by default the
/// identity frame at the origin). With the defaults this is the paper's family.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct Clamps {
    /// End displacement z* (height of the s = 1 clamp's point).
    pub z_star: f64,
    /// End shift δ along the flip axis (eq. 2.13).
    pub delta: f64,
    /// End rotation φ in radians, continuous (turns are kept): the s = 1
    /// clamp's turn about its own tangent.
    pub phi: f64,
    /// Shift and orientation of the s = 1 clamp (default: the paper's).
    #[serde(default, skip_serializing_if = "EndPlacement::is_default")]
    pub end: EndPlacement,
    /// The s = 0 clamp (default: the paper's).
    #[serde(default, skip_serializing_if = "StartClamp::is_default")]
    pub start: StartClamp,
    /// Model scalars this state sets (a branch in K3 or in the weight).
    #[serde(default, skip_serializing_if = "ModelScalars::is_unset")]
    pub scalars: ModelScalars,
    /// Boundary conditions (default: both clamped). A pinned end keeps only
    /// its clamp's point; a free end keeps nothing of its clamp.
    #[serde(default, skip_serializing_if = "Ends::both_clamped")]
    pub ends: Ends,
}

impl Clamps {
    /// From (z*, δ, φ/2π): the paper's family.
    pub fn new(z_star: f64, delta: f64, phi_over_2pi: f64) -> Self {
        Clamps {
            z_star,
            delta,
            phi: 2.0 * PI * phi_over_2pi,
            end: EndPlacement::default(),
            start: StartClamp::default(),
            scalars: ModelScalars::default(),
            ends: Ends::CLAMPED,
        }
    }

    /// φ / 2π.
    pub fn phi_over_2pi(&self) -> f64 {
        self.phi / (2.0 * PI)
    }

    /// Whether both clamps are the paper's (e3-aligned, s = 0 at the origin):
    /// the walls, the rays along ∓e3 and Lk − φ/2π ∈ ℤ hold as in the paper.
    pub fn is_paper(&self) -> bool {
        self.end.is_default() && self.start.is_default() && self.ends.both_clamped()
    }

    /// End point r(1) = (x − δ cos φ/2, y − δ sin φ/2, z*) (eq. 2.13 with no shift).
    pub fn end_point(&self) -> Vector3<f64> {
        let p = Vector3::new(
            -self.delta * (self.phi / 2.0).cos(),
            -self.delta * (self.phi / 2.0).sin(),
            self.z_star,
        );
        let [x, y] = self.end.shift;
        if x == 0.0 && y == 0.0 {
            return p;
        }
        p + Vector3::new(x, y, 0.0)
    }

    /// The clamps a fraction `f` of the way to `to`, every scalar linearly (z*,
    /// δ and φ in the same floating-point steps as the paper's loading paths).
    pub fn lerp(&self, to: &Clamps, f: f64) -> Clamps {
        let mut c = Clamps {
            z_star: self.z_star + f * (to.z_star - self.z_star),
            delta: self.delta + f * (to.delta - self.delta),
            phi: self.phi + f * (to.phi - self.phi),
            ..*self
        };
        for p in &Parameter::ALL[3..] {
            let (a, b) = (p.value(self), p.value(to));
            if a != b {
                c = p.with(&c, a + f * (b - a));
            }
        }
        let blend = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(a), Some(b)) if a != b => Some(a + f * (b - a)),
            (a, None) => a,
            (_, b) => b,
        };
        let (x, y) = (&self.scalars, &to.scalars);
        c.scalars = ModelScalars {
            k2: blend(x.k2, y.k2),
            k3: blend(x.k3, y.k3),
            weight: blend(x.weight, y.weight),
            natural_scale: blend(x.natural_scale, y.natural_scale),
            ..*y
        };
        let turn = |a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>| {
            if a == b { *a } else { a.slerp(b, f) }
        };
        c.end.orientation.rotation =
            turn(&self.end.orientation.rotation, &to.end.orientation.rotation);
        c.start.orientation.rotation = turn(
            &self.start.orientation.rotation,
            &to.start.orientation.rotation,
        );
        c
    }

    /// Largest change of any scalar between two clamps (φ and turns in turns).
    pub fn gap(&self, to: &Clamps) -> f64 {
        let mut g = Parameter::ALL
            .iter()
            .chain(&Parameter::MODEL)
            .filter(|p| !p.value(self).is_nan() || !p.value(to).is_nan())
            .map(|p| (p.value(self) - p.value(to)).abs())
            .fold(0.0, f64::max);
        for (a, b) in [
            (self.end.orientation.rotation, to.end.orientation.rotation),
            (
                self.start.orientation.rotation,
                to.start.orientation.rotation,
            ),
        ] {
            if a != b {
                g = g.max(a.angle_to(&b));
            }
        }
        g
    }

    /// The cubic from r(0) along t(0) to r(1) along t(1) (tangents scaled by
    /// the distance of the clamps): a start shape for general clamps, straight
    /// when both tangents lie along the chord.
    /// With a free end the rod leaves its other end straight along that
    /// end's tangent (both free: from r(0) along t(0)).
    pub fn hermite(&self, s: f64) -> Vector3<f64> {
        if self.ends.end == EndKind::Free {
            return self.start_point() + self.start_tangent() * s;
        }
        if self.ends.start == EndKind::Free {
            return self.end_point() - self.end_tangent() * (1.0 - s);
        }
        let (p0, p1) = (self.start_point(), self.end_point());
        let l = (p1 - p0).norm().max(1e-3);
        let (s2, s3) = (s * s, s * s * s);
        p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
            + self.start_tangent() * (l * (s3 - 2.0 * s2 + s))
            + p1 * (-2.0 * s3 + 3.0 * s2)
            + self.end_tangent() * (l * (s3 - s2))
    }

    /// d1 blended linearly from the s = 0 clamp's to the s = 1 clamp's (the
    /// start shape's material frame; only its projection ⟂ the tangent counts).
    pub fn blended_d1(&self, s: f64) -> Vector3<f64> {
        let d0 = self.start_frame() * Vector3::x();
        let d1 = self.end_frame() * Vector3::x();
        d0 * (1.0 - s) + d1 * s
    }

    /// Height of the s = 1 clamp's point above the s = 0 clamp's along the
    /// s = 0 tangent: the upper wall (z* for the paper's clamps).
    pub fn top_wall(&self) -> f64 {
        if self.start.is_default() {
            return self.z_star;
        }
        (self.end_point() - self.start_point()).dot(&self.start_tangent())
    }

    /// Whether the clamps' rays are parallel (−e3 from r(0), +e3 from r(1)),
    /// so that the ray closure's link less φ/2π is an integer (Lk = Tw + Wr
    /// = n + φ/2π) and can be carried along a branch.
    pub fn rays_parallel(&self) -> bool {
        // a pinned or free end turns: its ray follows the rod, so the link
        // of the closure is not tied to φ
        self.start.is_default() && self.end.orientation.is_identity() && self.ends.both_clamped()
    }

    /// Directions of the rays that close the rod: −t(0) from r(0), +t(1) from r(1).
    pub fn ray_directions(&self) -> [Vector3<f64>; 2] {
        [-self.start_tangent(), self.end_tangent()]
    }

    /// Start point r(0).
    pub fn start_point(&self) -> Vector3<f64> {
        self.start.position
    }

    /// Unit tangent of the s = 1 clamp.
    pub fn end_tangent(&self) -> Vector3<f64> {
        self.end.orientation.tangent()
    }

    /// Unit tangent of the s = 0 clamp.
    pub fn start_tangent(&self) -> Vector3<f64> {
        self.start.orientation.tangent()
    }

    /// Material frame (d1, d2, d3) of the s = 0 clamp, columns of a rotation.
    pub fn start_frame(&self) -> Rotation3<f64> {
        self.start.orientation.matrix()
            * Rotation3::from_axis_angle(&Vector3::z_axis(), self.start.turn)
    }

    /// Material frame (d1, d2, d3) of the s = 1 clamp.
    pub fn end_frame(&self) -> Rotation3<f64> {
        self.end.orientation.matrix() * Rotation3::from_axis_angle(&Vector3::z_axis(), self.phi)
    }

    /// Distance between the clamp points: at most the rod's length 1.
    pub fn span(&self) -> f64 {
        (self.end_point() - self.start_point()).norm()
    }

    /// How the clamp dofs of `state` (at these clamps) move to reach `target`,
    /// as a velocity over a unit step: ∂_c∇E is linear in it.
    pub fn velocity_to(&self, target: &Clamps, state: &RodState) -> ClampVelocity {
        let n = state.segments();
        let mut v =
            ClampVelocity::end(target.end_point() - self.end_point(), target.phi - self.phi);
        if target.end.orientation != self.end.orientation {
            let (a, b) = clamp_edge(target.end_point(), target.end_tangent(), n);
            v.nodes[2] = a - state.nodes[n];
            v.nodes[3] = b - state.nodes[n + 1];
            v.theta[1] += rigid_turn(&self.end.orientation, &target.end.orientation);
        }
        if target.start != self.start {
            let (a, b) = clamp_edge(target.start_point(), target.start_tangent(), n);
            v.nodes[0] = a - state.nodes[0];
            v.nodes[1] = b - state.nodes[1];
            v.theta[0] = target.start.turn - self.start.turn
                + rigid_turn(&self.start.orientation, &target.start.orientation);
        }
        v.for_ends(self.ends)
    }
}

/// Nodes of a clamp edge of length h = 1/n centred on `point` along `tangent`.
fn clamp_edge(
    point: Vector3<f64>,
    tangent: Vector3<f64>,
    n: usize,
) -> (Vector3<f64>, Vector3<f64>) {
    let h = 1.0 / n as f64;
    (point - 0.5 * h * tangent, point + 0.5 * h * tangent)
}

/// Change of the material angle of a clamp edge when its orientation turns
/// from `a` to `b` and its reference director is parallel transported: the
/// angle, about the new tangent, from the transported old reference to the
/// new one.
fn rigid_turn(a: &Orientation, b: &Orientation) -> f64 {
    let moved = transport(&a.reference(), &a.tangent(), &b.tangent());
    frames::signed_angle(v3(&moved), v3(&b.reference()), v3(&b.tangent()))
}

/// Index map between the rod's nodes/angles and the free degrees of freedom.
/// Free dofs are interleaved (θ_j, x_{j+1}) so that the Hessian is banded:
/// θ_j at a + 4j and x_i at a + 4i − 3, the offset a set by the s = 0 end
/// (−4 clamped: θ_1 first; 0 pinned: θ_0 first; 3 free: x_0 first). A
/// clamped end fixes nodes 0, 1 (N, N+1) and θ_0 (θ_N); a pinned one fixes
/// only the ghost node 0 (N+1), placed opposite its neighbour across the pin
/// (whose dof is then its offset from the pin point); a free one nothing.
#[derive(Clone, Copy, Debug)]
pub struct DofMap {
    /// Number of segments N.
    pub n: usize,
    /// Boundary conditions.
    pub ends: Ends,
}

impl DofMap {
    /// The map of a clamped-clamped rod of N segments.
    pub fn clamped(n: usize) -> Self {
        DofMap {
            n,
            ends: Ends::CLAMPED,
        }
    }

    /// Offset a of the interleaved numbering.
    fn offset(&self) -> isize {
        match self.ends.start {
            EndKind::Clamped => -4,
            EndKind::Pinned => 0,
            EndKind::Free => 3,
        }
    }

    /// Free nodes, in dof order (3(N−2) + … coordinates).
    pub fn free_nodes(&self) -> std::ops::RangeInclusive<usize> {
        let lo = match self.ends.start {
            EndKind::Clamped => 2,
            EndKind::Pinned => 1,
            EndKind::Free => 0,
        };
        let hi = match self.ends.end {
            EndKind::Clamped => self.n - 1,
            EndKind::Pinned => self.n,
            EndKind::Free => self.n + 1,
        };
        lo..=hi
    }

    /// Edges whose material angle is free.
    pub fn free_angles(&self) -> std::ops::RangeInclusive<usize> {
        let lo = usize::from(self.ends.start == EndKind::Clamped);
        let hi = self.n - usize::from(self.ends.end == EndKind::Clamped);
        lo..=hi
    }

    /// Edges with stretching energy: those of free length (all but the
    /// clamps, of length h).
    pub fn stretched_edges(&self) -> std::ops::RangeInclusive<usize> {
        let lo = usize::from(self.ends.start == EndKind::Clamped);
        let hi = self.n - usize::from(self.ends.end == EndKind::Clamped);
        lo..=hi
    }

    /// Weight of edge j in the midpoint rule over s ∈ [0, 1]: an end edge
    /// is half outside the rod.
    pub fn edge_weight(&self, j: usize) -> f64 {
        if j == 0 || j == self.n { 0.5 } else { 1.0 }
    }

    /// The node a pinned end's ghost node is placed from (x_0 = 2 r(0) − x_1,
    /// x_{N+1} = 2 r(1) − x_N), if node i is one.
    pub fn dependent(&self, i: usize) -> Option<usize> {
        if i == 0 && self.ends.start == EndKind::Pinned {
            Some(1)
        } else if i == self.n + 1 && self.ends.end == EndKind::Pinned {
            Some(self.n)
        } else {
            None
        }
    }

    /// Number of free degrees of freedom: 3(N-2) positions + (N-1) angles
    /// between two clamps, more at pinned or free ends.
    pub fn len(&self) -> usize {
        let last = match self.ends.end {
            EndKind::Clamped => 4 * self.n as isize - 3,
            EndKind::Pinned => 4 * self.n as isize + 1,
            EndKind::Free => 4 * self.n as isize + 4,
        };
        (self.offset() + last) as usize
    }

    /// Never empty (N >= 4).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// First dof of node i, if free.
    pub fn node(&self, i: usize) -> Option<usize> {
        self.free_nodes()
            .contains(&i)
            .then(|| (self.offset() + 4 * i as isize - 3) as usize)
    }

    /// Dof of the material angle of edge j, if free.
    pub fn theta(&self, j: usize) -> Option<usize> {
        self.free_angles()
            .contains(&j)
            .then(|| (self.offset() + 4 * j as isize) as usize)
    }

    /// Free dof indices of the vertex stencil i (x_{i-1}, x_i, x_{i+1}, θ_{i-1}, θ_i).
    pub fn vertex_stencil(&self, i: usize) -> [Option<usize>; 11] {
        let mut out = [None; 11];
        for (k, node) in [i - 1, i, i + 1].into_iter().enumerate() {
            if let Some(d) = self.node(node) {
                for c in 0..3 {
                    out[3 * k + c] = Some(d + c);
                }
            }
        }
        out[9] = self.theta(i - 1);
        out[10] = self.theta(i);
        out
    }

    /// Free dof indices of the edge stencil j (x_j, x_{j+1}).
    pub fn edge_stencil(&self, j: usize) -> [Option<usize>; 6] {
        let mut out = [None; 6];
        for (k, node) in [j, j + 1].into_iter().enumerate() {
            if let Some(d) = self.node(node) {
                for c in 0..3 {
                    out[3 * k + c] = Some(d + c);
                }
            }
        }
        out
    }

    /// In a stencil over `nodes`, the (local) block of a pinned end's ghost
    /// node and the block of the node it is placed from: its derivatives
    /// fold onto that node with a minus sign (x_ghost = 2p − x).
    pub fn pinned_block(&self, nodes: &[usize]) -> Option<(usize, usize)> {
        nodes.iter().enumerate().find_map(|(k, &i)| {
            let from = self.dependent(i)?;
            nodes.iter().position(|&j| j == from).map(|l| (k, l))
        })
    }

    /// Whether dof `d` is a translational one (a node coordinate).
    pub fn is_translation(&self, d: usize) -> bool {
        (d as isize - self.offset()).rem_euclid(4) != 0
    }
}

/// Configuration of a discrete rod: nodes, material angles and the reference
/// frames (time-parallel transported between iterates, with the reference twist
/// accumulated continuously).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct RodState {
    /// Clamp parameters this state satisfies.
    pub clamps: Clamps,
    /// Nodes x_0..x_{N+1}.
    pub nodes: Vec<Vector3<f64>>,
    /// Material angle of each edge relative to its reference director.
    pub theta: Vec<f64>,
    /// Reference director a1 of each edge (unit, perpendicular to the edge).
    pub reference: Vec<Vector3<f64>>,
    /// Reference twist at each vertex (index 0 unused).
    pub reference_twist: Vec<f64>,
    /// Constrained laws: multiplier λ_i of u2 = 0 at each vertex (index 0
    /// unused; empty means all zero), part of a constrained equilibrium like
    /// the nodes are: ∇E + Σ λ_i ∇κ2_i = 0 (−λ_i/h is the moment m2 that keeps
    /// the strip from bending in its plane).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub multipliers: Vec<f64>,
}

/// Unit tangent of edge j.
pub fn tangent(nodes: &[Vector3<f64>], j: usize) -> Vector3<f64> {
    (nodes[j + 1] - nodes[j]).normalize()
}

fn v3(v: &Vector3<f64>) -> V3<f64> {
    [v[0], v[1], v[2]]
}

fn vec3(v: V3<f64>) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

/// Parallel transport for nalgebra vectors (see [`frames::parallel_transport`]).
pub fn transport(a: &Vector3<f64>, t: &Vector3<f64>, t_new: &Vector3<f64>) -> Vector3<f64> {
    vec3(frames::parallel_transport(v3(a), v3(t), v3(t_new)))
}

/// Reference twist at vertex i given its previous value: the angle about t_i
/// from the transported a1_{i-1} to a1_i, continued from `previous`.
pub fn reference_twist(
    a_prev: &Vector3<f64>,
    t_prev: &Vector3<f64>,
    a: &Vector3<f64>,
    t: &Vector3<f64>,
    previous: f64,
) -> f64 {
    let ut = frames::parallel_transport(v3(a_prev), v3(t_prev), v3(t));
    let ut = frames::rotate_about(ut, v3(t), previous);
    previous + frames::signed_angle(ut, v3(a), v3(t))
}

impl RodState {
    /// Number of segments N.
    pub fn segments(&self) -> usize {
        self.nodes.len() - 2
    }

    /// Build a state from a smooth centreline r(s) and director d1(s), s in [0,1].
    /// The clamp nodes and angles are set from `clamps`; interior nodes sample r at
    /// s = (i - 1/2) h, angles sample d1 at edge midpoints. The reference twist at
    /// the last vertex takes the branch that makes the local twist smallest, so
    /// the state carries the curve's own twist and φ keeps its turns.
    pub fn from_curve(
        n: usize,
        clamps: Clamps,
        r: impl Fn(f64) -> Vector3<f64>,
        d1: impl Fn(f64) -> Vector3<f64>,
    ) -> RodState {
        let h = 1.0 / n as f64;
        let e3 = Vector3::z();
        let end = clamps.end_point();
        let t_end = clamps.end_tangent();
        let mut nodes: Vec<Vector3<f64>> = (0..n + 2).map(|i| r((i as f64 - 0.5) * h)).collect();
        let ends = clamps.ends;
        // a free end edge samples the curve; a pinned one turns about its
        // pin, its ghost node placed below
        if ends.start == EndKind::Clamped {
            if clamps.start.is_default() {
                nodes[0] = -0.5 * h * e3;
                nodes[1] = 0.5 * h * e3;
            } else {
                (nodes[0], nodes[1]) = clamp_edge(clamps.start_point(), clamps.start_tangent(), n);
            }
        }
        if ends.end == EndKind::Clamped {
            nodes[n] = end - 0.5 * h * t_end;
            nodes[n + 1] = end + 0.5 * h * t_end;
        }
        place_pinned(&mut nodes, &clamps);
        // space-parallel reference frames from the s = 0 clamp; zero reference
        // twist in between
        let mut reference = vec![Vector3::x(); n + 1];
        reference[0] = clamps.start.orientation.reference();
        if ends.start != EndKind::Clamped {
            // the end edge's own frame: d1 projected on its normal plane
            let t = tangent(&nodes, 0);
            let mut a = d1(0.0);
            a -= a.dot(&t) * t;
            reference[0] = if a.norm() < 1e-9 {
                // d1 along the edge: any normal will do
                crate::geometry::normal_to(&t)
            } else {
                a.normalize()
            };
        }
        let free_end = usize::from(ends.end != EndKind::Clamped);
        for j in 1..n + free_end {
            let a = transport(
                &reference[j - 1],
                &tangent(&nodes, j - 1),
                &tangent(&nodes, j),
            );
            // re-orthonormalise against round-off drift
            let t = tangent(&nodes, j);
            reference[j] = (a - a.dot(&t) * t).normalize();
        }
        let mut reference_twist = vec![0.0; n + 1];
        let mut theta = vec![0.0; n + 1];
        if ends.start == EndKind::Clamped {
            theta[0] = clamps.start.turn;
        }
        for j in 1..n + free_end {
            let t = tangent(&nodes, j);
            let a1 = reference[j];
            let a2 = t.cross(&a1);
            let d = d1(j as f64 * h);
            let raw = d.dot(&a2).atan2(d.dot(&a1));
            theta[j] = theta[j - 1] + wrap(raw - theta[j - 1]);
        }
        if ends.end == EndKind::Clamped {
            reference[n] = clamps.end.orientation.reference();
            theta[n] = clamps.phi;
        }
        let rt = reference_twist_fresh(&nodes, &reference, n);
        let m = theta[n] - theta[n - 1] + rt;
        reference_twist[n] = rt - 2.0 * PI * (m / (2.0 * PI)).round();
        RodState {
            clamps,
            nodes,
            theta,
            reference,
            reference_twist,
            multipliers: Vec::new(),
        }
    }

    /// Straight rod from (0,0,0) to the clamp end point, with the material frame
    /// turning uniformly by φ (a straight twisted rod when δ = 0).
    pub fn straight(n: usize, clamps: Clamps) -> RodState {
        if !clamps.is_paper() {
            return RodState::from_curve(
                n,
                clamps,
                |s| clamps.hermite(s),
                |s| clamps.blended_d1(s),
            );
        }
        let end = clamps.end_point();
        let phi = clamps.phi;
        RodState::from_curve(
            n,
            clamps,
            move |s| end * s,
            move |s| Vector3::new((phi * s).cos(), (phi * s).sin(), 0.0),
        )
    }

    /// Apply a step `dq` on the free dofs: move nodes and angles, transport the
    /// reference frames in time and continue the reference twist.
    pub fn displaced(&self, map: &DofMap, dq: &[f64]) -> RodState {
        let mut next = self.clone();
        self.displace_into(map, dq, &mut next);
        next
    }

    /// As [`Self::displaced`], writing into `next` (which must have this state's shape).
    pub fn displace_into(&self, map: &DofMap, dq: &[f64], next: &mut RodState) {
        self.move_into(map, dq, self.clamps, next);
    }

    /// Move the free dofs by `dq` and the s = 1 clamp to `clamps` in one step,
    /// writing into `next` (same shape): one transport of the frames, no
    /// allocation.
    pub fn move_into(&self, map: &DofMap, dq: &[f64], clamps: Clamps, next: &mut RodState) {
        next.clamps = clamps;
        next.nodes.copy_from_slice(&self.nodes);
        next.theta.copy_from_slice(&self.theta);
        next.multipliers.clone_from(&self.multipliers);
        next.move_clamp_nodes(&self.clamps);
        debug_assert_eq!(
            map.ends, clamps.ends,
            "dof map and clamps disagree on the ends"
        );
        for i in map.free_nodes() {
            let d = map.node(i).unwrap();
            next.nodes[i] += Vector3::new(dq[d], dq[d + 1], dq[d + 2]);
        }
        for j in map.free_angles() {
            next.theta[j] += dq[map.theta(j).unwrap()];
        }
        place_pinned(&mut next.nodes, &clamps);
        next.update_frames_from(self);
        next.set_clamp_angles(self);
    }

    /// Move the four clamp nodes from their place at `old` clamps to this
    /// state's clamps: a translation when the orientation is unchanged (so that
    /// the paper's clamps move exactly as before), else placed afresh.
    fn move_clamp_nodes(&mut self, old: &Clamps) {
        let n = self.segments();
        let c = self.clamps;
        // a pinned end edge translates with its pin (its dof is the offset
        // from the pin); a free one stays
        if c.ends.start == EndKind::Pinned {
            let shift = c.start_point() - old.start_point();
            self.nodes[0] += shift;
            self.nodes[1] += shift;
        }
        if c.ends.end == EndKind::Pinned {
            let shift = c.end_point() - old.end_point();
            self.nodes[n] += shift;
            self.nodes[n + 1] += shift;
        }
        if c.ends.end == EndKind::Clamped {
            if c.end.orientation == old.end.orientation {
                let shift = c.end_point() - old.end_point();
                self.nodes[n] += shift;
                self.nodes[n + 1] += shift;
            } else {
                (self.nodes[n], self.nodes[n + 1]) = clamp_edge(c.end_point(), c.end_tangent(), n);
            }
        }
        if c.ends.start == EndKind::Clamped
            && (c.start.position != old.start.position
                || c.start.orientation != old.start.orientation)
        {
            (self.nodes[0], self.nodes[1]) = clamp_edge(c.start_point(), c.start_tangent(), n);
        }
    }

    /// Material angles of the clamp edges after the reference frames were
    /// transported from `old`: the clamp's turn plus the angle from the
    /// transported reference to the clamp's reference director, continued from
    /// its value at `old` (zero for the paper's clamps, so θ_N = φ exactly).
    fn set_clamp_angles(&mut self, old: &RodState) {
        let n = self.segments();
        let c = self.clamps;
        let o = old.clamps;
        let offset = |state: &RodState, j: usize, orientation: &Orientation, previous: f64| {
            let t = tangent(&state.nodes, j);
            let raw = frames::signed_angle(
                v3(&state.reference[j]),
                v3(&orientation.reference()),
                v3(&t),
            );
            previous + wrap(raw - previous)
        };
        // the angle of a pinned or free end is a dof: it stays
        let before = old.theta[n] - o.phi;
        if c.ends.end == EndKind::Clamped {
            self.theta[n] = c.phi
                + if c.end.orientation == o.end.orientation {
                    before
                } else {
                    offset(self, n, &c.end.orientation, before)
                };
        }
        let before = old.theta[0] - o.start.turn;
        if c.ends.start != EndKind::Clamped {
            return;
        }
        self.theta[0] = c.start.turn
            + if c.start.orientation == o.start.orientation {
                before
            } else {
                offset(self, 0, &c.start.orientation, before)
            };
    }

    /// Time-parallel transport the reference directors from `old` (same N) to
    /// this state's tangents and continue the reference twist.
    pub fn update_frames_from(&mut self, old: &RodState) {
        let n = self.segments();
        let mut t_prev = tangent(&self.nodes, 0);
        self.reference[0] = old.reference[0];
        if self.nodes[..2] != old.nodes[..2] {
            // the s = 0 clamp moved: its reference director is transported too
            let a = transport(&old.reference[0], &tangent(&old.nodes, 0), &t_prev);
            self.reference[0] = (a - a.dot(&t_prev) * t_prev).normalize();
        }
        for j in 1..=n {
            let t_old = tangent(&old.nodes, j);
            let t = tangent(&self.nodes, j);
            let a = transport(&old.reference[j], &t_old, &t);
            self.reference[j] = (a - a.dot(&t) * t).normalize();
            self.reference_twist[j] = reference_twist(
                &self.reference[j - 1],
                &t_prev,
                &self.reference[j],
                &t,
                old.reference_twist[j],
            );
            t_prev = t;
        }
    }

    /// Twist at vertex i: θ_i - θ_{i-1} + reference twist.
    pub fn vertex_twist(&self, i: usize) -> f64 {
        self.theta[i] - self.theta[i - 1] + self.reference_twist[i]
    }

    /// Total twist Tw = (1/2π) ∫ u3 ds.
    pub fn twist(&self) -> f64 {
        (1..=self.segments())
            .map(|i| self.vertex_twist(i))
            .sum::<f64>()
            / (2.0 * PI)
    }

    /// Material directors (d1, d2, d3) of edge j.
    pub fn directors(&self, j: usize) -> [Vector3<f64>; 3] {
        let t = tangent(&self.nodes, j);
        let (d1, d2) = frames::material_directors(v3(&t), v3(&self.reference[j]), self.theta[j]);
        [vec3(d1), vec3(d2), t]
    }

    /// Largest distance between corresponding nodes of two states of one rod.
    pub fn largest_node_distance(&self, other: &RodState) -> f64 {
        self.nodes
            .iter()
            .zip(&other.nodes)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max)
    }

    /// Heights of the interior nodes 1..=N (s in (0,1)) along the s = 0
    /// clamp's tangent, above its point: z for the paper's clamps.
    fn heights(&self) -> Vec<f64> {
        let n = self.segments();
        let interior = &self.nodes[1..=n];
        if self.clamps.start.is_default() && self.clamps.ends.start == EndKind::Clamped {
            return interior.iter().map(|p| p.z).collect();
        }
        let (r0, t0) = (self.start_point(), self.start_axis());
        interior.iter().map(|p| (p - r0).dot(&t0)).collect()
    }

    /// Clearance of the interior extrema of the height from the walls at 0 and
    /// at the s = 1 clamp's height (z = 0 and z = z* for the paper's clamps;
    /// negative: outside; see [`wall_clearance`]).
    pub fn wall_clearance(&self) -> f64 {
        wall_clearance(&self.heights(), self.top_wall())
    }

    /// Interior node heights: (min, max) over nodes 1..=N (s in (0,1)).
    pub fn z_range(&self) -> (f64, f64) {
        self.heights()
            .into_iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| {
                (lo.min(z), hi.max(z))
            })
    }

    /// Walled: every interior node strictly between the walls.
    pub fn walled(&self) -> bool {
        let (lo, hi) = self.z_range();
        lo > 0.0 && hi < self.top_wall()
    }

    /// Move the s = 1 clamp to new parameters: the two clamp nodes translate, the
    /// clamp angle becomes φ; interior dofs are kept.
    pub fn set_clamps(&mut self, clamps: Clamps) {
        let n = self.segments();
        let before = self.clamps;
        let mut old = self.clone();
        self.clamps = clamps;
        self.move_clamp_nodes(&before);
        place_pinned(&mut self.nodes, &clamps);
        if clamps.end.orientation == before.end.orientation {
            // a translated clamp: the frames are transported from the moved
            // nodes, i.e. only the clamp edge's neighbours feel the move
            old.nodes[n] = self.nodes[n];
            old.nodes[n + 1] = self.nodes[n + 1];
        }
        self.update_frames_from(&old);
        self.set_clamp_angles(&old);
    }
}

/// Place a pinned end's ghost node opposite its neighbour across the pin:
/// x_0 = 2 r(0) − x_1, x_{N+1} = 2 r(1) − x_N.
fn place_pinned(nodes: &mut [Vector3<f64>], clamps: &Clamps) {
    let n = nodes.len() - 2;
    if clamps.ends.start == EndKind::Pinned {
        nodes[0] = 2.0 * clamps.start_point() - nodes[1];
    }
    if clamps.ends.end == EndKind::Pinned {
        nodes[n + 1] = 2.0 * clamps.end_point() - nodes[n];
    }
}

/// Reference twist from scratch at vertex i (value in (-π, π]).
fn reference_twist_fresh(nodes: &[Vector3<f64>], reference: &[Vector3<f64>], i: usize) -> f64 {
    reference_twist(
        &reference[i - 1],
        &tangent(nodes, i - 1),
        &reference[i],
        &tangent(nodes, i),
        0.0,
    )
}

/// Wrap an angle into (-π, π].
pub fn wrap(a: f64) -> f64 {
    a - 2.0 * PI * (a / (2.0 * PI)).round()
}

impl RodState {
    /// The centreline as a polyline from r(0) = 0 to r(1) = (x*, y*, z*): the
    /// clamp end points and the nodes 1..=N between them, with arc lengths.
    pub fn centreline(&self) -> (Vec<Vector3<f64>>, Vec<f64>) {
        let n = self.segments();
        let h = 1.0 / n as f64;
        let mut points = Vec::with_capacity(n + 2);
        let mut arc = Vec::with_capacity(n + 2);
        points.push(self.start_point());
        arc.push(0.0);
        for i in 1..=n {
            points.push(self.nodes[i]);
            arc.push((i as f64 - 0.5) * h);
        }
        points.push(self.end_point());
        arc.push(1.0);
        (points, arc)
    }

    /// The rod's end r(0): the clamp's or pin's point, or the midpoint of a
    /// free end edge.
    pub fn start_point(&self) -> Vector3<f64> {
        match self.clamps.ends.start {
            EndKind::Free => 0.5 * (self.nodes[0] + self.nodes[1]),
            _ => self.clamps.start_point(),
        }
    }

    /// The rod's end r(1) (as [`Self::start_point`]).
    pub fn end_point(&self) -> Vector3<f64> {
        let n = self.segments();
        match self.clamps.ends.end {
            EndKind::Free => 0.5 * (self.nodes[n] + self.nodes[n + 1]),
            _ => self.clamps.end_point(),
        }
    }

    /// Tangent at s = 0: the clamp's, or the end edge's where it turns.
    fn start_axis(&self) -> Vector3<f64> {
        match self.clamps.ends.start {
            EndKind::Clamped => self.clamps.start_tangent(),
            _ => tangent(&self.nodes, 0),
        }
    }

    /// Directions of the rays that close the rod: −t(0) from r(0), +t(1)
    /// from r(1), along the clamps or, at a pinned or free end, along the
    /// end edge's actual tangent.
    pub fn ray_directions(&self) -> [Vector3<f64>; 2] {
        let n = self.segments();
        let [mut down, mut up] = self.clamps.ray_directions();
        if self.clamps.ends.start != EndKind::Clamped {
            down = -tangent(&self.nodes, 0);
        }
        if self.clamps.ends.end != EndKind::Clamped {
            up = tangent(&self.nodes, n);
        }
        [down, up]
    }

    /// Height of r(1) above r(0) along t(0): the upper wall (the clamps'
    /// when both are clamped, else measured on the rod's actual ends).
    pub fn top_wall(&self) -> f64 {
        if self.clamps.ends.both_clamped() {
            return self.clamps.top_wall();
        }
        (self.end_point() - self.start_point()).dot(&self.start_axis())
    }
}

/// A scalar of the clamps that a branch, a loading path, a sweep or a map can
/// vary. Angles of turn are measured in turns (φ/2π), tilts in radians.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[serde(rename_all = "snake_case")]
pub enum Parameter {
    /// End displacement z* (height of the s = 1 clamp).
    ZStar,
    /// End shift δ.
    Delta,
    /// End rotation, measured as φ/2π.
    #[serde(alias = "phi_over_2pi")]
    Phi,
    /// x-shift of the s = 1 clamp's point (added to the paper's x*).
    EndX,
    /// y-shift of the s = 1 clamp's point.
    EndY,
    /// Tilt of the s = 1 clamp's tangent (radians).
    EndTilt,
    /// Azimuth of that tilt about e3 (radians).
    EndTiltAzimuth,
    /// x of the s = 0 clamp's point.
    StartX,
    /// y of the s = 0 clamp's point.
    StartY,
    /// z of the s = 0 clamp's point.
    StartZ,
    /// Tilt of the s = 0 clamp's tangent (radians).
    StartTilt,
    /// Azimuth of that tilt about e3 (radians).
    StartTiltAzimuth,
    /// Turn of the s = 0 clamp about its tangent, in turns (/2π).
    #[serde(alias = "start_turn_over_2pi")]
    StartTurn,
    /// K2 = B22/B11 (Kirchhoff law).
    #[serde(rename = "K2", alias = "k2")]
    K2,
    /// K3 = B33/B11.
    #[serde(rename = "K3", alias = "k3")]
    K3,
    /// The weight w L³/B11 along the scene's direction.
    Weight,
    /// Factor on the natural strains û (1: the scene's).
    NaturalScale,
}

impl Parameter {
    /// The model's scalars.
    pub const MODEL: [Parameter; 4] = [
        Parameter::K2,
        Parameter::K3,
        Parameter::Weight,
        Parameter::NaturalScale,
    ];

    /// Whether it is a scalar of the model rather than a clamp coordinate.
    pub fn is_model(&self) -> bool {
        Parameter::MODEL.contains(self)
    }

    /// Whether it moves the s = 1 clamp alone: the rod's equations and its
    /// start are then the same at every value, and only the s = 1
    /// conditions change with it.
    pub fn moves_end_only(&self) -> bool {
        matches!(
            self,
            Parameter::ZStar
                | Parameter::Delta
                | Parameter::Phi
                | Parameter::EndX
                | Parameter::EndY
                | Parameter::EndTilt
                | Parameter::EndTiltAzimuth
        )
    }

    /// Every clamp coordinate, in the order of the scene format's documentation.
    pub const ALL: [Parameter; 13] = [
        Parameter::ZStar,
        Parameter::Delta,
        Parameter::Phi,
        Parameter::EndX,
        Parameter::EndY,
        Parameter::EndTilt,
        Parameter::EndTiltAzimuth,
        Parameter::StartX,
        Parameter::StartY,
        Parameter::StartZ,
        Parameter::StartTilt,
        Parameter::StartTiltAzimuth,
        Parameter::StartTurn,
    ];

    /// Its value for `clamps` (φ as φ/2π).
    pub fn value(&self, c: &Clamps) -> f64 {
        match self {
            Parameter::ZStar => c.z_star,
            Parameter::Delta => c.delta,
            Parameter::Phi => c.phi_over_2pi(),
            Parameter::EndX => c.end.shift[0],
            Parameter::EndY => c.end.shift[1],
            Parameter::EndTilt => c.end.orientation.tilt,
            Parameter::EndTiltAzimuth => c.end.orientation.tilt_azimuth,
            Parameter::StartX => c.start.position.x,
            Parameter::StartY => c.start.position.y,
            Parameter::StartZ => c.start.position.z,
            Parameter::StartTilt => c.start.orientation.tilt,
            Parameter::StartTiltAzimuth => c.start.orientation.tilt_azimuth,
            Parameter::StartTurn => c.start.turn / (2.0 * PI),
            // NaN where the state does not carry it (a scene sets the scalars
            // it varies: `Scene::clamps`)
            Parameter::K2 => c.scalars.k2.unwrap_or(f64::NAN),
            Parameter::K3 => c.scalars.k3.unwrap_or(f64::NAN),
            Parameter::Weight => c.scalars.weight.unwrap_or(f64::NAN),
            Parameter::NaturalScale => c.scalars.natural_scale.unwrap_or(f64::NAN),
        }
    }

    /// `clamps` with this parameter set to `v`.
    pub fn with(&self, c: &Clamps, v: f64) -> Clamps {
        let mut c = *c;
        match self {
            Parameter::ZStar => c.z_star = v,
            Parameter::Delta => c.delta = v,
            Parameter::Phi => c.phi = 2.0 * PI * v,
            Parameter::EndX => c.end.shift[0] = v,
            Parameter::EndY => c.end.shift[1] = v,
            Parameter::EndTilt => c.end.orientation.tilt = v,
            Parameter::EndTiltAzimuth => c.end.orientation.tilt_azimuth = v,
            Parameter::StartX => c.start.position.x = v,
            Parameter::StartY => c.start.position.y = v,
            Parameter::StartZ => c.start.position.z = v,
            Parameter::StartTilt => c.start.orientation.tilt = v,
            Parameter::StartTiltAzimuth => c.start.orientation.tilt_azimuth = v,
            Parameter::StartTurn => c.start.turn = 2.0 * PI * v,
            Parameter::K2 => c.scalars.k2 = Some(v),
            Parameter::K3 => c.scalars.k3 = Some(v),
            Parameter::Weight => c.scalars.weight = Some(v),
            Parameter::NaturalScale => c.scalars.natural_scale = Some(v),
        }
        c
    }

    /// Whether it moves the s = 0 clamp.
    pub fn moves_start(&self) -> bool {
        matches!(
            self,
            Parameter::StartX
                | Parameter::StartY
                | Parameter::StartZ
                | Parameter::StartTilt
                | Parameter::StartTiltAzimuth
                | Parameter::StartTurn
        )
    }

    /// How the clamp dofs of `state` move with the parameter (exact: the
    /// derivative of the clamp nodes and angles at the state's clamps).
    pub fn velocity(&self, state: &RodState) -> ClampVelocity {
        let c = &state.clamps;
        let n = state.segments();
        let half = c.phi / 2.0;
        let z = Vector3::zeros();
        // a rigid rotation ω of a clamp about its point p moves its nodes by
        // ω × (x − p) and, as its reference director is parallel transported,
        // turns its material angle by ω·t
        let rotate = |omega: Vector3<f64>, start: bool| {
            let (p, a, b) = if start {
                (c.start_point(), state.nodes[0], state.nodes[1])
            } else {
                (c.end_point(), state.nodes[n], state.nodes[n + 1])
            };
            let t = (b - a).normalize();
            (omega.cross(&(a - p)), omega.cross(&(b - p)), omega.dot(&t))
        };
        let v = match self {
            Parameter::ZStar => ClampVelocity::end(Vector3::z(), 0.0),
            Parameter::Delta => {
                ClampVelocity::end(Vector3::new(-half.cos(), -half.sin(), 0.0), 0.0)
            }
            Parameter::Phi => ClampVelocity::end(
                Vector3::new(c.delta * PI * half.sin(), -c.delta * PI * half.cos(), 0.0),
                2.0 * PI,
            ),
            Parameter::EndX => ClampVelocity::end(Vector3::x(), 0.0),
            Parameter::EndY => ClampVelocity::end(Vector3::y(), 0.0),
            Parameter::EndTilt | Parameter::EndTiltAzimuth => {
                let k = usize::from(*self == Parameter::EndTiltAzimuth);
                let (a, b, th) = rotate(c.end.orientation.tilt_rates()[k], false);
                ClampVelocity {
                    nodes: [z, z, a, b],
                    theta: [0.0, th],
                }
            }
            Parameter::StartX | Parameter::StartY | Parameter::StartZ => {
                let mut e = Vector3::zeros();
                e[*self as usize - Parameter::StartX as usize] = 1.0;
                ClampVelocity {
                    nodes: [e, e, z, z],
                    theta: [0.0, 0.0],
                }
            }
            Parameter::StartTilt | Parameter::StartTiltAzimuth => {
                let k = usize::from(*self == Parameter::StartTiltAzimuth);
                let (a, b, th) = rotate(c.start.orientation.tilt_rates()[k], true);
                ClampVelocity {
                    nodes: [a, b, z, z],
                    theta: [th, 0.0],
                }
            }
            Parameter::StartTurn => ClampVelocity {
                nodes: [z; 4],
                theta: [2.0 * PI, 0.0],
            },
            // the model's scalars move no clamp (their ∂p∇E is the energy's
            // `parameter_derivative`)
            Parameter::K2 | Parameter::K3 | Parameter::Weight | Parameter::NaturalScale => {
                ClampVelocity::default()
            }
        };
        v.for_ends(c.ends)
    }

    /// Whether it only turns a clamp (its point stays): nothing for a
    /// pinned end, whose frame is free.
    pub fn only_turns(&self) -> bool {
        matches!(
            self,
            Parameter::EndTilt
                | Parameter::EndTiltAzimuth
                | Parameter::StartTilt
                | Parameter::StartTiltAzimuth
                | Parameter::StartTurn
        )
    }

    /// The parameter of a scene name ("phi" is φ/2π's short name).
    pub fn named(name: &str) -> Option<Parameter> {
        Parameter::ALL
            .iter()
            .chain(Parameter::MODEL.iter())
            .copied()
            .find(|p| p.name() == name || (name == "phi" && *p == Parameter::Phi))
    }

    /// Name as in scenes and summaries.
    pub fn name(&self) -> &'static str {
        match self {
            Parameter::ZStar => "z_star",
            Parameter::Delta => "delta",
            Parameter::Phi => "phi_over_2pi",
            Parameter::EndX => "end_x",
            Parameter::EndY => "end_y",
            Parameter::EndTilt => "end_tilt",
            Parameter::EndTiltAzimuth => "end_tilt_azimuth",
            Parameter::StartX => "start_x",
            Parameter::StartY => "start_y",
            Parameter::StartZ => "start_z",
            Parameter::StartTilt => "start_tilt",
            Parameter::StartTiltAzimuth => "start_tilt_azimuth",
            Parameter::StartTurn => "start_turn_over_2pi",
            Parameter::K2 => "K2",
            Parameter::K3 => "K3",
            Parameter::Weight => "weight",
            Parameter::NaturalScale => "natural_scale",
        }
    }

    /// The symbol a figure's axis carries (the paper's: φ/2π, z*, δ).
    pub fn symbol(&self) -> &'static str {
        match self {
            Parameter::Phi => "φ/2π",
            Parameter::ZStar => "z*",
            Parameter::Delta => "δ",
            other => other.name(),
        }
    }
}

/// Serde of a [`Parameter`] by its scene name ([`Parameter::name`]), the
/// spelling of map files (`#[serde(with = "parameter_by_name")]`).
pub mod parameter_by_name {
    use super::Parameter;
    use serde::{Deserialize, Deserializer, Serializer, de::Error};

    /// Write the parameter's name.
    pub fn serialize<S: Serializer>(p: &Parameter, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(p.name())
    }

    /// Read a parameter from its name.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Parameter, D::Error> {
        let name = String::deserialize(d)?;
        Parameter::named(&name)
            .ok_or_else(|| D::Error::custom(format!("unknown parameter {name:?}")))
    }
}

/// Ranges keyed by parameter, written keyed by the parameters' names (a
/// bounding box in map files: `#[serde(with = "ranges_by_name")]`).
pub mod ranges_by_name {
    use super::Parameter;
    use serde::{Deserialize, Deserializer, Serializer, de::Error, ser::SerializeMap};
    use std::collections::BTreeMap;

    /// Write {name: [lo, hi]}.
    pub fn serialize<S: Serializer>(
        ranges: &BTreeMap<Parameter, [f64; 2]>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(ranges.len()))?;
        for (p, r) in ranges {
            map.serialize_entry(p.name(), r)?;
        }
        map.end()
    }

    /// Read {name: [lo, hi]}.
    pub fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<BTreeMap<Parameter, [f64; 2]>, D::Error> {
        BTreeMap::<String, [f64; 2]>::deserialize(d)?
            .into_iter()
            .map(|(name, r)| {
                Parameter::named(&name)
                    .map(|p| (p, r))
                    .ok_or_else(|| D::Error::custom(format!("unknown parameter {name:?}")))
            })
            .collect()
    }
}
