//! Writhe of a closed polygon by the exact segment-pair formula: each pair of
//! straight segments contributes the solid angle it subtends (Klenin &
//! Langowski, Biopolymers 54 (2000) 307), so long straight rays cost nothing.

use nalgebra::Vector3;
use std::f64::consts::PI;

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

/// Writhe of the closed polygon through `points` (the last point joins the first).
pub fn writhe_closed(points: &[Vector3<f64>]) -> f64 {
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
