//! AUTO-07p's labelled folds (LP) and branch points (BP) beside knotrod's
//! events on the same branch: the continuation scene of the AUTO mapping is
//! run (its events polished on the continuum branch, each with its error
//! bar) and each AUTO label is set beside knotrod's nearest event of its
//! kind, with AUTO's own location tolerance from its files.

use crate::analysis::event::{Event, EventKind};
use crate::io::auto::{AutoEvent, AutoInput, PointType};
use crate::scene::Scene;
use crate::study::error::{Context, Result};
use crate::study::run::run_scene;
use serde::{Deserialize, Serialize};
use std::fmt::Write;

/// knotrod's event matched to an AUTO label.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Matched {
    /// Its label (S, F1, ...).
    pub label: String,
    /// Its kind.
    pub kind: EventKind,
    /// Where, polished on the continuum branch (the discrete rod's value if
    /// it could not be polished).
    pub value: f64,
    /// The polished value's error bar (None: not polished).
    pub error: Option<f64>,
    /// The discrete rod's value.
    pub discrete: f64,
}

/// One AUTO label against knotrod.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct LabelComparison {
    /// AUTO's event.
    pub auto: AutoEvent,
    /// knotrod's nearest event of the same kind.
    pub knotrod: Option<Matched>,
    /// AUTO − knotrod.
    pub difference: Option<f64>,
    /// |difference| within knotrod's bar plus AUTO's location tolerance.
    pub within: Option<bool>,
}

/// AUTO's labels against the events of knotrod's continuation.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct EventsComparison {
    /// The continuation scene run (None: none given).
    pub scene: Option<String>,
    /// Each AUTO label.
    pub labels: Vec<LabelComparison>,
    /// knotrod's folds and branch points within the range AUTO's branch
    /// covers that no AUTO label matched.
    pub unmatched: Vec<Matched>,
    /// The range of the continuation parameter AUTO's branch covers.
    pub covered: Option<(f64, f64)>,
    /// AUTO's EPSS, DS and DSMAX (from the branch file's header).
    pub constants: Option<[f64; 3]>,
}

fn kind_of(p: PointType) -> Option<EventKind> {
    match p {
        PointType::Fold => Some(EventKind::Fold),
        PointType::BranchPoint => Some(EventKind::BranchPoint),
        _ => None,
    }
}

fn matched(e: &Event, p: crate::model::rod::Parameter) -> Matched {
    let discrete = e.value(p);
    let polished = e.continuum.as_ref().filter(|c| c.parameter == p);
    Matched {
        label: e.label.clone(),
        kind: e.kind,
        value: polished.map_or(discrete, |c| c.value),
        error: polished.map(|c| c.error),
        discrete,
    }
}

/// Set AUTO's labels of `input` beside knotrod's `events` (of a branch in
/// the same parameter).
pub fn compare(input: &AutoInput, scene: Option<String>, events: &[Event]) -> EventsComparison {
    let parameter = input.events.iter().find_map(|e| e.parameter);
    let factor = parameter
        .and_then(|p| input.map.parameters.iter().find(|m| m.parameter == p))
        .map_or(1.0, |m| m.factor);
    let covered = input
        .branch
        .rows
        .iter()
        .filter_map(|r| r.values.first())
        .map(|v| v * factor)
        .fold(None, |acc: Option<(f64, f64)>, v| {
            Some(acc.map_or((v, v), |(a, b)| (a.min(v), b.max(v))))
        });
    let mut used = vec![false; events.len()];
    let labels = input
        .events
        .iter()
        .map(|a| {
            let best = match (kind_of(a.kind), a.parameter) {
                (Some(kind), Some(p)) => events
                    .iter()
                    .enumerate()
                    .filter(|(_, e)| e.kind == kind)
                    .map(|(k, e)| (k, matched(e, p)))
                    .min_by(|x, y| {
                        (x.1.value - a.value)
                            .abs()
                            .total_cmp(&(y.1.value - a.value).abs())
                    }),
                _ => None,
            };
            if let Some((k, _)) = &best {
                used[*k] = true;
            }
            let knotrod = best.map(|b| b.1);
            let difference = knotrod.as_ref().map(|m| a.value - m.value);
            let within = knotrod.as_ref().and_then(|m| {
                let bar = m.error? + a.tolerance.unwrap_or(0.0);
                Some((a.value - m.value).abs() <= bar)
            });
            LabelComparison {
                auto: a.clone(),
                knotrod,
                difference,
                within,
            }
        })
        .collect();
    let unmatched = match (parameter, covered) {
        (Some(p), Some((lo, hi))) => events
            .iter()
            .zip(&used)
            .filter(|(e, u)| {
                !**u && matches!(e.kind, EventKind::Fold | EventKind::BranchPoint) && {
                    let v = e.value(p);
                    v >= lo && v <= hi
                }
            })
            .map(|(e, _)| matched(e, p))
            .collect(),
        _ => vec![],
    };
    EventsComparison {
        scene,
        labels,
        unmatched,
        covered,
        constants: match (input.branch.epss, input.branch.ds, input.branch.dsmax) {
            (Some(e), Some(d), Some(m)) => Some([e, d, m]),
            _ => None,
        },
    }
}

