//! Figure 10 and the experiment: the strip's island at δ = 0.10 for zero
//! width, for the lab's ribbon, and for that ribbon under its weight with
//! the major loop facing down and up; the photographed knot's verdicts.

use crate::analysis::equilibrium::analyse;
use crate::report::error::{Context, Result};
use crate::scene::Scene;
use crate::study::boundary::PolishedBoundary;
use crate::study::start::{in_the_lab, starting_equilibrium};
use std::fmt::Write;
use std::path::Path;

/// The cases: scene, what it adds. The first four are the paper's figure's
/// (checked again from N = 200), the rest plastify (b), (c) and (d).
const CASES: [(&str, &str); 10] = [
    ("fig10_island", "(a) zero width"),
    ("fig10_island_ribbon", "(b) ribbon w/L = 0.057"),
    (
        "fig10_island_down",
        "(c) ribbon, weight 25, major loop down",
    ),
    ("fig10_island_up", "(d) ribbon, weight 25, major loop up"),
    ("fig10_island_plastic_plus", "(e+) (b) plastified, û1 > 0"),
    ("fig10_island_plastic_minus", "(e−) (b) plastified, û1 < 0"),
    (
        "fig10_island_down_plastic_plus",
        "(f+) (c) plastified, û1 > 0",
    ),
    (
        "fig10_island_down_plastic_minus",
        "(f−) (c) plastified, û1 < 0",
    ),
    (
        "fig10_island_up_plastic_plus",
        "(g+) (d) plastified, û1 > 0",
    ),
    (
        "fig10_island_up_plastic_minus",
        "(g−) (d) plastified, û1 < 0",
    ),
];

/// The cases checked again from N = 200.
const FINE_CHECKED: usize = 4;

/// The lab strips' end deflection once unclamped (paper Sec. 5: "about 5 %").
const END_DEFLECTION: f64 = 0.05;

/// The photographed knot (paper Figure 10-left and Figure 1).
const PHOTOGRAPHED: [f64; 2] = [0.17, 0.78];

/// One case's island and the photographed knot in it.
struct Case {
    what: &'static str,
    polished: Option<PolishedBoundary>,
    why_not: Option<String>,
    discrete_area: Option<f64>,
    grid_deviation: Option<f64>,
    gravity: Option<[f64; 3]>,
    /// The polished area ± error again from N = 200 (the ribbon's cases),
    /// or why there is none.
    at_200: Option<std::result::Result<(f64, f64), String>>,
    photographed: String,
}

