//! Knot types and writhe of closed curves.

use knotrod::geometry::knot::{KnotError, knot_type, knot_type_along};
use knotrod::geometry::polyline::{CurveError, parse_points};
use knotrod::geometry::writhe::{segment_pair_writhe, try_writhe_closed, writhe_closed};
use nalgebra::{Rotation3, Vector3};
use std::f64::consts::PI;

use crate::common;
use common::Lcg;

fn direction(rng: &mut Lcg) -> Vector3<f64> {
    loop {
        let v = Vector3::new(rng.next(), rng.next(), rng.next());
        if v.norm() > 0.1 && v.norm() < 1.0 {
            return v.normalize();
        }
    }
}

fn curve(m: usize, f: impl Fn(f64) -> Vector3<f64>) -> Vec<Vector3<f64>> {
    (0..m).map(|k| f(2.0 * PI * k as f64 / m as f64)).collect()
}

fn torus(p: f64, q: f64, m: usize) -> Vec<Vector3<f64>> {
    curve(m, |t| {
        Vector3::new(
            (2.0 + (q * t).cos()) * (p * t).cos(),
            (2.0 + (q * t).cos()) * (p * t).sin(),
            (q * t).sin(),
        )
    })
}

fn figure_eight(m: usize) -> Vec<Vector3<f64>> {
    curve(m, |t| {
        Vector3::new(
            (2.0 + (2.0 * t).cos()) * (3.0 * t).cos(),
            (2.0 + (2.0 * t).cos()) * (3.0 * t).sin(),
            (4.0 * t).sin(),
        )
    })
}

/// An unknot with many crossings in projection: a circle wound in a
/// deep spiral that comes back out the same way (a "coiled" unknot).
fn messy_unknot(m: usize) -> Vec<Vector3<f64>> {
    curve(m, |t| {
        // out along a 5-turn spiral at z = +1 side, back along it at z = -1 side
        let u = t / (2.0 * PI);
        let (r, z, ang) = if u < 0.5 {
            let w = u / 0.5;
            (1.0 + 2.0 * w, 0.3 * (PI * w).sin() + 0.05, 10.0 * PI * w)
        } else {
            let w = (1.0 - u) / 0.5;
            (
                1.0 + 2.0 * w + 0.3,
                -0.3 * (PI * w).sin() - 0.05,
                10.0 * PI * w + 0.2,
            )
        };
        Vector3::new(r * ang.cos(), r * ang.sin(), z + 0.4 * (3.0 * ang).sin())
    })
}

fn determinant_in_random_directions(points: &[Vector3<f64>], seed: u64) -> Vec<u64> {
    let mut rng = Lcg(seed);
    (0..20)
        .filter_map(|_| knot_type_along(points, &direction(&mut rng)).ok())
        .map(|k| k.determinant)
        .collect()
}

