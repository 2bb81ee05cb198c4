//! Figure 7: the islands of good knots, the grid of lines against the
//! boundary traced by two-parameter continuation.

use crate::model::rod::Parameter;
use crate::report::error::{Context, Result};
use crate::scene::MapSpec;
use crate::scene::Scene;
use crate::study::boundary::Traced;
use crate::study::map::{Line, Map};
use std::fmt::Write;
use std::path::Path;

/// The section "Figure 7-left" (Kirchhoff rod).
pub(super) fn kirchhoff_section(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\n## Figure 7-left: the island of good knots (Kirchhoff rod, δ = 0.05)\n"
    )?;
    s += &island_table(scenes, "fig7_island_kirchhoff", &["S", "W1", "W2", "X"])?;
    writeln!(
        s,
        "\nThe paper's island is bounded by the four curves S, W1, W2 and X (compare the traced curves above). At z* = 0.115 the paper's Figure 3 has good knots from W1 = 0.774 to W2 = 0.82 (two digits); the loop's crossings of that line are above. The two walls are one condition (the flip maps z to z* − z, so a symmetric knot touches both at once) and one curve round the island's lowest z*, named W1 and W2 on its two sides. S is the pitchfork of the flip-symmetric family (lowest eigenvalue zero). Where a grid end differs from the loop by more than the chords' error, the line's coarse continuation step jumped over a sliver of unwalled states between W2 and X; the refined line (table above) finds the traced W2."
    )?;
    Ok(s)
}

/// The section "Figure 7-right" (elastic strip).
pub(super) fn strip_section(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\n## Figure 7-right: the island of good knots (elastic strip, δ = 0.05)\n"
    )?;
    s += &island_table(scenes, "fig7_island_strip", &["W1", "W2", "X1", "X2"])?;
    writeln!(
        s,
        "\nThe strip's island is larger than the rod's (area and φ range), as the paper finds; the paper bounds it by W1, W2, X1 and X2 (compare the traced curves above). The grid shows a notch the paper does not describe: an unknotted wedge that enters the island from above at z* ≈ 0.17 and splits the good interval of each z* above it in two (see the Figure 8 table, same at N = 200). The walk shows what it is: not another curve but a fold of a crossing curve — the same strands (near the flip axis) pass through each other at two values of φ, and the walk follows that curve down into the notch and up again. Near the island's upper-left corner, where the two crossing curves meet, several segment pairs of nearly coincident strands are in contact at once and the walk turns through a few short corners there."
    )?;
    Ok(s)
}

/// A map's table, with its traced boundary compared with the curves the
/// paper names (`paper`).
fn island_table(scenes: &Path, name: &str, paper: &[&str]) -> Result<String> {
    let scene = Scene::load(&scenes.join(format!("{name}.toml")))?;
    let spec = scene.map.clone().context("fig7 scene has no [map]")?;
    let cont = scene
        .continuation
        .as_ref()
        .context("fig7 scene has no [continuation]")?;
    let map = island_map(&scene, &spec, name, cont.parameter, cont.range)?;
    let mut s = grid_table(&scene, &spec, &map, name)?;
    if let Some(t) = &map.traced {
        s += &traced_comparison(&scene, &spec, &map, t, paper)?;
    }
    Ok(s)
}

/// The map as `knotrod map` computes it: the grid of lines and the traced
/// boundary.
pub(super) fn island_map(
    scene: &Scene,
    spec: &MapSpec,
    name: &str,
    along: Parameter,
    range: [f64; 2],
) -> Result<Map> {
    let cache =
        std::env::temp_dir().join(format!("knotrod-validate-island-{}", std::process::id()));
    let indices: Vec<usize> = (0..spec.lines).collect();
    let lines = crate::study::map::compute_lines(
        scene,
        spec,
        &indices,
        None,
        &crate::io::map_files::LineFolder::create(&cache, scene, spec, None)?,
        &|_| {},
    )?;
    let traced = crate::io::map_files::trace_cached(scene, spec, None, &cache, &|_, _| {})?;
    let _ = std::fs::remove_dir_all(&cache);
    Ok(crate::study::map::assemble(
        name,
        spec,
        along,
        range,
        lines,
        Some(traced),
    ))
}

