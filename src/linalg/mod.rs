//! Linear algebra that knows no physics: sparse symmetric patterns and their
//! LDLᵀ factorisation with a reused symbolic analysis, inertia and the lowest
//! eigenvalues (shift-invert Lanczos), forward-mode jets for exact
//! derivatives, and the work counters of a run.

pub mod eigen;
pub mod jet;
pub mod sparse;

pub mod counters;