/// The section "Figure 10 and the experiment".
pub(super) fn section(scenes: &Path) -> Result<String> {
    let mut s = String::new();
    writeln!(s, "\n## Figure 10 and the experiment\n")?;
    writeln!(
        s,
        "Commands: `cargo run --release -- map scenes/NAME.toml` for NAME in {} (N = 100, 25 lines, the boundary polished on the continuum). The strip at δ = 0.10 (Sadowsky law); the ribbon is the surface r + v d1, |v| ≤ w/2, on which walls, self-contact and crossings are measured (docs/design.md, \"Finite width\"); the weight w_g = 12(1 − ν²)ρgL³/(Eh²) ≈ 25 acts across the clamps' axis, along (down) or against (up) the weightless start's major loop at the photographed knot (z* = 0.17, φ/2π = 0.78), fixed while the island is traced.\n",
        CASES
            .iter()
            .map(|(n, _)| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", ")
    )?;
    let plastic =
        crate::model::natural::arc_curvature(END_DEFLECTION).context("the lab's end deflection")?;
    writeln!(
        s,
        "Plastification (e±, f±, g±): the lab's strips were slightly plastified, \"an end deflection of about {:.0} % of the length once unclamped\". Read as a uniform natural curvature û1 whose stress-free arc, held at one end, ends {END_DEFLECTION}·L off its tangent ((1 − cos û1)/û1 = {END_DEFLECTION}): |û1| = {plastic:.6} (scenes: `natural_strains = {{ end_deflection = ±{END_DEFLECTION} }}`); û1 > 0 turns the tangent towards −d2. The paper says neither its sign nor its direction, so both are computed.\n",
        100.0 * END_DEFLECTION
    )?;
    let cases = CASES
        .iter()
        .enumerate()
        .map(|(k, &(name, what))| case(scenes, name, what, k < FINE_CHECKED))
        .collect::<Result<Vec<_>>>()?;
    writeln!(
        s,
        "| case | gravity | polished area ± error | from N = 200 | z* range | φ/2π range | corners (z*, φ/2π) | discrete area | grid ends vs walk (φ/2π) |"
    )?;
    writeln!(s, "|---|---|---|---|---|---|---|---|---|")?;
    for c in &cases {
        // a component zero to the printed digits as 0.000, not −0.000
        let shown = |x: f64| if x.abs() < 5e-4 { 0.0 } else { x };
        let gravity = c.gravity.map_or("none".into(), |g| {
            format!(
                "({:.3}, {:.3}, {:.3})",
                shown(g[0]),
                shown(g[1]),
                shown(g[2])
            )
        });
        let opt = |v: Option<f64>, f: &dyn Fn(f64) -> String| v.map_or("—".into(), f);
        let discrete = opt(c.discrete_area, &|a| format!("{a:.6}"));
        let deviation = opt(c.grid_deviation, &|d| format!("{d:.1e}"));
        let at_200 = match &c.at_200 {
            None => "—".into(),
            Some(Ok((a, e))) => format!("{a:.7} ± {e:.1e}"),
            Some(Err(why)) => why.clone(),
        };
        match &c.polished {
            Some(p) => {
                let (z, phi) = ranges(p);
                let corners: Vec<String> = p
                    .corners
                    .iter()
                    .map(|k| {
                        format!(
                            "{}/{} ({:.5}, {:.5}) ± {:.0e}",
                            k.between[0], k.between[1], k.point[0], k.point[1], k.error
                        )
                    })
                    .collect();
                writeln!(
                    s,
                    "| {} | {gravity} | {:.7} ± {:.1e} | {at_200} | [{:.4}, {:.4}] | [{:.4}, {:.4}] | {} | {discrete} | {deviation} |",
                    c.what,
                    p.area,
                    p.area_error,
                    z[0],
                    z[1],
                    phi[0],
                    phi[1],
                    corners.join("; ")
                )?;
            }
            None => writeln!(
                s,
                "| {} | {gravity} | not polished: {} | {at_200} | | | | {discrete} | {deviation} |",
                c.what,
                c.why_not.as_deref().unwrap_or("no closed boundary")
            )?,
        }
    }
    let area = |k: usize| cases[k].polished.as_ref().map(|p| p.area);
    if let (Some(a), Some(b), Some(c), Some(d)) = (area(0), area(1), area(2), area(3)) {
        writeln!(
            s,
            "\nWhat each effect does to the island's area: the width takes it from {a:.5} to {b:.5} ({:+.1} %); the weight, the major loop down, to {c:.5} ({:+.1} % of the ribbon's), up, to {d:.5} ({:+.1} %); down and up differ by {:.1} % of the ribbon's island.",
            100.0 * (b / a - 1.0),
            100.0 * (c / b - 1.0),
            100.0 * (d / b - 1.0),
            100.0 * (c - d).abs() / b
        )?;
        if let (Some(ep), Some(em), Some(fp), Some(fm), Some(gp), Some(gm)) =
            (area(4), area(5), area(6), area(7), area(8), area(9))
        {
            writeln!(
                s,
                "Plastification takes the ribbon's island to {ep:.5} (û1 > 0, {:+.1} %) or {em:.5} (û1 < 0, {:+.1} %); under its weight facing down to {fp:.5} ({:+.1} % of (c)'s) or {fm:.5} ({:+.1} %), facing up to {gp:.5} ({:+.1} % of (d)'s) or {gm:.5} ({:+.1} %).",
                100.0 * (ep / b - 1.0),
                100.0 * (em / b - 1.0),
                100.0 * (fp / c - 1.0),
                100.0 * (fm / c - 1.0),
                100.0 * (gp / d - 1.0),
                100.0 * (gm / d - 1.0),
            )?;
        }
    }
    writeln!(
        s,
        "\nThe photographed knot (z* = {}, φ/2π = {}, δ = 0.10; the paper: good, facing down), solved at N = 100 from the unfolded double ring:\n",
        PHOTOGRAPHED[0], PHOTOGRAPHED[1]
    )?;
    writeln!(s, "| case | verdict |")?;
    writeln!(s, "|---|---|")?;
    for c in &cases {
        writeln!(s, "| {} | {} |", c.what, c.photographed)?;
    }
    Ok(s)
}

