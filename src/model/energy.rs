//! Elastic energy of the discrete Kirchhoff rod (discrete elastic rods form) and
//! its exact gradient and Hessian.
//!
//! Each term is a small stencil function generic over the scalar; derivatives are
//! exact, by forward-mode automatic differentiation with (hyper-)dual numbers of
//! the stencil (11 variables at a vertex, 6 at an edge), then scattered into a
//! sparse Hessian of fixed pattern. Reference directors of the two edges of a
//! vertex follow the perturbation by time-parallel transport, and the reference
//! twist is continued from its stored value, exactly as the state update does,
//! so these derivatives are those of the energy along the solver's own steps.

use crate::model::frames::{self, Scalar, V3, lift};
use crate::model::rod::{DofMap, Law, RodModel, RodState, tangent};
use crate::solve::sparse::{NO_SLOT, SymmetricPattern};
use nalgebra::{SVector, Vector3};

/// Which energy terms to include.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Terms {
    /// Bending, 1/2 ∫ (u1² + K2 u2²).
    pub bending: bool,
    /// Twisting, 1/2 ∫ K3 u3².
    pub twisting: bool,
    /// Stretching penalty, 1/2 ∫ S (|r'| - 1)².
    pub stretching: bool,
}

impl Terms {
    /// All terms.
    pub const ALL: Terms = Terms {
        bending: true,
        twisting: true,
        stretching: true,
    };
    /// Bending only.
    pub const BENDING: Terms = Terms {
        bending: true,
        twisting: false,
        stretching: false,
    };
    /// Twisting only.
    pub const TWISTING: Terms = Terms {
        bending: false,
        twisting: true,
        stretching: false,
    };
    /// Stretching only.
    pub const STRETCHING: Terms = Terms {
        bending: false,
        twisting: false,
        stretching: true,
    };
}

/// The frozen frame data of a vertex stencil at the current state.
#[derive(Clone, Copy, Debug)]
pub struct VertexFrames {
    a_prev: Vector3<f64>,
    t_prev: Vector3<f64>,
    a: Vector3<f64>,
    t: Vector3<f64>,
    reference_twist: f64,
}

impl VertexFrames {
    /// Frames of vertex i (between edges i-1 and i).
    pub fn at(state: &RodState, i: usize) -> Self {
        VertexFrames {
            a_prev: state.reference[i - 1],
            t_prev: tangent(&state.nodes, i - 1),
            a: state.reference[i],
            t: tangent(&state.nodes, i),
            reference_twist: state.reference_twist[i],
        }
    }
}

/// Local variables of vertex i: its two edges e_{i-1}, e_i and angles
/// θ_{i-1}, θ_i (the energy depends on the nodes only through the edges, so
/// derivatives are taken in these 8 variables and mapped to the 11 node ones).
pub fn vertex_variables(state: &RodState, i: usize) -> [f64; 8] {
    let mut q = [0.0; 8];
    q[0..3].copy_from_slice((state.nodes[i] - state.nodes[i - 1]).as_slice());
    q[3..6].copy_from_slice((state.nodes[i + 1] - state.nodes[i]).as_slice());
    q[6] = state.theta[i - 1];
    q[7] = state.theta[i];
    q
}

/// Local variable of edge j: the edge vector x_{j+1} - x_j.
pub fn edge_variables(state: &RodState, j: usize) -> [f64; 3] {
    let e = state.nodes[j + 1] - state.nodes[j];
    [e.x, e.y, e.z]
}

/// Node-variable index (x_{i-1}, x_i, x_{i+1}, θ_{i-1}, θ_i: 11) → list of
/// (edge-variable index, coefficient) with e_{i-1} = x_i − x_{i−1}, e_i = x_{i+1} − x_i.
fn vertex_chain(a: usize) -> [(usize, f64); 2] {
    match a {
        0..=2 => [(a, -1.0), (usize::MAX, 0.0)],
        3..=5 => [(a - 3, 1.0), (a, -1.0)],
        6..=8 => [(a - 3, 1.0), (usize::MAX, 0.0)],
        9 => [(6, 1.0), (usize::MAX, 0.0)],
        _ => [(7, 1.0), (usize::MAX, 0.0)],
    }
}

