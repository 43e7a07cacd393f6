//! The bookkeeping of a step in progress ([`StepTally`]): durations, the contact audit, flags and the energy
//! lost in impacts, which the step's report is made of.

use crate::contact::{constrained_dynamics, ActiveSet, Role};
use crate::dynamics::Model;
use crate::integrate::DenseStep;

use super::impact::{Branch, SwingLock, TouchdownImpact, Unit, UnitImpact};
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
    /// The smallest `dtheta/dt` so far.
    pub(super) slowest: Slowest,
}

/// The smallest `dtheta/dt` of a step \[rad/s\], from the points the event search evaluates: at a local minimum
/// inside a phase, the vertex of the parabola through the lowest point and its two neighbours, so that it is a
/// smooth function of the start as long as that minimum is (near a family's end where the wheel rolls back, it
/// falls to zero there; [`crate::walk::StepReport::slowest`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Slowest {
    /// The smallest value so far.
    pub(super) value: f64,
    /// The last two points `(t, dtheta/dt)` of the phase in progress.
    last: [Option<(f64, f64)>; 2],
}

impl Default for Slowest {
    fn default() -> Slowest {
        Slowest {
            value: f64::INFINITY,
            last: [None, None],
        }
    }
}

impl Slowest {
    /// A phase starts at time `t` with `dtheta/dt = v` (after an impact, `dtheta/dt` may have jumped).
    pub(super) fn begin_phase(&mut self, t: f64, v: f64) {
        self.last = [None, None];
        self.see(t, v);
    }

    /// The phase in progress has `dtheta/dt = v` at time `t` (later than the points seen before).
    pub(super) fn see(&mut self, t: f64, v: f64) {
        self.value = self.value.min(v);
        if let [Some((t0, v0)), Some((t1, v1))] = self.last {
            if v1 <= v0 && v1 <= v && t0 < t1 && t1 < t {
                // p(s) = v1 + b (s - t1) + c (s - t1)^2 through the three points (divided differences).
                let (d01, d12) = ((v1 - v0) / (t1 - t0), (v - v1) / (t - t1));
                let c = (d12 - d01) / (t - t0);
                let b = d01 + c * (t1 - t0);
                if c > 0.0 {
                    self.value = self.value.min(v1 - b * b / (4.0 * c));
                }
            }
        }
        self.last = [self.last[1], Some((t, v))];
    }
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

    /// Account for the plastic impact `closed` that closed `unit` of `leg` at a landing or a stopper hit: its
    /// pulls to the contact audit, its kinetic energy loss as a ground impact's or a stopper's, and Leg 2
    /// landing or sliding through it as scuffing.
    pub(super) fn see_closed_unit(&mut self, closed: &UnitImpact, unit: Unit, leg: Role) {
        self.audit.pull_impulse = self.audit.pull_impulse.max(closed.pull_impulse);
        self.see_cone_impulse(closed.cone_impulse);
        match unit {
            Unit::Contact(_) => self.impact_loss += closed.loss,
            Unit::Stop(..) => self.stopper_loss += closed.loss,
        }
        self.scuffing |=
            (leg == Role::Rear && matches!(unit, Unit::Contact(_))) || closed.active.slide2;
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
        let power: f64 = Role::BOTH
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The smallest value of a parabola sampled off its vertex is its vertex's, exactly (up to rounding), from
    /// unequally spaced points; a phase that starts after a jump counts with its own points: no parabola is
    /// drawn across the jump.
    #[test]
    fn the_smallest_dtheta_dt_is_refined_to_the_vertex() {
        let f = |t: f64| 2.0 * (t - 0.337).powi(2) + 0.25;
        let mut slowest = Slowest::default();
        slowest.begin_phase(0.0, f(0.0));
        for t in [0.1, 0.2, 0.31, 0.4, 0.45, 0.6] {
            slowest.see(t, f(t));
        }
        assert!((slowest.value - 0.25).abs() < 1e-15, "{}", slowest.value);
        let mut jumped = Slowest::default();
        jumped.begin_phase(0.0, 3.0);
        jumped.see(0.1, 2.0);
        jumped.begin_phase(0.2, 1.9);
        jumped.see(0.3, 2.5);
        assert_eq!(jumped.value, 1.9);
    }
}
