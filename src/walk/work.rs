//! Work counts of the walk: how many integrator steps, right-hand-side evaluations, located events and
//! impacts a walk took ([`WorkCounts`]). They say nothing about the physics; they lock the numerics (a change
//! of the integrator, the event search or the impact procedure shows as a change of the counts, see
//! `tests/work_counts.rs`) and give benchmarks a measure of work that does not depend on the machine.
//!
//! Every [`super::Walker`] counts its own work ([`super::Walker::work`]), and [`super::WalkRun`] /
//! [`super::WalkEnd`] report a walk's. The walkers a gait search makes are counted by the step map they
//! belong to (`StepMap::work` in `gait`).

use std::ops::AddAssign;

use serde::Serialize;

use super::events::EventKind;

/// Events of each kind that a walk handled (docs/model.md section 4).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct EventCounts {
    /// Touchdowns of the next leg (each ends a step).
    pub touchdown: usize,
    /// Lift-offs (or starts of sliding) of an active contact.
    pub lift_off: usize,
    /// Stopper unlocks.
    pub unlock: usize,
    /// Landings or rear re-contacts of an airborne tip.
    pub landing: usize,
    /// Stopper hits of a free leg.
    pub stopper_hit: usize,
    /// Falls (the step fails).
    pub fall: usize,
    /// Roll-backs (the step fails).
    pub roll_back: usize,
    /// Compression-stop hits of a free leg (`min_length > 0`).
    #[serde(skip_serializing_if = "is_zero")]
    pub compression_hit: usize,
    /// Compression-stop unlocks (`min_length > 0`).
    #[serde(skip_serializing_if = "is_zero")]
    pub compression_unlock: usize,
    /// Stopper locks of the swinging leg (`rear_exit = "continue"`).
    #[serde(skip_serializing_if = "is_zero")]
    pub swing_lock: usize,
    /// Landings of the swinging leg (the step fails).
    #[serde(skip_serializing_if = "is_zero")]
    pub swing_landing: usize,
    /// Sticking tips starting to slip (Coulomb friction: the force reached the edge of the cone).
    #[serde(skip_serializing_if = "is_zero")]
    pub slip_start: usize,
    /// Slipping tips coming to rest (Coulomb friction: stick, or slip the other way).
    #[serde(skip_serializing_if = "is_zero")]
    pub slip_stop: usize,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

impl EventCounts {
    /// No event.
    pub(crate) const ZERO: EventCounts = EventCounts {
        touchdown: 0,
        lift_off: 0,
        unlock: 0,
        landing: 0,
        stopper_hit: 0,
        fall: 0,
        roll_back: 0,
        compression_hit: 0,
        compression_unlock: 0,
        swing_lock: 0,
        swing_landing: 0,
        slip_start: 0,
        slip_stop: 0,
    };

    /// Count one event of `kind`.
    pub(crate) fn count(&mut self, kind: EventKind) {
        let n = match kind {
            EventKind::Touchdown => &mut self.touchdown,
            EventKind::LiftOff(_) => &mut self.lift_off,
            EventKind::Unlock(_) => &mut self.unlock,
            EventKind::Landing(_) => &mut self.landing,
            EventKind::StopperHit(_) => &mut self.stopper_hit,
            EventKind::Fall => &mut self.fall,
            EventKind::RollBack => &mut self.roll_back,
            EventKind::CompressionHit(_) => &mut self.compression_hit,
            EventKind::CompressionUnlock(_) => &mut self.compression_unlock,
            EventKind::SwingLock => &mut self.swing_lock,
            EventKind::SwingLanding => &mut self.swing_landing,
            EventKind::ConeLimit(_) => &mut self.slip_start,
            EventKind::SlipStop(_) => &mut self.slip_stop,
        };
        *n += 1;
    }
}

impl AddAssign for EventCounts {
    fn add_assign(&mut self, o: EventCounts) {
        self.touchdown += o.touchdown;
        self.lift_off += o.lift_off;
        self.unlock += o.unlock;
        self.landing += o.landing;
        self.stopper_hit += o.stopper_hit;
        self.fall += o.fall;
        self.roll_back += o.roll_back;
        self.compression_hit += o.compression_hit;
        self.compression_unlock += o.compression_unlock;
        self.swing_lock += o.swing_lock;
        self.swing_landing += o.swing_landing;
        self.slip_start += o.slip_start;
        self.slip_stop += o.slip_stop;
    }
}

/// The work of a walk (or of one step): what the integrator and the walker did, failed steps included.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct WorkCounts {
    /// Steps attempted (touchdown to touchdown), failed ones included.
    pub steps: usize,
    /// Accepted integrator steps.
    pub accepted: usize,
    /// Rejected integrator trial steps.
    pub rejected: usize,
    /// Evaluations of the phase's right-hand side by the integrator (each one constrained-dynamics solve),
    /// starting-step estimates included.
    pub rhs_evals: usize,
    /// Crossings of an event function located by root finding on the dense output (the earliest one in an
    /// integrator step is the event; later ones in the same step are located and dropped).
    pub crossings: usize,
    /// Evaluations of an event function during those root searches.
    pub root_evals: usize,
    /// Events handled, by kind.
    pub events: EventCounts,
    /// Impacts solved: touchdowns, rear re-contacts and landings, stopper and compression-stop hits.
    pub impacts: usize,
}

impl WorkCounts {
    /// No work.
    pub(crate) const ZERO: WorkCounts = WorkCounts {
        steps: 0,
        accepted: 0,
        rejected: 0,
        rhs_evals: 0,
        crossings: 0,
        root_evals: 0,
        events: EventCounts::ZERO,
        impacts: 0,
    };

    /// The work done since `earlier`, a reading of the same (growing) counts.
    pub fn since(&self, earlier: &WorkCounts) -> WorkCounts {
        let e = &earlier.events;
        WorkCounts {
            steps: self.steps - earlier.steps,
            accepted: self.accepted - earlier.accepted,
            rejected: self.rejected - earlier.rejected,
            rhs_evals: self.rhs_evals - earlier.rhs_evals,
            crossings: self.crossings - earlier.crossings,
            root_evals: self.root_evals - earlier.root_evals,
            events: EventCounts {
                touchdown: self.events.touchdown - e.touchdown,
                lift_off: self.events.lift_off - e.lift_off,
                unlock: self.events.unlock - e.unlock,
                landing: self.events.landing - e.landing,
                stopper_hit: self.events.stopper_hit - e.stopper_hit,
                fall: self.events.fall - e.fall,
                roll_back: self.events.roll_back - e.roll_back,
                compression_hit: self.events.compression_hit - e.compression_hit,
                compression_unlock: self.events.compression_unlock - e.compression_unlock,
                swing_lock: self.events.swing_lock - e.swing_lock,
                swing_landing: self.events.swing_landing - e.swing_landing,
                slip_start: self.events.slip_start - e.slip_start,
                slip_stop: self.events.slip_stop - e.slip_stop,
            },
            impacts: self.impacts - earlier.impacts,
        }
    }
}

impl AddAssign for WorkCounts {
    fn add_assign(&mut self, o: WorkCounts) {
        self.steps += o.steps;
        self.accepted += o.accepted;
        self.rejected += o.rejected;
        self.rhs_evals += o.rhs_evals;
        self.crossings += o.crossings;
        self.root_evals += o.root_evals;
        self.events += o.events;
        self.impacts += o.impacts;
    }
}
