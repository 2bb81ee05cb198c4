//! Solvers: sparse linear algebra and Newton's method for equilibria.

pub mod continuation;
pub mod newton;
pub mod sparse;
