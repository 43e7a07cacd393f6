//! The events of a phase (docs/model.md section 4): their kinds, the event functions, the grazing guards that
//! arm them, and the constants of the event search ([`EVENT_SAMPLES`], [`FORCE_EVENT_MARGIN`],
//! [`APPROACH_GAP`]), and what the search over one integrator step finds ([`StepSearch`], [`Hit`]). The table of
//! event functions is in the [module documentation](super).

use crate::contact::{
    cone_distance, cone_excess, constrained_dynamics, largest_pull, ActiveSet, ConstrainedDynamics,
    Role, Stop,
};
use crate::dynamics::{swinging, Coords, Model, L3, THETA};
use crate::params::SolverOptions;

use super::impact::{has_stop, stop_length, touchdown_leg, COMPLEMENTARITY_TOL};
use super::phase::{unpack, WalkVector};
use super::reindex::SWING_LEG;

/// A lift-off or stopper-unlock event fires when the force falls this far below zero \[N\] (or below its
/// value at the start of the phase, if the force-level problem accepted a slightly negative one within
/// [`super::impact::COMPLEMENTARITY_TOL`]): small enough that the contact audit sees no pull above 1e-9 N, large
/// enough that rounding of forces of ~100 N (~1e-12 N) cannot fire it.
pub(crate) const FORCE_EVENT_MARGIN: f64 = 1e-10;

/// The grazing guard of a landing or stopper event whose tip (leg) starts at the ground (stopper) already moving
/// into it \[m\]: such a contact is not grazing, so its event fires as soon as it moves this far (instead of
/// `recontact_gap` / `stopper_gap`). It happens after the `traditional` exchange drives the rear tip into the
/// ground, or when an impact's complementarity problem had no consistent solution. A leg that starts at its
/// stopper moving *away* from it (inward) is not grazing either (docs/model.md section 4): its stopper event
/// fires this far past where it started, so a leg that comes back within one integrator step locks at `L0`
/// instead of `stopper_gap` past it, and the overrun does not grow from lock to lock.
pub(crate) const APPROACH_GAP: f64 = 1e-12;

/// A slip-stop event of a slip that starts at rest fires when its slip speed falls this far below its value at
/// the start \[m/s\] (one that starts moving fires at 0): small enough that the friction force does no
/// measurable work on a tip creeping the other way, large enough that rounding (~1e-16 m/s) cannot fire it.
pub(crate) const SLIP_STOP_MARGIN: f64 = 1e-12;

/// Fewest equal sub-intervals of an integrator step at whose ends every event function (and the contact
/// audit's pulling force) is evaluated on the dense output: events are resolved to a quarter of a step at
/// least, and to `event_spacing` ([`sample_count`]).
pub(crate) const EVENT_SAMPLES: usize = 4;

/// The number of equal sub-intervals of `[t0, t1]` at whose ends the event functions and the contact audit are
/// evaluated: [`EVENT_SAMPLES`], or more where they would be longer than `spacing`.
pub(crate) fn sample_count(t0: f64, t1: f64, spacing: f64) -> usize {
    // A step of exactly `EVENT_SAMPLES` spacings (the default `max_step`'s of earlier versions, 0.04 s) keeps its
    // four points whatever the rounding of the quotient.
    let needed = ((t1 - t0) / spacing * (1.0 - 1e-12)).ceil();
    // `t1 - t0 <= max_step <= 1` and `spacing >= 1e-6` (their validated ranges): at most 1e6 points.
    if needed > EVENT_SAMPLES as f64 {
        needed as usize
    } else {
        EVENT_SAMPLES
    }
}

