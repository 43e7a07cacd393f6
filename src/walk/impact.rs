//! Touchdown: re-indexing and the DLS-indicator impact procedure (docs/model.md section 5, paper Sec. 2.2,
//! algorithm (A1)-(A4), (B1)-(B3)), plus the plastic impacts and unilateral checks used by every other event,
//! each resolved by the complementarity problems of `walk::complementarity`.

use serde::Serialize;

use crate::contact::{
    cone_excess, constrained_dynamics, largest_pull, swing_lock_impulse, ActiveSet, ContactError,
    ImpulseSolution, Multipliers, Role, Stop,
};
use crate::dynamics::{Coords, LegIndex, Model, L3, THETA};
use crate::params::ImpactModel;

pub use super::complementarity::Unit;
pub(crate) use super::complementarity::{
    consistent_active_set, plastic_impact, plastic_impact_by, Candidate, Mode, COMPLEMENTARITY_TOL,
    STICK_SPEED_TOL,
};

/// The three DLS indicators of the paper (Sec. 2.2): `lambda_I4` from (A1), `lambda_2+`, `lambda_4+` from (B1).
/// `NaN` where the procedure does not define them (`lambda_2+`, `lambda_4+` after (A3), all three when the
/// rear leg was not on the ground at touchdown or the legs are rigid).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DlsIndicators {
    /// Normal impulse on Leg 2 of the DLS collision (A1) \[N s\] (`lambda_I4` in every output).
    #[serde(rename = "lambda_I4")]
    pub lambda_i4: f64,
    /// Normal force on Leg 1 just after impact, Eqs. (6)-(7) \[N\].
    pub lambda_2_plus: f64,
    /// Normal force on Leg 2 just after impact, Eqs. (6)-(7) \[N\].
    pub lambda_4_plus: f64,
}

impl DlsIndicators {
    /// All three undefined.
    pub(crate) const UNDEFINED: DlsIndicators = DlsIndicators {
        lambda_i4: f64::NAN,
        lambda_2_plus: f64::NAN,
        lambda_4_plus: f64::NAN,
    };
}

/// Which branch of the procedure a touchdown took.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum Branch {
    /// (B2): `lambda_I4 >= 0`, `lambda_2+ >= 0`, `lambda_4+ >= 0`: a DLS phase follows.
    Dls,
    /// (A3), or the traditional impact: the rear leg leaves at once (`J_SLS` collision).
    Sls,
    /// (B3): `lambda_I4 >= 0` but `lambda_4+ < 0`: SLS from the DLS post-impact velocity (the paper's open case).
    SlsB3,
    /// `lambda_I4 >= 0` but `lambda_2+ < 0`: Leg 1 bounces at once.
    Bounce,
    /// The rear leg was in the air at touchdown (after a bounce): a plain plastic landing of Leg 1.
    RearAirborne,
}

impl std::fmt::Display for Branch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Branch::Dls => "DLS",
            Branch::Sls => "SLS",
            Branch::SlsB3 => "SLS_B3",
            Branch::Bounce => "BOUNCE",
            Branch::RearAirborne => "REAR_AIRBORNE",
        })
    }
}

/// What the touchdown impact produced.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TouchdownImpact {
    /// `q'+`.
    pub qd_plus: Coords,
    /// DLS indicators of this touchdown.
    pub indicators: DlsIndicators,
    /// Branch of the procedure.
    pub branch: Branch,
    /// Units that took the impulse (all at zero relative velocity after it).
    pub impulse_set: ActiveSet,
    /// Contacts the procedure asks to keep for the motion that follows (its preferred phase).
    pub preferred: ActiveSet,
    /// Kinetic energy lost in the impact \[J\].
    pub loss: f64,
    /// The largest pulling impulse of the applied collision \[N s\], 0 if none pulls (contact audit).
    pub pull_impulse: f64,
    /// The largest excess of a sticking contact's impulse over the friction cone \[N s\], 0 if none (friction
    /// audit).
    pub cone_impulse: f64,
}

