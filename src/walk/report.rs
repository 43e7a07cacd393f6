//! What a step reports (the per-step report and its energy and contact audits; docs/model.md sections 5
//! and 7).

use serde::Serialize;

use super::impact::{Branch, DlsIndicators};
use super::section::SectionState;

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
    /// Kinetic energy lost when a sliding leg hits its stopper \[J\].
    pub stopper: f64,
    /// `loss - (damper + impact + stopper)` \[J\]: zero up to the integration error.
    pub residual: f64,
}

/// Contact audit of one step (docs/model.md sections 3-4): the ground only pushes, stoppers only pull a leg inward,
/// and no tip goes below the ground. Each field is 0 when the law holds exactly; a few 1e-10 come from event
/// location and integration.
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
    /// `penetration` is), 0 if none: a free leg's stopper event fires `stopper_gap` past `L0` at most
    /// (docs/model.md section 4). Not yet in the CSV and JSON outputs.
    #[serde(skip)]
    pub stopper_overrun: f64,
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
}
