//! Re-indexing at touchdown (paper Sec. 2.2, docs/model.md section 5): the touching leg becomes Leg 1, the legs
//! behind it shift, and the legs that leave `q` must be in the air, and locked or reset.

use crate::contact::{ActiveSet, Role};
use crate::dynamics::{swinging, Coords, Model, L1, L3, THETA};
use crate::params::RearExit;

use super::error::WalkError;
use super::impact::has_stopper;

/// The index of the swinging leg (`L3`, [`RearExit::Continue`]): the old Leg 2, one leg behind the new Leg 2.
pub(crate) const SWING_LEG: usize = 2;

/// Re-indexing at touchdown (paper Sec. 2.2, docs/model.md section 5): the touching leg `touching` (the front
/// leg `j = -1` in a walk, see [`touchdown_leg`]) becomes Leg 1, the leg behind it becomes Leg 2, and the legs
/// that leave `q` (the old Leg 2; after a long flight also the old Leg 1) must be in the air, and locked at
/// `L0` ([`RearExit::Relock`]), or swing on as `L3` ([`RearExit::Continue`], the old Leg 2 after a step, which
/// must have been locked by now if it swung since the last touchdown), or reset to the spokes' length,
/// `touchdown_length` or `L0` ([`RearExit::Reset`]: their length and rate are discarded). The new Leg 1 has the
/// touchdown length. The origin moves to the new tip. Returns `(q_dagger, q'_dagger, active set before impact,
/// energy removed by the reset)`: `T + V` before minus after the reset \[J\], 0 when no leg was reset.
pub(super) fn reindex(
    model: &Model,
    time: f64,
    q: &Coords,
    qd: &Coords,
    active: ActiveSet,
    touching: usize,
) -> Result<(Coords, Coords, ActiveSet, f64), WalkError> {
    // The touching leg is `shift` legs ahead of Leg 1; with `shift > 1` the new Leg 2 is a locked leg.
    let shift = model.legs() - touching;
    let leaving: &[Role] = if shift == 1 {
        &[Role::Rear]
    } else {
        &Role::BOTH
    };
    if swinging(q) {
        // The leg that left at the last touchdown still swings: it would leave again, or it is touching down.
        return Err(WalkError::SwingingLegNotLocked {
            time,
            length: q[L3],
            rate: qd[L3],
        });
    }
    let (q_reset, qd_reset, swing) = leave(model, time, (q, qd), active, leaving, shift == 1)?;
    let front = model.tip(q, qd, touching);
    let v = front.velocity(qd);
    // The new Leg 1 lands at the touchdown length, and a spoke that becomes Leg 2 has it too.
    let l_td = model.params().spoke_length();
    let at_stopper = model.params().lands_on_stopper();
    let (l2, l2_dot) = if shift == 1 {
        (q[L1], qd[L1])
    } else {
        (l_td, 0.0)
    };
    let theta = if shift == 1 {
        q[THETA] - model.alpha()
    } else {
        // psi of the touching leg, in [-pi, pi].
        let psi = q[THETA] + touching as f64 * model.alpha();
        psi - std::f64::consts::TAU * (psi / std::f64::consts::TAU).round()
    };
    let q_new = Coords::new(0.0, front.position.y, theta, l_td, l2, swing.0);
    let qd_new = Coords::new(v.x, v.y, qd[THETA], 0.0, l2_dot, swing.1);
    let mut before = ActiveSet {
        contact1: false,
        contact2: shift == 1 && active.contact1,
        // It arrives locked on its stopper unless it lands shorter (`touchdown_length`).
        lock1: at_stopper,
        // A leg that becomes Leg 2 keeps its lock only if Leg 2 has a stopper (`rear_stopper`).
        lock2: ((shift > 1 && at_stopper) || (shift == 1 && active.lock1))
            && has_stopper(model, Role::Rear),
        // A leg held at its compression stop stays held as Leg 2.
        compression2: shift == 1 && active.compression1,
        ..Default::default()
    };
    // A tip slipping with Coulomb friction slips on as Leg 2's (the section's `slip` coordinate).
    if shift == 1 && active.contact1 && active.slip1 != 0 {
        before.set_slipping(Role::Rear, active.slip1);
    }
    // Only a free leg is reset: with none, the reset removes nothing, exactly.
    let reset_energy = if (q_reset, qd_reset) == (*q, *qd) {
        0.0
    } else {
        model.energy(q, qd) - model.energy(&q_reset, &qd_reset)
    };
    Ok((q_new, qd_new, before, reset_energy))
}

/// The legs `leaving` `q` at a touchdown (`one_step`: the old Leg 2 after a step, else after a flight): each must
/// be in the air, and locked, or reset ([`RearExit::Reset`]: the state returned has its length and rate reset),
/// or swing on as `L3` ([`RearExit::Continue`], one leg at a time: its length and rate returned).
fn leave(
    model: &Model,
    time: f64,
    (q, qd): (&Coords, &Coords),
    active: ActiveSet,
    leaving: &[Role],
    one_step: bool,
) -> Result<(Coords, Coords, (f64, f64)), WalkError> {
    let (mut q_reset, mut qd_reset) = (*q, *qd);
    // The old Leg 2 swinging on as `L3` (`RearExit::Continue`).
    let mut swing = (0.0, 0.0);
    for &leg in leaving {
        if active.contact(leg) {
            return Err(WalkError::RearLegInContact { time });
        }
        if active.lock(leg) {
            // Locked: at `L0` and at rest (to the stopper's tolerance, which every choice leaves out). A leg held
            // at its compression stop is not: it is reset, or not relocked.
            continue;
        }
        let i = Model::stroke_coordinate(leg);
        match model.params().rear_exit {
            RearExit::Reset => {
                q_reset[i] = model.params().spoke_length();
                qd_reset[i] = 0.0;
            }
            // One leg at a time: the old Leg 2 after a step (after a flight that moves Leg 1 out too, both would
            // leave).
            RearExit::Continue if one_step => swing = (q[i], qd[i]),
            _ => {
                return Err(WalkError::RearLegNotLocked {
                    time,
                    length: q[i],
                    rate: qd[i],
                })
            }
        }
    }
    Ok((q_reset, qd_reset, swing))
}