/// The leg whose touchdown ends the step: of the legs not in `q` (`j = 2..N`, all at `L0`), the one with the
/// lowest tip (docs/model.md section 4). In a walk this is the front leg `j = -1` ([`Model::front_leg`], chosen
/// on a tie); after a long flight the wheel may have turned by more than `alpha`, and then a leg further ahead
/// (or behind) comes down first. Since every such leg has length `L0`, the lowest tip is the one whose angle
/// `psi_j = theta + j alpha` is nearest to 0 modulo `2 pi`: the front leg, the leg `j = 2`, or the leg nearest
/// to `j = -theta / alpha`.
pub(crate) fn touchdown_leg(model: &Model, q: &Coords) -> LegIndex {
    let n = model.legs();
    let front = model.front_leg();
    let nearest = (-q[THETA] / model.alpha()).round().rem_euclid(n as f64) as usize % n;
    let mut best = (front, model.tip_height(q, front));
    for j in [2, nearest] {
        if (2..n).contains(&j) && j != front {
            let h = model.tip_height(q, j);
            if h < best.1 {
                best = (j, h);
            }
        }
    }
    best.0
}

/// The candidates of a touchdown impulse: the new Leg 1's contact, closing (no-slip if its normal impulse
/// pushes, else frictionless under [`ContactInconsistency::Slide`]), and the stops that may take an impulse:
/// Leg 1's stopper (at `L0`, locked before touchdown) and Leg 2's stopper or compression stop if it holds the
/// leg, unless they act both ways (`rigid_legs`, then they are forced).
fn touchdown_candidates(model: &Model, before: &ActiveSet) -> Vec<Candidate> {
    let bilateral = bilateral_stoppers(model);
    let mut candidates = vec![Candidate::closing(Unit::Contact(Role::Fore), model)];
    for leg in Role::BOTH {
        for stop in Stop::BOTH {
            if before.held(leg, stop) && !bilateral.held(leg, stop) {
                candidates.push(Candidate::new(Unit::Stop(leg, stop), Mode::Off));
            }
        }
    }
    candidates
}

/// The touchdown impact at `(q_dagger, q'_dagger)` after re-indexing (docs/model.md section 5).
///
/// `before` is the active set just before impact in the new indexing: `contact2` = the old Leg 1 was on the
/// ground, `lock1` = true (the new leg arrives locked), `lock2` = the old Leg 1's stopper.
///
/// 1. (A1) solve Eq. (5) with `J_DLS`: DLS indicator 1 is `lambda_I4`.
/// 2. (A3) if `lambda_I4 < 0`, the collision is recomputed with `J_SLS`.
/// 3. (A4)/(B1) otherwise keep `q'+` of (A1) and solve Eqs. (6)-(7) for `lambda+`: `lambda_2+`, `lambda_4+`.
/// 4. (B2) both non-negative: DLS; (B3) `lambda_4+ < 0`: SLS from the same `q'+`; `lambda_2+ < 0`: bounce.
///
/// Every collision is the impulse-level complementarity problem of [`plastic_impact`] in which Leg 2's
/// contact is forced by the procedure (on in (A1), off in (A3)) and the new Leg 1 is the closing unit: it takes
/// a no-slip impulse when that impulse pushes (the paper's `J_DLS`, `J_SLS`, and every regular touchdown), a
/// frictionless one when a no-slip impulse would pull, as on a leg that lands behind the hub after a flight.
/// With Coulomb friction (a finite `friction`) both tips of the (A1) collision take an impulse that sticks
/// where the cone holds the no-slip impulse and slips with a Coulomb impulse where it does not
/// (docs/model.md section 12); `lambda_I4` is then the normal impulse of that collision.
///
/// With [`ImpactModel::Traditional`] the indicators are still computed and reported, but the collision is
/// always the `J_SLS` one. With `rigid_legs` the stoppers act both ways and the exchange is the traditional
/// one; the indicators are undefined (a DLS collision of two locked legs is statically indeterminate).
pub(crate) fn touchdown_impact(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    before: ActiveSet,
) -> Result<TouchdownImpact, ContactError> {
    let finish = |impulse_set: ActiveSet,
                  sol: ImpulseSolution,
                  indicators: DlsIndicators,
                  branch: Branch,
                  preferred: ActiveSet| TouchdownImpact {
        qd_plus: sol.qd_plus,
        indicators,
        branch,
        impulse_set,
        preferred,
        loss: kinetic_loss(model, q, qd, &sol),
        pull_impulse: pull_of(model, &impulse_set, &sol),
        cone_impulse: cone_excess(&sol.impulses, &impulse_set, model.params().friction),
    };
    let sls = ActiveSet {
        contact1: true,
        ..Default::default()
    };
    let candidates = touchdown_candidates(model, &before);
    // Leg 2's contact as the procedure forces it (off for the J_SLS collision, on for the J_DLS one).
    let rear_off = bilateral_stoppers(model);
    let rear_on = ActiveSet {
        contact2: true,
        ..rear_off
    };

    if model.params().rigid_legs {
        let (set, sol) = plastic_impact(model, q, qd, rear_off, &candidates)?;
        return Ok(finish(set, sol, DlsIndicators::UNDEFINED, Branch::Sls, set));
    }
    if !before.contact2 {
        let (set, sol) = plastic_impact(model, q, qd, rear_off, &candidates)?;
        return Ok(finish(
            set,
            sol,
            DlsIndicators::UNDEFINED,
            Branch::RearAirborne,
            sls,
        ));
    }

    // (A1) the DLS collision. With Coulomb friction Leg 2's tip takes its impulse sticking or slipping, as the
    // cone decides: a closing unit of the impulse problem rather than a forced one.
    let dls = ActiveSet {
        contact2: true,
        ..sls
    };
    let DlsCollision {
        set: dls_set,
        sol: dls_sol,
        indicators,
    } = dls_collision(model, (q, qd), &candidates, (rear_off, rear_on))?;

    if model.params().impact == ImpactModel::Traditional || indicators.lambda_i4 < 0.0 {
        // (A3), or the traditional exchange: the rear leg leaves at once.
        let (set, sol) = plastic_impact(model, q, qd, rear_off, &candidates)?;
        return Ok(finish(set, sol, indicators, Branch::Sls, sls));
    }
    let DlsIndicators {
        lambda_2_plus,
        lambda_4_plus,
        ..
    } = indicators;
    let (branch, preferred) = match (lambda_2_plus >= 0.0, lambda_4_plus >= 0.0) {
        (true, true) => (Branch::Dls, dls),
        (true, false) => (Branch::SlsB3, sls),
        (false, rear) => (
            Branch::Bounce,
            ActiveSet {
                contact2: rear,
                ..Default::default()
            },
        ),
    };
    Ok(finish(dls_set, dls_sol, indicators, branch, preferred))
}

