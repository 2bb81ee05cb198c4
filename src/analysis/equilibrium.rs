//! One equilibrium of a scene: initial shape, Newton solve, and the quantities
//! the paper reports (clamp reactions, twist, walls, stability).

use crate::analysis::class::GoodKnot;
use crate::geometry::closure::{closure_knot_along, ray_closure, reach};
use crate::geometry::distance::{
    Approach, CurveTree, distance_to_ray, min_self_distance, strand_side,
};
use crate::geometry::knot::{KnotType, knot_names};
use crate::geometry::ribbon::Ribbon;
use crate::geometry::walls::wall_clearance_between;
use crate::geometry::writhe::writhe_closed;
use crate::linalg::eigen::{
    Gram, Spectrum, StabilityError, lowest_eigenvalues, lowest_eigenvalues_refined,
};
use crate::linalg::sparse::Ldlt;
use crate::model::contact_hessian::ContactHessian;
use crate::model::energy::{RodEnergy, vertex_strains};
use crate::model::rod::{Law, RodState};
use crate::solve::minimizer::Minimizer;
use crate::solve::outcome::SolveReport;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// An equilibrium and its measurements (one entry of "equilibria" in the JSON summary).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Equilibrium {
    /// End displacement.
    pub z_star: f64,
    /// End shift.
    pub delta: f64,
    /// End rotation / 2π (continuous).
    pub phi_over_2pi: f64,
    /// Newton met its gradient test.
    pub converged: bool,
    /// Final relative gradient norm.
    pub gradient_norm: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// Relative gradient per iteration.
    pub residual_history: Vec<f64>,
    /// Elastic energy.
    pub energy: f64,
    /// Internal force at s = 0 (material frame).
    pub n0: [f64; 3],
    /// Internal moment at s = 0 (material frame).
    pub m0: [f64; 3],
    /// Tw = (1/2π) ∫ u3 ds.
    pub twist: f64,
    /// Lowest interior node height (of a ribbon: the lowest across its
    /// width, see [`Measure::strip_width`]).
    pub min_z: f64,
    /// Highest interior node height (of a ribbon: across its width).
    pub max_z: f64,
    /// 0 < z < z* at every interior node (of a ribbon: across its width).
    pub walled: bool,
    /// Lowest eigenvalues of the Hessian on the free dofs.
    pub lowest_eigenvalues: Vec<f64>,
    /// Lowest eigenvalues of H v = ω² M v (lumped translational mass).
    pub omega_squared: Vec<f64>,
    /// Count of negative eigenvalues (inertia).
    pub negative_eigenvalues: usize,
    /// All eigenvalues positive.
    pub stable: bool,
    /// Writhe of the ray-closed centreline.
    pub writhe: f64,
    /// Tw + writhe (for walled configurations the paper's Tw + polar writhe).
    pub link: f64,
    /// |Δ(−1)| of the ray closure (3: trefoil; 0 when it has no knot type).
    pub knot_determinant: u64,
    /// Alexander polynomial of the ray closure, lowest degree first.
    pub alexander: Vec<i64>,
    /// The knots with that polynomial (see [`KnotType::name`]).
    pub knot_name: Option<String>,
    /// The ray closure passes through itself: it has no knot type.
    #[serde(alias = "knot_ambiguous")]
    pub knot_undefined: bool,
    /// The ray closure is the knot asked for (`[diagnostics] knot`).
    #[serde(default)]
    pub knotted: bool,
    /// Smallest distance between parts of the centreline at least the gap
    /// apart (of a strip with a width: between parts of its ribbon).
    pub min_self_distance: f64,
    /// Arc lengths (s, s') of that closest approach.
    pub min_self_distance_s: [f64; 2],
    /// Clearance of the interior extrema of z from the walls (negative: outside).
    pub wall_distance: f64,
    /// Smallest distance to the clamps' rays (bottom, top), away from the clamps.
    pub ray_distance: [f64; 2],
    /// A good knot by the scene's predicate ([`GoodKnot`]): walled, the
    /// asked knot, stable, contact-free.
    pub good_knot: bool,
    /// Constrained laws: largest |u2| over the vertices (the residual of the
    /// constraint u2 = 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_u2: Option<f64>,
    /// Strip law: smallest |u1 − û1| over the vertices. Where it is comparable to
    /// the regularisation ε while the twist is not small, the Sadowsky energy
    /// is singular and the result depends on ε (see `regularised`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_u1: Option<f64>,
    /// Strip law: some vertex has |u1 − û1| < 3ε with |u3| > ε, i.e. the
    /// regularisation, not the Sadowsky law, decides its shape there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub regularised: Option<bool>,
    /// Contacts (with a `[contact]` model): arc length, obstacle, force.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contacts: Vec<crate::model::contact::ContactForce>,
    /// Sum of the contact forces' magnitudes.
    #[serde(default)]
    pub contact_force: f64,
    /// Branch this equilibrium lies on (0 for a single solve).
    #[serde(default)]
    pub branch: usize,
    /// Leg of the branch: 0 from the start in the first direction, 1 in the
    /// other (whose first point follows the branch's start).
    #[serde(default)]
    pub leg: usize,
    /// The full discrete state (restart with `[initial] shape = "file"`).
    pub state: RodState,
}

