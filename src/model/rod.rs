//! The discrete Kirchhoff rod: parameters, clamps, degrees of freedom and state.
//!
//! Discretisation (N segments, h = 1/N): nodes x_0..x_{N+1} at arc lengths
//! s = (i - 1/2) h, edges e_j = x_{j+1} - x_j centred at s = j h. Edge 0 and edge
//! N are the clamps: each is centred on its end point, half outside the rod, so
//! that the N interior vertices (1..=N, curvature and twist) sample [0, 1] by the
//! midpoint rule and the scheme stays second order. Fixed: nodes 0, 1, N, N+1
//! and the material angles of edges 0 and N.

use crate::geometry::walls::wall_clearance;
use crate::model::frames::{self, V3};
use crate::model::natural::NaturalStrains;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Velocity of the s = 1 clamp's dofs with respect to a loading parameter:
/// both clamp nodes translate by `end`, the clamp angle turns by `theta`.
#[derive(Clone, Copy, Debug)]
pub struct ClampVelocity {
    /// d(end point)/dp.
    pub end: Vector3<f64>,
    /// dφ/dp.
    pub theta: f64,
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

/// The clamp at s = 1 (the clamp at s = 0 is the identity frame at the origin).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct Clamps {
    /// End displacement z*.
    pub z_star: f64,
    /// End shift δ along the flip axis (eq. 2.13).
    pub delta: f64,
    /// End rotation φ in radians, continuous (turns are kept).
    pub phi: f64,
}

impl Clamps {
    /// From (z*, δ, φ/2π).
    pub fn new(z_star: f64, delta: f64, phi_over_2pi: f64) -> Self {
        Clamps {
            z_star,
            delta,
            phi: 2.0 * PI * phi_over_2pi,
        }
    }

    /// φ / 2π.
    pub fn phi_over_2pi(&self) -> f64 {
        self.phi / (2.0 * PI)
    }

    /// End point (x*, y*, z*) = (-δ cos φ/2, -δ sin φ/2, z*) (eq. 2.13).
    pub fn end_point(&self) -> Vector3<f64> {
        Vector3::new(
            -self.delta * (self.phi / 2.0).cos(),
            -self.delta * (self.phi / 2.0).sin(),
            self.z_star,
        )
    }
}

/// Index map between the rod's nodes/angles and the free degrees of freedom.
/// Free dofs are interleaved (θ_j, x_{j+1}) so that the Hessian is banded.
#[derive(Clone, Copy, Debug)]
pub struct DofMap {
    /// Number of segments N.
    pub n: usize,
}

impl DofMap {
    /// Number of free degrees of freedom: 3(N-2) positions + (N-1) angles.
    pub fn len(&self) -> usize {
        4 * self.n - 7
    }

    /// Never empty (N >= 4).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// First dof of node i, if free.
    pub fn node(&self, i: usize) -> Option<usize> {
        (2..self.n).contains(&i).then(|| 4 * (i - 2) + 1)
    }

