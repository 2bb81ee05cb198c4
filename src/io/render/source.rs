//! The states to draw, from a recording (`.mcap`) or a `run --json` summary:
//! by index, or the state nearest a labelled event (e.g. `X`, `W1`).

use super::picture::Body;
use crate::analysis::class::Class;
use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::Event;
use crate::io::error::{IoError, Result};
use crate::io::recording::{Scalars, parse_recording, parse_state};
use crate::io::summary::Summary;
use crate::model::rod::{Law, RodModel, RodState};
use nalgebra::Vector3;
use std::path::Path;

/// The width a strip is drawn with when its scene gives none (the model's
/// strip is of zero width): the paper's experimental strips, w/L = 0.057
/// (Figure 10), rounded.
pub const DISPLAY_STRIP_WIDTH: f64 = 0.05;

/// Which state to draw.
#[derive(Clone, Debug, PartialEq)]
pub enum Pick {
    /// The state of this index in the run.
    Index(u64),
    /// The state nearest this φ/2π (the first of the run's states at the
    /// least distance).
    Phi(f64),
    /// The state nearest an event on its branch: by its label (`X`), or its
    /// kind (`contact_lost`, the first; `contact_lost:2`, the second).
    Event(String),
}

impl Pick {
    /// A whole number is an index, `phi=V` a value of φ/2π, anything else an
    /// event's label or kind.
    pub fn parse(text: &str) -> std::result::Result<Pick, String> {
        let text = text.trim();
        if let Some(v) = text.strip_prefix("phi=") {
            return match v.trim().parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(Pick::Phi(v)),
                _ => Err(format!("--index {text}: phi= takes a number (φ/2π)")),
            };
        }
        Ok(match text.parse::<u64>() {
            Ok(k) => Pick::Index(k),
            Err(_) => Pick::Event(text.to_string()),
        })
    }
}

/// One state with what its picture needs to say about it.
struct Found {
    state: RodState,
    model: RodModel,
    class: Class,
    twist: f64,
    label: String,
    contacts: Vec<Vector3<f64>>,
}

/// The bodies to draw from `path` (a recording or a summary), one per pick;
/// `ribbon`, if given, the width a strip is drawn with.
pub fn bodies(path: &Path, picks: &[Pick], ribbon: Option<f64>) -> Result<Vec<Body>> {
    let bytes = crate::io::read_limited(path, crate::io::DATA_FILE_LIMIT)
        .map_err(IoError::file("cannot read", path))?;
    let found = if bytes.starts_with(mcap::MAGIC) {
        from_recording(path, &bytes, picks)?
    } else {
        from_summary(path, &bytes, picks)?
    };
    Ok(found
        .into_iter()
        .map(|f| body(f, ribbon, strip_width_of(path, &bytes)))
        .collect())
}

/// The scene's strip width, from a recording's metadata.
fn strip_width_of(path: &Path, bytes: &[u8]) -> Option<f64> {
    if !bytes.starts_with(mcap::MAGIC) {
        return None;
    }
    let rec = parse_recording(path, bytes).ok()?;
    let scene = crate::scene::Scene::parse(rec.metadata.get("scene")?).ok()?;
    (scene.model.strip_width > 0.0).then_some(scene.model.strip_width)
}

fn body(f: Found, ribbon: Option<f64>, scene_width: Option<f64>) -> Body {
    let strip = matches!(f.model.law, Law::Strip { .. });
    let width = strip.then(|| ribbon.or(scene_width).unwrap_or(DISPLAY_STRIP_WIDTH));
    let c = crate::io::plot::colour_of(f.class);
    let clamps = &f.state.clamps;
    let mut title = class_name(f.class).to_string();
    if let Some(w) = width {
        title.push_str(&format!(" (strip drawn {w} wide)"));
    }
    let caption = format!(
        "{title}\nφ/2π = {:.4}   z* = {:.4}   δ = {:.4}   Tw = {:.4}",
        clamps.phi_over_2pi(),
        clamps.z_star,
        clamps.delta,
        f.twist,
    );
    Body {
        diameter: 4.0 / f.model.stretching_stiffness.sqrt(),
        state: f.state,
        ribbon: width,
        colour: [c.0, c.1, c.2],
        label: f.label,
        caption,
        contacts: f.contacts,
    }
}

/// The class as the paper's captions say it.
fn class_name(c: Class) -> &'static str {
    match c {
        Class::Good => "good knot",
        Class::StableUnwalled => "stable knot, unwalled or touching itself",
        Class::Unknotted => "unknotted",
        Class::Unstable => "unstable",
        Class::None => "",
    }
}

/// Where a state lies, to find it by an event.
struct Key {
    index: u64,
    branch: usize,
    phi_over_2pi: f64,
    z_star: f64,
    delta: f64,
    twist: f64,
}