/// Map an 8-variable gradient to the 11 node variables.
fn vertex_gradient_to_nodes(g8: &[f64]) -> [f64; 11] {
    let mut g = [0.0; 11];
    for (a, ga) in g.iter_mut().enumerate() {
        for &(k, alpha) in vertex_chain(a).iter().filter(|c| c.0 != usize::MAX) {
            *ga += alpha * g8[k];
        }
    }
    g
}

/// Map an 8-variable gradient and Hessian to the 11 node variables.
fn vertex_to_nodes(g8: &[f64], h8: &[f64]) -> ([f64; 11], [f64; 121]) {
    let mut g = [0.0; 11];
    let mut h = [0.0; 121];
    for a in 0..11 {
        for &(i, alpha) in vertex_chain(a).iter().filter(|c| c.0 != usize::MAX) {
            g[a] += alpha * g8[i];
            for b in 0..11 {
                for &(j, beta) in vertex_chain(b).iter().filter(|c| c.0 != usize::MAX) {
                    h[a * 11 + b] += alpha * beta * h8[i * 8 + j];
                }
            }
        }
    }
    (g, h)
}

struct VertexGeometry<T> {
    /// Integrated curvature binormal 2 t0 × t1 / (1 + t0·t1) ≈ h (u1 d1 + u2 d2).
    kb: V3<T>,
    t1: V3<T>,
    a0: V3<T>,
    a1: V3<T>,
    t0: V3<T>,
}

fn vertex_geometry<T: Scalar>(q: &[T], c: &VertexFrames) -> VertexGeometry<T> {
    let e0 = [q[0], q[1], q[2]];
    let e1 = [q[3], q[4], q[5]];
    let t0 = frames::scale(frames::norm(e0).recip(), e0);
    let t1 = frames::scale(frames::norm(e1).recip(), e1);
    let a0 = frames::parallel_transport(lift(&c.a_prev), lift(&c.t_prev), t0);
    let a1 = frames::parallel_transport(lift(&c.a), lift(&c.t), t1);
    let kb = frames::scale(
        (frames::dot(t0, t1) + 1.0).recip() * 2.0,
        frames::cross(t0, t1),
    );
    VertexGeometry { kb, t1, a0, a1, t0 }
}

/// Bending energy at one vertex: (κ1² + K2 κ2²) / (2h), with κ the integrated
/// curvature binormal projected on the averaged material directors.
pub fn bending_energy<T: Scalar>(q: &[T], c: &VertexFrames, model: &RodModel) -> T {
    let g = vertex_geometry(q, c);
    bending_from(&g, q, model)
}

fn bending_from<T: Scalar>(g: &VertexGeometry<T>, q: &[T], model: &RodModel) -> T {
    let (d1a, d2a) = frames::material_directors(g.t0, g.a0, q[6]);
    let (d1b, d2b) = frames::material_directors(g.t1, g.a1, q[7]);
    let k1 = frames::dot(g.kb, frames::add(d1a, d1b)) * 0.5;
    let k2 = frames::dot(g.kb, frames::add(d2a, d2b)) * 0.5;
    (k1 * k1 + k2 * k2 * model.k2) * (0.5 / model.segment_length())
}

/// Twist at one vertex: θ_i - θ_{i-1} + reference twist (continued from the
/// stored value through time-parallel transport).
pub fn vertex_twist<T: Scalar>(q: &[T], c: &VertexFrames) -> T {
    let g = vertex_geometry(q, c);
    twist_from(&g, q, c)
}

fn twist_from<T: Scalar>(g: &VertexGeometry<T>, q: &[T], c: &VertexFrames) -> T {
    let r = T::from(c.reference_twist);
    let ut = frames::parallel_transport(g.a0, g.t0, g.t1);
    let ut = frames::rotate_about(ut, g.t1, r);
    let reference = r + frames::signed_angle(ut, g.a1, g.t1);
    q[7] - q[6] + reference
}

