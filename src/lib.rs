//! knotrod: equilibria, stability and knot diagnostics of clamped elastic rods
//! (discrete elastic rods), after "Stable elastic knots with no self-contact".
//!
//! Layers, from the bottom up (each imports only those below it; see
//! docs/design.md): [`linalg`], [`geometry`], [`model`], [`solve`],
//! [`analysis`], [`scene`], [`study`], [`io`], [`report`], [`cli`].
//!
//! The entry points most programs need are re-exported here:
//!
//! ```no_run
//! let scene = knotrod::Scene::load(std::path::Path::new("scenes/appendix_d.toml"))?;
//! let eq = knotrod::solve_scene(&scene, None)?;
//! println!("Tw = {}, stable: {}, good knot: {}", eq.twist, eq.stable, eq.good_knot);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

pub mod analysis;
// the unit-test harness leaves out the CLI: it holds no unit tests (the suite
// runs it as the binary; tests/architecture.rs keeps it so), and the harness
// is the whole crate compiled a second time
#[cfg(not(test))]
pub mod cli;
pub mod geometry;
pub mod io;
pub mod linalg;
pub mod model;
pub mod report;
pub mod scene;
pub mod solve;
pub mod study;

pub use analysis::class::Class;
pub use analysis::equilibrium::{AnalysisError, Conformation, Equilibrium, Measure, analyse};
pub use analysis::event::{Event, EventKind};
pub use geometry::knot::{KnotType, knot_type};
pub use geometry::writhe::writhe_closed;
pub use model::energy::RodEnergy;
pub use model::rod::{Clamps, Law, Parameter, RodModel, RodState};
pub use scene::{Scene, SceneError};
pub use solve::continuation::{ContinuationError, ContinuationSettings, Tracer};
pub use solve::minimizer::Minimizer;
pub use solve::outcome::{SolveError, SolveReport, SolverSettings};
pub use study::error::StudyError;
pub use study::run::run_scene;
pub use study::start::{solve_scene, starting_equilibrium};
