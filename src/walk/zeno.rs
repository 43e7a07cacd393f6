//! Zeno sequences of stopper impacts and of landings resolved at their accumulation point (docs/model.md
//! sections 4-5).
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
//! `stopper_gap`, not on the integrator's steps. A compression stop (`min_length`) is treated the same way,
//! mirrored: a leg within `stopper_gap` above it, moving outward slower than its inward acceleration turns it
//! round within the gap, is locked there.
//!
//! **Landings.** The same happens with the two tips on the ground: when both tips touch a frictionless ground,
//! the landing of one kicks the other up at about the speed it landed with (the impulse at one tip reaches the
//! other through the mass matrix), the kicked tip comes back within microseconds and kicks the first, and the
//! tips take turns carrying the wheel thousands of times per millisecond, sinking by the grazing guard
//! `recontact_gap` at every landing (the short-leg starts of the default basin did this). A free tip at the
//! ground (`height <= recontact_gap`) that separates at a speed `v` with `v^2 < 2 a_down recontact_gap`,
//! where `a_down > 0` is its downward acceleration as a free tip, is closed by a plastic impact the same way,
//! as its next landing would close it: held without slip, unless holding it would pull it down by more than
//! [`ZENO_IMPULSE_WARNING`] (a tip sliding fast along the ground), then frictionless; the motion goes on with
//! both tips on the ground.

use crate::contact::{
    cone_excess, constrained_dynamics, largest_pull, ActiveSet, ContactError, ImpulseSolution,
    Role, Stop,
};
use crate::dynamics::{Coords, Model};
use crate::params::ContactInconsistency;

use super::error::WalkError;

use super::impact::{
    bilateral_stoppers, consistent_active_set, has_stop, plastic_impact, post_impact_candidates,
    stop_length, Candidate, Mode, Unit, COMPLEMENTARITY_TOL, STICK_SPEED_TOL,
};

/// A Zeno lock whose stopper impulse exceeds this \[N s\] is reported as a warning by `vrw simulate`: the rule
/// then changes the momentum by more than a grazing correction. The impulse of a lock is at most about
/// `m sqrt(2 a_out stopper_gap)`: 3.6e-4 N s for a 1 kg leg under 65 m/s^2 with the default `stopper_gap`.
pub const ZENO_IMPULSE_WARNING: f64 = 1e-3;

/// What [`lock_zeno_stoppers`] did to the state after an impact.
#[derive(Debug, Clone, PartialEq)]
pub struct ZenoLock {
    /// The stoppers locked and the contacts closed at the accumulation point.
    pub locked: ActiveSet,
    /// `q'` after the locks.
    pub qd_plus: Coords,
    /// The active set of the motion that follows.
    pub active: ActiveSet,
    /// Kinetic energy the locks and closures took away \[J\] (a stopper loss of the energy audit).
    pub loss: f64,
    /// The largest pulling impulse of a locked stopper (outward) or a closed tip (downward) \[N s\]
    /// (`ContactAudit::zeno_impulse`), at most about `m sqrt(2 a gap)` with the unit's gap.
    pub impulse: f64,
    /// The largest pulling impulse of the other units that took an impulse in the locks \[N s\] (contact audit).
    pub pull_impulse: f64,
    /// The units that took an impulse in each of the locks' plastic impacts, in order (at most one per leg):
    /// what the exact derivatives replay (`crate::variational`).
    pub impulse_sets: Vec<ActiveSet>,
    /// The largest excess of a sticking contact's impulse over the friction cone in the locks \[N s\], 0 if none
    /// (and without friction).
    pub cone_impulse: f64,
}

