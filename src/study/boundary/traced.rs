//! The traced boundary: the walk's pieces named as the paper does (W1, W2,
//! X1, X2, S), the loop's area and extent.

use crate::analysis::event::PolishFailure;
use crate::model::rod::{Parameter, RodState, ranges_by_name};
use crate::study::boundary::condition::Condition;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A point of the walk on one condition.
#[derive(Clone, Debug)]
pub(super) struct TrailPoint {
    /// (swept parameter, value along the lines).
    pub at: [f64; 2],
    /// The condition's unit gradient in the plane (towards the good side);
    /// its component along the lines (the continuation's parameter) is
    /// positive where the good side lies above.
    pub normal: [f64; 2],
    /// The discrete equilibrium there, the polish's start (absent in trails
    /// made by hand).
    pub state: Option<RodState>,
}

/// A piece of the walk: its condition and its points.
pub(super) type Trail = (Condition, Vec<TrailPoint>);

/// One piece of the traced boundary: a polyline on one condition.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Piece {
    /// Paper-style name (W1, W2, X, X1, S, ...).
    pub label: String,
    /// The condition followed.
    pub condition: String,
    /// Points (swept parameter, value along) in walk order (good region on
    /// the left).
    pub points: Vec<[f64; 2]>,
}

/// A corner of the polished boundary.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PolishedCorner {
    /// The pieces it joins, in walk order.
    pub between: [String; 2],
    /// (swept parameter, value along) on the continuum.
    pub point: [f64; 2],
    /// Error estimate of either coordinate (the change when the
    /// integrator's tolerance falls a hundredfold, plus the last steps).
    pub error: f64,
    /// The discrete rod's corner (the walk's).
    pub discrete: [f64; 2],
}

/// The traced boundary on the continuum.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PolishedBoundary {
    /// The pieces, named as the traced ones: the walk's points and one
    /// between each pair of neighbours, polished.
    pub pieces: Vec<Piece>,
    /// The corners.
    pub corners: Vec<PolishedCorner>,
    /// Enclosed area, Richardson-extrapolated from the polygons of all the
    /// points and of the walk's points alone.
    pub area: f64,
    /// Its error estimate: the Richardson correction (the finest polygon's
    /// estimated error, which bounds the extrapolated area's), plus each
    /// point's own error times the half chords beside it.
    pub area_error: f64,
    /// The shoelace area of the polygon of all the points (no
    /// extrapolation).
    pub area_polygon: f64,
    /// Largest error estimate of a point's polished coordinate.
    pub largest_point_error: f64,
    /// Largest |discrete − continuum| of a walk point along its line: the
    /// discrete rod's error at its N.
    pub largest_shift: f64,
    /// Integrator tolerance of the polish (its errors from a second pass at
    /// a hundredth of it).
    pub tolerance: f64,
    /// Walk points the polish could not locate (left out, their
    /// neighbours' middle polished instead), and why.
    #[serde(default, deserialize_with = "dropped_data_or_text")]
    pub dropped: Vec<DroppedPoint>,
}

impl PolishedBoundary {
    /// The pieces' points joined in walk order (swept parameter, value
    /// along), as [`Traced::polygon`].
    pub fn polygon(&self) -> Vec<[f64; 2]> {
        self.pieces.iter().flat_map(|p| p.points.clone()).collect()
    }

    /// Whether the polished loop winds round the point `p` (swept
    /// parameter, value along; even–odd rule).
    pub fn encloses(&self, p: [f64; 2]) -> bool {
        let ring = self.polygon();
        let mut inside = false;
        for (k, a) in ring.iter().enumerate() {
            let b = ring[(k + 1) % ring.len()];
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if x > p[0] {
                    inside = !inside;
                }
            }
        }
        inside
    }
}

/// A walk point the boundary's polish left out.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct DroppedPoint {
    /// The condition of its piece, as the pieces name it.
    pub condition: String,
    /// The discrete point (swept parameter, value along); None in maps
    /// written before the points were kept as data.
    #[serde(default)]
    pub at: Option<[f64; 2]>,
    /// Why it could not be polished.
    pub why: PolishFailure,
}

