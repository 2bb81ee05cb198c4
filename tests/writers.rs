//! Every output is written to `PATH.tmp` and renamed into place, held against
//! a second writer (issue 31, item 10): two runs of one recording, a full
//! disk (a small tmpfs, when this machine lets the test mount one) and the
//! files of a run left whole.

use crate::common;

use common::temp_dir;
use knotrod::io::recording::read_recording;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// `knotrod run` of the Figure 3 branch at N = 60 with `extra` arguments.
fn fig3_run(extra: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_knotrod"));
    c.args(["run", "scenes/fig3_kirchhoff.toml", "--segments", "60"])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    c
}

#[test]
fn of_two_runs_writing_one_recording_one_succeeds_and_the_other_names_the_path() {
    let dir = temp_dir("two-writers");
    let rec = dir.join("same.mcap");
    let json = dir.join("same.json");
    let args = [
        "--record",
        rec.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ];
    let first = fig3_run(&args).spawn().unwrap();
    // the second starts once the first holds its files (its run takes
    // seconds; before, both wrote one file and both exited 0)
    let start = Instant::now();
    while !dir.join("same.mcap.tmp").exists() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "first run did not start"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    let second = fig3_run(&args).output().unwrap();
    let first = first.wait_with_output().unwrap();
    let (e1, e2) = (
        String::from_utf8_lossy(&first.stderr),
        String::from_utf8_lossy(&second.stderr),
    );
    assert!(first.status.success(), "first: {e1}");
    assert!(!second.status.success(), "both runs succeeded");
    // the second is refused before any work, naming a file it would write
    assert!(
        e2.contains("another writer")
            && (e2.contains(&*json.to_string_lossy()) || e2.contains(&*rec.to_string_lossy())),
        "{e2}"
    );
    // the recording and the summary read back whole
    let r = read_recording(&rec).expect("a readable recording");
    assert!(!r.scalars.is_empty());
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(
        summary["equilibria"].as_array().unwrap().len(),
        r.scalars.len()
    );
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A tmpfs of `size` mounted at `dir`, unmounted when dropped; None (with a
/// message) where the test may not mount one (not root, no tmpfs).
struct SmallDisk(std::path::PathBuf);

impl SmallDisk {
    fn mount(dir: &Path, size: &str) -> Option<SmallDisk> {
        std::fs::create_dir_all(dir).unwrap();
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(dir)
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if !ok {
            eprintln!(
                "skipped: cannot mount a small tmpfs at {} (needs root)",
                dir.display()
            );
        }
        ok.then(|| SmallDisk(dir.to_path_buf()))
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

#[test]
fn a_full_disk_says_so_naming_the_file_and_leaves_the_previous_one() {
    let dir = temp_dir("full-disk").join("disk");
    let Some(_disk) = SmallDisk::mount(&dir, "64k") else {
        return;
    };
    let rec = dir.join("same.mcap");
    std::fs::write(&rec, "the previous recording").unwrap();
    let out = fig3_run(&["--record", rec.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("No space left on device") && err.contains(&*rec.to_string_lossy()),
        "{err}"
    );
    assert!(!err.contains("attempted another write"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(
        std::fs::read_to_string(&rec).unwrap(),
        "the previous recording"
    );
    // the temporary file is gone: the space is free again
    assert!(!dir.join("same.mcap.tmp").exists());
    // a summary that does not fit either: the same answer
    let json = dir.join("s.json");
    std::fs::write(&json, "{}").unwrap();
    let out = fig3_run(&["--no-record", "--json", json.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("No space left on device"), "{err}");
    assert_eq!(std::fs::read_to_string(&json).unwrap(), "{}");
}
