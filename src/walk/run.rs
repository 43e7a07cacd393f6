//! Walks of many steps (docs/model.md section 5): [`simulate`] keeps every step's report, [`simulate_streaming`]
//! hands each to a callback and keeps none; [`WalkRun`] and [`WalkEnd`] say how they ended.

use super::error::WalkError;
use super::report::StepReport;
use super::section::SectionState;
use super::trajectory::Trajectory;
use super::walker::Walker;
use super::work::WorkCounts;
use crate::dynamics::Model;
use crate::params::SolverOptions;

/// The result of [`simulate`]: every completed step, and how the run ended.
#[derive(Debug, Clone)]
pub struct WalkRun {
    /// Reports of the completed steps.
    pub steps: Vec<StepReport>,
    /// `None` if all requested steps were walked, else why the walk stopped.
    pub failure: Option<WalkError>,
    /// Time reached \[s\]: the last touchdown, or the time of the failure if the walk stopped.
    pub time: f64,
    /// The work of the walk (integrator steps, events, impacts), failed step included.
    pub work: WorkCounts,
}

/// Walk `steps` steps from `initial`, keeping every completed step when the walk stops early.
///
/// Every report is kept in memory; for long walks use [`simulate_streaming`].
pub fn simulate(
    model: &Model,
    opts: &SolverOptions,
    initial: &SectionState,
    steps: usize,
    trajectory: Option<&mut Trajectory>,
) -> Result<WalkRun, WalkError> {
    let mut reports = Vec::with_capacity(steps.min(1 << 16));
    let end = simulate_streaming(model, opts, initial, steps, trajectory, None, |report| {
        reports.push(*report);
        Ok::<(), WalkError>(())
    })?;
    Ok(WalkRun {
        steps: reports,
        failure: end.failure,
        time: end.time,
        work: end.work,
    })
}

/// How a walk driven by [`simulate_streaming`] ended.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkEnd {
    /// Steps completed.
    pub steps: usize,
    /// Why the walk stopped before the requested number of steps, if a step failed.
    pub failure: Option<WalkError>,
    /// The interrupt flag stopped the walk (between two steps).
    pub interrupted: bool,
    /// Time reached \[s\]: the last touchdown, or the time of the failure if a step failed.
    pub time: f64,
    /// The work of the walk (integrator steps, events, impacts), failed step included.
    pub work: WorkCounts,
}

/// Walk up to `steps` steps from `initial`, handing each step's report to `on_step` as soon as the step is
/// done and keeping none, so memory does not grow with the number of steps. The trajectory, if any, is
/// flushed after every step.
///
/// The walk stops early when a step fails (the failure and its time are in the [`WalkEnd`]), when `on_step`
/// returns an error (returned as is), when the trajectory's sink fails (find its error with
/// [`Trajectory::take_error`]), or when `interrupt` is set; the flag is checked before every step and, inside a
/// step, every [`INTERRUPT_CHECK_STEPS`](super::INTERRUPT_CHECK_STEPS) integrator steps (a step with
/// stiff legs can take millions), so an interrupted walk ends soon with every completed step reported (the
/// step in progress is dropped).
pub fn simulate_streaming<E: From<WalkError>>(
    model: &Model,
    opts: &SolverOptions,
    initial: &SectionState,
    steps: usize,
    mut trajectory: Option<&mut Trajectory>,
    interrupt: Option<&std::sync::atomic::AtomicBool>,
    mut on_step: impl FnMut(&StepReport) -> Result<(), E>,
) -> Result<WalkEnd, E> {
    let mut walker = Walker::new(model, opts, initial)?.with_interrupt(interrupt);
    let mut end = WalkEnd {
        steps: 0,
        failure: None,
        interrupted: false,
        time: walker.state().time,
        work: WorkCounts::ZERO,
    };
    while end.steps < steps {
        if interrupt.is_some_and(|flag| flag.load(std::sync::atomic::Ordering::Relaxed)) {
            end.interrupted = true;
            break;
        }
        let result = walker.step(trajectory.as_deref_mut());
        let sink_failed = trajectory.as_deref_mut().is_some_and(|tr| {
            tr.flush();
            tr.failed()
        });
        if sink_failed {
            break;
        }
        match result {
            Ok(report) => {
                end.steps += 1;
                end.time = walker.state().time;
                on_step(&report)?;
            }
            Err(WalkError::Interrupted { .. }) => {
                end.interrupted = true;
                break;
            }
            Err(e) => {
                end.time = e.time().unwrap_or(end.time);
                end.failure = Some(e);
                break;
            }
        }
    }
    end.work = walker.work();
    Ok(end)
}
