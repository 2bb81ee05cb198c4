//! Writhe of a closed polygon, exactly (up to rounding), two ways.
//!
//! - Segment pairs: each pair of straight segments contributes the solid angle
//!   it subtends (Klenin & Langowski, Biopolymers 54 (2000) 307), so long
//!   straight rays cost nothing; O(n²).
//! - One projection (Cimasoni, J. Knot Theory Ramif. 10 (2001) 387; Aldinger,
//!   Klapper & Tabor, ibid. 4 (1995) 343): squash the curve onto the plane
//!   along a direction ξ, (x, y, z) → (x, y, λz) with λ from 1 to 0. No two
//!   strands meet on the way, so by Fuller's theorem the writhe changes by
//!   1/2π times the signed area the tangent indicatrix sweeps, and at λ → 0
//!   it is the sum of the crossing signs. For a polygon the indicatrix is the
//!   tangents joined by the corners' great arcs, each of which slides down its
//!   meridians to the equator: the area is a sum of one spherical
//!   quadrilateral per corner. The crossings come from a sweep, so the cost is
//!   O(n log n + pairs tested), and there is no approximation: both ways agree
//!   to rounding (tests), and long curves use this one.

use crate::geometry::knot::diagram::{Degenerate, MARGIN, MOST_PAIRS, Projection};
use crate::geometry::knot::{KnotError, distinct_points, projection_directions};
use nalgebra::Vector3;
use std::f64::consts::PI;

/// Polygons with fewer segments than this use the segment-pair sum (a few
/// milliseconds); longer ones one projection.
const PAIRWISE_BELOW: usize = 1000;

/// Projection directions tried before the segment-pair sum is used.
const PROJECTIONS: usize = 23;

/// Signed solid angle of the triangle (a, b, c) seen from the origin
/// (Van Oosterom & Strackee, IEEE Trans. Biomed. Eng. 30 (1983) 125).
fn triangle_solid_angle(a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) -> f64 {
    let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
    let num = a.dot(&b.cross(c));
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * num.atan2(den)
}

/// Signed contribution Ω/(4π) of the segment pair (p1→p2, p3→p4) to the Gauss
/// double integral (counted once; the writhe sums it over ordered pairs i ≠ j):
/// the solid angle of the parallelogram {x_j − x_i} seen from the origin, split
/// into two triangles — two `atan2`, cheaper than Klenin & Langowski's four
/// normalisations and four `asin` (Biopolymers 54 (2000) 307), which the tests
/// keep as a reference.
pub fn segment_pair_writhe(
    p1: &Vector3<f64>,
    p2: &Vector3<f64>,
    p3: &Vector3<f64>,
    p4: &Vector3<f64>,
) -> f64 {
    let r13 = p3 - p1;
    let r14 = p4 - p1;
    let r23 = p3 - p2;
    let r24 = p4 - p2;
    -(triangle_solid_angle(&r13, &r14, &r24) + triangle_solid_angle(&r13, &r24, &r23)) / (4.0 * PI)
}

/// Writhe of the closed polygon through `points` (the last point joins the
/// first), by the segment-pair sum for short polygons and one projection for
/// long ones; the segment-pair sum also when no projection direction tried is
/// generic. NaN if a point is not finite.
pub fn writhe_closed(points: &[Vector3<f64>]) -> f64 {
    match distinct_points(points) {
        Err(KnotError::NotFinite(_)) => f64::NAN,
        Err(_) => 0.0,
        Ok(p) if p.len() < PAIRWISE_BELOW => writhe_pairwise(&p),
        Ok(p) => writhe_projected(&p).unwrap_or_else(|_| writhe_pairwise(&p)),
    }
}

/// Writhe of the closed polygon through `points`, as [`writhe_closed`], but
/// an error instead of the O(n²) segment-pair sum for a long polygon with no
/// generic projection, or whose projection's sweep would test more than
/// [`MOST_PAIRS`] segment pairs (with the estimate).
pub fn try_writhe_closed(points: &[Vector3<f64>]) -> Result<f64, KnotError> {
    let p = match distinct_points(points) {
        Err(KnotError::TooFewPoints(_)) => return Ok(0.0),
        other => other?,
    };
    let m = p.len() as u64;
    if p.len() < PAIRWISE_BELOW {
        return Ok(writhe_pairwise(&p));
    }
    match writhe_projected(&p) {
        Ok(w) => Ok(w),
        Err(Degenerate::TooMuchWork(pairs)) => Err(KnotError::too_long(pairs)),
        Err(_) if m * m / 2 <= MOST_PAIRS => Ok(writhe_pairwise(&p)),
        Err(_) => Err(KnotError::NoGenericProjection(PROJECTIONS)),
    }
}

/// The segment-pair sum, O(n²).
fn writhe_pairwise(points: &[Vector3<f64>]) -> f64 {
    let m = points.len();
    if m < 4 {
        return 0.0;
    }
    let seg = |k: usize| (&points[k], &points[(k + 1) % m]);
    let mut total = 0.0;
    for i in 0..m {
        let (a, b) = seg(i);
        // adjacent segments share a vertex and contribute nothing
        for j in i + 2..m {
            if i == 0 && j == m - 1 {
                continue;
            }
            let (c, d) = seg(j);
            total += segment_pair_writhe(a, b, c, d);
        }
    }
    2.0 * total
}

/// The writhe from the first generic direction of a fixed list; the last
/// reason a direction failed if none is generic (too much work at once).
fn writhe_projected(points: &[Vector3<f64>]) -> Result<f64, Degenerate> {
    let mut last = Degenerate::Projection;
    for dir in projection_directions(PROJECTIONS) {
        match writhe_along(points, &dir) {
            Ok(w) => return Ok(w),
            Err(e @ Degenerate::TooMuchWork(_)) => return Err(e),
            Err(e) => last = e,
        }
    }
    Err(last)
}

