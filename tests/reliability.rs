//! The reliability issue's reproductions that are about size and time: a
//! budget refuses what would run for hours or fill the memory, long solves
//! show progress, non-finite starts name their input, files are read only
//! up to a limit.

use crate::common;

use common::{knotrod, temp_dir};
use knotrod::scene::{Job, Scene, SceneError};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const SMALL: &str =
    "[model]\nsegments = 100\n[clamps]\nz_star = 0.115\ndelta = 0.05\nphi_over_2pi = 0.802\n";

fn write(dir: &std::path::Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn a_million_segments_is_refused_with_its_estimate_unless_allowed() {
    let scene = Scene::parse(&SMALL.replace("segments = 100", "segments = 1000000")).unwrap();
    let e = scene.check_budget(Job::Run, None, false).unwrap_err();
    let SceneError::TooLarge { what, key, .. } = &e else {
        panic!("{e}")
    };
    assert_eq!((*what, *key), ("memory", "budget.memory_gb"));
    assert!(e.to_string().contains("--allow-large"), "{e}");
    // asked for: the estimate passes, and a raised budget does too
    assert!(scene.check_budget(Job::Run, None, true).is_ok());
    let raised = Scene::parse(&format!(
        "{}\n[budget]\nmemory_gb = 20\nhours = 100\n",
        SMALL.replace("segments = 100", "segments = 1000000")
    ))
    .unwrap();
    assert!(raised.check_budget(Job::Run, None, false).is_ok());
    // the command refuses it at once, before any work
    let dir = temp_dir("budget");
    let path = write(
        &dir,
        "big.toml",
        &SMALL.replace("segments = 100", "segments = 1000000"),
    );
    let t = Instant::now();
    let out = knotrod(&["run", &path, "--no-record"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("budget.memory_gb"),
        "{err}"
    );
    assert!(t.elapsed() < Duration::from_secs(20));
    // and so does --segments past the scene's own N
    let small = write(&dir, "small.toml", SMALL);
    let out = knotrod(&["run", &small, "--no-record", "--segments", "1000000"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("budget.memory_gb"));
}

#[test]
fn a_map_of_a_hundred_thousand_lines_is_refused_with_its_time() {
    let text = std::fs::read_to_string("scenes/fig7_island_kirchhoff.toml")
        .unwrap()
        .replace("lines = 27", "lines = 100000");
    let scene = Scene::parse(&text).unwrap();
    let e = scene.check_budget(Job::Map, None, false).unwrap_err();
    assert!(
        matches!(
            &e,
            SceneError::TooLarge {
                key: "budget.hours",
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("map.lines"), "{e}");
    let dir = temp_dir("budget-map");
    let path = write(&dir, "lines.toml", &text);
    let out = knotrod(&["map", &path]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("budget.hours"),
        "{err}"
    );
}

#[test]
fn every_shipped_scene_is_within_the_default_budget() {
    for entry in std::fs::read_dir("scenes").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let scene = Scene::load(&path).unwrap();
        scene
            .check_budget(Job::Run, None, false)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        if scene.map.is_some() {
            scene
                .check_budget(Job::Map, None, false)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        }
    }
}

/// The first line a run of `scene` prints on its standard error (a pipe:
/// its progress as plain lines), and how long it took to come; the run is
/// then stopped.
fn first_progress_line(scene: &str) -> (String, Duration) {
    let t = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_knotrod"))
        .args(["run", scene, "--no-record"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stderr.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    let waited = t.elapsed();
    let _ = child.kill();
    let _ = child.wait();
    (first, waited)
}

/// The solver iterations a progress line reports ("… 123 Newton iterations …").
fn iterations_in(line: &str) -> usize {
    let before = line
        .split(" Newton iterations")
        .next()
        .unwrap_or_else(|| panic!("no iterations in {line:?}"));
    before
        .rsplit(' ')
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no count in {line:?}"))
}

#[test]
fn a_long_solve_prints_progress_within_seconds() {
    // a stiff rod at N = 2000: a thousand slow Newton iterations
    let dir = temp_dir("progress");
    let path = write(
        &dir,
        "stiff.toml",
        &SMALL.replace("segments = 100", "segments = 2000\nrod_diameter = 1e-5"),
    );
    let (first, waited) = first_progress_line(&path);
    assert!(iterations_in(&first) > 0, "{first}");
    // due at 1 s; the bound leaves room for a loaded machine
    assert!(waited < Duration::from_secs(15), "{waited:?}");
}

#[test]
fn the_heartbeat_counts_the_contact_solver_too() {
    // the trefoil relaxed onto the rays: a second of SQP with contact before
    // the first equilibrium (its iterations were not counted before)
    let (first, _) = first_progress_line("scenes/trefoil_contact_start.toml");
    assert!(iterations_in(&first) > 0, "{first}");
}

#[test]
fn non_finite_starts_name_their_input() {
    let dir = temp_dir("non-finite");
    let shooting = write(
        &dir,
        "shoot.toml",
        &format!(
            "{SMALL}[initial]\nshape = \"shooting\"\nn0 = [1e200, 0, 0]\nm0 = [1e200, 1, 0]\n"
        ),
    );
    let out = knotrod(&["run", &shooting, "--no-record"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("initial.n0"), "{err}");
    let bump = write(
        &dir,
        "bump.toml",
        &format!("{SMALL}[initial]\nbump = [1e150, 0, 0]\n"),
    );
    let out = knotrod(&["run", &bump, "--no-record"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("initial.bump"),
        "{err}"
    );
}

#[test]
fn endless_files_are_refused_not_read() {
    // a device has no size to check: the read itself stops at the limit
    let out = knotrod(&["run", "/dev/zero"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("the most read is"),
        "{err}"
    );
}

#[test]
fn bad_values_of_the_new_settings_name_their_field() {
    for (extra, field) in [
        ("[budget]\nmemory_gb = -1.0\n", "budget.memory_gb"),
        ("[budget]\nhours = nan\n", "budget.hours"),
        ("[load]\nweight = 1e9\n", "load.weight"),
        (
            "[load]\nweight = 1.0\ndirection = [0.0, 0.0, 0.0]\n",
            "load.direction",
        ),
        ("[load]\ndirection = [0.0, 1.0]\n", "direction"),
    ] {
        let e = Scene::parse(&format!("{SMALL}{extra}")).unwrap_err();
        assert!(e.to_string().contains(field), "{extra}: {e}");
    }
    for (model, field) in [
        ("natural_strains = [1e4, 0.0, 0.0]", "model.natural_strains"),
        ("natural_strains = [1.0, 0.0]", "natural_strains"),
        (
            "kind = \"strip\"\nnatural_strains = [1.0, 0.0, 0.5]",
            "model.natural_strains",
        ),
        (
            "kind = \"unbendable\"\nnatural_strains = [0.0, 1.0, 0.0]",
            "model.natural_strains",
        ),
    ] {
        let text = SMALL.replace("segments = 100", &format!("segments = 100\n{model}"));
        let e = Scene::parse(&text).unwrap_err();
        assert!(e.to_string().contains(field), "{model}: {e}");
    }
}
