//! Recordings: MCAP written by every run, readable by the mcap crate with
//! Foxglove's exact schemas, restartable, finalised on Ctrl-C, and read back
//! with clear errors when damaged.

use knotrod::analysis::event::EventKind;
use knotrod::io::recording::{
    SCALARS_TOPIC, SCENE_TOPIC, STATE_TOPIC, TF_TOPIC, read_recording, read_state,
};
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;
use common::{knotrod, temp_dir};

/// Run a scene recording to `rec`; the recording's bytes.
fn run_recorded(scene: &Path, rec: &Path) -> Vec<u8> {
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
    std::fs::read(rec).unwrap()
}

/// A short branch of the Figure 3 problem at N = 40.
fn short_branch_scene(dir: &Path, extra: &str) -> PathBuf {
    let text = std::fs::read_to_string("scenes/appendix_d.toml")
        .unwrap()
        .replace("segments = 200", "segments = 40");
    let text = text.split("[reference]").next().unwrap().to_string();
    let scene = dir.join("branch.toml");
    std::fs::write(
        &scene,
        format!("{text}\n[continuation]\nparameter = \"phi\"\nrange = [0.78, 0.84]\ndirection = \"up\"\n{extra}"),
    )
    .unwrap();
    scene
}

#[test]
fn recording_has_foxglove_schemas_and_every_message_decodes() {
    let dir = temp_dir("rec-schemas");
    let scene = short_branch_scene(&dir, "");
    let rec = dir.join("run.mcap");
    let bytes = run_recorded(&scene, &rec);
    let summary = mcap::Summary::read(&bytes)
        .unwrap()
        .expect("finalised with a summary");
    let mut schemas: Vec<(String, String, String)> = summary
        .channels
        .values()
        .map(|c| {
            let s = c.schema.as_ref().unwrap();
            (c.topic.clone(), s.name.clone(), s.encoding.clone())
        })
        .collect();
    schemas.sort();
    assert!(schemas.contains(&(
        SCENE_TOPIC.into(),
        "foxglove.SceneUpdate".into(),
        "protobuf".into()
    )));
    assert!(schemas.contains(&(
        TF_TOPIC.into(),
        "foxglove.FrameTransform".into(),
        "protobuf".into()
    )));
    assert!(schemas.contains(&(
        SCALARS_TOPIC.into(),
        "knotrod.Scalars".into(),
        "jsonschema".into()
    )));
    let mut counts = std::collections::BTreeMap::<String, usize>::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        *counts.entry(m.channel.topic.clone()).or_default() += 1;
        match m.channel.topic.as_str() {
            SCENE_TOPIC => {
                let u = <foxglove::messages::SceneUpdate as prost::Message>::decode(&m.data[..])
                    .unwrap();
                let rod = u.entities.iter().find(|e| e.id == "rod").unwrap();
                assert_eq!(rod.lines[0].points.len(), 42, "centreline points");
                assert!(
                    (rod.lines[0].thickness - 0.005).abs() < 1e-15,
                    "tube of the rod's diameter"
                );
            }
            TF_TOPIC => {
                <foxglove::messages::FrameTransform as prost::Message>::decode(&m.data[..])
                    .unwrap();
            }
            _ => {
                let _: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
            }
        }
    }
    let states = counts[SCALARS_TOPIC];
    assert!(states > 3);
    assert_eq!(counts[SCENE_TOPIC], states);
    assert_eq!(counts[STATE_TOPIC], states);
    let r = read_recording(&rec).unwrap();
    assert!(r.metadata["scene"].contains("[continuation]"));
    assert_eq!(r.metadata["knotrod_version"], env!("CARGO_PKG_VERSION"));
    // info and export read it back
    let out = knotrod(&["info", rec.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stdout).contains(&format!("states: {states}")));
    for fmt in ["csv", "json", "obj"] {
        let out = knotrod(&[
            "export",
            rec.to_str().unwrap(),
            "--index",
            "2",
            "--format",
            fmt,
        ]);
        assert!(out.status.success() && !out.stdout.is_empty(), "{fmt}");
    }
}