/// The units at `(q, q')` under `active` that the Zeno rule closes (as flags of an [`ActiveSet`]): the free legs
/// at their stopper (`L0 - L <= stopper_gap`), moving inward (`L' < -COMPLEMENTARITY_TOL`) slower than the speed
/// that would take them more than `stopper_gap` inward against their outward acceleration `a_out = L''` before
/// they return (`L'^2 < 2 a_out stopper_gap`), and the free tips at the ground (`height <= recontact_gap`: a
/// tip that landed at the grazing guard is `recontact_gap` below it)
/// rising (`v > COMPLEMENTARITY_TOL`) slower than the speed that would take them above `recontact_gap` against
/// their downward acceleration (`v^2 < 2 a_down recontact_gap`); a tip closes as a no-slip contact here (see
/// [`lock_zeno_stoppers`] for when it slides instead). Units in `exclude` were closed already.
fn zeno_units(
    model: &Model,
    (q, qd): (&Coords, &Coords),
    active: &ActiveSet,
    (stopper_gap, recontact_gap): (f64, f64),
    exclude: &ActiveSet,
) -> Result<ActiveSet, ContactError> {
    let bilateral = bilateral_stoppers(model);
    let mut units = ActiveSet::default();
    let mut dynamics = None;
    let mut free_dynamics = || -> Result<_, ContactError> {
        if dynamics.is_none() {
            dynamics = Some(constrained_dynamics(model, q, qd, active)?);
        }
        Ok(dynamics.expect("just computed"))
    };
    for leg in Role::BOTH {
        let i = Model::stroke_coordinate(leg);
        // A compression stop the same way, mirrored: a free leg within `stopper_gap` above `min_length`,
        // moving outward slower than its inward acceleration can turn round within the gap.
        for stop in Stop::BOTH {
            let s = stop.sign();
            let free = has_stop(model, leg, stop)
                && !(active.held(leg, stop)
                    || bilateral.held(leg, stop)
                    || exclude.held(leg, stop));
            let v = s * qd[i];
            if free
                && s * (stop_length(model, stop) - q[i]) <= stopper_gap
                && v < -COMPLEMENTARITY_TOL
            {
                let a_back = s * free_dynamics()?.qdd[i];
                if a_back > 0.0 && v * v < 2.0 * a_back * stopper_gap {
                    units.set_held(leg, stop, true);
                }
            }
        }
        let tip_free = !(active.contact(leg) || exclude.contact(leg));
        if tip_free && model.tip_height(q, leg.index()) <= recontact_gap {
            let tip = model.tip(q, qd, leg.index());
            let v = tip.velocity(qd).y;
            if v > COMPLEMENTARITY_TOL {
                let a_down = -(tip.jacobian * free_dynamics()?.qdd + tip.velocity_product).y;
                if a_down > 0.0 && v * v < 2.0 * a_down * recontact_gap {
                    units.set_contact(leg, true);
                }
            }
        }
    }
    Ok(units)
}

/// The units of `a` and of `b` (a contact sliding in either slides).
fn union(a: &ActiveSet, b: &ActiveSet) -> ActiveSet {
    ActiveSet {
        contact1: a.contact1 || b.contact1,
        contact2: a.contact2 || b.contact2,
        lock1: a.lock1 || b.lock1,
        lock2: a.lock2 || b.lock2,
        slide1: a.slide1 || b.slide1,
        slide2: a.slide2 || b.slide2,
        compression1: a.compression1 || b.compression1,
        compression2: a.compression2 || b.compression2,
        slip1: if a.slip1 != 0 { a.slip1 } else { b.slip1 },
        slip2: if a.slip2 != 0 { a.slip2 } else { b.slip2 },
    }
}

