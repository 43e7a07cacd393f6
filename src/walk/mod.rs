//! The hybrid walk (MODEL.md sections 4-5): continuous phases separated by located events.
//!
//! A [`Walker`] holds the wheel at the Poincare section (just before a touchdown, after re-indexing) and
//! [`Walker::step`] advances it to the next one: the touchdown impact of [`impact`], then phases of constrained
//! motion, each integrated by an [`Integrator`] (DOP853 by default) until the earliest event, located on the dense
//! output (every event function is evaluated at the ends of [`EVENT_SAMPLES`] equal parts of each step):
//!
//! | event | function crossing zero from above |
//! |---|---|
//! | touchdown | height of the lowest tip of the legs not in `q` (the next leg's in a walk, see [`touchdown_leg`]) |
//! | lift-off of an active contact | normal force `lambda_2` or `lambda_4` (to [`FORCE_EVENT_MARGIN`] below 0) |
//! | landing / rear re-contact of an airborne tip | its height (armed once above `recontact_gap`, see below) |
//! | stopper unlock | the stopper's inward reaction (to [`FORCE_EVENT_MARGIN`] below 0) |
//! | stopper hit of a free leg | `L0 - L` (armed once below `L0 - stopper_gap`) |
//! | fall | hub height minus `fall_hub_height` |
//! | rolling back | `dtheta/dt` |
//!
//! **Grazing guard.** Right after a lift-off at `lambda_4 = 0` the tip leaves the ground with zero velocity and
//! acceleration, so the height function starts at zero. Such an event is *disarmed*: its function is
//! `height - (min(h0, 0) - recontact_gap)` with `h0` the height at the start of the phase, which fires only if
//! the tip sinks `recontact_gap` below where it started (or below the ground) without having risen; once the
//! height exceeds `recontact_gap` at an accepted step the event is armed and its function is the height itself.
//! Stoppers use `stopper_gap` the same way. Both are options of [`SolverOptions`]. (Measuring from `h0` matters
//! after a re-contact located at `-recontact_gap`: a guard measured from the ground would start at zero and
//! never fire, letting the tip sink.)
//!
//! **Impacts.** Every impact (touchdown, rear re-contact, stopper lock) is an impulse-level complementarity
//! problem over every unilateral unit present (see [`impact::plastic_impact`]); only the closing unit (and at
//! touchdown the paper's (A1)/(A3) choice for Leg 2) is forced. The force-level problem then picks the phase
//! that follows.
//!
//! **Audits.** Every step reports an energy audit and a contact audit ([`ContactAudit`]): the largest pulling
//! force at the ends of the [`EVENT_SAMPLES`] parts of every accepted integrator step and at every event instant,
//! the largest pulling impulse of its impacts, and
//! the deepest any tip went below the ground, checked on the dense output at [`PENETRATION_SAMPLES`] points
//! per integrator step.

mod error;
pub mod impact;
pub mod report;
pub mod section;

use nalgebra::SVector;

use crate::contact::{
    constrained_dynamics, largest_pull, ActiveSet, ConstrainedDynamics, Leg, Multipliers, Phase,
};
use crate::dynamics::{Coords, Model, L1, L2, NQ, THETA, X};
use crate::integrate::{locate_root, DenseStep, Integrator, OdeSystem, Tolerances};
use crate::params::SolverOptions;

pub use error::WalkError;
use impact::{
    bilateral_stoppers, close_unit, consistent_active_set, post_impact_candidates,
    touchdown_impact, touchdown_leg, Candidate, Unit, COMPLEMENTARITY_TOL,
};
pub use impact::{Branch, DlsIndicators};
pub use report::{ContactAudit, EnergyAudit, StepReport};
pub use section::SectionState;

/// A lift-off or stopper-unlock event fires when the force falls this far below zero \[N\] (or below its
/// value at the start of the phase, if the force-level problem accepted a slightly negative one within
/// [`impact::COMPLEMENTARITY_TOL`]): small enough that the contact audit sees no pull above 1e-9 N, large
/// enough that rounding of forces of ~100 N (~1e-12 N) cannot fire it.
pub const FORCE_EVENT_MARGIN: f64 = 1e-10;

