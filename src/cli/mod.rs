//! The `knotrod` command line.

use crate::geometry::closure::{extent, ray_closure};
use crate::geometry::knot::knot_type;
use crate::geometry::writhe::writhe_closed;
use crate::io::curve_file::read_points;
use crate::io::plot::{PlotPoint, bifurcation_diagram};
use crate::io::summary::{Summary, print_equilibrium, print_events};
use crate::report::validation;
use crate::scene::Scene;
use crate::study::error::StudyError;
use crate::study::run::run_scene;
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
        /// Record to this MCAP file (default: recordings/<scene>.mcap).
        #[arg(long)]
        record: Option<PathBuf>,
        /// Do not record.
        #[arg(long, conflicts_with = "record")]
        no_record: bool,
    },
    /// Channels, states, parameter range and events of a recording.
    Info {
        /// The MCAP recording.
        recording: PathBuf,
    },
    /// One recorded state as a table (csv, json) or a tube mesh (obj).
    Export {
        /// The MCAP recording.
        recording: PathBuf,
        /// Index of the state.
        #[arg(long, default_value_t = 0)]
        index: u64,
        /// csv | json | obj.
        #[arg(long, value_enum, default_value = "csv")]
        format: ExportFormat,
        /// Output file (default: stdout).
        #[arg(long)]
        out: Option<PathBuf>,
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
    /// Redraw the bifurcation diagram of a run's JSON summary or MCAP recording.
    Plot {
        /// The summary (`run --json`) or recording (`.mcap`).
        summary: PathBuf,
        /// Output stem (default: the summary's path without extension).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Map the good-knot region: a branch in φ per value of a second parameter.
    Map {
        /// Scene with [continuation] (the branches) and [map] (the grid).
        scene: PathBuf,
        /// Write the map here (default recordings/<scene>.map.json).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Compute only shard i of n ("i/n") and write a partial result.
        #[arg(long)]
        shard: Option<String>,
        /// Override the scene's number of segments.
        #[arg(long)]
        segments: Option<usize>,
    },
    /// Join partial maps (from `map --shard`) into one map.
    Merge {
        /// Partial results.
        parts: Vec<PathBuf>,
        /// Write the map here.
        #[arg(long)]
        json: PathBuf,
    },
    /// Time the standard workloads and the growth of per-step costs with N.
    Bench {
        /// Folder holding the scenes.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
        /// Also write the report as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
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

/// Export formats.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum ExportFormat {
    /// Nodes and material frames, one row per node.
    Csv,
    /// The full state.
    Json,
    /// A triangle mesh of the tube.
    Obj,
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
            record,
            no_record,
        } => run(
            &scene,
            json,
            segments,
            if no_record { None } else { Some(record) },
        ),
        Command::Info { recording } => {
            crate::io::export::info(&recording, &mut std::io::stdout().lock())
        }
        Command::Export {
            recording,
            index,
            format,
            out,
        } => crate::io::export::export(&recording, index, format, out.as_deref()),
        Command::Convergence { scene, segments } => convergence(&scene, &segments),
        Command::Knot {
            curve,
            closed,
            rays,
            json,
        } => knot(&curve, closed, rays, json),
        Command::Plot { summary, out } => {
            let stem = out.unwrap_or_else(|| summary.with_extension(""));
            let (title, points, events) = if summary.extension().is_some_and(|e| e == "mcap") {
                let rec = crate::io::recording::read_recording(&summary)?;
                let points: Vec<PlotPoint> = rec.scalars.iter().map(PlotPoint::from).collect();
                let title = summary
                    .file_stem()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .into_owned();
                (title, points, rec.events)
            } else {
                let text = std::fs::read_to_string(&summary)
                    .with_context(|| format!("cannot read {}", summary.display()))?;
                let s: Summary = serde_json::from_str(&text)
                    .with_context(|| format!("{} is not a knotrod summary", summary.display()))?;
                let points = s.equilibria.iter().map(PlotPoint::from).collect();
                (
                    format!("{} (N = {})", s.scene, s.segments),
                    points,
                    s.events,
                )
            };
            for f in bifurcation_diagram(&stem, &title, &points, &events)? {
                writeln!(std::io::stdout().lock(), "plot written to {}", f.display())?;
            }
            Ok(())
        }
        Command::Map {
            scene,
            json,
            shard,
            segments,
        } => map_command(&scene, json, shard.as_deref(), segments),
        Command::Merge { parts, json } => {
            let map = crate::io::map_files::merge(&parts)?;
            write_map(&map, &json)
        }
        Command::Bench { scenes, json } => {
            let r = crate::report::bench::run(&scenes)?;
            crate::report::bench::print(&r, &mut std::io::stdout().lock())?;
            if let Some(p) = json {
                std::fs::write(&p, serde_json::to_string_pretty(&r)? + "\n")
                    .with_context(|| format!("writing {}", p.display()))?;
            }
            Ok(())
        }
        Command::Validate { scenes } => {
            write!(std::io::stdout().lock(), "{}", validation::report(&scenes)?)?;
            Ok(())
        }
    }
}

