//! The bookkeeping of a step in progress ([`StepTally`]): durations, the contact audit, flags and the energy
//! lost in impacts, which the step's report is made of.

use crate::contact::{constrained_dynamics, ActiveSet, Leg};
use crate::dynamics::Model;
use crate::integrate::DenseStep;

use super::impact::SwingLock;
use super::impact::{Branch, TouchdownImpact};
use super::phase::{unpack, NY};
use super::report::{ContactAudit, FrictionAudit};
use super::zeno::ZenoLock;

/// Bookkeeping of the step in progress.
#[derive(Debug, Default, Clone, Copy)]
pub(super) struct StepTally {
    /// Time in double-limb support so far \[s\].
    pub(super) dls_duration: f64,
    /// Time Leg 2's tip touched the ground so far \[s\].
    pub(super) rear_contact_duration: f64,
    /// The contact audit so far.
    pub(super) audit: ContactAudit,
    /// Leg 2 scuffed (re-contact or slide).
    pub(super) scuffing: bool,
    /// Leg 1 bounced.
    pub(super) bounce: bool,
    /// Kinetic energy lost in ground impacts \[J\].
    pub(super) impact_loss: f64,
    /// Kinetic energy lost in stopper impacts \[J\].
    pub(super) stopper_loss: f64,
    /// Energy dissipated by Coulomb friction on slipping tips between impacts \[J\].
    pub(super) friction_loss: f64,
    /// Events handled so far.
    pub(super) events: usize,
}

impl StepTally {
    /// The tally of a step right after its touchdown impact `td`: its loss, a bounce, its pulling impulse and,
    /// with Coulomb friction, its impulse's excess over the cone.
    pub(super) fn after_touchdown(model: &Model, td: &TouchdownImpact) -> StepTally {
        let mut tally = StepTally {
            impact_loss: td.loss,
            bounce: td.branch == Branch::Bounce,
            ..StepTally::default()
        };
        tally.audit.pull_impulse = td.pull_impulse;
        if model.params().has_friction() {
            tally.audit.friction = Some(FrictionAudit {
                cone_violation_impulse: td.cone_impulse,
                ..FrictionAudit::default()
            });
        }
        tally
    }

    /// Account for the slip of some tips over the dense output of `step` up to `until`: the friction work, by
    /// Gauss-Legendre quadrature ([`slip_work`]), to the energy audit, and the largest friction power to the
    /// friction audit.
    pub(super) fn see_slip(
        &mut self,
        model: &Model,
        active: ActiveSet,
        step: &DenseStep<NY>,
        until: f64,
    ) {
        let (dissipated, power) = slip_work(model, active, step, until);
        self.friction_loss += dissipated;
        if let Some(friction) = &mut self.audit.friction {
            friction.slip_power = friction.slip_power.max(power);
        }
    }

    /// A contact that stuck through an impact took an impulse `excess` outside the friction cone \[N s\].
    pub(super) fn see_cone_impulse(&mut self, excess: f64) {
        if let Some(friction) = &mut self.audit.friction {
            friction.cone_violation_impulse = friction.cone_violation_impulse.max(excess);
        }
    }

    /// Account for a Zeno lock (docs/model.md section 5): its kinetic energy loss is a stopper loss, its impulse
    /// goes to the contact audit as `zeno_impulse` (the other units' pulls as `pull_impulse`).
    pub(super) fn see_zeno(&mut self, lock: &ZenoLock) {
        self.stopper_loss += lock.loss;
        self.audit.zeno_impulse = self.audit.zeno_impulse.max(lock.impulse);
        self.audit.pull_impulse = self.audit.pull_impulse.max(lock.pull_impulse);
        self.see_cone_impulse(lock.cone_impulse);
        self.scuffing |= lock.active.slide2;
    }

    /// Account for the swinging leg's stopper lock from `before` (rear_exit = continue): a stopper loss, its
    /// pulls to the contact audit, and Leg 1 leaving or Leg 2 sliding through it.
    pub(super) fn see_swing_lock(&mut self, lock: &SwingLock, before: &ActiveSet) {
        self.stopper_loss += lock.loss;
        self.audit.pull_impulse = self.audit.pull_impulse.max(lock.pull_impulse);
        self.bounce |= before.contact1 && !lock.active.contact1;
        self.scuffing |= lock.active.slide2;
    }
}

/// Gauss-Legendre nodes on `[-1, 1]` and weights of the friction work's quadrature: five points, exact for
/// polynomials of degree 9, so that on the integrator's steps the quadrature error stays far below the
/// dense output's own (the friction power is smooth within a phase).
const GAUSS_LEGENDRE_5: [(f64, f64); 5] = [
    (0.0, 128.0 / 225.0),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// The energy the friction force of the slipping tips of `active` dissipates over `step` up to `until`,
/// `-integral of sum lambda_t v_t dt` \[J\], and the largest friction power `lambda_t v_t` at the quadrature
/// points \[W\] (never positive when the law holds). Hand-written quadrature on the integrator's dense output
/// rather than an extra integrated state: one more state would change the error norm, and so the steps, of
/// every walk without friction.
fn slip_work(model: &Model, active: ActiveSet, step: &DenseStep<NY>, until: f64) -> (f64, f64) {
    let (t0, half) = (0.5 * (step.t0() + until), 0.5 * (until - step.t0()));
    let (mut work, mut largest) = (0.0, f64::NEG_INFINITY);
    for (node, weight) in GAUSS_LEGENDRE_5 {
        let (q, qd) = unpack(&step.eval(t0 + half * node));
        let Ok(d) = constrained_dynamics(model, &q, &qd, &active) else {
            return (f64::NAN, f64::NAN);
        };
        let power: f64 = Leg::BOTH
            .into_iter()
            .filter(|&leg| active.slip(leg) != 0)
            .map(|leg| {
                let v = model.tip(&q, &qd, leg.index()).velocity(&qd).x;
                d.multipliers[leg.tangential_row()] * v
            })
            .sum();
        work += weight * power;
        largest = largest.max(power);
    }
    (-half * work, largest.max(0.0))
}
