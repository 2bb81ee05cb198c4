//! Elastic energy of the discrete Kirchhoff rod (discrete elastic rods form) and
//! its exact gradient and Hessian.
//!
//! Each term is a small stencil function generic over the scalar; derivatives are
//! exact and scattered into a sparse Hessian of fixed pattern. At a vertex (8
//! variables: two edges, two angles) the strains' gradients and Hessians are
//! in closed form ([`crate::model::strain_hessian`]) and the law's derivatives
//! in the three strains come from a small jet, so every law shares the chain
//! rule; jets of the whole stencil remain its fallback and the tests' oracle.
//! An edge's stretching (3 variables) is differentiated by jets. Reference
//! directors of the two edges of a vertex follow the perturbation by
//! time-parallel transport, and the reference twist is continued from its
//! stored value, exactly as the state update does, so these derivatives are
//! those of the energy along the solver's own steps.

use crate::linalg::jet::{self, Grad, Jet3, Jet4, Jet8};
use crate::linalg::sparse::{NO_SLOT, SymmetricPattern};
use crate::model::frames::{self, Scalar, V3, lift};
use crate::model::rod::{
    ClampVelocity, Clamps, DofMap, EndKind, Ends, Law, RodModel, RodState, tangent,
};
use crate::model::strain_hessian::{self, QuaternionDerivatives, VertexChart};
use nalgebra::Vector3;

/// Which energy terms to include.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Terms {
    /// Bending, 1/2 ∫ (u1² + K2 u2²).
    pub bending: bool,
    /// Twisting, 1/2 ∫ K3 u3².
    pub twisting: bool,
    /// Stretching penalty, 1/2 ∫ S (|r'| - 1)².
    pub stretching: bool,
    /// The weight, −∫ w g·r ds.
    pub gravity: bool,
}