/// Set by Ctrl-C / SIGTERM: the run stops at the next equilibrium and still
/// finalises its recording and summary.
static INTERRUPTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

fn run(
    path: &Path,
    json: Option<PathBuf>,
    segments: Option<usize>,
    record: Option<Option<PathBuf>>,
) -> Result<()> {
    let scene = Scene::load(path)?;
    let _ = ctrlc::set_handler(|| INTERRUPTED.store(true, std::sync::atomic::Ordering::SeqCst));
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
    let mut recorder = match record {
        Some(file) => {
            let file = file.unwrap_or_else(|| {
                PathBuf::from("recordings")
                    .join(format!("{}.mcap", scene.name.as_deref().unwrap_or("run")))
            });
            let text = std::fs::read_to_string(path).unwrap_or_default();
            Some(crate::io::recording::Recorder::create(
                &file,
                &text,
                &model,
                scene.model.rod_diameter,
            )?)
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
        let mut record = |eq: crate::analysis::equilibrium::Equilibrium| -> Result<()> {
            if let Some((w, _)) = stream.as_mut() {
                serde_json::to_writer(&mut *w, &eq)?;
                w.write_all(b"\n")?;
                w.flush()?;
            }
            if let Some(r) = recorder.as_mut() {
                r.record(&eq)?;
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
            if INTERRUPTED.load(std::sync::atomic::Ordering::SeqCst) {
                anyhow::bail!("interrupted (Ctrl-C): stopped after this equilibrium");
            }
            Ok(())
        };
        let mut observer = |eq| record(eq).map_err(|e| StudyError::Observer(e.into()));
        run_scene(&scene, segments, &mut observer)
    };
    progress.finish_and_clear();
    summary.equilibria = equilibria;
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "scene {} — {}, N = {} ({:.2} s, {} equilibria)",
        summary.scene,
        model.describe(),
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
    // the recording is finalised whatever happened, with what was computed
    if let Some(mut r) = recorder {
        r.events(&summary.events)?;
        let (file, states) = (r.path().to_path_buf(), r.len());
        r.finish()?;
        writeln!(
            out,
            "recording written to {} ({states} states)",
            file.display()
        )?;
    }
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
        let points: Vec<PlotPoint> = summary.equilibria.iter().map(PlotPoint::from).collect();
        for f in bifurcation_diagram(&stem, &title, &points, &summary.events)? {
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
        Some(e) => Err(e.into()),
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

fn write_map(map: &crate::study::map::Map, json: &Path) -> Result<()> {
    if let Some(dir) = json.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(json, serde_json::to_string_pretty(map)? + "\n")
        .with_context(|| format!("writing {}", json.display()))?;
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "map of {} over {} lines: good area {:.6}",
        map.scene,
        map.lines.len(),
        map.good_area
    )?;
    for (k, v) in &map.bounding_box {
        writeln!(out, "  good knots for {k} in [{:.5}, {:.5}]", v[0], v[1])?;
    }
    for l in &map.lines {
        let iv: Vec<String> = l.intervals.iter().map(|i| i.to_string()).collect();
        writeln!(
            out,
            "  {} = {:.4}: {}{}",
            map.parameter,
            l.value,
            if iv.is_empty() {
                "no good knots".into()
            } else {
                iv.join(" ")
            },
            l.error
                .as_deref()
                .map(|e| format!(" (FAILED: {e})"))
                .unwrap_or_default()
        )?;
    }
    if let Some(t) = &map.traced {
        writeln!(
            out,
            "traced boundary: {} pieces, {} points, {} equilibria, {}",
            t.pieces.len(),
            t.points,
            t.equilibria,
            if t.closed { "closed" } else { "open" }
        )?;
        for p in &t.pieces {
            let (a, b) = (p.points[0], p.points[p.points.len() - 1]);
            writeln!(
                out,
                "  {:<5} ({}) from ({:.5}, {:.5}) to ({:.5}, {:.5}), {} points",
                p.label,
                p.condition,
                a[0],
                a[1],
                b[0],
                b[1],
                p.points.len()
            )?;
        }
        if let Some(a) = t.area {
            writeln!(out, "  enclosed area {a:.6} (grid: {:.6})", map.good_area)?;
        }
        for (k, v) in &t.bounding_box {
            writeln!(out, "  traced {k} in [{:.5}, {:.5}]", v[0], v[1])?;
        }
        if let Some(g) = &t.grid_check {
            writeln!(
                out,
                "  grid check: {} interval ends, largest φ/2π deviation {:.2e}, lines counting other ends: {:?}",
                g.ends, g.max_phi_deviation, g.lines_with_other_count
            )?;
        }
        if let Some(why) = &t.stopped {
            writeln!(out, "  walk stopped: {why}")?;
        }
    }
    writeln!(out, "map written to {}", json.display())?;
    for f in crate::io::plot::island_map(&json.with_extension(""), map)? {
        writeln!(out, "plot written to {}", f.display())?;
    }
    Ok(())
}

fn map_command(
    path: &Path,
    json: Option<PathBuf>,
    shard: Option<&str>,
    segments: Option<usize>,
) -> Result<()> {
    let scene = Scene::load(path)?;
    let spec = scene
        .map
        .clone()
        .context("the scene has no [map] section")?;
    let name = scene.name.clone().unwrap_or_else(|| "map".into());
    let json = json.unwrap_or_else(|| PathBuf::from("recordings").join(format!("{name}.map.json")));
    let shard = match shard {
        Some(s) => Some(parse_shard(s)?),
        None => None,
    };
    let Some(slices) = spec.slices.clone() else {
        return map_plane(&scene, &name, &json, shard, segments).map(|_| ());
    };
    // a 3D map: one plane map per slice, each with its own file and cache
    let mut maps = Vec::new();
    for (k, v) in slices.values.iter().enumerate() {
        let slice = slices.scene(&scene, k);
        let stem = json.file_stem().and_then(|s| s.to_str()).unwrap_or("map");
        let file = json.with_file_name(format!("{stem}_slice{k}.json"));
        writeln!(
            std::io::stdout().lock(),
            "slice {k}: {} = {v}",
            slices.parameter.name()
        )?;
        if let Some(m) = map_plane(
            &slice,
            &format!("{name} ({} = {v})", slices.parameter.name()),
            &file,
            shard,
            segments,
        )? {
            maps.push(m);
        }
    }
    if shard.is_some() {
        return Ok(());
    }
    let map3 = crate::study::map::assemble_3d(&name, &slices, maps);
    std::fs::write(&json, serde_json::to_string_pretty(&map3)? + "\n")
        .with_context(|| format!("writing {}", json.display()))?;
    let mut out = std::io::stdout().lock();
    writeln!(out, "3D map of {name}: good volume {:.6}", map3.good_volume)?;
    for (k, v) in &map3.bounding_box {
        writeln!(out, "  good knots for {k} in [{:.5}, {:.5}]", v[0], v[1])?;
    }
    for ((v, a), t) in map3
        .slice_values
        .iter()
        .zip(&map3.slice_areas)
        .zip(&map3.traced_areas)
    {
        writeln!(
            out,
            "  {} = {v}: good area {a:.6}, traced {}",
            map3.slice_parameter,
            t.map_or("—".to_string(), |t| format!("{t:.6}"))
        )?;
    }
    for p in crate::io::plot::island_slices(&json.with_extension(""), &map3)? {
        writeln!(out, "plot written to {}", p.display())?;
    }
    writeln!(out, "3D map written to {}", json.display())?;
    Ok(())
}

/// One plane of a map (or one shard of it): returns the assembled map when
/// the whole plane was computed.
fn map_plane(
    scene: &Scene,
    name: &str,
    json: &Path,
    shard: Option<(usize, usize)>,
    segments: Option<usize>,
) -> Result<Option<crate::study::map::Map>> {
    let spec = scene
        .map
        .clone()
        .context("the scene has no [map] section")?;
    let cont = scene
        .continuation
        .as_ref()
        .context("the scene has no [continuation] section")?;
    let indices = match shard {
        Some(sh) => crate::study::map::shard_lines(&spec, sh),
        None => (0..spec.lines).collect(),
    };
    // computed lines are kept beside the output: an interrupted map resumes
    let cache = json.with_extension("lines");
    // the boundary walk is one sequential computation: shard 0 carries it
    let traced = match shard {
        Some((i, _)) if i != 0 => None,
        _ => {
            let spinner = indicatif::ProgressBar::new_spinner();
            let t =
                crate::io::map_files::trace_cached(scene, &spec, segments, &cache, &|k, on| {
                    spinner.set_message(format!("tracing the boundary: point {k}, on {on}"));
                    spinner.tick();
                })?;
            spinner.finish_and_clear();
            Some(t)
        }
    };
    let progress = indicatif::ProgressBar::new(indices.len() as u64);
    progress.set_style(
        indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} lines, ETA {eta} — {msg}")
            .unwrap(),
    );
    let store = crate::io::map_files::LineFolder::create(&cache)?;
    let lines = crate::study::map::compute_lines(scene, &spec, &indices, segments, &store, &|l| {
        progress.inc(1);
        progress.set_message(format!(
            "{} = {:.4}: {} good intervals",
            spec.parameter.name(),
            l.value,
            l.intervals.len()
        ));
    })?;
    progress.finish_and_clear();
    match shard {
        Some(sh) => {
            let part = crate::io::map_files::Partial {
                scene: name.to_string(),
                spec,
                phi_range: cont.range,
                shard: sh,
                lines,
                traced,
            };
            std::fs::write(json, serde_json::to_string_pretty(&part)? + "\n")
                .with_context(|| format!("writing {}", json.display()))?;
            writeln!(
                std::io::stdout().lock(),
                "partial map (shard {}/{}) written to {}",
                sh.0,
                sh.1,
                json.display()
            )?;
            Ok(None)
        }
        None => {
            let map = crate::study::map::assemble(name, &spec, cont.range, lines, traced);
            write_map(&map, json)?;
            Ok(Some(map))
        }
    }
}

/// Parse "i/n".
fn parse_shard(s: &str) -> Result<(usize, usize)> {
    let (i, n) = s.split_once('/').context("--shard takes i/n")?;
    let (i, n): (usize, usize) = (i.trim().parse()?, n.trim().parse()?);
    if n == 0 || i >= n {
        anyhow::bail!("--shard {s}: need 0 <= i < n");
    }
    Ok((i, n))
}
