//! Events of a path of equilibria (a branch or a loading path): what happens,
//! where, and the paper's labels (W1, W2, X, S, F1, J1, ...).

use crate::model::rod::{Clamps, Parameter};
use crate::solve::event::Vanishing;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// What happens at an event (JSON: the snake_case name, e.g. "branch_point").
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    /// The rod touches a wall (enters or leaves the walled region).
    Wall,
    /// The centreline passes through itself or a ray (the link jumps by ±2).
    Crossing,
    /// A strip's ribbon comes to touch itself, or comes clear of itself
    /// (the crossing X of a ribbon, before its centreline's).
    RibbonContact,
    /// The count of negative eigenvalues changes.
    Stability,
    /// The parameter turns back along the branch.
    Fold,
    /// A branch point: another branch crosses this one.
    BranchPoint,
    /// The rod jumps off its branch (loading paths).
    Jump,
    /// The knot type of the ray closure changes.
    KnotChange,
    /// The branch ends (lost, or a switch failed).
    End,
    /// The last contact opens (loading with contact).
    ContactLost,
}

impl EventKind {
    /// The name used in JSON and tables.
    pub fn name(self) -> &'static str {
        match self {
            EventKind::Wall => "wall",
            EventKind::Crossing => "crossing",
            EventKind::RibbonContact => "ribbon_contact",
            EventKind::Stability => "stability",
            EventKind::Fold => "fold",
            EventKind::BranchPoint => "branch_point",
            EventKind::Jump => "jump",
            EventKind::KnotChange => "knot_change",
            EventKind::End => "end",
            EventKind::ContactLost => "contact_lost",
        }
    }

    /// The quantity that vanishes at an event of this kind (none for a jump,
    /// an end or a lost contact, which no test function locates).
    pub fn vanishing(self) -> Option<Vanishing> {
        match self {
            EventKind::Fold | EventKind::Stability | EventKind::BranchPoint => {
                Some(Vanishing::Singularity)
            }
            EventKind::Wall => Some(Vanishing::WallGap),
            EventKind::Crossing | EventKind::KnotChange => Some(Vanishing::StrandGap),
            EventKind::RibbonContact => Some(Vanishing::RibbonGap),
            EventKind::Jump | EventKind::End | EventKind::ContactLost => None,
        }
    }

    /// The letter of the paper's labels, for the kinds the figures label.
    fn label_prefix(self) -> Option<&'static str> {
        match self {
            EventKind::Wall => Some("W"),
            EventKind::Crossing | EventKind::RibbonContact => Some("X"),
            EventKind::BranchPoint => Some("S"),
            EventKind::Fold => Some("F"),
            EventKind::Jump => Some("J"),
            _ => None,
        }
    }
}

impl std::fmt::Display for EventKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // padding and alignment of tables apply to the name
        f.pad(self.name())
    }
}

/// A located event.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Event {
    /// What happens.
    pub kind: EventKind,
    /// Label as in the paper's figures (W1, W2, X, S, F1, ...).
    pub label: String,
    /// Where.
    pub phi_over_2pi: f64,
    /// Where.
    pub z_star: f64,
    /// Where.
    pub delta: f64,
    /// Twist there (the figures' vertical axis).
    pub twist: f64,
    /// Branch it lies on (for a loading path: the leg of the path).
    pub branch: usize,
    /// Free text (e.g. negative eigenvalue counts on either side).
    pub detail: String,
    /// The whole clamps where they are not the paper's or carry the model's
    /// scalars (a branch in a tilt or in K3): z*, δ and φ alone do not say where.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clamps: Option<Clamps>,
    /// The event located again on the continuum branch, when asked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub continuum: Option<ContinuumEvent>,
    /// Why the event could not be located again on the continuum branch,
    /// when its polish was asked and failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub not_polished: Option<PolishFailure>,
    /// Width of the interval of the continuation's parameter (φ as φ/2π)
    /// the discrete event was bisected to: it lies within it (wider than
    /// the locate tolerance gives where the bisection stopped at a singular
    /// point). None for events not bisected.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub located_within: Option<f64>,
}

/// Why an event was not polished on the continuum branch (typed, so a
/// reader can tell the kinds apart without parsing text).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum PolishFailure {
    /// Walls and crossings of a ribbon were not polished (written by
    /// versions before the ribbon's continuum test functions; read only).
    Ribbon,
    /// A merger of two critical points of a distance is not an event of a
    /// branch.
    Merger,
    /// The discrete centreline has no self-approach to start a crossing from.
    NoSelfApproach,
    /// The crossing is of a closing ray, not of the centreline's strands.
    RayCrossing {
        /// How far apart the centreline's strands are.
        distance: f64,
    },
    /// The shooting Jacobian has no singular vectors to border it with.
    NoSingularVectors,
    /// The continuum branch (integrator, corrector or root finder) failed.
    Continuum {
        /// The solver's reason.
        message: String,
    },
    /// A traced boundary has no pieces to polish.
    NoBoundary,
    /// Too many of a traced boundary's points failed for its area to mean
    /// much (more than a tenth).
    TooManyFailed {
        /// Points that failed.
        failed: usize,
        /// Points in all.
        of: usize,
        /// The first failure.
        first: Box<PolishFailure>,
    },
}

impl PolishFailure {
    /// Read a failure written as data, or as the text earlier versions wrote
    /// (kept as the continuum's message), so old map files still load.
    pub fn data_or_text<'de, D>(d: D) -> Result<Option<PolishFailure>, D::Error>
    where
        D: serde::Deserializer<'de>,
    {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Written {
            Data(PolishFailure),
            Text(String),
        }
        Ok(Option::<Written>::deserialize(d)?.map(|w| match w {
            Written::Data(f) => f,
            Written::Text(message) => PolishFailure::Continuum { message },
        }))
    }
}