/// Twisting energy at one vertex: K3 m² / (2h).
pub fn twisting_energy<T: Scalar>(q: &[T], c: &VertexFrames, model: &RodModel) -> T {
    let m = vertex_twist(q, c);
    m * m * (0.5 * model.k3 / model.segment_length())
}

/// Stretching energy of one edge (variables: the edge vector): S h/2 (|e|/h - 1)².
pub fn stretching_energy<T: Scalar>(q: &[T], model: &RodModel) -> T {
    let h = model.segment_length();
    let e = [q[0], q[1], q[2]];
    let strain = frames::norm(e) * (1.0 / h) - 1.0;
    strain * strain * (0.5 * model.stretching_stiffness * h)
}

/// Material curvatures at one vertex: integrated κ1 = h u1 and κ2 = h u2 (the
/// curvature binormal on the averaged material directors).
fn material_curvatures<T: Scalar>(g: &VertexGeometry<T>, q: &[T]) -> (T, T) {
    let (d1a, d2a) = frames::material_directors(g.t0, g.a0, q[6]);
    let (d1b, d2b) = frames::material_directors(g.t1, g.a1, q[7]);
    (
        frames::dot(g.kb, frames::add(d1a, d1b)) * 0.5,
        frames::dot(g.kb, frames::add(d2a, d2b)) * 0.5,
    )
}

/// Material curvatures and twist rate (u1, u2, u3) at vertex i.
pub fn vertex_strains(state: &RodState, i: usize) -> [f64; 3] {
    let c = VertexFrames::at(state, i);
    let q = vertex_variables(state, i);
    let g = vertex_geometry(&q, &c);
    let (k1, k2) = material_curvatures(&g, &q);
    let m = twist_from(&g, &q, &c);
    let h = 1.0 / state.segments() as f64;
    [k1 / h, k2 / h, m / h]
}

/// Integrated curvature κ2 = h u2 about d2 at one vertex: the strip's
/// constraint function (u2 = 0).
pub fn normal_curvature<T: Scalar>(q: &[T], c: &VertexFrames) -> T {
    let g = vertex_geometry(q, c);
    material_curvatures(&g, q).1
}

/// Sadowsky energy of a strip at one vertex, h/2 (u1² + u3²)² / (u1² + ε²),
/// from the integrated curvature κ1 = h u1 and twist m = h u3.
pub fn strip_energy<T: Scalar>(k1: T, m: T, regularisation: f64, h: f64) -> T {
    let a = k1 * k1 + m * m;
    a * a / ((k1 * k1 + (regularisation * h).powi(2)) * (2.0 * h))
}

/// Multiplier λ of vertex i's constraint κ2 = 0 and the penalty ρ of the
/// augmented Lagrangian E + Σ (λ κ2 + ρ/2 κ2²).
#[derive(Clone, Copy, Debug)]
pub struct VertexMultiplier {
    /// λ_i.
    pub lambda: f64,
    /// ρ.
    pub penalty: f64,
}

fn vertex_energy<T: Scalar>(
    q: &[T],
    c: &VertexFrames,
    model: &RodModel,
    terms: Terms,
    multiplier: Option<VertexMultiplier>,
) -> T {
    let g = vertex_geometry(q, c);
    let h = model.segment_length();
    let (k1, k2) = material_curvatures(&g, q);
    let mut e = T::from(0.0);
    match model.law {
        Law::Strip { regularisation } => {
            // bending and twisting do not separate in the strip law
            if terms.bending || terms.twisting {
                let m = twist_from(&g, q, c);
                e += strip_energy(k1, m, regularisation, h);
            }
        }
        law => {
            if terms.bending {
                let k2_stiffness = if law == Law::Kirchhoff { model.k2 } else { 0.0 };
                e += (k1 * k1 + k2 * k2 * k2_stiffness) * (0.5 / h);
            }
            if terms.twisting {
                let m = twist_from(&g, q, c);
                e += m * m * (0.5 * model.k3 / h);
            }
        }
    }
    if let Some(w) = multiplier {
        e += k2 * (k2 * (0.5 * w.penalty) + w.lambda);
    }
    e
}