#[test]
fn a_recorded_state_restarts_the_run_exactly() {
    let dir = temp_dir("rec-restart");
    let scene = short_branch_scene(&dir, "");
    let rec = dir.join("run.mcap");
    let json = dir.join("run.json");
    let out = knotrod(&[
        "run",
        scene.to_str().unwrap(),
        "--record",
        rec.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let k = 3;
    let recorded = read_state(&rec, k).unwrap().state;
    let from_summary: knotrod::model::rod::RodState =
        serde_json::from_value(summary["equilibria"][k as usize]["state"].clone()).unwrap();
    // exactly the computed state
    for (a, b) in recorded.nodes.iter().zip(&from_summary.nodes) {
        assert!((a - b).norm() <= 1e-12);
    }
    // restart a single solve from it: already in equilibrium, same energy
    let phi = summary["equilibria"][k as usize]["phi_over_2pi"]
        .as_f64()
        .unwrap();
    let restart = dir.join("restart.toml");
    std::fs::write(
        &restart,
        format!(
            "[model]\nsegments = 40\n[clamps]\nz_star = 0.115\ndelta = 0.05\nphi_over_2pi = {phi:.17}\n[initial]\nfrom_recording = {:?}\nindex = {k}\n",
            rec.to_str().unwrap()
        ),
    )
    .unwrap();
    let json2 = dir.join("restart.json");
    let out = knotrod(&[
        "run",
        restart.to_str().unwrap(),
        "--no-record",
        "--json",
        json2.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let again: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json2).unwrap()).unwrap();
    let (e1, e2) = (
        summary["equilibria"][k as usize]["energy"]
            .as_f64()
            .unwrap(),
        again["equilibria"][0]["energy"].as_f64().unwrap(),
    );
    assert!((e1 - e2).abs() <= 1e-12 * e1, "{e1} vs {e2}");
    assert!(again["equilibria"][0]["iterations"].as_u64().unwrap() <= 1);
    let restarted: knotrod::model::rod::RodState =
        serde_json::from_value(again["equilibria"][0]["state"].clone()).unwrap();
    let moved = restarted.largest_node_distance(&recorded);
    assert!(moved < 1e-10, "restart moved the state by {moved}");
}

#[test]
fn interrupted_run_leaves_a_finalised_recording() {
    let dir = temp_dir("rec-interrupt");
    // a long branch so that it is still running when interrupted
    let scene = short_branch_scene(&dir, "").to_str().unwrap().to_string();
    let text = std::fs::read_to_string(&scene)
        .unwrap()
        .replace("range = [0.78, 0.84]", "range = [0.78, 1.5]")
        .replace("segments = 40", "segments = 120");
    std::fs::write(&scene, text).unwrap();
    let rec = dir.join("run.mcap");
    let json = dir.join("run.json");
    let child = Command::new(env!("CARGO_BIN_EXE_knotrod"))
        .args([
            "run",
            &scene,
            "--record",
            rec.to_str().unwrap(),
            "--json",
            json.to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // wait for a few streamed equilibria (in the stream's temporary file
    // until the run ends), then Ctrl-C
    let lines = dir.join("run.jsonl.tmp");
    let start = std::time::Instant::now();
    while std::fs::read_to_string(&lines).map_or(0, |t| t.lines().count()) < 5 {
        assert!(
            start.elapsed().as_secs() < 120,
            "run produced no equilibria"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("interrupted") && !err.contains("panicked"),
        "{err}"
    );
    let r = read_recording(&rec).expect("finalised, readable recording");
    assert!(r.scalars.len() >= 5);
    let bytes = std::fs::read(&rec).unwrap();
    assert!(
        mcap::Summary::read(&bytes).unwrap().is_some(),
        "summary written"
    );
    // the JSON summary holds the same states
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(
        summary["equilibria"].as_array().unwrap().len(),
        r.scalars.len()
    );
    // and so does the stream, renamed into place; no temporary file is left
    let streamed = std::fs::read_to_string(dir.join("run.jsonl")).unwrap();
    assert_eq!(streamed.lines().count(), r.scalars.len());
    for f in ["run.jsonl.tmp", "run.mcap.tmp", "run.json.tmp"] {
        assert!(!dir.join(f).exists(), "{f} left behind");
    }
}

#[test]
fn damaged_recordings_give_clear_errors() {
    let dir = temp_dir("rec-damaged");
    let scene = short_branch_scene(&dir, "");
    let rec = dir.join("run.mcap");
    assert!(
        knotrod(&[
            "run",
            scene.to_str().unwrap(),
            "--record",
            rec.to_str().unwrap()
        ])
        .status
        .success()
    );
    let bytes = std::fs::read(&rec).unwrap();
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let garbage = dir.join("garbage.mcap");
    std::fs::write(&garbage, b"this is not an mcap file at all").unwrap();
    for bad in [&cut, &garbage] {
        let e = read_recording(bad).expect_err("damaged recording rejected");
        assert!(
            matches!(&e, knotrod::io::IoError::Recording { path, .. } if path == bad),
            "{e}"
        );
        assert!(
            e.to_string().contains("not a readable MCAP recording"),
            "{e}"
        );
        let out = knotrod(&["info", bad.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && !err.contains("panicked"), "{err}");
    }
    let e = read_state(&rec, 10_000).err().unwrap();
    assert!(matches!(e, knotrod::io::IoError::Recording { .. }), "{e}");
    assert!(e.to_string().contains("no state with index 10000"), "{e}");
    // corruption inside a chunk is detected (its CRC), never read as data or
    // turned into an allocation of a corrupted length
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let mut damaged = Vec::new();
    for (k, chunk) in summary.chunk_indexes.iter().take(4).enumerate() {
        let (start, len) = (
            chunk.chunk_start_offset as usize,
            chunk.chunk_length as usize,
        );
        let mut flipped = bytes.clone();
        flipped[start + len / 2 + k] ^= 1 << (k % 8);
        damaged.push(("one bit", flipped));
        let mut zeroed = bytes.clone();
        let from = start + len / 3;
        let to = (from + 1700).min(start + len);
        zeroed[from..to].fill(0);
        damaged.push(("1.7 KB zeroed", zeroed));
    }
    assert!(damaged.len() >= 2);
    for (i, (what, b)) in damaged.iter().enumerate() {
        let path = dir.join(format!("damaged_{i}.mcap"));
        std::fs::write(&path, b).unwrap();
        assert!(
            read_recording(&path).is_err(),
            "{what} in a chunk read as data"
        );
        for cmd in ["info", "export"] {
            let out = knotrod(&[cmd, path.to_str().unwrap()]);
            let err = String::from_utf8_lossy(&out.stderr);
            // an exit code, not a signal (an abort has none)
            assert!(
                out.status.code().is_some_and(|c| c != 0) && !err.contains("panicked"),
                "{cmd} on {what}: {:?} {err}",
                out.status
            );
        }
    }
}

#[test]
fn contacts_are_recorded_and_drawn() {
    // a clamped beam pushed by a segment obstacle: one contact, drawn as a
    // red cube at the contact point, its force in the scalars
    let dir = temp_dir("rec-contacts");
    let scene = dir.join("beam.toml");
    std::fs::write(
        &scene,
        "[model]\nsegments = 40\n[clamps]\nz_star = 1.0\ndelta = 0.0\nphi_over_2pi = 0.0\n\
         [contact]\nrays = false\nself_contact = false\n\
         obstacles = [[0.0049, -0.1, 0.5, 0.0049, 0.1, 0.5]]\n",
    )
    .unwrap();
    let rec = dir.join("beam.mcap");
    let bytes = run_recorded(&scene, &rec);
    let mut drawn = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic == SCENE_TOPIC {
            let u =
                <foxglove::messages::SceneUpdate as prost::Message>::decode(&m.data[..]).unwrap();
            let c = u.entities.iter().find(|e| e.id == "contacts").unwrap();
            assert_eq!(c.cubes.len(), 1);
            let at = c.cubes[0].pose.as_ref().unwrap().position.as_ref().unwrap();
            assert!(
                (at.z - 0.5).abs() < 1e-9 && (at.x + 1e-4).abs() < 1e-6,
                "{at:?}"
            );
            drawn += 1;
        }
    }
    assert_eq!(drawn, 1);
    let r = read_recording(&rec).unwrap();
    assert!(r.scalars[0].contact_force > 0.0);
}

#[test]
fn a_recording_written_by_an_earlier_version_reads_back_with_its_fields() {
    // recordings/samples/fig3_n60.mcap was written by knotrod at git 2ad98bb
    // (before the layered crate): its events, scalars and states must still
    // read, with the events' kinds as the typed enum
    let sample = Path::new(env!("CARGO_MANIFEST_DIR")).join("recordings/samples/fig3_n60.mcap");
    let rec = read_recording(&sample).unwrap();
    assert_eq!(rec.scalars.len(), 131);
    for topic in ["/events", "/rod/scalars", "/rod/scene", "/rod/state", "/tf"] {
        assert!(
            rec.channels.contains_key(topic),
            "{topic}: {:?}",
            rec.channels
        );
    }
    assert_eq!(rec.events.len(), 10);
    let kinds: Vec<EventKind> = rec.events.iter().map(|e| e.kind).collect();
    for k in [
        EventKind::Wall,
        EventKind::Crossing,
        EventKind::KnotChange,
        EventKind::Stability,
        EventKind::BranchPoint,
        EventKind::Fold,
    ] {
        assert!(kinds.contains(&k), "{k}: {kinds:?}");
    }
    let w1 = rec.events.iter().find(|e| e.label == "W1").unwrap();
    assert_eq!(w1.kind, EventKind::Wall);
    assert!((w1.phi_over_2pi - 0.77472).abs() < 1e-5, "{w1:?}");
    assert_eq!(rec.scalars.iter().filter(|s| s.good_knot).count(), 14);
    let last = read_state(&sample, 130).unwrap();
    assert_eq!(last.state.segments(), 60);
    assert_eq!(last.model.segments, 60);
    assert!(rec.metadata["scene"].contains("[continuation]"));
}