impl Terms {
    /// All terms.
    pub const ALL: Terms = Terms {
        bending: true,
        twisting: true,
        stretching: true,
        gravity: true,
    };
    /// Bending only.
    pub const BENDING: Terms = Terms {
        bending: true,
        twisting: false,
        stretching: false,
        gravity: false,
    };
    /// Twisting only.
    pub const TWISTING: Terms = Terms {
        bending: false,
        twisting: true,
        stretching: false,
        gravity: false,
    };
    /// Stretching only.
    pub const STRETCHING: Terms = Terms {
        bending: false,
        twisting: false,
        stretching: true,
        gravity: false,
    };
    /// The weight only.
    pub const GRAVITY: Terms = Terms {
        bending: false,
        twisting: false,
        stretching: false,
        gravity: true,
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

/// Map an 8-variable gradient (e_{i-1}, e_i, θ_{i-1}, θ_i) to the 11 node
/// variables (x_{i-1}, x_i, x_{i+1}, θ_{i-1}, θ_i), with e_{i-1} = x_i − x_{i−1}
/// and e_i = x_{i+1} − x_i.
fn vertex_gradient_to_nodes(g8: &[f64]) -> [f64; 11] {
    let mut g = [0.0; 11];
    for c in 0..3 {
        g[c] = -g8[c];
        g[3 + c] = g8[c] - g8[3 + c];
        g[6 + c] = g8[3 + c];
    }
    g[9] = g8[6];
    g[10] = g8[7];
    g
}

/// Map an 8-variable gradient and Hessian to the 11 node variables.
fn vertex_to_nodes(g8: &[f64], h8: &[f64]) -> ([f64; 11], [f64; 121]) {
    // e_{i-1} = x_i − x_{i−1}, e_i = x_{i+1} − x_i: node block k of the
    // Hessian is Σ c_a c_b H8[edge a][edge b] over the edges at each node
    let g = vertex_gradient_to_nodes(g8);
    let mut h = [0.0; 121];
    // edge-space 3×3 blocks (E0,E0), (E0,E1), (E1,E1) and the angle rows
    let block = |p: usize, q: usize, r: usize, c: usize| h8[(3 * p + r) * 8 + 3 * q + c];
    for r in 0..3 {
        for c in 0..3 {
            let (a, b, d) = (block(0, 0, r, c), block(0, 1, r, c), block(1, 1, r, c));
            let b_t = block(1, 0, r, c);
            // node blocks (x_{i-1}, x_i, x_{i+1}) with coefficients (−1, 0) (1, −1) (0, 1)
            let at = |i: usize, j: usize| (i * 3 + r) * 11 + j * 3 + c;
            h[at(0, 0)] = a;
            h[at(0, 1)] = -a + b;
            h[at(0, 2)] = -b;
            h[at(1, 0)] = -a + b_t;
            h[at(1, 1)] = a - b - b_t + d;
            h[at(1, 2)] = b - d;
            h[at(2, 0)] = -b_t;
            h[at(2, 1)] = b_t - d;
            h[at(2, 2)] = d;
        }
    }
    for (t, row) in [(9, 6), (10, 7)] {
        for (u, col) in [(9, 6), (10, 7)] {
            h[t * 11 + u] = h8[row * 8 + col];
        }
        for c in 0..3 {
            let (e0, e1) = (h8[row * 8 + c], h8[row * 8 + 3 + c]);
            for (node, v) in [(0, -e0), (1, e0 - e1), (2, e1)] {
                h[t * 11 + node * 3 + c] = v;
                h[(node * 3 + c) * 11 + t] = v;
            }
        }
    }
    (g, h)
}

/// What one edge of a vertex stencil contributes: its tangent, reference
/// director (time-parallel transported from the stored one) and material
/// directors.
#[derive(Clone, Copy)]
struct EdgeFrame<T> {
    t: V3<T>,
    a: V3<T>,
    d1: V3<T>,
    d2: V3<T>,
    theta: T,
}

/// Unit tangent of edge vector `e` and the reference director transported to
/// it from the stored (a_ref, t_ref).
fn tangent_and_reference<T: Scalar>(
    e: V3<T>,
    a_ref: &Vector3<f64>,
    t_ref: &Vector3<f64>,
) -> (V3<T>, V3<T>) {
    let t = frames::scale(frames::norm(e).recip(), e);
    (t, frames::parallel_transport(lift(a_ref), lift(t_ref), t))
}

impl<T: Scalar> EdgeFrame<T> {
    fn of(e: V3<T>, theta: T, a_ref: &Vector3<f64>, t_ref: &Vector3<f64>) -> Self {
        let (t, a) = tangent_and_reference(e, a_ref, t_ref);
        let (d1, d2) = frames::material_directors(t, a, theta);
        EdgeFrame {
            t,
            a,
            d1,
            d2,
            theta,
        }
    }
}

/// The two edge frames of vertex i from its variables (e_{i-1}, e_i, θ_{i-1}, θ_i).
fn edge_frames<T: Scalar>(q: &[T], c: &VertexFrames) -> [EdgeFrame<T>; 2] {
    [
        EdgeFrame::of([q[0], q[1], q[2]], q[6], &c.a_prev, &c.t_prev),
        EdgeFrame::of([q[3], q[4], q[5]], q[7], &c.a, &c.t),
    ]
}

/// Integrated curvature binormal 2 t0 × t1 / (1 + t0·t1).
fn curvature_binormal<T: Scalar>(t0: V3<T>, t1: V3<T>) -> V3<T> {
    frames::scale(
        (frames::dot(t0, t1) + 1.0).recip() * 2.0,
        frames::cross(t0, t1),
    )
}

/// Reference twist between the edges (t0, a0) and (t1, a1), continued from
/// its stored value `r` (the angle from a0 transported to t1 and turned by r,
/// to a1, is small).
fn reference_twist<T: Scalar>(t0: V3<T>, a0: V3<T>, t1: V3<T>, a1: V3<T>, r: f64) -> T {
    let ut = frames::parallel_transport(a0, t0, t1);
    let (s, c) = r.sin_cos();
    let ut = frames::add(
        frames::scale(T::from(c), ut),
        frames::scale(T::from(s), frames::cross(t1, ut)),
    );
    frames::signed_angle(ut, a1, t1) + r
}

/// Integrated strains of a vertex: κ1 = h u1, κ2 = h u2 (the curvature
/// binormal on the averaged material directors) and the twist m = h u3.
#[derive(Clone, Copy)]
struct Strains<T> {
    k1: T,
    k2: T,
    m: T,
}

fn strains<T: Scalar>(f: &[EdgeFrame<T>; 2], c: &VertexFrames) -> Strains<T> {
    let kb = curvature_binormal(f[0].t, f[1].t);
    let reference = reference_twist(f[0].t, f[0].a, f[1].t, f[1].a, c.reference_twist);
    Strains {
        k1: frames::dot(kb, frames::add(f[0].d1, f[1].d1)) * 0.5,
        k2: frames::dot(kb, frames::add(f[0].d2, f[1].d2)) * 0.5,
        m: f[1].theta - f[0].theta + reference,
    }
}

/// [`strains`] as jets in the 8 stencil variables, each intermediate
/// differentiated only in the variables it depends on: tangents and reference
/// directors in their edge's 3, material directors in 4 (edge and angle), the
/// curvature binormal and reference twist in the 6 of both edges.
fn strain_jets(q: [f64; 8], c: &VertexFrames) -> Strains<Jet8> {
    const EDGE: [[usize; 3]; 2] = [[0, 1, 2], [3, 4, 5]];
    const EDGE_AND_ANGLE: [[usize; 4]; 2] = [[0, 1, 2, 6], [3, 4, 5, 7]];
    const BOTH: [usize; 6] = [0, 1, 2, 3, 4, 5];
    // embeddings write in place: these jets are large and moving them costs
    // more than the arithmetic
    let zero8 = Jet8::from(0.0);
    let zero6 = jet::Jet6::from(0.0);
    let zero4 = Jet4::from(0.0);
    let refs = [(&c.a_prev, &c.t_prev), (&c.a, &c.t)];
    let (mut t6, mut a6) = ([[zero6; 3]; 2], [[zero6; 3]; 2]);
    let (mut d1, mut d2) = ([zero8; 3], [zero8; 3]);
    for k in 0..2 {
        let e = [0, 1, 2].map(|j| Jet3::variable(q[EDGE[k][j]], j));
        let (t, a) = tangent_and_reference(e, refs[k].0, refs[k].1);
        let (mut t4, mut a4) = ([zero4; 3], [zero4; 3]);
        for j in 0..3 {
            t[j].embed_into(&mut t4[j], [0, 1, 2]);
            a[j].embed_into(&mut a4[j], [0, 1, 2]);
            t[j].embed_into(&mut t6[k][j], EDGE[k]);
            a[j].embed_into(&mut a6[k][j], EDGE[k]);
        }
        let (e1, e2) = frames::material_directors(t4, a4, Jet4::variable(q[6 + k], 3));
        for j in 0..3 {
            let (mut x1, mut x2) = (zero8, zero8);
            e1[j].embed_into(&mut x1, EDGE_AND_ANGLE[k]);
            e2[j].embed_into(&mut x2, EDGE_AND_ANGLE[k]);
            d1[j] += x1;
            d2[j] += x2;
        }
    }
    let kb6 = curvature_binormal(t6[0], t6[1]);
    let mut kb = [zero8; 3];
    for j in 0..3 {
        kb6[j].embed_into(&mut kb[j], BOTH);
    }
    let mut m = Jet8::variable(q[7], 7) - Jet8::variable(q[6], 6);
    let mut reference = zero8;
    reference_twist(t6[0], a6[0], t6[1], a6[1], c.reference_twist).embed_into(&mut reference, BOTH);
    m += reference;
    Strains {
        k1: frames::dot(kb, d1) * 0.5,
        k2: frames::dot(kb, d2) * 0.5,
        m,
    }
}

/// Stretching energy of one edge (variables: the edge vector): S h/2 (|e|/h - 1)².
pub fn stretching_energy<T: Scalar>(q: &[T], model: &RodModel) -> T {
    let h = model.segment_length();
    let e = [q[0], q[1], q[2]];
    let strain = frames::norm(e) * (1.0 / h) - 1.0;
    strain * strain * (0.5 * model.stretching_stiffness * h)
}

/// Material curvatures and twist rate (u1, u2, u3) at vertex i.
pub fn vertex_strains(state: &RodState, i: usize) -> [f64; 3] {
    let c = VertexFrames::at(state, i);
    let u = strains(&edge_frames(&vertex_variables(state, i), &c), &c);
    let h = 1.0 / state.segments() as f64;
    [u.k1 / h, u.k2 / h, u.m / h]
}

/// Integrated curvature κ2 = h u2 about d2 at one vertex: the strip's
/// constraint function (u2 = 0).
pub fn normal_curvature<T: Scalar>(q: &[T], c: &VertexFrames) -> T {
    strains(&edge_frames(q, c), c).k2
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

/// Bending and twisting energy (or the strip's, or the augmented
/// Lagrangian's) at vertex i, from its variables, with the natural strains
/// `natural` there.
pub fn vertex_energy<T: Scalar>(
    q: &[T],
    c: &VertexFrames,
    (model, natural): (&RodModel, [f64; 3]),
    terms: Terms,
    multiplier: Option<VertexMultiplier>,
) -> T {
    energy_of_strains(
        strains(&edge_frames(q, c), c),
        (model, natural),
        terms,
        multiplier,
    )
}

/// Energy and gradient of [`vertex_energy`]: ∂E/∂s through the closed-form
/// strain gradients, or by jets of the stencil where those do not apply.
fn vertex_energy_gradient(
    q: [f64; 8],
    c: &VertexFrames,
    model: (&RodModel, [f64; 3]),
    terms: Terms,
    multiplier: Option<VertexMultiplier>,
) -> (f64, [f64; 8]) {
    let Some((s, chart)) = vertex_chart(&q, c) else {
        return jet::gradient(q, |v| vertex_energy(v, c, model, terms, multiplier));
    };
    let strains = Strains {
        k1: Grad::<3>::variable(s.k1, 0),
        k2: Grad::<3>::variable(s.k2, 1),
        m: Grad::<3>::variable(s.m, 2),
    };
    let e = energy_of_strains(strains, model, terms, multiplier);
    let mut g_q = [0.0; 4];
    for (a, g) in chart.strain_gradients().iter().enumerate() {
        for r in 0..4 {
            g_q[r] += e.g[a] * g[r];
        }
    }
    (e.v, chart.gradient(&g_q))
}

/// How far a stored reference director may be from unit length and from
/// normal to its stored tangent, and an edge from its stored tangent, for the
/// closed-form derivatives. The rod's own frame update keeps all three at
/// round-off; a state edited by hand (nodes moved, frames not transported)
/// is differentiated by jets instead.
const CHART_TOLERANCE: f64 = 1e-10;

/// The strains at vertex variables `q` and the chart of their closed-form
/// derivatives ([`strain_hessian`]), or `None` where its assumption (unit
/// reference directors normal to the edges, edges at the stored tangents)
/// does not hold.
fn vertex_chart(q: &[f64; 8], c: &VertexFrames) -> Option<(Strains<f64>, VertexChart)> {
    let f = edge_frames(q, c);
    let stored = [(&c.a_prev, &c.t_prev), (&c.a, &c.t)];
    for (k, (a, t)) in stored.into_iter().enumerate() {
        let drift = (Vector3::from(f[k].t) - t).norm_squared();
        if a.dot(t).abs() > CHART_TOLERANCE
            || (a.norm_squared() - 1.0).abs() > CHART_TOLERANCE
            || drift > CHART_TOLERANCE * CHART_TOLERANCE
        {
            return None;
        }
    }
    let frame = |k: usize| strain_hessian::EdgeFrame {
        d1: Vector3::from(f[k].d1),
        d2: Vector3::from(f[k].d2),
        t: Vector3::from(f[k].t),
        length: frames::norm([q[3 * k], q[3 * k + 1], q[3 * k + 2]]),
    };
    Some((strains(&f, c), VertexChart::new([frame(0), frame(1)])))
}

/// The strains as the three independent variables of a [`Jet3`], so that
/// [`energy_of_strains`] gives ∂E/∂s and ∂²E/∂s² for every law.
fn strain_variables(s: Strains<f64>) -> Strains<Jet3> {
    Strains {
        k1: Jet3::variable(s.k1, 0),
        k2: Jet3::variable(s.k2, 1),
        m: Jet3::variable(s.m, 2),
    }
}

/// Energy, gradient and Hessian of [`vertex_energy`]: the chain rule
/// H = Jᵀ ∂²E/∂s² J + Σ ∂E/∂s_a ∇²s_a through the closed-form strain
/// derivatives, or through [`strain_jets`] where those do not apply.
fn vertex_energy_hessian(
    q: [f64; 8],
    c: &VertexFrames,
    model: (&RodModel, [f64; 3]),
    terms: Terms,
    multiplier: Option<VertexMultiplier>,
) -> (f64, [f64; 8], [[f64; 8]; 8]) {
    let Some((s, chart)) = vertex_chart(&q, c) else {
        return vertex_energy_hessian_by_jets(q, c, model, terms, multiplier);
    };
    let e = energy_of_strains(strain_variables(s), model, terms, multiplier);
    let d = QuaternionDerivatives::compose(&chart.strains(), e.g, e.dense_hessian());
    let (g, h) = chart.hessian(&d);
    (e.v, g, h)
}

/// [`vertex_energy_hessian`] by jets of the whole stencil: the fallback, and
/// the tests' oracle.
fn vertex_energy_hessian_by_jets(
    q: [f64; 8],
    c: &VertexFrames,
    model: (&RodModel, [f64; 3]),
    terms: Terms,
    multiplier: Option<VertexMultiplier>,
) -> (f64, [f64; 8], [[f64; 8]; 8]) {
    let e = energy_of_strains(strain_jets(q, c), model, terms, multiplier);
    (e.v, e.g, e.dense_hessian())
}

fn energy_of_strains<T: Scalar>(
    u: Strains<T>,
    (model, natural): (&RodModel, [f64; 3]),
    terms: Terms,
    multiplier: Option<VertexMultiplier>,
) -> T {
    let h = model.segment_length();
    let mut e = T::from(0.0);
    match model.law {
        Law::Strip { regularisation } => {
            // bending and twisting do not separate in the strip law
            if terms.bending || terms.twisting {
                // the law of u1 − û1 (the model's definition of a naturally
                // curved strip); û1 = 0 leaves the operations of a straight one
                let k1 = if natural[0] != 0.0 {
                    u.k1 - T::from(natural[0] * h)
                } else {
                    u.k1
                };
                e += strip_energy(k1, u.m, regularisation, h);
            }
        }
        law => {
            // strains relative to the natural ones (integrated over h)
            let [n1, n2, n3] = natural.map(|v| T::from(v * h));
            if terms.bending {
                let k2_stiffness = if law == Law::Kirchhoff { model.k2 } else { 0.0 };
                let (a1, a2) = (u.k1 - n1, u.k2 - n2);
                e += (a1 * a1 + a2 * a2 * k2_stiffness) * (0.5 / h);
            }
            if terms.twisting {
                let a3 = u.m - n3;
                e += a3 * a3 * (0.5 * model.k3 / h);
            }
        }
    }
    if let Some(w) = multiplier {
        e += u.k2 * (u.k2 * (0.5 * w.penalty) + w.lambda);
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
    /// Hessian pattern: stencils are the N vertices then the stretched edges
    /// (1..N-1 between two clamps, the end edges too at a pinned or free end).
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
        Self::with_ends(model, terms, Ends::CLAMPED)
    }

    /// Evaluator for a rod with these boundary conditions (the states it
    /// evaluates must have them: `state.clamps.ends`).
    pub fn with_ends(model: RodModel, terms: Terms, ends: Ends) -> Self {
        let map = DofMap {
            n: model.segments,
            ends,
        };
        let n = model.segments;
        let mut stencils: Vec<Vec<Option<usize>>> = Vec::with_capacity(2 * n + 2);
        for i in 1..=n {
            stencils.push(map.vertex_stencil(i).to_vec());
        }
        for j in map.stretched_edges() {
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

    /// The natural strains at vertex i (s = (i − ½)h).
    pub fn natural_at(&self, i: usize) -> [f64; 3] {
        natural_at(&self.model, i)
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
            let q = vertex_variables(state, i);
            let (v, g8) = match vertex_chart(&q, &c) {
                Some((s, chart)) => (s.k2, chart.gradient(&chart.strain_gradients()[1])),
                None => jet::gradient(q, |v| normal_curvature(v, &c)),
            };
            (v, vertex_gradient_to_nodes(&g8))
        }));
    }

    /// Total energy.
    pub fn energy(&self, state: &RodState) -> f64 {
        let n = self.model.segments;
        let model = self.model_at(state);
        let mut e = 0.0;
        if self.terms.bending || self.terms.twisting {
            for i in 1..=n {
                let q = vertex_variables(state, i);
                e += vertex_energy(
                    &q,
                    &VertexFrames::at(state, i),
                    (&*model, natural_at(&model, i)),
                    self.terms,
                    self.multiplier(state, i),
                );
            }
        }
        if self.terms.stretching {
            for j in self.map.stretched_edges() {
                let w = self.map.edge_weight(j);
                e += w * stretching_energy(&edge_variables(state, j), &self.model);
            }
        }
        if self.terms.gravity {
            e += self.gravity_energy(state, &model);
        }
        e
    }

    /// The weight's potential energy −∫ w g·r ds, by the midpoint rule on
    /// the nodes x_1..x_N (node i stands for s ∈ [(i−1)h, ih]).
    pub fn gravity_energy(&self, state: &RodState, model: &RodModel) -> f64 {
        let w = Vector3::from(model.weight);
        let h = self.model.segment_length();
        -h * (1..=self.model.segments)
            .map(|i| w.dot(&state.nodes[i]))
            .sum::<f64>()
    }

    /// The weight's force on node i (its gradient is −h w g on each of
    /// x_1..x_N, its Hessian zero).
    fn gravity_gradient(&self, model: &RodModel) -> Vector3<f64> {
        -self.model.segment_length() * Vector3::from(model.weight)
    }

    /// Add the weight's gradient on the free translations; returns its
    /// squared norm (for the force scale).
    fn scatter_gravity(&self, grad: &mut [f64], model: &RodModel) -> f64 {
        let g = self.gravity_gradient(model);
        let mut scale2 = 0.0;
        if g == Vector3::zeros() {
            return 0.0;
        }
        for i in 1..=self.model.segments {
            if let Some(d) = self.map.node(i) {
                for k in 0..3 {
                    grad[d + k] += g[k];
                    scale2 += g[k] * g[k];
                }
            }
        }
        scale2
    }

    /// Energy, node-variable gradient and Hessian (row-major 11×11) of the
    /// bending and twisting at vertex i.
    pub fn vertex_local(&self, state: &RodState, i: usize) -> (f64, [f64; 11], [f64; 121]) {
        let model = self.model_at(state);
        self.vertex_local_with(state, i, &model)
    }

    /// As [`Self::vertex_local`] with the model (and its scalars) given.
    fn vertex_local_with(
        &self,
        state: &RodState,
        i: usize,
        model: &RodModel,
    ) -> (f64, [f64; 11], [f64; 121]) {
        let (e, g8, h8) = self.vertex_hessian8(state, i, model);
        let (g, h) = vertex_to_nodes(&g8, h8.as_flattened());
        (e, g, h)
    }

    /// Energy, gradient and Hessian of vertex i in its 8 variables
    /// (e_{i-1}, e_i, θ_{i-1}, θ_i).
    pub(crate) fn vertex_hessian8(
        &self,
        state: &RodState,
        i: usize,
        model: &RodModel,
    ) -> (f64, [f64; 8], [[f64; 8]; 8]) {
        vertex_energy_hessian(
            vertex_variables(state, i),
            &VertexFrames::at(state, i),
            (model, natural_at(model, i)),
            self.terms,
            self.multiplier(state, i),
        )
    }

    /// Add vertex i's gradient and Hessian in its 8 variables to the free
    /// gradient and the Hessian values; returns the squared norm of its node
    /// gradient. The upper triangle of the node Hessian is formed entry by
    /// entry as it is scattered (no 11×11 block in between); a stencil with
    /// a pinned end's ghost node takes the general path through
    /// [`Self::fold_pinned`].
    fn scatter_vertex(
        &self,
        i: usize,
        g8: &[f64; 8],
        h8: &[[f64; 8]; 8],
        grad: &mut [f64],
        values: &mut [f64],
    ) -> f64 {
        let slots = &self.pattern.slots[i - 1];
        if self.map.pinned_block(&[i - 1, i, i + 1]).is_some() {
            let (mut gl, mut hl) = vertex_to_nodes(g8, h8.as_flattened());
            self.fold_pinned(&[i - 1, i, i + 1], &mut gl, Some(&mut hl));
            scatter_hessian(slots, 11, &hl, values);
            return scatter(&self.map.vertex_stencil(i), &gl, grad);
        }
        // node variable a = Σ c v over its (8-variable v, coefficient c) pairs:
        // e_{i-1} = x_i − x_{i−1}, e_i = x_{i+1} − x_i
        const NODE_TERMS: [[(usize, f64); 2]; 11] = [
            [(0, -1.0), (0, 0.0)],
            [(1, -1.0), (1, 0.0)],
            [(2, -1.0), (2, 0.0)],
            [(0, 1.0), (3, -1.0)],
            [(1, 1.0), (4, -1.0)],
            [(2, 1.0), (5, -1.0)],
            [(3, 1.0), (3, 0.0)],
            [(4, 1.0), (4, 0.0)],
            [(5, 1.0), (5, 0.0)],
            [(6, 1.0), (6, 0.0)],
            [(7, 1.0), (7, 0.0)],
        ];
        for a in 0..11 {
            let [(u0, c0), (u1, c1)] = NODE_TERMS[a];
            for b in a..11 {
                let s = slots[a * 11 + b];
                if s != NO_SLOT {
                    let [(v0, d0), (v1, d1)] = NODE_TERMS[b];
                    values[s] += c0 * (d0 * h8[u0][v0] + d1 * h8[u0][v1])
                        + c1 * (d0 * h8[u1][v0] + d1 * h8[u1][v1]);
                }
            }
        }
        scatter(
            &self.map.vertex_stencil(i),
            &vertex_gradient_to_nodes(g8),
            grad,
        )
    }

    /// Energy, node-variable gradient and Hessian (row-major 6×6) of the
    /// stretching of edge j.
    /// An end edge (at a pinned or free end) counts half: see
    /// [`DofMap::edge_weight`].
    pub fn edge_local(&self, state: &RodState, j: usize) -> (f64, [f64; 6], [f64; 36]) {
        let w = self.map.edge_weight(j);
        let (e, g3, h3) = jet::hessian::<3, 6>(edge_variables(state, j), |v| {
            let e = stretching_energy(v, &self.model);
            if w == 1.0 { e } else { e * w }
        });
        let mut g = [0.0; 6];
        let mut h = [0.0; 36];
        for a in 0..3 {
            g[a] = -g3[a];
            g[3 + a] = g3[a];
            for b in 0..3 {
                let v = h3[a][b];
                h[a * 6 + b] = v;
                h[(3 + a) * 6 + 3 + b] = v;
                h[a * 6 + 3 + b] = -v;
                h[(3 + a) * 6 + b] = -v;
            }
        }
        (e, g, h)
    }

    /// Energy and node-variable gradient of the bending and twisting at
    /// vertex i.
    fn vertex_gradient(&self, state: &RodState, i: usize, model: &RodModel) -> (f64, [f64; 11]) {
        let (e, g8) = vertex_energy_gradient(
            vertex_variables(state, i),
            &VertexFrames::at(state, i),
            (model, natural_at(model, i)),
            self.terms,
            self.multiplier(state, i),
        );
        (e, vertex_gradient_to_nodes(&g8))
    }

    /// The model at `state`: its own, with the scalars the state sets (a
    /// branch in K3 or in the weight).
    pub fn model_at(&self, state: &RodState) -> std::borrow::Cow<'_, RodModel> {
        let scalars = &state.clamps.scalars;
        if scalars.is_unset() {
            std::borrow::Cow::Borrowed(&self.model)
        } else {
            std::borrow::Cow::Owned(scalars.apply(&self.model))
        }
    }

    /// Add Σ Δp ∂p∇E over the model's scalars that change from the state's
    /// clamps to `target` (the clamps' own move is `Clamps::velocity_to`).
    pub fn add_scalar_changes(&self, state: &RodState, target: &Clamps, out: &mut [f64]) {
        let n = out.len();
        let mut d = Vec::new();
        let mut work = Vec::new();
        for p in crate::model::rod::Parameter::MODEL {
            let (a, b) = (p.value(&state.clamps), p.value(target));
            if a.is_finite() && b.is_finite() && a != b {
                d.resize(n, 0.0);
                work.resize(n, 0.0);
                self.parameter_derivative(state, p, &mut d, &mut work);
                out.iter_mut().zip(&d).for_each(|(o, v)| *o += (b - a) * v);
            }
        }
    }

    /// ∂(∇E)/∂p on the free dofs for any parameter: the clamps' mixed
    /// Hessian applied to their velocity, or for a scalar of the model the
    /// gradient at p = 1 less the gradient at p = 0 (∇E is affine in K2, K3,
    /// the weight and the scale of û); `work` is scratch of the same length.
    pub fn parameter_derivative(
        &self,
        state: &RodState,
        parameter: crate::model::rod::Parameter,
        out: &mut [f64],
        work: &mut [f64],
    ) {
        if !parameter.is_model() {
            self.gradient_parameter_derivative(state, &parameter.velocity(state), out);
            return;
        }
        let at = |v: f64| parameter.with(&state.clamps, v).scalars.apply(&self.model);
        self.gradient_with(state, &at(1.0), out);
        self.gradient_with(state, &at(0.0), work);
        for (o, w) in out.iter_mut().zip(work.iter()) {
            *o -= w;
        }
    }

    fn edge_gradient(&self, state: &RodState, j: usize) -> (f64, [f64; 6]) {
        let h = self.model.segment_length();
        let e = state.nodes[j + 1] - state.nodes[j];
        let len = e.norm();
        // S h/2 (|e|/h - 1)²: gradient S (|e|/h - 1) e/|e| on x_{j+1}
        let mut f = self.model.stretching_stiffness * (len / h - 1.0) / len;
        let mut energy = 0.5 * self.model.stretching_stiffness * h * (len / h - 1.0).powi(2);
        let w = self.map.edge_weight(j);
        if w != 1.0 {
            f *= w;
            energy *= w;
        }
        (
            energy,
            [-f * e.x, -f * e.y, -f * e.z, f * e.x, f * e.y, f * e.z],
        )
    }

    /// Gradient with respect to all nodes and angles (clamp dofs included).
    pub fn full_gradient(&self, state: &RodState) -> FullGradient {
        let n = self.model.segments;
        let model = self.model_at(state);
        let mut g = FullGradient {
            nodes: vec![Vector3::zeros(); n + 2],
            theta: vec![0.0; n + 1],
        };
        if self.terms.bending || self.terms.twisting {
            for i in 1..=n {
                let (_, gl) = self.vertex_gradient(state, i, &model);
                for k in 0..3 {
                    g.nodes[i - 1 + k] += Vector3::new(gl[3 * k], gl[3 * k + 1], gl[3 * k + 2]);
                }
                g.theta[i - 1] += gl[9];
                g.theta[i] += gl[10];
            }
        }
        if self.terms.stretching {
            for j in self.map.stretched_edges() {
                let (_, gl) = self.edge_gradient(state, j);
                g.nodes[j] += Vector3::new(gl[0], gl[1], gl[2]);
                g.nodes[j + 1] += Vector3::new(gl[3], gl[4], gl[5]);
            }
        }
        if self.terms.gravity {
            let w = self.gravity_gradient(&model);
            for x in &mut g.nodes[1..=n] {
                *x += w;
            }
        }
        g
    }

    /// Gradient on the free dofs (into `grad`), with energy and force scale.
    pub fn gradient(&self, state: &RodState, grad: &mut [f64]) -> GradientInfo {
        self.gradient_with(state, &self.model_at(state), grad)
    }

    /// As [`Self::gradient`] with the model's scalars of `model`.
    fn gradient_with(&self, state: &RodState, model: &RodModel, grad: &mut [f64]) -> GradientInfo {
        let n = self.model.segments;
        grad.iter_mut().for_each(|v| *v = 0.0);
        let (mut energy, mut scale2) = (0.0, 0.0);
        if self.terms.bending || self.terms.twisting {
            for i in 1..=n {
                let (e, mut gl) = self.vertex_gradient(state, i, model);
                self.fold_pinned(&[i - 1, i, i + 1], &mut gl, None);
                energy += e;
                scale2 += scatter(&self.map.vertex_stencil(i), &gl, grad);
            }
        }
        if self.terms.stretching {
            for j in self.map.stretched_edges() {
                let (e, mut gl) = self.edge_gradient(state, j);
                self.fold_pinned(&[j, j + 1], &mut gl, None);
                energy += e;
                scale2 += scatter(&self.map.edge_stencil(j), &gl, grad);
            }
        }
        if self.terms.gravity {
            energy += self.gravity_energy(state, model);
            scale2 += self.scatter_gravity(grad, model);
        }
        GradientInfo {
            energy,
            force_scale: scale2.sqrt(),
        }
    }

    /// Gradient and Hessian (upper values on `self.pattern`) on the free dofs.
    /// One pass over the stencils in order, without allocation: with the
    /// closed-form stencil derivatives a vertex costs about as much as
    /// handing it to another thread would.
    pub fn hessian(&self, state: &RodState, grad: &mut [f64], values: &mut [f64]) -> GradientInfo {
        let n = self.model.segments;
        let model = self.model_at(state);
        grad.iter_mut().for_each(|v| *v = 0.0);
        values.iter_mut().for_each(|x| *x = 0.0);
        let (mut energy, mut scale2) = (0.0, 0.0);
        if self.terms.bending || self.terms.twisting {
            for i in 1..=n {
                let (e, g8, h8) = self.vertex_hessian8(state, i, &model);
                energy += e;
                scale2 += self.scatter_vertex(i, &g8, &h8, grad, values);
            }
        }
        if self.terms.stretching {
            for (k, j) in self.map.stretched_edges().enumerate() {
                let (e, mut gl, mut hl) = self.edge_local(state, j);
                self.fold_pinned(&[j, j + 1], &mut gl, Some(&mut hl));
                energy += e;
                scale2 += scatter(&self.map.edge_stencil(j), &gl, grad);
                scatter_hessian(&self.pattern.slots[n + k], 6, &hl, values);
            }
        }
        if self.terms.gravity {
            energy += self.gravity_energy(state, &model);
            scale2 += self.scatter_gravity(grad, &model);
        }
        GradientInfo {
            energy,
            force_scale: scale2.sqrt(),
        }
    }
}

impl RodEnergy {
    /// The chain rule through a pinned end's ghost node (x_g = 2p − x_k,
    /// or with the pin moving, both nodes translating with it): in a stencil
    /// over `nodes`, the ghost's gradient and Hessian rows and columns fold
    /// onto x_k with a minus sign. Nothing happens between clamps or free ends.
    pub fn fold_pinned(&self, nodes: &[usize], g: &mut [f64], h: Option<&mut [f64]>) {
        let Some((ghost, from)) = self.map.pinned_block(nodes) else {
            return;
        };
        let m = g.len();
        let (a, b) = (3 * ghost, 3 * from);
        for c in 0..3 {
            g[b + c] -= g[a + c];
            g[a + c] = 0.0;
        }
        if let Some(h) = h {
            for c in 0..3 {
                for k in 0..m {
                    h[(b + c) * m + k] -= h[(a + c) * m + k];
                }
            }
            for k in 0..m {
                for c in 0..3 {
                    h[k * m + b + c] -= h[k * m + a + c];
                }
            }
            for c in 0..3 {
                for k in 0..m {
                    h[(a + c) * m + k] = 0.0;
                    h[k * m + a + c] = 0.0;
                }
            }
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
    /// A free s = 0 end carries neither; a pinned one no moment, its force
    /// in the end edge's material frame.
    pub fn clamp_reactions(&self, state: &RodState) -> ClampReactions {
        let c = &state.clamps;
        if c.ends.start == EndKind::Free {
            let zero = Vector3::zeros();
            return ClampReactions {
                force: zero,
                moment: zero,
            };
        }
        let g = self.full_gradient(state);
        let force = -(g.nodes[0] + g.nodes[1]);
        if c.ends.start == EndKind::Pinned {
            // the pin's translation moves both nodes of the end edge
            let [d1, d2, d3] = state.directors(0);
            return ClampReactions {
                force: Vector3::new(force.dot(&d1), force.dot(&d2), force.dot(&d3)),
                moment: Vector3::zeros(),
            };
        }
        if c.start.is_default() {
            // a rotation ω moves clamp nodes by ω × x and turns the clamp's frame by
            // ω; about e3 that is a change of θ_0 (for ω ⟂ e3 time-parallel transport
            // of the clamp's reference director is the rigid rotation to first order)
            let moment = -(state.nodes[0].cross(&g.nodes[0])
                + state.nodes[1].cross(&g.nodes[1])
                + g.theta[0] * Vector3::z());
            return ClampReactions { force, moment };
        }
        // the same about the clamp's point, then in its material frame
        let p = c.start_point();
        let t = c.start_tangent();
        let moment = -((state.nodes[0] - p).cross(&g.nodes[0])
            + (state.nodes[1] - p).cross(&g.nodes[1])
            + g.theta[0] * t);
        let frame = c.start_frame().inverse();
        ClampReactions {
            force: frame * force,
            moment: frame * moment,
        }
    }

    /// Internal force and moment n(s), m(s) at the centre of every edge
    /// j = 0..=N (s = jh), in that edge's material frame (d1, d2, d3): what
    /// the rod beyond the cut exerts on the part before it. As for
    /// [`Self::clamp_reactions`], minus the derivative of the elastic energy
    /// with respect to a rigid translation and rotation, about the edge's
    /// centre, of the part before the cut (nodes 0..=j+1, angles 0..=j) — or,
    /// in the rod's second half, plus that of the part after it (nodes
    /// j..=N+1, angles j..=N), so both clamps are cut like the s = 0 one and
    /// edge N gives the reaction at s = 1. Edge 0 of a paper clamp is the
    /// clamp reaction (exactly, for a weightless rod). The weight is a load
    /// along the rod, not an internal force, so its share of the gradient is
    /// left out; a constrained law's multipliers are not included (as in the
    /// clamp reactions).
    pub fn internal_loads(&self, state: &RodState) -> Vec<ClampReactions> {
        let g = self.full_gradient(state);
        let n = self.model.segments;
        let weight = if self.terms.gravity {
            self.gravity_gradient(&self.model_at(state))
        } else {
            Vector3::zeros()
        };
        let elastic = |i: usize| {
            if (1..=n).contains(&i) {
                g.nodes[i] - weight
            } else {
                g.nodes[i]
            }
        };
        let angle = |j: usize| g.theta[j] * state.directors(j)[2];
        // running sums (Σ g_i, Σ x_i × g_i + Σ g_θk t_k) of the part moved;
        // about the point p the moment is the second minus p × the first
        let node = |i: usize| (elastic(i), state.nodes[i].cross(&elastic(i)));
        let half = n / 2;
        let mut sums = vec![(Vector3::zeros(), Vector3::zeros()); n + 1];
        let mut acc = node(0);
        for (j, sum) in sums.iter_mut().enumerate().take(half + 1) {
            let (f, m) = node(j + 1);
            acc = (acc.0 + f, acc.1 + m + angle(j));
            // the part before pushes back: minus its derivative
            *sum = (-acc.0, -acc.1);
        }
        let mut acc = node(n + 1);
        for j in (half + 1..=n).rev() {
            let (f, m) = node(j);
            acc = (acc.0 + f, acc.1 + m + angle(j));
            sums[j] = acc;
        }
        sums.iter()
            .enumerate()
            .map(|(j, (force, about_origin))| {
                let p = 0.5 * (state.nodes[j] + state.nodes[j + 1]);
                let moment = about_origin - p.cross(force);
                let [d1, d2, d3] = state.directors(j);
                let frame = |v: &Vector3<f64>| Vector3::new(v.dot(&d1), v.dot(&d2), v.dot(&d3));
                ClampReactions {
                    force: frame(force),
                    moment: frame(&moment),
                }
            })
            .collect()
    }

    /// Lumped mass of each free dof: the segment length for node coordinates,
    /// zero for material angles (no rotational inertia, as in the paper) and
    /// for a free end's ghost node beyond s ∈ [0, 1].
    pub fn lumped_mass(&self) -> Vec<f64> {
        let h = self.model.segment_length();
        let mut mass: Vec<f64> = (0..self.map.len())
            .map(|d| if self.map.is_translation(d) { h } else { 0.0 })
            .collect();
        for ghost in [0, self.model.segments + 1] {
            if let Some(d) = self.map.node(ghost) {
                mass[d..d + 3].iter_mut().for_each(|m| *m = 0.0);
            }
        }
        mass
    }
}

impl RodEnergy {
    /// Velocity of vertex i's 11 stencil variables (nodes i-1, i, i+1, angles
    /// i-1, i) when the clamps move with `velocity`.
    fn clamp_local_velocity(&self, i: usize, velocity: &ClampVelocity) -> [f64; 11] {
        let n = self.model.segments;
        let mut vel = [0.0; 11];
        for (k, node) in [i - 1, i, i + 1].into_iter().enumerate() {
            if let Some(v) = self.node_velocity(node, velocity) {
                vel[3 * k..3 * k + 3].copy_from_slice(v.as_slice());
            }
        }
        if i == 1 {
            vel[9] = velocity.theta[0];
        }
        if i == n {
            vel[10] = velocity.theta[1];
        }
        vel
    }

    /// Velocity of node `node` if it is one of the clamps' four.
    fn node_velocity(&self, node: usize, velocity: &ClampVelocity) -> Option<Vector3<f64>> {
        let n = self.model.segments;
        let slot = match node {
            0 => Some(0),
            1 => Some(1),
            _ if node == n => Some(2),
            _ if node == n + 1 => Some(3),
            _ => None,
        };
        slot.map(|c| velocity.nodes[c])
    }

    /// The vertices whose stencils touch a moving clamp: the last two, and the
    /// first two when the s = 0 clamp moves.
    fn clamp_vertices(&self, velocity: &ClampVelocity) -> impl Iterator<Item = usize> {
        let n = self.model.segments;
        let start = if velocity.moves_start() { 1..3 } else { 1..1 };
        start.chain(n - 1..n + 1)
    }

    /// ∂κ2_i/∂p for every constraint row (from `constraint_rows`) when the
    /// clamps move with `velocity`: nonzero at the vertices next to a clamp.
    pub fn constraint_parameter_derivative(
        &self,
        rows: &[(f64, [f64; 11])],
        velocity: &ClampVelocity,
        out: &mut [f64],
    ) {
        out.iter_mut().for_each(|v| *v = 0.0);
        for i in self.clamp_vertices(velocity) {
            let vel = self.clamp_local_velocity(i, velocity);
            out[i - 1] = rows[i - 1].1.iter().zip(&vel).map(|(g, v)| g * v).sum();
        }
    }
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
        if self.terms.bending || self.terms.twisting {
            for i in self.clamp_vertices(velocity) {
                let (_, _, hl) = self.vertex_local(state, i);
                let vel = self.clamp_local_velocity(i, velocity);
                let mut r = [0.0; 11];
                for (a, r) in r.iter_mut().enumerate() {
                    *r = (0..11).map(|b| hl[a * 11 + b] * vel[b]).sum::<f64>();
                }
                self.fold_pinned(&[i - 1, i, i + 1], &mut r, None);
                for (d, r) in self.map.vertex_stencil(i).iter().zip(r) {
                    if let Some(d) = d {
                        out[*d] += r;
                    }
                }
            }
        }
        if self.terms.stretching {
            // the stretched edges next to the clamps: edge N−1 (its node N
            // is the clamp's) and edge 1 (its node 1) when the s = 0 clamp
            // moves; the end edges themselves at a pinned end
            let edges = self.map.stretched_edges();
            let first = [0, 1].into_iter().filter(|_| velocity.moves_start());
            let last = [n - 1, n].into_iter();
            for j in first.chain(last).filter(|j| edges.contains(j)) {
                let mut vel = [0.0; 6];
                for (k, node) in [j, j + 1].into_iter().enumerate() {
                    if let Some(v) = self.node_velocity(node, velocity) {
                        vel[3 * k..3 * k + 3].copy_from_slice(v.as_slice());
                    }
                }
                let (_, _, hl) = self.edge_local(state, j);
                let mut r = [0.0; 6];
                for (a, r) in r.iter_mut().enumerate() {
                    *r = (0..6).map(|b| hl[a * 6 + b] * vel[b]).sum::<f64>();
                }
                self.fold_pinned(&[j, j + 1], &mut r, None);
                for (d, r) in self.map.edge_stencil(j).iter().zip(r) {
                    if let Some(d) = d {
                        out[*d] += r;
                    }
                }
            }
        }
    }
}

/// û of `model` at vertex i (its arc length (i − ½)h).
fn natural_at(model: &RodModel, i: usize) -> [f64; 3] {
    model.natural_strains.at_vertex(i, model.segments)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in [−1, 1) from a fixed seed.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }

