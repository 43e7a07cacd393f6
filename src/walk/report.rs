//! What a step reports (docs/model.md sections 5 and 7): the indicators and durations, the energy audit and
//! the contact audit, with the tolerances above which an audit value is a warning the user sees.

use serde::Serialize;

use crate::fmt::short;

use super::impact::{Branch, DlsIndicators};
use super::section::SectionState;
use super::zeno::ZENO_IMPULSE_WARNING;

/// Energy bookkeeping of one step, from just before its touchdown to just before the next one
/// (docs/model.md section 7): the loss of `T + V` must equal the damper dissipation plus the impact and stopper
/// losses.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EnergyAudit {
    /// `T + V` just before the touchdown that starts the step \[J\] (in the step's frame).
    pub start: f64,
    /// `T + V` just before the next touchdown \[J\] (same frame).
    pub end: f64,
    /// `start - end` \[J\].
    pub loss: f64,
    /// `integral of c (dL1^2 + dL2^2) dt` over the step \[J\].
    pub damper: f64,
    /// Kinetic energy lost in the touchdown collision and in ground re-contacts \[J\].
    pub impact: f64,
    /// Kinetic energy lost when a sliding leg hits its stopper, and in Zeno locks (docs/model.md section 5)
    /// \[J\].
    pub stopper: f64,
    /// Energy the Coulomb friction force dissipated while tips slipped between impacts, `-integral of lambda_t
    /// v_t dt` \[J\] (a finite `friction` only; the friction inside an impact is part of `impact`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// `loss - (damper + impact + stopper + friction)` \[J\]: zero up to the integration error.
    pub residual: f64,
    /// Energy removed (negative: added) after the step, at the touchdown that ends it, by discarding the old
    /// rear leg's length and rate (`rear_exit = "reset"`, docs/model.md section 5) \[J\]: `end` minus `T + V`
    /// of the reset state. 0 with `rear_exit = "relock"` (written only when not 0).
    #[serde(skip_serializing_if = "is_zero")]
    pub reset: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// A step whose energy audit leaves more than this unexplained \[J\] is a warning: the integration or an event
/// is then not to be trusted.
pub const ENERGY_RESIDUAL_WARNING: f64 = 1e-6;

/// A pulling force (or outward stopper reaction) above this \[N\] is a warning. Forces of 100 N that cross zero
/// at 1e4 to 1e5 N/s, located to `event_time_tol` (1e-13 s), overshoot by up to 1e-8 N; this is a hundred
/// times that, and a millionth of the wheel's weight.
pub const PULL_FORCE_WARNING: f64 = 1e-6;

/// A pulling impulse above this \[N s\] is a warning. Impulses come from a linear solve with the active set
/// fixed, so a law that holds gives 0 up to rounding (1e-15); the wrong active set gives 1e-2 to 10 N s.
pub const PULL_IMPULSE_WARNING: f64 = 1e-9;

/// A tip deeper than this below the ground \[m\] is a warning: a re-contact is armed `recontact_gap` (1e-11 m
/// by default, at most 1e-6 m) above the ground and located to `event_time_tol`, so a law that holds stays
/// within about 1e-11 m.
pub const PENETRATION_WARNING: f64 = 1e-9;

/// A leg farther than this past its stopper \[m\] is a warning: a free leg's stopper event fires at most
/// `stopper_gap` (1e-9 m by default) past `L0`.
pub const STOPPER_OVERRUN_WARNING: f64 = 1e-8;