impl std::fmt::Display for PolishFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PolishFailure::Ribbon => write!(f, "walls and crossings of a ribbon are not polished"),
            PolishFailure::Merger => write!(f, "a merger of critical points is not polished"),
            PolishFailure::NoSelfApproach => write!(f, "no self-approach of the centreline"),
            PolishFailure::RayCrossing { distance } => write!(
                f,
                "the centreline's strands are {distance:.2e} apart (a crossing of a ray is not polished)"
            ),
            PolishFailure::NoSingularVectors => write!(f, "no singular vectors"),
            PolishFailure::Continuum { message } => write!(f, "{message}"),
            PolishFailure::NoBoundary => write!(f, "no boundary to polish"),
            PolishFailure::TooManyFailed { failed, of, first } => {
                write!(f, "{failed} of {of} points failed, the first: {first}")
            }
        }
    }
}

/// An event located on the continuum branch (the Kirchhoff or strip
/// equations integrated to a tolerance), beside the discrete rod's.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ContinuumEvent {
    /// The branch's parameter.
    pub parameter: Parameter,
    /// Its value at the event (φ as φ/2π).
    pub value: f64,
    /// Estimated error of `value`: its change when the integrator's
    /// tolerance falls a hundredfold, plus the last secant step.
    pub error: f64,
    /// The discrete rod's value less the continuum's (its discretisation
    /// error at this N).
    pub discrete_minus_continuum: f64,
    /// Tw there.
    pub twist: f64,
    /// The shooting unknowns there.
    pub unknowns: [f64; 6],
    /// Arclengths of the touching extremum (a wall) or of the two crossing
    /// strands.
    pub arclengths: Vec<f64>,
    /// Secant steps taken.
    pub steps: usize,
}

impl Event {
    /// An event of `kind` at clamps `c`, where the twist is `twist`.
    pub fn at(kind: EventKind, c: &Clamps, twist: f64, branch: usize, detail: String) -> Event {
        Event {
            kind,
            label: String::new(),
            phi_over_2pi: c.phi_over_2pi(),
            z_star: c.z_star,
            delta: c.delta,
            twist,
            branch,
            detail,
            clamps: (!c.is_paper() || !c.scalars.is_unset()).then_some(*c),
            continuum: None,
            not_polished: None,
            located_within: None,
        }
    }

    /// The value of parameter `p` where the event lies (φ as φ/2π): from its
    /// whole clamps when it carries them, else from the paper's (z*, δ, φ).
    pub fn value(&self, p: Parameter) -> f64 {
        match (p, &self.clamps) {
            // the stored fields, exactly as written (φ/2π is not recomputed)
            (Parameter::ZStar, _) => self.z_star,
            (Parameter::Delta, _) => self.delta,
            (Parameter::Phi, _) => self.phi_over_2pi,
            (_, Some(c)) => p.value(c),
            (_, None) => p.value(&Clamps::new(self.z_star, self.delta, self.phi_over_2pi)),
        }
    }
}

/// Label events as in the paper's figures: walls W1, W2, … by increasing φ on
/// each branch, S for branch points, F for folds, J for jumps, and X, X2, …
/// for crossings in the order met from the start of the branch.
pub fn label_events(events: &mut [Event]) {
    let mut crossings = HashMap::<(usize, u64), usize>::new();
    let crossing = |k: EventKind| matches!(k, EventKind::Crossing | EventKind::RibbonContact);
    for e in events.iter_mut().filter(|e| crossing(e.kind)) {
        let k = crossings.entry((e.branch, e.z_star.to_bits())).or_insert(0);
        *k += 1;
        e.label = if *k == 1 { "X".into() } else { format!("X{k}") };
    }
    let mut order: Vec<usize> = (0..events.len()).collect();
    order.sort_by(|&i, &j| {
        (
            events[i].branch,
            events[i].z_star.to_bits(),
            events[i].phi_over_2pi,
        )
            .partial_cmp(&(
                events[j].branch,
                events[j].z_star.to_bits(),
                events[j].phi_over_2pi,
            ))
            .unwrap()
    });
    let mut counters = HashMap::<(usize, u64, &str), usize>::new();
    for &i in &order {
        let Some(prefix) = events[i].kind.label_prefix() else {
            continue;
        };
        if prefix == "X" {
            continue;
        }
        let key = (events[i].branch, events[i].z_star.to_bits(), prefix);
        let k = counters.entry(key).or_insert(0);
        *k += 1;
        events[i].label = if prefix == "W" || prefix == "F" || prefix == "J" || *k > 1 {
            format!("{prefix}{k}")
        } else {
            prefix.to_string()
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_event_is_placed_in_any_parameter() {
        // the paper's clamps: no clamps kept, every coordinate from (z*, δ, φ)
        let paper = Clamps::new(0.115, 0.05, 0.802);
        let e = Event::at(EventKind::Wall, &paper, 0.1, 0, String::new());
        assert!(e.clamps.is_none());
        assert_eq!(e.value(Parameter::Phi), e.phi_over_2pi);
        assert_eq!(e.value(Parameter::ZStar), 0.115);
        assert_eq!(e.value(Parameter::EndTilt), 0.0);
        assert!(e.value(Parameter::K3).is_nan());
        // a tilted clamp carrying K3: both from the kept clamps
        let c = Parameter::K3.with(&Parameter::EndTilt.with(&paper, -0.043), 2.5);
        let e = Event::at(EventKind::Wall, &c, 0.1, 0, String::new());
        assert_eq!(e.value(Parameter::EndTilt), -0.043);
        assert_eq!(e.value(Parameter::K3), 2.5);
        assert_eq!(e.value(Parameter::Phi), c.phi_over_2pi());
    }
}
