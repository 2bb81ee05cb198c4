//! knotrod: equilibria, stability and knot diagnostics of clamped elastic rods
//! (discrete elastic rods), after "Stable elastic knots with no self-contact".

pub mod analytic;
pub mod asymptotics;
pub mod bench;
pub mod boundary;
pub mod branch;
pub mod cli;
pub mod equilibrium;
pub mod export;
pub mod geometry;
pub mod loading;
pub mod map;
pub mod model;
pub mod plot;
pub mod record;
pub mod run;
pub mod scene;
pub mod solve;
pub mod stability;
pub mod summary;
pub mod validation;