/// The grazing guard of a landing or stopper event whose tip (leg) starts at the ground (stopper) already moving
/// into it \[m\]: such a contact is not grazing, so its event fires as soon as it moves this far (instead of
/// `recontact_gap` / `stopper_gap`). It happens after the `traditional` exchange drives the rear tip into the
/// ground, or when an impact's complementarity problem had no consistent solution.
pub const APPROACH_GAP: f64 = 1e-12;

/// Largest speed of Leg 2's tip at a touchdown for the wheel to count as on the Poincare section \[m/s\]: the
/// no-slip constraint holds it at rest up to the integration error (~1e-12 m/s).
pub const SECTION_TIP_SPEED_TOL: f64 = 1e-8;

/// Size of the integrated state `[q, q', E_damper]`.
pub const NY: usize = 2 * NQ + 1;
/// The integrated state: coordinates, velocities and the energy dissipated by the dampers so far in the step.
pub type WalkVector = SVector<f64, NY>;

fn pack(q: &Coords, qd: &Coords, dissipated: f64) -> WalkVector {
    let mut y = WalkVector::zeros();
    y.fixed_rows_mut::<NQ>(0).copy_from(q);
    y.fixed_rows_mut::<NQ>(NQ).copy_from(qd);
    y[2 * NQ] = dissipated;
    y
}

fn unpack(y: &WalkVector) -> (Coords, Coords) {
    (
        y.fixed_rows::<NQ>(0).into_owned(),
        y.fixed_rows::<NQ>(NQ).into_owned(),
    )
}

/// The vector field of one phase: Eq. (1) with the constraints of `active`, plus the damper power
/// `c (dL1^2 + dL2^2)` as a quadrature.
#[derive(Debug, Clone, Copy)]
pub struct PhaseSystem<'a> {
    /// The model.
    pub model: &'a Model,
    /// Active contacts and stoppers.
    pub active: ActiveSet,
}

impl OdeSystem<NY> for PhaseSystem<'_> {
    fn rhs(&self, _t: f64, y: &WalkVector) -> WalkVector {
        let (q, qd) = unpack(y);
        match constrained_dynamics(self.model, &q, &qd, &self.active) {
            Ok(d) => {
                let c = self.model.params().viscosity;
                pack(&qd, &d.qdd, c * (qd[L1] * qd[L1] + qd[L2] * qd[L2]))
            }
            // The integrator reports a non-finite derivative as an error with its time.
            Err(_) => WalkVector::repeat(f64::NAN),
        }
    }
}

