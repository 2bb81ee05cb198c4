//! `knotrod map` and `knotrod merge`: the good-knot region of a scene.

use super::progress::Progress;
use crate::io::json::write_pretty;
use crate::io::live::LiveMap;
use crate::io::map_files::{LineFolder, Partial, merge as merge_parts, trace_cached};
use crate::io::output::{OutputKind, output_kind};
use crate::linalg::counters::{Work, within};
use crate::scene::MapSpec;
use crate::scene::{Job, Scene};
use crate::study::boundary::Traced;
use crate::study::map::{Line, Map, Map3};
use anyhow::{Context, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Map a scene (a plane, or a 3D map of slices), or one shard of it.
pub fn map(
    path: &Path,
    json: Option<PathBuf>,
    shard: Option<&str>,
    segments: Option<usize>,
    live: Option<&str>,
    allow_large: bool,
) -> Result<()> {
    let scene = Scene::load(path)?;
    if let Some(n) = segments {
        anyhow::ensure!(
            (4..=1_000_000).contains(&n),
            "--segments must be in 4..=1000000, got {n}"
        );
    }
    scene.check_budget(Job::Map, segments, allow_large)?;
    let scene = crate::cli::run::lab_scene(scene, segments)?;
    let spec = scene
        .map
        .clone()
        .context("the scene has no [map] section")?;
    let name = scene.file_stem("map");
    // a map keeps its lines, slices and plots beside its file
    if let Some(p) = &json {
        anyhow::ensure!(
            output_kind(p) == OutputKind::File,
            "--json {}: a map keeps its computed lines, slices and plots beside its \
             file; name a file (not standard output, a FIFO or a device)",
            p.display()
        );
    }
    let json = json.unwrap_or_else(|| PathBuf::from("recordings").join(format!("{name}.map.json")));
    let shard = match shard {
        Some(s) => Some(parse_shard(s)?),
        None => None,
    };
    let live = match live {
        Some(address) => {
            let l = LiveMap::start(address)?;
            let host = address.rsplit_once(':').map_or(address, |(h, _)| h);
            eprintln!(
                "live view at ws://{host}:{} (Foxglove: Open connection, Foxglove WebSocket; \
                 plot /map/points.value against /map/points.along)",
                l.port()
            );
            Some(l)
        }
        None => None,
    };
    let result = map_scene(&scene, &spec, &name, &json, shard, segments, live.as_ref());
    if let Some(l) = live {
        l.stop();
    }
    result
}

/// Map a scene's plane or slices (see [`map`]).
fn map_scene(
    scene: &Scene,
    spec: &MapSpec,
    name: &str,
    json: &Path,
    shard: Option<(usize, usize)>,
    segments: Option<usize>,
    live: Option<&LiveMap>,
) -> Result<()> {
    let Some(slices) = spec.slices.clone() else {
        return map_plane(scene, name, json, shard, segments, live).map(|_| ());
    };
    // a 3D map: one plane map per slice, each with its own file and cache
    let mut maps = Vec::new();
    for (k, v) in slices.values.iter().enumerate() {
        let slice = slices.scene(scene, k);
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
            live,
        )? {
            maps.push(m);
        }
    }
    if shard.is_some() {
        return Ok(());
    }
    let map3 = crate::study::map::assemble_3d(name, &slices, maps);
    write_pretty(json, &map3)?;
    print_map3(name, &map3, json)
}

/// Join partial maps into one map, written to `json`.
pub fn merge(parts: &[PathBuf], json: &Path) -> Result<()> {
    let map = merge_parts(parts)?;
    write_map(&map, json)
}

/// "good knots for z_star in [lo, hi]", one line per parameter.
fn print_good_ranges(
    out: &mut impl Write,
    ranges: &std::collections::BTreeMap<crate::model::rod::Parameter, [f64; 2]>,
) -> std::io::Result<()> {
    for (k, v) in ranges {
        writeln!(
            out,
            "  good knots for {} in [{:.5}, {:.5}]",
            k.name(),
            v[0],
            v[1]
        )?;
    }
    Ok(())
}

/// Print a 3D map, draw its slices and say where it was written.
fn print_map3(name: &str, map3: &Map3, json: &Path) -> Result<()> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "3D map of {name}: good volume {:.6}", map3.good_volume)?;
    print_good_ranges(&mut out, &map3.bounding_box)?;
    for ((v, a), t) in map3
        .slice_values
        .iter()
        .zip(&map3.slice_areas)
        .zip(&map3.traced_areas)
    {
        writeln!(
            out,
            "  {} = {v}: good area {a:.6}, traced {}",
            map3.slice_parameter.name(),
            t.map_or("—".to_string(), |t| format!("{t:.6}"))
        )?;
    }
    for p in crate::io::plot::island_slices(&json.with_extension(""), map3)? {
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
    live: Option<&LiveMap>,
) -> Result<Option<Map>> {
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
    let traced = match shard {
        Some((i, _)) if i != 0 => None,
        _ => Some(trace(scene, &spec, segments, &cache)?),
    };
    let lines = compute_lines(scene, &spec, &indices, segments, &cache, live)?;
    match shard {
        Some(sh) => {
            let part = Partial {
                scene: name.to_string(),
                spec,
                along: cont.parameter,
                range: cont.range,
                shard: sh,
                lines,
                traced,
            };
            write_pretty(json, &part)?;
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
            let map =
                crate::study::map::assemble(name, &spec, cont.parameter, cont.range, lines, traced);
            write_map(&map, json)?;
            Ok(Some(map))
        }
    }
}

