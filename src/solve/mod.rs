//! Solvers: sparse linear algebra and Newton's method for equilibria.

pub mod continuation;
pub mod kkt;
pub mod newton;
pub mod sparse;
pub mod sqp;

/// Process-wide work counters, read by `knotrod bench`.
pub mod counters {
    use std::sync::atomic::AtomicUsize;
    /// Numerical sparse factorisations.
    pub static FACTORIZATIONS: AtomicUsize = AtomicUsize::new(0);
    /// Newton and corrector iterations (Hessian evaluations).
    pub static NEWTON_ITERATIONS: AtomicUsize = AtomicUsize::new(0);
}