        fn vector(&mut self) -> Vector3<f64> {
            Vector3::new(self.next(), self.next(), self.next())
        }
    }

    /// A random stencil at its own frames: edges of random length and a bend
    /// of up to about 120°, unit reference directors normal to them, any
    /// angles and any reference twist (continued a few turns).
    fn random_stencil(rng: &mut Rng) -> ([f64; 8], VertexFrames) {
        let t0 = rng.vector().normalize();
        let t1 = loop {
            let t1 = (t0 + 1.2 * rng.vector()).normalize();
            if t0.dot(&t1) > -0.5 {
                break t1;
            }
        };
        let e0 = t0 * (0.05 + 0.3 * (rng.next() + 1.0));
        let e1 = t1 * (0.05 + 0.3 * (rng.next() + 1.0));
        let normal = |t: &Vector3<f64>, v: Vector3<f64>| (v - v.dot(t) * t).normalize();
        let c = VertexFrames {
            a_prev: normal(&t0, rng.vector()),
            t_prev: e0.normalize(),
            a: normal(&t1, rng.vector()),
            t: e1.normalize(),
            reference_twist: 3.0 * rng.next()
                + 2.0 * std::f64::consts::PI * (2.0 * rng.next()).round(),
        };
        let q = [
            e0.x,
            e0.y,
            e0.z,
            e1.x,
            e1.y,
            e1.z,
            3.0 * rng.next(),
            3.0 * rng.next(),
        ];
        (q, c)
    }