/// Gradient of the energy with respect to every node and angle, clamps included.
#[derive(Clone, Debug)]
pub struct FullGradient {
    /// ∂E/∂x_i for every node.
    pub nodes: Vec<Vector3<f64>>,
    /// ∂E/∂θ_j for every edge.
    pub theta: Vec<f64>,
}

/// Energy, gradient and Hessian evaluator for one rod model and dof layout.
#[derive(Clone, Debug)]
pub struct RodEnergy {
    /// The rod's parameters.
    pub model: RodModel,
    /// Free dofs.
    pub map: DofMap,
    /// Which terms are included.
    pub terms: Terms,
    /// Hessian pattern: stencils are the N vertices then the N-2 free edges 1..N-1.
    pub pattern: SymmetricPattern,
    /// Constrained laws: the penalty ρ of the augmented Lagrangian
    /// E + Σ (λ_i κ2_i + ρ/2 κ2_i²) evaluated in their place (λ from the
    /// state). With ρ = PENALTY / h its Hessian has the inertia of the Hessian
    /// reduced to the constraint tangent space, and its lowest eigenvalues
    /// agree with the reduced ones to O(1/ρ).
    pub penalty: Option<f64>,
}

/// Penalty of the augmented Lagrangian in units of 1/h: that of a Kirchhoff
/// rod with K2 = PENALTY.
pub const PENALTY: f64 = 1e4;

/// Result of a gradient evaluation.
#[derive(Clone, Copy, Debug)]
pub struct GradientInfo {
    /// Energy.
    pub energy: f64,
    /// Norm of all stencil gradient contributions before they cancel: the scale of
    /// the internal forces, used to make the residual relative.
    pub force_scale: f64,
}

impl RodEnergy {
    /// Evaluator for `model` with all energy terms.
    pub fn new(model: RodModel) -> Self {
        Self::with_terms(model, Terms::ALL)
    }

    /// Evaluator restricted to some energy terms.
    pub fn with_terms(model: RodModel, terms: Terms) -> Self {
        let map = DofMap { n: model.segments };
        let n = model.segments;
        let mut stencils: Vec<Vec<Option<usize>>> = Vec::with_capacity(2 * n);
        for i in 1..=n {
            stencils.push(map.vertex_stencil(i).to_vec());
        }
        for j in 1..n {
            stencils.push(map.edge_stencil(j).to_vec());
        }
        let pattern = SymmetricPattern::from_stencils(map.len(), &stencils);
        let penalty = model
            .law
            .constrained()
            .then(|| PENALTY / model.segment_length());
        RodEnergy {
            model,
            map,
            terms,
            pattern,
            penalty,
        }
    }

    /// The multiplier term of vertex i, if the law is constrained.
    fn multiplier(&self, state: &RodState, i: usize) -> Option<VertexMultiplier> {
        self.penalty.map(|penalty| VertexMultiplier {
            lambda: state.multipliers.get(i).copied().unwrap_or(0.0),
            penalty,
        })
    }

    /// The constraints κ2_i = h u2_i (i = 1..=N) and their gradients on the
    /// 11 node variables of vertex i's stencil.
    pub fn constraint_rows(&self, state: &RodState) -> Vec<(f64, [f64; 11])> {
        let mut rows = Vec::with_capacity(self.model.segments);
        self.constraint_rows_into(state, &mut rows);
        rows
    }

    /// As [`Self::constraint_rows`], into `rows` (its allocation reused).
    pub fn constraint_rows_into(&self, state: &RodState, rows: &mut Vec<(f64, [f64; 11])>) {
        rows.clear();
        rows.extend((1..=self.model.segments).map(|i| {
            let c = VertexFrames::at(state, i);
            let q = SVector::<f64, 8>::from(vertex_variables(state, i));
            let (v, g8) =
                num_dual::gradient(|v: SVector<_, 8>| normal_curvature(v.as_slice(), &c), &q);
            (v, vertex_gradient_to_nodes(g8.as_slice()))
        }));
    }

