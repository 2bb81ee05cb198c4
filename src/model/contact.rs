//! Contact of the rod (a tube of diameter h around its centreline) with the
//! clamps' rays, with fixed obstacles and with itself: candidate pairs within
//! a margin, their gaps g = distance − h and the gradients of g with respect
//! to the nodes (closest-point parameters held fixed: exact first order for
//! a unique closest pair).

use crate::geometry::distance::{CurveTree, segment_distance};
use crate::linalg::jet::{self, Scalar};
use crate::model::rod::RodState;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// What the rod touches.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Obstacle {
    /// The ray continuing the s = 0 clamp (along −e3 from the origin).
    RayBottom,
    /// The ray continuing the s = 1 clamp (along +e3 from the end point).
    RayTop,
    /// Fixed obstacle k of the scene (a segment).
    Fixed(usize),
    /// The rod itself, at arc length s'.
    SelfAt(f64),
}

impl Obstacle {
    /// Short name for summaries.
    pub fn name(&self) -> String {
        match self {
            Obstacle::RayBottom => "ray_bottom".into(),
            Obstacle::RayTop => "ray_top".into(),
            Obstacle::Fixed(k) => format!("obstacle_{k}"),
            Obstacle::SelfAt(_) => "self".into(),
        }
    }
}

/// Contact settings.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactModel {
    /// Rod diameter h: centrelines keep at least h apart (and h from the
    /// rays, which have the rod's diameter; h/2 from the fixed obstacles'
    /// axes plus their radius, taken as h/2 as well).
    pub diameter: f64,
    /// Contact with the two rays.
    pub rays: bool,
    /// Self-contact (pairs at least `gap` apart in arc length).
    pub self_contact: bool,
    /// Arc-length gap below which two parts of the rod do not interact, and
    /// the arc length near each clamp that does not touch its ray.
    pub gap: f64,
    /// Fixed segment obstacles (end points).
    pub obstacles: Vec<[Vector3<f64>; 2]>,
    /// Pairs closer than h + margin become constraints; a step moves no node
    /// more than margin / 2, so no other pair can close the gap in one step.
    pub margin: f64,
    /// Length of the rays.
    pub ray_length: f64,
}

/// One candidate contact.
#[derive(Clone, Debug)]
pub struct Gap {
    /// Gap g = distance − h (negative: interpenetration).
    pub gap: f64,
    /// Arc length on the rod.
    pub s: f64,
    /// The other body.
    pub obstacle: Obstacle,
    /// ∂g/∂x for the centreline points involved: (point index, gradient).
    pub gradient: Vec<(usize, Vector3<f64>)>,
    /// Centreline segments involved (first on the rod; second if self).
    pub segments: [usize; 2],
}

/// Closest points of segment a (points a0, a1) to segment b: the gap and the
/// gradients on the four end points.
fn pair_gap(p: &[Vector3<f64>; 4], diameter: f64) -> (f64, f64, f64, [Vector3<f64>; 4]) {
    let (d, ta, tb) = segment_distance(&p[0], &p[1], &p[2], &p[3]);
    let pa = p[0] + ta * (p[1] - p[0]);
    let pb = p[2] + tb * (p[3] - p[2]);
    let n = if d > 1e-300 {
        (pa - pb) / d
    } else {
        // coincident: any direction perpendicular to the first segment
        let t = (p[1] - p[0]).normalize();
        crate::geometry::normal_to(&t)
    };
    (
        d - diameter,
        ta,
        tb,
        [(1.0 - ta) * n, ta * n, -(1.0 - tb) * n, -tb * n],
    )
}

