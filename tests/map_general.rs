//! Maps in any two parameters: the good knots of the Appendix D knot in
//! (z*, tilt of the s = 1 clamp), each line a branch in the tilt, checked
//! against the one-parameter branch of `scenes/tilted_end_clamp.toml` and
//! against the boundary walked in the plane; old map files still load.

use knotrod::analysis::event::EventKind;
use knotrod::model::rod::Parameter;
use knotrod::scene::Scene;
use knotrod::study::map::{Map, branch_intervals_in};
use serde_json::Value;

use crate::common;
use common::{map_json, run, temp_dir};

/// A scene file's text with some settings replaced (each must be there).
fn variant(file: &str, replace: &[(&str, &str)]) -> String {
    let mut text = std::fs::read_to_string(file).unwrap();
    for (from, to) in replace {
        assert!(text.contains(from), "{file} has no {from}");
        text = text.replace(from, to);
    }
    text
}

/// Tilt values of the wall events of a branch at z* = 0.115, below and above
/// zero (the good interval's ends).
fn wall_events_around_zero(events: &[knotrod::analysis::event::Event]) -> (f64, f64) {
    let walls: Vec<f64> = events
        .iter()
        .filter(|e| e.kind == EventKind::Wall && e.branch == 0)
        .map(|e| e.value(Parameter::EndTilt))
        .collect();
    let below = walls
        .iter()
        .copied()
        .filter(|t| *t < 0.0)
        .fold(f64::NEG_INFINITY, f64::max);
    let above = walls
        .iter()
        .copied()
        .filter(|t| *t > 0.0)
        .fold(f64::INFINITY, f64::min);
    (below, above)
}

/// The map of a variant of a scene file (see [`variant`]), run by
/// `knotrod map` in a fresh directory and read back.
fn map_of(name: &str, file: &str, replace: &[(&str, &str)]) -> Map {
    let dir = temp_dir(name);
    let scene = dir.join(format!("{name}.toml"));
    std::fs::write(&scene, variant(file, replace)).unwrap();
    map_json(&scene, &dir.join(format!("{name}.json")))
}

/// How often the traced boundary crosses the map's lines, each crossing
/// required within `tol` of one of that line's interval ends.
fn crossings_at_interval_ends(map: &Map, tol: f64) -> usize {
    let t = map.traced.as_ref().expect("the boundary was traced");
    let mut cuts = 0;
    for l in &map.lines {
        let ends: Vec<f64> = l.intervals.iter().flat_map(|i| [i.lo, i.hi]).collect();
        for c in t.cuts(l.value) {
            let d = ends
                .iter()
                .map(|e| (e - c).abs())
                .fold(f64::INFINITY, f64::min);
            assert!(
                d < tol,
                "{} = {}: the walk crosses at {c}, {d} from the grid's ends {ends:?}",
                map.parameter.name(),
                l.value
            );
            cuts += 1;
        }
    }
    cuts
}