    /// Total energy.
    pub fn energy(&self, state: &RodState) -> f64 {
        let n = self.model.segments;
        let mut e = 0.0;
        if self.terms.bending || self.terms.twisting {
            for i in 1..=n {
                let q = vertex_variables(state, i);
                e += vertex_energy(
                    &q,
                    &VertexFrames::at(state, i),
                    &self.model,
                    self.terms,
                    self.multiplier(state, i),
                );
            }
        }
        if self.terms.stretching {
            for j in 1..n {
                e += stretching_energy(&edge_variables(state, j), &self.model);
            }
        }
        e
    }

    /// Energy, node-variable gradient and Hessian (row-major 11×11) of the
    /// bending and twisting at vertex i.
    pub fn vertex_local(&self, state: &RodState, i: usize) -> (f64, [f64; 11], [f64; 121]) {
        let c = VertexFrames::at(state, i);
        let w = self.multiplier(state, i);
        let q = SVector::<f64, 8>::from(vertex_variables(state, i));
        let (e, g8, h8) = num_dual::hessian(
            |v: SVector<_, 8>| vertex_energy(v.as_slice(), &c, &self.model, self.terms, w),
            &q,
        );
        let (g, h) = vertex_to_nodes(g8.as_slice(), h8.as_slice());
        (e, g, h)
    }

    /// Energy, node-variable gradient and Hessian (row-major 6×6) of the
    /// stretching of edge j.
    pub fn edge_local(&self, state: &RodState, j: usize) -> (f64, [f64; 6], [f64; 36]) {
        let q = SVector::<f64, 3>::from(edge_variables(state, j));
        let (e, g3, h3) = num_dual::hessian(
            |v: SVector<_, 3>| stretching_energy(v.as_slice(), &self.model),
            &q,
        );
        let mut g = [0.0; 6];
        let mut h = [0.0; 36];
        for a in 0..3 {
            g[a] = -g3[a];
            g[3 + a] = g3[a];
            for b in 0..3 {
                let v = h3[(a, b)];
                h[a * 6 + b] = v;
                h[(3 + a) * 6 + 3 + b] = v;
                h[a * 6 + 3 + b] = -v;
                h[(3 + a) * 6 + b] = -v;
            }
        }
        (e, g, h)
    }

    fn vertex_gradient(&self, state: &RodState, i: usize) -> (f64, [f64; 11]) {
        let c = VertexFrames::at(state, i);
        let w = self.multiplier(state, i);
        let q = SVector::<f64, 8>::from(vertex_variables(state, i));
        let (e, g8) = num_dual::gradient(
            |v: SVector<_, 8>| vertex_energy(v.as_slice(), &c, &self.model, self.terms, w),
            &q,
        );
        (e, vertex_gradient_to_nodes(g8.as_slice()))
    }

    fn edge_gradient(&self, state: &RodState, j: usize) -> (f64, [f64; 6]) {
        let h = self.model.segment_length();
        let e = state.nodes[j + 1] - state.nodes[j];
        let len = e.norm();
        // S h/2 (|e|/h - 1)²: gradient S (|e|/h - 1) e/|e| on x_{j+1}
        let f = self.model.stretching_stiffness * (len / h - 1.0) / len;
        let energy = 0.5 * self.model.stretching_stiffness * h * (len / h - 1.0).powi(2);
        (
            energy,
            [-f * e.x, -f * e.y, -f * e.z, f * e.x, f * e.y, f * e.z],
        )
    }

    /// Gradient with respect to all nodes and angles (clamp dofs included).
    pub fn full_gradient(&self, state: &RodState) -> FullGradient {
        let n = self.model.segments;
        let mut g = FullGradient {
            nodes: vec![Vector3::zeros(); n + 2],
            theta: vec![0.0; n + 1],
        };
        if self.terms.bending || self.terms.twisting {
            for i in 1..=n {
                let (_, gl) = self.vertex_gradient(state, i);
                for k in 0..3 {
                    g.nodes[i - 1 + k] += Vector3::new(gl[3 * k], gl[3 * k + 1], gl[3 * k + 2]);
                }
                g.theta[i - 1] += gl[9];
                g.theta[i] += gl[10];
            }
        }
        if self.terms.stretching {
            for j in 1..n {
                let (_, gl) = self.edge_gradient(state, j);
                g.nodes[j] += Vector3::new(gl[0], gl[1], gl[2]);
                g.nodes[j + 1] += Vector3::new(gl[3], gl[4], gl[5]);
            }
        }
        g
    }

