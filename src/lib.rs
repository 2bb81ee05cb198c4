//! knotrod: equilibria, stability and knot diagnostics of clamped elastic rods
//! (discrete elastic rods), after "Stable elastic knots with no self-contact".

pub mod model;
pub mod solve;
