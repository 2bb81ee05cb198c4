//! Simplification of a closed polygon without changing its knot type
//! (Koniaris & Muthukumar, J. Biomol. Struct. Dyn. 8 (1991); Taylor, Nature
//! 406 (2000)): a vertex is removed when the triangle it spans with its two
//! neighbours meets no other segment, which is an isotopy. The test is
//! conservative: a segment within a tolerance of the triangle keeps the
//! vertex, so rounding can only leave a vertex in place, never change the knot.
//!
//! Candidates come from a hash grid of segment bounding boxes, rebuilt each
//! pass at the current median segment length, so a pass costs O(n) for a
//! curve of bounded local density; each pass removes a fixed fraction of the
//! vertices of a dense curve (three quarters of a noisy one), so the passes
//! together cost O(n) too (plus O(n) for each pass that removes little).

use nalgebra::Vector3;

/// Segments whose boxes span more cells than this are kept in a list that
/// every query scans (the long closing rays, the far loop).
const LARGE: i64 = 64;

/// Most candidate segments tested against triangles in one simplification
/// (a 10⁶-point noisy curve needs 5·10⁷; a curve that fills a box needs
/// O(n²)): past it the polygon is returned as far as it got, which is still
/// the same knot, and the diagram's own limits decide.
const MOST_CANDIDATES: usize = 300_000_000;

/// End of a bucket's list.
const NONE: u32 = u32::MAX;

type Cell = (i32, i32, i32);

/// The polygon as a doubly linked cycle of vertices, segments named by their
/// first vertex.
struct Cycle<'a> {
    p: &'a [Vector3<f64>],
    next: Vec<usize>,
    prev: Vec<usize>,
    alive: usize,
}

/// A spatial hash of segment boxes: cells of size h hashed into a table of
/// buckets, each a linked list of entries in one pool, so filing and
/// unfiling allocate nothing per cell. Cells that share a bucket only add
/// candidates, which the exact tests reject.
struct Grid {
    origin: Vector3<f64>,
    h: f64,
    /// First entry of each bucket.
    heads: Vec<u32>,
    /// Bits of the bucket index.
    bits: u32,
    /// (segment, next entry of its bucket).
    entries: Vec<(u32, u32)>,
    large: Vec<u32>,
    /// Cell range of each filed segment; None for large or unfiled ones.
    range: Vec<Option<(Cell, Cell)>>,
}

impl Grid {
    /// A grid for `live` segments named 0..n.
    fn new(origin: Vector3<f64>, h: f64, n: usize, live: usize) -> Grid {
        // about 4 buckets per segment: a segment spans ~8 cells, each
        // bucket then holds about two entries
        let bits = (4 * live.max(16)).next_power_of_two().trailing_zeros();
        Grid {
            origin,
            h,
            heads: vec![NONE; 1 << bits],
            bits,
            entries: Vec::with_capacity(8 * live),
            large: Vec::new(),
            range: vec![None; n],
        }
    }

    fn cell(&self, x: &Vector3<f64>) -> Cell {
        let c = (x - self.origin) / self.h;
        (c.x.floor() as i32, c.y.floor() as i32, c.z.floor() as i32)
    }

    fn bucket(&self, (i, j, k): Cell) -> usize {
        let key = (i as u32 as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ (j as u32 as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
            ^ (k as u32 as u64).wrapping_mul(0x1656_67B1_9E37_79F9);
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - self.bits)) as usize
    }

    fn span(lo: Cell, hi: Cell) -> i64 {
        // in i64: cell indices near i32's ends must not wrap to a small span
        let side = |a: i32, b: i32| (b as i64 - a as i64 + 1).max(0);
        side(lo.0, hi.0)
            .saturating_mul(side(lo.1, hi.1))
            .saturating_mul(side(lo.2, hi.2))
    }

    fn cells(lo: Cell, hi: Cell) -> impl Iterator<Item = Cell> {
        (lo.0..=hi.0).flat_map(move |i| {
            (lo.1..=hi.1).flat_map(move |j| (lo.2..=hi.2).map(move |k| (i, j, k)))
        })
    }

    fn insert(&mut self, id: usize, a: &Vector3<f64>, b: &Vector3<f64>) {
        let (lo, hi) = (self.cell(&a.inf(b)), self.cell(&a.sup(b)));
        if Self::span(lo, hi) > LARGE {
            self.large.push(id as u32);
            self.range[id] = None;
            return;
        }
        for c in Self::cells(lo, hi) {
            let at = self.bucket(c);
            self.entries.push((id as u32, self.heads[at]));
            self.heads[at] = (self.entries.len() - 1) as u32;
        }
        self.range[id] = Some((lo, hi));
    }

