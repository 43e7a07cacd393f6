//! Zeno sequences of stopper impacts resolved at their accumulation point (docs/model.md sections 4-5).
//!
//! When one leg hits its stopper while the other rests on its own, the impact's complementarity problem stops
//! the first leg and kicks the second a little off its stopper (inward, at a few percent of the speed); the
//! second leg's preloaded spring brings it back, its impact kicks the first leg off again at a few percent of
//! that, and so on: a Zeno sequence, whose impacts come closer in time and smaller in speed and which converges
//! within microseconds to both legs locked. The walker cannot follow it impact by impact: once a kicked leg's
//! excursion `v^2 / (2 a_out)` is below `stopper_gap`, its stopper event is inside the grazing guard.
//! [`lock_zeno_stoppers`] takes the sequence to its accumulation point instead, as event-driven simulators take
//! a bouncing ball to rest (Drake's rod2d example, Siconos' event-driven scheme; Goebel and Teel, Ames et al.
//! on Zeno hybrid systems): right after an impact, a leg that is at its stopper (within `stopper_gap` of `L0`)
//! and separates inward at a speed `v` with `v^2 < 2 a_out stopper_gap`, where `a_out > 0` is its outward
//! acceleration as a free leg, is locked by a plastic stopper impact. The rule depends only on the state and on
//! `stopper_gap`, not on the integrator's steps.

use crate::contact::{constrained_dynamics, largest_pull, ActiveSet, ContactError, Leg};
use crate::dynamics::{Coords, Model};

use super::error::WalkError;

use super::impact::{
    bilateral_stoppers, consistent_active_set, plastic_impact, post_impact_candidates, Candidate,
    Mode, Unit, COMPLEMENTARITY_TOL,
};

/// A Zeno lock whose stopper impulse exceeds this \[N s\] is reported as a warning by `vrw simulate`: the rule
/// then changes the momentum by more than a grazing correction. The impulse of a lock is at most about
/// `m sqrt(2 a_out stopper_gap)`: 3.6e-4 N s for a 1 kg leg under 65 m/s^2 with the default `stopper_gap`.
pub const ZENO_IMPULSE_WARNING: f64 = 1e-3;

/// What [`lock_zeno_stoppers`] did to the state after an impact.
#[derive(Debug, Clone, PartialEq)]
pub struct ZenoLock {
    /// The stoppers locked at the accumulation point.
    pub locked: ActiveSet,
    /// `q'` after the locks.
    pub qd_plus: Coords,
    /// The active set of the motion that follows.
    pub active: ActiveSet,
    /// Kinetic energy the locks took away \[J\] (a stopper loss of the energy audit).
    pub loss: f64,
    /// The largest outward (pulling) impulse of a locked stopper \[N s\] (`ContactAudit::zeno_impulse`), at most
    /// about `m sqrt(2 a_out stopper_gap)`.
    pub impulse: f64,
    /// The largest pulling impulse of the other units that took an impulse in the locks \[N s\] (contact audit).
    pub pull_impulse: f64,
    /// The units that took an impulse in each of the locks' plastic impacts, in order (at most one per leg):
    /// what the exact derivatives replay (`crate::variational`).
    pub impulse_sets: Vec<ActiveSet>,
}

/// The free legs at `(q, q')` under `active` that the Zeno rule locks: at their stopper (`L0 - L <=
/// stopper_gap`), moving inward (`L' < -COMPLEMENTARITY_TOL`) slower than the speed that would take them more
/// than `stopper_gap` inward against their outward acceleration `a_out = L''` before they return
/// (`L'^2 < 2 a_out stopper_gap`).
fn zeno_legs(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: &ActiveSet,
    stopper_gap: f64,
    exclude: &ActiveSet,
) -> Result<ActiveSet, ContactError> {
    let l0 = model.params().stopper_length;
    let bilateral = bilateral_stoppers(model);
    let mut legs = ActiveSet::default();
    let mut dynamics = None;
    for leg in Leg::BOTH {
        let i = leg.length_coordinate();
        if active.lock(leg) || bilateral.lock(leg) || exclude.lock(leg) {
            continue;
        }
        let v = qd[i];
        if l0 - q[i] > stopper_gap || v >= -COMPLEMENTARITY_TOL {
            continue;
        }
        if dynamics.is_none() {
            dynamics = Some(constrained_dynamics(model, q, qd, active)?);
        }
        let a_out = dynamics.as_ref().map_or(0.0, |d| d.qdd[i]);
        if a_out > 0.0 && v * v < 2.0 * a_out * stopper_gap {
            legs.set_lock(leg, true);
        }
    }
    Ok(legs)
}

