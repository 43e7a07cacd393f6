//! The sampled trajectory of a walk: [`Sample`]s taken from the dense output every `dt` seconds and after
//! every event, kept in memory or streamed to a [`SampleSink`] ([`Trajectory`]).

use crate::contact::{constrained_dynamics, ActiveSet, Multipliers};
use crate::dynamics::{Coords, Model, X};
use crate::integrate::DenseStep;

use super::phase::{unpack, WalkState, WalkVector, NY};

/// One sample of the trajectory, taken from the dense output.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Time \[s\].
    pub time: f64,
    /// `q` with `x` measured from the start of the walk.
    pub q: Coords,
    /// `q'`.
    pub qd: Coords,
    /// Active contacts and stoppers.
    pub active: ActiveSet,
    /// `[lambda_1, lambda_2, lambda_3, lambda_4, mu_1, mu_2]`.
    pub multipliers: Multipliers,
    /// Which physical leg is Leg 1.
    pub leg1: usize,
}

/// Where a streaming [`Trajectory`] sends each sample as it is taken (for instance a CSV writer).
pub trait SampleSink: Send {
    /// Take one sample.
    fn write(&mut self, sample: &Sample) -> std::io::Result<()>;
    /// Push what is buffered to its destination ([`super::simulate_streaming`] calls it after every step).
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Samples of the trajectory every `dt` seconds, plus one right after every event.
///
/// Two kinds: [`Trajectory::new`] keeps every sample in memory (in [`Trajectory::samples`]), for plots and
/// tests of short walks; [`Trajectory::streaming`] hands each sample to a [`SampleSink`] as it is taken and
/// keeps none, so a long walk runs in bounded memory. A sink that fails is not called again; its first error
/// is kept for [`Trajectory::take_error`].
pub struct Trajectory {
    dt: f64,
    next: usize,
    /// Time of the last sample taken, if any.
    last_time: Option<f64>,
    /// Samples taken so far.
    taken: usize,
    /// The samples, in time order (always empty for a streaming trajectory).
    pub samples: Vec<Sample>,
    sink: Option<Box<dyn SampleSink>>,
    error: Option<std::io::Error>,
}

impl std::fmt::Debug for Trajectory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Trajectory")
            .field("dt", &self.dt)
            .field("taken", &self.taken)
            .field("samples", &self.samples.len())
            .field("streaming", &self.sink.is_some())
            .field("error", &self.error)
            .finish()
    }
}

impl Trajectory {
    /// Sample every `dt` seconds of simulated time and keep the samples in memory.
    pub fn new(dt: f64) -> Trajectory {
        Trajectory {
            dt,
            next: 0,
            last_time: None,
            taken: 0,
            samples: Vec::new(),
            sink: None,
            error: None,
        }
    }

    /// Sample every `dt` seconds of simulated time and hand each sample to `sink` as it is taken, keeping
    /// none in memory.
    pub fn streaming(dt: f64, sink: Box<dyn SampleSink>) -> Trajectory {
        Trajectory {
            sink: Some(sink),
            ..Trajectory::new(dt)
        }
    }

    /// Number of samples taken so far (kept or streamed).
    pub fn len(&self) -> usize {
        self.taken
    }

    /// No sample taken yet.
    pub fn is_empty(&self) -> bool {
        self.taken == 0
    }

    /// The first error of the sink, if it failed (it is then no longer called). Taking it clears it.
    pub fn take_error(&mut self) -> Option<std::io::Error> {
        self.error.take()
    }

    /// The sink failed (its error is kept for [`Trajectory::take_error`]).
    pub(crate) fn failed(&self) -> bool {
        self.error.is_some()
    }

    /// Flush the sink, if any (a failure is kept for [`Trajectory::take_error`]).
    pub(crate) fn flush(&mut self) {
        if let (Some(sink), None) = (&mut self.sink, &self.error) {
            if let Err(e) = sink.flush() {
                self.error = Some(e);
            }
        }
    }

    /// Take a sample of the state `y` at `time`, in the frame of `frame`.
    pub(crate) fn push(
        &mut self,
        model: &Model,
        time: f64,
        y: &WalkVector,
        active: ActiveSet,
        frame: &WalkState,
    ) {
        let (mut q, qd) = unpack(y);
        let multipliers = constrained_dynamics(model, &q, &qd, &active)
            .map_or(Multipliers::repeat(f64::NAN), |d| d.multipliers);
        q[X] += frame.x_origin;
        let sample = Sample {
            time,
            q,
            qd,
            active,
            multipliers,
            leg1: frame.leg1,
        };
        self.last_time = Some(time);
        self.taken += 1;
        match &mut self.sink {
            Some(sink) => {
                if self.error.is_none() {
                    if let Err(e) = sink.write(&sample) {
                        self.error = Some(e);
                    }
                }
            }
            None => self.samples.push(sample),
        }
    }

    /// Take the samples due on the dense output of `step` up to `until`.
    pub(crate) fn record(
        &mut self,
        model: &Model,
        step: &DenseStep<NY>,
        until: f64,
        active: ActiveSet,
        frame: &WalkState,
    ) {
        loop {
            let t = self.next as f64 * self.dt;
            if t > until {
                break;
            }
            if t >= step.t0() && self.last_time.is_none_or(|last| last < t) {
                self.push(model, t, &step.eval(t), active, frame);
            }
            self.next += 1;
        }
    }
}
