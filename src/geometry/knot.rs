//! Knot type of a closed polygon: a projection to a generic plane, its
//! crossings, and the Alexander polynomial from the Wirtinger presentation
//! (Fox calculus), with the knot determinant |Δ(−1)|.

use nalgebra::{DMatrix, Vector2, Vector3};
use num_complex::Complex;
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
    /// A knot with this polynomial (the polynomial does not determine the knot).
    pub name: Option<String>,
    /// Crossings in the projection used.
    pub crossings: usize,
    /// Projection directions tried (degenerate ones are skipped).
    pub directions: usize,
    /// The projections did not agree, or none was usable.
    pub ambiguous: bool,
}

/// A crossing of the projected diagram.
#[derive(Clone, Copy, Debug)]
struct Crossing {
    over: (usize, f64),
    under: (usize, f64),
    positive: bool,
}

/// Why a projection could not be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Degenerate {
    /// A crossing at a vertex, or overlapping/parallel projected segments.
    Projection,
    /// Two segments meet in space (the curve passes through itself).
    SelfIntersection,
}

fn cross2(a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Crossings of the closed polygon projected along `dir`.
fn crossings(closed: &[Vector3<f64>], dir: &Vector3<f64>) -> Result<Vec<Crossing>, Degenerate> {
    let v = dir.normalize();
    let trial = if v.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let a = (trial - trial.dot(&v) * v).normalize();
    let b = v.cross(&a);
    let m = closed.len();
    let p2: Vec<Vector2<f64>> = closed
        .iter()
        .map(|p| Vector2::new(p.dot(&a), p.dot(&b)))
        .collect();
    let depth: Vec<f64> = closed.iter().map(|p| p.dot(&v)).collect();
    let scale = closed
        .iter()
        .map(|p| p.amax())
        .fold(0.0, f64::max)
        .max(1e-300);
    // bounding boxes in the projection, for a cheap rejection
    let bbox: Vec<(Vector2<f64>, Vector2<f64>)> = (0..m)
        .map(|i| {
            let (p, q) = (p2[i], p2[(i + 1) % m]);
            (p.inf(&q), p.sup(&q))
        })
        .collect();
    let eps = 1e-10;
    let mut out = Vec::new();
    for i in 0..m {
        for j in i + 2..m {
            if i == 0 && j == m - 1 {
                continue;
            }
            let (lo_i, hi_i) = bbox[i];
            let (lo_j, hi_j) = bbox[j];
            if lo_i.x > hi_j.x || lo_j.x > hi_i.x || lo_i.y > hi_j.y || lo_j.y > hi_i.y {
                continue;
            }
            let (p, r) = (p2[i], p2[(i + 1) % m] - p2[i]);
            let (q, s) = (p2[j], p2[(j + 1) % m] - p2[j]);
            let denom = cross2(r, s);
            let qp = q - p;
            if denom.abs() <= 1e-12 * r.norm() * s.norm() {
                // parallel in projection: degenerate only if they overlap
                if cross2(qp, r).abs() <= 1e-12 * r.norm() * scale {
                    return Err(Degenerate::Projection);
                }
                continue;
            }
            let t = cross2(qp, s) / denom;
            let u = cross2(qp, r) / denom;
            if t < -eps || t > 1.0 + eps || u < -eps || u > 1.0 + eps {
                continue;
            }
            if t < eps || t > 1.0 - eps || u < eps || u > 1.0 - eps {
                return Err(Degenerate::Projection);
            }
            let di = depth[i] + t * (depth[(i + 1) % m] - depth[i]);
            let dj = depth[j] + u * (depth[(j + 1) % m] - depth[j]);
            if (di - dj).abs() <= 1e-12 * scale {
                return Err(Degenerate::SelfIntersection);
            }
            let (over, under, d_over, d_under) = if di > dj {
                ((i, t), (j, u), r, s)
            } else {
                ((j, u), (i, t), s, r)
            };
            out.push(Crossing {
                over,
                under,
                positive: cross2(d_over, d_under) > 0.0,
            });
        }
    }
    Ok(out)
}

/// Alexander polynomial (coefficients, lowest degree first, before
/// normalisation) of a diagram, or None if it is not numerically integral.
fn alexander_of(crossings: &[Crossing]) -> Option<Vec<i64>> {
    let n = crossings.len();
    if n <= 1 {
        return Some(vec![1]);
    }
    // walk the curve: events in order of (segment, parameter)
    let mut events: Vec<(usize, f64, usize, bool)> = Vec::with_capacity(2 * n);
    for (c, x) in crossings.iter().enumerate() {
        events.push((x.over.0, x.over.1, c, false));
        events.push((x.under.0, x.under.1, c, true));
    }
    events.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    // arcs run from one undercrossing to the next (mod n)
    let mut over_arc = vec![0usize; n];
    let mut in_arc = vec![0usize; n];
    let mut out_arc = vec![0usize; n];
    let mut arc = 0usize;
    for &(_, _, c, under) in &events {
        if under {
            in_arc[c] = arc;
            arc = (arc + 1) % n;
            out_arc[c] = arc;
        } else {
            over_arc[c] = arc;
        }
    }
    // rows of the Alexander matrix A + t B (Fox derivatives of the Wirtinger
    // relations, negative rows multiplied by t)
    let mut a = DMatrix::<f64>::zeros(n, n);
    let mut b = DMatrix::<f64>::zeros(n, n);
    for (c, x) in crossings.iter().enumerate() {
        let (k, i, j) = (over_arc[c], in_arc[c], out_arc[c]);
        if x.positive {
            a[(c, k)] += 1.0;
            b[(c, k)] -= 1.0;
            b[(c, i)] += 1.0;
            a[(c, j)] -= 1.0;
        } else {
            b[(c, k)] += 1.0;
            a[(c, k)] -= 1.0;
            a[(c, i)] += 1.0;
            b[(c, j)] -= 1.0;
        }
    }
    // det of the (n-1)-minor has degree <= n-1: evaluate at the n-th roots of
    // unity and invert the discrete Fourier transform
    let m = n - 1;
    let values: Vec<Complex<f64>> = (0..n)
        .map(|k| {
            let t = Complex::from_polar(1.0, 2.0 * PI * k as f64 / n as f64);
            let mat = DMatrix::<Complex<f64>>::from_fn(m, m, |r, c| {
                Complex::new(a[(r, c)], 0.0) + t * b[(r, c)]
            });
            mat.determinant()
        })
        .collect();
    let mut coeffs = Vec::with_capacity(n);
    for j in 0..n {
        let c: Complex<f64> = (0..n)
            .map(|k| values[k] * Complex::from_polar(1.0, -2.0 * PI * (j * k) as f64 / n as f64))
            .sum::<Complex<f64>>()
            / n as f64;
        let r = c.re.round();
        if (c.re - r).abs() > 1e-6 || c.im.abs() > 1e-6 {
            return None;
        }
        coeffs.push(r as i64);
    }
    Some(coeffs)
}

/// Strip powers of t and fix the sign so that Δ(1) = 1; None if Δ(1) ≠ ±1.
fn normalise(mut c: Vec<i64>) -> Option<Vec<i64>> {
    while c.last() == Some(&0) {
        c.pop();
    }
    let lead = c.iter().position(|x| *x != 0)?;
    c.drain(..lead);
    let at_one: i64 = c.iter().sum();
    match at_one {
        1 => Some(c),
        -1 => Some(c.into_iter().map(|x| -x).collect()),
        _ => None,
    }
}

/// A knot with this Alexander polynomial, for small knots.
pub fn knot_name(alexander: &[i64]) -> Option<&'static str> {
    Some(match alexander {
        [1] => "0_1 (unknot)",
        [1, -1, 1] => "3_1 (trefoil)",
        [-1, 3, -1] | [1, -3, 1] => "4_1 (figure-eight)",
        [1, -1, 1, -1, 1] => "5_1 (cinquefoil)",
        [2, -3, 2] => "5_2",
        [-2, 5, -2] | [2, -5, 2] => "6_1",
        [-1, 3, -3, 3, -1] | [1, -3, 3, -3, 1] => "6_2",
        [1, -3, 5, -3, 1] => "6_3",
        [1, -1, 1, -1, 1, -1, 1] => "7_1",
        _ => return None,
    })
}