/// The writhe from the projection along `dir`: the crossing signs plus the
/// corners' swept areas over 2π (module doc).
fn writhe_along(points: &[Vector3<f64>], dir: &Vector3<f64>) -> Result<f64, Degenerate> {
    let proj = Projection::new(points, dir)?;
    let m = points.len();
    let [a, b, v] = proj.frame;
    // the tangent in the frame, and its foot on the equator
    let tangent = |i: usize| {
        let t = (points[(i + 1) % m] - points[i]).normalize();
        let t = Vector3::new(t.dot(&a), t.dot(&b), t.dot(&v));
        (t, Vector3::new(t.x, t.y, 0.0).normalize())
    };
    let mut area = 0.0;
    let (mut t1, mut e1) = tangent(m - 1);
    for i in 0..m {
        let (t2, e2) = tangent(i);
        // a cusp in projection (adjacent segments antiparallel in the plane):
        // the corner's arc passes through ±ξ, where its meridians are not
        // defined
        let (u, w) = (proj.segment((i + m - 1) % m), proj.segment(i));
        if u.dot(&w) < 0.0 && (u.x * w.y - u.y * w.x).abs() <= MARGIN * u.norm() * w.norm() {
            return Err(Degenerate::Projection);
        }
        // the quadrilateral t1 → t2 → e2 → e1 lies in an open hemisphere
        // (the plane's direction that separates the corner's projected
        // tangents from the origin), so two triangles give its area
        area += triangle_solid_angle(&t1, &t2, &e2) + triangle_solid_angle(&t1, &e2, &e1);
        (t1, e1) = (t2, e2);
    }
    let mut signs = 0i64;
    proj.for_each_crossing(|c| {
        signs += if c.positive { 1 } else { -1 };
        Ok(())
    })?;
    Ok(signs as f64 + area / (2.0 * PI))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference: Klenin & Langowski's formula. Signed solid-angle contribution Ω/(4π) of the segment pair (p1→p2, p3→p4) to
    /// the Gauss double integral (counted once; the writhe sums it over ordered
    /// pairs i ≠ j, i.e. twice over unordered pairs).
    fn klenin_langowski(
        p1: &Vector3<f64>,
        p2: &Vector3<f64>,
        p3: &Vector3<f64>,
        p4: &Vector3<f64>,
    ) -> f64 {
        let r13 = p3 - p1;
        let r14 = p4 - p1;
        let r23 = p3 - p2;
        let r24 = p4 - p2;
        let unit = |v: Vector3<f64>| {
            let n = v.norm();
            if n > 0.0 { Some(v / n) } else { None }
        };
        let (Some(n1), Some(n2), Some(n3), Some(n4)) = (
            unit(r13.cross(&r14)),
            unit(r14.cross(&r24)),
            unit(r24.cross(&r23)),
            unit(r23.cross(&r13)),
        ) else {
            // a degenerate quadrilateral (coplanar or touching): no solid angle
            return 0.0;
        };
        // asin via atan2: accurate near ±1 and free of libm slow paths
        let asin = |x: f64| {
            let x = x.clamp(-1.0, 1.0);
            x.atan2(((1.0 - x) * (1.0 + x)).sqrt())
        };
        let omega = asin(n1.dot(&n2)) + asin(n2.dot(&n3)) + asin(n3.dot(&n4)) + asin(n4.dot(&n1));
        let sign = (p4 - p3).cross(&(p2 - p1)).dot(&r13);
        if sign > 0.0 {
            omega / (4.0 * PI)
        } else if sign < 0.0 {
            -omega / (4.0 * PI)
        } else {
            0.0
        }
    }

    /// Random closed polygons (points uniform in a cube: tangled, with up to
    /// thousands of crossings) and random directions: the projection's writhe
    /// is the segment-pair sum's to rounding.
    #[test]
    fn projected_writhe_equals_the_segment_pair_sum() {
        let mut x: u64 = 9;
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut compared = 0;
        for m in [5, 10, 40, 200, 1200] {
            for _ in 0..4 {
                let p: Vec<Vector3<f64>> = (0..m)
                    .map(|_| Vector3::new(next(), next(), next()))
                    .collect();
                let exact = writhe_pairwise(&p);
                for _ in 0..3 {
                    let dir = Vector3::new(next(), next(), next());
                    if let Ok(w) = writhe_along(&p, &dir) {
                        assert!(
                            (w - exact).abs() < 1e-9 * (1.0 + exact.abs()),
                            "m = {m}: {w} by projection, {exact} by pairs"
                        );
                        compared += 1;
                    }
                }
                if m >= PAIRWISE_BELOW {
                    let w = writhe_closed(&p);
                    assert!((w - exact).abs() < 1e-9 * (1.0 + exact.abs()));
                }
            }
        }
        assert!(compared >= 55, "{compared} generic projections of 60");
    }

    #[test]
    fn both_segment_pair_formulas_agree() {
        let mut x: u64 = 7;
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut worst: f64 = 0.0;
        for _ in 0..10_000 {
            let mut p = || Vector3::new(next(), next(), next());
            let (a, b, c, d) = (p(), p(), p(), p());
            let (u, v) = (
                klenin_langowski(&a, &b, &c, &d),
                segment_pair_writhe(&a, &b, &c, &d),
            );
            worst = worst.max((u - v).abs());
        }
        assert!(worst < 1e-12, "largest difference {worst:e}");
    }
}