    /// Gradient on the free dofs (into `grad`), with energy and force scale.
    pub fn gradient(&self, state: &RodState, grad: &mut [f64]) -> GradientInfo {
        let n = self.model.segments;
        grad.iter_mut().for_each(|v| *v = 0.0);
        let (mut energy, mut scale2) = (0.0, 0.0);
        if self.terms.bending || self.terms.twisting {
            for i in 1..=n {
                let (e, gl) = self.vertex_gradient(state, i);
                energy += e;
                scale2 += scatter(&self.map.vertex_stencil(i), &gl, grad);
            }
        }
        if self.terms.stretching {
            for j in 1..n {
                let (e, gl) = self.edge_gradient(state, j);
                energy += e;
                scale2 += scatter(&self.map.edge_stencil(j), &gl, grad);
            }
        }
        GradientInfo {
            energy,
            force_scale: scale2.sqrt(),
        }
    }

    /// Gradient and Hessian (upper values on `self.pattern`) on the free dofs.
    /// The stencils are evaluated in parallel, then scattered in order (so the
    /// result does not depend on the number of threads).
    pub fn hessian(&self, state: &RodState, grad: &mut [f64], values: &mut [f64]) -> GradientInfo {
        use rayon::prelude::*;
        let n = self.model.segments;
        grad.iter_mut().for_each(|v| *v = 0.0);
        values.iter_mut().for_each(|x| *x = 0.0);
        let (mut energy, mut scale2) = (0.0, 0.0);
        if self.terms.bending || self.terms.twisting {
            let local: Vec<(f64, [f64; 11], [f64; 121])> = (1..n + 1)
                .into_par_iter()
                .with_min_len(16)
                .map(|i| self.vertex_local(state, i))
                .collect();
            for (k, (e, gl, hl)) in local.iter().enumerate() {
                let i = k + 1;
                energy += e;
                scale2 += scatter(&self.map.vertex_stencil(i), gl, grad);
                scatter_hessian(&self.pattern.slots[i - 1], 11, hl, values);
            }
        }
        if self.terms.stretching {
            for j in 1..n {
                let (e, gl, hl) = self.edge_local(state, j);
                energy += e;
                scale2 += scatter(&self.map.edge_stencil(j), &gl, grad);
                scatter_hessian(&self.pattern.slots[n + j - 1], 6, &hl, values);
            }
        }
        GradientInfo {
            energy,
            force_scale: scale2.sqrt(),
        }
    }
}

/// Add a stencil gradient into the free gradient; returns its squared norm.
fn scatter(dofs: &[Option<usize>], local: &[f64], grad: &mut [f64]) -> f64 {
    let mut s = 0.0;
    for (d, g) in dofs.iter().zip(local) {
        if let Some(d) = d {
            grad[*d] += g;
            s += g * g;
        }
    }
    s
}

/// Add a stencil Hessian (column-major m×m) into the upper-triangle values.
fn scatter_hessian(slots: &[usize], m: usize, local: &[f64], values: &mut [f64]) {
    // slots are row-major (a, b); each unordered pair lands once in the upper
    // triangle, so take a <= b in global order: both (a,b) and (b,a) map to the
    // same slot, add only one of them (the diagonal once).
    for a in 0..m {
        for b in a..m {
            let s = slots[a * m + b];
            if s != NO_SLOT {
                values[s] += local[b * m + a];
            }
        }
    }
}

/// Force n(0) and moment m(0) at s = 0 (components in the material frame there,
/// which is the lab frame): the internal force and moment that the rod s > 0
/// exerts across s = 0, i.e. minus the derivative of the energy with respect to
/// a rigid translation and rotation (about the origin) of the s = 0 clamp.
#[derive(Clone, Copy, Debug)]
pub struct ClampReactions {
    /// n(0).
    pub force: Vector3<f64>,
    /// m(0).
    pub moment: Vector3<f64>,
}

