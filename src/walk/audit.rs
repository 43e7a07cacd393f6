//! The contact audit's per-step checks (docs/model.md section 7): the largest pulling force seen, tips below
//! the ground on the dense output ([`PENETRATION_SAMPLES`] points per integrator step), and legs past their
//! stoppers or compression stops.

use crate::contact::{Leg, Stop};
use crate::dynamics::{swinging, Model, L3};
use crate::integrate::DenseStep;

use super::events::{Forces, EVENT_SAMPLES};
use super::impact::{has_stop, has_stopper, stop_length};
use super::phase::{unpack, WalkVector, NY};
use super::report::ContactAudit;

/// Number of points per integrator step (besides its start) at which the dense output is checked for tips
/// below the ground: the event search's points, whose states the audit reuses (up to an event, the part of
/// the step before it is sampled the same way).
pub(crate) const PENETRATION_SAMPLES: usize = EVENT_SAMPLES;

impl ContactAudit {
    /// The pulling force (or reaction) and the friction cone's excess seen at some instant of the step.
    pub(crate) fn see_force(&mut self, forces: Forces) {
        self.pull_force = self.pull_force.max(forces.pull);
        if let Some(friction) = &mut self.friction {
            friction.cone_violation = friction.cone_violation.max(forces.cone);
        }
    }

    /// Deepest tip below the ground at `y`, over every leg (Legs 1 and 2 at their lengths, the others at `L0`),
    /// and the farthest Leg 1 or 2 is past its stopper (Leg 1 alone when Leg 2 has none, `rear_stopper`) or
    /// below its compression stop (`min_length > 0`), or a swinging leg past its stopper.
    pub(crate) fn see_tips(&mut self, model: &Model, y: &WalkVector) {
        let (q, _) = unpack(y);
        self.penetration = self.penetration.max(-model.lowest_tip_height(&q));
        for leg in Leg::BOTH {
            // Rigid legs' bilateral stoppers are audited too (a rigid leg has no compression stop).
            let audited = |stop| match stop {
                Stop::Extension => has_stopper(model, leg),
                Stop::Compression => has_stop(model, leg, stop),
            };
            for stop in Stop::BOTH.into_iter().filter(|&s| audited(s)) {
                let past = stop.sign() * (q[leg.length_coordinate()] - stop_length(model, stop));
                self.stopper_overrun = self.stopper_overrun.max(past);
            }
        }
        if swinging(&q) {
            let past = q[L3] - model.params().stopper_length;
            self.stopper_overrun = self.stopper_overrun.max(past);
        }
    }

    /// Tips below the ground on the dense output of `step` up to `until` (not only at its ends).
    pub(crate) fn see_dense(&mut self, model: &Model, step: &DenseStep<NY>, until: f64) {
        let t0 = step.t0();
        for i in 1..=PENETRATION_SAMPLES {
            let t = t0 + (until - t0) * i as f64 / PENETRATION_SAMPLES as f64;
            self.see_tips(model, &step.eval(t));
        }
    }
}