/// The DLS collision of a touchdown and its indicators: the units that took an impulse, its solution and the
/// three DLS indicators.
struct DlsCollision {
    set: ActiveSet,
    sol: ImpulseSolution,
    indicators: DlsIndicators,
}

/// (A1) the DLS collision of a touchdown at `(q, q')` (Eq. (5) with `J_DLS`, among `candidates`, Leg 2's
/// contact forced on as in `rear_on`, or with Coulomb friction a closing unit besides those forced in
/// `rear_off`), and (B1) the forces just after it, Eqs. (6)-(7), where `lambda_I4 >= 0`.
fn dls_collision(
    model: &Model,
    (q, qd): (&Coords, &Coords),
    candidates: &[Candidate],
    (rear_off, rear_on): (ActiveSet, ActiveSet),
) -> Result<DlsCollision, ContactError> {
    let (set, sol) = if model.params().has_friction() {
        let mut with_rear = candidates.to_vec();
        with_rear.push(Candidate::closing(Unit::Contact(Role::Rear), model));
        plastic_impact(model, q, qd, rear_off, &with_rear)?
    } else {
        plastic_impact(model, q, qd, rear_on, candidates)?
    };
    let lambda_i4 = sol.normal_impulse(Role::Rear);
    // (B1) forces just after the DLS collision, Eqs. (6)-(7).
    let (lambda_2_plus, lambda_4_plus) = if lambda_i4 >= 0.0 {
        let after = constrained_dynamics(model, q, &sol.qd_plus, &set)?;
        (
            after.normal_force(Role::Fore),
            after.normal_force(Role::Rear),
        )
    } else {
        (f64::NAN, f64::NAN)
    };
    Ok(DlsCollision {
        set,
        sol,
        indicators: DlsIndicators {
            lambda_i4,
            lambda_2_plus,
            lambda_4_plus,
        },
    })
}

/// Does `leg` have its extension stopper? Leg 1 always; Leg 2 unless `rear_stopper = false`.
pub(crate) fn has_stopper(model: &Model, leg: Role) -> bool {
    leg == Role::Fore || model.params().rear_stopper
}

/// Does `leg` have `stop` as a unilateral limit with its own events? The stopper as [`has_stopper`] says, the
/// compression stop where `min_length > 0`; neither with `rigid_legs` (the stoppers are then bilateral and
/// always active, and the legs never shorten).
pub(crate) fn has_stop(model: &Model, leg: Role, stop: Stop) -> bool {
    let params = model.params();
    !params.rigid_legs
        && match stop {
            Stop::Extension => has_stopper(model, leg),
            Stop::Compression => params.min_length > 0.0,
        }
}

