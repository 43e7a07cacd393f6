//! The walk of a legged walker with compliant legs (docs/model.md section 13): the paper's procedure for any
//! [`Mechanism`] whose two legs take turns. A phase integrates Eq. (1) with its active constraints (each tip
//! stuck, sliding without friction or free; each telescopic leg held at its stopper or free), chosen by the
//! force-level complementarity rule of docs/model.md section 3 ([`forces`]); every impact is the impulse-level
//! complementarity problem of section 5, and a heel strike follows the DLS-indicator procedure (A1)-(A4),
//! (B1)-(B3) ([`impact`]). Events (a heel strike, a lift-off, a stopper's hit and unlock, a bounced tip's
//! landing, a fall) are located on the integrator's dense output ([`walk`]), which records the step for its
//! exact derivatives ([`derivative`]).
//!
//! Conventions: contact point 0 is the fore (stance) leg's tip and contact point 1 the rear leg's; the rear
//! leg, once its tip has left the ground, is the swing leg, and its tip reaching the ground ahead of the fore
//! tip is the heel strike that ends a step. The walker then exchanges the legs' roles ([`Legged::relabel`]).
//! The swing tip's crossings of the ground behind the fore tip (a leg of full length passing the stance leg, or
//! a free leg extending after its lift-off) are foot scuffing, ignored as the compass-gait papers do, and
//! counted.
//!
//! The wheel walks by `crate::walk` still; this walk is to become the one walk (docs/model.md section 13).

pub mod check;
pub mod derivative;
pub mod family;
pub mod forces;
pub mod gait;
pub mod impact;
pub mod walk;

use nalgebra::{DVector, SVector};

use super::constrained::{ConstrainedError, Row};
use super::Mechanism;

/// A telescopic leg's stroke: the coordinate that is its length and the stopper that holds it at most
/// `stopper` long.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stroke {
    /// Index of the leg's length in `q`.
    pub coordinate: usize,
    /// The stopper's length `L0` \[m\].
    pub stopper: f64,
}

/// What a legged walker gives the walk beyond its [`Mechanism`]: contact point 0 is the fore leg's tip, 1 the
/// rear (swing) leg's.
pub trait Legged<const N: usize>: Mechanism<N> {
    /// The fore and the rear leg's strokes (`None` for a rigid leg).
    fn strokes(&self) -> [Option<Stroke>; 2];

    /// The hip's height above the ground: the walker falls where it reaches 0.
    fn hip_height(&self, q: &SVector<f64, N>) -> f64;

    /// How fast the walker moves forward (the hip's velocity down the slope, in the walker's units): it rolls
    /// back where this reaches 0.
    fn progress(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64;

    /// The state after a heel strike with the legs' roles exchanged (the landing leg is the fore leg, the old
    /// fore leg the rear one), the origin moved to the new fore tip.
    fn relabel(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> (SVector<f64, N>, SVector<f64, N>);

    /// The names of the section's coordinates ([`Legged::section_of`]).
    fn section_names(&self) -> Vec<&'static str>;

    /// The free coordinates of a state at a heel strike, after the relabeling and before the impact (the
    /// section: the fore leg at its stopper with its tip at the origin, the rear tip at rest on the ground).
    fn section_of(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> DVector<f64>;

    /// The state on the section with the free coordinates `s`; `None` where there is none (the rear leg too
    /// short to reach the ground).
    fn state_at_section(&self, s: &DVector<f64>) -> Option<(SVector<f64, N>, SVector<f64, N>)>;
}

/// The state of a tip.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Tip {
    /// On the ground without slipping: the contact's two rows.
    Stuck,
    /// On the ground, sliding without friction: the normal row alone (the `inconsistent_contact = "slide"`
    /// rule of docs/model.md section 4).
    Sliding,
    /// In the air.
    Free,
}

/// The active constraints of a phase: each tip's state and whether each leg is held at its stopper.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Modes {
    /// The fore and rear tips.
    pub tips: [Tip; 2],
    /// The fore and rear legs held at their stoppers.
    pub held: [bool; 2],
}

impl Modes {
    /// The constraint rows, in the order: the fore tip's (tangential, normal), the rear tip's, the fore leg's
    /// stopper, the rear leg's.
    pub fn rows(&self, strokes: &[Option<Stroke>; 2]) -> Vec<Row> {
        let mut rows = Vec::with_capacity(6);
        for (i, tip) in self.tips.iter().enumerate() {
            match tip {
                Tip::Stuck => rows.extend(Row::contact(i)),
                Tip::Sliding => rows.push(Row::Normal(i)),
                Tip::Free => {}
            }
        }
        for (held, stroke) in self.held.iter().zip(strokes) {
            if let (true, Some(stroke)) = (held, stroke) {
                rows.push(Row::Held(stroke.coordinate));
            }
        }
        rows
    }
}

/// The multipliers of a solve by unit: a tip's normal force (or impulse), its tangential one, a stopper's
/// holding force (the inward force it exerts, `>= 0` while it holds). `None` for a unit not active.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct UnitForces {
    /// The tips' normal forces \[N, or N s for an impulse\].
    pub normal: [Option<f64>; 2],
    /// The tips' tangential forces (stuck tips only).
    pub tangential: [Option<f64>; 2],
    /// The stoppers' holding forces.
    pub holding: [Option<f64>; 2],
}

