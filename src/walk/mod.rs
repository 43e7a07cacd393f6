//! The hybrid walk (docs/model.md sections 4-5): continuous phases separated by located events.
//!
//! A [`Walker`] holds the wheel at the Poincare section (just before a touchdown, after re-indexing) and
//! [`Walker::step`] advances it to the next one: the touchdown impact of [`impact`], then phases of constrained
//! motion, each integrated by an `Integrator` (DOP853 by default) until the earliest event, located on the dense
//! output (every event function is evaluated at the ends of `EVENT_SAMPLES` equal parts of each step):
//!
//! | event | function crossing zero from above |
//! |---|---|
//! | touchdown | height of the lowest tip of the legs not in `q` (the next leg's in a walk, see `impact::touchdown_leg`) |
//! | lift-off of an active contact | normal force `lambda_2` or `lambda_4` (to `FORCE_EVENT_MARGIN` below 0) |
//! | landing / rear re-contact of an airborne tip | its height (armed once above `recontact_gap`, see below) |
//! | stopper unlock | the stopper's inward reaction (to `FORCE_EVENT_MARGIN` below 0) |
//! | stopper hit of a free leg | `L0 - L` (armed once below `L0 - stopper_gap`) |
//! | compression-stop unlock (with `min_length > 0`) | the compression stop's outward reaction (to `FORCE_EVENT_MARGIN` below 0) |
//! | compression-stop hit of a free leg (with `min_length > 0`) | `L - min_length` (armed once above `min_length + stopper_gap`) |
//! | fall | hub height minus `fall_hub_height` |
//! | rolling back | `dtheta/dt` |
//!
//! **Grazing guard.** Right after a lift-off at `lambda_4 = 0` the tip leaves the ground with zero velocity and
//! acceleration, so the height function starts at zero. Such an event is *disarmed*: its function is
//! `height - (min(h0, 0) - recontact_gap)` with `h0` the height at the start of the phase, which fires only if
//! the tip sinks `recontact_gap` below where it started (or below the ground) without having risen; once the
//! height exceeds `recontact_gap` at an accepted step the event is armed and its function is the height itself.
//! Stoppers and compression stops use `stopper_gap` the same way. Both are options of [`SolverOptions`](crate::params::SolverOptions). (Measuring from `h0` matters
//! after a re-contact located at `-recontact_gap`: a guard measured from the ground would start at zero and
//! never fire, letting the tip sink.)
//!
//! **Impacts.** Every impact (touchdown, rear re-contact, stopper lock) is an impulse-level complementarity
//! problem over every unilateral unit present (see `impact::plastic_impact`); only the closing unit (and at
//! touchdown the paper's (A1)/(A3) choice for Leg 2) is forced. The force-level problem then picks the phase
//! that follows. A leg that an impact kicks off its stopper too slowly to leave it by `stopper_gap` is locked at
//! once (the Zeno rule of `zeno.rs`, docs/model.md section 5), and a leg that leaves its stopper faster has its
//! stopper event fire at `L0` (`APPROACH_GAP`).
//!
//! **Audits.** Every step reports an energy audit and a contact audit ([`ContactAudit`]): the largest pulling
//! force at the ends of the `EVENT_SAMPLES` parts of every accepted integrator step and at every event instant,
//! the largest pulling impulse of its impacts, and
//! the deepest any tip went below the ground, checked on the dense output at `PENETRATION_SAMPLES` points
//! per integrator step.
//!
//! **Layout.** `phase.rs` holds the phase ODE, `events.rs` the event functions and their guards,
//! `audit.rs` the contact audit's per-step checks, `impact.rs` the impacts, `zeno.rs` the Zeno rule for
//! sequences of stopper impacts, `walker.rs` the step
//! ([`Walker`]), `run.rs` the walks of many steps ([`simulate`], [`simulate_streaming`]), `trajectory.rs`
//! the sampled trajectory and `work.rs` the work counts ([`WorkCounts`]).

mod audit;
mod complementarity;
mod contact_event;
mod error;
mod events;
pub mod impact;
pub mod interrupt;
mod phase;
mod reindex;
pub(crate) mod report;
mod run;
pub(crate) mod section;
mod tally;
pub(crate) mod tape;
mod trajectory;
mod walker;
mod work;
mod zeno;

pub use error::WalkError;
pub(crate) use events::EventKind;
pub use impact::{Branch, DlsIndicators};
pub use interrupt::{clear_interrupt, interrupt_flag, interrupted};
pub(crate) use phase::{pack, unpack, StageLog};
pub use phase::{PhaseSystem, WalkState, WalkVector};
pub use report::{
    ContactAudit, EnergyAudit, FrictionAudit, StepReport, CONE_VIOLATION_WARNING,
    ENERGY_RESIDUAL_WARNING, PENETRATION_WARNING, PULL_FORCE_WARNING, PULL_IMPULSE_WARNING,
    SLIP_POWER_WARNING, STOPPER_OVERRUN_WARNING,
};
pub use run::{simulate, simulate_streaming, WalkEnd, WalkRun};
pub use section::{ParseSectionError, SectionState, MAX_SECTION_SPEED, SECTION_COORDINATES};
pub use trajectory::{Sample, SampleSink, Trajectory};
pub use walker::{Walker, INTERRUPT_CHECK_STEPS};
pub use work::{EventCounts, WorkCounts};
pub use zeno::ZENO_IMPULSE_WARNING;
