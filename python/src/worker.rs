//! Work off the Python thread: on a pool of the threads asked for, with the GIL released while
//! the caller waits, and Ctrl-C turned into the work's interrupt.

use std::sync::mpsc;
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use crate::errors::bad_argument;

/// Most worker threads, as on the command line.
const MAX_THREADS: usize = 1024;

/// How often a waiting run looks for Ctrl-C.
const SIGNAL_POLL: Duration = Duration::from_millis(100);

/// A worker pool of `threads` threads, or `None` for rayon's global pool (one per core).
pub(crate) fn thread_pool(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    let Some(n) = threads else {
        return Ok(None);
    };
    if !(1..=MAX_THREADS).contains(&n) {
        return Err(bad_argument(
            "threads",
            format!("must be from 1 to {MAX_THREADS}, not {n}"),
        ));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map(Some)
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start {n} worker threads: {e}")))
}

/// Runs `work` on `pool` (or the global one) on a thread of its own, with the GIL released
/// while the calling thread waits, looking for Ctrl-C every [`SIGNAL_POLL`]. A first signal
/// sets `interrupt` and the work is waited for (it stops at its next check); a second one is
/// raised at once, and the work is left to end on its own in the background. Returns the work's
/// result and the first signal's exception, if one came. A panic in the work is a
/// `RuntimeError`, never the interpreter's end.
pub(crate) fn without_gil<T: Send + 'static>(
    py: Python<'_>,
    pool: Option<rayon::ThreadPool>,
    interrupt: &penumbra_solver::Interrupt,
    work: impl FnOnce() -> T + Send + 'static,
) -> PyResult<(T, Option<PyErr>)> {
    let (done, mut finished) = mpsc::channel();
    let worker = std::thread::Builder::new()
        .name("penumbra".into())
        .spawn(move || {
            let result = match pool {
                Some(pool) => pool.install(work),
                None => work(),
            };
            // Nobody waits any more after a second Ctrl-C: the result is dropped.
            let _ = done.send(result);
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a worker thread: {e}")))?;
    let mut signal = None;
    loop {
        // The waiting thread keeps its own thread state, so that Python can stop it at exit.
        let (receiver, received) = py.detach(move || {
            let received = finished.recv_timeout(SIGNAL_POLL);
            (finished, received)
        });
        finished = receiver;
        match received {
            Ok(result) => return Ok((result, signal)),
            Err(mpsc::RecvTimeoutError::Disconnected) => return Err(panicked(worker.join())),
            Err(mpsc::RecvTimeoutError::Timeout) => {}
        }
        if let Err(e) = py.check_signals() {
            if signal.is_some() {
                return Err(e);
            }
            interrupt.set();
            signal = Some(e);
        }
    }
}

/// The error of a worker that ended without a result.
fn panicked(joined: std::thread::Result<()>) -> PyErr {
    let what = match joined {
        Ok(()) => String::from("the worker ended without a result"),
        Err(panic) => panic
            .downcast_ref::<&str>()
            .map(ToString::to_string)
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default(),
    };
    PyRuntimeError::new_err(format!(
        "penumbra failed inside (a bug; please report it with the scene): {what}"
    ))
}
