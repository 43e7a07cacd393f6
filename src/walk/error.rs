//! Why a walk, a step or a gait search stopped (STYLE.md point 6): every variant carries the time and the
//! phase where it happened, so a failed run is a result the user can read.

use crate::contact::{ContactError, Phase};
use crate::fmt::short;
use crate::integrate::IntegrationError;

/// A walk that cannot continue.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WalkError {
    /// The hub dropped below `fall_hub_height`.
    #[error(
        "fell: hub height {hub_height:.4} m below the threshold at t = {time:.6} s in {phase}"
    )]
    Fell {
        /// Time \[s\].
        time: f64,
        /// Phase at the fall.
        phase: Phase,
        /// Hub height \[m\].
        hub_height: f64,
    },
    /// The wheel stopped and started rolling backward (`dtheta/dt` reached 0).
    #[error("rolled back: dtheta/dt reached 0 at t = {time:.6} s in {phase}")]
    RolledBack {
        /// Time \[s\].
        time: f64,
        /// Phase.
        phase: Phase,
    },
    /// The interrupt flag was set during the step (e.g. Ctrl-C); it is read every
    /// [`INTERRUPT_CHECK_STEPS`](super::INTERRUPT_CHECK_STEPS) integrator steps.
    #[error("interrupted at t = {time:.6} s in {phase}")]
    Interrupted {
        /// Time \[s\].
        time: f64,
        /// Phase.
        phase: Phase,
    },
    /// No touchdown within `max_step_time`.
    #[error("stalled: no touchdown within {limit} s (t = {time:.6} s, in {phase})")]
    Stalled {
        /// Time \[s\].
        time: f64,
        /// Phase.
        phase: Phase,
        /// The time limit of one step \[s\].
        limit: f64,
    },
    /// More than `max_events_per_step` events in one step (Zeno chatter).
    #[error("chatter: {events} events in one step by t = {time:.6} s in {phase}")]
    Chatter {
        /// Time \[s\].
        time: f64,
        /// Phase.
        phase: Phase,
        /// Number of events in the step.
        events: usize,
    },
    /// At touchdown the old Leg 2, which leaves `q`, was not locked at `L0` (docs/model.md section 5).
    #[error("old rear leg not relocked at touchdown (t = {time:.6} s, length {length:.6} m, rate {rate:.4} m/s)")]
    RearLegNotLocked {
        /// Time \[s\].
        time: f64,
        /// Its length \[m\].
        length: f64,
        /// Its rate of extension \[m/s\].
        rate: f64,
    },
    /// Under `rear_exit = "continue"`, the swinging leg (`L3`, the old rear leg) still swung at the touchdown
    /// after the one where it left Legs 1 and 2 (another leg would leave then, or it is the leg touching down).
    #[error(
        "the swinging leg (the old rear leg) was not locked by the next touchdown (t = {time:.6} s, length \
         {length:.6} m, rate {rate:.4} m/s)"
    )]
    SwingingLegNotLocked {
        /// Time \[s\].
        time: f64,
        /// Its length \[m\].
        length: f64,
        /// Its rate of extension \[m/s\].
        rate: f64,
    },
    /// Under `rear_exit = "continue"`, the tip of the swinging leg reached the ground.
    #[error("the swinging leg (the old rear leg) touched the ground at t = {time:.6} s in {phase} (length {length:.6} m)")]
    SwingingLegLanded {
        /// Time \[s\].
        time: f64,
        /// Phase.
        phase: Phase,
        /// Its length \[m\].
        length: f64,
    },
    /// Under `rear_exit = "continue"`, the old rear leg still swings at this touchdown (it left Legs 1 and 2
    /// unlocked): the walk goes on, but the Poincare section `(L2, thetadot, L2dot)` does not hold the swinging
    /// leg's state, so no step map starts here (gaits whose rear leg is late are not analysed yet).
    #[error(
        "the old rear leg still swings at touchdown (t = {time:.6} s, L3 = {length:.6} m, L3dot = {rate:.4} \
         m/s): the walk goes on, but the Poincare section (L2, thetadot, L2dot) does not hold it"
    )]
    SwingAtSection {
        /// Time \[s\].
        time: f64,
        /// Its length \[m\].
        length: f64,
        /// Its rate of extension \[m/s\].
        rate: f64,
    },
    /// At touchdown the old Leg 2 was still on the ground: three legs would support the wheel.
    #[error("old rear leg still on the ground at touchdown (t = {time:.6} s)")]
    RearLegInContact {
        /// Time \[s\].
        time: f64,
    },
    /// At touchdown the old Leg 1's tip (the new Leg 2) was sliding: the wheel is not on the Poincare section
    /// `(L2, thetadot, L2dot)`, which assumes that tip at rest, so a step map started from a section state
    /// would not be this walk. The walk itself can go on; the step map cannot.
    #[error(
        "the stance tip slides at touchdown (t = {time:.6} s, {speed:.3e} m/s): the walk leaves the Poincare \
         section (L2, thetadot, L2dot), which assumes it at rest"
    )]
    OffSection {
        /// Time \[s\].
        time: f64,
        /// Speed of the tip \[m/s\].
        speed: f64,
    },
    /// A step map that acts on `dtheta/dt` alone because Leg 2 is held at its compression stop at the section
    /// (`L2 = min_length`, `dL2/dt = 0`) reached a touchdown where it is free: the walk itself can go on, but the
    /// map's coordinates do not describe it (a gait on the border between the two, docs/model.md section 6).
    #[error(
        "Leg 2 is held at its compression stop at the section the step map starts from, but free at the next \
         touchdown (L2 = {length:.9} m, L2dot = {rate:.3e} m/s): the map on dtheta/dt alone cannot follow"
    )]
    HoldChanged {
        /// `L2` at the touchdown \[m\].
        length: f64,
        /// `dL2/dt` there \[m/s\].
        rate: f64,
    },
    /// A step map on states whose stance tip is at rest at the section reached a touchdown where it slips
    /// (Coulomb friction): the walk itself can go on, but the map's coordinates do not hold the slip velocity.
    #[error(
        "the stance tip slips at the next touchdown (slip {slip:.3e} m/s) but is at rest at the section the \
         step map starts from: the map on (L2, thetadot, L2dot) cannot follow"
    )]
    SlipAtSection {
        /// The tip's slip velocity at the touchdown \[m/s\].
        slip: f64,
    },
    /// No set of active contacts and stoppers satisfies the unilateral conditions.
    #[error("no consistent contact state at t = {time:.6} s in {phase}")]
    InconsistentContacts {
        /// Time \[s\].
        time: f64,
        /// Phase before the search.
        phase: Phase,
    },
    /// The constraint equations could not be solved.
    #[error("constraint solve failed at t = {time:.6} s in {phase}: {source}")]
    Contact {
        /// Time \[s\].
        time: f64,
        /// Phase.
        phase: Phase,
        /// What failed.
        source: ContactError,
    },
    /// The integrator failed.
    #[error("integration failed in {phase}: {source}")]
    Integration {
        /// Phase.
        phase: Phase,
        /// What failed.
        source: IntegrationError,
    },
    /// A Poincare-section state the wheel cannot be in.
    #[error("invalid section state: {field} = {}: {reason}", short(*.value))]
    InvalidSection {
        /// Which component (`L2`, `thetadot`, `L2dot`, `slip`).
        field: &'static str,
        /// Its value.
        value: f64,
        /// Why it is rejected.
        reason: &'static str,
    },
}