impl std::fmt::Display for DroppedPoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.at {
            Some(at) => write!(
                f,
                "{} at ({:.5}, {:.5}): {}",
                self.condition, at[0], at[1], self.why
            ),
            None => write!(f, "{}", self.why),
        }
    }
}

/// Dropped points written as data, or as the lines of text earlier versions
/// wrote (kept whole as the reason, the point not known apart from it).
fn dropped_data_or_text<'de, D>(d: D) -> Result<Vec<DroppedPoint>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Written {
        Data(DroppedPoint),
        Text(String),
    }
    Ok(Vec::<Written>::deserialize(d)?
        .into_iter()
        .map(|w| match w {
            Written::Data(p) => p,
            Written::Text(message) => DroppedPoint {
                condition: String::new(),
                at: None,
                why: PolishFailure::Continuum { message },
            },
        })
        .collect())
}

/// How the traced boundary compares with the grid of one-parameter branches.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct GridCheck {
    /// Grid interval ends compared (lines whose value the loop spans).
    pub ends: usize,
    /// Largest |grid end − nearest boundary crossing of that line|, in the
    /// parameter along the lines.
    #[serde(alias = "max_phi_deviation")]
    pub max_deviation: f64,
    /// Lines where the loop and the grid count different interval ends.
    pub lines_with_other_count: Vec<f64>,
}

/// The island's boundary traced by two-parameter continuation.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Traced {
    /// The pieces in walk order.
    pub pieces: Vec<Piece>,
    /// The walk came back to its start.
    pub closed: bool,
    /// Area enclosed (closed walks only).
    pub area: Option<f64>,
    /// Extent of the traced boundary: {swept: [lo, hi], along: [lo, hi]}
    /// (written keyed by the parameters' names).
    #[serde(with = "ranges_by_name")]
    pub bounding_box: BTreeMap<Parameter, [f64; 2]>,
    /// Points of the pieces (a corner counts in both its pieces).
    pub points: usize,
    /// Equilibria solved (Newton at fixed clamps).
    pub equilibria: usize,
    /// Why the walk stopped before closing, if it did.
    pub stopped: Option<String>,
    /// Comparison with the grid's good intervals.
    #[serde(default)]
    pub grid_check: Option<GridCheck>,
    /// The boundary polished on the continuum (`[map] polish = true`).
    #[serde(default)]
    pub polished: Option<PolishedBoundary>,
    /// Why the polish failed, if it did.
    #[serde(default, deserialize_with = "PolishFailure::data_or_text")]
    pub not_polished: Option<PolishFailure>,
}

impl Traced {
    /// The pieces' points joined in walk order.
    pub fn polygon(&self) -> Vec<[f64; 2]> {
        self.pieces.iter().flat_map(|p| p.points.clone()).collect()
    }

    /// Values along the lines where the traced loop crosses the line
    /// (swept parameter = v).
    pub fn cuts(&self, v: f64) -> Vec<f64> {
        self.polygon()
            .windows(2)
            .filter(|w| (w[0][0] <= v) != (w[1][0] <= v))
            .map(|w| w[0][1] + (v - w[0][0]) / (w[1][0] - w[0][0]) * (w[1][1] - w[0][1]))
            .collect()
    }

    /// A walk that could not start.
    pub fn failed(why: String) -> Self {
        Traced {
            pieces: vec![],
            closed: false,
            area: None,
            bounding_box: BTreeMap::new(),
            points: 0,
            equilibria: 0,
            stopped: Some(why),
            grid_check: None,
            polished: None,
            not_polished: None,
        }
    }
}

/// Two crossing conditions of the same strands, up to a few segments.
fn same_crossing(a: &Condition, b: &Condition) -> bool {
    match (a, b) {
        (Condition::Crossing(a), Condition::Crossing(b)) => a.near(b.first, b.other),
        _ => false,
    }
}

