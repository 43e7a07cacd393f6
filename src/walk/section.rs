//! The Poincare section of docs/model.md section 6: just before touchdown, after re-indexing.
//!
//! There `x = z = 0` (the new Leg 1's tip is the origin), `L1 = L0` (the touchdown length), `dL1/dt = 0`, and Leg 2's tip is on the
//! ground and at rest, so the state reduces to `s = (L2, dtheta/dt, dL2/dt)`: `theta` follows from Leg 2's tip
//! touching the ground and `(dx, dz)` from Leg 2's tip being at rest.

use serde::Serialize;

use super::WalkError;
use crate::contact::Leg;
use crate::dynamics::{lit, Coords, CoordsOf, Mechanics, Model, Real, L2, THETA, X, Z};

/// With `rigid_legs`, how far `L2` may be from `L0` (and `dL2/dt` from 0) at the section: the locked legs drift
/// by rounding only \[m, m/s\].
pub(crate) const RIGID_SECTION_TOL: f64 = 1e-9;

/// How far below the ground the tip of a leg other than Legs 1 and 2 may be at a section state \[m\] (the
/// penetration the contact audit tolerates): a section state deeper than that is not a state of the wheel.
pub(crate) const SECTION_GROUND_TOL: f64 = 1e-9;

/// How far above `min_length` `L2` may be, and `dL2/dt` from 0, at a section state whose Leg 2 is held at its
/// compression stop \[m, m/s\] ([`SectionState::rear_held`]): a held leg drifts by rounding only.
pub(crate) const HELD_SECTION_TOL: f64 = 1e-9;

/// A point `s = (L2, dtheta/dt, dL2/dt)` on the Poincare section.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SectionState {
    /// Length of Leg 2 (the stance leg about to become the rear leg) \[m\].
    #[serde(rename = "L2")]
    pub l2: f64,
    /// Angular velocity of the wheel \[rad/s\].
    #[serde(rename = "thetadot")]
    pub theta_dot: f64,
    /// Rate of change of the length of Leg 2 \[m/s\].
    #[serde(rename = "L2dot")]
    pub l2_dot: f64,
}

impl SectionState {
    /// The section state as a vector `[L2, dtheta/dt, dL2/dt]`.
    pub fn to_array(&self) -> [f64; 3] {
        [self.l2, self.theta_dot, self.l2_dot]
    }

    /// The section state from a vector `[L2, dtheta/dt, dL2/dt]`.
    pub fn from_array(s: [f64; 3]) -> SectionState {
        SectionState {
            l2: s[0],
            theta_dot: s[1],
            l2_dot: s[2],
        }
    }

    /// Largest coordinate difference between two section states, `max(|dL2|, |dthetadot|, |dL2dot|)`: the
    /// distance every gait comparison uses (same gait, settled walk, period of the returns).
    pub fn distance(&self, other: &SectionState) -> f64 {
        (self.l2 - other.l2)
            .abs()
            .max((self.theta_dot - other.theta_dot).abs())
            .max((self.l2_dot - other.l2_dot).abs())
    }

    /// Check that this is a state the wheel can be in at touchdown.
    pub fn validate(&self, model: &Model) -> Result<(), WalkError> {
        let l0 = model.params().stopper_length;
        let bad = |field: &'static str, value: f64, reason: &'static str| {
            Err(WalkError::InvalidSection {
                field,
                value,
                reason,
            })
        };
        for (field, value) in [
            ("L2", self.l2),
            ("thetadot", self.theta_dot),
            ("L2dot", self.l2_dot),
        ] {
            if !value.is_finite() {
                return bad(field, value, "must be a finite number");
            }
        }
        if !(self.l2 > 0.0 && self.l2 <= l0) {
            return bad("L2", self.l2, "must lie in (0, stopper_length]");
        }
        if self.l2 < model.params().min_length - HELD_SECTION_TOL {
            return bad(
                "L2",
                self.l2,
                "must be at least min_length (the compression stop)",
            );
        }
        if self.theta_dot <= 0.0 {
            return bad(
                "thetadot",
                self.theta_dot,
                "must be positive (the wheel rolls forward)",
            );
        }
        let (q, _) = self.to_coords(model);
        if (2..model.legs()).any(|j| model.tip_height(&q, j) < -SECTION_GROUND_TOL) {
            return bad(
                "L2",
                self.l2,
                "puts the tip of a leg behind Leg 2 below the ground: with Leg 1 at stopper_length, L2 must \
                 exceed about stopper_length cos(2 pi / legs)",
            );
        }
        if model.params().rigid_legs
            && ((self.l2 - l0).abs() > RIGID_SECTION_TOL || self.l2_dot.abs() > RIGID_SECTION_TOL)
        {
            return bad(
                "L2",
                self.l2,
                "rigid_legs needs L2 = stopper_length and L2dot = 0",
            );
        }
        Ok(())
    }