#[test]
fn map_in_z_star_and_end_tilt_agrees_with_the_tilt_branch_and_the_walk() {
    const N: &str = "segments = 50";
    // N = 50, six lines z* = 0.105, 0.115, ..., 0.155 (the branch point of the
    // untilted knot lies near 0.150 at this N: the walk starts below it)
    let map = map_of(
        "map-tilt",
        "scenes/map_zstar_tilt.toml",
        &[
            ("segments = 100", N),
            ("range = [0.095, 0.165]", "range = [0.105, 0.155]"),
            ("lines = 15", "lines = 6"),
            ("grid_columns = 61", "grid_columns = 21"),
            ("trace_from = [0.15, 0.0]", "trace_from = [0.14, 0.0]"),
        ],
    );
    assert_eq!(
        (map.parameter.name(), map.along.name()),
        ("z_star", "end_tilt")
    );
    assert_eq!(map.grid_along.len(), 21);
    assert_eq!(map.grid_along[0], -0.1);
    assert!(
        map.bounding_box.contains_key(&Parameter::EndTilt)
            && map.bounding_box.contains_key(&Parameter::ZStar)
    );

    // every good interval is one tilt interval bounded by the walls: W1
    // below (the good side above it, as in φ), W2 above
    let good: Vec<_> = map
        .lines
        .iter()
        .filter(|l| !l.intervals.is_empty())
        .collect();
    assert!(good.len() >= 4, "lines with good knots: {}", good.len());
    for l in &map.lines {
        assert!(l.error.is_none(), "z* = {}: {:?}", l.value, l.error);
        for i in &l.intervals {
            assert_eq!(
                (i.lo_label.as_str(), i.hi_label.as_str()),
                ("W1", "W2"),
                "z* = {}: {i}",
                l.value
            );
            assert!(
                i.lo < 0.0 && i.hi > 0.0 && i.hi - i.lo < 0.1,
                "z* = {}: {i}",
                l.value
            );
        }
    }

    // the line at z* = 0.115 is the branch of tilted_end_clamp.toml at the
    // same N: its ends are that branch's wall events (measured: within
    // 5e-9, each located by bisection on a branch with other steps)
    let branch = Scene::parse(&variant(
        "scenes/tilted_end_clamp.toml",
        &[("segments = 100", N)],
    ))
    .unwrap();
    let (eqs, events) = run(&branch);
    let (w_lo, w_hi) = wall_events_around_zero(&events);
    let line = map
        .lines
        .iter()
        .find(|l| (l.value - 0.115).abs() < 1e-12)
        .expect("a line at z* = 0.115");
    assert_eq!(line.intervals.len(), 1, "{:?}", line.intervals);
    let iv = &line.intervals[0];
    assert!(
        (iv.lo - w_lo).abs() < 1e-6 && (iv.hi - w_hi).abs() < 1e-6,
        "map line {iv} against the branch's walls {w_lo}, {w_hi}"
    );
    // and the branch's own intervals in the tilt say the same
    let own = branch_intervals_in(Parameter::EndTilt, &eqs, &events);
    assert!(
        own.iter()
            .any(|i| (i.lo - iv.lo).abs() < 1e-6 && (i.hi - iv.hi).abs() < 1e-6),
        "{own:?}"
    );

    // the walk in the plane: wall curves only, each crossing of a line
    // within 2e-4 in tilt of that line's interval ends (measured 3.2e-5)
    let t = map.traced.as_ref().expect("the boundary was traced");
    assert!(t.points > 20, "{:?}", t.stopped);
    for p in &t.pieces {
        assert!(["W1", "W2"].contains(&p.label.as_str()), "{}", p.label);
    }
    let cuts = crossings_at_interval_ends(&map, 2e-4);
    assert!(cuts >= 6, "the walk crosses the lines {cuts} times");
    if t.closed {
        let g = t.grid_check.as_ref().unwrap();
        assert!(g.max_deviation < 2e-4, "{g:?}");
    } else {
        // the region's right tip is the untilted knot's branch point S: the
        // tilt unfolds the pitchfork into folds meeting in a cusp there, and
        // the walk stops next to it (measured: 1e-4 beyond it)
        let mut z = branch.clone();
        let c = z.continuation.as_mut().unwrap();
        c.parameter = Parameter::ZStar;
        c.range = [0.1, 0.2];
        let (_, z_events) = run(&z);
        let s = z_events
            .iter()
            .find(|e| e.kind == EventKind::BranchPoint)
            .expect("the untilted branch in z* has a branch point");
        let last = *t.pieces.last().unwrap().points.last().unwrap();
        assert!(
            (last[0] - s.z_star).abs() < 1e-3 && last[1].abs() < 2e-3,
            "the walk stopped at {last:?}, S at z* = {}: {:?}",
            s.z_star,
            t.stopped
        );
    }
}