#[test]
fn torus_and_figure_eight_knots() {
    type Case = (&'static str, Vec<Vector3<f64>>, u64, Vec<i64>);
    let cases: Vec<Case> = vec![
        ("T(2,3)", torus(2.0, 3.0, 300), 3, vec![1, -1, 1]),
        ("T(3,2) mirror", torus(2.0, -3.0, 300), 3, vec![1, -1, 1]),
        ("T(2,5)", torus(2.0, 5.0, 500), 5, vec![1, -1, 1, -1, 1]),
        ("figure-eight", figure_eight(400), 5, vec![-1, 3, -1]),
        (
            "circle",
            curve(100, |t| Vector3::new(t.cos(), t.sin(), 0.0)),
            1,
            vec![1],
        ),
    ];
    for (name, pts, det, poly) in cases {
        let k = knot_type(&pts).unwrap();
        assert_eq!(k.determinant, det, "{name}: {k:?}");
        assert_eq!(k.alexander, poly, "{name}: {k:?}");
        let dets = determinant_in_random_directions(&pts, 11);
        assert!(dets.len() >= 18, "{name}: too many degenerate projections");
        assert!(dets.iter().all(|d| *d == det), "{name}: {dets:?}");
    }
}

#[test]
fn messy_unknot_is_unknot_from_every_direction() {
    let pts = messy_unknot(2000);
    let mut rng = Lcg(5);
    let mut max_crossings = 0;
    for _ in 0..20 {
        if let Ok(k) = knot_type_along(&pts, &direction(&mut rng)) {
            assert_eq!(k.alexander, vec![1]);
            max_crossings = max_crossings.max(k.projected);
        }
    }
    assert!(
        max_crossings >= 10,
        "the test curve should be messy: {max_crossings} crossings"
    );
    assert_eq!(knot_type(&pts).unwrap().determinant, 1);
}

#[test]
fn writhe_of_planar_and_symmetric_curves_vanishes() {
    let circle = curve(200, |t| Vector3::new(t.cos(), t.sin(), 0.0));
    assert!(writhe_closed(&circle).abs() < 1e-14);
    let planar = curve(300, |t| {
        Vector3::new(
            (2.0 + (3.0 * t).cos()) * t.cos(),
            (2.0 + (3.0 * t).cos()) * t.sin(),
            0.0,
        )
    });
    assert!(writhe_closed(&planar).abs() < 1e-14);
}

#[test]
fn writhe_is_invariant_and_converges_with_resolution() {
    let w: Vec<f64> = [200, 400, 800]
        .iter()
        .map(|&m| writhe_closed(&torus(2.0, 3.0, m)))
        .collect();
    // second-order convergence of the polygon's writhe to the smooth curve's
    let order = ((w[0] - w[1]) / (w[1] - w[2])).log2();
    assert!((order - 2.0).abs() < 0.2, "order {order}, writhes {w:?}");
    // rigid motions and a shift of the starting vertex change nothing
    let base = torus(2.0, 3.0, 400);
    let rot = Rotation3::from_euler_angles(0.3, -1.1, 2.0);
    let moved: Vec<Vector3<f64>> = base
        .iter()
        .map(|p| rot * p + Vector3::new(1.0, 2.0, 3.0))
        .collect();
    assert!((writhe_closed(&moved) - w[1]).abs() < 1e-11);
    let mut shifted = base.clone();
    shifted.rotate_left(37);
    assert!((writhe_closed(&shifted) - w[1]).abs() < 1e-11);
    // a mirror image has the opposite writhe
    let mirror: Vec<Vector3<f64>> = base.iter().map(|p| Vector3::new(p.x, p.y, -p.z)).collect();
    assert!((writhe_closed(&mirror) + w[1]).abs() < 1e-11);
}

#[test]
fn passing_a_strand_through_another_changes_writhe_by_two() {
    // a trefoil deformed by pushing one crossing through: family with a
    // parameter moving one strand in depth across another
    let family = |lift: f64| -> Vec<Vector3<f64>> {
        curve(600, |t| {
            let p = Vector3::new(
                (2.0 + (3.0 * t).cos()) * (2.0 * t).cos(),
                (2.0 + (3.0 * t).cos()) * (2.0 * t).sin(),
                (3.0 * t).sin(),
            );
            // near t = π/6 the strand is at a crossing; push it in z
            let bump = (-((t - PI / 6.0) / 0.15).powi(2)).exp();
            p + Vector3::new(0.0, 0.0, lift * bump)
        })
    };
    let before = writhe_closed(&family(0.0));
    let after = writhe_closed(&family(-3.0));
    let jump = after - before;
    // the smooth deformation away from the crossing changes writhe continuously,
    // the passage adds exactly ±2: check the change through the passage with a
    // pair of nearby curves on both sides
    let (lo, hi) = bracket_passage(&family);
    let d = writhe_closed(&family(hi)) - writhe_closed(&family(lo));
    assert!(
        (d.abs() - 2.0).abs() < 1e-3,
        "jump {d} at passage, total change {jump}"
    );
    assert_ne!(
        knot_type(&family(0.0)).unwrap().determinant,
        knot_type(&family(-3.0)).unwrap().determinant
    );
}

/// Find lift values just before and after the strand passage (where the knot
/// type changes), within 3e-9 (above the 1e-10 relative margin at which
/// strands count as meeting).
fn bracket_passage(family: &dyn Fn(f64) -> Vec<Vector3<f64>>) -> (f64, f64) {
    let det = |l: f64| knot_type(&family(l)).unwrap().determinant;
    let (mut lo, mut hi) = (0.0, -3.0);
    let d0 = det(lo);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if det(mid) == d0 { lo = mid } else { hi = mid }
    }
    (lo, hi)
}

