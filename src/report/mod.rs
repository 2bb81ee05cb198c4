//! Reports computed from the library: the validation report, analytic
//! checks, and the benchmark.

pub mod analytic;
pub mod auto_events;
pub mod bench;
pub mod error;
pub mod validation;
pub mod verify;