/// A crossing followed across neighbouring segment pairs (a corner where
/// the knot test flickered at a sharp tip) is one curve: such consecutive
/// pieces are joined.
pub(super) fn merge_crossings(mut pieces: Vec<Trail>) -> Vec<Trail> {
    let mut k = 1;
    while k < pieces.len() {
        if same_crossing(&pieces[k - 1].0, &pieces[k].0) {
            let next = pieces.remove(k);
            pieces[k - 1].1.extend(next.1.into_iter().skip(1));
        } else {
            k += 1;
        }
    }
    pieces
}

/// The paper's name of a piece: walls are W1 where the good region lies
/// above them along the lines (in φ for the paper), W2 where it lies below.
fn label(c: &Condition, side: f64) -> &'static str {
    match c {
        Condition::Wall if side >= 0.0 => "W1",
        Condition::Wall => "W2",
        Condition::Crossing(_) => "X",
        Condition::Stability => "S",
    }
}

/// Name the pieces as the paper does and measure the loop.
pub(super) fn name_pieces(
    [swept, along]: [Parameter; 2],
    equilibria: usize,
    pieces: Vec<Trail>,
    closed: bool,
    stopped: Option<String>,
) -> Traced {
    let pieces = merge_crossings(pieces);
    // split the pieces where their name changes (a wall curve turning round
    // the island's tip is W1 on one side and W2 on the other)
    let mut named: Vec<Piece> = Vec::new();
    for (c, points) in &pieces {
        let piece = |name: &str, p: [f64; 2]| Piece {
            label: name.into(),
            condition: c.describe(),
            points: vec![p],
        };
        let mut current = piece(label(c, points[0].normal[1]), points[0].at);
        for (k, &TrailPoint { at: p, normal, .. }) in points.iter().enumerate().skip(1) {
            let side = normal[1];
            current.points.push(p);
            // the piece's last point (a corner or the walk's start) keeps
            // its piece's name; elsewhere a change of side starts a new one
            let name = label(c, side);
            if name != current.label && k + 1 < points.len() {
                named.push(std::mem::replace(&mut current, piece(name, p)));
            }
        }
        named.push(current);
    }
    // a closed walk starts inside a piece: join its two ends
    if closed && named.len() > 1 && named[0].label == named[named.len() - 1].label {
        let first = named.remove(0);
        named
            .last_mut()
            .unwrap()
            .points
            .extend(first.points.into_iter().skip(1));
    }
    // several pieces of one name are numbered along the lines (X1, X2 as in
    // the paper)
    let mut by_label: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for (k, p) in named.iter().enumerate() {
        by_label.entry(p.label.clone()).or_default().push(k);
    }
    for (label, mut ks) in by_label {
        if ks.len() < 2 {
            continue;
        }
        let mean = |p: &Piece| p.points.iter().map(|x| x[1]).sum::<f64>() / p.points.len() as f64;
        ks.sort_by(|&a, &b| mean(&named[a]).total_cmp(&mean(&named[b])));
        for (i, k) in ks.into_iter().enumerate() {
            named[k].label = if label == "X" {
                format!("X{}", i + 1)
            } else {
                format!("{label}.{}", i + 1)
            };
        }
    }
    let mut traced = Traced {
        points: named.iter().map(|p| p.points.len()).sum(),
        pieces: named,
        closed,
        area: None,
        bounding_box: BTreeMap::new(),
        equilibria,
        stopped,
        grid_check: None,
        polished: None,
        not_polished: None,
    };
    let all = traced.polygon();
    traced.area = closed.then(|| {
        0.5 * all
            .windows(2)
            .map(|w| w[0][0] * w[1][1] - w[1][0] * w[0][1])
            .sum::<f64>()
            .abs()
    });
    if !all.is_empty() {
        for (k, name) in [swept, along].into_iter().enumerate() {
            let lo = all.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
            let hi = all.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
            traced.bounding_box.insert(name, [lo, hi]);
        }
    }
    traced
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wall_curve_round_the_tip_is_w1_on_one_side_and_w2_on_the_other() {
        // a closed walk starting on the wall's upper side (good side below,
        // W2), round the tip (W1), then a stability curve back to the start
        let points = |p: &[([f64; 2], f64)]| {
            p.iter()
                .map(|&(at, side): &([f64; 2], f64)| TrailPoint {
                    at,
                    normal: [(1.0 - side * side).sqrt(), side],
                    state: None,
                })
                .collect::<Vec<_>>()
        };
        let trail: Vec<Trail> = vec![
            (
                Condition::Wall,
                points(&[
                    ([0.2, 0.9], -0.5),
                    ([0.1, 0.8], -0.2),
                    ([0.1, 0.7], 0.3),
                    ([0.2, 0.6], 0.6),
                ]),
            ),
            (
                Condition::Stability,
                points(&[([0.2, 0.6], 0.1), ([0.3, 0.8], 0.1), ([0.2, 0.9], 0.1)]),
            ),
        ];
        let t = name_pieces([Parameter::ZStar, Parameter::Phi], 7, trail, true, None);
        let labels: Vec<&str> = t.pieces.iter().map(|p| p.label.as_str()).collect();
        // the walk's first piece (W2 from the start) joins its last (W2 back to
        // the start) only when they share a name; here S closes the loop
        assert_eq!(labels, ["W2", "W1", "S"]);
        assert_eq!(t.pieces[0].points, vec![[0.2, 0.9], [0.1, 0.8], [0.1, 0.7]]);
        assert_eq!(t.bounding_box[&Parameter::ZStar], [0.1, 0.3]);
        // shoelace area of the polygon (0.2,0.9) (0.1,0.8) (0.1,0.7) (0.2,0.6) (0.3,0.8)
        assert!((t.area.unwrap() - 0.035).abs() < 1e-12, "{:?}", t.area);
        assert_eq!(t.equilibria, 7);
    }

    #[test]
    fn polish_failures_are_written_as_data_and_old_text_still_reads() {
        let mut t = Traced::failed("a test".into());
        t.not_polished = Some(PolishFailure::TooManyFailed {
            failed: 3,
            of: 20,
            first: Box::new(PolishFailure::NoSingularVectors),
        });
        let json = serde_json::to_value(&t).unwrap();
        assert_eq!(json["not_polished"]["reason"], "too_many_failed");
        assert_eq!(
            json["not_polished"]["first"]["reason"],
            "no_singular_vectors"
        );
        let back: Traced = serde_json::from_value(json.clone()).unwrap();
        assert_eq!(back, t);
        // a map written before the failures were typed
        let mut old = json;
        old["not_polished"] = "the corner's secant steps did not converge".into();
        let back: Traced = serde_json::from_value(old).unwrap();
        assert_eq!(
            back.not_polished,
            Some(PolishFailure::Continuum {
                message: "the corner's secant steps did not converge".into()
            })
        );
    }

    #[test]
    fn a_dropped_point_keeps_its_condition_place_and_reason() {
        let d = DroppedPoint {
            condition: "wall".into(),
            at: Some([0.17, 0.8]),
            why: PolishFailure::NoSelfApproach,
        };
        let json = serde_json::to_value(vec![d.clone()]).unwrap();
        assert_eq!(json[0]["why"]["reason"], "no_self_approach");
        let back = dropped_data_or_text(json).unwrap();
        assert_eq!(back, vec![d.clone()]);
        assert_eq!(
            d.to_string(),
            "wall at (0.17000, 0.80000): no self-approach of the centreline"
        );
        let old = serde_json::json!(["wall at (0.1, 0.8): no self-approach"]);
        let back = dropped_data_or_text(old).unwrap();
        assert!(
            matches!(&back[0].why, PolishFailure::Continuum { message } if message.contains("wall at"))
        );
        // read from old text, written and read again unchanged (no NaN
        // placeholder, which JSON writes as null)
        let again = dropped_data_or_text(serde_json::to_value(&back).unwrap()).unwrap();
        assert_eq!(again, back);
        assert_eq!(back[0].to_string(), "wall at (0.1, 0.8): no self-approach");
    }
}