/// Kinds of events (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum EventKind {
    Touchdown,
    Fall,
    RollBack,
    LiftOff(Role),
    Unlock(Role),
    Landing(Role),
    StopperHit(Role),
    /// A free leg reaches its compression stop (`L = min_length`).
    CompressionHit(Role),
    /// The compression stop's reaction on a held leg falls to zero.
    CompressionUnlock(Role),
    /// The swinging leg (`L3`, `rear_exit = "continue"`) reaches its stopper (`L3 = L0`).
    SwingLock,
    /// The tip of the swinging leg reaches the ground (the walk stops; with three legs it is the next leg to
    /// touch down, and that is a touchdown).
    SwingLanding,
    /// With Coulomb friction, a sticking tip's tangential force reaches the edge of the cone:
    /// `mu lambda_n - |lambda_t| = 0`.
    ConeLimit(Role),
    /// With Coulomb friction, a slipping tip comes to rest: its slip velocity reaches 0.
    SlipStop(Role),
}

impl EventKind {
    /// The event at which a free leg reaches `stop`.
    pub(crate) fn hit(leg: Role, stop: Stop) -> EventKind {
        match stop {
            Stop::Extension => EventKind::StopperHit(leg),
            Stop::Compression => EventKind::CompressionHit(leg),
        }
    }

    /// The event at which `stop`'s reaction on a held leg falls to zero.
    pub(crate) fn unlock(leg: Role, stop: Stop) -> EventKind {
        match stop {
            Stop::Extension => EventKind::Unlock(leg),
            Stop::Compression => EventKind::CompressionUnlock(leg),
        }
    }

    /// The leg and stop of a stop hit, if this is one.
    pub(crate) fn stop_hit(self) -> Option<(Role, Stop)> {
        match self {
            EventKind::StopperHit(leg) => Some((leg, Stop::Extension)),
            EventKind::CompressionHit(leg) => Some((leg, Stop::Compression)),
            _ => None,
        }
    }

    /// The leg and stop of an unlock, if this is one.
    pub(crate) fn stop_unlock(self) -> Option<(Role, Stop)> {
        match self {
            EventKind::Unlock(leg) => Some((leg, Stop::Extension)),
            EventKind::CompressionUnlock(leg) => Some((leg, Stop::Compression)),
            _ => None,
        }
    }
}

/// One event of a phase: its kind and the level at which its function fires.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Event {
    /// What happens when it fires.
    pub(crate) kind: EventKind,
    /// The event fires when its unshifted function falls to this level: 0 once armed, and
    /// `min(h0, 0) - gap` while a guarded event is disarmed (see the module documentation).
    pub(crate) floor: f64,
}

/// What the contact audit checks at an instant: the largest pulling force (see [`largest_pull`]) and the largest
/// excess of a sticking contact's force over the friction cone (see [`cone_excess`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Forces {
    pub(crate) pull: f64,
    pub(crate) cone: f64,
}

impl Forces {
    /// Nothing pulls, nothing leaves the cone.
    pub(crate) const NONE: Forces = Forces {
        pull: 0.0,
        cone: 0.0,
    };
}

/// An event located in an integrator step.
pub(super) struct Hit {
    /// When \[s\].
    pub(super) time: f64,
    /// Which event of the phase's [`EventSet`].
    pub(super) index: usize,
    /// The state then, on the step's dense output.
    pub(super) y: WalkVector,
}

/// The event search over one integrator step (`Phases::search_step` in `walker.rs`).
pub(super) struct StepSearch {
    /// The earliest crossing `(time, event index)`, if any.
    pub(super) hit: Option<(f64, usize)>,
    /// Event values at the last sample point evaluated.
    pub(super) g_next: Vec<f64>,
    /// The largest pulling force at that point.
    pub(super) pull_next: Forces,
}

/// Event functions of one phase.
pub(crate) struct EventSet<'a> {
    model: &'a Model,
    opts: &'a SolverOptions,
    active: ActiveSet,
    pub(crate) events: Vec<Event>,
}

