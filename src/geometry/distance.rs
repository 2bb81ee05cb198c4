//! Distances between parts of a centreline and from it to the clamps' rays.
//!
//! A bounding-volume tree over index-contiguous runs of segments (parry's
//! `Aabb`s) gives the candidates; parry's exact segment–segment closest points
//! give the answer. Contiguous nodes let one test discard a whole pair of
//! subtrees whose arc-length separation is below the exclusion gap — which a
//! centroid-sorted tree cannot — so the search costs O(N log N) rather than
//! O(N · number of arc neighbours).

use nalgebra::Vector3;
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;
use parry3d_f64::query::closest_points::closest_points_segment_segment_with_locations_nD;

const LEAF: usize = 4;

/// A point as parry's vector.
pub(super) fn v(p: &Vector3<f64>) -> Vector {
    Vector::new(p.x, p.y, p.z)
}

/// Closest points of two segments: (distance, parameter on the first in [0,1],
/// parameter on the second).
pub fn segment_distance(
    a0: &Vector3<f64>,
    a1: &Vector3<f64>,
    b0: &Vector3<f64>,
    b1: &Vector3<f64>,
) -> (f64, f64, f64) {
    let (la, lb) =
        closest_points_segment_segment_with_locations_nD((&v(a0), &v(a1)), (&v(b0), &v(b1)));
    let ta = la.barycentric_coordinates()[1];
    let tb = lb.barycentric_coordinates()[1];
    let pa = a0 + ta * (a1 - a0);
    let pb = b0 + tb * (b1 - b0);
    ((pa - pb).norm(), ta, tb)
}

fn aabb_distance(a: &Aabb, b: &Aabb) -> f64 {
    let gap = (a.mins - b.maxs).max(b.mins - a.maxs).max(Vector::ZERO);
    gap.length()
}

struct Node {
    aabb: Aabb,
    lo: usize,
    hi: usize,
    children: Option<(usize, usize)>,
}

/// Bounding-volume tree over the segments of a polyline (segment k joins
/// points k and k+1), each node a contiguous run of segments.
pub struct CurveTree<'a> {
    points: &'a [Vector3<f64>],
    nodes: Vec<Node>,
}

impl<'a> CurveTree<'a> {
    /// Build over the open polyline `points`.
    pub fn new(points: &'a [Vector3<f64>]) -> Self {
        let mut tree = CurveTree {
            points,
            nodes: Vec::with_capacity(2 * points.len() / LEAF + 2),
        };
        if points.len() >= 2 {
            tree.build(0, points.len() - 1);
        }
        tree
    }

    fn build(&mut self, lo: usize, hi: usize) -> usize {
        let id = self.nodes.len();
        self.nodes.push(Node {
            aabb: Aabb::from_points(self.points[lo..=hi].iter().map(v)),
            lo,
            hi,
            children: None,
        });
        if hi - lo > LEAF {
            let mid = (lo + hi) / 2;
            let l = self.build(lo, mid);
            let r = self.build(mid, hi);
            self.nodes[id].children = Some((l, r));
        }
        id
    }
}

impl CurveTree<'_> {
    /// Visit the segment pairs (i < j) at least `gap` apart in arc length
    /// whose runs are not pruned: `prune(d)` is asked with the distance
    /// between two runs' boxes (nearest run pairs are visited first, so a
    /// shrinking bound prunes early); `leaf(i, j)` gets every surviving pair.
    pub(super) fn walk_pairs(
        &self,
        arc: &[f64],
        gap: f64,
        prune: &dyn Fn(f64) -> bool,
        leaf: &mut dyn FnMut(usize, usize),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![(0usize, 0usize)];
        while let Some((a, b)) = stack.pop() {
            let (na, nb) = (&self.nodes[a], &self.nodes[b]);
            // largest separation available between the two runs (a before b)
            if arc[nb.hi - 1] - arc[na.lo + 1] < gap || prune(aabb_distance(&na.aabb, &nb.aabb)) {
                continue;
            }
            match (na.children, nb.children) {
                (None, None) => {
                    for i in na.lo..na.hi {
                        for j in nb.lo.max(i + 1)..nb.hi {
                            if arc[j] - arc[i + 1] >= gap {
                                leaf(i, j);
                            }
                        }
                    }
                }
                _ => {
                    // split the larger run (a self pair splits into three pairs)
                    let split_a = match (na.children, nb.children) {
                        (Some(_), None) => true,
                        (None, Some(_)) => false,
                        _ => na.hi - na.lo >= nb.hi - nb.lo,
                    };
                    let mut pairs: Vec<(usize, usize)> = if a == b {
                        let (l, r) = na.children.unwrap();
                        vec![(l, l), (l, r), (r, r)]
                    } else if split_a {
                        let (l, r) = na.children.unwrap();
                        vec![(l, b), (r, b)]
                    } else {
                        let (l, r) = nb.children.unwrap();
                        vec![(a, l), (a, r)]
                    };
                    // visit the nearest pair first (pushed last)
                    pairs.sort_by(|p, q| {
                        let dp = aabb_distance(&self.nodes[p.0].aabb, &self.nodes[p.1].aabb);
                        let dq = aabb_distance(&self.nodes[q.0].aabb, &self.nodes[q.1].aabb);
                        dq.total_cmp(&dp)
                    });
                    stack.extend(pairs);
                }
            }
        }
    }

    /// Segment pairs (i < j), at least `gap` apart in arc length, closer than
    /// `within`.
    pub fn pairs_within(&self, arc: &[f64], gap: f64, within: f64) -> Vec<(usize, usize)> {
        let points = self.points;
        let mut out = Vec::new();
        self.walk_pairs(arc, gap, &|d| d >= within, &mut |i, j| {
            let (d, _, _) =
                segment_distance(&points[i], &points[i + 1], &points[j], &points[j + 1]);
            if d < within {
                out.push((i, j));
            }
        });
        out
    }
}

