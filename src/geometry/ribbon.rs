//! A strip of finite width as a ribbon: the surface swept by a segment of
//! width w across the centreline along its material director d1 (from −w/2
//! to +w/2). At each point of the centreline the ribbon runs across along
//! the mean of the directors d1 of the two segments meeting there, so each
//! segment carries a quadrilateral piece between its two ends' crossbars and
//! the ribbon is continuous (its edges do not jump where d1 turns from one
//! segment to the next), tending to the continuum's r ± (w/2) d1. Distances
//! between parts of the ribbon and its heights (for the walls) are measured
//! on these pieces, not on the centreline.
//!
//! A piece is two of parry's triangles; the distance of two pieces is
//! exact: zero when an edge of one (its diagonal included) pierces the
//! other (parry's ray–triangle test), else the least of the corner-to-piece
//! projections (parry's triangle point projection) and the edge–edge
//! closest points — the closest points of two disjoint triangles always
//! include a corner or a pair of edges.

use crate::geometry::distance::{Approach, CurveTree, segment_distance, v};
use nalgebra::Vector3;
use parry3d_f64::query::{PointQuery, Ray, RayCast};
use parry3d_f64::shape::Triangle;

/// The piece of one ribbon segment: corners p0 − a0, p0 + a0, p1 + a1,
/// p1 − a1 with a0, a1 its ends' crossbars ((w/2) d1 for a rectangle), as
/// the two triangles either side of the diagonal from the first corner to
/// the third.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// Corners in order round the piece.
    pub corners: [Vector3<f64>; 4],
}

/// The closest points of two pieces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    /// Their distance (0 when the pieces meet).
    pub distance: f64,
    /// The closest point on the first piece.
    pub on_a: Vector3<f64>,
    /// The closest point on the second piece.
    pub on_b: Vector3<f64>,
}

impl Piece {
    /// The piece of the segment p0 → p1 with director `d1` (a unit vector
    /// normal to the segment) and full width `width`.
    pub fn new(p0: &Vector3<f64>, p1: &Vector3<f64>, d1: &Vector3<f64>, width: f64) -> Piece {
        Piece::between(p0, p1, d1, d1, width)
    }

    /// The piece of the segment p0 → p1 whose ends run across along `a0`
    /// and `a1` (unit vectors), of full width `width`: a quadrilateral, as
    /// two triangles.
    pub fn between(
        p0: &Vector3<f64>,
        p1: &Vector3<f64>,
        a0: &Vector3<f64>,
        a1: &Vector3<f64>,
        width: f64,
    ) -> Piece {
        let (a0, a1) = (0.5 * width * a0, 0.5 * width * a1);
        Piece {
            corners: [p0 - a0, p0 + a0, p1 + a1, p1 - a1],
        }
    }

    fn triangles(&self) -> [Triangle; 2] {
        let c = self.corners.map(|p| v(&p));
        [
            Triangle::new(c[0], c[1], c[2]),
            Triangle::new(c[0], c[2], c[3]),
        ]
    }

    /// The triangles' edges: the four round the piece and the diagonal
    /// (where a piece that is not flat may be met or be closest).
    fn edges(&self) -> [(Vector3<f64>, Vector3<f64>); 5] {
        let c = &self.corners;
        [
            (c[0], c[1]),
            (c[1], c[2]),
            (c[2], c[3]),
            (c[3], c[0]),
            (c[0], c[2]),
        ]
    }

    /// The nearest point of the piece to `p`.
    fn project(&self, p: &Vector3<f64>) -> Vector3<f64> {
        let [t0, t1] = self.triangles();
        let (a, b) = (
            t0.project_local_point(v(p), true).point,
            t1.project_local_point(v(p), true).point,
        );
        let near = if (a - v(p)).length() <= (b - v(p)).length() {
            a
        } else {
            b
        };
        Vector3::new(near.x, near.y, near.z)
    }

    /// Where the segment e0 → e1 pierces the piece, if it does (a segment
    /// lying in the piece's plane is found by the edge–edge and corner
    /// distances instead).
    fn pierced_by(&self, e0: &Vector3<f64>, e1: &Vector3<f64>) -> Option<Vector3<f64>> {
        let ray = Ray::new(v(e0), v(&(e1 - e0)));
        self.triangles()
            .iter()
            .find_map(|t| t.cast_local_ray(&ray, 1.0, true))
            .map(|toi| e0 + toi * (e1 - e0))
    }
}