/// Right after an impact at `time`, at `(q, q')` whose motion would continue with `active`: lock every leg the
/// Zeno rule picks (see the [module documentation](self)) by a plastic impact in which those stoppers close and
/// every other unit of `active` is a candidate of the impulse-level complementarity problem (it takes a
/// non-negative impulse or separates). A locked stopper's impulse is not checked for sign: it is the small
/// outward impulse that stands for the spring's push over the rest of the sequence, and it is reported as
/// [`ZenoLock::impulse`]. The force-level problem then gives the motion that follows, which is checked again
/// (each leg is locked at most once). `None` when no leg qualifies; an error when the force-level problem has
/// no consistent set after the locks.
pub fn lock_zeno_stoppers(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: ActiveSet,
    stopper_gap: f64,
    time: f64,
) -> Result<Option<ZenoLock>, WalkError> {
    let phase = active.phase();
    let contact_error = WalkError::contact_at(time, phase);
    let rigid = model.params().rigid_legs;
    let mut locked = ActiveSet::default();
    let (mut qd_now, mut active_now) = (*qd, active);
    let mut pull_impulse: f64 = 0.0;
    let mut zeno_impulse: f64 = 0.0;
    let mut impulse_sets = Vec::new();
    loop {
        let legs = zeno_legs(model, q, &qd_now, &active_now, stopper_gap, &locked)
            .map_err(contact_error)?;
        if legs == ActiveSet::default() {
            break;
        }
        let mut forced = bilateral_stoppers(model);
        let mut candidates = Vec::new();
        for leg in Leg::BOTH {
            if legs.lock(leg) {
                forced.set_lock(leg, true);
                locked.set_lock(leg, true);
            }
            for unit in [Unit::Contact(leg), Unit::Stopper(leg)] {
                if unit.mode(&active_now) != Mode::Off && unit.mode(&forced) == Mode::Off {
                    candidates.push(Candidate::keep(unit, &active_now));
                }
            }
        }
        let (impulse_set, sol) =
            plastic_impact(model, q, &qd_now, forced, &candidates).map_err(contact_error)?;
        impulse_sets.push(impulse_set);
        let mut others = impulse_set;
        for leg in Leg::BOTH {
            if legs.lock(leg) {
                others.set_lock(leg, false);
                zeno_impulse = zeno_impulse.max(-sol.stopper_impulse(leg));
            }
        }
        pull_impulse = pull_impulse.max(largest_pull(&sol.impulses, &others, rigid));
        let mut present = active_now;
        for leg in Leg::BOTH {
            if legs.lock(leg) {
                present.set_lock(leg, true);
            }
        }
        let (forced, candidates) =
            post_impact_candidates(model, q, &sol.qd_plus, &impulse_set, &present, &impulse_set);
        let (next, _) = consistent_active_set(model, q, &sol.qd_plus, forced, &candidates)
            .map_err(contact_error)?
            .ok_or(WalkError::InconsistentContacts { time, phase })?;
        qd_now = sol.qd_plus;
        active_now = next;
    }
    if locked == ActiveSet::default() {
        return Ok(None);
    }
    Ok(Some(ZenoLock {
        locked,
        qd_plus: qd_now,
        active: active_now,
        loss: model.kinetic_energy(q, qd) - model.kinetic_energy(q, &qd_now),
        impulse: zeno_impulse,
        pull_impulse,
        impulse_sets,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{L1, L2};
    use crate::params::Params;

    /// A wheel in flight with Leg 1 locked and Leg 2 just kicked off its stopper.
    fn flight(model: &Model, v2: f64) -> (Coords, Coords, ActiveSet) {
        let l0 = model.params().stopper_length;
        let q = Coords::new(0.0, 0.1, -0.2, l0, l0);
        let qd = Coords::new(1.0, 0.5, 1.5, 0.0, v2);
        let active = ActiveSet {
            lock1: true,
            ..ActiveSet::default()
        };
        (q, qd, active)
    }

    fn stiff() -> Model {
        Model::new(&Params {
            stiffness: 3000.0,
            ..Params::default()
        })
        .unwrap()
    }

    /// A kick too small to clear the gap is locked; the impulse stops the leg, is outward and within the
    /// bound `m sqrt(2 a gap)`, and the kinetic energy it takes is positive and within `m a gap`.
    #[test]
    fn a_kick_below_the_gap_is_locked_plastically() {
        let model = stiff();
        let gap = 1e-9;
        let (q, qd, active) = flight(&model, -1e-5);
        let a = constrained_dynamics(&model, &q, &qd, &active).unwrap().qdd[L2];
        assert!(a > 0.0);
        let lock = lock_zeno_stoppers(&model, &q, &qd, active, gap, 0.0)
            .unwrap()
            .expect("locked");
        assert!(lock.locked.lock2 && lock.active.lock2 && lock.active.lock1);
        assert!(lock.qd_plus[L2].abs() < 1e-15 && lock.qd_plus[L1].abs() < 1e-15);
        assert!(lock.impulse > 0.0 && lock.impulse <= 1.0 * (2.0 * a * gap).sqrt());
        assert!(lock.loss > 0.0 && lock.loss <= 1.0 * a * gap);
        assert_eq!(lock.pull_impulse, 0.0);
        // The same state with a kick that clears the gap is left alone.
        let fast = -2.0 * (2.0 * a * gap).sqrt();
        let (q, qd, active) = flight(&model, fast);
        assert!(lock_zeno_stoppers(&model, &q, &qd, active, gap, 0.0)
            .unwrap()
            .is_none());
    }

    /// A leg moving outward, a leg away from its stopper, and a leg already locked are not touched.
    #[test]
    fn only_legs_leaving_their_stopper_slowly_are_locked() {
        let model = stiff();
        let (q, qd, active) = flight(&model, 1e-6);
        assert!(lock_zeno_stoppers(&model, &q, &qd, active, 1e-9, 0.0)
            .unwrap()
            .is_none());
        let (mut q, qd, active) = flight(&model, -1e-6);
        q[L2] -= 1e-6;
        assert!(lock_zeno_stoppers(&model, &q, &qd, active, 1e-9, 0.0)
            .unwrap()
            .is_none());
        let (q, qd, mut active) = flight(&model, 0.0);
        active.lock2 = true;
        assert!(lock_zeno_stoppers(&model, &q, &qd, active, 1e-9, 0.0)
            .unwrap()
            .is_none());
    }
}