    /// Dof of the material angle of edge j, if free.
    pub fn theta(&self, j: usize) -> Option<usize> {
        (1..self.n).contains(&j).then(|| 4 * (j - 1))
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

    /// Whether dof `d` is a translational one (a node coordinate).
    pub fn is_translation(&self, d: usize) -> bool {
        !d.is_multiple_of(4)
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
        let mut nodes: Vec<Vector3<f64>> = (0..n + 2).map(|i| r((i as f64 - 0.5) * h)).collect();
        nodes[0] = -0.5 * h * e3;
        nodes[1] = 0.5 * h * e3;
        nodes[n] = end - 0.5 * h * e3;
        nodes[n + 1] = end + 0.5 * h * e3;
        // space-parallel reference frames from the s = 0 clamp; zero reference
        // twist in between
        let mut reference = vec![Vector3::x(); n + 1];
        for j in 1..n {
            let a = transport(
                &reference[j - 1],
                &tangent(&nodes, j - 1),
                &tangent(&nodes, j),
            );
            // re-orthonormalise against round-off drift
            let t = tangent(&nodes, j);
            reference[j] = (a - a.dot(&t) * t).normalize();
        }
        reference[n] = Vector3::x();
        let mut reference_twist = vec![0.0; n + 1];
        let mut theta = vec![0.0; n + 1];
        for j in 1..n {
            let t = tangent(&nodes, j);
            let a1 = reference[j];
            let a2 = t.cross(&a1);
            let d = d1(j as f64 * h);
            let raw = d.dot(&a2).atan2(d.dot(&a1));
            theta[j] = theta[j - 1] + wrap(raw - theta[j - 1]);
        }
        theta[n] = clamps.phi;
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
        let n = self.segments();
        next.clamps = clamps;
        next.nodes.copy_from_slice(&self.nodes);
        next.theta.copy_from_slice(&self.theta);
        next.multipliers.clone_from(&self.multipliers);
        let shift = clamps.end_point() - self.clamps.end_point();
        next.nodes[n] += shift;
        next.nodes[n + 1] += shift;
        next.theta[n] = clamps.phi;
        for i in 2..n {
            let d = map.node(i).unwrap();
            next.nodes[i] += Vector3::new(dq[d], dq[d + 1], dq[d + 2]);
        }
        for j in 1..n {
            next.theta[j] += dq[map.theta(j).unwrap()];
        }
        next.update_frames_from(self);
    }

    /// Time-parallel transport the reference directors from `old` (same N) to
    /// this state's tangents and continue the reference twist.
    pub fn update_frames_from(&mut self, old: &RodState) {
        let n = self.segments();
        let mut t_prev = tangent(&self.nodes, 0);
        self.reference[0] = old.reference[0];
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

    /// Clearance of the interior extrema of z from the walls z = 0 and z = z*
    /// (negative: outside; see [`wall_clearance`]).
    pub fn wall_clearance(&self) -> f64 {
        // the interior nodes 1..=N are the centreline without its clamp ends
        let n = self.segments();
        let heights: Vec<f64> = self.nodes[1..=n].iter().map(|p| p.z).collect();
        wall_clearance(&heights, self.clamps.z_star)
    }

    /// Interior node heights: (min z, max z) over nodes 1..=N (s in (0,1)).
    pub fn z_range(&self) -> (f64, f64) {
        let n = self.segments();
        self.nodes[1..=n]
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x[2]), hi.max(x[2]))
            })
    }

    /// Walled: every interior node strictly between the planes z = 0 and z = z*.
    pub fn walled(&self) -> bool {
        let (lo, hi) = self.z_range();
        lo > 0.0 && hi < self.clamps.z_star
    }

    /// Move the s = 1 clamp to new parameters: the two clamp nodes translate, the
    /// clamp angle becomes φ; interior dofs are kept.
    pub fn set_clamps(&mut self, clamps: Clamps) {
        let n = self.segments();
        let shift = clamps.end_point() - self.clamps.end_point();
        self.nodes[n] += shift;
        self.nodes[n + 1] += shift;
        let old = self.clone();
        self.theta[n] = clamps.phi;
        self.clamps = clamps;
        self.update_frames_from(&old);
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
        points.push(Vector3::zeros());
        arc.push(0.0);
        for i in 1..=n {
            points.push(self.nodes[i]);
            arc.push((i as f64 - 0.5) * h);
        }
        points.push(self.clamps.end_point());
        arc.push(1.0);
        (points, arc)
    }
}

/// A loading parameter of the s = 1 clamp.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Parameter {
    /// End displacement z*.
    ZStar,
    /// End shift δ.
    Delta,
    /// End rotation, measured as φ/2π.
    #[serde(alias = "phi_over_2pi")]
    Phi,
}

impl Parameter {
    /// Its value for `clamps` (φ as φ/2π).
    pub fn value(&self, c: &Clamps) -> f64 {
        match self {
            Parameter::ZStar => c.z_star,
            Parameter::Delta => c.delta,
            Parameter::Phi => c.phi_over_2pi(),
        }
    }

    /// `clamps` with this parameter set to `v`.
    pub fn with(&self, c: &Clamps, v: f64) -> Clamps {
        let mut c = *c;
        match self {
            Parameter::ZStar => c.z_star = v,
            Parameter::Delta => c.delta = v,
            Parameter::Phi => c.phi = 2.0 * PI * v,
        }
        c
    }

    /// How the clamp's dofs move with the parameter.
    pub fn velocity(&self, c: &Clamps) -> ClampVelocity {
        let half = c.phi / 2.0;
        let (end, theta) = match self {
            Parameter::ZStar => (Vector3::z(), 0.0),
            Parameter::Delta => (Vector3::new(-half.cos(), -half.sin(), 0.0), 0.0),
            Parameter::Phi => (
                Vector3::new(c.delta * PI * half.sin(), -c.delta * PI * half.cos(), 0.0),
                2.0 * PI,
            ),
        };
        ClampVelocity { end, theta }
    }

    /// Name as in summaries.
    pub fn name(&self) -> &'static str {
        match self {
            Parameter::ZStar => "z_star",
            Parameter::Delta => "delta",
            Parameter::Phi => "phi_over_2pi",
        }
    }
}
