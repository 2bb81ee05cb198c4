//! The integration tests, one binary: a module per area (`cargo test --test
//! suite maps::` runs one area). One binary links the crate and its
//! dependencies once instead of once per file, which is most of the time a
//! change takes to reach its first test (CONTRIBUTING.md).

mod common;

mod analytic;
mod architecture;
mod auto;
mod bad_input;
mod contact;
mod continuation;
mod continuum_stability;
mod convergence;
mod diagnostics;
mod energy_derivatives;
mod free_ends;
mod fuzz;
mod general_rods;
mod knots;
mod live;
mod map_general;
mod maps;
mod model_parameters;
mod observer;
mod output_paths;
mod paper_equilibria;
mod pictures;
mod polish;
mod profile;
mod recordings;
mod reliability;
mod ribbon;
mod scenes_and_cli;
mod stability;
mod strip;
mod strip_shooting;
mod verify;
mod vtk_export;
mod writers;
