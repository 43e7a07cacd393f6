//! Exact derivatives of the step map (docs/model.md section 10): `DP = dP/ds` and `dP/dp` for one chosen
//! parameter, from the variational equations of every phase (the KKT solve differentiated with its active set
//! fixed) composed with the saltation matrix of every event, replayed over the step the walk took.
//!
//! The walker records its step (`walk/tape.rs`: the impulse sets of its impacts, the active
//! set and accepted integrator steps of each phase, the event that ended it); `replay` integrates the
//! augmented system `[y, S]` over the same steps and crosses each event with its time's sensitivity. The
//! derivatives of the equations of motion, the KKT solution, the guards, the collisions, the re-indexing and
//! the section's own constraint come from forward-mode automatic differentiation (dual numbers,
//! `dual.rs`,
//! through the same generic code the walk runs, [`crate::dynamics::Real`]). Where the map has no derivative (a
//! grazing event, two events at one instant) the replay says so ([`NotDifferentiable`]) instead of returning
//! a number.
//!
//! `dual.rs` holds the dual numbers, `kkt.rs` the derivatives of the constrained dynamics and of the
//! collision, `replay.rs` the variational equations and the events.

mod dual;
mod kkt;
mod replay;

pub(crate) use dual::{dual as dual_of, seeded, Dual};
pub(crate) use replay::{augmented, replay_step, sensitivity, slip_derivative, Sensitivity, NC};
pub use replay::{COINCIDENT_EVENTS, GRAZING_RATE};

/// A DLS indicator closer to zero than this (\[N s\] for `lambda_I4`, \[N\] for `lambda_2+`, `lambda_4+`) puts
/// the touchdown on the border between two branches of the impact procedure (the complementarity tolerance of
/// the impact's own decisions).
pub const BORDER_TOL: f64 = 1e-9;

/// Why a step has no derivative (or the replay could not give it).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NotDifferentiable {
    /// An event met the flow tangentially (its rate along the flow vanishes against its derivatives, see
    /// [`GRAZING_RATE`]): the step map is not differentiable there.
    #[error("grazing {event} event at t = {time} s: the step map is not differentiable there")]
    Grazing {
        /// Time of the event \[s\].
        time: f64,
        /// Which event.
        event: String,
    },
    /// Two events within [`COINCIDENT_EVENTS`] of each other (e.g. a lift-off at a stopper lock): the step map
    /// has a corner there.
    #[error("two events at t = {time} s: the step map has a corner there and no derivative")]
    CoincidentEvents {
        /// Time of the second event \[s\].
        time: f64,
    },
    /// The touchdown impact's branch is decided by a DLS indicator within [`BORDER_TOL`] of zero: the state is on
    /// the border between two smooth pieces of the step map (a border collision), where it has only one-sided
    /// derivatives.
    #[error("{indicator} = {value:e} at the touchdown at t = {time} s: on the border between two impact branches, the step map is not differentiable there")]
    Border {
        /// Time of the touchdown \[s\].
        time: f64,
        /// The indicator (`lambda_I4`, `lambda_2_plus`, `lambda_4_plus`).
        indicator: &'static str,
        /// Its value.
        value: f64,
    },
    /// The stance tip is at rest at a section state of a map whose section slips (Coulomb friction): the state
    /// is on the border between the sections of a sticking and a slipping tip, where the map has only one-sided
    /// derivatives in the slip.
    #[error("the stance tip is at rest on a map whose section slips: on the border between sticking and slipping, the step map has only one-sided derivatives there")]
    SectionAtRest,
    /// With Coulomb friction, an impulse of an impact is on the border between sticking and slipping (a
    /// sticking impulse on the edge of its cone, or a slipping tip at rest after it) within [`BORDER_TOL`]:
    /// the step map is not differentiable there.
    #[error("{what} = {value:e} at the impact at t = {time} s: on the border between a sticking and a slipping impulse, the step map is not differentiable there")]
    ImpulseBorder {
        /// Time of the impact \[s\].
        time: f64,
        /// `cone_distance` (of a sticking impulse from the edge of its cone \[N s\]) or `slip_after` (a slipping
        /// tip's velocity after the impact \[m/s\]).
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// A KKT or collision solve in the replay was singular.
    #[error("singular constraint solve at t = {time} s in the derivative replay")]
    Singular {
        /// Time \[s\].
        time: f64,
    },
    /// The replay's state left the walk's (an internal error: it takes the walk's steps bit for bit).
    #[error("the derivative replay diverged from the walk at t = {time} s")]
    Diverged {
        /// Time \[s\].
        time: f64,
    },
    /// The recorded step is incomplete (it did not reach its touchdown).
    #[error("the step was not recorded to its touchdown")]
    Incomplete,
    /// A leg swings in the step (`rear_exit = "continue"`): the step does not start on the Poincare section,
    /// and the saltation of the swinging leg's lock is not built.
    #[error("a leg swings in the step at t = {time} s: its exact derivative is not built")]
    Swinging {
        /// Time \[s\].
        time: f64,
    },
}

#[cfg(test)]
mod tests;
