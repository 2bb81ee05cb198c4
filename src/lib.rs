//! knotrod: equilibria, stability and knot diagnostics of clamped elastic rods
//! (discrete elastic rods), after "Stable elastic knots with no self-contact".
//!
//! Layers, from the bottom up (each imports only those below it; see
//! docs/design.md): [`linalg`], [`geometry`], [`model`], [`solve`],
//! [`analysis`], [`scene`], [`study`], [`io`], [`report`], [`cli`].
#![warn(missing_docs)]

pub mod analysis;
pub mod cli;
pub mod geometry;
pub mod io;
pub mod linalg;
pub mod model;
pub mod report;
pub mod scene;
pub mod solve;
pub mod study;
