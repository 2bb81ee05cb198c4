//! Reading recordings back: `knotrod info` and `knotrod export`.

use crate::io::error::{IoError, Result};
use crate::io::recording::{StateMessage, read_recording, read_state};
use std::io::Write;
use std::path::Path;

/// Export formats of one recorded state.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum ExportFormat {
    /// Nodes and material frames, one row per node.
    Csv,
    /// The full state.
    Json,
    /// A triangle mesh of the tube.
    Obj,
    /// Its shooting unknowns, polished on the continuum equations, as a
    /// `[[solution]]` of a `knotrod verify` file.
    Shooting,
    /// VTK PolyData (ParaView, pyvista): the centreline with the tube's
    /// radius, s, the material frame, the strains, n and m as point data.
    Vtp,
    /// Every state of the recording as a VTK time series: `--out NAME.pvd`
    /// and one `NAME_K.vtp` beside it per state (`--index` is not used).
    Pvd,
}

/// Print what a recording holds.
pub fn info(path: &Path, out: &mut impl Write) -> Result<()> {
    let rec = read_recording(path)?;
    print_info(path, &rec, out).map_err(IoError::Output)
}

fn print_info(
    path: &Path,
    rec: &crate::io::recording::Recording,
    out: &mut impl Write,
) -> std::io::Result<()> {
    writeln!(out, "recording {}", path.display())?;
    if let Some(v) = rec.metadata.get("knotrod_version") {
        writeln!(
            out,
            "  written by knotrod {v} (git {})",
            rec.metadata.get("git_revision").map_or("?", |s| s.as_str())
        )?;
    }
    writeln!(out, "  channels:")?;
    for (topic, count) in &rec.channels {
        writeln!(out, "    {topic:<14} {count} messages")?;
    }
    writeln!(out, "  states: {}", rec.scalars.len())?;
    let range = |f: fn(&crate::io::recording::Scalars) -> f64| {
        let v: Vec<f64> = rec.scalars.iter().map(f).collect();
        (
            v.iter().copied().fold(f64::INFINITY, f64::min),
            v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    };
    if !rec.scalars.is_empty() {
        for (name, (lo, hi)) in [
            ("z*", range(|s| s.z_star)),
            ("δ", range(|s| s.delta)),
            ("φ/2π", range(|s| s.phi_over_2pi)),
            ("Tw", range(|s| s.twist)),
        ] {
            writeln!(out, "  {name:<5} from {lo:.5} to {hi:.5}")?;
        }
        let stable = rec.scalars.iter().filter(|s| s.stable).count();
        let good = rec.scalars.iter().filter(|s| s.good_knot).count();
        writeln!(out, "  {stable} stable states, {good} good knots")?;
    }
    writeln!(out, "  events: {}", rec.events.len())?;
    for e in &rec.events {
        writeln!(
            out,
            "    {:<5} {:<13} branch {} z* {:.5} φ/2π {:.5}  {}",
            e.label, e.kind, e.branch, e.z_star, e.phi_over_2pi, e.detail
        )?;
    }
    Ok(())
}

/// Export one recorded state (every state, for `Pvd`).
pub fn export(path: &Path, index: u64, format: ExportFormat, out: Option<&Path>) -> Result<()> {
    if let ExportFormat::Pvd = format {
        return series(path, out);
    }
    let msg = read_state(path, index)?;
    if let ExportFormat::Vtp = format {
        let title = format!("knotrod state {index} of {}", path.display());
        let bytes = crate::io::vtk::vtp(&msg.model, &msg.state, &title, path)?;
        return write_out(out, &bytes);
    }
    let text = match format {
        ExportFormat::Json => serde_json::to_string_pretty(&msg)
            .map_err(IoError::json("cannot encode the state as JSON", path))?,
        ExportFormat::Csv => csv(&msg),
        ExportFormat::Obj => obj(&msg, path, index),
        ExportFormat::Shooting => shooting(&msg, path, index)?,
        ExportFormat::Vtp | ExportFormat::Pvd => unreachable!("written above"),
    };
    write_out(out, text.as_bytes())
}

/// Write `bytes` to `out`, or to standard output.
fn write_out(out: Option<&Path>, bytes: &[u8]) -> Result<()> {
    match out {
        Some(p) => crate::io::output::write_file(p, bytes),
        None => std::io::stdout()
            .lock()
            .write_all(bytes)
            .map_err(IoError::Output),
    }
}

/// Every state of a recording as `.vtp` files beside the collection `out`
/// (`NAME.pvd`), the state's index as time; the collection is written last,
/// so it lists only files that are there.
fn series(path: &Path, out: Option<&Path>) -> Result<()> {
    let Some(out) = out.filter(|p| p.extension().is_some_and(|e| e == "pvd")) else {
        return Err(IoError::Recording {
            path: path.into(),
            reason: "--format pvd writes a collection and a file per state: name it with \
                     --out NAME.pvd"
                .into(),
        });
    };
    let bytes = crate::io::read_limited(path, crate::io::DATA_FILE_LIMIT)
        .map_err(IoError::file("cannot read recording", path))?;
    let stem = out
        .file_stem()
        .unwrap_or_default()
        .to_string_lossy()
        .into_owned();
    let dir = out.parent().unwrap_or(Path::new(""));
    let mut parts = Vec::new();
    crate::io::recording::each_state(path, &bytes, |msg| {
        let file = format!("{stem}_{:05}.vtp", msg.index);
        let title = format!("knotrod state {} of {}", msg.index, path.display());
        let vtp = crate::io::vtk::vtp(&msg.model, &msg.state, &title, path)?;
        crate::io::output::write_file(&dir.join(&file), &vtp)?;
        parts.push((msg.index as f64, file));
        Ok(())
    })?;
    crate::io::output::write_file(out, crate::io::vtk::collection(&parts).as_bytes())
}

/// Nodes and material frames, one row per node.
fn csv(msg: &StateMessage) -> String {
    use std::fmt::Write as _;
    let s = &msg.state;
    let mut text = String::from("node,s,x,y,z,d1x,d1y,d1z,d2x,d2y,d2z\n");
    let (points, arc) = s.centreline();
    let n = s.segments();
    for (k, (p, a)) in points.iter().zip(&arc).enumerate() {
        // the frame of the edge starting at this point (clamp frame at the ends)
        let j = k.min(n);
        let [d1, d2, _] = s.directors(j);
        let _ = writeln!(
            text,
            "{k},{a},{},{},{},{},{},{},{},{},{}",
            p.x, p.y, p.z, d1.x, d1.y, d1.z, d2.x, d2.y, d2.z
        );
    }
    text
}

/// A tube around the centreline, 12 sides, of the diameter of the solid
/// circular rod with this stretching stiffness (S = 16/h²).
fn obj(msg: &StateMessage, path: &Path, index: u64) -> String {
    use std::fmt::Write as _;
    let s = &msg.state;
    let radius = 2.0 / msg.model.stretching_stiffness.sqrt();
    let (points, _) = s.centreline();
    let sides = 12;
    let mut text = format!("# knotrod state {index} of {}\n", path.display());
    let n = s.segments();
    for (k, p) in points.iter().enumerate() {
        let [d1, d2, _] = s.directors(k.min(n));
        for q in 0..sides {
            let a = 2.0 * std::f64::consts::PI * q as f64 / sides as f64;
            let v = p + radius * (a.cos() * d1 + a.sin() * d2);
            let _ = writeln!(text, "v {} {} {}", v.x, v.y, v.z);
        }
    }
    for k in 0..points.len() - 1 {
        for q in 0..sides {
            let (a, b) = (k * sides + q + 1, k * sides + (q + 1) % sides + 1);
            let (c, d) = (a + sides, b + sides);
            let _ = writeln!(text, "f {a} {b} {d} {c}");
        }
    }
    text
}

/// The state's shooting unknowns as a `[[solution]]` of a verify file: its
/// clamp coordinates (the paper's three, and every general one that moved)
/// and the discrete rod's unknowns polished by Newton shooting.
fn shooting(msg: &StateMessage, path: &Path, index: u64) -> Result<String> {
    use crate::model::rod::Parameter;
    use std::fmt::Write as _;
    let u = crate::study::verify::shooting_unknowns(&msg.model, &msg.state).map_err(|e| {
        IoError::Recording {
            path: path.into(),
            reason: format!("state {index}: {}", crate::study::error::describe(&e)),
        }
    })?;
    let c = &msg.state.clamps;
    let mut t = String::new();
    let _ = writeln!(
        t,
        "# state {index} of {}: the discrete rod's unknowns at N = {} polished by Newton \
         shooting on the continuum equations (s = 1 residual {:.1e}); at N they were\n# {:?}\n\
         # verify with: knotrod verify FILE --scene SCENE (the scene of the recording)",
        path.display(),
        msg.state.segments(),
        u.residual,
        u.discrete
    );
    let _ = writeln!(t, "[[solution]]\nname = \"state {index}\"");
    let general = !c.is_paper();
    for p in Parameter::ALL.iter().chain(Parameter::MODEL.iter()) {
        let v = p.value(c);
        let paper = matches!(p, Parameter::ZStar | Parameter::Delta | Parameter::Phi);
        if v.is_finite() && (paper || general || Parameter::MODEL.contains(p)) {
            let _ = writeln!(t, "{} = {v:?}", p.name());
        }
    }
    let p = &u.polished;
    let _ = writeln!(t, "n0 = [{:?}, {:?}, {:?}]", p[0], p[1], p[2]);
    if u.strip {
        let _ = writeln!(t, "u1_0 = {:?}\nm2_0 = {:?}\nu3_0 = {:?}", p[3], p[4], p[5]);
    } else {
        let _ = writeln!(t, "m0 = [{:?}, {:?}, {:?}]", p[3], p[4], p[5]);
    }
    Ok(t)
}
