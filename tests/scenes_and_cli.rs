//! Scene validation (errors name the field, never a panic) and the command line.

use knotrod::scene::{Scene, SceneError};
use std::process::Command;

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

fn error_of(text: &str) -> String {
    match Scene::parse(text) {
        Ok(_) => panic!("scene accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn good_scene_parses() {
    let s = Scene::parse(GOOD).unwrap();
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
    ];
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

fn knotrod(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_knotrod"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn run_writes_summary_and_restarts_from_it() {
    let dir = std::env::temp_dir().join(format!("knotrod-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
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
    let dir = std::env::temp_dir().join(format!("knotrod-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
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
