//! Knot type of a closed polygon, exactly.
//!
//! The polygon is first simplified by triangle elimination (an isotopy), then
//! projected along the first generic direction of a fixed list; the diagram's
//! Gauss code is shrunk by Reidemeister I and II moves, and the Alexander
//! polynomial is the determinant of a minor of its Alexander matrix, computed
//! in exact integer arithmetic ([`modular`]) and normalised (no factor t,
//! Δ(1) = +1). The determinant of the knot is |Δ(−1)|. Names come from the
//! table of prime knots up to 10 crossings (KnotInfo) and their sums.

pub(crate) mod diagram;
mod modular;
mod names;
mod simplify;
mod table;

pub use names::{alexander_of, knot_names};

use diagram::{Degenerate, Diagram};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The knot type of a closed curve.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct KnotType {
    /// |Δ(−1)|: 1 for the unknot, 3 for the trefoil, 5 for the figure-eight.
    pub determinant: u64,
    /// Alexander polynomial coefficients, lowest degree first, normalised to
    /// Δ(1) = 1 with no factor t.
    pub alexander: Vec<i64>,
    /// The knots with this polynomial, joined by " or " (None past the table).
    pub name: Option<String>,
    /// Every tabled knot, and sum of tabled knots, with this polynomial.
    pub names: Vec<String>,
    /// Crossings of the projection used.
    pub projected: usize,
    /// Crossings left after the Reidemeister I and II moves: the diagram the
    /// polynomial came from.
    pub crossings: usize,
    /// Vertices of the polygon after simplification.
    pub vertices: usize,
    /// Projection directions tried (degenerate ones are skipped).
    pub projections: usize,
}

/// Why a curve has no knot type.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum KnotError {
    /// Fewer than three distinct points.
    #[error("a closed curve needs at least 3 distinct points, it has {0}")]
    TooFewPoints(usize),
    /// A coordinate is NaN or infinite.
    #[error("point {0} of the curve is not finite")]
    NotFinite(usize),
    /// The curve passes through itself.
    #[error(
        "the curve passes through itself near ({:.6}, {:.6}, {:.6}) (in projection coordinates): it has no knot type",
        .0.x, .0.y, .0.z
    )]
    SelfIntersection(Vector3<f64>),
    /// Every projection direction tried was degenerate.
    #[error("no generic projection among {0} directions")]
    NoGenericProjection(usize),
    /// The reduced diagram is too large for its determinant (O(n³) per
    /// prime, n² memory): a curve this tangled is not a rod's knot.
    #[error(
        "the curve's diagram keeps {} crossings after simplification (at most {MAX_CROSSINGS} are resolved, in about a second; these would take about {seconds:.1e} s): it is too tangled to identify",
        .0,
        seconds = (*.0 as f64 / MAX_CROSSINGS as f64).powi(4)
    )]
    TooManyCrossings(usize),
    /// The projection's sweep would test more segment pairs than it may: the
    /// count, and the seconds it would take.
    #[error(
        "the curve's projection has {pairs:.2e} pairs of overlapping segments to test, about {seconds:.0} s (at most {:.0e} are tested): it is too tangled to identify",
        diagram::MOST_PAIRS as f64
    )]
    TooLong {
        /// Pairs of segments the sweep would test.
        pairs: f64,
        /// Estimated seconds.
        seconds: f64,
    },
    /// A coefficient of the Alexander polynomial does not fit in 64 bits.
    #[error("the Alexander polynomial has a coefficient beyond 64 bits")]
    Overflow,
}

impl KnotError {
    /// The error for a sweep of `pairs` segment pairs, with its estimate.
    pub(crate) fn too_long(pairs: u64) -> KnotError {
        KnotError::TooLong {
            pairs: pairs as f64,
            seconds: pairs as f64 / diagram::PAIRS_PER_SECOND,
        }
    }
}

/// Largest reduced diagram whose polynomial is computed: the cost grows as
/// crossings⁴ (a fuzzed curve of 489 crossings took 6.5 s; 300 take about one).
pub const MAX_CROSSINGS: usize = 300;

/// Directions tried before giving up: a polygon in general position has
/// degenerate projections on a set of measure zero.
const PROJECTIONS: usize = 23;