/// The wheel between events, in the frame of its current Leg 1.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkState {
    /// Time \[s\].
    pub time: f64,
    /// `q` (with `x` relative to `x_origin`).
    pub q: Coords,
    /// `q'`.
    pub qd: Coords,
    /// Active contacts and stoppers (before the touchdown impact, when at the section).
    pub active: ActiveSet,
    /// Position along the slope of this frame's origin (the touchdown point of Leg 1) \[m\].
    pub x_origin: f64,
    /// Which physical leg (0..N) is Leg 1.
    pub leg1: usize,
}

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
    /// Push what is buffered to its destination ([`simulate_streaming`] calls it after every step).
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

    /// Flush the sink, if any (a failure is kept for [`Trajectory::take_error`]).
    pub fn flush(&mut self) {
        if let (Some(sink), None) = (&mut self.sink, &self.error) {
            if let Err(e) = sink.flush() {
                self.error = Some(e);
            }
        }
    }

    fn push(
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

    fn record(
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

/// Kinds of events (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum EventKind {
    Touchdown,
    Fall,
    RollBack,
    LiftOff(Leg),
    Unlock(Leg),
    Landing(Leg),
    StopperHit(Leg),
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Event {
    kind: EventKind,
    /// The event fires when its unshifted function falls to this level: 0 once armed, and
    /// `min(h0, 0) - gap` while a guarded event is disarmed (see the module documentation).
    floor: f64,
}

/// Event functions of one phase.
struct EventSet<'a> {
    model: &'a Model,
    opts: &'a SolverOptions,
    active: ActiveSet,
    events: Vec<Event>,
}

impl<'a> EventSet<'a> {
    fn new(
        model: &'a Model,
        opts: &'a SolverOptions,
        active: ActiveSet,
        y: &WalkVector,
    ) -> EventSet<'a> {
        let (q, qd) = unpack(y);
        let mut kinds = vec![EventKind::Touchdown, EventKind::Fall, EventKind::RollBack];
        for leg in Leg::BOTH {
            kinds.push(if active.contact(leg) {
                EventKind::LiftOff(leg)
            } else {
                EventKind::Landing(leg)
            });
            if !model.params().rigid_legs {
                kinds.push(if active.lock(leg) {
                    EventKind::Unlock(leg)
                } else {
                    EventKind::StopperHit(leg)
                });
            }
        }
        let mut set = EventSet {
            model,
            opts,
            active,
            events: Vec::with_capacity(kinds.len()),
        };
        let needed = kinds.iter().any(|k| Self::needs_forces(*k));
        let dynamics = set.dynamics_if(needed, &q, &qd);
        for kind in kinds {
            let f0 = || set.raw(kind, &q, &qd, &dynamics);
            let floor = if Self::needs_forces(kind) {
                // A force event fires once the force falls FORCE_EVENT_MARGIN below zero, or below its value at
                // the phase start if that is already (within the complementarity tolerance) negative.
                f0().min(0.0) - FORCE_EVENT_MARGIN
            } else if let Some(gap) = Self::guard(opts, kind) {
                // Guarded events start disarmed unless their function already clears the gap. A tip (leg) that
                // starts at the ground (stopper) already moving into it is not grazing: it fires at once.
                let gap = if set.approaching(kind, &q, &qd) {
                    APPROACH_GAP
                } else {
                    gap
                };
                let h0 = f0();
                if h0 > gap {
                    0.0
                } else {
                    h0.min(0.0) - gap
                }
            } else {
                0.0
            };
            set.events.push(Event { kind, floor });
        }
        set
    }

    /// The grazing guard of an event kind, if it has one.
    fn guard(opts: &SolverOptions, kind: EventKind) -> Option<f64> {
        match kind {
            EventKind::Landing(_) => Some(opts.recontact_gap),
            EventKind::StopperHit(_) => Some(opts.stopper_gap),
            _ => None,
        }
    }

    /// Is the unit of a guarded event moving into the ground (past its stopper) at `(q, q')`?
    fn approaching(&self, kind: EventKind, q: &Coords, qd: &Coords) -> bool {
        match kind {
            EventKind::Landing(leg) => {
                self.model.tip(q, qd, leg.index()).velocity(qd).y < -COMPLEMENTARITY_TOL
            }
            EventKind::StopperHit(leg) => qd[leg.length_coordinate()] > COMPLEMENTARITY_TOL,
            _ => false,
        }
    }

    /// The unshifted function of an event.
    fn raw(
        &self,
        kind: EventKind,
        q: &Coords,
        qd: &Coords,
        dynamics: &Option<ConstrainedDynamics>,
    ) -> f64 {
        let force = |f: &dyn Fn(&ConstrainedDynamics) -> f64| dynamics.as_ref().map_or(f64::NAN, f);
        match kind {
            EventKind::Touchdown => self.model.tip_height(q, touchdown_leg(self.model, q)),
            EventKind::Fall => self.model.hub_height(q) - self.opts.fall_hub_height,
            EventKind::RollBack => qd[THETA],
            EventKind::LiftOff(leg) => force(&|d| d.normal_force(leg)),
            EventKind::Unlock(leg) => force(&|d| d.stopper_reaction(leg)),
            EventKind::Landing(leg) => self.model.tip_height(q, leg.index()),
            EventKind::StopperHit(leg) => {
                self.model.params().stopper_length - q[leg.length_coordinate()]
            }
        }
    }

    /// The value of event `e` at `(q, q')`: its function measured from its floor.
    fn shifted(
        &self,
        e: &Event,
        q: &Coords,
        qd: &Coords,
        dynamics: &Option<ConstrainedDynamics>,
    ) -> f64 {
        self.raw(e.kind, q, qd, dynamics) - e.floor
    }

    fn needs_forces(kind: EventKind) -> bool {
        matches!(kind, EventKind::LiftOff(_) | EventKind::Unlock(_))
    }

    fn dynamics_if(&self, needed: bool, q: &Coords, qd: &Coords) -> Option<ConstrainedDynamics> {
        needed
            .then(|| constrained_dynamics(self.model, q, qd, &self.active).ok())
            .flatten()
    }

    /// Values of all event functions at `y`, and the largest pulling force there (0 when no unilateral unit is
    /// active, see [`largest_pull`]).
    fn values(&self, y: &WalkVector) -> (Vec<f64>, f64) {
        let (q, qd) = unpack(y);
        let needed = self.events.iter().any(|e| Self::needs_forces(e.kind));
        let dynamics = self.dynamics_if(needed, &q, &qd);
        let values = self
            .events
            .iter()
            .map(|e| self.shifted(e, &q, &qd, &dynamics))
            .collect();
        let pull = dynamics.map_or(0.0, |d| {
            largest_pull(&d.multipliers, &self.active, self.model.params().rigid_legs)
        });
        (values, pull)
    }

    /// Value of event `k` at `y`.
    fn value(&self, k: usize, y: &WalkVector) -> f64 {
        let (q, qd) = unpack(y);
        let e = &self.events[k];
        let dynamics = self.dynamics_if(Self::needs_forces(e.kind), &q, &qd);
        self.shifted(e, &q, &qd, &dynamics)
    }

    /// Arm guarded events whose function has cleared its gap; `values` are updated to the new definitions.
    fn arm(&mut self, values: &mut [f64]) {
        let opts = self.opts;
        for (e, value) in self.events.iter_mut().zip(values.iter_mut()) {
            let Some(gap) = Self::guard(opts, e.kind) else {
                continue;
            };
            if e.floor == 0.0 {
                continue;
            }
            let raw = *value + e.floor;
            if raw > gap {
                e.floor = 0.0;
                *value = raw;
            }
        }
    }
}

