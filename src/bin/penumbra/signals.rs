//! Ctrl-C and SIGTERM: the run stops computing and writes what it has; a run that has not
//! stopped a second later is ended, writing nothing; a second signal ends it at once.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use penumbra_solver::Interrupt;

/// How long a run has after a signal to stop computing by itself.
const GRACE: Duration = Duration::from_millis(900);

/// How often the watchdog looks at the interrupt flag.
const POLL: Duration = Duration::from_millis(20);

/// A run's signals: which one came, and whether its outputs are being written (which a signal
/// does not cut short).
pub(crate) struct Signals {
    received: Arc<AtomicUsize>,
    writing: Arc<AtomicBool>,
}

impl Signals {
    /// Catches SIGINT and SIGTERM into `interrupt`, and watches that the run stops within
    /// [`GRACE`] of one; `out` is named when the run is ended with nothing written.
    pub(crate) fn catch(interrupt: &Interrupt, out: PathBuf) -> std::io::Result<Signals> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let received = Arc::new(AtomicUsize::new(0));
        for signal in [SIGINT, SIGTERM] {
            // Registered first, so it sees the flag as it was before this signal set it.
            signal_hook::flag::register_conditional_shutdown(
                signal,
                128 + signal,
                interrupt.flag(),
            )?;
            signal_hook::flag::register(signal, interrupt.flag())?;
            signal_hook::flag::register_usize(signal, Arc::clone(&received), signal as usize)?;
        }
        let signals = Signals {
            received,
            writing: Arc::new(AtomicBool::new(false)),
        };
        let (interrupt, received, writing) = (
            interrupt.clone(),
            Arc::clone(&signals.received),
            Arc::clone(&signals.writing),
        );
        std::thread::Builder::new()
            .name("watchdog".into())
            .spawn(move || watch(&interrupt, &received, &writing, &out))?;
        Ok(signals)
    }

    /// The outputs are being written: a signal no longer ends the run unfinished.
    pub(crate) fn writing(&self) {
        self.writing.store(true, Ordering::SeqCst);
    }

    /// The conventional status of a process ended by the signal that came: 130 for SIGINT,
    /// 143 for SIGTERM.
    pub(crate) fn status(&self) -> std::process::ExitCode {
        std::process::ExitCode::from(status(&self.received))
    }
}

fn status(received: &AtomicUsize) -> u8 {
    128 + received.load(Ordering::Relaxed).min(127) as u8
}

/// Waits for a signal; then gives the run [`GRACE`] to stop computing, and ends it if it has not.
fn watch(
    interrupt: &Interrupt,
    received: &AtomicUsize,
    writing: &AtomicBool,
    out: &std::path::Path,
) {
    while !interrupt.is_set() {
        std::thread::sleep(POLL);
    }
    let signalled = Instant::now();
    while signalled.elapsed() < GRACE {
        if writing.load(Ordering::SeqCst) {
            return;
        }
        std::thread::sleep(POLL);
    }
    if writing.load(Ordering::SeqCst) {
        return;
    }
    eprintln!(
        "interrupted: the run did not stop within a second, so nothing written, {} left as it was",
        out.display()
    );
    std::process::exit(i32::from(status(received)));
}