/// Measuring an equilibrium failed: its stability analysis (the step named).
#[derive(Debug, thiserror::Error)]
#[error("{step}")]
pub struct AnalysisError {
    /// Which analysis.
    pub step: &'static str,
    /// Why.
    #[source]
    pub source: StabilityError,
}

/// Settings of the measurements of an equilibrium.
#[derive(Clone, Debug)]
pub struct Measure {
    /// Lowest eigenvalues to compute.
    pub eigenvalues: usize,
    /// What a good knot is.
    pub good: GoodKnot,
    /// Arc-length gap of the self-distance.
    pub self_distance_gap: f64,
    /// Ray length of the writhe closure.
    pub ray_length: f64,
    /// Width w/L of a strip's ribbon (along d1, centred on the centreline):
    /// when positive the self-distance, the walls and the self-contact
    /// events are measured on the ribbon; 0 measures the centreline.
    pub strip_width: f64,
}

/// The walls as seen by one measurement: the interior heights' range, walled,
/// and the clearance of the interior extrema (see [`Equilibrium::min_z`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Walls {
    /// Lowest interior height.
    pub min_z: f64,
    /// Highest interior height.
    pub max_z: f64,
    /// Strictly between z = 0 and z = z*.
    pub walled: bool,
    /// Clearance of the interior extrema (negative: outside).
    pub clearance: f64,
}

/// The ribbon of `state` (segment k of its centreline carries edge k's d1)
/// with its centreline and arc lengths.
pub fn ribbon_data(state: &RodState) -> (Vec<Vector3<f64>>, Vec<f64>, Vec<Vector3<f64>>) {
    let (points, arc) = state.centreline();
    // the centreline's segment k is (part of) edge k, the clamps' included
    let d1 = (0..points.len() - 1)
        .map(|k| state.directors(k)[0])
        .collect();
    (points, arc, d1)
}

/// The walls of `state`, on its ribbon when `strip_width` > 0 (else exactly
/// the centreline's, [`RodState::wall_clearance`] and [`RodState::walled`]).
pub fn walls(state: &RodState, strip_width: f64) -> Walls {
    if strip_width <= 0.0 {
        let (min_z, max_z) = state.z_range();
        return Walls {
            min_z,
            max_z,
            walled: state.walled(),
            clearance: state.wall_clearance(),
        };
    }
    let (points, _, d1) = ribbon_data(state);
    let ribbon = Ribbon {
        points: &points,
        d1: &d1,
        width: strip_width,
    };
    let (low, high) = ribbon.heights();
    // the interior points 1..=N, as for the centreline
    let n = state.segments();
    let (low, high) = (&low[1..=n], &high[1..=n]);
    let min_z = low.iter().copied().fold(f64::INFINITY, f64::min);
    let max_z = high.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let z_star = state.clamps.top_wall();
    Walls {
        min_z,
        max_z,
        walled: min_z > 0.0 && max_z < z_star,
        clearance: wall_clearance_between(low, high, z_star),
    }
}