impl UnitForces {
    /// The multipliers `lambda` of the rows of `modes` (in [`Modes::rows`]' order) by unit.
    pub fn of(modes: &Modes, lambda: &DVector<f64>) -> UnitForces {
        let mut forces = UnitForces::default();
        let mut r = 0;
        for (i, tip) in modes.tips.iter().enumerate() {
            match tip {
                Tip::Stuck => {
                    forces.tangential[i] = Some(lambda[r]);
                    forces.normal[i] = Some(lambda[r + 1]);
                    r += 2;
                }
                Tip::Sliding => {
                    forces.normal[i] = Some(lambda[r]);
                    r += 1;
                }
                Tip::Free => {}
            }
        }
        for (i, held) in modes.held.iter().enumerate() {
            if *held && r < lambda.len() {
                // The row `dL/dt = 0` takes a generalized force along `L`; the stopper pushes inward.
                forces.holding[i] = Some(-lambda[r]);
                r += 1;
            }
        }
        forces
    }
}

/// Why a legged walker's step failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LeggedError {
    /// The integration failed.
    #[error("integration failed: {0}")]
    Integration(#[from] crate::integrate::IntegrationError),
    /// A constrained solve failed.
    #[error("{0}")]
    Constrained(#[from] ConstrainedError),
    /// No set of active constraints is consistent (every candidate pulls or penetrates).
    #[error("no consistent contact state at t = {time}")]
    Inconsistent {
        /// When.
        time: f64,
    },
    /// No heel strike within the longest step.
    #[error("no heel strike within {time} s")]
    Stalled {
        /// The time walked.
        time: f64,
    },
    /// The walker stopped vaulting over its fore leg and falls back.
    #[error("the walker rolled back (stopped over its fore leg) at t = {time} s")]
    RolledBack {
        /// When.
        time: f64,
    },
    /// The hip reached the ground.
    #[error("the walker fell (hip on the ground) at t = {time} s")]
    Fell {
        /// When.
        time: f64,
    },
    /// More events in one step than allowed.
    #[error("more than {events} events in one step (chatter) at t = {time} s")]
    Chatter {
        /// The limit.
        events: usize,
        /// When.
        time: f64,
    },
    /// The swing leg was not at its stopper at the heel strike: the state is not on the section.
    #[error("the swing leg was not locked at its stopper at the heel strike (t = {time} s): not on the section")]
    SwingLegNotLocked {
        /// When.
        time: f64,
    },
    /// The fore tip was not stuck at the heel strike: the state is not on the section.
    #[error("the stance tip was {state:?} at the heel strike (t = {time} s): not on the section")]
    StanceNotStuck {
        /// Its state.
        state: Tip,
        /// When.
        time: f64,
    },
    /// The section state has no walker state.
    #[error("the section state has no walker state (the hip at or below the ground, or the rear leg too short to reach it)")]
    OffSection,
    /// The caller asked the walk to stop.
    #[error("interrupted")]
    Interrupted,
}

impl LeggedError {
    /// Short machine-readable name.
    pub fn kind(&self) -> &'static str {
        match self {
            LeggedError::Integration(_) => "integration_failed",
            LeggedError::Constrained(_) => "constrained_solve_failed",
            LeggedError::Inconsistent { .. } => "inconsistent_contact",
            LeggedError::Stalled { .. } => "stalled",
            LeggedError::Fell { .. } => "fell",
            LeggedError::RolledBack { .. } => "rolled_back",
            LeggedError::Chatter { .. } => "chatter",
            LeggedError::SwingLegNotLocked { .. } => "swing_leg_not_locked",
            LeggedError::StanceNotStuck { .. } => "stance_not_stuck",
            LeggedError::OffSection => "off_section",
            LeggedError::Interrupted => "interrupted",
        }
    }
}

#[cfg(test)]
mod tests;
