//! Progress reporting and interruption of long computations, without tying the libraries to a
//! terminal or a signal handler. The meshing crate is the first to do long work, so the solver
//! and the pipeline share these from here.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Receives progress of a stage: `start` with the number of steps, `set` with the steps done.
/// Called from worker threads, so implementations must be `Sync`.
pub trait Progress: Sync {
    /// A stage called `stage` begins, with `total` steps.
    fn start(&self, stage: &str, total: u64);
    /// `done` of the stage's steps are done.
    fn set(&self, done: u64);
    /// The stage is over.
    fn finish(&self);
}

/// Reports nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&self, _stage: &str, _total: u64) {}
    fn set(&self, _done: u64) {}
    fn finish(&self) {}
}

/// A flag that asks long work to stop, shared by its clones; a signal handler sets it through
/// [`Interrupt::flag`].
#[derive(Clone, Debug, Default)]
pub struct Interrupt(Arc<AtomicBool>);

impl Interrupt {
    /// The flag itself, for a signal handler to set.
    pub fn flag(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.0)
    }

    /// Asks the work to stop.
    pub fn set(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Withdraws the request, for work started afterwards.
    pub fn clear(&self) {
        self.0.store(false, Ordering::Relaxed);
    }

    /// Whether stopping was asked for.
    pub fn is_set(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// Two interrupts are the same when they share their flag.
impl PartialEq for Interrupt {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}