/// The stop `stop`'s limit on a leg's length \[m\]: `L0` or `min_length`.
pub(crate) fn stop_length(model: &Model, stop: Stop) -> f64 {
    match stop {
        Stop::Extension => model.params().stopper_length,
        Stop::Compression => model.params().min_length,
    }
}

/// The stoppers that act both ways and are always active: both with `rigid_legs` (docs/model.md section 7), none
/// otherwise. Every active-set resolution starts from this set.
pub(crate) fn bilateral_stoppers(model: &Model) -> ActiveSet {
    let rigid = model.params().rigid_legs;
    ActiveSet {
        lock1: rigid,
        lock2: rigid,
        ..ActiveSet::default()
    }
}

/// Candidates for the motion right after an impact at `(q, q'+)`: every unit that took the impulse is closed
/// (zero relative velocity) and may stay active; every other unit `present` at the impact that still touches
/// (a tip at the ground, or a leg at its stopper, with relative velocity within [`COMPLEMENTARITY_TOL`] of
/// zero) may engage too, so that no free tip accelerates into the ground. A unit left approaching (only the
/// `traditional` exchange does that) stays free, and its landing event fires at once. `preferred` gives the modes
/// the procedure wants (the paper's branch at a touchdown). With `rigid_legs` the stoppers are bilateral and
/// forced.
pub(crate) fn post_impact_candidates(
    model: &Model,
    q: &Coords,
    qd_plus: &Coords,
    impulse_set: &ActiveSet,
    present: &ActiveSet,
    preferred: &ActiveSet,
) -> (ActiveSet, Vec<Candidate>) {
    let forced = bilateral_stoppers(model);
    let mut candidates = Vec::new();
    for leg in Role::BOTH {
        let contact = Unit::Contact(leg);
        if impulse_set.contact(leg) {
            candidates.push(Candidate::keep(contact, preferred));
        } else if present.contact(leg)
            && model.tip(q, qd_plus, leg.index()).velocity(qd_plus).y.abs() <= COMPLEMENTARITY_TOL
        {
            candidates.push(Candidate::new(contact, Mode::Off));
        }
        for stop in Stop::BOTH {
            if forced.held(leg, stop) {
                continue;
            }
            let unit = Unit::Stop(leg, stop);
            if impulse_set.held(leg, stop) {
                candidates.push(Candidate::new(unit, Mode::On));
            } else if present.held(leg, stop)
                && qd_plus[Model::stroke_coordinate(leg)].abs() <= COMPLEMENTARITY_TOL
            {
                candidates.push(Candidate::new(unit, Mode::Off));
            }
        }
    }
    (forced, candidates)
}

/// What an impact closing one unit produced (see [`close_unit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitImpact {
    /// The units that took the impulse.
    pub impulse_set: ActiveSet,
    /// The active set of the motion that follows (the force-level problem at `q'+`).
    pub active: ActiveSet,
    /// `q'+`.
    pub qd_plus: Coords,
    /// The applied impulses in the fixed stacking.
    pub impulses: Multipliers,
    /// Kinetic energy lost \[J\].
    pub loss: f64,
    /// The largest pulling impulse \[N s\], 0 if none pulls (contact audit).
    pub pull_impulse: f64,
    /// The largest excess of a sticking contact's impulse over the friction cone \[N s\], 0 if none (friction
    /// audit).
    pub cone_impulse: f64,
}

/// A plastic impact closing `unit` (a tip landing on the ground or a leg hitting its stopper) at `(q, q')` with
/// `active` the units active just before, then the active set of the motion that follows; `None` if no active
/// set is consistent after the impact.
///
/// Only the closing unit must take an impulse (no-slip if that impulse pushes, else, under
/// [`crate::params::ContactInconsistency::Slide`], a frictionless one: a no-slip impact can demand a pulling normal impulse,
/// the impulsive form of the lift-off inconsistency). Every other unit present (each ground contact, no-slip
/// or sliding, and each locked stopper) is a candidate of the impulse-level complementarity problem of `plastic_impact`: it takes
/// a non-negative impulse and ends at zero relative normal velocity, or takes none and separates. Nothing is
/// held through the impact because it was active before: when Leg 2's stopper locks while its tip slides, the
/// tip may leave the ground (docs/model.md section 4).
pub fn close_unit(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: ActiveSet,
    unit: Unit,
) -> Result<Option<UnitImpact>, ContactError> {
    let forced = bilateral_stoppers(model);
    let mut candidates = vec![Candidate::closing(unit, model)];
    for leg in Role::BOTH {
        for other in Unit::of(leg) {
            if other != unit && other.mode(&active) != Mode::Off && other.mode(&forced) == Mode::Off
            {
                candidates.push(Candidate::keep(other, &active));
            }
        }
    }
    let (impulse_set, sol) = plastic_impact(model, q, qd, forced, &candidates)?;
    let mut present = active;
    unit.apply(&mut present, Mode::On);
    let (forced, candidates) =
        post_impact_candidates(model, q, &sol.qd_plus, &impulse_set, &present, &impulse_set);
    let Some((next, _)) = consistent_active_set(model, q, &sol.qd_plus, forced, &candidates)?
    else {
        return Ok(None);
    };
    Ok(Some(UnitImpact {
        impulse_set,
        active: next,
        qd_plus: sol.qd_plus,
        impulses: sol.impulses,
        loss: kinetic_loss(model, q, qd, &sol),
        pull_impulse: pull_of(model, &impulse_set, &sol),
        cone_impulse: cone_excess(&sol.impulses, &impulse_set, model.params().friction),
    }))
}