/// Number of equal sub-intervals of an integrator step at whose ends every event function (and the contact
/// audit's pulling force) is evaluated on the dense output: events are resolved to a quarter of a step,
/// however long the steps of a high-order integrator are.
pub const EVENT_SAMPLES: usize = 4;

/// Number of points per integrator step (besides its start) at which the dense output is checked for tips
/// below the ground: the event search's points, whose states the audit reuses (up to an event, the part of
/// the step before it is sampled the same way).
pub const PENETRATION_SAMPLES: usize = EVENT_SAMPLES;

impl ContactAudit {
    fn see_force(&mut self, pull: f64) {
        self.pull_force = self.pull_force.max(pull);
    }

    /// Deepest tip below the ground at `y`, over every leg (Legs 1 and 2 at their lengths, the others at `L0`),
    /// and the farthest Leg 1 or 2 is past its stopper.
    fn see_tips(&mut self, model: &Model, y: &WalkVector) {
        let (q, _) = unpack(y);
        self.penetration = self.penetration.max(-model.lowest_tip_height(&q));
        let l0 = model.params().stopper_length;
        self.stopper_overrun = self.stopper_overrun.max(q[L1].max(q[L2]) - l0);
    }

    /// Tips below the ground on the dense output of `step` up to `until` (not only at its ends).
    fn see_dense(&mut self, model: &Model, step: &DenseStep<NY>, until: f64) {
        let t0 = step.t0();
        for i in 1..=PENETRATION_SAMPLES {
            let t = t0 + (until - t0) * i as f64 / PENETRATION_SAMPLES as f64;
            self.see_tips(model, &step.eval(t));
        }
    }
}

/// Bookkeeping of the step in progress.
#[derive(Debug, Default, Clone, Copy)]
struct StepTally {
    dls_duration: f64,
    rear_contact_duration: f64,
    audit: ContactAudit,
    scuffing: bool,
    bounce: bool,
    impact_loss: f64,
    stopper_loss: f64,
    events: usize,
}

/// Walks the wheel from touchdown to touchdown.
#[derive(Debug, Clone)]
pub struct Walker<'m> {
    model: &'m Model,
    opts: SolverOptions,
    /// At the section: just before the touchdown impact, after re-indexing.
    state: WalkState,
    steps_done: usize,
    /// Why the next step cannot start (the re-indexing at the last touchdown failed).
    blocked: Option<WalkError>,
}