/// Run the mapping's continuation scene (if it has one) and compare its
/// events with AUTO's labels.
pub fn compare_with_continuation(input: &AutoInput) -> Result<EventsComparison> {
    let Some(path) = &input.map.continuation else {
        return Ok(compare(input, None, &[]));
    };
    let scene = Scene::load(path).context("the AUTO mapping's continuation scene")?;
    let events =
        run_scene(&scene, None, &mut ()).with_context(|| format!("running {}", path.display()))?;
    Ok(compare(input, Some(path.display().to_string()), &events))
}

fn bar(v: Option<f64>) -> String {
    v.map_or("—".into(), |x| format!("{x:.1e}"))
}

/// The report's section "AUTO's labelled events" (markdown).
pub fn markdown(c: &EventsComparison) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "## AUTO's labelled events\n");
    match &c.scene {
        Some(scene) => {
            let _ = writeln!(
                s,
                "Each fold (LP) and branch point (BP) AUTO-07p located, beside knotrod's nearest \
                 event of the same kind on the branch of `{scene}` (polished on the continuum \
                 branch; its ± is the change when the integrator's tolerance falls a \
                 hundredfold, plus the last secant step). AUTO's own ± is its location \
                 tolerance: the arclength EPSS (1 + √|DS·DSMAX|) at which it stops refining a \
                 special point, times the parameter's derivative along its branch there \
                 (RLDOT of the s-file). \"Within\" is |AUTO − knotrod| ≤ the sum of the two.\n"
            );
        }
        None => {
            let _ = writeln!(
                s,
                "No continuation scene was given (`continuation = \"scene.toml\"` in [auto], \
                 or `--map continuation=…`): AUTO's labels alone.\n"
            );
        }
    }
    if let Some([epss, ds, dsmax]) = c.constants {
        let _ = writeln!(
            s,
            "AUTO's constants (its branch file): EPSS = {epss:e}, DS = {ds:e}, DSMAX = {dsmax:e}: \
             special points located to {:.2e} in its arclength.\n",
            epss * (1.0 + (ds * dsmax).abs().sqrt())
        );
    }
    if c.labels.is_empty() {
        let _ = writeln!(s, "AUTO's branch file labels no fold or branch point.\n");
        return s;
    }
    let name = c
        .labels
        .iter()
        .find_map(|l| l.auto.parameter)
        .map_or("parameter", |p| p.name());
    let _ = writeln!(
        s,
        "| AUTO | {name} | ± AUTO | knotrod | {name} | ± knotrod | AUTO − knotrod | within |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for l in &c.labels {
        let (label, value, error) = match &l.knotrod {
            Some(m) => (
                format!("{} ({})", m.label, m.kind),
                format!("{:.12}", m.value),
                match m.error {
                    Some(e) => format!("{e:.1e}"),
                    None => "not polished".into(),
                },
            ),
            None => ("none".into(), "—".into(), "—".into()),
        };
        let _ = writeln!(
            s,
            "| {} LAB {} | {:.11} | {} | {label} | {value} | {error} | {} | {} |",
            l.auto.kind.name(),
            l.auto.label,
            l.auto.value,
            bar(l.auto.tolerance),
            l.difference.map_or("—".into(), |d| format!("{d:+.2e}")),
            match l.within {
                Some(true) => "yes",
                Some(false) => "**no**",
                None => "—",
            }
        );
    }
    for m in &c.unmatched {
        let _ = writeln!(
            s,
            "\nknotrod's {} ({}) at {:.12} ± {} lies within AUTO's branch but has no AUTO label.",
            m.label,
            m.kind,
            m.value,
            bar(m.error)
        );
    }
    s.push('\n');
    s
}
