//! What a user runs: the starting equilibrium, branches (continuation with
//! located events), sweeps, loading paths, maps and the boundary walk,
//! asymptotics. Results go to observers; nothing here touches files.

pub mod asymptotics;
pub mod boundary;
pub mod branch;
pub mod error;
pub mod fold;
pub mod loading;
pub mod map;
pub mod observer;
pub mod polish;
pub mod run;
pub mod start;
pub mod verify;
