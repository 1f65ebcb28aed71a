//! A run's progress told to a Python callable: `callback(stage, done, total)`, from the worker
//! threads, at most a few times a second per stage and always at a stage's end.

use std::sync::Mutex;
use std::time::{Duration, Instant};

use penumbra_solver::Progress;
use pyo3::prelude::*;

/// How often a stage reports at most.
const EVERY: Duration = Duration::from_millis(200);

/// The stage under way.
struct Stage {
    name: String,
    total: u64,
    /// When the stage last reported, and with how many steps done.
    reported: Instant,
    last: u64,
}

/// Progress reported to a Python callable. An exception in the callable stops the reports, and
/// is raised once the run is over.
pub(crate) struct Callback {
    callable: Py<PyAny>,
    stage: Mutex<Option<Stage>>,
    failed: Mutex<Option<PyErr>>,
}

impl Callback {
    pub(crate) fn new(callable: Py<PyAny>) -> Callback {
        Callback {
            callable,
            stage: Mutex::new(None),
            failed: Mutex::new(None),
        }
    }

    /// The callable's exception, if it raised one.
    pub(crate) fn error(&self) -> Option<PyErr> {
        self.failed.lock().unwrap_or_else(|e| e.into_inner()).take()
    }

    /// Tells the callable, unless it failed before.
    fn report(&self, name: &str, done: u64, total: u64) {
        let mut failed = self.failed.lock().unwrap_or_else(|e| e.into_inner());
        if failed.is_some() {
            return;
        }
        // `None`: the interpreter is shutting down, and nobody is listening.
        let called =
            Python::try_attach(|py| self.callable.call1(py, (name, done, total)).map(drop));
        if let Some(Err(e)) = called {
            *failed = Some(e);
        }
    }

    fn with_stage(&self, f: impl FnOnce(&mut Option<Stage>) -> Option<(String, u64, u64)>) {
        // A poisoned lock only means another thread panicked mid-update: keep reporting.
        let due = f(&mut self.stage.lock().unwrap_or_else(|e| e.into_inner()));
        if let Some((name, done, total)) = due {
            self.report(&name, done, total);
        }
    }
}

impl Progress for Callback {
    fn start(&self, stage: &str, total: u64) {
        self.with_stage(|current| {
            *current = Some(Stage {
                name: stage.to_owned(),
                total,
                reported: Instant::now(),
                last: 0,
            });
            Some((stage.to_owned(), 0, total))
        });
    }

    fn set(&self, done: u64) {
        self.with_stage(|current| {
            let stage = current.as_mut()?;
            let now = Instant::now();
            // The end is reported by `finish`.
            if done == stage.last || done >= stage.total || now - stage.reported < EVERY {
                return None;
            }
            (stage.reported, stage.last) = (now, done);
            Some((stage.name.clone(), done, stage.total))
        });
    }

    fn finish(&self) {
        self.with_stage(|current| {
            let stage = current.take()?;
            Some((stage.name, stage.total, stage.total))
        });
    }
}