/// Exact closest points of two ribbon pieces.
pub fn piece_distance(a: &Piece, b: &Piece) -> Closest {
    // meeting pieces meet where an edge of one pierces the other
    for (x, y) in [(a, b), (b, a)] {
        for (e0, e1) in x.edges() {
            if let Some(p) = y.pierced_by(&e0, &e1) {
                return Closest {
                    distance: 0.0,
                    on_a: p,
                    on_b: p,
                };
            }
        }
    }
    let mut best = Closest {
        distance: f64::INFINITY,
        on_a: a.corners[0],
        on_b: b.corners[0],
    };
    let mut offer = |on_a: Vector3<f64>, on_b: Vector3<f64>| {
        let d = (on_a - on_b).norm();
        if d < best.distance {
            best = Closest {
                distance: d,
                on_a,
                on_b,
            };
        }
    };
    for c in &a.corners {
        offer(*c, b.project(c));
    }
    for c in &b.corners {
        offer(a.project(c), *c);
    }
    for (a0, a1) in a.edges() {
        for (b0, b1) in b.edges() {
            let (_, ta, tb) = segment_distance(&a0, &a1, &b0, &b1);
            offer(a0 + ta * (a1 - a0), b0 + tb * (b1 - b0));
        }
    }
    best
}

/// A ribbon: the open polyline `points`, the director d1 of each segment
/// (`d1[k]` for points k → k+1, unit and normal to it) and the width.
#[derive(Clone, Copy, Debug)]
pub struct Ribbon<'a> {
    /// Centreline points.
    pub points: &'a [Vector3<f64>],
    /// Director d1 of each segment.
    pub d1: &'a [Vector3<f64>],
    /// Full width w (the ribbon spans ±w/2 along d1).
    pub width: f64,
}