/// Fuller's formula (1978): for closed curves C0, C1 with tangents T0(t),
/// T1(t) never opposite, Wr(C1) − Wr(C0) = (1/2π) ∮ (T0 × T1)·(T0' + T1') /
/// (1 + T0·T1) dt. A single smooth periodic integral (spectrally accurate by the
/// trapezoidal rule): an independent reference for the polygon's double sum.
fn fuller_writhe_difference(
    t0: impl Fn(f64) -> Vector3<f64>,
    t1: impl Fn(f64) -> Vector3<f64>,
    m: usize,
) -> f64 {
    let h = 2.0 * PI / m as f64;
    let d = 1e-5;
    (0..m)
        .map(|k| {
            let t = k as f64 * h;
            let (a, b) = (t0(t), t1(t));
            let da = (t0(t + d) - t0(t - d)) / (2.0 * d);
            let db = (t1(t + d) - t1(t - d)) / (2.0 * d);
            a.cross(&b).dot(&(da + db)) / (1.0 + a.dot(&b))
        })
        .sum::<f64>()
        * h
        / (2.0 * PI)
}

#[test]
fn writhe_of_a_closed_helix_matches_fullers_formula() {
    // a helix of n turns wound on a circle (closed on itself); reference: the
    // circle, of writhe 0
    for (n, a) in [(3.0, 0.1), (5.0, 0.06), (8.0, 0.03)] {
        let r = |t: f64| {
            Vector3::new(
                (1.0 + a * (n * t).cos()) * t.cos(),
                (1.0 + a * (n * t).cos()) * t.sin(),
                a * (n * t).sin(),
            )
        };
        let dr = |t: f64| (r(t + 1e-6) - r(t - 1e-6)) / 2e-6;
        let t1 = |t: f64| dr(t).normalize();
        let t0 = |t: f64| Vector3::new(-t.sin(), t.cos(), 0.0);
        let exact = fuller_writhe_difference(t0, t1, 4000);
        // the polygon converges as 1/M²: Richardson from M and 2M
        let (w1, w2) = (
            writhe_closed(&curve(1000, r)),
            writhe_closed(&curve(2000, r)),
        );
        let extrapolated = (4.0 * w2 - w1) / 3.0;
        assert!(
            (extrapolated - exact).abs() < 1e-6,
            "n = {n}: polygon {extrapolated} vs Fuller {exact}"
        );
        assert!(exact.abs() > 0.01, "a non-trivial writhe");
    }
}

/// One polygon of tests/fixtures/knots/curves.json (see its README).
#[derive(serde::Deserialize)]
struct FixtureCurve {
    name: String,
    kind: String,
    expected: Option<String>,
    points: Vec<[f64; 3]>,
    alexander_pyknotid: Option<Vec<i64>>,
    alexander_topoly: Option<Vec<i64>>,
    determinant: u64,
}

