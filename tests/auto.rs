//! `knotrod verify` on AUTO-07p's own files (issue 39): the s./b. parser on
//! a checked-in output (tests/fixtures/auto: a real NTST = 6, NCOL = 2 run of
//! the Figure 3 branch, its branch file trimmed), its refusals of bad files
//! and mappings, and, where AUTO-07p is installed, a fresh AUTO run of the
//! Figure 3 branch verified label by label, its fold against knotrod's.

use knotrod::io::auto::{
    AutoError, AutoMap, PointType, parse_branch, parse_solutions, read_auto_input,
    read_branch_file, read_solutions_file,
};
use knotrod::io::verify_file::{VerifyFileError, read_solutions};
use knotrod::model::rod::Parameter;
use knotrod::report::auto_events::compare_with_continuation;
use knotrod::study::verify::{Verdict, VerifyOptions, verify_all};
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;

const S_SMALL: &str = "tests/fixtures/auto/s.small";
const B_SMALL: &str = "tests/fixtures/auto/b.small";
/// The rod model's mapping (benches/peers/auto07p/rod.f90): U(13..15) = n,
/// U(16..18) = m in material components, PAR(1) = φ/2π, PAR(2) = z*,
/// PAR(3) = δ.
const MAPPING: &str = r#"
[auto]
n0 = [13, 14, 15]
m0 = [16, 17, 18]
parameters = { phi = { par = 1, unit = "turns" }, z_star = { par = 2 }, delta = { par = 3 } }
"#;

#[test]
fn the_parser_reads_a_real_auto_07p_output() {
    let sols = read_solutions_file(Path::new(S_SMALL)).unwrap();
    assert_eq!(sols.len(), 2);
    let (a, b) = (&sols[0], &sols[1]);
    assert_eq!((a.label, a.kind, a.point), (3, PointType::Regular, 40));
    assert_eq!(
        (b.label, b.kind, b.point, b.code),
        (4, PointType::Fold, 75, 5)
    );
    for s in &sols {
        assert_eq!((s.ntst, s.ncol, s.ndim, s.t.len()), (6, 2, 18, 13));
        assert_eq!((s.t[0], s.t[12]), (0.0, 1.0));
        // the s = 0 clamp: r = 0, d_i = e_i (rod.f90's boundary conditions)
        let clamp = [0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1.];
        for (x, c) in s.row(0)[..12].iter().zip(clamp) {
            assert!((x - c).abs() < 1e-12, "{:?}", s.row(0));
        }
        // the direction is stored: one active parameter, PHI = PAR(1)
        assert_eq!(s.active, vec![1]);
        assert_eq!(s.parameter_direction.len(), 1);
        assert_eq!(s.par.len(), 36);
        assert_eq!(
            (s.par[1], s.par[2], s.par[3], s.par[4]),
            (0.115, 0.05, 3.0, 3.0)
        );
    }
    // 11 printed digits: half a unit of the 10th decimal of the mantissa
    assert_eq!(b.par[0], 0.73997431457);
    assert!((b.par_half_units[0] - 5e-12).abs() < 1e-24);
    let branch = read_branch_file(Path::new(B_SMALL)).unwrap();
    assert_eq!(
        (branch.epss, branch.ds, branch.dsmax),
        (Some(1e-3), Some(-0.01), Some(0.5))
    );
    assert_eq!(branch.epsu, Some(1e-7));
    assert_eq!(&branch.columns[..3], ["PHI", "L2-NORM", "MAX x"]);
    assert_eq!(branch.rows.len(), 11);
    let lp = branch.rows.iter().find(|r| r.label == 4).unwrap();
    assert_eq!(
        (lp.kind, lp.point, lp.values[0]),
        (PointType::Fold, 75, b.par[0])
    );
    assert!(branch.rows.iter().all(|r| r.values.len() == 8));
}

