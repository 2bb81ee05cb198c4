//! Parameter-space maps: sharding (n shards merged = one run, bit for bit),
//! resuming from computed lines, and the island's boundaries.

use std::path::{Path, PathBuf};

use crate::common;
use common::{knotrod, knotrod_ok, map_json, temp_dir};

/// The Figure 7-left scene with some settings replaced, written into `dir`.
fn fig7_variant(dir: &Path, name: &str, replace: &[(&str, &str)]) -> PathBuf {
    scene_variant("scenes/fig7_island_kirchhoff.toml", dir, name, replace)
}

/// The scene `from` with each text `replace`d, written to `dir/name`.
fn scene_variant(from: &str, dir: &Path, name: &str, replace: &[(&str, &str)]) -> PathBuf {
    let mut text = std::fs::read_to_string(from).unwrap();
    for (from, to) in replace {
        assert!(text.contains(from), "the scene has no {from}");
        text = text.replace(from, to);
    }
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The Figure 7 island at N = 40, 4 lines, unpolished: a map in seconds
/// (also the live view's test map).
pub(crate) fn small_map_scene(dir: &Path) -> PathBuf {
    fig7_variant(
        dir,
        "small_map.toml",
        &[
            ("segments = 100", "segments = 40"),
            ("range = [0.65, 1.1]", "range = [0.74, 0.95]"),
            ("range = [0.04, 0.30]", "range = [0.12, 0.18]"),
            ("lines = 27", "lines = 4"),
            ("grid_columns = 91", "grid_columns = 11"),
            ("polish = true", "polish = false"),
        ],
    )
}

#[test]
fn shards_merge_to_the_single_run_bit_for_bit_and_maps_resume() {
    let dir = temp_dir("map");
    let scene = small_map_scene(&dir);
    let s = scene.to_str().unwrap();
    let whole = dir.join("whole.json");
    knotrod_ok(&["map", s, "--json", whole.to_str().unwrap()]);
    let mut parts = Vec::new();
    for i in 0..3 {
        let p = dir.join(format!("part{i}.json"));
        knotrod_ok(&[
            "map",
            s,
            "--shard",
            &format!("{i}/3"),
            "--json",
            p.to_str().unwrap(),
        ]);
        parts.push(p);
    }
    let merged = dir.join("merged.json");
    let mut args = vec!["merge".to_string()];
    args.extend(parts.iter().map(|p| p.to_str().unwrap().to_string()));
    args.extend(["--json".to_string(), merged.to_str().unwrap().to_string()]);
    knotrod_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let (a, b) = (
        std::fs::read(&whole).unwrap(),
        std::fs::read(&merged).unwrap(),
    );
    assert!(a == b, "merged shards differ from the single run");
    // merged to standard output: the same bytes there alone (issue 54)
    let mut dash: Vec<&str> = vec!["merge"];
    dash.extend(parts.iter().map(|p| p.to_str().unwrap()));
    dash.extend(["--json", "-"]);
    let out = knotrod(&dash);
    assert!(
        out.status.success() && out.stdout == a,
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!Path::new("-.svg").exists() && !Path::new("-.png").exists());
    let map: serde_json::Value = serde_json::from_slice(&a).unwrap();
    for key in ["boundaries", "grid", "good_area", "bounding_box"] {
        assert!(map.get(key).is_some(), "map lacks {key}");
    }
    assert!(map["good_area"].as_f64().unwrap() > 0.0);
    // a missing shard is an error, not a silently smaller map
    let out = knotrod(&[
        "merge",
        parts[0].to_str().unwrap(),
        "--json",
        dir.join("bad.json").to_str().unwrap(),
    ]);
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("missing"));
    // resume: with its lines computed, a rerun recomputes nothing (the line
    // files are not rewritten) and agrees; a deleted line is recomputed
    let cache = whole.with_extension("lines");
    let stamp = |k: usize| {
        std::fs::metadata(cache.join(format!("line_{k:05}.json")))
            .unwrap()
            .modified()
            .unwrap()
    };
    let before: Vec<_> = (0..4).map(stamp).collect();
    std::fs::remove_file(cache.join("line_00002.json")).unwrap();
    let out = knotrod(&["map", s, "--json", whole.to_str().unwrap()]);
    assert!(out.status.success());
    for k in [0, 1, 3] {
        assert_eq!(stamp(k), before[k], "line {k} was recomputed");
    }
    assert!(std::fs::read(&whole).unwrap() == a);
    // the kept lines belong to their scene and N: a run at another N does
    // not reuse them, and the scene's own N afterwards gets its own back
    let w = whole.to_str().unwrap();
    let fresh = dir.join("fresh").join("n20.json");
    knotrod_ok(&[
        "map",
        s,
        "--segments",
        "20",
        "--json",
        fresh.to_str().unwrap(),
    ]);
    knotrod_ok(&["map", s, "--segments", "20", "--json", w]);
    assert!(
        std::fs::read(&whole).unwrap() == std::fs::read(&fresh).unwrap(),
        "N = 20 reused the N = 40 lines"
    );
    knotrod_ok(&["map", s, "--json", w]);
    assert!(
        std::fs::read(&whole).unwrap() == a,
        "N = 40 reused the N = 20 lines"
    );
}