    /// A rod of `law` with N = `segments` and stiffnesses of no symmetry.
    fn model(law: Law, segments: usize) -> RodModel {
        RodModel {
            segments,
            k2: 2.3,
            k3: 1.7,
            stretching_stiffness: 50.0,
            law,
            weight: [0.0; 3],
            natural_strains: Default::default(),
        }
    }

    /// Largest difference over the largest entry of the oracle.
    fn relative(a: &[f64], oracle: &[f64]) -> f64 {
        let scale = oracle.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = a
            .iter()
            .zip(oracle)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        diff / scale.max(f64::MIN_POSITIVE)
    }

    #[test]
    fn closed_form_strain_derivatives_match_jets() {
        let mut rng = Rng(7);
        let mut worst: f64 = 0.0;
        for _ in 0..500 {
            let (q, c) = random_stencil(&mut rng);
            let (s, chart) = vertex_chart(&q, &c).expect("a stencil at its own frames");
            let jets = strain_jets(q, &c);
            let derivatives = chart.strains();
            for (k, (value, jet)) in [(s.k1, jets.k1), (s.k2, jets.k2), (s.m, jets.m)]
                .into_iter()
                .enumerate()
            {
                assert!((value - jet.v).abs() < 1e-12 * (1.0 + jet.v.abs()));
                let (g, h) = chart.hessian(&derivatives[k]);
                let gradient = relative(&g, &jet.g);
                let hessian = relative(h.as_flattened(), jet.dense_hessian().as_flattened());
                if k == 2 {
                    // the published twist gradient ∂m/∂e_k = κb / (2 |e_k|)
                    // (Bergou et al. 2010), which this convention keeps
                    let edges = [[q[0], q[1], q[2]], [q[3], q[4], q[5]]];
                    let lengths = edges.map(frames::norm);
                    let tangents = [0, 1].map(|k| frames::scale(lengths[k].recip(), edges[k]));
                    let kb = curvature_binormal(tangents[0], tangents[1]);
                    for e in 0..2 {
                        for r in 0..3 {
                            let published = kb[r] / (2.0 * lengths[e]);
                            assert!(
                                (g[3 * e + r] - published).abs() < 1e-12 * (1.0 + published.abs())
                            );
                        }
                    }
                }
                assert_eq!(chart.gradient(&derivatives[k].g), g);
                assert_eq!(chart.strain_gradients()[k], derivatives[k].g);
                assert!(gradient < 1e-10, "strain {k}: gradient off by {gradient:e}");
                assert!(hessian < 1e-10, "strain {k}: Hessian off by {hessian:e}");
                worst = worst.max(gradient).max(hessian);
            }
        }
        eprintln!("strains: closed form vs jets, largest relative difference {worst:e}");
    }

