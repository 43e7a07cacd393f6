//! The library's interrupt flag (Ctrl-C): set by the command line's signal handler and by the Python binding's
//! signal watcher, read by every walk (every [`INTERRUPT_CHECK_STEPS`](super::INTERRUPT_CHECK_STEPS)
//! integrator steps, and before the first) and by the grid runner between points.
//!
//! A walk that reads it set fails with [`WalkError::Interrupted`](super::WalkError::Interrupted), so every
//! phase of every job (gaits, continuation, thresholds, special points, curves) stops within a fraction of a
//! second. What a phase computed while the flag was set is not a result: a job that sees [`interrupted`] after
//! a phase keeps only what was complete before it (and says so); it never turns an interrupted walk into a
//! family end, a threshold or a special point. Whoever sets the flag clears it before the next job
//! ([`clear_interrupt`]).

use std::sync::atomic::{AtomicBool, Ordering};

/// The flag (see the module documentation).
static INTERRUPT: AtomicBool = AtomicBool::new(false);

/// The library's interrupt flag, for a signal handler to set.
pub fn interrupt_flag() -> &'static AtomicBool {
    &INTERRUPT
}

/// Has the interrupt flag been set (what the job computed since may be cut short)?
pub fn interrupted() -> bool {
    INTERRUPT.load(Ordering::SeqCst)
}

/// Clear the interrupt flag (before a new job, in a process that outlives an interruption).
pub fn clear_interrupt() {
    INTERRUPT.store(false, Ordering::SeqCst);
}

/// Is `flag` (a job's own), or the library's flag, set?
pub(crate) fn stop_requested(flag: Option<&AtomicBool>) -> bool {
    flag.is_some_and(|f| f.load(Ordering::Relaxed)) || INTERRUPT.load(Ordering::Relaxed)
}