/// The case's map as `knotrod map` computes it (its gravity fixed first),
/// and the photographed knot under its model.
fn case(scenes: &Path, name: &'static str, what: &'static str, fine: bool) -> Result<Case> {
    let scene = Scene::load(&scenes.join(format!("{name}.toml")))?;
    let gravity = scene.load.major_loop.is_some();
    let scene = in_the_lab(&scene, None)?.into_owned();
    let spec = scene.map.clone().context("fig10 scene has no [map]")?;
    let cont = scene
        .continuation
        .as_ref()
        .context("fig10 scene has no [continuation]")?;
    let map = super::islands::island_map(&scene, &spec, name, cont.parameter, cont.range)?;
    let traced = map.traced.as_ref();
    // the ribbon's islands again from N = 200: the polish removes the
    // discrete rod's error, so the areas agree to their bars
    let at_200 = if fine && scene.model.strip_width > 0.0 {
        let mut fine = scene.clone();
        fine.model.segments = 200;
        let m = super::islands::island_map(&fine, &spec, name, cont.parameter, cont.range)?;
        Some(match m.traced {
            Some(t) => match (t.polished, t.not_polished, t.stopped) {
                (Some(p), _, _) => Ok((p.area, p.area_error)),
                (None, Some(f), _) => Err(format!("not polished: {f}")),
                (None, None, Some(why)) => Err(format!("walk stopped: {why}")),
                (None, None, None) => Err("not polished".into()),
            },
            None => Err("no boundary traced".into()),
        })
    } else {
        None
    };
    Ok(Case {
        what,
        polished: traced.and_then(|t| t.polished.clone()),
        why_not: traced.and_then(|t| t.not_polished.as_ref().map(|f| f.to_string())),
        discrete_area: traced.filter(|t| t.closed).and_then(|t| t.area),
        grid_deviation: traced.and_then(|t| t.grid_check.as_ref().map(|g| g.max_deviation)),
        gravity: gravity.then_some(scene.load.direction),
        at_200,
        photographed: photographed(&scene, traced.and_then(|t| t.polished.as_ref()))?,
    })
}

/// Whether the photographed knot is a good knot under the scene's model,
/// and why not; and whether the polished boundary encloses it.
fn photographed(scene: &Scene, polished: Option<&PolishedBoundary>) -> Result<String> {
    let mut at = scene.clone();
    at.map = None;
    at.clamps.z_star = PHOTOGRAPHED[0];
    at.clamps.phi_over_2pi = PHOTOGRAPHED[1];
    let (mut newton, state, report) = starting_equilibrium(&at, None)?;
    let eq = analyse(&mut newton, &state, &report, &at.measure())?;
    let mut why = Vec::new();
    if !eq.walled {
        why.push(format!("not walled (clearance {:.4})", eq.wall_distance));
    }
    if !eq.stable {
        why.push("unstable".to_string());
    }
    if !eq.knotted {
        why.push(format!(
            "not the trefoil ({})",
            eq.knot_name.as_deref().unwrap_or("no knot type")
        ));
    }
    if eq.min_self_distance <= 0.0 {
        why.push("touching itself".to_string());
    }
    let verdict = if eq.good_knot {
        format!(
            "good (wall clearance {:.4}, self-distance {:.4}, lowest ω² {:.1})",
            eq.wall_distance,
            eq.min_self_distance,
            eq.omega_squared.first().copied().unwrap_or(f64::NAN)
        )
    } else if why.is_empty() {
        "not good".to_string()
    } else {
        format!("not good: {}", why.join(", "))
    };
    let inside = polished.map(|p| {
        if p.encloses(PHOTOGRAPHED) {
            "; inside the polished island"
        } else {
            "; outside the polished island"
        }
    });
    Ok(format!("{verdict}{}", inside.unwrap_or_default()))
}

/// The polished boundary's extent in z* and φ/2π.
fn ranges(p: &PolishedBoundary) -> ([f64; 2], [f64; 2]) {
    let mut z = [f64::INFINITY, f64::NEG_INFINITY];
    let mut phi = z;
    for q in p.polygon() {
        z = [z[0].min(q[0]), z[1].max(q[0])];
        phi = [phi[0].min(q[1]), phi[1].max(q[1])];
    }
    (z, phi)
}