    #[test]
    fn closed_form_energy_hessian_matches_jets_for_every_law() {
        let laws = [
            Law::Kirchhoff,
            Law::Unbendable,
            Law::Strip {
                regularisation: 0.3,
            },
        ];
        let term_sets = [Terms::ALL, Terms::BENDING, Terms::TWISTING];
        let mut rng = Rng(11);
        let mut worst: f64 = 0.0;
        for law in laws {
            for terms in term_sets {
                for _ in 0..100 {
                    let model = model(law, 5);
                    let natural = [rng.next(), 2.0 * rng.next(), 3.0 * rng.next()];
                    let multiplier = law.constrained().then(|| VertexMultiplier {
                        lambda: 3.0 * rng.next(),
                        penalty: PENALTY * 5.0,
                    });
                    let (q, c) = random_stencil(&mut rng);
                    assert!(vertex_chart(&q, &c).is_some());
                    let args = ((&model, natural), terms, multiplier);
                    let (e, g, h) = vertex_energy_hessian(q, &c, args.0, args.1, args.2);
                    let (e_jet, g_jet, h_jet) =
                        vertex_energy_hessian_by_jets(q, &c, args.0, args.1, args.2);
                    assert!((e - e_jet).abs() <= 1e-12 * e_jet.abs().max(1e-300));
                    let (e_grad, g_grad) = vertex_energy_gradient(q, &c, args.0, args.1, args.2);
                    let (_, g_grad_jet) =
                        jet::gradient(q, |v| vertex_energy(v, &c, args.0, args.1, args.2));
                    assert_eq!(e_grad, e);
                    let gradient = relative(&g_grad, &g_grad_jet);
                    assert!(
                        gradient < 1e-10,
                        "{law:?}: gradient alone off by {gradient:e}"
                    );
                    worst = worst.max(gradient);
                    let gradient = relative(&g, &g_jet);
                    let hessian = relative(h.as_flattened(), h_jet.as_flattened());
                    assert!(gradient < 1e-10, "{law:?}: gradient off by {gradient:e}");
                    assert!(hessian < 1e-10, "{law:?}: Hessian off by {hessian:e}");
                    worst = worst.max(gradient).max(hessian);
                }
            }
        }
        eprintln!("energy: closed form vs jets, largest relative difference {worst:e}");
    }