    fn remove(&mut self, id: usize) {
        match self.range[id].take() {
            None => self.large.retain(|&s| s as usize != id),
            Some((lo, hi)) => {
                // one entry per cell: unlink one from each cell's bucket
                for c in Self::cells(lo, hi) {
                    let at = self.bucket(c);
                    let (mut prev, mut e) = (NONE, self.heads[at]);
                    while e != NONE && self.entries[e as usize].0 as usize != id {
                        (prev, e) = (e, self.entries[e as usize].1);
                    }
                    if e == NONE {
                        continue;
                    }
                    let after = self.entries[e as usize].1;
                    if prev == NONE {
                        self.heads[at] = after;
                    } else {
                        self.entries[prev as usize].1 = after;
                    }
                }
            }
        }
    }

    /// Segments whose boxes may meet the box [lo, hi], into `out` (with
    /// repeats); false when the box spans more cells than there are segments
    /// (the caller then scans them all).
    fn near(&self, lo: &Vector3<f64>, hi: &Vector3<f64>, live: usize, out: &mut Vec<u32>) -> bool {
        let (a, b) = (self.cell(lo), self.cell(hi));
        out.clear();
        out.extend_from_slice(&self.large);
        if Self::span(a, b) > live as i64 {
            return false;
        }
        for c in Self::cells(a, b) {
            let mut e = self.heads[self.bucket(c)];
            while e != NONE {
                let (s, next) = self.entries[e as usize];
                out.push(s);
                e = next;
            }
        }
        true
    }
}