/// The index of the state `pick` names among states with these scalars.
fn choose(path: &Path, pick: &Pick, scalars: &[Key], events: &[Event]) -> Result<(u64, String)> {
    let bad = |reason: String| IoError::Recording {
        path: path.into(),
        reason,
    };
    match pick {
        Pick::Index(k) => {
            if scalars.iter().any(|s| s.index == *k) {
                Ok((*k, String::new()))
            } else if scalars.is_empty() {
                Err(bad(format!("--index {k}: the file holds no states")))
            } else {
                Err(bad(format!(
                    "--index {k}: no such state (the file holds {} states, 0 to {})",
                    scalars.len(),
                    scalars.len() - 1
                )))
            }
        }
        Pick::Phi(v) => scalars
            .iter()
            .min_by(|a, b| {
                (a.phi_over_2pi - v)
                    .abs()
                    .total_cmp(&(b.phi_over_2pi - v).abs())
            })
            .map(|s| (s.index, String::new()))
            .ok_or_else(|| bad("the file holds no states".into())),
        Pick::Event(label) => {
            // a label (X, W1), else a kind, the k-th of it as `kind:k` (from 1)
            let (kind, nth) = match label.rsplit_once(':') {
                Some((k, n)) => (k, n.parse::<usize>().ok()),
                None => (label.as_str(), Some(1)),
            };
            let by_kind = || {
                events
                    .iter()
                    .filter(|e| e.kind.name() == kind)
                    .nth(nth?.checked_sub(1)?)
            };
            let Some(e) = events.iter().find(|e| &e.label == label).or_else(by_kind) else {
                let mut names: Vec<String> = events
                    .iter()
                    .map(|e| {
                        if e.label.is_empty() {
                            e.kind.name().to_string()
                        } else {
                            e.label.clone()
                        }
                    })
                    .collect();
                names.dedup();
                return Err(bad(format!(
                    "--index {label}: no event of this label or kind (the events are {})",
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                )));
            };
            // (past a fold two states share the clamps: the twist tells them apart)
            let gap = |s: &Key| {
                (s.phi_over_2pi - e.phi_over_2pi).abs()
                    + (s.z_star - e.z_star).abs()
                    + (s.delta - e.delta).abs()
                    + (s.twist - e.twist).abs()
            };
            let on_branch = scalars.iter().filter(|s| s.branch == e.branch);
            let best = on_branch
                .min_by(|a, b| gap(a).total_cmp(&gap(b)))
                .or_else(|| scalars.iter().min_by(|a, b| gap(a).total_cmp(&gap(b))))
                .ok_or_else(|| bad("the file holds no states".into()))?;
            Ok((best.index, label.clone()))
        }
    }
}

fn from_recording(path: &Path, bytes: &[u8], picks: &[Pick]) -> Result<Vec<Found>> {
    let rec = parse_recording(path, bytes)?;
    let keys: Vec<_> = rec
        .scalars
        .iter()
        .map(|s| Key {
            index: s.index,
            branch: s.branch,
            phi_over_2pi: s.phi_over_2pi,
            z_star: s.z_star,
            delta: s.delta,
            twist: s.twist,
        })
        .collect();
    picks
        .iter()
        .map(|pick| {
            let (index, label) = choose(path, pick, &keys, &rec.events)?;
            let msg = parse_state(path, bytes, index)?;
            let s: &Scalars = rec
                .scalars
                .iter()
                .find(|s| s.index == index)
                .expect("chosen among the scalars");
            Ok(Found {
                class: Class::of(
                    s.stable,
                    s.knotted.unwrap_or(s.knot_determinant == 3),
                    s.good_knot,
                ),
                twist: s.twist,
                label,
                contacts: Vec::new(),
                state: msg.state,
                model: msg.model,
            })
        })
        .collect()
}

fn from_summary(path: &Path, bytes: &[u8], picks: &[Pick]) -> Result<Vec<Found>> {
    let text = std::str::from_utf8(bytes.strip_prefix("\u{feff}".as_bytes()).unwrap_or(bytes))
        .map_err(|e| IoError::Recording {
            path: path.into(),
            reason: format!("neither an MCAP recording nor a UTF-8 summary ({e})"),
        })?;
    let s: Summary = serde_json::from_str(text).map_err(|e| IoError::Recording {
        path: path.into(),
        reason: format!("neither an MCAP recording nor a knotrod summary ({e})"),
    })?;
    let keys: Vec<_> = s
        .equilibria
        .iter()
        .enumerate()
        .map(|(k, e)| Key {
            index: k as u64,
            branch: e.branch,
            phi_over_2pi: e.phi_over_2pi,
            z_star: e.z_star,
            delta: e.delta,
            twist: e.twist,
        })
        .collect();
    let strip = s.model.kind == "strip";
    picks
        .iter()
        .map(|pick| {
            let (index, label) = choose(path, pick, &keys, &s.events)?;
            let e = &s.equilibria[index as usize];
            let mut model = RodModel {
                segments: s.segments,
                k2: s.model.k2,
                k3: s.model.k3,
                stretching_stiffness: s.model.stretching_stiffness,
                law: Law::Kirchhoff,
                weight: [0.0; 3],
                natural_strains: Default::default(),
            };
            if strip {
                model.law = Law::Strip {
                    regularisation: 0.0,
                };
            }
            Ok(Found {
                class: Class::of(e.stable, e.knotted, e.good_knot),
                twist: e.twist,
                label,
                contacts: contact_points(e),
                state: e.state.clone(),
                model,
            })
        })
        .collect()
}

/// Where an equilibrium's contacts are on its centreline.
fn contact_points(e: &Equilibrium) -> Vec<Vector3<f64>> {
    let (points, arc) = e.state.centreline();
    e.contacts
        .iter()
        .map(|c| {
            let k = arc.partition_point(|a| *a <= c.s).clamp(1, arc.len() - 1);
            let t = ((c.s - arc[k - 1]) / (arc[k] - arc[k - 1]).max(1e-300)).clamp(0.0, 1.0);
            points[k - 1] + t * (points[k] - points[k - 1])
        })
        .collect()
}