impl Ribbon<'_> {
    /// The direction the ribbon runs across at point k: the mean of the
    /// directors of the segments meeting there (the end segments' own at
    /// the ends).
    pub fn across(&self, k: usize) -> Vector3<f64> {
        let last = self.d1.len() - 1;
        let (before, after) = (self.d1[k.saturating_sub(1).min(last)], self.d1[k.min(last)]);
        (before + after).try_normalize(1e-12).unwrap_or(after)
    }

    /// Edge `sign` (±1) of segment k's piece: from point k's end of its
    /// crossbar to point k + 1's (continuous from one piece to the next).
    pub fn edge(&self, k: usize, sign: f64) -> [Vector3<f64>; 2] {
        let a = sign * (0.5 * self.width);
        [
            self.points[k] + a * self.across(k),
            self.points[k + 1] + a * self.across(k + 1),
        ]
    }

    /// The piece of segment k, between the crossbars at its two points.
    pub fn piece(&self, k: usize) -> Piece {
        Piece::between(
            &self.points[k],
            &self.points[k + 1],
            &self.across(k),
            &self.across(k + 1),
            self.width,
        )
    }

    /// Arc length of the centreline point nearest to `p`'s projection on
    /// segment k (the ribbon's point across its width).
    fn arc_at(&self, arc: &[f64], k: usize, p: &Vector3<f64>) -> f64 {
        let e = self.points[k + 1] - self.points[k];
        let t = ((p - self.points[k]).dot(&e) / e.norm_squared()).clamp(0.0, 1.0);
        arc[k] + t * (arc[k + 1] - arc[k])
    }

    fn approach(&self, arc: &[f64], i: usize, j: usize) -> Approach {
        let c = piece_distance(&self.piece(i), &self.piece(j));
        Approach {
            distance: c.distance,
            s: [self.arc_at(arc, i, &c.on_a), self.arc_at(arc, j, &c.on_b)],
            segments: [i, j],
        }
    }

    /// Minimum distance between pieces whose segments are at least `gap`
    /// apart in arc length (as [`crate::geometry::distance::min_self_distance`]
    /// for the centreline; `arc[k]` is point k's arc length), and the
    /// centreline arc lengths across from the closest points. None if no pair
    /// qualifies.
    pub fn min_self_distance(&self, arc: &[f64], gap: f64) -> Option<Approach> {
        let tree = CurveTree::new(self.points);
        let mut best: Option<Approach> = None;
        let bound = std::cell::Cell::new(f64::INFINITY);
        // every ribbon point lies within w/2 of its run's centreline, so two
        // runs' pieces are no closer than their centreline boxes less w
        let width = self.width;
        tree.walk_pairs(arc, gap, &|d| d - width >= bound.get(), &mut |i, j| {
            let a = self.approach(arc, i, j);
            if a.distance < bound.get() {
                bound.set(a.distance);
                best = Some(a);
            }
        });
        best
    }

    /// A pair of pieces at least `gap` apart in arc length that touch (their
    /// distance is zero), other than the pairs `skip(i, j)` (i < j) leaves
    /// out, if there is one.
    pub fn touching_pair(
        &self,
        arc: &[f64],
        gap: f64,
        skip: &dyn Fn(usize, usize) -> bool,
    ) -> Option<[usize; 2]> {
        let tree = CurveTree::new(self.points);
        let mut found = None;
        let width = self.width;
        let done = std::cell::Cell::new(false);
        // pieces touch only where their centrelines come within w
        tree.walk_pairs(arc, gap, &|d| done.get() || d > width, &mut |i, j| {
            if found.is_none()
                && !skip(i, j)
                && piece_distance(&self.piece(i), &self.piece(j)).distance <= 0.0
            {
                found = Some([i, j]);
                done.set(true);
            }
        });
        found
    }

    /// Brute-force O(N²) reference for [`Ribbon::min_self_distance`].
    pub fn min_self_distance_brute(&self, arc: &[f64], gap: f64) -> Option<Approach> {
        let mut best: Option<Approach> = None;
        for i in 0..self.points.len() - 1 {
            for j in i + 1..self.points.len() - 1 {
                if arc[j] - arc[i + 1] < gap {
                    continue;
                }
                let a = self.approach(arc, i, j);
                if best.is_none_or(|b| a.distance < b.distance) {
                    best = Some(a);
                }
            }
        }
        best
    }

    /// The lowest and highest heights (z) of the ribbon across each point:
    /// its crossbar there reaches ±(w/2)|a_z| above and below it (a the
    /// direction across, [`Ribbon::across`]).
    pub fn heights(&self) -> (Vec<f64>, Vec<f64>) {
        let half = 0.5 * self.width;
        self.points
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let reach = half * self.across(k).z.abs();
                (p.z - reach, p.z + reach)
            })
            .unzip()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z)
    }

    #[test]
    fn flat_pieces_side_by_side_are_their_gap_apart() {
        // two unit pieces along x in the plane z = 0, widths 0.2, centrelines
        // 0.5 apart in y: the facing edges are 0.5 − 0.2 apart
        let a = Piece::new(&p(0.0, 0.0, 0.0), &p(1.0, 0.0, 0.0), &Vector3::y(), 0.2);
        let b = Piece::new(&p(0.0, 0.5, 0.0), &p(1.0, 0.5, 0.0), &Vector3::y(), 0.2);
        let c = piece_distance(&a, &b);
        assert!((c.distance - 0.3).abs() < 1e-15, "{}", c.distance);
        assert!((c.on_a.y - 0.1).abs() < 1e-15 && (c.on_b.y - 0.4).abs() < 1e-15);
    }

    #[test]
    fn an_edge_through_a_piece_makes_them_meet() {
        // a vertical piece standing through a horizontal one
        let a = Piece::new(&p(-1.0, 0.0, 0.0), &p(1.0, 0.0, 0.0), &Vector3::y(), 1.0);
        let b = Piece::new(&p(0.0, 0.0, -1.0), &p(0.0, 0.0, 1.0), &Vector3::x(), 0.5);
        let c = piece_distance(&a, &b);
        assert_eq!(c.distance, 0.0);
        assert_eq!(piece_distance(&b, &a).distance, 0.0);
    }

    #[test]
    fn the_tree_search_finds_the_brute_force_minimum() {
        // a twisted helix of two turns: its ribbon's nearest pieces across a
        // turn, found by the tree as by every pair
        let n = 120;
        let points: Vec<Vector3<f64>> = (0..=n)
            .map(|k| {
                let t = 4.0 * std::f64::consts::PI * k as f64 / n as f64;
                p(0.1 * t.cos(), 0.1 * t.sin(), 0.012 * t)
            })
            .collect();
        let d1: Vec<Vector3<f64>> = (0..n)
            .map(|k| {
                let e = (points[k + 1] - points[k]).normalize();
                let twist = 3.0 * k as f64 / n as f64;
                let n1 = e.cross(&Vector3::z()).normalize();
                let n2 = e.cross(&n1);
                twist.cos() * n1 + twist.sin() * n2
            })
            .collect();
        let arc: Vec<f64> = std::iter::once(0.0)
            .chain(points.windows(2).scan(0.0, |s, w| {
                *s += (w[1] - w[0]).norm();
                Some(*s)
            }))
            .collect();
        let ribbon = Ribbon {
            points: &points,
            d1: &d1,
            width: 0.03,
        };
        let fast = ribbon.min_self_distance(&arc, 0.3).unwrap();
        let slow = ribbon.min_self_distance_brute(&arc, 0.3).unwrap();
        assert_eq!(fast.distance, slow.distance);
        // the ribbon is closer to itself than the centreline is
        let line = crate::geometry::distance::min_self_distance(&points, &arc, 0.3).unwrap();
        assert!(fast.distance < line.distance - 1e-3, "{fast:?} {line:?}");
    }

    #[test]
    fn heights_reach_across_the_tilted_width() {
        let points = [p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(2.0, 0.0, 1.0)];
        let s = 0.5f64.sqrt();
        let d1 = [Vector3::y(), p(0.0, s, s)];
        let ribbon = Ribbon {
            points: &points,
            d1: &d1,
            width: 0.4,
        };
        let (low, high) = ribbon.heights();
        assert_eq!(low[0], 0.0);
        // across at point 1: the mean of y and (0, s, s), 22.5° out of the
        // plane; at the last point, its segment's own
        let mid = std::f64::consts::FRAC_PI_8.sin();
        assert!((low[1] + 0.2 * mid).abs() < 1e-15, "{}", low[1]);
        assert!((high[2] - 1.0 - 0.2 * s).abs() < 1e-15);
    }
}
