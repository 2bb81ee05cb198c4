//! `knotrod knot`: writhe and knot type of any curve.

use crate::geometry::closure::{extent, ray_closure};
use crate::geometry::knot::{KnotError, KnotType, knot_type, unit_sized};
use crate::geometry::writhe::try_writhe_closed;
use crate::io::curve_file::read_points;
use crate::io::json::write_pretty;
use anyhow::{Context, Result};
use nalgebra::Vector3;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Directions of the closing rays of an open curve.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum RayKind {
    /// Along the end tangents.
    Tangent,
    /// Along −z from the first point and +z from the last.
    Z,
}

/// Writhe and knot type of a curve file, printed or as JSON.
pub fn knot(path: &Path, closed: bool, rays: RayKind, json: Option<PathBuf>) -> Result<()> {
    let points = read_points(path)?;
    let (writhe, kt) = writhe_and_knot(&points, closed, rays);
    let writhe = writhe.with_context(|| format!("writhe of {}", path.display()))?;
    let kt = kt.with_context(|| format!("knot type of {}", path.display()))?;
    let answer = serde_json::json!({
        "curve": path.display().to_string(),
        "points": points.len(),
        "closed": closed,
        "writhe": writhe,
        "knot_determinant": kt.determinant,
        "alexander": kt.alexander,
        "knot_name": kt.name,
        "knot_names": kt.names,
        "crossings": kt.crossings,
        "vertices_simplified": kt.vertices,
        "projections": kt.projections,
    });
    let mut out = std::io::stdout().lock();
    match json {
        Some(p) if crate::io::output::is_standard_output(&p) => {
            writeln!(out, "{}", serde_json::to_string_pretty(&answer)?)?
        }
        other => {
            let closure = if closed { "closed" } else { "closed by rays" };
            let head = format!(
                "curve {} ({} points, {closure})",
                path.display(),
                points.len()
            );
            print_knot(&head, writhe, &kt, &mut out)?;
            if let Some(p) = other {
                write_pretty(&p, &answer)?;
            }
        }
    }
    Ok(())
}

/// Writhe and knot type of a closed curve, or of an open one closed by rays.
/// Both are unchanged by moving and scaling the curve, so it is first brought
/// to unit size: the rays' lengths cannot overflow.
fn writhe_and_knot(
    points: &[Vector3<f64>],
    closed: bool,
    rays: RayKind,
) -> (Result<f64, KnotError>, Result<KnotType, KnotError>) {
    let points = unit_sized(points);
    if closed {
        return (try_writhe_closed(&points), knot_type(&points));
    }
    let m = points.len();
    let (bottom, top) = match rays {
        RayKind::Tangent => (points[0] - points[1], points[m - 1] - points[m - 2]),
        RayKind::Z => (-Vector3::z(), Vector3::z()),
    };
    let size = extent(&points);
    // writhe error of the closure decays as 1/(ray length)
    let w = try_writhe_closed(&ray_closure(&points, bottom, top, 1e6 * size));
    (
        w,
        knot_type(&ray_closure(
            &points,
            bottom,
            top,
            2.0 * size + size.max(1.0),
        )),
    )
}

/// The answer for people.
fn print_knot(head: &str, writhe: f64, kt: &KnotType, out: &mut impl Write) -> Result<()> {
    writeln!(out, "{head}")?;
    writeln!(out, "  writhe {writhe:.6}")?;
    writeln!(out, "  knot determinant {}", kt.determinant)?;
    writeln!(out, "  Alexander polynomial {}", polynomial(&kt.alexander))?;
    match kt.names.as_slice() {
        [] => writeln!(
            out,
            "  knot: none of the tabled ones (prime knots to 10 crossings and their sums)"
        )?,
        [one] => writeln!(out, "  knot {one}")?,
        many => writeln!(
            out,
            "  knot one of {} (they share this polynomial)",
            many.join(", ")
        )?,
    }
    writeln!(
        out,
        "  ({} crossings in the reduced diagram, {} vertices after simplification)",
        kt.crossings, kt.vertices
    )?;
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