    #[test]
    fn the_rods_own_states_take_the_closed_form_at_every_vertex() {
        // the frame update re-normalises each transported reference director
        // against its tangent; the clamp edges take theirs from the clamp,
        // normal to the clamp's tangent up to the round-off of x_{N+1} − x_N
        for (n, ends) in [
            (12, Ends::CLAMPED),
            (
                40,
                Ends {
                    start: EndKind::Pinned,
                    end: EndKind::Free,
                },
            ),
            (3200, Ends::CLAMPED),
        ] {
            let mut clamps = Clamps::new(0.4, 0.1, 0.37);
            clamps.ends = ends;
            let base = RodState::straight(n, clamps);
            let map = RodEnergy::with_ends(model(Law::Kirchhoff, n), Terms::ALL, ends).map;
            let mut rng = Rng(5);
            let dq: Vec<f64> = (0..map.len())
                .map(|d| if map.is_translation(d) { 0.3 / n as f64 } else { 0.5 } * rng.next())
                .collect();
            let state = base.displaced(&map, &dq).displaced(&map, &dq);
            for i in 1..=n {
                let q = vertex_variables(&state, i);
                assert!(
                    vertex_chart(&q, &VertexFrames::at(&state, i)).is_some(),
                    "N = {n}, vertex {i}"
                );
            }
        }
    }

    #[test]
    fn a_reference_director_off_its_edge_falls_back_to_jets() {
        let mut rng = Rng(3);
        let (q, mut c) = random_stencil(&mut rng);
        // a node moved after the frames were transported: the stored
        // reference director no longer normal to the current tangent
        c.a = (c.a + 1e-3 * c.t).normalize();
        assert!(vertex_chart(&q, &c).is_none());
        let model = model(Law::Kirchhoff, 5);
        let args = ((&model, [0.3, -0.2, 0.5]), Terms::ALL, None);
        assert_eq!(
            vertex_energy_hessian(q, &c, args.0, args.1, args.2),
            vertex_energy_hessian_by_jets(q, &c, args.0, args.1, args.2)
        );
    }
}
