//! The step meter of a task: how many steps the walks of one task of a grid job took (each step walked is one
//! evaluation of the step map `P`, failed steps included), whichever threads ran them.
//!
//! A grid job ([`crate::study`]) runs each of its tasks (a point of a row, a threshold's refinement, a continued
//! curve) under a meter of its own ([`StepMeter::run`]); every [`crate::walk::Walker`] step adds one to the meter of
//! the task that runs it. The meter is the thread's while the task runs, and a task's own parallel work carries
//! it to the threads that run it (`join`, `carried`), so that a thread that picks up another task's work
//! while it waits counts that work to the other task. The counts are therefore a deterministic function of
//! the tasks, the same for any number of threads, and with the task graph of the job's schedule they give its
//! work and span ([`crate::study::parallelism`]).

use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// The steps walked by one task (shared by the threads that run its work).
#[derive(Debug, Clone, Default)]
pub struct StepMeter(Arc<AtomicU64>);

thread_local! {
    /// The meter of the task this thread runs now, if any.
    static CURRENT: RefCell<Option<StepMeter>> = const { RefCell::new(None) };
}

impl StepMeter {
    /// A meter at zero.
    pub fn new() -> StepMeter {
        StepMeter::default()
    }

    /// The steps counted so far.
    pub fn steps(&self) -> u64 {
        self.0.load(Ordering::Relaxed)
    }

    /// Count `steps` more (the steps of a task nested in this one, measured apart).
    pub(crate) fn add(&self, steps: u64) {
        self.0.fetch_add(steps, Ordering::Relaxed);
    }

    /// Run `f` with this meter counting the steps it walks (on this thread, and on the threads its parallel
    /// work reaches through `join` and `carried`).
    pub fn run<R>(&self, f: impl FnOnce() -> R) -> R {
        with_meter(Some(self.clone()), f)
    }
}

/// Restores the thread's meter when a metered section ends, also on unwinding.
struct Restore(Option<StepMeter>);

impl Drop for Restore {
    fn drop(&mut self) {
        let previous = self.0.take();
        CURRENT.with(|c| *c.borrow_mut() = previous);
    }
}

/// Run `f` with `meter` as the thread's meter (none: steps are not counted), then restore the one before.
fn with_meter<R>(meter: Option<StepMeter>, f: impl FnOnce() -> R) -> R {
    let previous = CURRENT.with(|c| c.replace(meter));
    let _restore = Restore(previous);
    f()
}

/// The meter of the task this thread runs now.
pub(crate) fn current() -> Option<StepMeter> {
    CURRENT.with(|c| c.borrow().clone())
}

/// Count one step walked to the thread's meter (if any).
pub(crate) fn count_step() {
    CURRENT.with(|c| {
        if let Some(m) = c.borrow().as_ref() {
            m.0.fetch_add(1, Ordering::Relaxed);
        }
    });
}

/// `rayon::join(a, b)`, both halves counted to the caller's meter.
pub(crate) fn join<A, B, RA, RB>(a: A, b: B) -> (RA, RB)
where
    A: FnOnce() -> RA + Send,
    B: FnOnce() -> RB + Send,
    RA: Send,
    RB: Send,
{
    let (ma, mb) = (current(), current());
    rayon::join(move || with_meter(ma, a), move || with_meter(mb, b))
}

/// `f` counted to the caller's meter wherever it runs: the closure of a parallel iterator's `map` inside a
/// task.
pub(crate) fn carried<T, R>(f: impl Fn(T) -> R + Sync + Send) -> impl Fn(T) -> R + Sync + Send {
    let meter = current();
    move |t| with_meter(meter.clone(), || f(t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// Steps counted inside a task's parallel work go to its meter, never to another task's, for any number of
    /// threads; steps outside any task are not counted.
    #[test]
    fn parallel_work_counts_to_its_task() {
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let meters: Vec<StepMeter> = (0..8).map(|_| StepMeter::new()).collect();
            pool.install(|| {
                meters.par_iter().enumerate().for_each(|(k, m)| {
                    m.run(|| {
                        let (_, _) = join(
                            || (0..k).for_each(|_| count_step()),
                            || {
                                (0..10).into_par_iter().for_each(carried(|_| count_step()));
                            },
                        );
                    })
                });
                count_step();
            });
            let counts: Vec<u64> = meters.iter().map(StepMeter::steps).collect();
            assert_eq!(
                counts,
                (0..8).map(|k| k + 10).collect::<Vec<u64>>(),
                "{threads} threads"
            );
        }
        assert!(current().is_none());
    }
}
