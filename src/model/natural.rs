//! Natural (rest) strains û = (û1, û2, û3) of a rod: constant along it, or a
//! table of rows [s, û1, û2, û3] linearly interpolated in the arc length s.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Natural strains, in units of 1/L. The Kirchhoff energy is
/// ½ ∫ B_i (u_i − û_i(s))²; the strip law replaces u1 by u1 − û1(s)
/// (û2 = û3 = 0 for strips).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum NaturalStrains {
    /// The same (û1, û2, û3) everywhere.
    Constant([f64; 3]),
    /// Rows [s, û1, û2, û3], s increasing from 0 to 1 (validated by the
    /// scene), linearly interpolated in between.
    Table(Vec<[f64; 4]>),
}

impl Default for NaturalStrains {
    fn default() -> Self {
        NaturalStrains::Constant([0.0; 3])
    }
}

impl From<[f64; 3]> for NaturalStrains {
    fn from(u: [f64; 3]) -> Self {
        NaturalStrains::Constant(u)
    }
}

impl NaturalStrains {
    /// Every û scaled by `f` (1: itself, exactly).
    pub fn scaled(&self, f: f64) -> NaturalStrains {
        if f == 1.0 {
            return self.clone();
        }
        match self {
            NaturalStrains::Constant(u) => NaturalStrains::Constant(u.map(|v| f * v)),
            NaturalStrains::Table(rows) => NaturalStrains::Table(
                rows.iter()
                    .map(|r| [r[0], f * r[1], f * r[2], f * r[3]])
                    .collect(),
            ),
        }
    }

    /// û(s), linearly interpolated (held constant outside the table's range).
    pub fn at(&self, s: f64) -> [f64; 3] {
        match self {
            // the triple itself: the constant case keeps its exact numbers
            NaturalStrains::Constant(u) => *u,
            NaturalStrains::Table(rows) => interpolate(rows, s),
        }
    }

    /// û(s) as a vector.
    pub fn vector_at(&self, s: f64) -> Vector3<f64> {
        Vector3::from(self.at(s))
    }

    /// û at vertex i of N segments, which sits at s = (i − ½)/N.
    pub fn at_vertex(&self, i: usize, segments: usize) -> [f64; 3] {
        match self {
            NaturalStrains::Constant(u) => *u,
            NaturalStrains::Table(_) => self.at((i as f64 - 0.5) / segments as f64),
        }
    }

    /// Whether û = 0 everywhere (a naturally straight, untwisted rod).
    pub fn is_zero(&self) -> bool {
        match self {
            NaturalStrains::Constant(u) => *u == [0.0; 3],
            NaturalStrains::Table(rows) => rows.iter().all(|r| r[1..] == [0.0; 3]),
        }
    }

    /// Whether component k (0: û1, 1: û2, 2: û3) is zero everywhere.
    pub fn component_is_zero(&self, k: usize) -> bool {
        match self {
            NaturalStrains::Constant(u) => u[k] == 0.0,
            NaturalStrains::Table(rows) => rows.iter().all(|r| r[k + 1] == 0.0),
        }
    }

    /// Every value of û given (the triple, or each row's three).
    pub fn values(&self) -> Vec<f64> {
        match self {
            NaturalStrains::Constant(u) => u.to_vec(),
            NaturalStrains::Table(rows) => rows.iter().flat_map(|r| r[1..].to_vec()).collect(),
        }
    }

    /// A short description for summaries.
    pub fn describe(&self) -> String {
        match self {
            NaturalStrains::Constant(u) => format!("û = ({}, {}, {})", u[0], u[1], u[2]),
            NaturalStrains::Table(rows) => {
                let (a, b) = (self.at(0.0), self.at(1.0));
                format!(
                    "û(s) from a table of {} rows, û(0) = ({}, {}, {}), û(1) = ({}, {}, {})",
                    rows.len(),
                    a[0],
                    a[1],
                    a[2],
                    b[0],
                    b[1],
                    b[2]
                )
            }
        }
    }
}

/// Largest end deflection of a naturally curved rod's stress-free arc, in
/// units of L: (1 − cos û)/û peaks at û ≈ 2.33 (the arc then bends back).
pub const MOST_END_DEFLECTION: f64 = 0.72;