/// Distance between the segments [p, q] and [a, b] (Ericson, Real-Time
/// Collision Detection, 5.1.9).
fn segment_distance(p: &Vector3<f64>, q: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let (d1, d2, r) = (q - p, b - a, p - a);
    let (aa, ee, ff) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let (s, t) = if aa <= f64::MIN_POSITIVE && ee <= f64::MIN_POSITIVE {
        (0.0, 0.0)
    } else if aa <= f64::MIN_POSITIVE {
        (0.0, (ff / ee).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if ee <= f64::MIN_POSITIVE {
            ((-c / aa).clamp(0.0, 1.0), 0.0)
        } else {
            let bb = d1.dot(&d2);
            let denom = aa * ee - bb * bb;
            let mut s = if denom > 0.0 {
                ((bb * ff - c * ee) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (bb * s + ff) / ee;
            if t < 0.0 {
                t = 0.0;
                s = (-c / aa).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((bb - c) / aa).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p + s * d1) - (a + t * d2)).norm()
}

/// Distance from x to the triangle (a, b, c) (Ericson 5.1.5).
fn point_triangle_distance(
    x: &Vector3<f64>,
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    c: &Vector3<f64>,
) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, x - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.norm();
    }
    let bp = x - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.norm();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (x - (a + d1 / (d1 - d3) * ab)).norm();
    }
    let cp = x - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.norm();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (x - (a + d2 / (d2 - d6) * ac)).norm();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return (x - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
    }
    let denom = 1.0 / (va + vb + vc);
    (x - (a + ab * (vb * denom) + ac * (vc * denom))).norm()
}

/// Whether the segment [p, q] comes within `tol` of the triangle (a, b, c)
/// with normal n = (b − a) × (c − a).
fn segment_meets_triangle(
    p: &Vector3<f64>,
    q: &Vector3<f64>,
    [a, b, c]: [&Vector3<f64>; 3],
    n: &Vector3<f64>,
    tol: f64,
) -> bool {
    let nn = n.norm();
    let (dp, dq) = (n.dot(&(p - a)) / nn, n.dot(&(q - a)) / nn);
    if (dp > tol && dq > tol) || (dp < -tol && dq < -tol) {
        return false;
    }
    if (dp > 0.0) != (dq > 0.0) && dp != dq {
        // the segment pierces the plane: inside the triangle?
        let x = p + (dp / (dp - dq)) * (q - p);
        let inside = [(a, b), (b, c), (c, a)]
            .iter()
            .all(|(u, v)| (*v - *u).cross(&(x - *u)).dot(n) >= 0.0);
        if inside {
            return true;
        }
    }
    let edges = [(a, b), (b, c), (c, a)];
    edges
        .iter()
        .any(|(u, v)| segment_distance(p, q, u, v) <= tol)
        || point_triangle_distance(p, a, b, c) <= tol
        || point_triangle_distance(q, a, b, c) <= tol
}

/// Whether the segment from the triangle's corner `a` to `z` (a neighbour
/// segment, sharing that corner) enters the triangle (a, u, v) anywhere but at
/// `a`: only possible when z lies (nearly) in its plane and the segment starts
/// into the corner's angle.
fn neighbour_enters(
    a: &Vector3<f64>,
    z: &Vector3<f64>,
    u: &Vector3<f64>,
    v: &Vector3<f64>,
    n: &Vector3<f64>,
    tol: f64,
) -> bool {
    let w = z - a;
    let nn = n.norm();
    let wn = w.norm();
    if (n.dot(&w) / nn).abs() > tol {
        return false;
    }
    // within the angle between a→u and a→v (< π), with a margin of 1e-9 rad
    let (eu, ev) = (u - a, v - a);
    let into_u = eu.cross(&w).dot(n) / (nn * eu.norm() * wn);
    let into_v = w.cross(&ev).dot(n) / (nn * ev.norm() * wn);
    into_u >= -1e-9 && into_v >= -1e-9
}

/// The closed polygon with vertices removed by triangle elimination until
/// none can be (at least three remain). `points` must have no repeated
/// consecutive points.
pub(super) fn simplify(points: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    let n = points.len();
    if n <= 3 {
        return points.to_vec();
    }
    let lo = points.iter().fold(points[0], |m, p| m.inf(p));
    let hi = points.iter().fold(points[0], |m, p| m.sup(p));
    let size = (hi - lo).norm().max(f64::MIN_POSITIVE);
    let tol = 1e-10 * size;
    let mut cyc = Cycle {
        p: points,
        next: (0..n).map(|i| (i + 1) % n).collect(),
        prev: (0..n).map(|i| (i + n - 1) % n).collect(),
        alive: n,
    };
    let mut start = 0;
    let mut seen = vec![0u32; n];
    let mut stamp = 0u32;
    let mut near = Vec::new();
    // cells are `coarsen` times the median segment: raised when a pass could
    // only defer (every removal would have made a segment too long for it)
    let mut coarsen = 1.0;
    let mut candidates = 0;
    'passes: loop {
        let order = cyc.vertices(start);
        let mut lengths: Vec<f64> = order
            .iter()
            .map(|&v| (cyc.p[cyc.next[v]] - cyc.p[v]).norm())
            .collect();
        let half = lengths.len() / 2;
        let (_, median, _) = lengths.select_nth_unstable_by(half, f64::total_cmp);
        // cells no finer than 2⁻²⁰ of the curve, so cell indices fit in i32
        let h = (coarsen * *median).max(size * 2f64.powi(-20));
        let mut grid = Grid::new(lo - Vector3::repeat(2.0 * h), h, n, order.len());
        for &v in &order {
            grid.insert(v, &cyc.p[v], &cyc.p[cyc.next[v]]);
        }
        let before = cyc.alive;
        let mut deferred = false;
        for &b in &order {
            if cyc.alive <= 3 || candidates > MOST_CANDIDATES {
                break 'passes;
            }
            let (a, c) = (cyc.prev[b], cyc.next[b]);
            let (pa, pb, pc) = (&cyc.p[a], &cyc.p[b], &cyc.p[c]);
            if (pc - pa).norm() > 3.0 * h {
                // a segment this long would slow this pass's grid: next pass
                deferred = true;
                continue;
            }
            let nrm = (pb - pa).cross(&(pc - pa));
            if nrm.norm() <= 1e-12 * (pb - pa).norm() * (pc - pa).norm() {
                // (nearly) collinear: no plane to test against; keep it
                continue;
            }
            let pad = Vector3::repeat(tol);
            let (blo, bhi) = (pa.inf(pb).inf(pc) - pad, pa.sup(pb).sup(pc) + pad);
            stamp += 1;
            if !grid.near(&blo, &bhi, cyc.alive, &mut near) {
                near.clear();
                near.extend(cyc.vertices(c).into_iter().map(|v| v as u32));
            }
            candidates += near.len();
            let (z, d) = (cyc.prev[a], c);
            let blocked = near.iter().any(|&s| {
                let s = s as usize;
                if seen[s] == stamp || s == a || s == b {
                    return false;
                }
                seen[s] = stamp;
                let (ps, pt) = (&cyc.p[s], &cyc.p[cyc.next[s]]);
                if s == z {
                    return neighbour_enters(pa, ps, pb, pc, &nrm, tol);
                }
                if s == d {
                    return neighbour_enters(pc, pt, pa, pb, &nrm, tol);
                }
                segment_meets_triangle(ps, pt, [pa, pb, pc], &nrm, tol)
            });
            if blocked {
                continue;
            }
            grid.remove(a);
            grid.remove(b);
            cyc.next[a] = c;
            cyc.prev[c] = a;
            cyc.alive -= 1;
            grid.insert(a, pa, pc);
            start = a;
        }
        if cyc.alive <= 3 || (cyc.alive == before && !deferred) {
            break;
        }
        if cyc.alive == before {
            // cells past the curve's size defer nothing more, and a zero
            // median (points that rounding made coincide) never coarsens
            let reach = coarsen * *median;
            if reach > size || !reach.is_finite() || *median == 0.0 {
                break;
            }
            coarsen *= 2.0;
        }
    }
    cyc.vertices(start).into_iter().map(|v| points[v]).collect()
}

impl Cycle<'_> {
    /// The live vertices in order from `start`.
    fn vertices(&self, start: usize) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.alive);
        let mut v = start;
        loop {
            out.push(v);
            v = self.next[v];
            if v == start {
                return out;
            }
        }
    }
}
