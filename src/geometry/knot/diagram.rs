//! A knot diagram: the crossings of a closed polygon projected along a
//! direction (found by a sweep over the segments' extents), its Gauss code,
//! the Reidemeister I and II moves that shrink it, and its Alexander matrix.

use nalgebra::{Vector2, Vector3};

/// A crossing of the projected diagram: segment and parameter along it of the
/// strand above and of the one below, and the crossing's sign.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Crossing {
    over: (usize, f64),
    under: (usize, f64),
    /// Whether the crossing is positive (right-handed).
    pub(crate) positive: bool,
}

/// Why a projection gives no diagram.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Degenerate {
    /// A crossing at a vertex, overlapping or point-like projected segments,
    /// or three strands through one point: another direction will do.
    Projection,
    /// Two segments meet in space, near this point: the curve passes through
    /// itself and has no knot type.
    SelfIntersection(Vector3<f64>),
    /// More crossings than [`MOST_CROSSINGS`] (so many that even listing
    /// them would take gigabytes).
    TooMany(usize),
    /// More pairs of segments to test than [`MOST_PAIRS`]: the sweep alone
    /// would take longer than anyone waits.
    TooMuchWork(u64),
}

/// Most projection crossings listed (40 MB of them).
pub(super) const MOST_CROSSINGS: usize = 1_000_000;

/// Most segment pairs the sweep tests (pairs whose extents along the sweep
/// overlap): about [`PAIRS_PER_SECOND`] are tested per second.
pub(crate) const MOST_PAIRS: u64 = 2_000_000_000;

/// Segment pairs the sweep tests per second (measured on a 10⁶-point noisy
/// trefoil, release build), for the estimate in the error past [`MOST_PAIRS`].
pub(crate) const PAIRS_PER_SECOND: f64 = 2e8;

