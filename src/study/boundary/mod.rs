//! The boundary of the island of good knots traced directly in the plane of
//! two parameters (the map's swept parameter, and the continuation's along
//! the lines: φ/2π for the paper's maps). Each boundary is a
//! codimension-one condition on the equilibria, zero on the curve and
//! positive on the good side:
//! - a wall touched: the smaller of the lowest interior node height (z = 0)
//!   and z* minus the highest (z = z*) — one condition, since the flip
//!   symmetry maps z to z* − z and a symmetric knot touches both at once;
//! - a crossing: the signed distance of the two strands (two segments, or a
//!   segment and a clamp's ray) whose passage changes the knot;
//! - stability: the lowest eigenvalue of the Hessian.
//!
//! A condition is followed by pseudo-arclength continuation of its zero set in
//! the plane: a predictor along the curve's tangent, a corrector along its
//! normal (secant iteration on the condition), each evaluation an equilibrium
//! found by Newton at fixed clamps from its neighbour, so that the whole walk
//! stays on one family of equilibria. Walking with the good region on the
//! left, the walk turns onto the next condition at every corner where another
//! property fails, until it closes on its start.
//!
//! `condition` defines the conditions, `walk` the continuation round the
//! region, `traced` names the pieces and measures the loop, `polish` locates
//! the loop again on the continuum (`[map] polish = true`).

mod condition;
mod polish;
mod traced;
mod walk;

pub use condition::{Condition, OtherStrand, Strands};
pub use traced::{DroppedPoint, GridCheck, Piece, PolishedBoundary, PolishedCorner, Traced};
pub use walk::trace_island;
