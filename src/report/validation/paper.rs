//! The paper's Appendices D and E against knotrod's equilibria, and the
//! writhe of the ray closure against the rays' length.

use crate::analysis::equilibrium::Equilibrium;
use crate::geometry::closure::ray_closure;
use crate::geometry::writhe::writhe_closed;
use crate::io::summary::relative_deviation;
use crate::report::error::{Context, Result};
use crate::scene::{ReferenceSpec, Scene};
use crate::study::start::solve_scene;
use nalgebra::Vector3;
use std::fmt::Write;

/// The sections "Appendix D", "Appendix E" and "Writhe of the ray closure".
pub(super) fn sections(d: &Scene, e: &Scene) -> Result<String> {
    let mut s = String::new();
    writeln!(s, "\n## Appendix D (good knot), N = 200\n")?;
    s += &paper_table(d, 200)?;
    writeln!(
        s,
        "\n## Appendix E (stable, knotted, not walled), N = 200\n"
    )?;
    s += &paper_table(e, 200)?;
    writeln!(s, "\n## Writhe of the ray closure versus ray length\n")?;
    writeln!(
        s,
        "The rod closed by rays along ∓z and a far loop; the writhe's error decays as 1/(ray length), and summaries use 1e6. The link Tw + Wr equals 3 + φ/2π (Călugăreanu–White for the ribbon d1 closed by the clamps' frames).\n"
    )?;
    s += &writhe_table(&[d, e])?;
    Ok(s)
}

/// One scene's equilibrium at N against the numbers of its `[reference]`.
fn paper_table(scene: &Scene, n: usize) -> Result<String> {
    let e = solve_scene(scene, Some(n))?;
    let r = scene
        .reference
        .as_ref()
        .context("scene has no [reference]")?;
    let mut s = String::new();
    writeln!(
        s,
        "| quantity | knotrod (N = {n}) | {} | deviation |",
        r.source.as_deref().unwrap_or("paper")
    )?;
    writeln!(s, "|---|---|---|---|")?;
    s += &solution_rows(&e, r)?;
    s += &property_rows(&e, r)?;
    Ok(s)
}

/// Rows of the boundary data n(0), m(0) and of Tw and the link.
fn solution_rows(e: &Equilibrium, r: &ReferenceSpec) -> Result<String> {
    let mut s = String::new();
    let v = |a: &[f64; 3]| format!("({:.3}, {:.3}, {:.3})", a[0], a[1], a[2]);
    if let Some(n0) = &r.n0 {
        writeln!(
            s,
            "| n(0) | {} | {} | {:.2}% of ‖n(0)‖ |",
            v(&e.n0),
            v(n0),
            100.0 * relative_deviation(&e.n0, n0)
        )?;
    }
    if let Some(m0) = &r.m0 {
        writeln!(
            s,
            "| m(0) | {} | {} | {:.2}% of ‖m(0)‖ |",
            v(&e.m0),
            v(m0),
            100.0 * relative_deviation(&e.m0, m0)
        )?;
    }
    if let Some(tw) = r.twist {
        writeln!(s, "| Tw | {:.4} | {tw} | {:+.4} |", e.twist, e.twist - tw)?;
    }
    if let Some(l) = r.link {
        writeln!(
            s,
            "| link Tw + Wr | {:.4} (Wr = {:.4}) | {l} | {:+.4} |",
            e.link,
            e.writhe,
            e.link - l
        )?;
    }
    Ok(s)
}

/// Rows of the knot type, self-distance, walls, stability and Newton's work.
fn property_rows(e: &Equilibrium, r: &ReferenceSpec) -> Result<String> {
    let mut s = String::new();
    if let Some(d) = r.knot_determinant {
        writeln!(
            s,
            "| knot determinant | {} ({}) | {d} | |",
            e.knot_determinant,
            e.knot_name.as_deref().unwrap_or("?")
        )?;
    }
    writeln!(
        s,
        "| min self-distance | {:.4} at s = ({:.3}, {:.3}) | > 0 (contact-free) | |",
        e.min_self_distance, e.min_self_distance_s[0], e.min_self_distance_s[1]
    )?;
    if let Some(w) = r.walled {
        writeln!(
            s,
            "| walled | {} (z in [{:.4}, {:.4}]) | {w} | |",
            e.walled, e.min_z, e.max_z
        )?;
    }
    if let Some(st) = r.stable {
        writeln!(
            s,
            "| stable | {} (lowest ω² = {:.3}, {} negative) | {st} | |",
            e.stable,
            e.omega_squared.first().copied().unwrap_or(f64::NAN),
            e.negative_eigenvalues
        )?;
    }
    writeln!(
        s,
        "| Newton | {} iterations, relative gradient {:.1e} | | |",
        e.iterations, e.gradient_norm
    )?;
    Ok(s)
}

/// The writhe of the ray closure for growing ray lengths, at N = 200.
fn writhe_table(scenes: &[&Scene]) -> Result<String> {
    let mut s = String::new();
    let radii = [1e1, 1e2, 1e3, 1e4, 1e5, 1e6];
    write!(s, "| scene (N = 200) |")?;
    for r in radii {
        write!(s, " Wr, rays {r:.0e} |")?;
    }
    writeln!(s, " Tw | link (rays 1e6) | paper Tw + Wp* |")?;
    writeln!(s, "|---|{}---|---|---|", "---|".repeat(radii.len()))?;
    for scene in scenes {
        let e = solve_scene(scene, Some(200))?;
        let (p, _) = e.state.centreline();
        write!(s, "| {} |", scene.name.as_deref().unwrap_or(""))?;
        for r in radii {
            let w = writhe_closed(&ray_closure(&p, -Vector3::z(), Vector3::z(), r));
            write!(s, " {w:.7} |")?;
        }
        let paper = scene
            .reference
            .as_ref()
            .and_then(|r| r.link)
            .map_or(String::new(), |l| l.to_string());
        writeln!(s, " {:.5} | {:.5} | {paper} |", e.twist, e.link)?;
    }
    Ok(s)
}