/// The units of a Zeno impact: the bilateral stoppers and the units `closing` closes, forced, and every other
/// unit of `active` a candidate of the impulse-level complementarity problem.
fn zeno_impact_units(
    model: &Model,
    (q, qd): (&Coords, &Coords),
    closing: &ActiveSet,
    active: &ActiveSet,
) -> (ActiveSet, Vec<Candidate>) {
    let mut forced = bilateral_stoppers(model);
    let mut candidates = Vec::new();
    for leg in Role::BOTH {
        for stop in Stop::BOTH {
            if closing.held(leg, stop) {
                forced.set_held(leg, stop, true);
            }
        }
        if closing.contact(leg) {
            // A closing tip is forced, its small pull being the Zeno impulse; with Coulomb friction a tip that
            // moves along the ground closes slipping that way (a sticking impulse would leave the cone).
            let v = model.tip(q, qd, leg.index()).velocity(qd).x;
            if model.params().has_friction() && v.abs() > STICK_SPEED_TOL {
                forced.set_slipping(leg, if v > 0.0 { 1 } else { -1 });
            } else {
                Unit::Contact(leg).apply(&mut forced, Unit::Contact(leg).mode(closing));
            }
        }
        for unit in Unit::of(leg) {
            if unit.mode(active) != Mode::Off && unit.mode(&forced) == Mode::Off {
                candidates.push(Candidate::keep(unit, active));
            }
        }
    }
    (forced, candidates)
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
    gaps: (f64, f64),
    time: f64,
) -> Result<Option<ZenoLock>, WalkError> {
    let phase = active.phase();
    let contact_error = WalkError::contact_at(time, phase);
    let mut locks = Locks::default();
    let (mut qd_now, mut active_now) = (*qd, active);
    loop {
        let legs = zeno_units(model, (q, &qd_now), &active_now, gaps, &locks.locked)
            .map_err(contact_error)?;
        if legs == ActiveSet::default() {
            break;
        }
        let impact = zeno_impact(model, (q, &qd_now), &active_now, legs, gaps, &locks.locked)
            .map_err(contact_error)?;
        let present = locks.record(model, &impact, active_now);
        let (sol, impulse_set) = (&impact.sol, &impact.impulse_set);
        let (forced, candidates) =
            post_impact_candidates(model, q, &sol.qd_plus, impulse_set, &present, impulse_set);
        let (next, _) = consistent_active_set(model, q, &sol.qd_plus, forced, &candidates)
            .map_err(contact_error)?
            .ok_or(WalkError::InconsistentContacts { time, phase })?;
        qd_now = sol.qd_plus;
        active_now = next;
    }
    if locks.locked == ActiveSet::default() {
        return Ok(None);
    }
    Ok(Some(ZenoLock {
        locked: locks.locked,
        qd_plus: qd_now,
        active: active_now,
        loss: model.kinetic_energy(q, qd) - model.kinetic_energy(q, &qd_now),
        impulse: locks.zeno_impulse,
        pull_impulse: locks.pull_impulse,
        impulse_sets: locks.impulse_sets,
        cone_impulse: locks.cone_impulse,
    }))
}

/// One plastic impact of a Zeno lock: the units it closes, the units that took an impulse and its solution.
struct ZenoImpact {
    /// The units the Zeno rule closes in it (those picked at first and those the impact kicks off too slowly).
    legs: ActiveSet,
    /// The units that took an impulse.
    impulse_set: ActiveSet,
    /// The impact's solution.
    sol: ImpulseSolution,
}

