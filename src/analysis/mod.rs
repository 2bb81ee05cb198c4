//! One equilibrium measured: clamp reactions, twist, walls, distances, knot
//! type, stability (contacts held), its class, and the typed events of a path.

pub mod class;
pub mod equilibrium;
pub mod event;