#[test]
fn a_mapping_turns_each_label_into_a_verify_row_and_its_lp_into_an_event() {
    let dir = common::temp_dir("auto-map");
    let map = dir.join("small.toml");
    let here = std::env::current_dir().unwrap();
    std::fs::write(
        &map,
        format!(
            "scene = \"{}\"\n{MAPPING}solutions = \"{}\"\n",
            here.join("scenes/appendix_d.toml").display(),
            here.join(S_SMALL).display()
        ),
    )
    .unwrap();
    let input = read_auto_input(&map, None, &[]).unwrap();
    // the branch file is found beside the solutions (s.small → b.small)
    assert_eq!(
        input.map.branch.as_deref(),
        Some(here.join(B_SMALL).as_path())
    );
    assert_eq!(input.solutions.len(), 2);
    let row = &input.solutions[1];
    assert_eq!(row.name, "LAB 4 LP (PT 75)");
    let sols = read_solutions_file(Path::new(S_SMALL)).unwrap();
    assert_eq!(row.unknowns[..], sols[1].row(0)[12..18]);
    assert_eq!(
        row.parameters,
        // in the mapping's key order (TOML tables are sorted)
        vec![
            (Parameter::Delta, 0.05),
            (Parameter::Phi, 0.73997431457),
            (Parameter::ZStar, 0.115)
        ]
    );
    assert!(row.rounding.iter().all(|&r| r > 0.0 && r < 1e-8));
    // AUTO's LP, located to EPSS (1 + √|DS DSMAX|) in arclength
    let [lp] = &input.events[..] else {
        panic!("{:?}", input.events)
    };
    assert_eq!((lp.kind, lp.label, lp.row), (PointType::Fold, 4, Some(1)));
    assert_eq!(lp.parameter, Some(Parameter::Phi));
    let arclength = 1e-3 * (1.0 + (0.01f64 * 0.5).sqrt());
    let expected = arclength * sols[1].parameter_direction[0].abs();
    assert!((lp.tolerance.unwrap() - expected).abs() < 1e-15 * expected.max(1e-300));
    // the same from the command line's --map, φ in radians scaled to φ/2π
    let pairs: Vec<String> = ["n0=13,14,15", "m0=16,17,18", "phi=1:radians"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let by_args = read_auto_input(
        Path::new(S_SMALL),
        Some(Path::new("scenes/appendix_d.toml")),
        &pairs,
    )
    .unwrap();
    let phi = by_args.solutions[1].parameters[0];
    assert_eq!(phi.0, Parameter::Phi);
    assert!((phi.1 - 0.73997431457 / std::f64::consts::TAU).abs() < 1e-16);
    // a b. file stands for its s. file
    let by_branch = read_auto_input(
        Path::new(B_SMALL),
        Some(Path::new("scenes/appendix_d.toml")),
        &pairs,
    )
    .unwrap();
    assert_eq!(by_branch.solutions.len(), 2);
    assert_eq!(by_branch.events.len(), 1);
}

/// The fixture's text with `f` applied, parsed as a solutions file.
fn solutions_with(f: impl Fn(&str) -> String) -> Result<usize, AutoError> {
    let text = std::fs::read_to_string(S_SMALL).unwrap();
    parse_solutions(Path::new("s.bad"), &f(&text)).map(|v| v.len())
}

fn first_line_with(text: &str, field: usize, value: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut h: Vec<String> = lines[0].split_whitespace().map(str::to_string).collect();
    h[field] = value.into();
    lines[0] = h.join(" ");
    lines.join("\n")
}

#[test]
fn bad_auto_files_and_mappings_get_clear_errors() {
    // absurd sizes are refused before anything is allocated, naming the field
    for (field, value, name) in [
        (6, "1000000000", "NTPL"),
        (7, "99999999", "NAR"),
        (11, "0", "NPAR"),
        (8, "100000", "NROWPR"),
        (4, "-1", "NFPR"),
    ] {
        let e = solutions_with(|t| first_line_with(t, field, value)).unwrap_err();
        let m = e.to_string();
        assert!(m.contains("s.bad: line 1: ") && m.contains(name), "{m}");
    }
    // a block that does not hold NTPL × NAR + NPAR numbers
    let e = solutions_with(|t| first_line_with(t, 6, "12")).unwrap_err();
    assert!(e.to_string().contains("NROWPR"), "{e}");
    // a number that is not one names its line and what it is
    let e =
        solutions_with(|t| t.replacen("1.0000000000E+000", "1.0000000000X+000", 1)).unwrap_err();
    let m = e.to_string();
    assert!(
        m.contains("line 2") && m.contains("U(4) of mesh point 1"),
        "{m}"
    );
    let e = solutions_with(|t| t.replacen("0.0000000000E+000", "NaN", 1)).unwrap_err();
    assert!(e.to_string().contains("t of mesh point 1"), "{e}");
    // no truncation of the file panics
    let text = std::fs::read_to_string(S_SMALL).unwrap();
    for cut in (0..text.len()).step_by(101) {
        let _ = parse_solutions(Path::new("s.cut"), &text[..cut]);
    }
    let btext = std::fs::read_to_string(B_SMALL).unwrap();
    for cut in (0..btext.len()).step_by(37) {
        let _ = parse_branch(Path::new("b.cut"), &btext[..cut]);
    }
    // a branch file's point with a column too few
    let short: String = btext
        .lines()
        .map(|l| {
            if l.starts_with("   1    40") {
                l[..l.len() - 19].to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let e = parse_branch(Path::new("b.bad"), &short).unwrap_err();
    assert!(
        e.to_string().contains("columns") && e.to_string().contains("7 values"),
        "{e}"
    );
    // mappings
    let map = |extra: &str| {
        AutoMap::from_toml(
            Path::new("m.toml"),
            &format!("[auto]\nsolutions = \"s.x\"\n{extra}"),
        )
    };
    for (extra, field) in [
        ("parameters = { phi = { par = 1 } }", "unit"),
        (
            "parameters = { phi = { par = 1, unit = \"degrees\" } }",
            "degrees",
        ),
        (
            "parameters = { z_star = { par = 2, unit = \"turns\" } }",
            "only phi",
        ),
        ("parameters = { zeta = { par = 2 } }", "zeta"),
        (
            "parameters = { phi = { par = 0, unit = \"turns\" } }",
            "count from 1",
        ),
        ("n0 = [13, 14]", "three"),
        ("n0 = [13, 14, \"x\"]", "integer"),
        ("colour = \"red\"", "colour"),
    ] {
        let e = map(extra).unwrap_err();
        assert!(e.to_string().contains(field), "{extra}: {e}");
    }
    let e = AutoMap::from_toml(Path::new("m.toml"), "[auto]\nn0 = [1, 2, 3]\n").unwrap_err();
    assert!(e.to_string().contains("solutions: missing"), "{e}");
    // an unmapped unknown, and a mapped PAR beyond the file's NPAR
    let pairs = |p: &[&str]| p.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let scene = Some(Path::new("scenes/appendix_d.toml"));
    let e = read_auto_input(Path::new(S_SMALL), scene, &pairs(&["n0=13,14,15"])).unwrap_err();
    assert!(e.to_string().contains("m0: missing"), "{e}");
    let e = read_auto_input(
        Path::new(S_SMALL),
        scene,
        &pairs(&["n0=13,14,15", "m0=16,17,18", "delta=40"]),
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("PAR(40)") && e.to_string().contains("NPAR = 36"),
        "{e}"
    );
    let e = read_auto_input(
        Path::new(S_SMALL),
        scene,
        &pairs(&["n0=13,14,15", "m0=16,17,99"]),
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("U(99)") && e.to_string().contains("NDIM = 18"),
        "{e}"
    );
    // a file verify does not read is named with the formats it does
    let dir = common::temp_dir("auto-format");
    let dat = dir.join("solutions.dat");
    std::fs::write(&dat, "1 2 3\n").unwrap();
    let e = read_solutions(&dat, None).unwrap_err();
    assert!(matches!(e, VerifyFileError::UnknownFormat { .. }), "{e}");
    assert!(
        e.to_string().contains("solutions.dat") && e.to_string().contains("AUTO-07p"),
        "{e}"
    );
    let out = common::knotrod(&["verify", dat.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("CSV") && !err.contains("panicked"),
        "{err}"
    );
    let out = common::knotrod(&[
        "verify",
        S_SMALL,
        "--scene",
        "scenes/appendix_d.toml",
        "--map",
        "phi=1",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("radians"), "{err}");
}

/// AUTO's point type of each verify row (the row's name starts "LAB k TY").
fn kinds_of_rows(input: &knotrod::io::auto::AutoInput) -> Vec<PointType> {
    input
        .solutions
        .iter()
        .map(|s| match s.name.split_whitespace().nth(2) {
            Some("LP") => PointType::Fold,
            Some("BP") => PointType::BranchPoint,
            _ => PointType::Regular,
        })
        .collect()
}

/// Why AUTO-07p cannot be run here, if it cannot.
fn auto_missing() -> Option<String> {
    let dir = std::env::var("AUTO_DIR").unwrap_or_else(|_| "/usr/lib/auto-07p".into());
    if !Path::new(&dir).join("python/auto").is_dir() {
        return Some(format!("no AUTO-07p at {dir} (apt-get install auto-07p)"));
    }
    for tool in ["python3", "gfortran", "make"] {
        let found = Command::new("sh")
            .args(["-c", &format!("command -v {tool}")])
            .output()
            .is_ok_and(|o| o.status.success());
        if !found {
            return Some(format!(
                "AUTO-07p needs {tool} to build its model, and it is missing"
            ));
        }
    }
    None
}

/// AUTO-07p's Figure 3 branch at NTST = 50 (benches/peers/auto07p), in a
/// fresh directory; the mapping file beside it.
fn run_auto(dir: &Path) -> PathBuf {
    let out = Command::new("python3")
        .args([
            "benches/peers/auto07p/fig3_labels.py",
            "--ntst",
            "50",
            "--npr",
            "20",
            "--dir",
        ])
        .arg(dir)
        .env("OMP_NUM_THREADS", "1")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "AUTO-07p run failed: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let here = std::env::current_dir().unwrap();
    let map = dir.join("fig3.toml");
    std::fs::write(
        &map,
        format!(
            "scene = \"{}\"\n{MAPPING}solutions = \"s.fig3\"\ncontinuation = \"{}\"\n",
            here.join("scenes/appendix_d.toml").display(),
            here.join("scenes/fig3_polished.toml").display()
        ),
    )
    .unwrap();
    map
}

#[test]
fn every_label_of_an_auto_07p_run_of_figure_3_is_confirmed_and_its_fold_is_knotrods() {
    if let Some(why) = auto_missing() {
        eprintln!("skipped: {why}");
        return;
    }
    let dir = common::temp_dir("auto-fig3");
    let map = run_auto(&dir);
    let input = read_auto_input(&map, None, &[]).unwrap();
    // labels every 20 steps, AUTO's BP (S) and its LP (the fold)
    let kinds: Vec<PointType> = input.events.iter().map(|e| e.kind).collect();
    assert_eq!(
        kinds,
        [PointType::BranchPoint, PointType::Fold],
        "{:?}",
        input.events
    );
    assert!(input.solutions.len() >= 4, "{:?}", input.solutions);
    let checks = verify_all(
        &input.scene,
        &input.solutions,
        &VerifyOptions::default(),
        &|_| Ok(()),
    )
    .unwrap();
    for (c, label) in checks.iter().zip(&kinds_of_rows(&input)) {
        assert_eq!(
            c.verdict,
            Verdict::Confirmed,
            "{}: {:?}, input {:?}, {:.2} rounding units",
            c.given.name,
            c.verdict,
            c.input,
            c.rounding_units.unwrap_or(f64::NAN)
        );
        if *label == PointType::Fold {
            // AUTO's LP is verified as a fold: at each N the discrete rod's
            // own fold (which lies O(h²) from AUTO's φ, where the discrete
            // rod may have no equilibrium), extrapolated, and the continuum's
            let fold = c.fold.as_ref().expect("an LP row is checked as a fold");
            let (continuum, error) = fold.continuum.expect("the continuum fold located");
            let lp = input
                .events
                .iter()
                .find(|e| e.kind == PointType::Fold)
                .unwrap();
            let tolerance = lp.tolerance.unwrap();
            assert!(
                (continuum - fold.given).abs() <= error + tolerance,
                "AUTO's LP {} against the continuum fold {continuum} ± {error:.1e} (AUTO ± {tolerance:.1e})",
                fold.given
            );
            // the discrete folds converge to it at second order
            let e = c
                .estimates
                .iter()
                .find(|e| e.quantity == knotrod::study::verify::Quantity::Fold)
                .unwrap();
            assert!((1.5..=2.5).contains(&e.order), "{e:?}");
            assert_eq!(e.agrees, Some(true), "{e:?}");
            assert!(
                c.claims
                    .iter()
                    .any(|k| k.claim.starts_with("fold") && k.confirmed())
            );
        }
    }
    // AUTO's LP against knotrod's polished fold, within the two bars
    let compared = compare_with_continuation(&input).unwrap();
    let lp = compared
        .labels
        .iter()
        .find(|l| l.auto.kind == PointType::Fold)
        .unwrap();
    let fold = lp.knotrod.as_ref().unwrap();
    let (bar, tolerance) = (fold.error.unwrap(), lp.auto.tolerance.unwrap());
    assert!(bar < 1e-9 && tolerance < 1e-7, "{lp:?}");
    assert_eq!(lp.within, Some(true), "{lp:?}");
    assert!(
        (lp.auto.value - fold.value).abs() <= bar + tolerance,
        "AUTO's LP {} vs knotrod's {} ± {bar:.1e} (AUTO ± {tolerance:.1e})",
        lp.auto.value,
        fold.value
    );
}