/// The swinging leg's stopper lock (see [`lock_swinging_leg`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SwingLock {
    /// `q` with the leg a spoke again (`L3 = 0`).
    pub(crate) q: Coords,
    /// `q'+` (`dL3/dt = 0`).
    pub(crate) qd_plus: Coords,
    /// The active set of the motion that follows.
    pub(crate) active: ActiveSet,
    /// Energy `T + V` lost \[J\]: the impact's, and the rounding of setting the leg to its stopper length.
    pub(crate) loss: f64,
    /// The largest pulling impulse of the units that took an impulse, the swinging leg's stopper included \[N s\]
    /// (contact audit).
    pub(crate) pull_impulse: f64,
}

/// The swinging leg (`L3`, `rear_exit = "continue"`) reaches its stopper: a plastic impact (5) that stops it
/// there, in which every other unit of `active` is a candidate of the impulse-level complementarity problem as
/// in [`close_unit`] (it pushes, or takes no impulse and separates), after which the leg is a spoke of the
/// wheel again (`L3` leaves `q`); then the active set of the motion that follows, `None` if none is
/// consistent.
pub(crate) fn lock_swinging_leg(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: ActiveSet,
) -> Result<Option<SwingLock>, ContactError> {
    let forced = bilateral_stoppers(model);
    let candidates: Vec<Candidate> = Role::BOTH
        .into_iter()
        .flat_map(Unit::of)
        .filter(|u| u.mode(&active) != Mode::Off && u.mode(&forced) == Mode::Off)
        .map(|u| Candidate::keep(u, &active))
        .collect();
    let (impulse_set, sol) = plastic_impact_by(model, (q, qd), forced, &candidates, |set| {
        swing_lock_impulse(model, q, qd, set).map(|(sol, _)| sol)
    })?;
    // The stopper's own impulse may only push the leg inward (`mu <= 0`): one that pulls goes to the audit.
    let (_, mu) = swing_lock_impulse(model, q, qd, &impulse_set)?;
    let pull_impulse = pull_of(model, &impulse_set, &sol).max(mu);
    let mut q_spoke = *q;
    let mut qd_plus = sol.qd_plus;
    (q_spoke[L3], qd_plus[L3]) = (0.0, 0.0);
    let (forced, candidates) = post_impact_candidates(
        model,
        &q_spoke,
        &qd_plus,
        &impulse_set,
        &active,
        &impulse_set,
    );
    let Some((next, _)) = consistent_active_set(model, &q_spoke, &qd_plus, forced, &candidates)?
    else {
        return Ok(None);
    };
    Ok(Some(SwingLock {
        q: q_spoke,
        qd_plus,
        active: next,
        loss: model.energy(q, qd) - model.energy(&q_spoke, &qd_plus),
        pull_impulse,
    }))
}

/// Kinetic energy an impact from `q'` to `sol.qd_plus` takes away \[J\].
fn kinetic_loss(model: &Model, q: &Coords, qd: &Coords, sol: &ImpulseSolution) -> f64 {
    model.kinetic_energy(q, qd) - model.kinetic_energy(q, &sol.qd_plus)
}

/// The largest pulling impulse of the units of `impulse_set` in `sol` \[N s\] (contact audit; stoppers of rigid
/// legs act both ways and are not audited).
fn pull_of(model: &Model, impulse_set: &ActiveSet, sol: &ImpulseSolution) -> f64 {
    largest_pull(&sol.impulses, impulse_set, model.params().rigid_legs)
}