/// Distance between the segments x[0..3]–x[3..6] and x[6..9]–x[9..12] with the
/// closest-point case of the current configuration held: each parameter is
/// either interior (then it is the stationary point, a function of the
/// coordinates) or at the end `Some(t)` where it sits. Smooth within the case,
/// so its jets give the gap's exact second derivatives there.
fn case_distance<T: Scalar>(x: &[T; 12], ta: Option<f64>, tb: Option<f64>) -> T {
    let p = |k: usize| [x[3 * k], x[3 * k + 1], x[3 * k + 2]];
    let sub = |a: [T; 3], b: [T; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [T; 3], b: [T; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let along = |a: [T; 3], t: T, u: [T; 3]| [a[0] + t * u[0], a[1] + t * u[1], a[2] + t * u[2]];
    let (u, v, w) = (sub(p(1), p(0)), sub(p(3), p(2)), sub(p(0), p(2)));
    let (s, t) = match (ta, tb) {
        (None, None) => {
            let (a, b, c, d, e) = (dot(u, u), dot(u, v), dot(v, v), dot(u, w), dot(v, w));
            let det = a * c - b * b;
            ((b * e - c * d) / det, (a * e - b * d) / det)
        }
        (Some(s), None) => {
            let s = T::from(s);
            (s, dot(sub(along(p(0), s, u), p(2)), v) / dot(v, v))
        }
        (None, Some(t)) => {
            let t = T::from(t);
            (dot(sub(along(p(2), t, v), p(0)), u) / dot(u, u), t)
        }
        (Some(s), Some(t)) => (T::from(s), T::from(t)),
    };
    let r = sub(along(p(0), s, u), along(p(2), t, v));
    dot(r, r).sqrt()
}

/// Second derivatives of the gap of segments p[0]p[1] and p[2]p[3] in their
/// 12 coordinates (row-major), at the current closest-point case.
pub fn gap_hessian(p: &[Vector3<f64>; 4]) -> [[f64; 12]; 12] {
    let (_, ta, tb) = segment_distance(&p[0], &p[1], &p[2], &p[3]);
    let (u, v) = (p[1] - p[0], p[3] - p[2]);
    // nearly parallel segments: the interior stationary point is ill-posed,
    // hold the first parameter where it is
    let parallel = u.cross(&v).norm_squared() < 1e-10 * u.norm_squared() * v.norm_squared();
    let end = |t: f64| (t <= 1e-12 || t >= 1.0 - 1e-12).then_some(t);
    let ta_case = end(ta).or(parallel.then_some(ta));
    let tb_case = end(tb);
    let mut x = [0.0; 12];
    for k in 0..4 {
        x[3 * k..3 * k + 3].copy_from_slice(p[k].as_slice());
    }
    jet::hessian::<12, 78>(x, |y| case_distance(y, ta_case, tb_case)).2
}

impl ContactModel {
    /// Candidate contacts of `state` (gap below `margin`).
    pub fn gaps(&self, state: &RodState) -> Vec<Gap> {
        let (points, arc) = state.centreline();
        let h = self.diameter;
        let within = h + self.margin;
        let mut out = Vec::new();
        let segs = points.len() - 1;
        let end = *points.last().unwrap();
        let mut obstacles: Vec<(Obstacle, [Vector3<f64>; 2], f64)> = Vec::new();
        if self.rays {
            obstacles.push((
                Obstacle::RayBottom,
                [Vector3::zeros(), -self.ray_length * Vector3::z()],
                0.0,
            ));
            obstacles.push((
                Obstacle::RayTop,
                [end, end + self.ray_length * Vector3::z()],
                1.0,
            ));
        }
        for (k, o) in self.obstacles.iter().enumerate() {
            obstacles.push((Obstacle::Fixed(k), *o, f64::NAN));
        }
        for (obstacle, [o0, o1], base) in &obstacles {
            for k in 0..segs {
                let mid = 0.5 * (arc[k] + arc[k + 1]);
                // a ray continues its clamp: the rod near it does not touch it
                if base.is_finite() && (mid - base).abs() < self.gap {
                    continue;
                }
                let (g, ta, _, grad) = pair_gap(&[points[k], points[k + 1], *o0, *o1], h);
                if g < self.margin {
                    out.push(Gap {
                        gap: g,
                        s: arc[k] + ta * (arc[k + 1] - arc[k]),
                        obstacle: *obstacle,
                        gradient: vec![(k, grad[0]), (k + 1, grad[1])],
                        segments: [k, usize::MAX],
                    });
                }
            }
        }
        if self.self_contact {
            for (i, j) in self_pairs(&points, &arc, self.gap, within) {
                let (g, ta, tb, grad) =
                    pair_gap(&[points[i], points[i + 1], points[j], points[j + 1]], h);
                if g < self.margin {
                    out.push(Gap {
                        gap: g,
                        s: arc[i] + ta * (arc[i + 1] - arc[i]),
                        obstacle: Obstacle::SelfAt(arc[j] + tb * (arc[j + 1] - arc[j])),
                        gradient: vec![
                            (i, grad[0]),
                            (i + 1, grad[1]),
                            (j, grad[2]),
                            (j + 1, grad[3]),
                        ],
                        segments: [i, j],
                    });
                }
            }
        }
        // rows of neighbouring segments whose closest points coincide (at a
        // shared node) are the same constraint: keep one, or the QP's rows
        // are exactly dependent
        let mut kept: Vec<Gap> = Vec::with_capacity(out.len());
        for g in out {
            let dup = kept.iter().any(|k| {
                std::mem::discriminant(&k.obstacle) == std::mem::discriminant(&g.obstacle)
                    && (k.gap - g.gap).abs() < 1e-14
                    && (k.s - g.s).abs() < 1e-12
                    && match (k.obstacle, g.obstacle) {
                        (Obstacle::SelfAt(a), Obstacle::SelfAt(b)) => (a - b).abs() < 1e-12,
                        (Obstacle::Fixed(a), Obstacle::Fixed(b)) => a == b,
                        _ => true,
                    }
            });
            if !dup {
                kept.push(g);
            }
        }
        kept
    }

    /// The four end points of a contact's segment pair (the rod's segment
    /// first; a ray or obstacle contributes fixed points).
    pub fn pair_points(&self, points: &[Vector3<f64>], c: &Gap) -> [Vector3<f64>; 4] {
        let k = c.segments[0];
        let other = match c.obstacle {
            Obstacle::RayBottom => [Vector3::zeros(), -self.ray_length * Vector3::z()],
            Obstacle::RayTop => {
                let end = *points.last().unwrap();
                [end, end + self.ray_length * Vector3::z()]
            }
            Obstacle::Fixed(o) => self.obstacles[o],
            Obstacle::SelfAt(_) => [points[c.segments[1]], points[c.segments[1] + 1]],
        };
        [points[k], points[k + 1], other[0], other[1]]
    }

    /// The gap of a candidate (same segments and obstacle) for the centreline
    /// `points` of another state.
    pub fn gap_at(&self, points: &[Vector3<f64>], c: &Gap) -> f64 {
        pair_gap(&self.pair_points(points, c), self.diameter).0
    }
}

/// Segment pairs (i < j) of a polyline at least `gap` apart in arc length
/// whose distance is below `within`: a walk of the bounding-volume tree,
/// O(N log N + pairs).
pub fn self_pairs(
    points: &[Vector3<f64>],
    arc: &[f64],
    gap: f64,
    within: f64,
) -> Vec<(usize, usize)> {
    let tree = CurveTree::new(points);
    tree.pairs_within(arc, gap, within)
}

/// A contact force of an equilibrium.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactForce {
    /// Arc length on the rod.
    pub s: f64,
    /// What it touches ("ray_bottom", "ray_top", "obstacle_k", "self").
    pub obstacle: String,
    /// Magnitude of the normal force (the multiplier of gap ≥ 0), in units
    /// of B/L².
    pub force: f64,
    /// Gap (distance − h) there: 0 in contact, to solver tolerance.
    pub gap: f64,
}