/// The closest approach of two parts of a curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Approach {
    /// Distance.
    pub distance: f64,
    /// Arc lengths where it is attained (s < s').
    pub s: [f64; 2],
    /// The two segments.
    pub segments: [usize; 2],
}

/// Closest approach of segments i and j of a polyline.
fn approach(points: &[Vector3<f64>], arc: &[f64], i: usize, j: usize) -> Approach {
    let (d, ta, tb) = segment_distance(&points[i], &points[i + 1], &points[j], &points[j + 1]);
    Approach {
        distance: d,
        s: [
            arc[i] + ta * (arc[i + 1] - arc[i]),
            arc[j] + tb * (arc[j + 1] - arc[j]),
        ],
        segments: [i, j],
    }
}

/// Minimum distance between segments of the polyline `points` (arc length
/// `arc[k]` at point k) whose arc-length separation (from the end of the first
/// to the start of the second) is at least `gap`. None if no pair qualifies.
pub fn min_self_distance(points: &[Vector3<f64>], arc: &[f64], gap: f64) -> Option<Approach> {
    let tree = CurveTree::new(points);
    let mut best: Option<Approach> = None;
    let bound = std::cell::Cell::new(f64::INFINITY);
    tree.walk_pairs(arc, gap, &|d| d >= bound.get(), &mut |i, j| {
        let a = approach(points, arc, i, j);
        if a.distance < bound.get() {
            bound.set(a.distance);
            best = Some(a);
        }
    });
    best
}

/// Brute-force O(N²) reference for [`min_self_distance`] (tests and checks).
pub fn min_self_distance_brute(points: &[Vector3<f64>], arc: &[f64], gap: f64) -> Option<Approach> {
    let mut best: Option<Approach> = None;
    for i in 0..points.len() - 1 {
        for j in i + 1..points.len() - 1 {
            if arc[j] - arc[i + 1] < gap {
                continue;
            }
            let a = approach(points, arc, i, j);
            if best.is_none_or(|b| a.distance < b.distance) {
                best = Some(a);
            }
        }
    }
    best
}

/// Closest approach (distance, arc length) of the polyline to a ray (origin,
/// unit direction, length), ignoring segments within arc length `exclude` of
/// `s_base` (the clamp the ray continues).
pub fn distance_to_ray(
    points: &[Vector3<f64>],
    arc: &[f64],
    origin: &Vector3<f64>,
    direction: &Vector3<f64>,
    length: f64,
    s_base: f64,
    exclude: f64,
) -> Option<(f64, f64)> {
    let tree = CurveTree::new(points);
    let end = origin + length * direction;
    let ray_box = Aabb::from_points([v(origin), v(&end)]);
    let mut best: Option<(f64, f64)> = None;
    let mut bound = f64::INFINITY;
    let mut stack = vec![0usize];
    while let Some(a) = stack.pop() {
        let n = &tree.nodes[a];
        if aabb_distance(&n.aabb, &ray_box) >= bound {
            continue;
        }
        // the whole run lies within the excluded arc around the clamp
        if arc[n.lo] >= s_base - exclude && arc[n.hi] <= s_base + exclude {
            continue;
        }
        match n.children {
            Some((l, r)) => stack.extend([l, r]),
            None => {
                for k in n.lo..n.hi {
                    let mid = 0.5 * (arc[k] + arc[k + 1]);
                    if (mid - s_base).abs() < exclude {
                        continue;
                    }
                    let (d, t, _) = segment_distance(&points[k], &points[k + 1], origin, &end);
                    if d < bound {
                        bound = d;
                        best = Some((d, arc[k] + t * (arc[k + 1] - arc[k])));
                    }
                }
            }
        }
    }
    best
}

/// The point at arc length `s` of the polyline (`arc[k]` is point k's).
pub fn point_at(points: &[Vector3<f64>], arc: &[f64], s: f64) -> Vector3<f64> {
    let k = arc.partition_point(|&a| a <= s).clamp(1, arc.len() - 1) - 1;
    let t = ((s - arc[k]) / (arc[k + 1] - arc[k])).clamp(0.0, 1.0);
    points[k] + t * (points[k + 1] - points[k])
}

/// Which side of each other two strands pass: at arc lengths s[0] < s[1],
/// the gap between their points along the normal n = c₀ × c₁ of the local
/// strand directions, each the chord over a few segments around segment
/// `around[i]` (oriented with s). Its sign flips exactly when the strands
/// pass through each other; None where the strands are parallel.
pub fn strand_side(
    points: &[Vector3<f64>],
    arc: &[f64],
    s: [f64; 2],
    around: [usize; 2],
) -> Option<f64> {
    let last = points.len() - 1;
    let chord = |k: usize| points[(k + 3).min(last)] - points[k.saturating_sub(2)];
    let n = chord(around[0]).cross(&chord(around[1]));
    let len = n.norm();
    if len <= 1e-12 * chord(around[0]).norm() * chord(around[1]).norm() {
        return None;
    }
    Some((point_at(points, arc, s[0]) - point_at(points, arc, s[1])).dot(&n) / len)
}