/// The good intervals of each grid line, and the good region's extent.
fn grid_table(scene: &Scene, spec: &MapSpec, map: &Map, name: &str) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "Command: `cargo run --release -- map scenes/{name}.toml` (N = {}, {} lines).\n",
        scene.model.segments, spec.lines
    )?;
    writeln!(
        s,
        "| z* | good interval(s) of φ/2π (lower boundary, upper boundary) |"
    )?;
    writeln!(s, "|---|---|")?;
    for l in &map.lines {
        let iv: Vec<String> = l.intervals.iter().map(|i| i.to_string()).collect();
        if !iv.is_empty() || l.error.is_some() {
            writeln!(
                s,
                "| {:.3} | {}{} |",
                l.value,
                iv.join(" "),
                l.error
                    .as_deref()
                    .map(|e| format!(" failed: {e}"))
                    .unwrap_or_default()
            )?;
        }
    }
    let bb = &map.bounding_box;
    writeln!(
        s,
        "\nGood knots for z* in [{:.3}, {:.3}] (lines {:.3} apart) and φ/2π in [{:.4}, {:.4}]; area {:.5} in the (z*, φ/2π) plane. Boundaries met: {}.",
        bb.get(&Parameter::ZStar).map_or(f64::NAN, |v| v[0]),
        bb.get(&Parameter::ZStar).map_or(f64::NAN, |v| v[1]),
        spec.value(1) - spec.value(0),
        bb.get(&Parameter::Phi).map_or(f64::NAN, |v| v[0]),
        bb.get(&Parameter::Phi).map_or(f64::NAN, |v| v[1]),
        map.good_area,
        map.grid_boundaries
            .keys()
            .cloned()
            .collect::<Vec<_>>()
            .join(", ")
    )?;
    Ok(s)
}

/// The traced boundary's table, its curves against the paper's, the grid
/// ends recomputed near it, and its crossings of the scene's own z*.
fn traced_comparison(
    scene: &Scene,
    spec: &MapSpec,
    map: &Map,
    t: &Traced,
    paper: &[&str],
) -> Result<String> {
    let mut s = traced_table(t)?;
    let mut ours: Vec<&str> = t.pieces.iter().map(|p| p.label.as_str()).collect();
    let order = ours.join(", ");
    ours.sort();
    let mut theirs = paper.to_vec();
    theirs.sort();
    writeln!(
        s,
        "Curves in walk order: {order}; {} the paper's ({}).",
        if ours == theirs {
            "exactly"
        } else {
            "not the same as"
        },
        paper.join(", ")
    )?;
    s += &refined_ends(scene, spec, map, t)?;
    // the loop across the scene's own z*, where the paper prints the
    // good interval of its Figure 3 (Kirchhoff rod)
    let z = spec.parameter.value(&scene.clamps());
    let mut cuts = t.cuts(z);
    cuts.sort_by(f64::total_cmp);
    let cuts: Vec<String> = cuts.iter().map(|c| format!("{c:.4}")).collect();
    writeln!(
        s,
        "\nThe loop crosses {} = {z} at φ/2π = {}.",
        spec.parameter.name(),
        cuts.join(", ")
    )?;
    Ok(s)
}

/// Grid ends more than 5e-4 from the traced loop, recomputed on their line
/// with a continuation step 20 times finer: a coarse step can jump over a
/// thin sliver of another class.
fn refined_ends(scene: &Scene, spec: &MapSpec, map: &Map, t: &Traced) -> Result<String> {
    let mut s = String::new();
    let mut fine = scene.clone();
    let c = fine
        .continuation
        .as_mut()
        .context("the map has a [continuation]")?;
    let step = c.max_step.unwrap_or(0.01) / 20.0;
    c.max_step = Some(step);
    for l in &map.lines {
        let far = far_ends(l, t);
        if far.is_empty() {
            continue;
        }
        if s.is_empty() {
            writeln!(
                s,
                "\nGrid ends more than 5e-4 from the loop, recomputed with a continuation step of {step} instead of {}:\n",
                step * 20.0
            )?;
            writeln!(
                s,
                "| z* | grid end | refined line's nearest end | traced loop |"
            )?;
            writeln!(s, "|---|---|---|---|")?;
        }
        s += &refined_rows(&fine, spec, l, far)?;
    }
    Ok(s)
}

