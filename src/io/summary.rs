//! The machine-readable run summary (JSON) and its human-readable print.

use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::Event;
use crate::model::rod::Parameter;
use crate::model::rod::RodModel;
use crate::scene::{ReferenceSpec, Scene};
use serde::{Deserialize, Serialize};
use std::io::Write;

/// The model as written in summaries.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ModelSummary {
    /// Model kind.
    pub kind: String,
    /// B22/B11.
    #[serde(rename = "K2")]
    pub k2: f64,
    /// B33/B11.
    #[serde(rename = "K3")]
    pub k3: f64,
    /// Stretching stiffness.
    pub stretching_stiffness: f64,
}

/// A run's summary: `{"scene", "model", "segments", "equilibria", "events"}`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Model parameters.
    pub model: ModelSummary,
    /// N.
    pub segments: usize,
    /// What `good_knot` means in this summary (the scene's `[diagnostics]`).
    #[serde(default)]
    pub good_knot: String,
    /// Equilibria in the order computed.
    pub equilibria: Vec<Equilibrium>,
    /// Located events (filled by continuation runs).
    pub events: Vec<Event>,
}

impl Summary {
    /// An empty summary for a scene and model.
    pub fn new(scene: &Scene, model: &RodModel) -> Self {
        Summary {
            scene: scene.name.clone().unwrap_or_default(),
            model: ModelSummary {
                kind: scene.model.kind.name().into(),
                k2: model.k2,
                k3: model.k3,
                stretching_stiffness: model.stretching_stiffness,
            },
            segments: model.segments,
            good_knot: scene.good_knot().describe(),
            equilibria: Vec::new(),
            events: Vec::new(),
        }
    }

    /// Write as JSON to `out`, opened at the start of the run (a temporary
    /// file renamed into place, so a reader never sees a half-written
    /// summary, and a second run of the same file is refused at its start).
    pub fn write(&self, out: crate::io::output::Output) -> crate::io::error::Result<()> {
        crate::io::json::write_pretty_to(out, self)
    }
}

fn vec3(v: &[f64; 3]) -> String {
    format!("({:.4}, {:.4}, {:.4})", v[0], v[1], v[2])
}

/// ‖a − b‖ / ‖b‖ for 3-vectors.
pub fn relative_deviation(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let d: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt();
    d / b.iter().map(|y| y * y).sum::<f64>().sqrt()
}

/// Human-readable report of one equilibrium, with the scene's published
/// reference values (if any) and our deviation from them.
pub fn print_equilibrium(
    e: &Equilibrium,
    scene: &Scene,
    out: &mut impl Write,
) -> std::io::Result<()> {
    writeln!(
        out,
        "equilibrium at z* = {:.4}, δ = {:.4}, φ/2π = {:.4}",
        e.z_star, e.delta, e.phi_over_2pi
    )?;
    writeln!(
        out,
        "  Newton: {} in {} iterations, relative gradient {:.2e}",
        if e.converged {
            "converged"
        } else {
            "NOT converged"
        },
        e.iterations,
        e.gradient_norm
    )?;
    writeln!(out, "  energy E = {:.6}", e.energy)?;
    writeln!(out, "  n(0) = {}", vec3(&e.n0))?;
    writeln!(out, "  m(0) = {}", vec3(&e.m0))?;
    writeln!(out, "  twist Tw = {:.5}", e.twist)?;
    if let Some(u2) = e.max_u2 {
        writeln!(out, "  constraint: max |u2| = {u2:.2e}")?;
    }
    if let (Some(u1), Some(reg)) = (e.min_u1, e.regularised) {
        let note = if reg {
            " — near the Sadowsky singularity: the regularisation decides the shape there"
        } else {
            ""
        };
        writeln!(out, "  strip: min |u1| = {u1:.4}{note}")?;
    }
    writeln!(
        out,
        "  z range ({:.5}, {:.5}) — {}",
        e.min_z,
        e.max_z,
        if e.walled { "walled" } else { "not walled" }
    )?;
    writeln!(
        out,
        "  {} ({} negative eigenvalues); lowest ω² = {}",
        if e.stable { "stable" } else { "UNSTABLE" },
        e.negative_eigenvalues,
        if e.omega_squared.is_empty() {
            "not computed".to_string()
        } else {
            e.omega_squared
                .iter()
                .map(|v| format!("{v:.4}"))
                .collect::<Vec<_>>()
                .join(", ")
        }
    )?;
    writeln!(
        out,
        "  writhe Wr = {:.5} (ray closure), link Tw + Wr = {:.5}",
        e.writhe, e.link
    )?;
    writeln!(
        out,
        "  knot: determinant {}, Alexander {:?}{}{}",
        e.knot_determinant,
        e.alexander,
        e.knot_name
            .as_deref()
            .map(|n| format!(" — {n}"))
            .unwrap_or_default(),
        if e.knot_undefined {
            " (none: the ray closure passes through itself)"
        } else {
            ""
        }
    )?;
    writeln!(
        out,
        "  min self-distance {:.5} at s = ({:.4}, {:.4}); wall clearance {:.5}; ray distance ({:.5}, {:.5})",
        e.min_self_distance,
        e.min_self_distance_s[0],
        e.min_self_distance_s[1],
        e.wall_distance,
        e.ray_distance[0],
        e.ray_distance[1]
    )?;
    writeln!(
        out,
        "  good knot: {} ({})",
        if e.good_knot { "YES" } else { "no" },
        scene.good_knot().describe()
    )?;
    if let Some(r) = &scene.reference {
        print_comparison(e, r, out)?;
    }
    Ok(())
}