/// The closest self-approach of `state` between parts at least
/// `measure.self_distance_gap` apart: of its ribbon when
/// `measure.strip_width` > 0, else of its centreline.
pub fn self_approach(state: &RodState, measure: &Measure) -> Option<Approach> {
    let gap = measure.self_distance_gap;
    if measure.strip_width <= 0.0 {
        let (points, arc) = state.centreline();
        return min_self_distance(&points, &arc, gap);
    }
    let (points, arc, d1) = ribbon_data(state);
    Ribbon {
        points: &points,
        d1: &d1,
        width: measure.strip_width,
    }
    .min_self_distance(&arc, gap)
}

/// Writhe, knot type, walls and distances of a state (see [`Equilibrium`]).
pub struct Conformation {
    /// Writhe of the ray closure.
    pub writhe: f64,
    /// Knot type of the ray closure (None: it passes through itself).
    pub knot: Option<KnotType>,
    /// Closest self-approach (of the ribbon when it has a width).
    pub self_approach: Option<Approach>,
    /// Wall clearance.
    pub wall_distance: f64,
    /// Distances to the bottom and top rays.
    pub ray_distance: [f64; 2],
    /// How the writhe and knot type were obtained.
    pub how: Measured,
}

/// How a conformation's writhe and knot type were obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Measured {
    /// Computed afresh: the O(N²) writhe, the knot type.
    Full,
    /// Carried from the previous point: no strand came near another.
    Carried,
    /// Across one passage of two strands (or none) from the previous point:
    /// the link's integer part jumps by the passage's ±2, the knot type is
    /// recomputed if they passed.
    Passage,
}

impl Conformation {
    /// Measure the centreline of `state`.
    pub fn of(state: &RodState, measure: &Measure) -> Conformation {
        Self::measure(state, measure, None)
    }

    /// Measure `state`, reached from the measured equilibrium `previous`
    /// (e.g. the last point of a branch). When no strand can have passed
    /// through another or through a ray on the way — every clearance, before
    /// and after, exceeds twice the largest node move — the ray-closed
    /// ribbon's link keeps its integer part (Călugăreanu–White: Lk = Tw + Wr
    /// = n + φ/2π), so Wr = n + φ/2π − Tw in O(N), and the knot type is
    /// unchanged. Otherwise both are computed afresh (O(N²)).
    pub fn continued(state: &RodState, measure: &Measure, previous: &Equilibrium) -> Conformation {
        Self::measure(state, measure, Some(previous))
    }

