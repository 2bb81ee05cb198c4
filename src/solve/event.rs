//! The one vocabulary of events: what vanishes where an event is. Every
//! test function — a discrete branch's test values, a boundary walk's
//! conditions, the continuum branch's test functions — measures one of
//! these quantities, and an event kind is located, polished and bounded by
//! the root of its quantity.

/// The quantity whose zero an event is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Vanishing {
    /// The Hessian (discrete) or the shooting Jacobian (continuum) is
    /// singular: a fold, a branch point, a change of stability.
    Singularity,
    /// The rod's clearance from a wall.
    WallGap,
    /// The signed distance of two strands (of the centreline or a clamp's
    /// ray) passing through each other: a crossing, a change of knot type.
    StrandGap,
    /// The self-distance of a strip's ribbon (it touches itself before its
    /// centreline crosses).
    RibbonGap,
    /// The closest approach of two strands merges with another critical
    /// point of their distance: where a crossing piece of a boundary ends.
    StrandMerger,
}

impl Vanishing {
    /// What fails on the far side of the zero, said of a good knot.
    pub fn failure(self) -> &'static str {
        match self {
            Vanishing::Singularity => "it is unstable",
            Vanishing::WallGap => "it is not between the walls",
            Vanishing::StrandGap | Vanishing::StrandMerger => "its ray closure is not a trefoil",
            Vanishing::RibbonGap => "its ribbon passes through itself",
        }
    }
}