impl RodEnergy {
    /// Internal force and moment at s = 0 from the discrete solution.
    pub fn clamp_reactions(&self, state: &RodState) -> ClampReactions {
        let g = self.full_gradient(state);
        let force = -(g.nodes[0] + g.nodes[1]);
        // a rotation ω moves clamp nodes by ω × x and turns the clamp's frame by
        // ω; about e3 that is a change of θ_0 (for ω ⟂ e3 time-parallel transport
        // of the clamp's reference director is the rigid rotation to first order)
        let moment = -(state.nodes[0].cross(&g.nodes[0])
            + state.nodes[1].cross(&g.nodes[1])
            + g.theta[0] * Vector3::z());
        ClampReactions { force, moment }
    }

    /// Lumped mass of each free dof: the segment length for node coordinates,
    /// zero for material angles (no rotational inertia, as in the paper).
    pub fn lumped_mass(&self) -> Vec<f64> {
        let h = self.model.segment_length();
        (0..self.map.len())
            .map(|d| if self.map.is_translation(d) { h } else { 0.0 })
            .collect()
    }
}

impl RodEnergy {
    /// Velocity of vertex i's 11 stencil variables (nodes i-1, i, i+1, angles
    /// i-1, i) when the s = 1 clamp moves with `velocity`.
    fn clamp_local_velocity(&self, i: usize, velocity: &ClampVelocity) -> [f64; 11] {
        let n = self.model.segments;
        let mut vel = [0.0; 11];
        for (k, node) in [i - 1, i, i + 1].into_iter().enumerate() {
            if node >= n {
                vel[3 * k..3 * k + 3].copy_from_slice(velocity.end.as_slice());
            }
        }
        if i == n {
            vel[10] = velocity.theta;
        }
        vel
    }

    /// ∂κ2_i/∂p for every constraint row (from `constraint_rows`) when the
    /// s = 1 clamp moves with `velocity`: nonzero at the last two vertices.
    pub fn constraint_parameter_derivative(
        &self,
        rows: &[(f64, [f64; 11])],
        velocity: &ClampVelocity,
        out: &mut [f64],
    ) {
        let n = self.model.segments;
        out.iter_mut().for_each(|v| *v = 0.0);
        for i in [n - 1, n] {
            let vel = self.clamp_local_velocity(i, velocity);
            out[i - 1] = rows[i - 1].1.iter().zip(&vel).map(|(g, v)| g * v).sum();
        }
    }
}

/// Velocity of the s = 1 clamp's dofs with respect to a loading parameter:
/// both clamp nodes translate by `end`, the clamp angle turns by `theta`.
#[derive(Clone, Copy, Debug)]
pub struct ClampVelocity {
    /// d(end point)/dp.
    pub end: Vector3<f64>,
    /// dφ/dp.
    pub theta: f64,
}

impl RodEnergy {
    /// ∂(∇E)/∂p on the free dofs when the s = 1 clamp moves with `velocity`:
    /// the mixed second derivatives (free × clamp dofs) of the three stencils
    /// that touch the clamp, applied to the clamp's velocity.
    pub fn gradient_parameter_derivative(
        &self,
        state: &RodState,
        velocity: &ClampVelocity,
        out: &mut [f64],
    ) {
        let n = self.model.segments;
        out.iter_mut().for_each(|v| *v = 0.0);
        let e = velocity.end;
        if self.terms.bending || self.terms.twisting {
            for i in [n - 1, n] {
                let (_, _, hl) = self.vertex_local(state, i);
                let vel = self.clamp_local_velocity(i, velocity);
                for (a, d) in self.map.vertex_stencil(i).iter().enumerate() {
                    if let Some(d) = d {
                        out[*d] += (0..11).map(|b| hl[a * 11 + b] * vel[b]).sum::<f64>();
                    }
                }
            }
        }
        if self.terms.stretching {
            let j = n - 1;
            let (_, _, hl) = self.edge_local(state, j);
            let vel = [0.0, 0.0, 0.0, e.x, e.y, e.z];
            for (a, d) in self.map.edge_stencil(j).iter().enumerate() {
                if let Some(d) = d {
                    out[*d] += (0..6).map(|b| hl[a * 6 + b] * vel[b]).sum::<f64>();
                }
            }
        }
    }
}