/// Contact audit of one step (docs/model.md sections 3, 4 and 7): the ground only pushes, stoppers only pull a
/// leg inward, no tip goes below the ground and no leg past its stopper. Each field is 0 when the law holds
/// exactly; a few 1e-10 come from event location and integration. A value above its tolerance
/// ([`PULL_FORCE_WARNING`], ...) is a warning ([`StepReport::audit_warnings`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct ContactAudit {
    /// The largest pulling normal force or outward stopper reaction seen in the step \[N\] (at every accepted
    /// integrator step, at three more points inside it, and at every event instant), 0 if none.
    pub pull_force: f64,
    /// The largest pulling impulse at any of the step's impacts \[N s\], 0 if none.
    pub pull_impulse: f64,
    /// The deepest any tip went below the ground during the step \[m\] (checked on the dense output), 0 if
    /// none.
    pub penetration: f64,
    /// The farthest Leg 1 or Leg 2 went past its stopper, `max(L - L0)` over the step \[m\] (checked where
    /// `penetration` is), 0 if none: a stopper lock is late by at most `APPROACH_GAP` per lock of a sequence,
    /// and `stopper_gap` after a grazing unlock (docs/model.md section 4).
    pub stopper_overrun: f64,
    /// The largest outward impulse of a stopper locked at the accumulation point of a Zeno sequence of stopper
    /// impacts \[N s\], 0 if none (docs/model.md section 5): the small velocity the lock removes, at most about
    /// `m sqrt(2 a_out stopper_gap)`; not a pull of the ground or a stopper, so it is not in `pull_impulse`.
    pub zeno_impulse: f64,
    /// The Coulomb friction audit (a finite `friction` only).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionAudit>,
}

/// A sticking contact's force farther than this outside the friction cone \[N\] is a warning: the slip-start
/// event fires `FORCE_EVENT_MARGIN` (1e-10 N) outside it, and its time is located to `event_time_tol`.
pub const CONE_VIOLATION_WARNING: f64 = 1e-6;

/// A positive friction power above this \[W\] is a warning: the friction force of a slipping tip opposes its
/// slip velocity, so its power is `-mu lambda_n |v_t| <= 0`; a slip that reverses without its stop event, or a
/// pulling normal force, would make it positive.
pub const SLIP_POWER_WARNING: f64 = 1e-9;

/// The Coulomb friction audit of one step (docs/model.md section 12): the force of a sticking contact stays in
/// the cone `|lambda_t| <= mu lambda_n`, an impulse that sticks too, and the friction force of a slipping tip
/// never does positive work. Each field is 0 when the law holds.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct FrictionAudit {
    /// The largest distance outside the friction cone, `(|lambda_t| - mu lambda_n) / sqrt(1 + mu^2)`, of a
    /// sticking contact's force seen in the step \[N\] (where the pulling force is checked), 0 if none is
    /// outside.
    pub cone_violation: f64,
    /// The same for a contact that stuck through an impact \[N s\], 0 if none.
    pub cone_violation_impulse: f64,
    /// The largest power `lambda_t v_t` of the friction force on a slipping tip \[W\] (at the quadrature points
    /// of the friction work), 0 if it never does positive work.
    pub slip_power: f64,
}
/// One step of the walk: from a touchdown to the next.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepReport {
    /// Step number, from 1.
    pub step: usize,
    /// Time of the touchdown that starts the step \[s\].
    pub time: f64,
    /// The Poincare-section state just before that touchdown.
    pub section: SectionState,
    /// `theta` at that touchdown, after re-indexing \[rad\].
    pub theta: f64,
    /// The three DLS indicators of the touchdown (docs/model.md section 5).
    pub indicators: DlsIndicators,
    /// Branch of the impact procedure taken.
    pub branch: Branch,
    /// Double-limb support during the step \[s\]: the time both tips are on the ground without slipping,
    /// (C1) and (C2) both holding (it ends when Leg 2 starts to slide or leaves).
    pub dls_duration: f64,
    /// Time Leg 2's tip touches the ground at all during the step, sticking or sliding \[s\].
    pub rear_contact_duration: f64,
    /// Time to the next touchdown \[s\].
    pub period: f64,
    /// Distance along the slope between this touchdown's tip and the next one's \[m\].
    pub step_length: f64,
    /// `step_length / period` \[m/s\].
    pub speed: f64,
    /// Leg 2's tip came back to the ground during the step.
    pub scuffing: bool,
    /// Leg 1 left the ground during the step (or at the touchdown itself).
    pub bounce: bool,
    /// Number of events (lift-offs, contacts, stopper locks/unlocks) in the step.
    pub events: usize,
    /// Energy bookkeeping.
    pub energy: EnergyAudit,
    /// Contact audit (its fields are flattened into the step's JSON record).
    #[serde(flatten)]
    pub contact: ContactAudit,
    /// The smallest `dtheta/dt` in the step \[rad/s\]: at a local minimum, the vertex of the parabola through
    /// the event search's three points around it. Near a family's end where the wheel rolls back, it falls to
    /// zero as a power of the distance to the end in the parameter: the family's ends are extrapolated with it
    /// (`family/end_search.rs`). Not written to the outputs.
    #[serde(skip)]
    pub slowest: f64,
}

