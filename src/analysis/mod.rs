//! One equilibrium measured: clamp reactions, twist, walls, distances, knot
//! type, stability (contacts held), its class, the typed events of a path, and
//! its fields along s (`profile`).

pub mod class;
pub mod equilibrium;
pub mod event;
pub mod profile;
