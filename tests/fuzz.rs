//! A short seeded run of the fuzz targets (`knotrod::io::fuzz`, shared with
//! the cargo-fuzz targets in fuzz/): mutated scenes, curves, point clouds and
//! recordings must give an answer or an error, never a panic. The seed is
//! fixed so that a failure reproduces; the long runs are cargo fuzz's.

use crate::common;

use common::{knotrod, temp_dir};
use knotrod::io::fuzz;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestRunner};

/// A seeded runner of `cases` cases.
fn runner(cases: u32, seed: u64) -> TestRunner {
    TestRunner::new(Config {
        cases,
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        ..Config::default()
    })
}

/// Tokens a hostile scene is made of: extreme numbers, brackets, keys and
/// sections.
const TOKENS: &[&str] = &[
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-inf",
    "0",
    "-0.0",
    "1e-300",
    "1000000000000",
    "-5",
    "4",
    "[",
    "]",
    "[1.0, 2.0, 3.0, 4.0]",
    "[0.3, 0.04]",
    "\"",
    "=",
    ",",
    "\n",
    "\n[map]\nrange = [0.1, 0.2]\nlines = 100000\n",
    "\n[sweep]\nparameter = \"delta\"\nvalues = [0.5, -0.5]\n",
    "\n[[loading]]\nz_star = 2.0\nsteps = 3\n",
    "\n[budget]\nmemory_gb = 1e-9\n",
    "segments = 1000000",
    "shape = \"double_ring\"",
    "steps = 10000000",
    "name = \"../x\"",
    "knot = \"0_1\"",
];

/// A shipped scene with `edits` (position fraction, token) applied.
fn mutate(text: &str, edits: &[(f64, usize, bool)]) -> String {
    let mut t = text.to_string();
    for &(at, token, replace) in edits {
        let mut k = ((t.len() as f64) * at) as usize;
        while k < t.len() && !t.is_char_boundary(k) {
            k += 1;
        }
        let k = k.min(t.len());
        let token = TOKENS[token % TOKENS.len()];
        if replace {
            // replace the word at k
            let end = t[k..]
                .find(|c: char| c.is_whitespace() || c == ',' || c == ']')
                .map_or(t.len(), |e| k + e);
            t.replace_range(k..end, token);
        } else {
            t.insert_str(k, token);
        }
    }
    t
}

#[test]
fn mutated_scenes_are_parsed_or_refused() {
    // the scene files (scenes/verify holds files of solutions)
    let scenes: Vec<String> = std::fs::read_dir("scenes")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    let edits = prop::collection::vec((0.0..1.0f64, 0..TOKENS.len(), any::<bool>()), 1..6);
    runner(400, 17)
        .run(&(0..scenes.len(), edits), |(k, e)| {
            fuzz::scene_text(mutate(&scenes[k], &e).as_bytes());
            Ok(())
        })
        .unwrap();
    runner(200, 18)
        .run(&prop::collection::vec(any::<u8>(), 0..400), |b| {
            fuzz::scene_text(&b);
            Ok(())
        })
        .unwrap();
}

#[test]
fn curve_files_and_point_clouds_are_read_or_refused() {
    let number = prop_oneof![
        (-10.0..10.0f64).prop_map(|v| format!("{v}")),
        Just("nan".to_string()),
        Just("1e308".to_string()),
        Just("x".to_string()),
        Just("".to_string()),
    ];
    let line = prop::collection::vec(number, 0..5).prop_map(|v| v.join(" "));
    runner(300, 19)
        .run(&prop::collection::vec(line, 0..60), |lines| {
            fuzz::curve_text(lines.join("\n").as_bytes());
            Ok(())
        })
        .unwrap();
    // raw points: coincident, collinear and crossing at will; a knot type
    // found is a knot's (odd determinant)
    runner(150, 20)
        .run(&prop::collection::vec(any::<u8>(), 0..1800), |b| {
            fuzz::knot_points(&b);
            Ok(())
        })
        .unwrap();
    // few distinct values: many degenerate projections
    let small = prop::collection::vec(prop_oneof![Just(0u8), Just(1u8), Just(255u8)], 0..600);
    runner(150, 21)
        .run(&small, |b| {
            fuzz::knot_points(&b);
            Ok(())
        })
        .unwrap();
}

#[test]
fn damaged_recordings_are_read_or_refused() {
    let dir = temp_dir("fuzz-rec");
    let scene = dir.join("short.toml");
    let text = std::fs::read_to_string("scenes/fig3_kirchhoff.toml").unwrap();
    let text =
        text.split("[output]").next().unwrap().to_string() + "\n" + "# short: a few points\n";
    let text = text
        .replace("segments = 200", "segments = 20")
        .replace("[continuation]", "[continuation]\nmax_points = 3");
    std::fs::write(&scene, text).unwrap();
    let rec = dir.join("run.mcap");
    let out = knotrod(&[
        "run",
        scene.to_str().unwrap(),
        "--record",
        rec.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let good = std::fs::read(&rec).unwrap();
    // the undamaged recording reads back
    knotrod::io::recording::parse_recording(&rec, &good).unwrap();
    let len = good.len();
    let damage = (0..len, any::<u8>(), 0..4u8, 1..2000usize);
    runner(300, 22)
        .run(&damage, |(at, byte, how, span)| {
            let mut b = good.clone();
            match how {
                0 => b[at] ^= 1 << (byte % 8),
                1 => b[at..(at + span).min(len)].fill(0),
                2 => b.truncate(at),
                _ => b[at..(at + span).min(len)].fill(byte),
            }
            fuzz::recording_bytes(&b);
            Ok(())
        })
        .unwrap();
}

#[test]
fn inputs_the_long_fuzz_runs_found_are_answered() {
    // 84 points whose diagram keeps 489 crossings: refused as too tangled
    // (was 6.5 s of polynomial arithmetic, a libFuzzer timeout)
    let b = std::fs::read("tests/fixtures/fuzz/knot_points_489_crossings").unwrap();
    fuzz::knot_points(&b);
    assert!(matches!(
        knotrod::geometry::knot::knot_type(&fuzz::points_of(&b)),
        Err(knotrod::geometry::knot::KnotError::TooManyCrossings(489))
    ));
    // 88 bytes whose record declares a 2.9 GB string: an error, no allocation
    let b = std::fs::read("tests/fixtures/fuzz/recording_declares_2_9_gb_string").unwrap();
    fuzz::recording_bytes(&b);
    assert!(knotrod::io::recording::parse_recording(std::path::Path::new("x"), &b).is_err());
}
