//! The conditions that bound the good region: walls, crossings of two
//! strands (with their flip images), stability.

use crate::geometry::distance::segment_distance;
use crate::geometry::ribbon::Ribbon;
use crate::solve::event::Vanishing;
use nalgebra::Vector3;

/// The other strand of a crossing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OtherStrand {
    /// Another segment of the centreline.
    Segment(usize),
    /// The ray continuing the s = 0 clamp (along −e3).
    BottomRay,
    /// The ray continuing the s = 1 clamp (along +e3).
    TopRay,
}

/// Two strands whose passage through each other changes the knot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strands {
    /// Segment of the centreline (segment k joins centreline points k, k+1).
    pub first: usize,
    /// The strand it crosses.
    pub other: OtherStrand,
    /// Orientation: +1 or −1, so that the good side is positive.
    pub sign: f64,
    /// Number of centreline segments (for the flip image of the strands).
    pub segments: usize,
}

/// A boundary condition: zero on the curve, positive on the good side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Condition {
    /// Walls: min(lowest interior node height, z* − highest).
    Wall,
    /// Signed distance of two crossing strands.
    Crossing(Strands),
    /// Lowest eigenvalue of the Hessian.
    Stability,
}

impl Condition {
    /// The quantity that vanishes on it.
    pub fn vanishing(&self) -> Vanishing {
        match self {
            Condition::Wall => Vanishing::WallGap,
            Condition::Crossing(_) => Vanishing::StrandGap,
            Condition::Stability => Vanishing::Singularity,
        }
    }

    /// Description, as in the JSON summary.
    pub fn describe(&self) -> String {
        match self {
            Condition::Wall => "wall".into(),
            Condition::Crossing(s) => match s.other {
                OtherStrand::Segment(j) => format!("crossing of segments {} and {j}", s.first),
                OtherStrand::BottomRay => format!("segment {} crossing the bottom ray", s.first),
                OtherStrand::TopRay => format!("segment {} crossing the top ray", s.first),
            },
            Condition::Stability => "lowest eigenvalue zero".into(),
        }
    }
}

/// Signed distance of segment i from the other strand (positive along
/// tᵢ × t_other) and the unsigned distance.
pub(super) fn strand_distance(
    points: &[Vector3<f64>],
    i: usize,
    other: OtherStrand,
    reach: f64,
) -> (f64, f64) {
    let (a0, a1) = (points[i], points[i + 1]);
    let last = *points.last().unwrap();
    let (b0, b1) = match other {
        OtherStrand::Segment(j) => (points[j], points[j + 1]),
        OtherStrand::BottomRay => (points[0], points[0] - reach * Vector3::z()),
        OtherStrand::TopRay => (last, last + reach * Vector3::z()),
    };
    signed_segments(&a0, &a1, &b0, &b1)
}

/// Distance of two segments and their signed distance along the cross
/// product of their directions.
fn signed_segments(
    a0: &Vector3<f64>,
    a1: &Vector3<f64>,
    b0: &Vector3<f64>,
    b1: &Vector3<f64>,
) -> (f64, f64) {
    let (d, ta, tb) = segment_distance(a0, a1, b0, b1);
    let pa = a0 + ta * (a1 - a0);
    let pb = b0 + tb * (b1 - b0);
    let n = (a1 - a0).cross(&(b1 - b0));
    (d, (pb - pa).dot(&n) / n.norm().max(1e-300))
}

/// The gap of the ribbon `ribbon` at two strands whose centrelines cross
/// near segments i and j: the least over the four pairs of its edges
/// ([`Ribbon::edge`]: continuous, so their distances are too, tending to the
/// continuum's r ± (w/2) d1) of their signed distance, each pair's closest
/// segments sought within `window` of i and j, times `sign`. Two narrow
/// ribbons crossing at an angle first touch edge to edge, so it vanishes
/// where the ribbon first touches itself there.
pub(super) fn ribbon_gap(ribbon: &Ribbon, i: usize, j: usize, window: usize, sign: f64) -> f64 {
    let segments = ribbon.points.len() - 1;
    let near = |k: usize| k.saturating_sub(window)..(k + window + 1).min(segments);
    let mut gap = f64::INFINITY;
    for (sa, sb) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
        let mut best = (f64::INFINITY, 0.0);
        for a in near(i) {
            let [a0, a1] = ribbon.edge(a, sa);
            for b in near(j).filter(|&b| b >= a + 2) {
                let [b0, b1] = ribbon.edge(b, sb);
                let (d, signed) = signed_segments(&a0, &a1, &b0, &b1);
                if d < best.0 {
                    best = (d, signed);
                }
            }
        }
        gap = gap.min(sign * best.1);
    }
    gap
}

impl Strands {
    /// The same strands, up to 3 segments along each, or their image by
    /// the flip symmetry (s ↔ 1 − s, the rays swapped): a flip-symmetric
    /// knot passes through itself at two mirror points at once, so the two
    /// crossings are one boundary.
    pub(super) fn near(&self, first: usize, other: OtherStrand) -> bool {
        // strands crossing at a shallow angle are close over several pairs
        self.near_within(first, other, 3)
    }