/// The uniform natural curvature û (units of 1/L) of a plastified rod whose
/// stress-free shape, held at one end, has its free end `deflection` (units
/// of L, signed as û) off the held end's tangent: the arc's
/// (1 − cos û)/û = |deflection|. `None` for a deflection that is not finite or
/// beyond [`MOST_END_DEFLECTION`].
pub fn arc_curvature(deflection: f64) -> Option<f64> {
    if !deflection.is_finite() || deflection.abs() > MOST_END_DEFLECTION {
        return None;
    }
    let d = deflection.abs();
    let offset = |u: f64| {
        if u < 1e-4 {
            // (1 − cos u)/u by its series: no cancellation near 0
            u / 2.0 - u.powi(3) / 24.0
        } else {
            (1.0 - u.cos()) / u
        }
    };
    // the offset rises monotonically on [0, 2.33]: bisection to the last bit
    let (mut lo, mut hi) = (0.0, 2.33);
    while hi - lo > f64::EPSILON * hi {
        let mid = 0.5 * (lo + hi);
        if offset(mid) < d { lo = mid } else { hi = mid }
    }
    Some(deflection.signum() * 0.5 * (lo + hi))
}

/// Linear interpolation in rows sorted by s (held at the end rows outside).
fn interpolate(rows: &[[f64; 4]], s: f64) -> [f64; 3] {
    let (Some(first), Some(last)) = (rows.first(), rows.last()) else {
        return [0.0; 3];
    };
    if s <= first[0] {
        return [first[1], first[2], first[3]];
    }
    if s >= last[0] {
        return [last[1], last[2], last[3]];
    }
    // the first row with s_k > s; s lies in [s_{k−1}, s_k)
    let k = rows.partition_point(|r| r[0] <= s);
    let (a, b) = (rows[k - 1], rows[k]);
    let t = (s - a[0]) / (b[0] - a[0]);
    [1, 2, 3].map(|c| a[c] + t * (b[c] - a[c]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_interpolates_linearly_and_holds_its_ends() {
        let t = NaturalStrains::Table(vec![
            [0.0, 2.0, 0.0, 1.0],
            [0.5, 3.0, 1.0, 0.0],
            [1.0, 3.0, 0.0, 0.0],
        ]);
        assert_eq!(t.at(0.25), [2.5, 0.5, 0.5]);
        assert_eq!(t.at(0.5), [3.0, 1.0, 0.0]);
        assert_eq!(t.at(-1.0), [2.0, 0.0, 1.0]);
        assert_eq!(t.at(2.0), [3.0, 0.0, 0.0]);
        assert_eq!(t.at_vertex(1, 2), [2.5, 0.5, 0.5]);
        assert!(!t.component_is_zero(1));
        let c = NaturalStrains::from([1.0, 0.0, 2.0]);
        assert_eq!(c.at_vertex(3, 10), [1.0, 0.0, 2.0]);
        assert!(c.component_is_zero(1) && !c.is_zero());
    }

    /// The arc of the curvature found for a deflection, integrated on its own
    /// (the tangent turning at û, Simpson's rule for the end's offset), ends
    /// that far off the held end's tangent; small deflections give û ≈ 2d.
    #[test]
    fn a_plastified_rod_s_arc_ends_at_the_asked_deflection() {
        for d in [0.05, -0.05, 1e-6, 0.3, 0.7] {
            let u = arc_curvature(d).unwrap();
            let n = 2000;
            let f = |s: f64| (u * s).sin();
            let simpson = (0..=n)
                .map(|k| {
                    let w = if k == 0 || k == n {
                        1.0
                    } else if k % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    w * f(k as f64 / n as f64)
                })
                .sum::<f64>()
                / (3.0 * n as f64);
            assert!(
                (simpson - d).abs() < 1e-12 * (1.0 + u.abs()),
                "d {d}: û {u}, arc ends {simpson}"
            );
        }
        let u = arc_curvature(0.05).unwrap();
        assert!((u - 0.1).abs() < 1e-3 && u > 0.1, "û {u} for 5 %");
        assert_eq!(arc_curvature(0.0), Some(0.0));
        assert_eq!(arc_curvature(0.8), None);
        assert_eq!(arc_curvature(f64::NAN), None);
    }
}
