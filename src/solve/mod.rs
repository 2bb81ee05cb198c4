//! Solvers: sparse linear algebra and Newton's method for equilibria.

pub mod newton;
pub mod sparse;