/// The boundary walk of a plane, with a spinner (one sequential computation:
/// shard 0 carries it).
fn trace(scene: &Scene, spec: &MapSpec, segments: Option<usize>, cache: &Path) -> Result<Traced> {
    let work = Work::new();
    let spinner = Progress::spinner("boundary points", &work);
    let t = within(Some(&work), || {
        trace_cached(scene, spec, segments, cache, &|k, on| {
            spinner.item(format!("tracing the boundary: point {k}, on {on}"));
        })
    })?;
    spinner.finish();
    Ok(t)
}

/// The lines `indices` of a plane, with a progress bar.
fn compute_lines(
    scene: &Scene,
    spec: &MapSpec,
    indices: &[usize],
    segments: Option<usize>,
    cache: &Path,
    live: Option<&LiveMap>,
) -> Result<Vec<Line>> {
    let work = Work::new();
    let progress = Progress::bar(indices.len() as u64, "lines", &work);
    let store = LineFolder::create(cache, scene, spec, segments)?;
    let lines = within(Some(&work), || {
        crate::study::map::compute_lines(scene, spec, indices, segments, &store, &|l| {
            if let Some(live) = live
                && let Err(e) = live.line(l)
            {
                // the map goes on: the live view is a view
                eprintln!("live view: {e}");
            }
            progress.item(format!(
                "{} = {:.4}: {} good intervals",
                spec.parameter.name(),
                l.value,
                l.intervals.len()
            ));
        })
    })?;
    progress.finish();
    Ok(lines)
}

/// Write a plane map to `json`, print it, and draw it beside the file.
fn write_map(map: &Map, json: &Path) -> Result<()> {
    write_pretty(json, map)?;
    // a map streamed (`merge --json -`, a FIFO, a device) has no file to draw
    // its plots beside, and standard output holds the map alone
    if output_kind(json) == OutputKind::Stream {
        return Ok(print_map(map, &mut std::io::stderr().lock())?);
    }
    let mut out = std::io::stdout().lock();
    print_map(map, &mut out)?;
    writeln!(out, "map written to {}", json.display())?;
    for f in crate::io::plot::island_map(&json.with_extension(""), map)? {
        writeln!(out, "plot written to {}", f.display())?;
    }
    Ok(())
}

/// The map's region line by line, and its traced boundary.
fn print_map(map: &Map, out: &mut impl Write) -> std::io::Result<()> {
    let (swept, along) = (map.parameter.symbol(), map.along.symbol());
    writeln!(
        out,
        "map of {} over {} lines of {along}: good area {:.6} in ({swept}, {along})",
        map.scene,
        map.lines.len(),
        map.good_area,
    )?;
    print_good_ranges(out, &map.bounding_box)?;
    for l in &map.lines {
        let iv: Vec<String> = l.intervals.iter().map(|i| i.to_string()).collect();
        writeln!(
            out,
            "  {} = {:.4}: {}{}",
            map.parameter.name(),
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
    print_traced(map, out)
}

/// The traced boundary of a map: its pieces, area, box and checks.
fn print_traced(map: &Map, out: &mut impl Write) -> std::io::Result<()> {
    let Some(t) = &map.traced else {
        return Ok(());
    };
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
        writeln!(out, "  traced {} in [{:.5}, {:.5}]", k.name(), v[0], v[1])?;
    }
    if let Some(g) = &t.grid_check {
        writeln!(
            out,
            "  grid check: {} interval ends, largest {} deviation {:.2e}, lines counting other ends: {:?}",
            g.ends,
            map.along.symbol(),
            g.max_deviation,
            g.lines_with_other_count
        )?;
    }
    if let Some(why) = &t.stopped {
        writeln!(out, "  walk stopped: {why}")?;
    }
    if let Some(why) = &t.not_polished {
        writeln!(out, "  not polished on the continuum: {why}")?;
    }
    if let Some(p) = &t.polished {
        writeln!(
            out,
            "  polished on the continuum (tolerance {:.0e}): area {:.7} ± {:.1e} (polygon {:.7}), \
             points to {:.1e}, largest discrete − continuum {:.2e}",
            p.tolerance,
            p.area,
            p.area_error,
            p.area_polygon,
            p.largest_point_error,
            p.largest_shift
        )?;
        for c in &p.corners {
            writeln!(
                out,
                "    corner {}/{} at ({:.7}, {:.7}) ± {:.1e} (discrete ({:.5}, {:.5}))",
                c.between[0],
                c.between[1],
                c.point[0],
                c.point[1],
                c.error,
                c.discrete[0],
                c.discrete[1]
            )?;
        }
        for d in &p.dropped {
            writeln!(out, "    left out: {d}")?;
        }
    }
    Ok(())
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