/// The interval ends of a grid line more than 5e-4 in φ/2π from the traced
/// loop's nearest crossing of the line, as (grid end, loop crossing).
fn far_ends(l: &Line, t: &Traced) -> Vec<(f64, f64)> {
    let cuts = t.cuts(l.value);
    let nearest = |x: f64| {
        cuts.iter()
            .copied()
            .min_by(|a, b| (a - x).abs().total_cmp(&(b - x).abs()))
    };
    l.intervals
        .iter()
        .flat_map(|i| [i.lo, i.hi])
        .filter_map(|e| nearest(e).map(|c| (e, c)))
        .filter(|(e, c)| (e - c).abs() > 5e-4)
        .collect()
}

/// The line recomputed with the finer step, its nearest ends to the loop's
/// crossings `far`.
fn refined_rows(fine: &Scene, spec: &MapSpec, l: &Line, far: Vec<(f64, f64)>) -> Result<String> {
    let mut s = String::new();
    let refined = crate::study::map::line(fine, spec, l.index, None);
    let ends: Vec<(f64, String)> = refined
        .intervals
        .iter()
        .flat_map(|i| [(i.lo, i.lo_label.clone()), (i.hi, i.hi_label.clone())])
        .collect();
    for (e, loop_end) in far {
        let r = ends
            .iter()
            .min_by(|a, b| (a.0 - loop_end).abs().total_cmp(&(b.0 - loop_end).abs()));
        writeln!(
            s,
            "| {:.3} | {:.5} | {} | {:.5} |",
            l.value,
            e,
            r.map_or("—".to_string(), |r| format!("{:.5} ({})", r.0, r.1)),
            loop_end
        )?;
    }
    Ok(s)
}

/// The boundary walked by two-parameter continuation, against the grid.
fn traced_table(t: &Traced) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\nThe boundary traced directly (two-parameter continuation of each condition, the good region on the left, turning at each corner onto the condition that fails there): {} points, {} equilibria solved, {}.\n",
        t.points,
        t.equilibria,
        if t.closed {
            "the walk closes on its start".to_string()
        } else {
            format!("open: {}", t.stopped.as_deref().unwrap_or("?"))
        }
    )?;
    writeln!(
        s,
        "| curve | condition | from (z*, φ/2π) | to (z*, φ/2π) | points |"
    )?;
    writeln!(s, "|---|---|---|---|---|")?;
    for p in &t.pieces {
        let (a, b) = (p.points[0], p.points[p.points.len() - 1]);
        writeln!(
            s,
            "| {} | {} | ({:.4}, {:.4}) | ({:.4}, {:.4}) | {} |",
            p.label,
            p.condition,
            a[0],
            a[1],
            b[0],
            b[1],
            p.points.len()
        )?;
    }
    s += &traced_extent(t)?;
    Ok(s)
}

/// The traced loop's extent and area, and its check against the grid.
fn traced_extent(t: &Traced) -> Result<String> {
    let mut s = String::new();
    let bb = &t.bounding_box;
    let range = |k: Parameter| bb.get(&k).copied().unwrap_or([f64::NAN; 2]);
    writeln!(
        s,
        "\nTraced extent: z* in [{:.4}, {:.4}], φ/2π in [{:.4}, {:.4}]; enclosed area {}.",
        range(Parameter::ZStar)[0],
        range(Parameter::ZStar)[1],
        range(Parameter::Phi)[0],
        range(Parameter::Phi)[1],
        t.area.map_or("—".to_string(), |a| format!("{a:.5}"))
    )?;
    if let Some(g) = &t.grid_check {
        writeln!(
            s,
            "Check against the grid: {} interval ends of the lines the loop spans lie within {:.1e} in φ/2π of the loop's crossings of those lines (chords of the traced polyline against bisected events); lines where the loop and the grid count different ends: {}.",
            g.ends,
            g.max_deviation,
            if g.lines_with_other_count.is_empty() {
                "none".to_string()
            } else {
                g.lines_with_other_count
                    .iter()
                    .map(|v| format!("{v:.3}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        )?;
    }
    Ok(s)
}
