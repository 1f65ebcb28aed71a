//! Progress reporting from long computations, without tying the library to a terminal.

/// Receives progress of a stage: `start` with the number of steps, `set` with the steps done.
/// Called from worker threads, so implementations must be `Sync`.
pub trait Progress: Sync {
    fn start(&self, stage: &str, total: u64);
    fn set(&self, done: u64);
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