fn fixture() -> Vec<FixtureCurve> {
    let text = std::fs::read_to_string("tests/fixtures/knots/curves.json").unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn fixture_polygons_agree_with_pyknotid_and_topoly() {
    let curves = fixture();
    assert!(curves.len() >= 300, "{} curves", curves.len());
    let (mut checked, mut knotted, mut named) = (0, 0, 0);
    let mut failures = Vec::new();
    for c in &curves {
        // the reference: both tools where both answered (they never disagree),
        // else pyknotid's (Topoly timed out on 11 curves)
        let reference = match (&c.alexander_pyknotid, &c.alexander_topoly) {
            (Some(a), Some(b)) if a != b => continue,
            (Some(a), _) | (None, Some(a)) => a.clone(),
            (None, None) => continue,
        };
        let points: Vec<Vector3<f64>> = c.points.iter().map(|p| Vector3::from(*p)).collect();
        checked += 1;
        match knot_type(&points) {
            Ok(k) if k.alexander == reference && k.determinant == c.determinant => {
                knotted += usize::from(k.determinant > 1);
                if let Some(expected) = &c.expected {
                    if !k.names.contains(expected) {
                        failures.push(format!("{}: names {:?} lack {expected}", c.name, k.names));
                    }
                    named += 1;
                }
            }
            other => failures.push(format!(
                "{} ({}): {other:?}, reference {reference:?}",
                c.name, c.kind
            )),
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {checked} differ:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(
        checked >= 300 && knotted >= 190 && named >= 90,
        "{checked} {knotted} {named}"
    );
}

#[test]
fn every_projection_of_small_fixture_polygons_agrees() {
    // without simplification and along random directions: the diagram, its
    // moves and the exact determinant alone must give the same answer
    let mut rng = Lcg(29);
    let mut projections = 0;
    for c in fixture().iter().filter(|c| c.points.len() <= 120) {
        let points: Vec<Vector3<f64>> = c.points.iter().map(|p| Vector3::from(*p)).collect();
        let whole = knot_type(&points).unwrap();
        for _ in 0..3 {
            if let Ok(k) = knot_type_along(&points, &direction(&mut rng)) {
                assert_eq!(k.alexander, whole.alexander, "{}", c.name);
                projections += 1;
            }
        }
    }
    assert!(projections > 150, "{projections} projections");
}

#[test]
fn a_dense_curve_and_degenerate_input_are_handled() {
    // 10⁵ points on T(3,5) = 10_124, jittered: simplification brings it
    // down to a few dozen vertices
    let mut rng = Lcg(41);
    let dense: Vec<Vector3<f64>> = torus(3.0, 5.0, 100_000)
        .into_iter()
        .map(|p| p + 1e-4 * Vector3::new(rng.next(), rng.next(), rng.next()))
        .collect();
    let k = knot_type(&dense).unwrap();
    assert_eq!(k.alexander, vec![1, -1, 0, 1, -1, 1, 0, -1, 1]);
    assert!(k.names.contains(&"10_124".to_string()), "{:?}", k.names);
    assert!(k.vertices < 200, "{} vertices left", k.vertices);
    // the closing point may repeat the first
    let mut repeated = torus(2.0, 3.0, 120);
    repeated.push(repeated[0]);
    assert_eq!(knot_type(&repeated).unwrap().determinant, 3);
    // a figure-eight curve in the plane passes through itself
    let lemniscate = curve(200, |t| Vector3::new(t.sin(), (2.0 * t).sin(), 0.0));
    assert!(matches!(
        knot_type(&lemniscate),
        Err(KnotError::SelfIntersection(_))
    ));
    assert!(matches!(
        knot_type(&lemniscate[..2]),
        Err(KnotError::TooFewPoints(2))
    ));
    // 2000 random points in a box: hundreds of thousands of crossings, a
    // clear error rather than gigabytes and hours
    let tangle: Vec<Vector3<f64>> = (0..2000)
        .map(|_| Vector3::new(rng.next(), rng.next(), rng.next()))
        .collect();
    assert!(matches!(
        knot_type(&tangle),
        Err(KnotError::TooManyCrossings(_))
    ));
    let mut bad = torus(2.0, 3.0, 50);
    bad[7].y = f64::NAN;
    assert!(matches!(knot_type(&bad), Err(KnotError::NotFinite(7))));
}

#[test]
fn knot_type_and_writhe_do_not_depend_on_scale() {
    // a 300-point trefoil at 1e100 read as the unknot (products of
    // coordinates overflowed), at 1e200 had no generic projection, at 1e-300
    // collapsed to one point when read from text
    let trefoil = torus(2.0, 3.0, 300);
    let w1 = writhe_closed(&trefoil);
    for scale in [1e-300, 1e-100, 1.0, 1e100, 1e150, 1e200, 1e300] {
        for shift in [0.0, 1e3] {
            let p: Vec<Vector3<f64>> = trefoil
                .iter()
                .map(|q| scale * (q + Vector3::repeat(shift)))
                .collect();
            let k = knot_type(&p).unwrap_or_else(|e| panic!("×{scale:e}: {e}"));
            assert_eq!(k.determinant, 3, "×{scale:e} +{shift}: {k:?}");
            assert_eq!(k.name.as_deref(), Some("3_1"), "×{scale:e}: {k:?}");
            let w = writhe_closed(&p);
            assert!(
                (w - w1).abs() < 1e-9,
                "×{scale:e} +{shift}: writhe {w}, {w1} at 1"
            );
        }
        let text: String = trefoil
            .iter()
            .map(|q| format!("{:e} {:e} {:e}\n", scale * q.x, scale * q.y, scale * q.z))
            .collect();
        assert_eq!(parse_points(&text).unwrap().len(), 300, "×{scale:e}");
    }
}

/// n points on the trefoil T(2,3), each moved by up to a quarter of the
/// shortest step in each coordinate (seeded): consecutive segments but one
/// then stay apart along the tangent all the way along the straight
/// homotopy to the smooth curve, so the noisy polygon is still a trefoil.
fn noisy_trefoil(n: usize, seed: u64) -> Vec<Vector3<f64>> {
    let smooth = torus(2.0, 3.0, n);
    let step = (0..n)
        .map(|k| (smooth[(k + 1) % n] - smooth[k]).norm())
        .fold(f64::INFINITY, f64::min);
    let mut rng = Lcg(seed);
    smooth
        .into_iter()
        .map(|p| p + 0.25 * step * Vector3::new(rng.next(), rng.next(), rng.next()))
        .collect()
}

#[test]
fn long_noisy_curves_keep_their_knot_and_exact_writhe() {
    // the writhe of a long curve comes from one projection: the same as the
    // sum over all segment pairs
    let p = noisy_trefoil(3000, 3);
    let m = p.len();
    let mut pairs = 0.0;
    for i in 0..m {
        for j in i + 2..m {
            if !(i == 0 && j == m - 1) {
                pairs += segment_pair_writhe(&p[i], &p[i + 1], &p[j], &p[(j + 1) % m]);
            }
        }
    }
    let w = writhe_closed(&p);
    assert!(
        (w - 2.0 * pairs).abs() < 1e-9,
        "{w} by projection, {} by pairs",
        2.0 * pairs
    );
    // 10⁵ points (10⁶ in `knotrod bench`): the trefoil, and a writhe
    let p = noisy_trefoil(100_000, 5);
    let k = knot_type(&p).unwrap();
    assert_eq!(k.name.as_deref(), Some("3_1"), "{k:?}");
    assert!(k.vertices < 50, "{} vertices left", k.vertices);
    let w = try_writhe_closed(&p).unwrap();
    assert!(w.is_finite() && w.abs() < 20.0, "writhe {w}");
    assert_eq!(w, writhe_closed(&p));
}

#[test]
fn a_curve_too_tangled_for_the_budget_is_refused_with_an_estimate() {
    // 10⁵ points in a box: some 10⁹ overlapping segment pairs to sweep and
    // O(n²) simplification; a clear error rather than minutes or hours
    let mut rng = Lcg(17);
    let cloud: Vec<Vector3<f64>> = (0..100_000)
        .map(|_| Vector3::new(rng.next(), rng.next(), rng.next()))
        .collect();
    for e in [
        knot_type(&cloud).unwrap_err(),
        try_writhe_closed(&cloud).unwrap_err(),
    ] {
        match e {
            KnotError::TooLong { pairs, seconds } => {
                assert!(pairs > 2e9 && seconds > 10.0, "{e}")
            }
            other => panic!("{other}"),
        }
    }
}

#[test]
fn a_curve_file_header_must_name_its_columns() {
    for header in [
        "x y z",
        "x,y,z",
        "X; Y; Z",
        "\"x\",\"y\",\"z\"",
        "# a comment\nx y z",
    ] {
        let text = format!("{header}\n0 0 0\n1 0 0\n0 1 0\n");
        assert_eq!(parse_points(&text).unwrap().len(), 3, "{header}");
    }
    // a typo in the first point was taken for a header and the point dropped
    for (text, line) in [
        ("0 0 O\n1 0 0\n0 1 0\n0 0 1\n", 1),
        ("x y z\n0 0 O\n1 0 0\n0 1 0\n0 0 1\n", 2),
        ("# c\n\n1,2,3e\n1 0 0\n0 1 0\n0 0 1\n", 3),
        ("x y z\nx y z\n1 0 0\n0 1 0\n0 0 1\n", 2),
        ("x y\n1 0 0\n0 1 0\n0 0 1\n", 1),
    ] {
        match parse_points(text) {
            Err(CurveError::Line { line: l, .. }) => assert_eq!(l, line, "{text:?}"),
            other => panic!("{text:?}: {other:?}"),
        }
    }
}

#[test]
fn a_curve_whose_points_rounding_makes_coincide_is_answered_at_once() {
    // found by the curve_text fuzz target: one coordinate 5.6e197 beside
    // ones of order 1, so unit sizing rounds the small ones onto one point;
    // the simplification's median segment was 0 and its passes never ended
    let out = common::knotrod(&[
        "knot",
        "tests/fixtures/curve_collapsing_points.txt",
        "--closed",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("knot type"), "{err}");
}