    fn measure(
        state: &RodState,
        measure: &Measure,
        previous: Option<&Equilibrium>,
    ) -> Conformation {
        let (points, arc) = state.centreline();
        let [down, up] = state.ray_directions();
        let start = state.start_point();
        // the knot type and ray distances need the rays only to leave the
        // curve's neighbourhood
        let reach = reach(&points);
        // the knot and the writhe are the centreline's, so are the strands
        // whose passage changes them
        let line_approach = min_self_distance(&points, &arc, measure.self_distance_gap);
        let (self_approach, wall_distance) = if measure.strip_width > 0.0 {
            (
                self_approach(state, measure),
                walls(state, measure.strip_width).clearance,
            )
        } else {
            (line_approach, state.wall_clearance())
        };
        let end = *points.last().unwrap();
        let gap = measure.self_distance_gap;
        let ray = |origin: &Vector3<f64>, dir: Vector3<f64>, s_base: f64| {
            distance_to_ray(&points, &arc, origin, &dir, reach, s_base, gap)
                .map_or(f64::INFINITY, |d| d.0)
        };
        let ray_distance = [ray(&start, down, 0.0), ray(&end, up, 1.0)];
        let self_distance = line_approach.map_or(f64::INFINITY, |a| a.distance);
        let carried = previous.filter(|p| {
            if p.state.nodes.len() != state.nodes.len()
                || p.knot_undefined
                || !state.clamps.rays_parallel()
                || p.state.clamps.start != state.clamps.start
                || p.state.clamps.end.orientation != state.clamps.end.orientation
            {
                return false;
            }
            let moved = p.state.largest_node_distance(state)
                + (p.state.clamps.end_point() - state.clamps.end_point()).norm();
            let clearance = [
                self_distance,
                ray_distance[0],
                ray_distance[1],
                p.min_self_distance,
                p.ray_distance[0],
                p.ray_distance[1],
            ]
            .into_iter()
            .fold(f64::INFINITY, f64::min);
            clearance > 2.0 * moved
        });
        let kept = |p: &Equilibrium| {
            Some(KnotType {
                determinant: p.knot_determinant,
                alexander: p.alexander.clone(),
                name: p.knot_name.clone(),
                names: knot_names(&p.alexander),
                projected: 0,
                crossings: 0,
                vertices: 0,
                projections: 0,
            })
        };
        // Wr = n + φ/2π − Tw with n the link's integer part, carried
        let writhe_with = |p: &Equilibrium, jump: f64| {
            (p.link - p.phi_over_2pi).round() + jump + state.clamps.phi_over_2pi() - state.twist()
        };
        // `p.min_self_distance` above is the ribbon's for a strip with a
        // width: never more than the centreline's, so only more cautious
        let passage = match (carried, previous, line_approach) {
            (None, Some(p), Some(a)) => {
                passage_jump(state, &points, &arc, p, &a, ray_distance, gap).map(|j| (p, j))
            }
            _ => None,
        };
        let (writhe, knot, how) = match (carried, passage) {
            (Some(p), _) => (writhe_with(p, 0.0), kept(p), Measured::Carried),
            (None, Some((p, jump))) => (
                writhe_with(p, jump),
                if jump == 0.0 {
                    kept(p)
                } else {
                    closure_knot_along(&points, [down, up]).ok()
                },
                Measured::Passage,
            ),
            (None, None) => (
                writhe_closed(&ray_closure(&points, down, up, measure.ray_length)),
                closure_knot_along(&points, [down, up]).ok(),
                Measured::Full,
            ),
        };
        Conformation {
            writhe,
            knot,
            self_approach,
            wall_distance,
            ray_distance,
            how,
        }
    }
}