/// The island's boundary traced by two-parameter continuation (the walk
/// around the good region) against the grid of one-parameter branches, each
/// located by bisection along its own branch: an independent check of every
/// interval end the loop spans.
#[test]
fn island_boundary_traced_directly_agrees_with_the_grid() {
    let dir = temp_dir("trace");
    let scene = fig7_variant(
        &dir,
        "trace.toml",
        &[
            ("segments = 100", "segments = 40"),
            ("range = [0.65, 1.1]", "range = [0.70, 1.0]"),
            ("max_step = 0.01", "max_step = 0.002"),
            ("range = [0.04, 0.30]", "range = [0.05, 0.29]"),
            ("lines = 27", "lines = 13"),
            ("grid_columns = 91", "grid_columns = 11"),
            ("polish = true", "polish = false"),
        ],
    );
    let map: serde_json::Value = map_json(&scene, &dir.join("trace.json"));
    let traced = &map["traced"];
    assert_eq!(traced["closed"], true, "{}", traced["stopped"]);
    // `plot` draws a map file as its map: the classes' legend, the curves named
    let stem = dir.join("replot");
    knotrod_ok(&[
        "plot",
        dir.join("trace.json").to_str().unwrap(),
        "--out",
        stem.to_str().unwrap(),
    ]);
    let svg = std::fs::read_to_string(stem.with_extension("svg")).unwrap();
    let texts: Vec<&str> = svg
        .split("<text")
        .skip(1)
        .filter_map(|t| t.split('>').nth(1)?.split('<').next())
        .map(str::trim)
        .collect();
    for name in ["good knot", "S", "W1", "W2", "X"] {
        assert!(texts.contains(&name), "{name} missing from {texts:?}");
    }
    // Figure 7-left: the island is bounded by S, W1, W2 and X
    let mut labels: Vec<&str> = traced["pieces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["label"].as_str().unwrap())
        .collect();
    labels.sort();
    assert_eq!(labels, ["S", "W1", "W2", "X"]);
    let check = &traced["grid_check"];
    assert!(check["ends"].as_u64().unwrap() >= 8);
    // measured 2.4e-5: the chords of the traced polyline (steps up to 0.005)
    // against bisected events; a boundary off by a grid step would fail
    assert!(check["max_deviation"].as_f64().unwrap() < 2e-4);
    assert!(
        check["lines_with_other_count"]
            .as_array()
            .unwrap()
            .is_empty()
    );
}

/// The traced boundary of `scene` with `replace`d settings (two map lines
/// and a coarse grid beside them), polished: its `traced` part.
fn polished_boundary(
    scene: &str,
    dir: &Path,
    name: &str,
    replace: &[(&str, &str)],
) -> serde_json::Value {
    let scene = scene_variant(scene, dir, &format!("{name}.toml"), replace);
    let map: serde_json::Value = map_json(&scene, &dir.join(format!("{name}.json")));
    let traced = map["traced"].clone();
    assert!(
        traced["polished"].is_object(),
        "{name}: {}",
        traced["not_polished"]
    );
    traced
}

/// Two polished boundaries of one island agree: their areas within the
/// summed error bars (below 1e-4 relative, and far from the first discrete
/// loop's area), their corners likewise.
fn assert_same_island(a: &serde_json::Value, b: &serde_json::Value, corners: usize) {
    let f = |t: &serde_json::Value, k: &str| t["polished"][k].as_f64().unwrap();
    let (area_a, area_b) = (f(a, "area"), f(b, "area"));
    let bar = f(a, "area_error") + f(b, "area_error");
    assert!(
        (area_a - area_b).abs() <= bar,
        "polished areas {area_a} and {area_b} differ by more than {bar:.2e}"
    );
    assert!(bar < 1e-4 * area_a, "error bar {bar:.2e} of {area_a}");
    // the discrete loops are several percent (rod) or a third of a percent
    // (strip) off at N = 100
    let discrete = a["area"].as_f64().unwrap();
    assert!((area_a - discrete).abs() > 5.0 * bar);
    let corners_of = |t: &serde_json::Value| t["polished"]["corners"].as_array().unwrap().clone();
    let (ca, cb) = (corners_of(a), corners_of(b));
    assert_eq!(ca.len(), corners);
    assert_eq!(ca.len(), cb.len());
    for (x, y) in ca.iter().zip(&cb) {
        assert_eq!(x["between"], y["between"]);
        let bar = x["error"].as_f64().unwrap() + y["error"].as_f64().unwrap();
        for k in 0..2 {
            let (p, q) = (
                x["point"][k].as_f64().unwrap(),
                y["point"][k].as_f64().unwrap(),
            );
            // beside the bars, each corner's secant stops within its
            // resolution, 1e-8 of the coordinate
            let resolution = 2.0 * 1e-8 * (1.0 + p.abs());
            assert!(
                (p - q).abs() <= bar + resolution,
                "corner {}: {p} against {q} (bars {bar:.1e})",
                x["between"]
            );
        }
    }
}

/// The rod island's boundary polished on the continuum: started from the
/// discrete walks at N = 100 and N = 140, which differ by the
/// discretisation, its area and corners agree within their stated errors,
/// and its area lies well away from the discrete loop's (the rod's O(1/N²)
/// error).
#[test]
fn polished_island_is_the_same_from_two_discretisations() {
    let dir = temp_dir("polish-map");
    let scene = "scenes/fig7_island_kirchhoff.toml";
    let polished = |n: &str| {
        polished_boundary(
            scene,
            &dir,
            &format!("polish{n}"),
            &[
                ("segments = 100", &format!("segments = {n}")),
                ("lines = 27", "lines = 2"),
                ("grid_columns = 91", "grid_columns = 11"),
            ],
        )
    };
    let (a, b) = (polished("100"), polished("140"));
    assert_same_island(&a, &b, 3);
    let discrete = a["area"].as_f64().unwrap();
    let area = a["polished"]["area"].as_f64().unwrap();
    assert!(
        (area - discrete).abs() > 0.05 * area,
        "{area} against the discrete {discrete}"
    );
}

/// The strip island's boundary polished from two walks, one at half the
/// other's step: the same area and corners within their bars. Its corner
/// X1/X2 is where the two crossings of the same strands run into one (their
/// closest points merge): the walk ends X1 late there, and the corner lies
/// 3e-3 in φ/2π below the walk's.
#[test]
fn polished_strip_island_is_the_same_from_two_walks() {
    let dir = temp_dir("polish-strip");
    let scene = "scenes/fig7_island_strip.toml";
    let polished = |name: &str, step: &str| {
        polished_boundary(
            scene,
            &dir,
            name,
            &[
                ("lines = 37", "lines = 2"),
                ("grid_columns = 111", "grid_columns = 11"),
                (
                    "polish = true",
                    &format!("polish = true\ntrace_step = {step}"),
                ),
            ],
        )
    };
    let (a, b) = (polished("step", "0.005"), polished("half", "0.0025"));
    assert_same_island(&a, &b, 3);
    let corner = &a["polished"]["corners"][1];
    assert_eq!(corner["between"][0], "X1");
    let (continuum, discrete) = (
        corner["point"][1].as_f64().unwrap(),
        corner["discrete"][1].as_f64().unwrap(),
    );
    assert!(
        discrete - continuum > 1e-3,
        "X1/X2 at φ/2π {continuum}, the walk's {discrete}"
    );
}

/// Several maps on one plane (Figure 10-right's style): the first's island
/// as a region, the others' as curves, each named, a knot marked; a map
/// without a closed boundary, a file that is no map, and names that do not
/// match the maps are refused.
#[test]
fn several_maps_are_drawn_on_one_plane() {
    let dir = temp_dir("overlay");
    let scene = fig7_variant(
        &dir,
        "traced.toml",
        &[
            ("segments = 100", "segments = 40"),
            ("lines = 27", "lines = 3"),
            ("grid_columns = 91", "grid_columns = 11"),
            ("polish = true", "polish = false"),
        ],
    );
    let s = scene.to_str().unwrap();
    let traced = dir.join("traced.json");
    knotrod_ok(&["map", s, "--json", traced.to_str().unwrap()]);
    let open = small_map_scene(&dir);
    let untraced = dir.join("untraced.json");
    knotrod_ok(&[
        "map",
        open.to_str().unwrap(),
        "--json",
        untraced.to_str().unwrap(),
    ]);
    let t = traced.to_str().unwrap();
    let over = dir.join("over");
    knotrod_ok(&[
        "plot",
        t,
        t,
        "--name",
        "the region",
        "--name",
        "the curve",
        "--mark",
        "a knot=0.15,0.8",
        "--out",
        over.to_str().unwrap(),
    ]);
    let svg = std::fs::read_to_string(over.with_extension("svg")).unwrap();
    for text in ["the region", "the curve", "a knot"] {
        assert!(svg.contains(text), "{text} not in the overlay");
    }
    let refused = |args: &[&str], why: &str| {
        let e = knotrod(args);
        let err = String::from_utf8_lossy(&e.stderr);
        assert!(!e.status.success() && err.contains(why), "{args:?}: {err}");
    };
    let o = over.to_str().unwrap();
    refused(
        &["plot", t, untraced.to_str().unwrap(), "--out", o],
        "no closed boundary",
    );
    refused(&["plot", t, s, "--out", o], "map files");
    refused(&["plot", t, t, "--name", "one", "--out", o], "--name");
    refused(&["plot", t, t, "--mark", "k=nan,0.8", "--out", o], "--mark");
    // one map with the overlay's options is drawn by them, not without them
    refused(&["plot", t, "--mark", "k=nan,0.8", "--out", o], "--mark");
    let single = dir.join("single");
    knotrod_ok(&[
        "plot",
        t,
        "--mark",
        "a knot=0.15,0.8",
        "--out",
        single.to_str().unwrap(),
    ]);
    let svg = std::fs::read_to_string(single.with_extension("svg")).unwrap();
    assert!(
        svg.contains("a knot"),
        "the mark not in the single map's plot"
    );
}