/// Knot type seen along one projection direction.
pub fn knot_type_along(
    closed: &[Vector3<f64>],
    dir: &Vector3<f64>,
) -> Result<(Vec<i64>, usize), Degenerate> {
    let cr = crossings(closed, dir)?;
    let poly = alexander_of(&cr)
        .and_then(normalise)
        .ok_or(Degenerate::Projection)?;
    Ok((poly, cr.len()))
}

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

/// Knot type of a closed polygon, from several projections: the answer of the
/// first three usable ones, more if they disagree; `ambiguous` if no majority.
pub fn knot_type(closed: &[Vector3<f64>]) -> KnotType {
    let mut answers: Vec<(Vec<i64>, usize)> = Vec::new();
    let mut tried = 0;
    for dir in projection_directions(23) {
        tried += 1;
        if let Ok(ans) = knot_type_along(closed, &dir) {
            answers.push(ans);
        }
        let agree = |k: usize| answers.iter().filter(|a| a.0 == answers[k].0).count();
        if answers.len() >= 3
            && (0..answers.len()).any(|k| 2 * agree(k) > answers.len() && agree(k) >= 3)
        {
            break;
        }
    }
    let best =
        (0..answers.len()).max_by_key(|&k| answers.iter().filter(|a| a.0 == answers[k].0).count());
    match best {
        Some(k) => {
            let votes = answers.iter().filter(|a| a.0 == answers[k].0).count();
            let alexander = answers[k].0.clone();
            let det: i64 = alexander
                .iter()
                .enumerate()
                .map(|(j, c)| if j % 2 == 0 { *c } else { -c })
                .sum();
            KnotType {
                determinant: det.unsigned_abs(),
                name: knot_name(&alexander).map(String::from),
                alexander,
                crossings: answers[k].1,
                directions: tried,
                ambiguous: votes < answers.len() || votes < 3,
            }
        }
        None => KnotType {
            determinant: 0,
            alexander: vec![],
            name: None,
            crossings: 0,
            directions: tried,
            ambiguous: true,
        },
    }
}