/// The jump of the writhe from the measured equilibrium `p` to `state`
/// (−2, 0 or +2) when the only strands that can have passed through each
/// other are the two at the closest approach `a`: the rays clear before and
/// after by twice the largest move, every close pair of segments (within
/// that distance) in both states near the pair at `a`, and on both sides a
/// clear signed gap between the strands. Passing from the side σ to −σ
/// changes the local Gauss integral sign((t₀ × t₁)·(r₀ − r₁)) from sign σ
/// to −sign σ, so Wr jumps by −2 sign σ. None where this cannot be told
/// (the caller computes the writhe afresh).
fn passage_jump(
    state: &RodState,
    points: &[Vector3<f64>],
    arc: &[f64],
    p: &Equilibrium,
    a: &Approach,
    ray_distance: [f64; 2],
    gap: f64,
) -> Option<f64> {
    if p.state.nodes.len() != state.nodes.len()
        || p.knot_undefined
        || !state.clamps.rays_parallel()
        || p.state.clamps.start != state.clamps.start
        || p.state.clamps.end.orientation != state.clamps.end.orientation
    {
        return None;
    }
    let moved = p.state.largest_node_distance(state)
        + (p.state.clamps.end_point() - state.clamps.end_point()).norm();
    let rays = [
        ray_distance[0],
        ray_distance[1],
        p.ray_distance[0],
        p.ray_distance[1],
    ]
    .into_iter()
    .fold(f64::INFINITY, f64::min);
    if rays <= 2.0 * moved {
        return None;
    }
    let (before, before_arc) = p.state.centreline();
    let h = arc[1] - arc[0];
    let radius = 4.0 * moved + 3.0 * h;
    let local = |pts: &[Vector3<f64>], arc: &[f64]| {
        CurveTree::new(pts)
            .pairs_within(arc, gap, 2.0 * moved)
            .into_iter()
            .all(|(i, j)| (arc[i] - a.s[0]).abs() <= radius && (arc[j] - a.s[1]).abs() <= radius)
    };
    if !local(points, arc) || !local(&before, &before_arc) {
        return None;
    }
    let previous_approach = min_self_distance(&before, &before_arc, gap)?;
    let near =
        |b: &Approach| (b.s[0] - a.s[0]).abs() <= radius && (b.s[1] - a.s[1]).abs() <= radius;
    if !near(&previous_approach) {
        return None;
    }
    // the same chords in both states orient the normal alike
    let side_now = strand_side(points, arc, a.s, a.segments)?;
    let side_before = strand_side(&before, &before_arc, previous_approach.s, a.segments)?;
    // a gap mostly along the normal: the strands are locally straight there
    if side_now.abs() < 0.5 * a.distance || side_before.abs() < 0.5 * previous_approach.distance {
        return None;
    }
    Some(if side_now.signum() == side_before.signum() {
        0.0
    } else {
        -2.0 * side_before.signum()
    })
}

/// The Hessian with the contacts held: for each contact row carrying force z
/// (gap closed), the Lagrangian's curvature −z ∇²g and a stiff penalty
/// ρ ∇g∇gᵀ, so that the inertia and lowest eigenvalues are those on the
/// tangent space of the active contacts (self-contacts included, on the
/// pattern widened by their couplings). None without held contacts.
fn hold_contacts(
    newton: &Minimizer,
    state: &RodState,
    report: &SolveReport,
    values: &[f64],
) -> Option<ContactHessian> {
    let model = newton.contact.as_ref()?;
    let held: Vec<&(crate::model::contact::Gap, f64)> = report
        .contact_rows
        .iter()
        .filter(|(g, z)| *z > 0.0 && g.gap < 1e-6 * model.diameter)
        .collect();
    if held.is_empty() {
        return None;
    }
    let energy = &newton.energy;
    let max_diag = energy.pattern.max_abs_diagonal(values);
    let gaps: Vec<&crate::model::contact::Gap> = held.iter().map(|(g, _)| g).collect();
    let mut wide = ContactHessian::new(energy, &gaps);
    wide.fill(
        energy,
        values,
        model,
        state,
        held.iter().map(|(g, z)| (g, *z)),
        1e3 * max_diag,
    );
    Some(wide)
}

/// Ratio of the second penalty to the law's own in [`stability_in_the_limit`].
const PENALTY_RATIO: f64 = 10.0;