    /// As [`Strands::near`], within `window` segments along each.
    pub(super) fn near_within(&self, first: usize, other: OtherStrand, window: usize) -> bool {
        let close = |x: usize, y: usize| x.abs_diff(y) <= window;
        let same = |a: usize, oa: OtherStrand, b: usize, ob: OtherStrand| {
            close(a, b)
                && match (oa, ob) {
                    (OtherStrand::Segment(i), OtherStrand::Segment(j)) => close(i, j),
                    (x, y) => x == y,
                }
        };
        let m = |i: usize| (self.segments - 1).saturating_sub(i);
        let mirror = match other {
            OtherStrand::Segment(j) => (m(j), OtherStrand::Segment(m(first))),
            OtherStrand::BottomRay => (m(first), OtherStrand::TopRay),
            OtherStrand::TopRay => (m(first), OtherStrand::BottomRay),
        };
        same(self.first, self.other, first, other)
            || same(self.first, self.other, mirror.0, mirror.1)
    }
}

/// The strands nearest to passing through each other: the closest pair of
/// segments at least `gap` apart in arc length, or a segment and a ray,
/// other than the strands `except` (the crossings the walk is on or tried
/// already at this corner, in contact at a corner between two crossings);
/// pairs of segments only unless `rays`.
pub(super) fn closest_strands(
    points: &[Vector3<f64>],
    arc: &[f64],
    gap: f64,
    except: &[Strands],
    rays: bool,
) -> (usize, OtherStrand) {
    let reach = crate::geometry::closure::reach(points);
    let segments = points.len() - 1;
    let skip = |i: usize, o: OtherStrand| except.iter().any(|e| e.near(i, o));
    let mut best = (f64::INFINITY, 0, OtherStrand::TopRay);
    for i in 0..segments {
        for j in i + 1..segments {
            if arc[j] - arc[i + 1] >= gap && !skip(i, OtherStrand::Segment(j)) {
                let d = strand_distance(points, i, OtherStrand::Segment(j), reach).0;
                if d < best.0 {
                    best = (d, i, OtherStrand::Segment(j));
                }
            }
        }
        let ends = [(OtherStrand::BottomRay, 0.0), (OtherStrand::TopRay, 1.0)];
        for (ray, base) in ends.into_iter().filter(|_| rays) {
            let mid = 0.5 * (arc[i] + arc[i + 1]);
            if (mid - base).abs() >= gap && !skip(i, ray) {
                let d = strand_distance(points, i, ray, reach).0;
                if d < best.0 {
                    best = (d, i, ray);
                }
            }
        }
    }
    (best.1, best.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strand_distance_is_signed_and_changes_sign_through_the_crossing() {
        // segment 0 along x at the origin; segment 2 along y at height h
        let at = |h: f64| {
            vec![
                Vector3::new(-1.0, 0.0, 0.0),
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(0.0, -1.0, h),
                Vector3::new(0.0, 1.0, h),
            ]
        };
        let (d, up) = strand_distance(&at(0.3), 0, OtherStrand::Segment(2), 10.0);
        let (_, down) = strand_distance(&at(-0.2), 0, OtherStrand::Segment(2), 10.0);
        assert!((d - 0.3).abs() < 1e-12 && (up - 0.3).abs() < 1e-12);
        assert!((down + 0.2).abs() < 1e-12);
    }

    #[test]
    fn a_ribbon_s_gap_is_the_centrelines_less_the_pieces_reach_across() {
        // strand a along x at height 0, strand b along y at height h; the
        // ribbons' d1 tilted by 30° out of their planes: each reaches
        // (w/2) sin 30° towards the other, so the edges meet at h = w/2
        let (w, tilt) = (0.2, 30f64.to_radians());
        let at = |h: f64| {
            let points = vec![
                Vector3::new(-1.0, 0.0, 0.0),
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(0.0, -1.0, h),
                Vector3::new(0.0, 0.0, h),
                Vector3::new(0.0, 1.0, h),
            ];
            let across_a = Vector3::new(0.0, tilt.cos(), tilt.sin());
            let across_b = Vector3::new(tilt.cos(), 0.0, tilt.sin());
            let d1 = vec![across_a, across_a, across_a, across_b, across_b];
            let ribbon = Ribbon {
                points: &points,
                d1: &d1,
                width: w,
            };
            // the crossing is at points 1 and 4, whose directors are their
            // strands' own (the joining segment's mixes in at points 2, 3)
            ribbon_gap(&ribbon, 0, 3, 1, 1.0)
        };
        for h in [0.3, 0.1, 0.05] {
            // sign: t_a × t_b = x × y = z, so b above a is positive
            let expected = h - 0.5 * w * 2.0 * tilt.sin();
            assert!((at(h) - expected).abs() < 1e-12, "{h}: {}", at(h));
        }
    }

    #[test]
    fn strands_are_the_same_up_to_neighbours_and_the_flip_image() {
        let s = Strands {
            first: 22,
            other: OtherStrand::Segment(76),
            sign: 1.0,
            segments: 101,
        };
        assert!(s.near(24, OtherStrand::Segment(74)));
        // the flip image s ↔ 1 − s: segment i ↔ 100 − i, the pair reversed
        assert!(s.near(24, OtherStrand::Segment(78)));
        assert!(!s.near(12, OtherStrand::Segment(89)));
        let r = Strands {
            first: 10,
            other: OtherStrand::BottomRay,
            sign: 1.0,
            segments: 101,
        };
        assert!(r.near(90, OtherStrand::TopRay));
        assert!(!r.near(90, OtherStrand::BottomRay));
    }
}
