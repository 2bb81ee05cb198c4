//! Linear algebra that knows no physics: sparse symmetric patterns and their
//! LDLᵀ factorisation with a reused symbolic analysis, inertia and the lowest
//! eigenvalues (shift-invert Lanczos), forward-mode jets for exact
//! derivatives, and process-wide work counters.

pub mod eigen;
pub mod jet;
pub mod sparse;

/// Process-wide work counters, read by `knotrod bench`.
pub mod counters {
    use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
    /// Numerical sparse factorisations.
    pub static FACTORIZATIONS: AtomicUsize = AtomicUsize::new(0);
    /// Newton and corrector iterations (Hessian evaluations).
    pub static NEWTON_ITERATIONS: AtomicUsize = AtomicUsize::new(0);
    /// The last relative gradient any solver met (f64 bits): with the
    /// iteration count, the heartbeat a progress display shows while one long
    /// solve runs (numerics never print).
    pub static RESIDUAL: AtomicU64 = AtomicU64::new(0);

    /// Record the last relative gradient.
    pub fn set_residual(rel: f64) {
        RESIDUAL.store(rel.to_bits(), Ordering::Relaxed);
    }

    /// The last relative gradient recorded.
    pub fn residual() -> f64 {
        f64::from_bits(RESIDUAL.load(Ordering::Relaxed))
    }

    /// Newton and corrector iterations so far.
    pub fn iterations() -> usize {
        NEWTON_ITERATIONS.load(Ordering::Relaxed)
    }
}