/// One impact problem at `(q, q')` under `active`, closing the units `legs` (none of `locked`): a tip closes as
/// a landing does, held (no slip) unless holding it would pull it down by more than a grazing correction, then
/// sliding (where sliding is allowed); and a unit that the impact itself kicks off too slowly to clear its gap
/// closes in the same impact (two tips that would take turns landing close together, the accumulation point of
/// their sequence).
fn zeno_impact(
    model: &Model,
    (q, qd): (&Coords, &Coords),
    active: &ActiveSet,
    mut legs: ActiveSet,
    gaps: (f64, f64),
    locked: &ActiveSet,
) -> Result<ZenoImpact, ContactError> {
    loop {
        let (forced, candidates) = zeno_impact_units(model, (q, qd), &legs, active);
        let (set, sol) = plastic_impact(model, q, qd, forced, &candidates)?;
        let pulled = Role::BOTH.into_iter().find(|&leg| {
            legs.contact(leg) && !legs.slide(leg) && sol.normal_impulse(leg) < -ZENO_IMPULSE_WARNING
        });
        if let (Some(leg), ContactInconsistency::Slide, false) = (
            pulled,
            model.params().inconsistent_contact,
            model.params().has_friction(),
        ) {
            legs.set_sliding(leg);
            continue;
        }
        // The units that took an impulse hold; the others are free after the impact.
        let kicked = zeno_units(model, (q, &sol.qd_plus), &set, gaps, &union(&legs, locked))?;
        if kicked == ActiveSet::default() {
            return Ok(ZenoImpact {
                legs,
                impulse_set: set,
                sol,
            });
        }
        legs = union(&legs, &kicked);
    }
}

/// What the locks of one Zeno sequence add up to (the fields of [`ZenoLock`] gathered impact by impact).
#[derive(Default)]
struct Locks {
    /// The stoppers locked and the contacts closed so far.
    locked: ActiveSet,
    /// The largest pulling impulse of the other units that took an impulse \[N s\].
    pull_impulse: f64,
    /// The largest pulling impulse of a locked stopper or a closed tip \[N s\].
    zeno_impulse: f64,
    /// The units that took an impulse in each impact, in order.
    impulse_sets: Vec<ActiveSet>,
    /// The largest excess of a sticking contact's impulse over the friction cone \[N s\].
    cone_impulse: f64,
}

