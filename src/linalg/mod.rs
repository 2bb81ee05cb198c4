//! Linear algebra that knows no physics: sparse symmetric patterns and their
//! LDLᵀ factorisation with a reused symbolic analysis, inertia and the lowest
//! eigenvalues (shift-invert Lanczos), forward-mode jets for exact
//! derivatives, and process-wide work counters.

pub mod eigen;
pub mod jet;
pub mod sparse;

/// Process-wide work counters, read by `knotrod bench`.
pub mod counters {
    use std::sync::atomic::AtomicUsize;
    /// Numerical sparse factorisations.
    pub static FACTORIZATIONS: AtomicUsize = AtomicUsize::new(0);
    /// Newton and corrector iterations (Hessian evaluations).
    pub static NEWTON_ITERATIONS: AtomicUsize = AtomicUsize::new(0);
}
