//! Output goes where the user points it (issue 54): a symbolic link is
//! followed and kept, a FIFO receives the whole output and stays a FIFO, a
//! full device behind a link says so and stays a device, `-` is standard
//! output; and text read with a leading UTF-8 byte-order mark reads as
//! without it. Each case in its own temporary folder.

use crate::common;

use common::temp_dir;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::process::{Command, Output, Stdio};

/// `knotrod run` of the Appendix D knot at N = 40 (one equilibrium, no
/// default recording) with `extra` arguments.
fn appendix_d(extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_knotrod"))
        .args(["run", "scenes/appendix_d.toml", "--segments", "40"])
        .args(extra)
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

fn summary(text: &str) -> serde_json::Value {
    let v: serde_json::Value = serde_json::from_str(text).unwrap_or_else(|e| panic!("{e}: {text}"));
    assert_eq!(v["equilibria"].as_array().map(Vec::len), Some(1), "{v}");
    v
}

#[test]
fn a_symlinked_summary_rewrites_its_target_and_keeps_the_link() {
    let dir = temp_dir("out-link");
    let target = dir.join("target.json");
    std::fs::write(&target, "old").unwrap();
    let link = dir.join("link.json");
    std::os::unix::fs::symlink("target.json", &link).unwrap();
    let out = appendix_d(&["--no-record", "--json", link.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    summary(&std::fs::read_to_string(&target).unwrap());
    // the stream of equilibria beside the link, as given
    assert!(dir.join("link.jsonl").exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_fifo_receives_the_whole_summary_and_stays_a_fifo() {
    let dir = temp_dir("out-fifo");
    let fifo = dir.join("f.json");
    if !Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        eprintln!("skipped: mkfifo is not available");
        return;
    }
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(&fifo).unwrap())
    };
    let out = appendix_d(&["--no-record", "--json", fifo.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    summary(&reader.join().unwrap());
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    // nothing was written beside it, nor left
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["f.json"], "{names:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_full_device_behind_a_link_fails_the_run_and_stays_a_device() {
    let full = Path::new("/dev/full");
    let is_device = || std::fs::metadata(full).is_ok_and(|m| m.file_type().is_char_device());
    if !is_device() {
        eprintln!("skipped: this machine has no /dev/full");
        return;
    }
    let dir = temp_dir("out-full");
    let link = dir.join("full");
    std::os::unix::fs::symlink(full, &link).unwrap();
    let link = link.to_str().unwrap();
    for args in [vec!["--no-record", "--json", link], vec!["--record", link]] {
        let out = appendix_d(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}: {err}");
        assert!(
            err.contains("No space left on device") && err.contains(link),
            "{args:?}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(is_device(), "/dev/full is no longer a device");
        assert!(
            std::fs::symlink_metadata(link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_dash_writes_the_summary_to_standard_output() {
    let dir = temp_dir("out-dash");
    let out = appendix_d(&["--no-record", "--json", "-"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    // standard output holds the summary alone: the text for people went to
    // standard error
    summary(&String::from_utf8_lossy(&out.stdout));
    assert!(err.contains("scene "), "{err}");
    assert!(!Path::new("-").exists() && !Path::new("-.jsonl").exists());
    // and an export to `-`
    let rec = dir.join("a.mcap");
    let made = appendix_d(&["--record", rec.to_str().unwrap()]);
    assert!(made.status.success());
    let out = Command::new(env!("CARGO_BIN_EXE_knotrod"))
        .args([
            "export",
            rec.to_str().unwrap(),
            "--format",
            "csv",
            "--out",
            "-",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("node,s,x,y,z"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_leading_byte_order_mark_is_read_as_without_it() {
    let dir = temp_dir("bom");
    let bom = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, format!("\u{feff}{text}")).unwrap();
        p
    };
    // a scene
    let plain = Path::new("scenes/appendix_d.toml");
    let marked = bom("appendix_d.toml", &std::fs::read_to_string(plain).unwrap());
    let json = |s: knotrod::scene::Scene| {
        let mut v = serde_json::to_value(s).unwrap();
        v.as_object_mut().unwrap().remove("name");
        v
    };
    assert_eq!(
        json(knotrod::scene::Scene::load(&marked).unwrap()),
        json(knotrod::scene::Scene::load(plain).unwrap())
    );
    // a curve
    let curve = "0 0 0\n1 0 0\n1 1 0\n0 1 1\n";
    let plain_curve = dir.join("plain.txt");
    std::fs::write(&plain_curve, curve).unwrap();
    assert_eq!(
        knotrod::io::curve_file::read_points(&bom("curve.txt", curve)).unwrap(),
        knotrod::io::curve_file::read_points(&plain_curve).unwrap()
    );
    // verify's CSV and TOML
    let csv = "name,phi_over_2pi,n0_1,n0_2,n0_3,m0_1,m0_2,m0_3,stable,knot\n\
               flip-symmetric,0.76,-31.956304646,30.008967518,36.268060172,5.484462436,-9.851921754,8.374621939,true,3_1\n";
    let plain_csv = dir.join("plain.csv");
    std::fs::write(&plain_csv, csv).unwrap();
    let read = |p: &Path| knotrod::io::verify_file::read_solutions(p, Some(plain)).unwrap();
    assert_eq!(read(&bom("rows.csv", csv)).1, read(&plain_csv).1);
    let toml = Path::new("scenes/verify/two_equilibria.toml");
    let marked_toml = bom("two.toml", &std::fs::read_to_string(toml).unwrap());
    assert_eq!(read(&marked_toml).1, read(toml).1);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_map_to_standard_output_is_refused_before_its_work() {
    // its lines, slices and plots go beside its file
    let out = Command::new(env!("CARGO_BIN_EXE_knotrod"))
        .args(["map", "scenes/fig7_island_kirchhoff.toml", "--json", "-"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("--json -") && err.contains("name a file"),
        "{err}"
    );
    assert!(out.stdout.is_empty());
}
