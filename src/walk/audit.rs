//! The contact audit's per-step checks (docs/model.md section 7): the largest pulling force seen, tips below
//! the ground on the dense output (at the event search's points, [`sample_count`] per integrator step), and
//! legs past their stoppers or compression stops.

use crate::contact::{Role, Stop};
use crate::dynamics::{swinging, Model, L3};
use crate::integrate::DenseStep;
use crate::params::SolverOptions;

use super::events::{sample_count, Forces};
use super::impact::{has_stop, has_stopper, stop_length};
use super::phase::{unpack, WalkVector, NY};
use super::report::ContactAudit;

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
        for leg in Role::BOTH {
            // Rigid legs' bilateral stoppers are audited too (a rigid leg has no compression stop).
            let audited = |stop| match stop {
                Stop::Extension => has_stopper(model, leg),
                Stop::Compression => has_stop(model, leg, stop),
            };
            for stop in Stop::BOTH.into_iter().filter(|&s| audited(s)) {
                let past =
                    stop.sign() * (q[Model::stroke_coordinate(leg)] - stop_length(model, stop));
                self.stopper_overrun = self.stopper_overrun.max(past);
            }
        }
        if swinging(&q) {
            let past = q[L3] - model.params().stopper_length;
            self.stopper_overrun = self.stopper_overrun.max(past);
        }
    }

    /// Tips below the ground on the dense output of `step` up to `until` (not only at its ends), at points
    /// `event_spacing` apart at most ([`sample_count`]: the event search's points, whose states the audit
    /// reuses where no event cuts the step short).
    pub(crate) fn see_dense(
        &mut self,
        model: &Model,
        step: &DenseStep<NY>,
        until: f64,
        opts: &SolverOptions,
    ) {
        let t0 = step.t0();
        let n = sample_count(t0, until, opts.event_spacing);
        for i in 1..=n {
            let t = t0 + (until - t0) * i as f64 / n as f64;
            self.see_tips(model, &step.eval(t));
        }
    }
}