impl Locks {
    /// Add `impact` under `active` (the set before it); the units present after it (`active` with the units
    /// it closed).
    fn record(&mut self, model: &Model, impact: &ZenoImpact, active: ActiveSet) -> ActiveSet {
        let ZenoImpact {
            legs,
            impulse_set,
            sol,
        } = impact;
        for leg in Role::BOTH {
            for stop in Stop::BOTH {
                if legs.held(leg, stop) {
                    self.locked.set_held(leg, stop, true);
                }
            }
            if legs.contact(leg) {
                Unit::Contact(leg).apply(&mut self.locked, Unit::Contact(leg).mode(legs));
            }
        }
        self.impulse_sets.push(*impulse_set);
        let mut others = *impulse_set;
        let mut present = active;
        for leg in Role::BOTH {
            for stop in Stop::BOTH {
                if legs.held(leg, stop) {
                    others.set_held(leg, stop, false);
                    present.set_held(leg, stop, true);
                    self.zeno_impulse = self.zeno_impulse.max(-sol.stop_impulse(leg, stop));
                }
            }
            if legs.contact(leg) {
                others.set_contact(leg, false);
                Unit::Contact(leg).apply(&mut present, Unit::Contact(leg).mode(legs));
                self.zeno_impulse = self.zeno_impulse.max(-sol.normal_impulse(leg));
            }
        }
        let rigid = model.params().rigid_legs;
        self.pull_impulse = self
            .pull_impulse
            .max(largest_pull(&sol.impulses, &others, rigid));
        let mu = model.params().friction;
        self.cone_impulse = self
            .cone_impulse
            .max(cone_excess(&sol.impulses, impulse_set, mu));
        present
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{L1, L2};
    use crate::params::Params;

    /// A wheel in flight with Leg 1 locked and Leg 2 just kicked off its stopper.
    fn flight(model: &Model, v2: f64) -> (Coords, Coords, ActiveSet) {
        let l0 = model.params().stopper_length;
        let q = Coords::new(0.0, 0.1, -0.2, l0, l0, 0.0);
        let qd = Coords::new(1.0, 0.5, 1.5, 0.0, v2, 0.0);
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
        let lock = lock_zeno_stoppers(&model, &q, &qd, active, (gap, 1e-11), 0.0)
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
        assert!(
            lock_zeno_stoppers(&model, &q, &qd, active, (gap, 1e-11), 0.0)
                .unwrap()
                .is_none()
        );
    }

    /// A leg moving outward, a leg away from its stopper, and a leg already locked are not touched.
    #[test]
    fn only_legs_leaving_their_stopper_slowly_are_locked() {
        let model = stiff();
        let (q, qd, active) = flight(&model, 1e-6);
        assert!(
            lock_zeno_stoppers(&model, &q, &qd, active, (1e-9, 1e-11), 0.0)
                .unwrap()
                .is_none()
        );
        let (mut q, qd, active) = flight(&model, -1e-6);
        q[L2] -= 1e-6;
        assert!(
            lock_zeno_stoppers(&model, &q, &qd, active, (1e-9, 1e-11), 0.0)
                .unwrap()
                .is_none()
        );
        let (q, qd, mut active) = flight(&model, 0.0);
        active.lock2 = true;
        assert!(
            lock_zeno_stoppers(&model, &q, &qd, active, (1e-9, 1e-11), 0.0)
                .unwrap()
                .is_none()
        );
    }

    /// Both tips at the ground, Leg 1 held, Leg 2's tip rising at `v` (kicked by Leg 1's landing): below the
    /// speed that could lift it above `recontact_gap` it is closed (no slip, at rest along the ground), with
    /// an impulse within the Zeno bound; above it, the tip is left to fly.
    #[test]
    fn a_tip_kicked_below_the_gap_is_closed_plastically() {
        let model = Model::new(&Params::default()).unwrap();
        let (l1, l2) = (0.95, 0.9);
        let alpha = model.alpha();
        let theta = ((l2 * alpha.cos() - l1) / (l2 * alpha.sin())).atan();
        let q = Coords::new(0.0, 0.0, theta, l1, l2, 0.0);
        let active = ActiveSet {
            contact1: true,
            ..ActiveSet::default()
        };
        // Leg 2's tip velocity is J_2 q'; with Leg 1 held (x' = z' = 0), move L2 to lift it.
        let with_tip_speed = |v: f64| {
            let mut qd = Coords::new(0.0, 0.0, 0.8, -0.1, 0.0, 0.0);
            let tip = model.tip(&q, &qd, 1);
            let (vx, vz) = (tip.velocity(&qd).x, tip.velocity(&qd).y);
            // Solve for the theta' and L2' that give the tip velocity (0, v) with L1' fixed.
            let j = tip.jacobian;
            let m = nalgebra::Matrix2::new(j[(0, 2)], j[(0, 4)], j[(1, 2)], j[(1, 4)]);
            let delta = m.lu().solve(&nalgebra::Vector2::new(-vx, v - vz)).unwrap();
            qd[2] += delta[0];
            qd[4] += delta[1];
            qd
        };
        let gaps = (1e-9, 1e-11);
        let qd = with_tip_speed(1e-7);
        let tip = model.tip(&q, &qd, 1);
        assert!((tip.velocity(&qd).y - 1e-7).abs() < 1e-15 && tip.velocity(&qd).x.abs() < 1e-15);
        let lock = lock_zeno_stoppers(&model, &q, &qd, active, gaps, 0.0)
            .unwrap()
            .expect("closed");
        assert!(lock.locked.contact2 && !lock.locked.slide2, "{lock:?}");
        assert!(lock.active.contact2, "{lock:?}");
        let after = model.tip(&q, &lock.qd_plus, 1).velocity(&lock.qd_plus);
        assert!(after.norm() < 1e-12, "the closed tip is at rest: {after}");
        assert!(
            lock.impulse < 1e-5,
            "a grazing correction: {}",
            lock.impulse
        );
        assert!(lock.loss >= 0.0);
        assert!(
            lock_zeno_stoppers(&model, &q, &with_tip_speed(1e-3), active, gaps, 0.0)
                .unwrap()
                .is_none()
        );
    }
}