impl WalkError {
    /// Is this a touchdown that is not on the Poincare section although the walk goes on there
    /// ([`WalkError::OffSection`], [`WalkError::SwingAtSection`])?
    pub(crate) fn leaves_section(&self) -> bool {
        matches!(
            self,
            WalkError::OffSection { .. } | WalkError::SwingAtSection { .. }
        )
    }

    /// Wraps a failed constraint solve at `time` in `phase` (for `map_err`).
    pub(crate) fn contact_at(time: f64, phase: Phase) -> impl Fn(ContactError) -> WalkError + Copy {
        move |source| WalkError::Contact {
            time,
            phase,
            source,
        }
    }

    /// The time the walk stopped at \[s\], if the failure has one (every failure of a step has).
    pub(crate) fn time(&self) -> Option<f64> {
        match self {
            WalkError::Fell { time, .. }
            | WalkError::RolledBack { time, .. }
            | WalkError::Interrupted { time, .. }
            | WalkError::Stalled { time, .. }
            | WalkError::Chatter { time, .. }
            | WalkError::RearLegNotLocked { time, .. }
            | WalkError::RearLegInContact { time }
            | WalkError::SwingingLegNotLocked { time, .. }
            | WalkError::SwingingLegLanded { time, .. }
            | WalkError::SwingAtSection { time, .. }
            | WalkError::OffSection { time, .. }
            | WalkError::InconsistentContacts { time, .. }
            | WalkError::Contact { time, .. } => Some(*time),
            WalkError::Integration { source, .. } => Some(match source {
                IntegrationError::StepSizeTooSmall { time, .. }
                | IntegrationError::NonFinite { time } => *time,
            }),
            WalkError::InvalidSection { .. }
            | WalkError::HoldChanged { .. }
            | WalkError::SlipAtSection { .. } => None,
        }
    }

    /// A short machine-readable name of the failure (`fell`, `stalled`, ...), used in CSV and JSON output.
    pub fn kind(&self) -> &'static str {
        match self {
            WalkError::Fell { .. } => "fell",
            WalkError::RolledBack { .. } => "rolled_back",
            WalkError::Interrupted { .. } => "interrupted",
            WalkError::Stalled { .. } => "stalled",
            WalkError::Chatter { .. } => "chatter",
            WalkError::RearLegNotLocked { .. } => "rear_leg_not_locked",
            WalkError::RearLegInContact { .. } => "rear_leg_in_contact",
            WalkError::SwingingLegNotLocked { .. } => "swinging_leg_not_locked",
            WalkError::SwingingLegLanded { .. } => "swinging_leg_landed",
            WalkError::SwingAtSection { .. } => "leg_swings_at_section",
            WalkError::OffSection { .. } => "off_section",
            WalkError::HoldChanged { .. } => "hold_changed",
            WalkError::SlipAtSection { .. } => "slip_at_section",
            WalkError::InconsistentContacts { .. } => "inconsistent_contacts",
            WalkError::Contact {
                source: ContactError::Painleve(_) | ContactError::PainleveSlip { .. },
                ..
            } => "painleve",
            WalkError::Contact {
                source: ContactError::InconsistentImpact(_),
                ..
            } => "inconsistent_impact",
            WalkError::Contact { .. } => "constraint_failure",
            WalkError::Integration { .. } => "solver_failure",
            WalkError::InvalidSection { .. } => "invalid_section",
        }
    }
}
