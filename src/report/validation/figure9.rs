//! Figure 9: the good knots of the strip in (δ, z*, φ), one island map per
//! slice of δ.

use crate::model::rod::Parameter;
use crate::report::error::{Context, Result};
use crate::scene::Scene;
use crate::scene::SliceSpec;
use crate::study::map::Map3;
use std::fmt::Write;
use std::path::Path;

/// The section "Figure 9: good knots of the strip in (δ, z*, φ)".
pub(super) fn section(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(s, "\n## Figure 9: good knots of the strip in (δ, z*, φ)\n")?;
    s += &map3_table(scenes)?;
    Ok(s)
}

/// The 3D map's slices, the highest-reaching slice traced again at 2N, and
/// the good volume.
fn map3_table(scenes: &Path) -> Result<String> {
    let scene = Scene::load(&scenes.join("fig9_strip_3d.toml"))?;
    let spec = scene.map.clone().context("fig9 scene has no [map]")?;
    let slices = spec
        .slices
        .clone()
        .context("fig9 scene has no [map.slices]")?;
    let cont = scene.continuation.as_ref().context("no [continuation]")?;
    let m3 = slice_maps(&scene, &slices, cont.parameter, cont.range)?;
    let mut s = String::new();
    writeln!(
        s,
        "Command: `cargo run --release -- map scenes/fig9_strip_3d.toml` (N = {}, {} lines per slice).\n",
        scene.model.segments, spec.lines
    )?;
    s += &slice_table(&m3)?;
    s += &highest_slice(&scene, &slices, &m3)?;
    let b = |k: Parameter| {
        m3.bounding_box
            .get(&k)
            .map_or("—".to_string(), |b| format!("[{:.3}, {:.3}]", b[0], b[1]))
    };
    writeln!(
        s,
        "\nGood volume {:.5} in (δ, z*, φ/2π); bounding box δ {}, z* {}, φ/2π {}. The paper: no good knots outside 0.01 < δ < 0.3, 0.05 < z* < 0.45, 0.02 < 1 − φ/2π < 0.5.",
        m3.good_volume,
        b(Parameter::Delta),
        b(Parameter::ZStar),
        b(Parameter::Phi)
    )?;
    Ok(s)
}

/// Each slice's island map (grid and traced boundary), assembled in 3D.
fn slice_maps(
    scene: &Scene,
    slices: &SliceSpec,
    along: Parameter,
    range: [f64; 2],
) -> Result<Map3> {
    let mut maps = Vec::new();
    for k in 0..slices.values.len() {
        let slice = slices.scene(scene, k);
        let sspec = slice.map.clone().unwrap();
        let cache =
            std::env::temp_dir().join(format!("knotrod-validate-fig9-{}-{k}", std::process::id()));
        let idx: Vec<usize> = (0..sspec.lines).collect();
        let lines = crate::study::map::compute_lines(
            &slice,
            &sspec,
            &idx,
            None,
            &crate::io::map_files::LineFolder::create(&cache, &slice, &sspec, None)?,
            &|_| {},
        )?;
        let traced = crate::io::map_files::trace_cached(&slice, &sspec, None, &cache, &|_, _| {})?;
        let _ = std::fs::remove_dir_all(&cache);
        maps.push(crate::study::map::assemble(
            "fig9",
            &sspec,
            along,
            range,
            lines,
            Some(traced),
        ));
    }
    Ok(crate::study::map::assemble_3d(
        "fig9_strip_3d",
        slices,
        maps,
    ))
}

/// One row per slice: the grid's good area and extent against the traced
/// boundary's.
fn slice_table(m3: &Map3) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "| δ | good area (grid) | z* range | φ/2π range | traced boundary: area, z* range, φ/2π range | largest φ/2π gap to the grid's ends |\n|---|---|---|---|---|---|"
    )?;
    for (m, v) in m3.slices.iter().zip(&m3.slice_values) {
        let r = |b: &std::collections::BTreeMap<Parameter, [f64; 2]>, k: Parameter| {
            b.get(&k)
                .map_or("—".to_string(), |b| format!("[{:.3}, {:.3}]", b[0], b[1]))
        };
        let traced = match &m.traced {
            Some(t) if t.closed => format!(
                "{:.5}, {}, {}",
                t.area.unwrap_or(f64::NAN),
                r(&t.bounding_box, Parameter::ZStar),
                r(&t.bounding_box, Parameter::Phi)
            ),
            Some(t) => format!("open: {}", t.stopped.as_deref().unwrap_or("?")),
            None => "—".to_string(),
        };
        let gap = m
            .traced
            .as_ref()
            .and_then(|t| t.grid_check.as_ref())
            .map_or("—".to_string(), |g| {
                format!("{:.1e} ({} ends)", g.max_deviation, g.ends)
            });
        writeln!(
            s,
            "| {v} | {:.5} | {} | {} | {traced} | {gap} |",
            m.good_area,
            r(&m.bounding_box, Parameter::ZStar),
            r(&m.bounding_box, Parameter::Phi)
        )?;
    }
    Ok(s)
}

/// The slice whose traced region reaches highest in z*, traced again at 2N.
fn highest_slice(scene: &Scene, slices: &SliceSpec, m3: &Map3) -> Result<String> {
    let mut s = String::new();
    let top = m3
        .slices
        .iter()
        .enumerate()
        .filter_map(|(k, m)| {
            let t = m.traced.as_ref().filter(|t| t.closed)?;
            Some((k, t.bounding_box.get(&Parameter::ZStar)?[1]))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((k, zmax)) = top {
        let slice = slices.scene(scene, k);
        let sspec = slice.map.clone().unwrap();
        let n = 2 * scene.model.segments as usize;
        let t = crate::study::boundary::trace_island(&slice, &sspec, Some(n), &|_, _| {})?;
        let fine = t
            .bounding_box
            .get(&Parameter::ZStar)
            .map_or("—".to_string(), |b| format!("{:.4}", b[1]));
        writeln!(
            s,
            "\nThe traced region reaching highest, at δ = {}: largest z* {zmax:.4} at N = {}, {fine} at N = {n} (walk {}; area {}).",
            slices.values[k],
            scene.model.segments,
            if t.closed { "closed" } else { "open" },
            t.area.map_or("—".to_string(), |a| format!("{a:.5}"))
        )?;
    }
    Ok(s)
}
