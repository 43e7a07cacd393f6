//! The force-level events of a contact (docs/model.md sections 4 and 12): a lift-off, and with Coulomb friction
//! a slip start at the edge of the cone and a slip stop, each resolved by the force-level complementarity
//! problem with every other active unit kept.

use crate::contact::{constrained_dynamics, ActiveSet, Role, Stop};
use crate::dynamics::{Coords, Model};

use super::complementarity::{consistent_active_set, Candidate, Mode, Unit};
use super::error::WalkError;
use super::events::EventKind;
use super::impact::bilateral_stoppers;

/// The active set after a contact's force-level event `kind` at `(q, q')`: a lift-off ([`Candidate::releasing`]);
/// with Coulomb friction, a sticking tip's force reaching the edge of the cone (it slips against the friction
/// force that reached it, [`Candidate::cone_reached`]) or a slipping tip coming to rest (it sticks where the cone
/// holds it, else slips the other way). See [`release_contact`].
pub(crate) fn contact_event(
    model: &Model,
    time: f64,
    (q, qd): (&Coords, &Coords),
    active: ActiveSet,
    kind: EventKind,
) -> Result<ActiveSet, WalkError> {
    let changing = match kind {
        EventKind::ConeLimit(leg) => {
            let dynamics = constrained_dynamics(model, q, qd, &active)
                .map_err(WalkError::contact_at(time, active.phase()))?;
            let direction = if dynamics.multipliers[leg.tangential_row()] > 0.0 {
                -1
            } else {
                1
            };
            Candidate::cone_reached(leg, direction)
        }
        EventKind::SlipStop(leg) => Candidate::new(Unit::Contact(leg), Mode::On),
        EventKind::LiftOff(leg) => Candidate::releasing(leg),
        // Not a contact's force-level event: nothing of the contacts changes.
        _ => {
            debug_assert!(false, "not a contact's force-level event: {kind:?}");
            return Ok(active);
        }
    };
    release_contact(model, time, (q, qd), active, changing)
}

/// A contact changes at a force-level event: the active set of the motion that follows, with `changing` the
/// contact's candidate and every other active unit kept. At a lift-off ([`Candidate::releasing`]) the tip
/// preferably leaves the ground (it slides instead if leaving would drive it into the ground, see
/// [`crate::params::ContactInconsistency`], or slips with Coulomb friction); with Coulomb friction, at the edge
/// of the cone ([`Candidate::cone_reached`]) it slips, and where a slip stops it sticks if the cone holds it.
/// No consistent set is [`WalkError::InconsistentContacts`]; a Painleve case is a [`WalkError::Contact`] whose
/// source is [`ContactError::Painleve`] (status `painleve`).
fn release_contact(
    model: &Model,
    time: f64,
    (q, qd): (&Coords, &Coords),
    active: ActiveSet,
    changing: Candidate,
) -> Result<ActiveSet, WalkError> {
    let phase = active.phase();
    let forced = bilateral_stoppers(model);
    let mut candidates = Vec::new();
    for leg in Role::BOTH {
        if active.contact(leg) {
            candidates.push(if Unit::Contact(leg) == changing.unit {
                changing
            } else {
                Candidate::keep(Unit::Contact(leg), &active)
            });
        }
        for stop in Stop::BOTH {
            if active.held(leg, stop) && !forced.held(leg, stop) {
                candidates.push(Candidate::keep(Unit::Stop(leg, stop), &active));
            }
        }
    }
    let (new_active, _) = consistent_active_set(model, q, qd, forced, &candidates)
        .map_err(WalkError::contact_at(time, phase))?
        .ok_or(WalkError::InconsistentContacts { time, phase })?;
    Ok(new_active)
}