/// The spectrum of [`stability`], for a constrained law (the strip's u2 = 0)
/// taken to the constraint itself: the augmented Lagrangian's Hessian, the
/// Lagrangian's plus ρ JᵀJ, has the constrained eigenvalues only as ρ → ∞,
/// each off by c/ρ (ρ = PENALTY/h holds the discrete strip 5e-4 below its
/// continuum ω², a bias that N does not remove). Computed at ρ and 10ρ, the
/// values are extrapolated as λ(10ρ) + (λ(10ρ) − λ(ρ))/9, the inertia is
/// the one at 10ρ. An unconstrained law has one spectrum.
fn stability_in_the_limit(
    newton: &mut Minimizer,
    state: &RodState,
    report: &SolveReport,
    k: usize,
    hessian: Option<&[f64]>,
) -> Result<(Spectrum, Vec<f64>), AnalysisError> {
    let Some(rho) = newton.energy.penalty else {
        return stability(newton, state, report, k, hessian);
    };
    let (plain, pencil) = stability(newton, state, report, k, hessian)?;
    newton.energy.penalty = Some(PENALTY_RATIO * rho);
    let stiffer = stability(newton, state, report, k, None);
    newton.energy.penalty = Some(rho);
    let (mut stiff_plain, stiff_pencil) = stiffer?;
    let limit = |a: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter()
            .zip(b)
            .map(|(lo, hi)| hi + (hi - lo) / (PENALTY_RATIO - 1.0))
            .collect()
    };
    stiff_plain.values = limit(&plain.values, &stiff_plain.values);
    Ok((stiff_plain, limit(&pencil, &stiff_pencil)))
}