impl StepReport {
    /// What the step's audits say is wrong: one message per audit value above its tolerance (energy residual,
    /// pulling force, pulling impulse, penetration, stopper overrun), naming the step, the value and the
    /// tolerance. A NaN value is a warning too. Empty when every law holds.
    pub fn audit_warnings(&self) -> Vec<String> {
        let mut checks = self.contact_checks();
        if let Some(f) = &self.contact.friction {
            checks.extend(friction_checks(f));
        }
        checks
            .iter()
            .filter(|check| check.value.is_nan() || check.value > check.limit)
            .map(|check| {
                let AuditCheck {
                    name,
                    value,
                    limit,
                    unit,
                    meaning,
                } = check;
                let shown = if *name == "energy residual" {
                    self.energy.residual
                } else {
                    *value
                };
                format!(
                    "step {}: {name} {} {unit} exceeds {} {unit} ({meaning})",
                    self.step,
                    short(shown),
                    short(*limit)
                )
            })
            .collect()
    }

    /// The checks of the energy audit and of the contact audit without friction (see
    /// [`StepReport::audit_warnings`]).
    fn contact_checks(&self) -> Vec<AuditCheck> {
        let c = &self.contact;
        vec![
            AuditCheck {
                name: "energy residual",
                value: self.energy.residual.abs(),
                limit: ENERGY_RESIDUAL_WARNING,
                unit: "J",
                meaning: "the energy audit does not close",
            },
            AuditCheck {
                name: "pulling force",
                value: c.pull_force,
                limit: PULL_FORCE_WARNING,
                unit: "N",
                meaning: "the ground or a stopper pulled",
            },
            AuditCheck {
                name: "pulling impulse",
                value: c.pull_impulse,
                limit: PULL_IMPULSE_WARNING,
                unit: "N s",
                meaning: "an impact pulled",
            },
            AuditCheck {
                name: "penetration",
                value: c.penetration,
                limit: PENETRATION_WARNING,
                unit: "m",
                meaning: "a tip went below the ground",
            },
            AuditCheck {
                name: "stopper overrun",
                value: c.stopper_overrun,
                limit: STOPPER_OVERRUN_WARNING,
                unit: "m",
                meaning: "a leg went past its stopper",
            },
            AuditCheck {
                name: "Zeno stopper lock impulse",
                value: c.zeno_impulse,
                limit: ZENO_IMPULSE_WARNING,
                unit: "N s",
                meaning: "docs/model.md section 5: lower stopper_gap",
            },
        ]
    }
}

/// One value of a step's audits against its tolerance, as [`StepReport::audit_warnings`] words a warning.
struct AuditCheck {
    /// What is checked.
    name: &'static str,
    /// Its value (a warning where above `limit` or NaN).
    value: f64,
    /// The tolerance.
    limit: f64,
    /// The unit of both.
    unit: &'static str,
    /// What a value above the tolerance means.
    meaning: &'static str,
}

/// The checks of the friction audit (with Coulomb friction; see [`StepReport::audit_warnings`]).
fn friction_checks(f: &FrictionAudit) -> [AuditCheck; 3] {
    [
        AuditCheck {
            name: "friction cone violation",
            value: f.cone_violation,
            limit: CONE_VIOLATION_WARNING,
            unit: "N",
            meaning: "a sticking tip's force left the friction cone",
        },
        AuditCheck {
            name: "impulse cone violation",
            value: f.cone_violation_impulse,
            limit: PULL_IMPULSE_WARNING,
            unit: "N s",
            meaning: "a sticking impulse left the friction cone",
        },
        AuditCheck {
            name: "friction power",
            value: f.slip_power,
            limit: SLIP_POWER_WARNING,
            unit: "W",
            meaning: "friction did positive work on a slipping tip",
        },
    ]
}