fn cross2(a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Relative size of the margins that make a projection degenerate: crossings
/// this close (in segment parameter) to a vertex or to each other, segments
/// this close to parallel.
pub(crate) const MARGIN: f64 = 1e-10;

/// Relative depth below which two strands at a crossing are taken to meet
/// (the curve then has no knot type): well above the depths' rounding, about
/// 10ε of the curve's size, which is all that can flip over and under; a
/// 10⁶-point noisy curve has strands within 10⁻¹⁰ of each other in depth at
/// some crossing in every direction, and they do not meet.
pub(crate) const DEPTH_MARGIN: f64 = 1e-13;

/// A closed polygon projected along a direction.
pub(crate) struct Projection {
    /// Orthonormal frame: two directions in the plane of projection, then the
    /// direction itself (depth grows along it).
    pub(crate) frame: [Vector3<f64>; 3],
    /// The vertices in the plane.
    pub(crate) p2: Vec<Vector2<f64>>,
    /// Their depths.
    depth: Vec<f64>,
    /// Size of the polygon (its bounding box's diagonal): margins scale with it.
    scale: f64,
}

impl Projection {
    /// The projection of `closed` along `dir`; `Projection` if a segment is
    /// seen end-on.
    pub(crate) fn new(closed: &[Vector3<f64>], dir: &Vector3<f64>) -> Result<Self, Degenerate> {
        let v = dir.normalize();
        let a = crate::geometry::normal_to(&v);
        let b = v.cross(&a);
        let p2: Vec<Vector2<f64>> = closed
            .iter()
            .map(|p| Vector2::new(p.dot(&a), p.dot(&b)))
            .collect();
        let depth = closed.iter().map(|p| p.dot(&v)).collect();
        let lo = closed.iter().fold(closed[0], |m, p| m.inf(p));
        let hi = closed.iter().fold(closed[0], |m, p| m.sup(p));
        let scale = (hi - lo).norm().max(f64::MIN_POSITIVE);
        let proj = Projection {
            frame: [a, b, v],
            p2,
            depth,
            scale,
        };
        if (0..closed.len()).any(|i| proj.segment(i).norm() <= MARGIN * scale) {
            // a segment seen end-on
            return Err(Degenerate::Projection);
        }
        Ok(proj)
    }

    /// Segment i in the plane, as a vector.
    pub(crate) fn segment(&self, i: usize) -> Vector2<f64> {
        self.p2[(i + 1) % self.p2.len()] - self.p2[i]
    }

    /// Extent of segment i along the sweep, padded by the margin.
    fn x_range(&self, i: usize) -> (f64, f64) {
        let (p, q) = (self.p2[i].x, self.p2[(i + 1) % self.p2.len()].x);
        let pad = MARGIN * self.scale;
        (p.min(q) - pad, p.max(q) + pad)
    }

    /// Segment pairs whose extents along the sweep overlap: the sweep's work,
    /// counted in O(n log n) before it starts (a pair (i, j) with i's range
    /// starting first overlaps unless i's range ends before j's starts).
    pub(crate) fn overlapping_pairs(&self) -> u64 {
        let m = self.p2.len();
        let mut starts: Vec<f64> = (0..m).map(|i| self.x_range(i).0).collect();
        let mut ends: Vec<f64> = (0..m).map(|i| self.x_range(i).1).collect();
        starts.sort_by(f64::total_cmp);
        ends.sort_by(f64::total_cmp);
        starts
            .iter()
            .enumerate()
            .map(|(rank, &x)| (rank - ends.partition_point(|&e| e < x)) as u64)
            .sum()
    }

    /// Every crossing of the projection, handed to `visit` (in no particular
    /// order); `TooMuchWork` up front if the sweep would test more than
    /// [`MOST_PAIRS`] pairs.
    pub(crate) fn for_each_crossing(
        &self,
        mut visit: impl FnMut(Crossing) -> Result<(), Degenerate>,
    ) -> Result<(), Degenerate> {
        let pairs = self.overlapping_pairs();
        if pairs > MOST_PAIRS {
            return Err(Degenerate::TooMuchWork(pairs));
        }
        let m = self.p2.len();
        // sweep in x: each segment meets only those whose x-range is still open
        let mut order: Vec<usize> = (0..m).collect();
        let ranges: Vec<(f64, f64)> = (0..m).map(|i| self.x_range(i)).collect();
        order.sort_by(|&i, &j| ranges[i].0.total_cmp(&ranges[j].0).then(i.cmp(&j)));
        let mut active: Vec<usize> = Vec::new();
        for &j in &order {
            let x = ranges[j].0;
            active.retain(|&i| ranges[i].1 >= x);
            for &i in &active {
                let (i, j) = (i.min(j), i.max(j));
                if j == i + 1 || (i == 0 && j == m - 1) {
                    continue;
                }
                if let Some(c) = self.crossing(i, j)? {
                    visit(c)?;
                }
            }
            active.push(j);
        }
        Ok(())
    }
}

/// Crossings of the closed polygon projected along `dir`.
pub(super) fn crossings(
    closed: &[Vector3<f64>],
    dir: &Vector3<f64>,
) -> Result<Vec<Crossing>, Degenerate> {
    let mut out = Vec::new();
    Projection::new(closed, dir)?.for_each_crossing(|c| {
        out.push(c);
        if out.len() > MOST_CROSSINGS {
            return Err(Degenerate::TooMany(out.len()));
        }
        Ok(())
    })?;
    // sort crossings by position for a deterministic numbering
    out.sort_by(|x, y| {
        x.under
            .0
            .cmp(&y.under.0)
            .then(x.under.1.total_cmp(&y.under.1))
    });
    Ok(out)
}

impl Projection {
    /// The crossing of projected segments i < j, if any.
    fn crossing(&self, i: usize, j: usize) -> Result<Option<Crossing>, Degenerate> {
        let (p2, depth, scale) = (&self.p2, &self.depth, self.scale);
        let m = p2.len();
        let (p, r) = (p2[i], p2[(i + 1) % m] - p2[i]);
        let (q, s) = (p2[j], p2[(j + 1) % m] - p2[j]);
        let (lo_i, hi_i) = (p.inf(&(p + r)), p.sup(&(p + r)));
        let (lo_j, hi_j) = (q.inf(&(q + s)), q.sup(&(q + s)));
        let pad = MARGIN * scale;
        if lo_i.x > hi_j.x + pad
            || lo_j.x > hi_i.x + pad
            || lo_i.y > hi_j.y + pad
            || lo_j.y > hi_i.y + pad
        {
            return Ok(None);
        }
        let denom = cross2(r, s);
        let qp = q - p;
        if denom.abs() <= MARGIN * r.norm() * s.norm() {
            // parallel in projection: degenerate only if they (nearly) overlap
            if cross2(qp, r).abs() <= MARGIN * r.norm() * scale {
                return Err(Degenerate::Projection);
            }
            return Ok(None);
        }
        let t = cross2(qp, s) / denom;
        let u = cross2(qp, r) / denom;
        let eps = MARGIN;
        if t < -eps || t > 1.0 + eps || u < -eps || u > 1.0 + eps {
            return Ok(None);
        }
        let (t, u) = (t.clamp(0.0, 1.0), u.clamp(0.0, 1.0));
        let di = depth[i] + t * (depth[(i + 1) % m] - depth[i]);
        let dj = depth[j] + u * (depth[(j + 1) % m] - depth[j]);
        if (di - dj).abs() <= DEPTH_MARGIN * scale {
            let at = p + t * r;
            return Err(Degenerate::SelfIntersection(Vector3::new(at.x, at.y, di)));
        }
        if t < eps || t > 1.0 - eps || u < eps || u > 1.0 - eps {
            return Err(Degenerate::Projection);
        }
        let (over, under, d_over, d_under) = if di > dj {
            ((i, t), (j, u), r, s)
        } else {
            ((j, u), (i, t), s, r)
        };
        Ok(Some(Crossing {
            over,
            under,
            positive: cross2(d_over, d_under) > 0.0,
        }))
    }
}

/// A knot diagram by its Gauss code: the crossings met along the curve, each
/// as (crossing, over?), and each crossing's sign.
#[derive(Clone, Debug)]
pub(super) struct Diagram {
    code: Vec<(usize, bool)>,
    positive: Vec<bool>,
}

impl Diagram {
    /// The diagram of these crossings; `Projection` if two fall on one
    /// point of a segment (a triple point).
    pub(super) fn new(crossings: &[Crossing]) -> Result<Diagram, Degenerate> {
        let mut events: Vec<(usize, f64, usize, bool)> = Vec::with_capacity(2 * crossings.len());
        for (c, x) in crossings.iter().enumerate() {
            events.push((x.over.0, x.over.1, c, true));
            events.push((x.under.0, x.under.1, c, false));
        }
        events.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        if events
            .windows(2)
            .any(|w| w[0].0 == w[1].0 && w[1].1 - w[0].1 < MARGIN)
        {
            return Err(Degenerate::Projection);
        }
        Ok(Diagram {
            code: events.iter().map(|e| (e.2, e.3)).collect(),
            positive: crossings.iter().map(|x| x.positive).collect(),
        })
    }

    /// Crossings left.
    pub(super) fn crossings(&self) -> usize {
        self.code.len() / 2
    }

    /// Remove kinks (Reidemeister I: a crossing met twice in a row) and
    /// bigons (Reidemeister II: two crossings met in a row, both over, and
    /// in a row again, both under) until none is left. Neither changes the
    /// knot; each sweep removes every move that is disjoint from the others.
    pub(super) fn reduce(&mut self) {
        loop {
            let len = self.code.len();
            if len == 0 {
                return;
            }
            let mut pos = vec![[0usize; 2]; self.positive.len()];
            for (k, &(c, over)) in self.code.iter().enumerate() {
                pos[c][over as usize] = k;
            }
            let mut gone = vec![false; self.positive.len()];
            let mut any = false;
            for k in 0..len {
                let (c1, o1) = self.code[k];
                let (c2, o2) = self.code[(k + 1) % len];
                if gone[c1] || gone[c2] {
                    continue;
                }
                if c1 == c2 {
                    gone[c1] = true;
                    any = true;
                } else if o1 == o2 {
                    let (q1, q2) = (pos[c1][!o1 as usize], pos[c2][!o1 as usize]);
                    if (q1 + 1) % len == q2 || (q2 + 1) % len == q1 {
                        gone[c1] = true;
                        gone[c2] = true;
                        any = true;
                    }
                }
            }
            if !any {
                return;
            }
            // renumber the crossings left
            let mut new_id = vec![usize::MAX; self.positive.len()];
            let mut positive = Vec::new();
            for (c, &g) in gone.iter().enumerate() {
                if !g {
                    new_id[c] = positive.len();
                    positive.push(self.positive[c]);
                }
            }
            self.code = self
                .code
                .iter()
                .filter(|(c, _)| !gone[*c])
                .map(|&(c, o)| (new_id[c], o))
                .collect();
            self.positive = positive;
        }
    }

    /// The Alexander matrix A + tB (n×n, row-major, n = crossings) from the
    /// Wirtinger presentation by Fox calculus: the arcs run from one
    /// undercrossing to the next; a positive crossing with over-arc k,
    /// incoming arc i and outgoing arc j gives the row (1 − t) at k, t at i,
    /// −1 at j, a negative one (t − 1) at k, 1 at i, −t at j.
    pub(super) fn alexander_matrix(&self) -> (Vec<i64>, Vec<i64>, usize) {
        let n = self.crossings();
        let mut over_arc = vec![0usize; n];
        let mut in_arc = vec![0usize; n];
        let mut out_arc = vec![0usize; n];
        let mut arc = 0usize;
        for &(c, over) in &self.code {
            if over {
                over_arc[c] = arc;
            } else {
                in_arc[c] = arc;
                arc = (arc + 1) % n;
                out_arc[c] = arc;
            }
        }
        let mut a = vec![0i64; n * n];
        let mut b = vec![0i64; n * n];
        for c in 0..n {
            let (k, i, j) = (over_arc[c], in_arc[c], out_arc[c]);
            if self.positive[c] {
                a[c * n + k] += 1;
                b[c * n + k] -= 1;
                b[c * n + i] += 1;
                a[c * n + j] -= 1;
            } else {
                b[c * n + k] += 1;
                a[c * n + k] -= 1;
                a[c * n + i] += 1;
                b[c * n + j] -= 1;
            }
        }
        (a, b, n)
    }
}
