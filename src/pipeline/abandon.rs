//! Meshing that an interrupt abandons instead of awaiting. Meshing checks the interrupt between
//! pieces of work, but one piece (a surface's quality refinement, a trial refinement of a large
//! floor) can take half a second, longer on a busy machine; a run interrupted then would miss
//! the second it has to write what it keeps. So the first mesh is made on threads of its own,
//! and an interrupted run goes on to its least mesh at once: the abandoned work stops at its
//! next check and is dropped.

use std::panic::AssertUnwindSafe;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

use penumbra_meshing::{Interrupt, MeshError};

/// How often the waiting run looks at the interrupt.
const POLL: Duration = Duration::from_millis(5);

/// `work`'s result, made on a thread pool of its own (as many threads as the caller's), or
/// [`MeshError::Interrupted`] as soon as `interrupt` is set. `work` is handed an interrupt of its
/// own, set when it is abandoned, so that clearing the run's interrupt for later work does not
/// let abandoned work go on.
pub(crate) fn abandoned_on<T: Send + 'static>(
    interrupt: &Interrupt,
    work: impl FnOnce(&Interrupt) -> Result<T, MeshError> + Send + 'static,
) -> Result<T, MeshError> {
    let threads = rayon::current_num_threads();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("mesh-{i}"))
        .build();
    // Without a pool of its own the work runs here and is awaited.
    let Ok(pool) = pool else {
        return work(interrupt);
    };
    let own = Interrupt::default();
    let theirs = own.clone();
    let (send, receive) = mpsc::channel();
    pool.spawn(move || {
        let result = std::panic::catch_unwind(AssertUnwindSafe(|| work(&theirs)));
        // The receiver is gone when the work was abandoned: nothing to tell.
        let _ = send.send(result);
    });
    loop {
        match receive.recv_timeout(POLL) {
            Ok(Ok(result)) => return result,
            // A panic of the work is the run's, as if it had run here.
            Ok(Err(panic)) => std::panic::resume_unwind(panic),
            Err(RecvTimeoutError::Timeout) if !interrupt.is_set() => {}
            // Interrupted (the work always sends, so the channel closes only with the pool).
            Err(_) => {
                own.set();
                return Err(MeshError::Interrupted);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::time::Instant;

    /// Work that ignores the interrupt for a long time is abandoned at once, and told to stop.
    #[test]
    fn interrupted_work_is_abandoned_and_told_to_stop() {
        let interrupt = Interrupt::default();
        let told = Arc::new(AtomicBool::new(false));
        let seen = Arc::clone(&told);
        let setter = interrupt.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(50));
            setter.set();
        });
        let started = Instant::now();
        let result = abandoned_on(&interrupt, move |own| {
            while !own.is_set() {
                std::thread::sleep(Duration::from_millis(1));
            }
            // Deaf to the interrupt for a while, as one long piece of meshing is.
            std::thread::sleep(Duration::from_secs(3));
            seen.store(true, Ordering::Relaxed);
            Ok(())
        });
        assert!(matches!(result, Err(MeshError::Interrupted)));
        assert!(started.elapsed() < Duration::from_secs(2));
        assert!(!told.load(Ordering::Relaxed), "the work was awaited");
    }

    /// Work that finishes gives its result, on as many threads as the caller has.
    #[test]
    fn finished_work_gives_its_result() {
        let threads = rayon::current_num_threads();
        let result = abandoned_on(&Interrupt::default(), |_| Ok(rayon::current_num_threads()));
        assert_eq!(result.ok(), Some(threads));
        let failed: Result<(), _> =
            abandoned_on(&Interrupt::default(), |_| Err(MeshError::Interrupted));
        assert!(matches!(failed, Err(MeshError::Interrupted)));
    }
}