/// Deterministic, well-spread projection directions (golden-angle spiral),
/// avoiding the z axis along which the clamps' rays run.
pub fn projection_directions(count: usize) -> Vec<Vector3<f64>> {
    let golden = PI * (3.0 - 5f64.sqrt());
    (0..)
        .map(|k| {
            let z = 0.7 * (1.0 - 2.0 * (k as f64 + 0.5) / 23.0);
            let r = (1.0 - z * z).sqrt();
            let phi = golden * k as f64 + 0.3;
            Vector3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .take(count)
        .collect()
}

/// 2^e as a pair of factors, each a normal f64, whose product is 2^e (one
/// power of two alone covers only e in −1022…1023).
fn power_of_two(e: i32) -> [f64; 2] {
    let half = e / 2;
    [2f64.powi(half), 2f64.powi(e - half)]
}

/// Exponent e with 2^(e−1) ≤ x < 2^(e+1) for a positive finite x, from
/// log2, which neither overflows nor underflows (subnormals included).
fn binary_exponent(x: f64) -> i32 {
    x.log2().floor() as i32 + 1
}

/// `points` scaled by a power of two so that the largest absolute coordinate
/// is near 1; exact, since scaling by 2^e only changes exponents.
fn scaled_to_unit(points: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    let largest = points.iter().map(|p| p.amax()).fold(0.0, f64::max);
    if largest == 0.0 {
        return points.to_vec();
    }
    let [f, g] = power_of_two(-binary_exponent(largest));
    points.iter().map(|p| (p * f) * g).collect()
}

/// The curve moved and scaled to unit size: its bounding box centred at the
/// origin, its largest coordinate between ½ and 2. Knot type and writhe do
/// not change, and every margin and tolerance downstream is relative to a
/// curve of size 1, so a curve at 10⁻³⁰⁰ or 10³⁰⁰ is read as at 1 (without
/// it, products of coordinates overflow or underflow). The first scaling
/// (before the centre is taken, so that lo + hi cannot overflow) and the
/// second are powers of two; only the translation rounds. The points must
/// be finite.
pub fn unit_sized(points: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    if points.is_empty() {
        return Vec::new();
    }
    let mut p = scaled_to_unit(points);
    let lo = p.iter().fold(p[0], |m, q| m.inf(q));
    let hi = p.iter().fold(p[0], |m, q| m.sup(q));
    let centre = (lo + hi) / 2.0;
    for q in &mut p {
        *q -= centre;
    }
    scaled_to_unit(&p)
}

/// The polygon without repeated consecutive points (the last point may
/// repeat the first), checked finite, at unit size ([`unit_sized`]).
pub(crate) fn distinct_points(closed: &[Vector3<f64>]) -> Result<Vec<Vector3<f64>>, KnotError> {
    if let Some(i) = closed.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(KnotError::NotFinite(i));
    }
    let mut out: Vec<Vector3<f64>> = Vec::with_capacity(closed.len());
    for p in unit_sized(closed) {
        if out.last() != Some(&p) {
            out.push(p);
        }
    }
    while out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    if out.len() < 3 {
        return Err(KnotError::TooFewPoints(out.len()));
    }
    Ok(out)
}

/// Knot type of the closed polygon through `closed` (the last point joins
/// the first).
pub fn knot_type(closed: &[Vector3<f64>]) -> Result<KnotType, KnotError> {
    let points = distinct_points(closed)?;
    let reduced = simplify::simplify(&points);
    let mut tried = 0;
    for dir in projection_directions(PROJECTIONS) {
        tried += 1;
        match along(&reduced, &dir) {
            Err(Some(e)) => return Err(e),
            Err(None) => continue,
            Ok(mut k) => {
                k.vertices = reduced.len();
                k.projections = tried;
                return Ok(k);
            }
        }
    }
    Err(KnotError::NoGenericProjection(tried))
}

/// Knot type read from the projection of the polygon along `dir`, without
/// simplifying it first (to check that every projection agrees).
pub fn knot_type_along(closed: &[Vector3<f64>], dir: &Vector3<f64>) -> Result<KnotType, KnotError> {
    let points = distinct_points(closed)?;
    along(&points, dir).map_err(|e| e.unwrap_or(KnotError::NoGenericProjection(1)))
}

/// The knot type from one projection; Err(None) if it is degenerate.
fn along(points: &[Vector3<f64>], dir: &Vector3<f64>) -> Result<KnotType, Option<KnotError>> {
    let degenerate = |d: Degenerate| match d {
        Degenerate::Projection => None,
        Degenerate::SelfIntersection(at) => Some(KnotError::SelfIntersection(at)),
        Degenerate::TooMany(n) => Some(KnotError::TooManyCrossings(n)),
        Degenerate::TooMuchWork(pairs) => Some(KnotError::too_long(pairs)),
    };
    let crossings = diagram::crossings(points, dir).map_err(degenerate)?;
    let mut diagram = Diagram::new(&crossings).map_err(degenerate)?;
    diagram.reduce();
    if diagram.crossings() > MAX_CROSSINGS {
        return Err(Some(KnotError::TooManyCrossings(diagram.crossings())));
    }
    let (a, b, n) = diagram.alexander_matrix();
    // any minor of order n − 1: drop the last row and column
    let m = n.saturating_sub(1);
    let minor = |x: &[i64]| -> Vec<i64> {
        (0..m)
            .flat_map(|r| x[r * n..r * n + m].iter().copied())
            .collect()
    };
    let det =
        modular::det_pencil(&minor(&a), &minor(&b), m).map_err(|_| Some(KnotError::Overflow))?;
    // Δ(1) = ±1 for a true diagram; anything else means a projection too
    // close to degenerate for its crossings to have been read right
    let alexander = normalise(det).ok_or(None)?;
    let determinant: i128 = alexander
        .iter()
        .enumerate()
        .map(|(j, &c)| if j % 2 == 0 { c as i128 } else { -(c as i128) })
        .sum();
    let names = knot_names(&alexander);
    Ok(KnotType {
        determinant: u64::try_from(determinant.unsigned_abs())
            .map_err(|_| Some(KnotError::Overflow))?,
        name: (!names.is_empty()).then(|| names.join(" or ")),
        names,
        alexander,
        projected: crossings.len(),
        crossings: diagram.crossings(),
        vertices: points.len(),
        projections: 1,
    })
}

/// Strip powers of t and fix the sign so that Δ(1) = 1; None if Δ(1) ≠ ±1.
fn normalise(mut c: Vec<i64>) -> Option<Vec<i64>> {
    while c.last() == Some(&0) {
        c.pop();
    }
    let lead = c.iter().position(|x| *x != 0)?;
    c.drain(..lead);
    let at_one: i128 = c.iter().map(|&x| x as i128).sum();
    match at_one {
        1 => Some(c),
        -1 => Some(c.into_iter().map(|x| -x).collect()),
        _ => None,
    }
}