/// Our equilibrium beside a scene's published values, with our deviation.
fn print_comparison(
    e: &Equilibrium,
    r: &ReferenceSpec,
    out: &mut impl Write,
) -> std::io::Result<()> {
    let src = r.source.as_deref().unwrap_or("reference");
    writeln!(out, "  compared with {src}:")?;
    if let Some(n0) = &r.n0 {
        writeln!(
            out,
            "    n(0) {}: relative deviation {:.3}%",
            vec3(n0),
            100.0 * relative_deviation(&e.n0, n0)
        )?;
    }
    if let Some(m0) = &r.m0 {
        writeln!(
            out,
            "    m(0) {}: relative deviation {:.3}%",
            vec3(m0),
            100.0 * relative_deviation(&e.m0, m0)
        )?;
    }
    if let Some(tw) = r.twist {
        writeln!(out, "    Tw {tw}: difference {:+.4}", e.twist - tw)?;
    }
    if let Some(l) = r.link {
        writeln!(out, "    link {l}: difference {:+.4}", e.link - l)?;
    }
    if let Some(d) = r.knot_determinant {
        writeln!(
            out,
            "    knot determinant {d}: {}",
            if d == e.knot_determinant {
                "agrees"
            } else {
                "DISAGREES"
            }
        )?;
    }
    if let Some(w) = r.walled {
        writeln!(
            out,
            "    walled {w}: {}",
            if w == e.walled { "agrees" } else { "DISAGREES" }
        )?;
    }
    if let Some(s) = r.stable {
        writeln!(
            out,
            "    stable {s}: {}",
            if s == e.stable { "agrees" } else { "DISAGREES" }
        )?;
    }
    Ok(())
}

/// The events located again on the continuum branch: the parameter there
/// with its error estimate, beside the discrete rod's value.
/// The event's polish failure as a suffix of its detail ("" when none).
fn not_polished(e: &Event) -> String {
    e.not_polished
        .as_ref()
        .map_or(String::new(), |f| format!("; not polished: {f}"))
}

fn print_polished(events: &[Event], out: &mut impl Write) -> std::io::Result<()> {
    let polished: Vec<(&Event, &crate::analysis::event::ContinuumEvent)> = events
        .iter()
        .filter_map(|e| e.continuum.as_ref().map(|c| (e, c)))
        .collect();
    let Some((_, first)) = polished.first() else {
        return Ok(());
    };
    let name = match first.parameter {
        Parameter::Phi => "φ/2π".to_string(),
        p => p.name().to_string(),
    };
    writeln!(
        out,
        "events on the continuum branch (polished; discrete − continuum is the discrete rod's error):"
    )?;
    writeln!(
        out,
        "  {:<6} {:<13} {:>6} {:>16} {:>9} {:>13} {:>10}  arclengths",
        "label", "kind", "branch", name, "± error", "discrete − c", "Tw"
    )?;
    for (e, c) in polished {
        let s: Vec<String> = c.arclengths.iter().map(|s| format!("{s:.5}")).collect();
        writeln!(
            out,
            "  {:<6} {:<13} {:>6} {:>16.12} {:>9.1e} {:>13.3e} {:>10.7}  {}",
            e.label,
            e.kind,
            e.branch,
            c.value,
            c.error,
            c.discrete_minus_continuum,
            c.twist,
            s.join(", ")
        )?;
    }
    Ok(())
}

/// Events as a table.
pub fn print_events(events: &[Event], out: &mut impl Write) -> std::io::Result<()> {
    if events.is_empty() {
        return Ok(());
    }
    writeln!(out, "events:")?;
    writeln!(
        out,
        "  {:<6} {:<13} {:>6} {:>9} {:>9} {:>8}  detail",
        "label", "kind", "branch", "z*", "φ/2π", "Tw"
    )?;
    for e in events {
        writeln!(
            out,
            "  {:<6} {:<13} {:>6} {:>9.5} {:>9.5} {:>8.4}  {}{}",
            e.label,
            e.kind,
            e.branch,
            e.z_star,
            e.phi_over_2pi,
            e.twist,
            e.detail,
            not_polished(e)
        )?;
    }
    print_polished(events, out)?;
    // general clamps: every coordinate that is not the paper's, per event
    let general: Vec<&Event> = events.iter().filter(|e| e.clamps.is_some()).collect();
    if let Some(first) = general.first().and_then(|e| e.clamps) {
        let moving: Vec<Parameter> = Parameter::ALL[3..]
            .iter()
            .chain(&Parameter::MODEL)
            .copied()
            .filter(|p| {
                // a clamp coordinate off the paper's, or a model scalar that
                // moves (or the one event's, when there is one)
                general.iter().any(|e| {
                    e.clamps.is_some_and(|c| {
                        let v = p.value(&c);
                        let moves = v != p.value(&first) || general.len() == 1;
                        !v.is_nan() && if p.is_model() { moves } else { v != 0.0 }
                    })
                })
            })
            .collect();
        if !moving.is_empty() {
            write!(out, "  at general clamps:  label ")?;
            for p in &moving {
                write!(out, " {:>12}", p.name())?;
            }
            writeln!(out)?;
            for e in &general {
                write!(out, "                      {:<6}", e.label)?;
                for p in &moving {
                    write!(out, " {:>12.6}", e.clamps.map_or(f64::NAN, |c| p.value(&c)))?;
                }
                writeln!(out)?;
            }
        }
    }
    Ok(())
}
