//! An open trefoil tied around the clamps' rays: the starting shape for the
//! paper's hand-made knot (configuration A, Figures 3-5).
//!
//! The closure of the rod by the rays (down from the s = 0 clamp, up from the
//! s = 1 clamp) is a trefoil when the rod leaves its first clamp sideways,
//! winds 1.5 turns around the z-axis while rising above the second clamp (the
//! upper ray passes through these turns), comes back down outside them and
//! enters the second clamp from below: the overhand knot with the upper ray as
//! the end pulled through the loop. The curve is scaled until its length is
//! the rod's (1) and sampled by arc length.

use nalgebra::Vector3;
use std::f64::consts::PI;

/// The guide polyline at scale `size` (radius of the turns), from the clamp
/// at the origin to the clamp at `end`.
fn guide(size: f64, end: Vector3<f64>) -> Vec<Vector3<f64>> {
    let (r, lift, top) = (size, 0.4 * size, 2.5 * size + end.z);
    let turns = 1.5;
    let mut p = Vec::new();
    // up from the first clamp and out to radius r on the −x side
    for k in 0..20 {
        let t = k as f64 / 20.0;
        p.push(Vector3::new(-r * t, 0.0, lift * (0.5 * PI * t).sin()));
    }
    // the turns around the axis, rising above the second clamp
    let m = 300;
    for k in 0..=m {
        let t = k as f64 / m as f64;
        let a = PI + 2.0 * PI * turns * t;
        p.push(Vector3::new(
            r * a.cos(),
            r * a.sin(),
            lift + (top - lift) * t,
        ));
    }
    // down outside the turns to below the second clamp
    let a = PI + 2.0 * PI * turns;
    let (outer, below) = (1.6 * r, end.z - lift);
    for k in 1..=40 {
        let t = k as f64 / 40.0;
        let rr = r + (outer - r) * (2.0 * t).min(1.0);
        p.push(Vector3::new(
            rr * a.cos(),
            rr * a.sin(),
            top + (below - top) * t,
        ));
    }
    // and in, to enter the second clamp from below
    let start = Vector3::new(outer * a.cos(), outer * a.sin(), below);
    for k in 1..=20 {
        let t = k as f64 / 20.0;
        let xy = start + (end - start) * t;
        p.push(Vector3::new(
            xy.x,
            xy.y,
            below + lift * (0.5 * PI * t).sin(),
        ));
    }
    p
}

fn length(p: &[Vector3<f64>]) -> f64 {
    p.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// Centreline r(s), s ∈ [0, 1], of unit length from the origin to `end`
/// (|end| well below 1), parametrised by arc length.
pub fn trefoil_centreline(end: Vector3<f64>) -> impl Fn(f64) -> Vector3<f64> {
    // length grows with the size: bisect for unit length
    let (mut lo, mut hi) = (1e-3, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if length(&guide(mid, end)) < 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let p = guide(0.5 * (lo + hi), end);
    let mut arc = vec![0.0];
    for w in p.windows(2) {
        arc.push(arc.last().unwrap() + (w[1] - w[0]).norm());
    }
    let total = *arc.last().unwrap();
    move |s: f64| {
        let target = s.clamp(0.0, 1.0) * total;
        let k = arc.partition_point(|a| *a < target).clamp(1, p.len() - 1);
        let t = ((target - arc[k - 1]) / (arc[k] - arc[k - 1]).max(1e-300)).clamp(0.0, 1.0);
        p[k - 1] + (p[k] - p[k - 1]) * t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centreline_has_unit_length_and_its_ends_at_the_clamps() {
        let end = Vector3::new(0.05, 0.0, 0.115);
        let r = trefoil_centreline(end);
        let n = 2000;
        let l: f64 = (0..n)
            .map(|k| (r((k + 1) as f64 / n as f64) - r(k as f64 / n as f64)).norm())
            .sum();
        assert!((l - 1.0).abs() < 1e-3, "length {l}");
        assert!(r(0.0).norm() < 1e-12);
        assert!((r(1.0) - end).norm() < 1e-12);
    }
}
