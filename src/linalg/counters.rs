//! The work of a run, counted where it is done: the solvers' iterations and
//! factorisations and the last relative gradient any of them met (the
//! heartbeat a progress display shows while one long solve runs; numerics
//! never print). A run owns its [`Work`]: the code running for it counts into
//! it through [`within`] on its thread, and a parallel section hands it on to
//! its workers with [`current`] and [`within`] again, so two runs in one
//! process (Python threads, the bench's workloads) never mix their counts.
//! Work done outside any run is not counted, nor is the continuum's shooting
//! (its Newton is not the discrete solvers').

use std::cell::RefCell;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

/// What one run has done so far.
#[derive(Debug, Default)]
pub struct Work {
    factorizations: AtomicUsize,
    iterations: AtomicUsize,
    /// f64 bits.
    residual: AtomicU64,
}

impl Work {
    /// A run's counters, all zero.
    pub fn new() -> Arc<Work> {
        Arc::new(Work::default())
    }

    /// Numerical sparse factorisations.
    pub fn factorizations(&self) -> usize {
        self.factorizations.load(Ordering::Relaxed)
    }

    /// Newton, SQP and corrector iterations (Hessian evaluations).
    pub fn iterations(&self) -> usize {
        self.iterations.load(Ordering::Relaxed)
    }

    /// The last relative gradient met (0 before any).
    pub fn residual(&self) -> f64 {
        f64::from_bits(self.residual.load(Ordering::Relaxed))
    }
}

thread_local! {
    /// The work this thread counts into, if it runs for one.
    static CURRENT: RefCell<Option<Arc<Work>>> = const { RefCell::new(None) };
}

/// Puts the thread's previous work back when dropped (also on a panic).
struct Restore(Option<Arc<Work>>);

impl Drop for Restore {
    fn drop(&mut self) {
        let previous = self.0.take();
        CURRENT.with(|c| *c.borrow_mut() = previous);
    }
}

/// Run `f` with what it does on this thread counted in `work` (None: not
/// counted).
pub fn within<T>(work: Option<&Arc<Work>>, f: impl FnOnce() -> T) -> T {
    let previous = CURRENT.with(|c| c.replace(work.cloned()));
    let _restore = Restore(previous);
    f()
}

/// The work this thread counts into: to hand on to parallel workers.
pub fn current() -> Option<Arc<Work>> {
    CURRENT.with(|c| c.borrow().clone())
}

fn count(f: impl FnOnce(&Work)) {
    CURRENT.with(|c| {
        if let Some(w) = c.borrow().as_deref() {
            f(w);
        }
    });
}

/// One numerical factorisation done.
pub fn add_factorization() {
    count(|w| {
        w.factorizations.fetch_add(1, Ordering::Relaxed);
    });
}

/// One solver iteration done.
pub fn add_iteration() {
    count(|w| {
        w.iterations.fetch_add(1, Ordering::Relaxed);
    });
}

/// The relative gradient a solver just met.
pub fn set_residual(rel: f64) {
    count(|w| w.residual.store(rel.to_bits(), Ordering::Relaxed));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_count_their_own_work_across_threads() {
        let (a, b) = (Work::new(), Work::new());
        add_iteration(); // outside any run: not counted
        within(Some(&a), || {
            add_iteration();
            add_factorization();
            set_residual(1e-3);
            // a worker thread handed the run's work counts into it
            let work = current();
            std::thread::spawn(move || within(work.as_ref(), add_iteration))
                .join()
                .unwrap();
            // a run nested inside (another study) counts apart
            within(Some(&b), add_iteration);
            add_iteration();
        });
        add_iteration();
        assert_eq!((a.iterations(), a.factorizations()), (3, 1));
        assert_eq!(a.residual(), 1e-3);
        assert_eq!((b.iterations(), b.factorizations()), (1, 0));
        assert!(current().is_none());
    }
}