/// The spectrum at an equilibrium: the Hessian's (contacts held) lowest `k`
/// eigenvalues and inertia, and the pencil's with the lumped mass (the ω²).
/// `hessian` is the Hessian at `state` when the caller has it already.
fn stability(
    newton: &mut Minimizer,
    state: &RodState,
    report: &SolveReport,
    k: usize,
    hessian: Option<&[f64]>,
) -> Result<(Spectrum, Vec<f64>), AnalysisError> {
    let energy: &RodEnergy = &newton.energy;
    let values = match hessian {
        Some(h) if h.len() == energy.pattern.nnz() => h.to_vec(),
        _ => {
            let mut grad = vec![0.0; energy.map.len()];
            let mut values = vec![0.0; energy.pattern.nnz()];
            energy.hessian(state, &mut grad, &mut values);
            values
        }
    };
    let mut held = hold_contacts(newton, state, report, &values);
    let energy: &RodEnergy = &newton.energy;
    // the rod's own Hessian form, stencil by stencil, refines the eigenpairs
    // (a stiff rod's assembled matrix has lost the lowest ones' digits);
    // with contacts held the widened matrix is all there is
    let gram = |z: &[Vec<f64>]| energy.hessian_gram(state, z);
    let (pattern, values, ldlt, form) = match held.as_mut() {
        Some(w) => (&w.pattern, &w.values, &mut w.ldlt, None),
        None => (
            &energy.pattern,
            &values,
            &mut newton.ldlt,
            Some(&gram as Gram<'_>),
        ),
    };
    let lowest = |mass: Option<&[f64]>, ldlt: &mut Ldlt| match form {
        Some(gram) => lowest_eigenvalues_refined(pattern, values, mass, k, ldlt, gram),
        None => lowest_eigenvalues(pattern, values, mass, k, ldlt),
    };
    let plain = lowest(None, ldlt).map_err(|source| AnalysisError {
        step: "stability of the Hessian",
        source,
    })?;
    // with no eigenvalues asked the inertia is all, and the pencil adds nothing
    let pencil_values = if k > 0 {
        let mass = energy.lumped_mass();
        lowest(Some(&mass), ldlt)
            .map_err(|source| AnalysisError {
                step: "stability with the lumped mass",
                source,
            })?
            .values
    } else {
        Vec::new()
    };
    Ok((plain, pencil_values))
}

/// What a constrained law asks to check of its strains: the constraint's
/// residual max |u2|, and for the strip min |u1| and whether the
/// regularisation decides the shape somewhere.
fn strain_checks(energy: &RodEnergy, state: &RodState) -> (Option<f64>, Option<f64>, Option<bool>) {
    let law = energy.model.law;
    // the strip law is that of u1 − û1: its singular zero moves with û1
    let strains: Vec<[f64; 3]> = if law.constrained() {
        (1..=state.segments())
            .map(|i| {
                let [u1, u2, u3] = vertex_strains(state, i);
                let shift = if matches!(law, Law::Strip { .. }) {
                    energy.natural_at(i)[0]
                } else {
                    0.0
                };
                [u1 - shift, u2, u3]
            })
            .collect()
    } else {
        Vec::new()
    };
    let max_u2 = law
        .constrained()
        .then(|| strains.iter().map(|u| u[1].abs()).fold(0.0, f64::max));
    let (min_u1, regularised) = match law {
        Law::Strip {
            regularisation: eps,
        } => (
            Some(
                strains
                    .iter()
                    .map(|u| u[0].abs())
                    .fold(f64::INFINITY, f64::min),
            ),
            Some(
                strains
                    .iter()
                    .any(|u| u[0].abs() < 3.0 * eps && u[2].abs() > eps),
            ),
        ),
        _ => (None, None),
    };
    (max_u2, min_u1, regularised)
}

/// Measure an equilibrium found by `newton` (its energy is reused for the Hessian).
pub fn analyse(
    newton: &mut Minimizer,
    state: &RodState,
    report: &SolveReport,
    measure: &Measure,
) -> Result<Equilibrium, AnalysisError> {
    analyse_from(newton, state, report, measure, None, None)
}

/// As [`analyse`], for a state reached from the measured equilibrium
/// `previous` (the writhe and knot type are carried over when no strand can
/// have passed through another: see [`Conformation::continued`]), and with the
/// Hessian at `state` when the caller has it already.
pub fn analyse_from(
    newton: &mut Minimizer,
    state: &RodState,
    report: &SolveReport,
    measure: &Measure,
    previous: Option<&Equilibrium>,
    hessian: Option<&[f64]>,
) -> Result<Equilibrium, AnalysisError> {
    let (plain, pencil_values) =
        stability_in_the_limit(newton, state, report, measure.eigenvalues, hessian)?;
    let reactions = newton.energy.clamp_reactions(state);
    let Walls {
        min_z,
        max_z,
        walled,
        ..
    } = walls(state, measure.strip_width);
    let z_star = state.clamps.z_star;
    let stable = plain.negative_count == 0 && plain.values.first().is_none_or(|v| *v > 0.0);
    let shape = Conformation::measure(state, measure, previous);
    let twist = state.twist();
    let knotted = measure
        .good
        .is_knot(shape.knot.as_ref().map(|k| k.alexander.as_slice()));
    let min_self_distance = shape.self_approach.map_or(f64::INFINITY, |a| a.distance);
    let (max_u2, min_u1, regularised) = strain_checks(&newton.energy, state);
    Ok(Equilibrium {
        z_star,
        delta: state.clamps.delta,
        phi_over_2pi: state.clamps.phi_over_2pi(),
        converged: report.converged,
        gradient_norm: report.gradient_norm,
        iterations: report.iterations,
        residual_history: report.residual_history.clone(),
        energy: report.energy,
        n0: reactions.force.into(),
        m0: reactions.moment.into(),
        twist,
        min_z,
        max_z,
        walled,
        lowest_eigenvalues: plain.values,
        omega_squared: pencil_values,
        negative_eigenvalues: plain.negative_count,
        stable,
        writhe: shape.writhe,
        link: twist + shape.writhe,
        knot_determinant: shape.knot.as_ref().map_or(0, |k| k.determinant),
        knotted,
        good_knot: measure
            .good
            .holds(walled, knotted, stable, min_self_distance),
        knot_undefined: shape.knot.is_none(),
        alexander: shape.knot.as_ref().map_or(vec![], |k| k.alexander.clone()),
        knot_name: shape.knot.and_then(|k| k.name),
        min_self_distance,
        min_self_distance_s: shape.self_approach.map_or([f64::NAN; 2], |a| a.s),
        wall_distance: shape.wall_distance,
        ray_distance: shape.ray_distance,
        max_u2,
        min_u1,
        regularised,
        contact_force: report.contacts.iter().map(|c| c.force).sum(),
        contacts: report.contacts.clone(),
        branch: 0,
        leg: 0,
        state: state.clone(),
    })
}
