//! The `knotrod` command line.

use crate::geometry::closure::{extent, ray_closure};
use crate::geometry::knot::knot_type;
use crate::geometry::polyline::read_points;
use crate::geometry::writhe::writhe_closed;
use crate::plot::bifurcation_diagram;
use crate::run::run_scene;
use crate::scene::Scene;
use crate::summary::{Summary, print_equilibrium, print_events};
use crate::validation;
use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use nalgebra::Vector3;
use std::io::Write;
use std::path::{Path, PathBuf};

/// knotrod: equilibria and stability of clamped elastic rods.
#[derive(Parser, Debug)]
#[command(version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Solve a scene and print its equilibrium.
    Run {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Write the JSON summary here.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Override the scene's number of segments.
        #[arg(long)]
        segments: Option<usize>,
    },
    /// Writhe and knot type of any curve (one "x y z" or "x,y,z" point per line).
    Knot {
        /// The curve file.
        curve: PathBuf,
        /// The curve is a closed loop (last point joins the first).
        #[arg(long)]
        closed: bool,
        /// How an open curve is closed: by rays along its end tangents, or
        /// along ∓z from the first and last points (the paper's closure).
        #[arg(long, value_enum, default_value = "tangent")]
        rays: RayKind,
        /// Write a JSON answer here ("-" for stdout).
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Redraw the bifurcation diagram of a run's JSON summary.
    Plot {
        /// The summary (written by `run --json`).
        summary: PathBuf,
        /// Output stem (default: the summary's path without extension).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Regenerate the validation report (docs/validation.md) on stdout.
    Validate {
        /// Folder holding the scenes.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
    },
    /// Convergence study in N of a scene's equilibrium (markdown table).
    Convergence {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Segment counts, comma separated.
        #[arg(long, value_delimiter = ',', default_value = "50,100,200,400,800")]
        segments: Vec<usize>,
    },
}

/// Directions of the closing rays of an open curve.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum RayKind {
    /// Along the end tangents.
    Tangent,
    /// Along −z from the first point and +z from the last.
    Z,
}

/// Run the command line.
pub fn main_with(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Run {
            scene,
            json,
            segments,
        } => run(&scene, json, segments),
        Command::Convergence { scene, segments } => convergence(&scene, &segments),
        Command::Knot {
            curve,
            closed,
            rays,
            json,
        } => knot(&curve, closed, rays, json),
        Command::Plot { summary, out } => {
            let text = std::fs::read_to_string(&summary)
                .with_context(|| format!("cannot read {}", summary.display()))?;
            let s: Summary = serde_json::from_str(&text)
                .with_context(|| format!("{} is not a knotrod summary", summary.display()))?;
            let stem = out.unwrap_or_else(|| summary.with_extension(""));
            let title = format!("{} (N = {})", s.scene, s.segments);
            for f in bifurcation_diagram(&stem, &title, &s.equilibria, &s.events)? {
                writeln!(std::io::stdout().lock(), "plot written to {}", f.display())?;
            }
            Ok(())
        }
        Command::Validate { scenes } => {
            write!(std::io::stdout().lock(), "{}", validation::report(&scenes)?)?;
            Ok(())
        }
    }
}

