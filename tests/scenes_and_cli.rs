//! Scene validation (errors name the field, never a panic) and the command line.

use knotrod::scene::{Scene, SceneError};

use crate::common;
use common::{knotrod, temp_dir};

const GOOD: &str = r#"
[model]
K2 = 3.0
K3 = 3.0
segments = 40
[clamps]
z_star = 0.9
delta = 0.05
phi_over_2pi = 0.3
"#;

/// A map over the GOOD scene, its settings open for more lines.
const MAP: &str = "\n[continuation]\nparameter = \"phi\"\nrange = [0.2, 0.4]\n\n[map]\nrange = [0.8, 0.9]\nlines = 2\n";

fn error_of(text: &str) -> String {
    match Scene::parse(text) {
        Ok(_) => panic!("scene accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn good_scene_parses() {
    let s = Scene::parse(GOOD).unwrap();
    // the map the bad-field cases extend is itself valid
    Scene::parse(&format!("{GOOD}{MAP}")).unwrap();
    assert_eq!(s.model.segments, 40);
    assert!((s.clamps().phi - 0.6 * std::f64::consts::PI).abs() < 1e-15);
}

#[test]
fn bad_scenes_name_the_field() {
    let cases = [
        (GOOD.replace("K2 = 3.0", "K2 = 3.0\nbogus = 1"), "bogus"),
        (
            GOOD.replace("segments = 40", "segments = -5"),
            "model.segments",
        ),
        (
            GOOD.replace("segments = 40", "segments = 2"),
            "model.segments",
        ),
        (GOOD.replace("K2 = 3.0", "K2 = 0.0"), "model.K2"),
        (GOOD.replace("K3 = 3.0", "K3 = -1.0"), "model.K3"),
        (
            GOOD.replace("z_star = 0.9", "z_star = 1.5"),
            "clamps.z_star",
        ),
        (
            GOOD.replace("z_star = 0.9", "z_star = nan"),
            "clamps.z_star",
        ),
        (GOOD.replace("delta = 0.05", "delta = 0.6"), "clamps.delta"),
        (
            GOOD.replace("phi_over_2pi = 0.3", "phi_over_2pi = inf"),
            "clamps.phi_over_2pi",
        ),
        (GOOD.replace("z_star = 0.9", "z_star = \"high\""), "z_star"),
        (
            format!("{GOOD}\n[initial]\nshape = \"shooting\"\nn0 = [1.0, 2.0, 3.0]\n"),
            "initial.m0",
        ),
        (format!("{GOOD}\n[initial]\nshape = \"spiral\"\n"), "spiral"),
        (
            format!("{GOOD}\n[solver]\ngradient_tol = -1.0\n"),
            "solver.gradient_tol",
        ),
        (format!("{GOOD}{MAP}trace_step = 0.0\n"), "map.trace_step"),
        (
            format!("{GOOD}{MAP}trace_from = [0.1, nan]\n"),
            "map.trace_from",
        ),
        // issue 17's reproductions: extra vector entries, unchecked sweeps,
        // legs and maps, meaningless settings
        (
            format!(
                "{GOOD}\n[initial]\nshape = \"shooting\"\nn0 = [-24.743, 17.772, 37.145, 999.0]\nm0 = [1.0, 2.0, 3.0]\n"
            ),
            "exactly 3 numbers",
        ),
        (
            format!("{GOOD}\n[continuation]\nparameter = \"phi\"\nrange = [0.25, 0.35, 123.0]\n"),
            "exactly 2 numbers",
        ),
        (
            format!("{GOOD}\n[reference]\nn0 = [1.0, 2.0]\n"),
            "exactly 3 numbers",
        ),
        (
            format!("{GOOD}\n[reference]\nn0 = [1.0, nan, 2.0]\n"),
            "reference.n0",
        ),
        (
            format!("{GOOD}\n[reference]\ntwist = inf\n"),
            "reference.twist",
        ),
        (
            format!("{GOOD}{MAP}\n[sweep]\nparameter = \"delta\"\nvalues = [0.05, -0.5]\n")
                .replace("[map]\nrange = [0.8, 0.9]\nlines = 2\n", ""),
            "sweep.values",
        ),
        (
            format!(
                "{GOOD}\n[continuation]\nparameter = \"phi\"\nrange = [0.2, 0.4]\n[sweep]\nparameter = \"z_star\"\nvalues = [2.0]\n"
            ),
            "sweep.values",
        ),
        (
            format!(
                "{GOOD}\n[[loading]]\nz_star = 0.99\nsteps = 5\n[[loading]]\ndelta = 0.5\nsteps = 5\n"
            ),
            "loading.delta",
        ),
        (
            GOOD.replace("z_star = 0.9", "z_star = 0.2")
                + &MAP.replace("range = [0.8, 0.9]", "range = [0.30, 0.04]"),
            "map.range",
        ),
        (
            format!("{GOOD}{MAP}grid_columns = 1000000000000\n"),
            "map.grid_columns",
        ),
        (
            format!("{GOOD}\n[diagnostics]\nray_length = 1e308\n"),
            "diagnostics.ray_length",
        ),
        (
            format!("{GOOD}\n[initial]\nshape = \"double_ring\"\nsteps = 10000000\n"),
            "initial.steps",
        ),
        (GOOD.replace("K2 = 3.0", "K2 = 1e308"), "model.K2"),
        (
            GOOD.replace("K2 = 3.0", "K2 = 3.0\nstretching_stiffness = 1e308"),
            "model.stretching_stiffness",
        ),
        (
            GOOD.replace("K2 = 3.0", "K2 = 3.0\nrod_diameter = 1e-200"),
            "model.rod_diameter",
        ),
        (
            format!("{GOOD}\n[initial]\nbump = [0.0, nan, 0.0]\n"),
            "initial.bump",
        ),
        (
            format!("{GOOD}\n[diagnostics]\nknot = \"12a_1\"\n"),
            "diagnostics.knot",
        ),
        (
            format!("{GOOD}\n[diagnostics]\nknot = \"0_1\"\n"),
            "diagnostics.knot",
        ),
        (
            format!("{GOOD}\n[diagnostics]\nclearance = \"touching\"\n"),
            "clearance",
        ),
        (
            format!("{GOOD}{MAP}\n[diagnostics]\nclearance = \"diameter\"\n"),
            "diagnostics.clearance",
        ),
    ];
    // a 200 KB line is not echoed whole
    let long = format!("{GOOD}\nname = \"{}\n", "x".repeat(200_000));
    let msg = error_of(&long);
    assert!(
        msg.len() < 1000 && msg.contains("line"),
        "{} bytes",
        msg.len()
    );
    // a tabled knot or a sum of them is accepted
    let sum = Scene::parse(&format!("{GOOD}\n[diagnostics]\nknot = \"3_1#4_1\"\n")).unwrap();
    assert_eq!(sum.good_knot().alexander, vec![-1, 4, -5, 4, -1]);
    for (text, field) in cases {
        let msg = error_of(&text);
        assert!(
            msg.contains(field),
            "error for `{field}` does not name it: {msg}"
        );
    }
    assert!(matches!(
        Scene::parse("[model"),
        Err(SceneError::Parse { .. })
    ));
}

#[test]
fn outputs_stay_where_they_belong() {
    // a scene's name cannot lead its files out of recordings/
    for (name, stem) in [
        ("../x", "_x"),
        ("/tmp/evil", "_tmp_evil"),
        ("fig 3", "fig_3"),
        ("..", "run"),
    ] {
        let s = Scene::parse(&format!("name = \"{name}\"\n{GOOD}")).unwrap();
        assert_eq!(s.file_stem("run"), stem, "{name}");
    }
    // the summary never overwrites its own stream, nor is it a folder: both
    // refused before any work
    let dir = temp_dir("outputs");
    for json in [dir.join("run.jsonl"), dir.clone()] {
        let out = knotrod(&[
            "run",
            "scenes/appendix_d.toml",
            "--json",
            json.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains("--json"), "{err}");
        assert!(
            !String::from_utf8_lossy(&out.stdout).contains("equilibria"),
            "the work ran"
        );
    }
    assert!(
        std::fs::read_dir(&dir).unwrap().next().is_none(),
        "stray files left"
    );
}

#[test]
fn run_writes_summary_and_restarts_from_it() {
    let dir = temp_dir("cli");
    let first = dir.join("first.json");
    let out = knotrod(&[
        "run",
        "scenes/appendix_d.toml",
        "--segments",
        "60",
        "--json",
        first.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("walled") && stdout.contains("stable"),
        "{stdout}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&first).unwrap()).unwrap();
    for key in ["scene", "model", "segments", "equilibria", "events"] {
        assert!(summary.get(key).is_some(), "summary lacks {key}");
    }
    let eq = &summary["equilibria"][0];
    for key in [
        "z_star",
        "delta",
        "phi_over_2pi",
        "converged",
        "gradient_norm",
        "iterations",
        "energy",
        "n0",
        "m0",
        "twist",
        "min_z",
        "max_z",
        "walled",
        "lowest_eigenvalues",
        "omega_squared",
        "negative_eigenvalues",
        "stable",
    ] {
        assert!(eq.get(key).is_some(), "equilibrium lacks {key}");
    }
    // restart from the recorded state: already in equilibrium
    let scene = dir.join("restart.toml");
    std::fs::write(
        &scene,
        format!(
            "[model]\nsegments = 60\n[clamps]\nz_star = 0.115\ndelta = 0.05\nphi_over_2pi = 0.802\n[initial]\nshape = \"file\"\nfile = {:?}\n",
            first.to_str().unwrap()
        ),
    )
    .unwrap();
    let second = dir.join("second.json");
    let out = knotrod(&[
        "run",
        scene.to_str().unwrap(),
        "--json",
        second.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let again: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&second).unwrap()).unwrap();
    let eq2 = &again["equilibria"][0];
    assert!(eq2["iterations"].as_u64().unwrap() <= 1);
    let (e1, e2) = (
        eq["energy"].as_f64().unwrap(),
        eq2["energy"].as_f64().unwrap(),
    );
    assert!((e1 - e2).abs() < 1e-10 * e1);
}

#[test]
fn bad_input_is_a_clear_error_not_a_panic() {
    let dir = temp_dir("bad");
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, GOOD.replace("segments = 40", "segments = -5")).unwrap();
    let out = knotrod(&["run", bad.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("model.segments") && !err.contains("panicked"),
        "{err}"
    );
    let out = knotrod(&["run", "does/not/exist.toml"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot read scene"));
    // a Newton that cannot converge in its budget says so
    let hard = dir.join("hard.toml");
    std::fs::write(
        &hard,
        format!("{GOOD}\n[solver]\nmax_iterations = 1\n").replace("z_star = 0.9", "z_star = 0.3"),
    )
    .unwrap();
    let out = knotrod(&["run", hard.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("Newton") && !err.contains("panicked"), "{err}");
}

fn write_curve(path: &std::path::Path, sep: &str, f: impl Fn(f64) -> [f64; 3], m: usize) {
    let mut text = String::from("# test curve\n");
    for k in 0..m {
        let p = f(2.0 * std::f64::consts::PI * k as f64 / m as f64);
        text += &format!("{}{sep}{}{sep}{}\n", p[0], p[1], p[2]);
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn knot_command_names_small_knots() {
    let dir = temp_dir("knot");
    let torus = |p: f64, q: f64| {
        move |t: f64| {
            [
                (2.0 + (q * t).cos()) * (p * t).cos(),
                (2.0 + (q * t).cos()) * (p * t).sin(),
                (q * t).sin(),
            ]
        }
    };
    let eight = |t: f64| {
        [
            (2.0 + (2.0 * t).cos()) * (3.0 * t).cos(),
            (2.0 + (2.0 * t).cos()) * (3.0 * t).sin(),
            (4.0 * t).sin(),
        ]
    };
    type Case = (
        &'static str,
        Box<dyn Fn(f64) -> [f64; 3]>,
        u64,
        &'static str,
    );
    let cases: [Case; 3] = [
        ("t23.csv", Box::new(torus(2.0, 3.0)), 3, "3_1"),
        ("t25.txt", Box::new(torus(2.0, 5.0)), 5, "5_1"),
        ("eight.xyz", Box::new(eight), 5, "4_1"),
    ];
    for (name, f, det, knot) in cases {
        let path = dir.join(name);
        write_curve(
            &path,
            if name.ends_with(".csv") { "," } else { " " },
            f,
            400,
        );
        let out = knotrod(&["knot", path.to_str().unwrap(), "--closed", "--json", "-"]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["knot_determinant"].as_u64(), Some(det), "{name}: {v}");
        assert!(
            v["knot_name"].as_str().unwrap().starts_with(knot),
            "{name}: {v}"
        );
        let names = v["knot_names"].as_array().unwrap();
        assert!(names.iter().any(|n| n == knot), "{name}: {v}");
    }
    // an open arc of the trefoil closed by rays along ±z is still a trefoil
    let arc = dir.join("open.txt");
    let mut text = String::new();
    for k in 0..=300 {
        let t = 0.2 + (2.0 * std::f64::consts::PI - 0.4) * k as f64 / 300.0;
        let p = torus(2.0, 3.0)(t);
        text += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    std::fs::write(&arc, text).unwrap();
    let out = knotrod(&["knot", arc.to_str().unwrap(), "--json", "-"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["knot_determinant"].as_u64(), Some(3), "{v}");
    // malformed input: a clear error naming the line
    let bad = dir.join("bad.txt");
    std::fs::write(&bad, "0 0 0\n1 1\n2 2 2\n").unwrap();
    let out = knotrod(&["knot", bad.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("line 2") && !err.contains("panicked"), "{err}");
}

#[test]
fn every_shipped_scene_passes_validation() {
    let mut count = 0;
    for entry in std::fs::read_dir("scenes").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            Scene::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            count += 1;
        }
    }
    assert!(count >= 13, "{count} scenes");
}

#[test]
fn bad_general_clamps_and_model_parameters_name_the_field() {
    let clamps = |extra: &str| {
        GOOD.replace(
            "phi_over_2pi = 0.3\n",
            &format!("phi_over_2pi = 0.3\n{extra}\n"),
        )
    };
    let branch = |p: &str, range: &str| {
        format!("{GOOD}\n[continuation]\nparameter = \"{p}\"\nrange = {range}\n")
    };
    let cases = [
        (
            clamps("end_rotation = { quaternion = [1.0, 1.0, 0.0, 0.0] }"),
            "clamps.end_rotation",
        ),
        (
            clamps("end_rotation = { axis_angle = [0.0, 0.0, 0.0, 1.0] }"),
            "clamps.end_rotation",
        ),
        (
            clamps("end_rotation = { euler_zyx = [nan, 0.0, 0.0] }"),
            "clamps.end_rotation",
        ),
        (
            clamps("end_rotation = { quaternion = [1.0, 0.0, 0.0] }"),
            "quaternion",
        ),
        (clamps("end_tilt = inf"), "clamps.end_tilt"),
        (clamps("end_tilt_azimuth = nan"), "clamps.end_tilt_azimuth"),
        (clamps("end_shift = [0.5, nan]"), "clamps.end_shift"),
        // the clamps farther apart than the rod is long
        (clamps("end_shift = [0.9, 0.0]"), "clamps.z_star"),
        (
            clamps("[clamps.start]\nposition = [0.0, 0.0, inf]"),
            "clamps.start.position",
        ),
        (
            clamps("[clamps.start]\nturn_over_2pi = nan"),
            "clamps.start.turn_over_2pi",
        ),
        (
            clamps("[clamps.start]\nrotation = { quaternion = [2.0, 0.0, 0.0, 0.0] }"),
            "clamps.start.rotation",
        ),
        (branch("K3", "[0.0, 4.0]"), "continuation.range"),
        (branch("weight", "[-1e9, 1.0]"), "continuation.range"),
        (
            branch("K2", "[1.0, 4.0]").replace("[model]\n", "[model]\nkind = \"strip\"\n"),
            "continuation.parameter",
        ),
        (
            format!("{GOOD}\n[[loading]]\ntargets = {{ end_tilt = nan }}\nsteps = 3\n"),
            "loading.targets",
        ),
        (
            format!("{GOOD}\n[[loading]]\ntargets = {{ bogus = 1.0 }}\nsteps = 3\n"),
            "bogus",
        ),
    ];
    for (text, field) in cases {
        let msg = error_of(&text);
        assert!(
            msg.contains(field),
            "error for `{field}` does not name it: {msg}"
        );
    }
}

/// Issue 31, item 11: two refusals of a strip's clamps carried 18 spaces (a
/// literal broken over lines without its `\`); every refusal reads as prose
/// (the fuzz targets check the same on every refused scene).
#[test]
fn refusals_of_a_strip_s_start_clamp_read_without_runs_of_spaces() {
    let strip = "[model]\nkind = \"strip\"\nsegments = 40\n[clamps]\nz_star = 0.215\n\
                 delta = 0.05\nphi_over_2pi = 0.94\n";
    let start = "[clamps.start]\nposition = [0.0, 0.0, 0.1]\n";
    for (text, field) in [
        (
            strip.replace("segments = 40", "segments = 40\nstrip_width = 0.01") + start,
            "model.strip_width",
        ),
        (
            format!(
                "{strip}{start}[initial]\nshape = \"shooting\"\nn0 = [0.0, 0.0, 1.0]\nu1_0 = 1.0\nm2_0 = 0.0\nu3_0 = 0.0\n"
            ),
            "clamps.start",
        ),
    ] {
        let e = error_of(&text);
        assert!(e.contains(field), "{e}");
        knotrod::io::fuzz::one_spaced(&e);
    }
}