impl<'m> Walker<'m> {
    /// Start at a Poincare-section state (MODEL.md section 6), at time 0 and position 0.
    pub fn new(
        model: &'m Model,
        opts: &SolverOptions,
        section: &SectionState,
    ) -> Result<Walker<'m>, WalkError> {
        section.validate(model)?;
        let (q, qd) = section.to_coords(model);
        let state = WalkState {
            time: 0.0,
            q,
            qd,
            active: ActiveSet {
                contact1: false,
                contact2: true,
                lock1: true,
                lock2: model.params().rigid_legs,
                ..Default::default()
            },
            x_origin: 0.0,
            leg1: 0,
        };
        Ok(Walker {
            model,
            opts: opts.clone(),
            state,
            steps_done: 0,
            blocked: None,
        })
    }

    /// The current state (at the section).
    pub fn state(&self) -> &WalkState {
        &self.state
    }

    /// The section coordinates `(L2, thetadot, L2dot)` at the current touchdown, without the check of
    /// [`Walker::section`]: what a return map or an orbit diagram records. Where the stance tip slides they do
    /// not hold the whole state, so they must not be used to start a walk there.
    pub fn touchdown_coordinates(&self) -> SectionState {
        SectionState::from_coords(&self.state.q, &self.state.qd)
    }

    /// The current Poincare-section state, or why the walk cannot continue, or why the wheel is not on the
    /// section ([`WalkError::OffSection`]: Leg 2's tip, which the section assumes at rest, slides).
    pub fn section(&self) -> Result<SectionState, WalkError> {
        if let Some(e) = &self.blocked {
            return Err(e.clone());
        }
        let (q, qd) = (&self.state.q, &self.state.qd);
        let speed = self.model.tip(q, qd, Leg::Two.index()).velocity(qd).norm();
        if speed > SECTION_TIP_SPEED_TOL {
            return Err(WalkError::OffSection {
                time: self.state.time,
                speed,
            });
        }
        Ok(self.touchdown_coordinates())
    }

    fn tolerances(&self) -> Tolerances {
        Tolerances {
            rtol: self.opts.rtol,
            atol: self.opts.atol,
            h_max: self.opts.max_step,
            ..Tolerances::default()
        }
    }

    /// Advance from this touchdown to the next one: the impact procedure, then the continuous phases and their
    /// events. Returns the step's report; the walker is then at the next section. Samples go to `trajectory`.
    pub fn step(
        &mut self,
        mut trajectory: Option<&mut Trajectory>,
    ) -> Result<StepReport, WalkError> {
        if let Some(e) = &self.blocked {
            return Err(e.clone());
        }
        let model = self.model;
        let opts = self.opts.clone();
        let start = self.state.clone();
        let t_start = start.time;

        let e_start = model.energy(&start.q, &start.qd);
        let td = touchdown_impact(model, &start.q, &start.qd, start.active)
            .map_err(WalkError::contact_at(t_start, Phase::SingleSupport))?;
        let mut tally = StepTally {
            impact_loss: td.loss,
            bounce: td.branch == Branch::Bounce,
            ..StepTally::default()
        };
        tally.audit.pull_impulse = td.pull_impulse;
        let mut present = start.active;
        present.set_contact(Leg::One, true);
        let (forced, candidates) = post_impact_candidates(
            model,
            &start.q,
            &td.qd_plus,
            &td.impulse_set,
            &present,
            &td.preferred,
        );
        let (mut active, _) =
            consistent_active_set(model, &start.q, &td.qd_plus, forced, &candidates)
                .map_err(WalkError::contact_at(t_start, td.preferred.phase()))?
                .ok_or(WalkError::InconsistentContacts {
                    time: t_start,
                    phase: td.preferred.phase(),
                })?;
        tally.scuffing |= active.slide2;

        let mut t = t_start;
        let mut y = pack(&start.q, &td.qd_plus, 0.0);
        if let Some(tr) = trajectory.as_deref_mut() {
            tr.push(model, t, &y, active, &start);
        }
        let t_limit = t_start + opts.max_step_time;
        let mut solver = Integrator::new(
            opts.integrator,
            &PhaseSystem { model, active },
            t,
            y,
            self.tolerances(),
        );
        let mut events = EventSet::new(model, &opts, active, &y);
        let (mut g_prev, pull) = events.values(&y);
        tally.audit.see_force(pull);
        tally.audit.see_tips(model, &y);

        loop {
            let phase = active.phase();
            if t >= t_limit {
                return Err(WalkError::Stalled {
                    time: t,
                    phase,
                    limit: opts.max_step_time,
                });
            }
            let sys = PhaseSystem { model, active };
            let step = solver
                .step(&sys, t_limit)
                .map_err(|source| WalkError::Integration { phase, source })?;
            // Events are looked for on EVENT_SAMPLES sub-intervals of the step's dense output, the first one
            // with a crossing first: an event function that dips below its floor and back within a step is
            // still caught if the dip is longer than a sub-interval.
            let mut hit: Option<(f64, usize)> = None;
            let (mut t_a, mut pull_next) = (step.t0(), 0.0);
            let mut g_next = Vec::new();
            // The states at the sample points, for the penetration audit when no event cuts the step short.
            let mut sampled = [WalkVector::zeros(); EVENT_SAMPLES];
            for (i, y_b) in (1..=EVENT_SAMPLES).zip(sampled.iter_mut()) {
                let t_b = if i == EVENT_SAMPLES {
                    step.t1()
                } else {
                    step.t0() + (step.t1() - step.t0()) * i as f64 / EVENT_SAMPLES as f64
                };
                *y_b = step.eval(t_b);
                (g_next, pull_next) = events.values(y_b);
                for k in 0..g_next.len() {
                    if g_prev[k] > 0.0 && g_next[k] <= 0.0 {
                        let tk = locate_root(
                            &step,
                            |_, y| events.value(k, y),
                            t_a,
                            g_prev[k],
                            t_b,
                            g_next[k],
                            opts.event_time_tol,
                        );
                        if hit.is_none_or(|(t_hit, _)| tk < t_hit) {
                            hit = Some((tk, k));
                        }
                    }
                }
                if hit.is_some() {
                    break;
                }
                if i < EVENT_SAMPLES {
                    tally.audit.see_force(pull_next);
                    g_prev = std::mem::take(&mut g_next);
                }
                t_a = t_b;
            }
            let t_end = hit.map_or(step.t1(), |(t_hit, _)| t_hit);
            if active.double_support() {
                tally.dls_duration += t_end - step.t0();
            }
            if active.contact2 {
                tally.rear_contact_duration += t_end - step.t0();
            }
            match hit {
                // The same points see_dense would take (t0 + (t1 - t0) i / PENETRATION_SAMPLES), evaluated once.
                None => sampled.iter().for_each(|y| tally.audit.see_tips(model, y)),
                Some(_) => tally.audit.see_dense(model, &step, t_end),
            }
            if let Some(tr) = trajectory.as_deref_mut() {
                tr.record(model, &step, t_end, active, &start);
            }
            let Some((t_hit, k)) = hit else {
                tally.audit.see_force(pull_next);
                events.arm(&mut g_next);
                g_prev = g_next;
                t = step.t1();
                continue;
            };

            // An event at t_hit.
            t = t_hit;
            y = step.eval(t_hit);
            let (q, qd) = unpack(&y);
            tally.audit.see_force(events.values(&y).1);
            let kind = events.events[k].kind;
            match kind {
                EventKind::Touchdown => {
                    let report = self.finish_step(&start, &td, tally, e_start, t, &y, active);
                    return Ok(report);
                }
                EventKind::Fall => {
                    return Err(WalkError::Fell {
                        time: t,
                        phase,
                        hub_height: model.hub_height(&q),
                    })
                }
                EventKind::RollBack => return Err(WalkError::RolledBack { time: t, phase }),
                EventKind::LiftOff(leg) => {
                    active = self.release_contact(t, &q, &qd, active, leg)?;
                    tally.bounce |= leg == Leg::One && !active.contact(Leg::One);
                    tally.scuffing |= active.slide2;
                }
                EventKind::Unlock(leg) => active.set_lock(leg, false),
                EventKind::Landing(leg) | EventKind::StopperHit(leg) => {
                    let unit = match kind {
                        EventKind::Landing(_) => Unit::Contact(leg),
                        _ => Unit::Stopper(leg),
                    };
                    let phase = active.phase();
                    let closed = close_unit(model, &q, &qd, active, unit)
                        .map_err(WalkError::contact_at(t, phase))?
                        .ok_or(WalkError::InconsistentContacts { time: t, phase })?;
                    tally.audit.pull_impulse = tally.audit.pull_impulse.max(closed.pull_impulse);
                    match unit {
                        Unit::Contact(_) => tally.impact_loss += closed.loss,
                        Unit::Stopper(_) => tally.stopper_loss += closed.loss,
                    }
                    tally.scuffing |= (leg == Leg::Two && matches!(unit, Unit::Contact(_)))
                        || closed.active.slide2;
                    active = closed.active;
                    y = pack(&q, &closed.qd_plus, y[2 * NQ]);
                }
            }
            tally.events += 1;
            if tally.events > opts.max_events_per_step {
                return Err(WalkError::Chatter {
                    time: t,
                    phase: active.phase(),
                    events: tally.events,
                });
            }
            let sys = PhaseSystem { model, active };
            solver.restart(&sys, t, y);
            events = EventSet::new(model, &opts, active, &y);
            let pull;
            (g_prev, pull) = events.values(&y);
            tally.audit.see_force(pull);
            if let Some(tr) = trajectory.as_deref_mut() {
                tr.push(model, t, &y, active, &start);
            }
        }
    }

    /// A contact's normal force reached zero: the active set of the motion that follows, preferring the tip to
    /// leave the ground (it slides instead if leaving would drive it into the ground, see
    /// [`crate::params::ContactInconsistency`]).
    fn release_contact(
        &self,
        time: f64,
        q: &Coords,
        qd: &Coords,
        active: ActiveSet,
        leaving: Leg,
    ) -> Result<ActiveSet, WalkError> {
        let model = self.model;
        let phase = active.phase();
        let forced = bilateral_stoppers(model);
        let mut candidates = Vec::new();
        for leg in Leg::BOTH {
            if active.contact(leg) {
                candidates.push(if leg == leaving {
                    Candidate::releasing(leg)
                } else {
                    Candidate::keep(Unit::Contact(leg), &active)
                });
            }
            if active.lock(leg) && !forced.lock(leg) {
                candidates.push(Candidate::keep(Unit::Stopper(leg), &active));
            }
        }
        let (new_active, _) = consistent_active_set(model, q, qd, forced, &candidates)
            .map_err(WalkError::contact_at(time, phase))?
            .ok_or(WalkError::InconsistentContacts { time, phase })?;
        Ok(new_active)
    }

    /// Close the step at the touchdown event `(t, y)`: the report, then re-indexing for the next step.
    #[allow(clippy::too_many_arguments)]
    fn finish_step(
        &mut self,
        start: &WalkState,
        td: &impact::TouchdownImpact,
        tally: StepTally,
        e_start: f64,
        t: f64,
        y: &WalkVector,
        active: ActiveSet,
    ) -> StepReport {
        let model = self.model;
        let (q, qd) = unpack(y);
        let e_end = model.energy(&q, &qd);
        let damper = y[2 * NQ];
        let loss = e_start - e_end;
        let touching = touchdown_leg(model, &q);
        let front = model.tip(&q, &qd, touching);
        let step_length = front.position.x - start.q[X];
        let period = t - start.time;
        self.steps_done += 1;
        let report = StepReport {
            step: self.steps_done,
            time: start.time,
            section: SectionState::from_coords(&start.q, &start.qd),
            theta: start.q[THETA],
            indicators: td.indicators,
            branch: td.branch,
            dls_duration: tally.dls_duration,
            rear_contact_duration: tally.rear_contact_duration,
            period,
            step_length,
            speed: step_length / period,
            scuffing: tally.scuffing,
            bounce: tally.bounce,
            events: tally.events,
            energy: EnergyAudit {
                start: e_start,
                end: e_end,
                loss,
                damper,
                impact: tally.impact_loss,
                stopper: tally.stopper_loss,
                residual: loss - (damper + tally.impact_loss + tally.stopper_loss),
            },
            contact: tally.audit,
        };
        match reindex(model, t, &q, &qd, active, touching) {
            Ok((q_new, qd_new, before)) => {
                self.state = WalkState {
                    time: t,
                    q: q_new,
                    qd: qd_new,
                    active: before,
                    x_origin: start.x_origin + front.position.x,
                    leg1: (start.leg1 + touching) % model.legs(),
                };
            }
            Err(e) => self.blocked = Some(e),
        }
        report
    }
}