fn run(path: &Path, json: Option<PathBuf>, segments: Option<usize>) -> Result<()> {
    let scene = Scene::load(path)?;
    if let Some(n) = segments {
        anyhow::ensure!(
            (4..=1_000_000).contains(&n),
            "--segments must be in 4..=1000000, got {n}"
        );
    }
    let model = scene.rod_model(segments);
    let start = std::time::Instant::now();
    let json = json.or(scene.output.json.clone());
    let mut summary = Summary::new(&scene, &model);
    // results are streamed as they come (one JSON line per equilibrium)
    let mut stream = match &json {
        Some(p) => {
            if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir)?;
            }
            let lines = p.with_extension("jsonl");
            Some((
                std::io::BufWriter::new(
                    std::fs::File::create(&lines)
                        .with_context(|| format!("creating {}", lines.display()))?,
                ),
                lines,
            ))
        }
        None => None,
    };
    let progress = indicatif::ProgressBar::new_spinner();
    progress.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {elapsed} {pos} equilibria — {msg}")
            .unwrap(),
    );
    let mut equilibria = Vec::new();
    let result = {
        let mut observer = |eq: crate::equilibrium::Equilibrium| -> Result<()> {
            if let Some((w, _)) = stream.as_mut() {
                serde_json::to_writer(&mut *w, &eq)?;
                w.write_all(b"\n")?;
                w.flush()?;
            }
            progress.inc(1);
            progress.set_message(format!(
                "branch {}: z* = {:.4}, δ = {:.4}, φ/2π = {:.4}, Tw = {:.4}{}",
                eq.branch,
                eq.z_star,
                eq.delta,
                eq.phi_over_2pi,
                eq.twist,
                if eq.stable { "" } else { " (unstable)" }
            ));
            equilibria.push(eq);
            Ok(())
        };
        run_scene(&scene, segments, &mut observer)
    };
    progress.finish_and_clear();
    summary.equilibria = equilibria;
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "scene {} — Kirchhoff rod, K2 = {}, K3 = {}, N = {} ({:.2} s, {} equilibria)",
        summary.scene,
        model.k2,
        model.k3,
        model.segments,
        start.elapsed().as_secs_f64(),
        summary.equilibria.len()
    )?;
    let failed = match result {
        Ok(events) => {
            summary.events = events;
            None
        }
        Err(e) => Some(e),
    };
    if scene.continuation.is_none() && scene.loading.is_empty() {
        if let Some(eq) = summary.equilibria.first() {
            print_equilibrium(eq, &scene, &mut out)?;
        }
    } else {
        print_events(&summary.events, &mut out)?;
        let stem = json
            .clone()
            .unwrap_or_else(|| PathBuf::from("recordings").join(&summary.scene));
        if let Some(dir) = stem.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        let title = format!("{} (N = {})", summary.scene, summary.segments);
        for f in bifurcation_diagram(&stem, &title, &summary.equilibria, &summary.events)? {
            writeln!(out, "plot written to {}", f.display())?;
        }
    }
    // the summary is written whatever happened, with what was computed
    if let Some(path) = &json {
        summary
            .write(path)
            .with_context(|| format!("writing {}", path.display()))?;
        writeln!(out, "summary written to {}", path.display())?;
    }
    match failed {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

fn convergence(path: &Path, segments: &[usize]) -> Result<()> {
    let scene = Scene::load(path)?;
    write!(
        std::io::stdout().lock(),
        "{}",
        validation::convergence_table(&scene, segments)?
    )?;
    Ok(())
}

fn knot(path: &Path, closed: bool, rays: RayKind, json: Option<PathBuf>) -> Result<()> {
    let points = read_points(path)?;
    let (writhe, kt) = if closed {
        (writhe_closed(&points), knot_type(&points))
    } else {
        let m = points.len();
        let (bottom, top) = match rays {
            RayKind::Tangent => (points[0] - points[1], points[m - 1] - points[m - 2]),
            RayKind::Z => (-Vector3::z(), Vector3::z()),
        };
        let size = extent(&points).max(1e-300);
        // writhe error of the closure decays as 1/(ray length)
        let w = writhe_closed(&ray_closure(&points, bottom, top, 1e6 * size));
        (
            w,
            knot_type(&ray_closure(
                &points,
                bottom,
                top,
                2.0 * size + size.max(1.0),
            )),
        )
    };
    let answer = serde_json::json!({
        "curve": path.display().to_string(),
        "points": points.len(),
        "closed": closed,
        "writhe": writhe,
        "knot_determinant": kt.determinant,
        "alexander": kt.alexander,
        "knot_name": kt.name,
        "crossings": kt.crossings,
        "projections": kt.directions,
        "ambiguous": kt.ambiguous,
    });
    let mut out = std::io::stdout().lock();
    match json {
        Some(p) if p.as_os_str() == "-" => {
            writeln!(out, "{}", serde_json::to_string_pretty(&answer)?)?
        }
        other => {
            writeln!(
                out,
                "curve {} ({} points, {})",
                path.display(),
                points.len(),
                if closed { "closed" } else { "closed by rays" }
            )?;
            writeln!(out, "  writhe {writhe:.6}")?;
            writeln!(out, "  knot determinant {}", kt.determinant)?;
            writeln!(out, "  Alexander polynomial {}", polynomial(&kt.alexander))?;
            writeln!(
                out,
                "  likely knot {}",
                kt.name
                    .as_deref()
                    .unwrap_or("not in the table (more than 7 crossings?)")
            )?;
            if kt.ambiguous {
                writeln!(
                    out,
                    "  AMBIGUOUS: projections disagree or are degenerate (the curve may pass through itself)"
                )?;
            }
            if let Some(p) = other {
                std::fs::write(&p, serde_json::to_string_pretty(&answer)? + "\n")
                    .with_context(|| format!("writing {}", p.display()))?;
            }
        }
    }
    Ok(())
}

/// Δ(t) as text, e.g. "1 - t + t^2".
fn polynomial(c: &[i64]) -> String {
    if c.is_empty() {
        return "unknown".into();
    }
    let mut s = String::new();
    for (j, &a) in c.iter().enumerate().filter(|(_, a)| **a != 0) {
        let mag = a.unsigned_abs();
        let sign = if a < 0 { "-" } else { "+" };
        if s.is_empty() {
            if a < 0 {
                s.push('-');
            }
        } else {
            s += &format!(" {sign} ");
        }
        let coef = if mag == 1 && j > 0 {
            String::new()
        } else {
            mag.to_string()
        };
        s += &match j {
            0 => mag.to_string(),
            1 => format!("{coef}t"),
            _ => format!("{coef}t^{j}"),
        };
    }
    s
}