    /// Is Leg 2 held at its compression stop in this state (`min_length > 0`, `L2 = min_length` and
    /// `dL2/dt = 0` within 1e-9, `HELD_SECTION_TOL`)? A walk that reaches a touchdown with its stance leg held there
    /// starts the next step so; a walker started from such a state does the same, and the step map then acts on
    /// `dtheta/dt` alone (docs/model.md section 6).
    pub fn rear_held(&self, model: &Model) -> bool {
        self.rear_held_under(model.params())
    }

    /// [`SectionState::rear_held`] under the parameters `params`.
    pub fn rear_held_under(&self, params: &crate::params::Params) -> bool {
        let min = params.min_length;
        min > 0.0
            && !params.rigid_legs
            && self.l2 - min <= HELD_SECTION_TOL
            && self.l2_dot.abs() <= HELD_SECTION_TOL
    }

    /// This state with `L2 = min_length` and `dL2/dt = 0` exactly where Leg 2 is held at its compression stop
    /// ([`SectionState::rear_held`]), else unchanged.
    pub fn pinned(&self, model: &Model) -> SectionState {
        self.pinned_under(model.params())
    }

    /// [`SectionState::pinned`] under the parameters `params`.
    pub fn pinned_under(&self, params: &crate::params::Params) -> SectionState {
        if self.rear_held_under(params) {
            SectionState {
                l2: params.min_length,
                l2_dot: 0.0,
                ..*self
            }
        } else {
            *self
        }
    }

    /// Generalized coordinates and velocities `(q_dagger, q'_dagger)` of this section state (with
    /// `rigid_legs`, `L2 = L0` and `dL2/dt = 0` exactly; with Leg 2 held at its compression stop,
    /// `L2 = min_length` and `dL2/dt = 0` exactly).
    pub fn to_coords(&self, model: &Model) -> (Coords, Coords) {
        let s = self.pinned(model);
        section_coords(model, model.mechanics(), (s.l2, s.theta_dot, s.l2_dot))
    }

    /// The section state of generalized coordinates at the section.
    pub fn from_coords(q: &Coords, qd: &Coords) -> SectionState {
        SectionState {
            l2: q[L2],
            theta_dot: qd[THETA],
            l2_dot: qd[L2],
        }
    }
}

/// The state `(q_dagger, q'_dagger)` at the section state `(L2, dtheta/dt, dL2/dt)` over any [`Real`] (the
/// section's own constraint, docs/model.md section 6): `x = z = 0`, `L1 = L0` (the touchdown length), `dL1/dt = 0`; `theta` puts Leg 2's
/// tip on the ground, `L0 cos(theta) = L2 cos(theta + alpha)`, i.e. `tan(theta) = (L2 cos(alpha) - L0) / (L2
/// sin(alpha))`; `(dx, dz)` hold Leg 2's tip at rest (`J_C2 q' = 0`, whose `x`, `z` columns are the identity).
/// With `rigid_legs`, `L2 = L0` and `dL2/dt = 0` exactly.
pub(crate) fn section_coords<T: Real>(
    model: &Model,
    mech: &Mechanics<T>,
    (l2, theta_dot, l2_dot): (T, T, T),
) -> (CoordsOf<T>, CoordsOf<T>) {
    // Leg 1 has just landed, at the touchdown length (`L0` by default, and always with rigid legs).
    let l0 = mech.spoke_length;
    let (l2, l2_dot) = if model.params().rigid_legs {
        (l0, T::zero())
    } else {
        (l2, l2_dot)
    };
    let alpha = model.alpha();
    let (cos_alpha, sin_alpha) = (lit::<T>(alpha.cos()), lit::<T>(alpha.sin()));
    let theta = ((l2 * cos_alpha - l0) / (l2 * sin_alpha)).atan();
    let zero = T::zero();
    let q = CoordsOf::<T>::new(zero, zero, theta, l0, l2, zero);
    let mut qd = CoordsOf::<T>::new(zero, zero, theta_dot, zero, l2_dot, zero);
    let v = model
        .tip_with(mech, &q, &qd, Leg::Two.index())
        .velocity(&qd);
    qd[X] = -v.x;
    qd[Z] = -v.y;
    (q, qd)
}

/// A section state written as `L2,thetadot,L2dot` could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid initial state {text:?}: {reason} (expected three numbers L2,thetadot,L2dot, e.g. 0.72,1.0,0.0)")]
pub struct ParseSectionError {
    /// The text given.
    pub text: String,
    /// What is wrong with it.
    pub reason: String,
}

impl std::str::FromStr for SectionState {
    type Err = ParseSectionError;

    fn from_str(text: &str) -> Result<SectionState, ParseSectionError> {
        let err = |reason: String| ParseSectionError {
            text: text.to_string(),
            reason,
        };
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        if parts.len() != 3 {
            return Err(err(format!("{} values given", parts.len())));
        }
        let mut values = [0.0; 3];
        for (value, (part, name)) in values
            .iter_mut()
            .zip(parts.iter().zip(["L2", "thetadot", "L2dot"]))
        {
            *value = part
                .parse::<f64>()
                .map_err(|_| err(format!("{name} = {part:?} is not a number")))?;
        }
        Ok(SectionState::from_array(values))
    }
}