#[test]
fn map_files_written_in_phi_still_load() {
    // a line, a traced check and a map as written before maps took any
    // parameter along their lines
    let old = r#"{
        "scene": "old", "parameter": "z_star",
        "lines": [{"index": 0, "value": 0.1, "points": [{"phi_over_2pi": 0.8, "twist": 0.1, "class": "good"}],
                   "events": [], "intervals": [], "error": null}],
        "boundaries": {}, "grid": [["good"]], "grid_phi": [0.8], "good_area": 0.0,
        "bounding_box": {"phi_over_2pi": [0.8, 0.8]},
        "traced": {"pieces": [], "closed": true, "area": 0.0, "bounding_box": {}, "points": 0,
                   "equilibria": 0, "stopped": null,
                   "grid_check": {"ends": 2, "max_phi_deviation": 1e-5, "lines_with_other_count": []}}
    }"#;
    let map: Map = serde_json::from_str(old).unwrap();
    assert_eq!(map.along, Parameter::Phi);
    assert_eq!(map.grid_along, [0.8]);
    assert_eq!(map.lines[0].points[0].along, 0.8);
    let g = map.traced.unwrap().grid_check.unwrap();
    assert_eq!(g.max_deviation, 1e-5);
    // and the new names are what is written
    let v: Value = serde_json::to_value(&map.lines[0].points[0]).unwrap();
    assert!(v.get("along").is_some() && v.get("phi_over_2pi").is_none());
}

#[test]
fn a_map_along_its_own_swept_parameter_is_refused_naming_the_field() {
    let text = variant(
        "scenes/map_zstar_tilt.toml",
        &[("parameter = \"z_star\"", "parameter = \"end_tilt\"")],
    );
    let err = Scene::parse(&text).unwrap_err().to_string();
    assert!(
        err.contains("map.parameter") && err.contains("continuation.parameter"),
        "{err}"
    );
}

#[test]
fn a_map_whose_lines_run_in_a_model_scalar_places_them_by_it() {
    // Figure 7-left's knot at N = 40, each line a branch in K3 (a scalar of
    // the model, carried by the states because the scene varies it)
    let map = map_of(
        "map-k3",
        "scenes/fig7_island_kirchhoff.toml",
        &[
            ("segments = 100", "segments = 40"),
            ("parameter = \"phi\"", "parameter = \"K3\""),
            ("range = [0.65, 1.1]", "range = [1.5, 5.0]"),
            ("max_step = 0.01", "max_step = 0.05"),
            ("range = [0.04, 0.30]", "range = [0.10, 0.145]"),
            ("lines = 27", "lines = 4"),
            ("grid_columns = 91", "grid_columns = 21"),
        ],
    );
    assert_eq!(map.along, Parameter::K3);
    // z* = 0.10 lies left of the region; 0.115 (the walk's start, K3 = 3),
    // 0.13 and 0.145 cross it
    for l in &map.lines {
        assert!(
            l.points.iter().all(|p| p.along.is_finite()),
            "z* = {}",
            l.value
        );
        let expected = usize::from(l.value > 0.11);
        assert_eq!(
            l.intervals.len(),
            expected,
            "z* = {}: {:?}",
            l.value,
            l.intervals
        );
        let Some(i) = l.intervals.first() else {
            continue;
        };
        assert!(
            i.lo > 2.0 && i.hi < 5.0 && i.lo < i.hi,
            "z* = {}: {i}",
            l.value
        );
        assert!(
            ["W1", "S"].contains(&i.lo_label.as_str()),
            "z* = {}: {i}",
            l.value
        );
        assert_eq!(i.hi_label, "W2", "z* = {}: {i}", l.value);
    }
    // the walk meets the lines at their ends (measured 2.9e-5), and follows
    // the stability boundary in (z*, K3) to the map's edge
    let t = map.traced.as_ref().unwrap();
    assert!(t.pieces.iter().any(|p| p.label == "S"), "{:?}", t.stopped);
    let cuts = crossings_at_interval_ends(&map, 2e-4);
    assert!(cuts >= 2, "the walk crosses the lines {cuts} times");
}