/// Re-indexing at touchdown (paper Sec. 2.2, MODEL.md section 5): the touching leg `touching` (the front leg
/// `j = -1` in a walk, see [`touchdown_leg`]) becomes Leg 1, the leg behind it becomes Leg 2, and the legs that
/// leave `q` (the old Leg 2; after a long flight also the old Leg 1) must be locked at `L0` and in the air. The
/// origin moves to the new tip. Returns `(q_dagger, q'_dagger, active set before impact)`.
fn reindex(
    model: &Model,
    time: f64,
    q: &Coords,
    qd: &Coords,
    active: ActiveSet,
    touching: usize,
) -> Result<(Coords, Coords, ActiveSet), WalkError> {
    // The touching leg is `shift` legs ahead of Leg 1; with `shift > 1` the new Leg 2 is a locked leg.
    let shift = model.legs() - touching;
    let leaving: &[Leg] = if shift == 1 { &[Leg::Two] } else { &Leg::BOTH };
    for &leg in leaving {
        if active.contact(leg) {
            return Err(WalkError::RearLegInContact { time });
        }
        if !active.lock(leg) {
            let i = leg.length_coordinate();
            return Err(WalkError::RearLegNotLocked {
                time,
                length: q[i],
                rate: qd[i],
            });
        }
    }
    let front = model.tip(q, qd, touching);
    let v = front.velocity(qd);
    let l0 = model.params().stopper_length;
    let (l2, l2_dot) = if shift == 1 {
        (q[L1], qd[L1])
    } else {
        (l0, 0.0)
    };
    let theta = if shift == 1 {
        q[THETA] - model.alpha()
    } else {
        // psi of the touching leg, in [-pi, pi].
        let psi = q[THETA] + touching as f64 * model.alpha();
        psi - std::f64::consts::TAU * (psi / std::f64::consts::TAU).round()
    };
    let q_new = Coords::new(0.0, front.position.y, theta, l0, l2);
    let qd_new = Coords::new(v.x, v.y, qd[THETA], 0.0, l2_dot);
    let before = ActiveSet {
        contact1: false,
        contact2: shift == 1 && active.contact1,
        lock1: true,
        lock2: shift > 1 || active.lock1,
        ..Default::default()
    };
    Ok((q_new, qd_new, before))
}

