//! Long jobs from Python: their progress handed to a Python callable, and Ctrl-C.
//!
//! A job runs with the GIL released on a thread of its own (its grid points on rayon's threads), while the
//! calling thread, Python's main thread, wakes every [`SIGNAL_POLL`]: it checks Python's signals and, when the
//! job has finished more points since the last wake, calls `progress(done, total)`. So the Python callable is
//! only ever called on the thread that called the job, with the GIL held, never from a worker thread, and at
//! most twenty times a second however fast the points come; its last call, when the job ends whole, has
//! `done == total`. An exception from the callable stops the job as Ctrl-C does.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

/// How often a long computation checks Python's signals and reports its progress.
pub(crate) const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// A job's count of finished points, and the Python callable `callback(done, total)` it is reported to.
pub(crate) struct Progress {
    done: AtomicUsize,
    total: usize,
    callback: Option<Py<PyAny>>,
}

impl Progress {
    /// `total` points to come, reported to `callback` (`None`: counted, never reported).
    pub(crate) fn new(callback: Option<Py<PyAny>>, total: usize) -> Progress {
        Progress {
            done: AtomicUsize::new(0),
            total,
            callback,
        }
    }

    /// One more point finished (called by the job's progress closure, on any thread).
    pub(crate) fn tick(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
    }

    /// Call the callback if the count moved since `reported` (updated); its exception is returned.
    fn report(&self, py: Python<'_>, reported: &mut usize) -> PyResult<()> {
        let Some(callback) = &self.callback else {
            return Ok(());
        };
        let done = self.done.load(Ordering::Relaxed).min(self.total);
        if done == *reported {
            return Ok(());
        }
        *reported = done;
        callback.call1(py, (done, self.total)).map(drop)
    }
}

/// Run `work` with the GIL released on a thread of its own while this (the calling, main) thread checks
/// Python's signals and reports `progress` every [`SIGNAL_POLL`] (see the module documentation): on Ctrl-C
/// (`KeyboardInterrupt`, or any exception a signal handler or the progress callable raises) it sets `flag`,
/// the interrupt flag `work` reads (the library's own for grids, where the grid runner stops between points;
/// a job's for a walk or a gait search, whose walker stops inside a step), waits for `work` to return,
/// discards its partial result and raises the exception.
pub(crate) fn interruptible_with<T: Send>(
    py: Python<'_>,
    flag: &AtomicBool,
    progress: Option<&Progress>,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    let (value, raised) = interruptible_keeping(py, flag, progress, work);
    match raised {
        Some(e) => Err(e),
        None => value,
    }
}

/// [`interruptible_with`] that keeps what `work` returned even when an exception was raised meanwhile: the
/// value (or the panic, as `RuntimeError`) and the exception, for a job whose complete part is handed on with
/// its `KeyboardInterrupt` (`vrw.map`).
pub(crate) fn interruptible_keeping<T: Send>(
    py: Python<'_>,
    flag: &AtomicBool,
    progress: Option<&Progress>,
    work: impl FnOnce() -> T + Send,
) -> (PyResult<T>, Option<PyErr>) {
    flag.store(false, Ordering::SeqCst);
    py.allow_threads(|| {
        std::thread::scope(|scope| {
            let handle = scope.spawn(work);
            let mut raised = None;
            let mut reported = 0;
            let poll = |raised: &mut Option<PyErr>, reported: &mut usize| {
                if raised.is_some() {
                    return;
                }
                let checked = Python::with_gil(|py| {
                    py.check_signals()?;
                    progress.map_or(Ok(()), |p| p.report(py, reported))
                });
                if let Err(e) = checked {
                    flag.store(true, Ordering::SeqCst);
                    *raised = Some(e);
                }
            };
            while !handle.is_finished() {
                std::thread::sleep(SIGNAL_POLL);
                poll(&mut raised, &mut reported);
            }
            let value = handle
                .join()
                .map_err(|_| PyRuntimeError::new_err("the computation panicked"));
            // The last count (the whole job's, unless it was cut short).
            poll(&mut raised, &mut reported);
            flag.store(false, Ordering::SeqCst);
            (value, raised)
        })
    })
}

/// The result of a job run by [`interruptible_keeping`] whose complete part survives Ctrl-C (`vrw.map`): its
/// conversion by `convert`, or the exception raised meanwhile. A result that says it was stopped
/// (`interrupted`: where, and what it kept) goes with the exception (a `KeyboardInterrupt` saying so if none
/// was raised) as its attribute `partial`, converted.
pub(crate) fn keeping_partial<'py, T>(
    py: Python<'py>,
    (computed, raised): (PyResult<Result<T, vrw::app::AppError>>, Option<PyErr>),
    interrupted: impl Fn(&T) -> Option<String>,
    convert: impl Fn(&T) -> PyResult<Bound<'py, pyo3::types::PyDict>>,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    match (computed, raised) {
        (Ok(Ok(result)), raised) => match (interrupted(&result), raised) {
            (Some(during), raised) => {
                let e = raised
                    .unwrap_or_else(|| pyo3::exceptions::PyKeyboardInterrupt::new_err(during));
                e.value(py).setattr("partial", convert(&result)?)?;
                Err(e)
            }
            (None, Some(e)) => Err(e),
            (None, None) => convert(&result),
        },
        (_, Some(e)) => Err(e),
        (computed, None) => convert(&computed?.map_err(crate::app_error)?),
    }
}