impl<'a> EventSet<'a> {
    pub(crate) fn new(
        model: &'a Model,
        opts: &'a SolverOptions,
        active: ActiveSet,
        y: &WalkVector,
    ) -> EventSet<'a> {
        let (q, qd) = unpack(y);
        let mut kinds = vec![EventKind::Touchdown, EventKind::Fall, EventKind::RollBack];
        for leg in Role::BOTH {
            kinds.push(if active.contact(leg) {
                EventKind::LiftOff(leg)
            } else {
                EventKind::Landing(leg)
            });
            if active.contact(leg) && model.params().has_friction() {
                kinds.push(if active.slip(leg) != 0 {
                    EventKind::SlipStop(leg)
                } else {
                    EventKind::ConeLimit(leg)
                });
            }
            for stop in Stop::BOTH.into_iter().filter(|&s| has_stop(model, leg, s)) {
                kinds.push(if active.held(leg, stop) {
                    EventKind::unlock(leg, stop)
                } else {
                    EventKind::hit(leg, stop)
                });
            }
        }
        if swinging(&q) {
            kinds.push(EventKind::SwingLock);
            if touchdown_leg(model, &q) != SWING_LEG {
                kinds.push(EventKind::SwingLanding);
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
            let floor = if let Some(margin) = Self::start_margin(kind) {
                // A force event fires once the force falls FORCE_EVENT_MARGIN below zero, or below its value at
                // the phase start if that is already (within the complementarity tolerance) negative. A slip
                // that starts at rest (or with its speed rounded a hair the other way) stops when it falls
                // SLIP_STOP_MARGIN below where it started, so that a slip that reverses at once is an event too,
                // not friction pushing the tip along.
                f0().min(0.0) - margin
            } else if let Some(gap) = Self::guard(opts, kind) {
                // Guarded events start disarmed unless their function already clears the gap. A tip (leg) that
                // starts at the ground (stopper) already moving into it is not grazing: it fires at once. Nor is
                // a leg that leaves its stopper at a definite speed: the Zeno rule locked it if that speed could
                // not take it `stopper_gap` away, so its stopper event fires at `L0`, not `stopper_gap` past it.
                let gap = if set.approaching(kind, &q, &qd) || set.separating(kind, &qd) {
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

    /// The margin below zero, or below its value at the phase start if that is negative, at which an event that
    /// starts at its zero fires: a force event's [`FORCE_EVENT_MARGIN`], a slip stop's [`SLIP_STOP_MARGIN`].
    fn start_margin(kind: EventKind) -> Option<f64> {
        if Self::needs_forces(kind) {
            Some(FORCE_EVENT_MARGIN)
        } else if matches!(kind, EventKind::SlipStop(_)) {
            Some(SLIP_STOP_MARGIN)
        } else {
            None
        }
    }

    /// The grazing guard of an event kind, if it has one.
    fn guard(opts: &SolverOptions, kind: EventKind) -> Option<f64> {
        match kind {
            EventKind::Landing(_) => Some(opts.recontact_gap),
            EventKind::StopperHit(_) | EventKind::CompressionHit(_) | EventKind::SwingLock => {
                Some(opts.stopper_gap)
            }
            _ => None,
        }
    }

    /// Is the unit of a guarded event moving into the ground (past its stopper) at `(q, q')`?
    fn approaching(&self, kind: EventKind, q: &Coords, qd: &Coords) -> bool {
        match kind {
            EventKind::SwingLock => qd[L3] > COMPLEMENTARITY_TOL,
            EventKind::Landing(leg) => {
                self.model.tip(q, qd, leg.index()).velocity(qd).y < -COMPLEMENTARITY_TOL
            }
            _ => kind.stop_hit().is_some_and(|(leg, stop)| {
                stop.sign() * qd[Model::stroke_coordinate(leg)] > COMPLEMENTARITY_TOL
            }),
        }
    }

    /// Does a free leg leave its stop (move inward from the stopper, outward from the compression stop) faster
    /// than [`COMPLEMENTARITY_TOL`] at `q'`?
    fn separating(&self, kind: EventKind, qd: &Coords) -> bool {
        if kind == EventKind::SwingLock {
            return qd[L3] < -COMPLEMENTARITY_TOL;
        }
        kind.stop_hit().is_some_and(|(leg, stop)| {
            stop.sign() * qd[Model::stroke_coordinate(leg)] < -COMPLEMENTARITY_TOL
        })
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
            EventKind::Unlock(leg) => force(&|d| d.stop_reaction(leg, Stop::Extension)),
            EventKind::CompressionUnlock(leg) => {
                force(&|d| d.stop_reaction(leg, Stop::Compression))
            }
            EventKind::Landing(leg) => self.model.tip_height(q, leg.index()),
            EventKind::StopperHit(leg) => self.room(leg, Stop::Extension, q),
            EventKind::CompressionHit(leg) => self.room(leg, Stop::Compression, q),
            EventKind::SwingLock => self.model.params().stopper_length - q[L3],
            EventKind::SwingLanding => self.model.tip_height(q, SWING_LEG),
            EventKind::ConeLimit(leg) => force(&|d| {
                let (t, n) = (d.multipliers[leg.tangential_row()], d.normal_force(leg));
                -cone_distance(self.model.params().friction, t, n)
            }),
            EventKind::SlipStop(leg) => {
                let v = self.model.tip(q, qd, leg.index()).velocity(qd).x;
                f64::from(self.active.slip(leg)) * v
            }
        }
    }

    /// How far a free leg is from `stop` (positive on the allowed side): `L0 - L` or `L - min_length`.
    fn room(&self, leg: Role, stop: Stop, q: &Coords) -> f64 {
        stop.sign() * (stop_length(self.model, stop) - q[Model::stroke_coordinate(leg)])
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
        matches!(
            kind,
            EventKind::LiftOff(_)
                | EventKind::Unlock(_)
                | EventKind::CompressionUnlock(_)
                | EventKind::ConeLimit(_)
        )
    }

    fn dynamics_if(&self, needed: bool, q: &Coords, qd: &Coords) -> Option<ConstrainedDynamics> {
        needed
            .then(|| constrained_dynamics(self.model, q, qd, &self.active).ok())
            .flatten()
    }

    /// Values of all event functions at `y`, and the forces the contact audit checks there (0 when no unilateral
    /// unit is active).
    pub(crate) fn values(&self, y: &WalkVector) -> (Vec<f64>, Forces) {
        let (q, qd) = unpack(y);
        let needed = self.events.iter().any(|e| Self::needs_forces(e.kind));
        let dynamics = self.dynamics_if(needed, &q, &qd);
        let values = self
            .events
            .iter()
            .map(|e| self.shifted(e, &q, &qd, &dynamics))
            .collect();
        let params = self.model.params();
        let forces = dynamics.map_or(Forces::NONE, |d| Forces {
            pull: largest_pull(&d.multipliers, &self.active, params.rigid_legs),
            cone: cone_excess(&d.multipliers, &self.active, params.friction),
        });
        (values, forces)
    }

    /// Value of event `k` at `y`.
    pub(crate) fn value(&self, k: usize, y: &WalkVector) -> f64 {
        let (q, qd) = unpack(y);
        let e = &self.events[k];
        let dynamics = self.dynamics_if(Self::needs_forces(e.kind), &q, &qd);
        self.shifted(e, &q, &qd, &dynamics)
    }

    /// Arm guarded events whose function has cleared its gap; `values` are updated to the new definitions.
    pub(crate) fn arm(&mut self, values: &mut [f64]) {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Four points per step at least, and none farther apart than the spacing: a step of exactly four spacings
    /// (the default 0.04 s step at 0.01 s) keeps its four points whatever the rounding of the quotient.
    #[test]
    fn samples_are_at_most_a_spacing_apart() {
        assert_eq!(sample_count(0.0, 0.04, 0.01), 4);
        assert_eq!(sample_count(1.37, 1.37 + 0.04, 0.01), 4);
        assert_eq!(sample_count(0.0, 0.001, 0.01), 4);
        assert_eq!(sample_count(0.0, 0.16, 0.01), 16);
        assert_eq!(sample_count(0.0, 0.161, 0.01), 17);
        assert_eq!(sample_count(0.0, 1.0, 1e-6), 1_000_000);
        for &(t0, t1, spacing) in &[(0.0, 0.3, 0.007), (2.5, 2.63, 0.01), (0.0, 1.0, 0.3)] {
            let n = sample_count(t0, t1, spacing);
            assert!(n >= EVENT_SAMPLES && (t1 - t0) / n as f64 <= spacing * (1.0 + 1e-12));
        }
    }
}