/// The result of [`simulate`]: every completed step, and how the run ended.
#[derive(Debug, Clone)]
pub struct WalkRun {
    /// Reports of the completed steps.
    pub steps: Vec<StepReport>,
    /// `None` if all requested steps were walked, else why the walk stopped.
    pub failure: Option<WalkError>,
    /// Time reached \[s\]: the last touchdown, or the time of the failure if the walk stopped.
    pub time: f64,
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
}

/// Walk up to `steps` steps from `initial`, handing each step's report to `on_step` as soon as the step is
/// done and keeping none, so memory does not grow with the number of steps. The trajectory, if any, is
/// flushed after every step.
///
/// The walk stops early when a step fails (the failure and its time are in the [`WalkEnd`]), when `on_step`
/// returns an error (returned as is), when the trajectory's sink fails (find its error with
/// [`Trajectory::take_error`]), or when `interrupt` is set; the flag is checked before every step, so an
/// interrupted walk ends at a touchdown with every completed step reported.
pub fn simulate_streaming<E: From<WalkError>>(
    model: &Model,
    opts: &SolverOptions,
    initial: &SectionState,
    steps: usize,
    mut trajectory: Option<&mut Trajectory>,
    interrupt: Option<&std::sync::atomic::AtomicBool>,
    mut on_step: impl FnMut(&StepReport) -> Result<(), E>,
) -> Result<WalkEnd, E> {
    let mut walker = Walker::new(model, opts, initial)?;
    let mut end = WalkEnd {
        steps: 0,
        failure: None,
        interrupted: false,
        time: walker.state().time,
    };
    while end.steps < steps {
        if interrupt.is_some_and(|flag| flag.load(std::sync::atomic::Ordering::Relaxed)) {
            end.interrupted = true;
            break;
        }
        let result = walker.step(trajectory.as_deref_mut());
        let sink_failed = trajectory.as_deref_mut().is_some_and(|tr| {
            tr.flush();
            tr.error.is_some()
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
            Err(e) => {
                end.time = e.time().unwrap_or(end.time);
                end.failure = Some(e);
                break;
            }
        }
    }
    Ok(end)
}
