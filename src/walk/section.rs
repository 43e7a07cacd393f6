//! The Poincare section of docs/model.md section 6: just before touchdown, after re-indexing.
//!
//! There `x = z = 0` (the new Leg 1's tip is the origin), `L1 = L0` (the touchdown length), `dL1/dt = 0`, and Leg 2's tip is on the
//! ground and at rest, so the state reduces to `s = (L2, dtheta/dt, dL2/dt)`: `theta` follows from Leg 2's tip
//! touching the ground and `(dx, dz)` from Leg 2's tip being at rest.
//!
//! With Coulomb friction (a finite `friction`) Leg 2's tip may still slip along the ground at the touchdown: the
//! section then has a fourth coordinate, the tip's slip velocity `v_s` (its velocity along the slope, `+x` down
//! it), and `(dx, dz)` give the tip the velocity `(v_s, 0)` (docs/model.md section 12). A tip at rest has
//! `v_s = 0`, the three-coordinate section.

use serde::Serialize;

use super::WalkError;
use crate::contact::{ActiveSet, Role};
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

/// The largest speed a section state may start with, in units of `sqrt(g L0)` (the speed of a fall from half a
/// leg length): hub speeds `thetadot L0` and leg rates `|L2dot|` beyond it are refused (`--initial 0.72,1,1e5`
/// ran 72 s before it failed).
pub const MAX_SECTION_SPEED: f64 = 100.0;

/// A point `s = (L2, dtheta/dt, dL2/dt)` on the Poincare section; with Coulomb friction, `(L2, dtheta/dt, dL2/dt,
/// v_s)` where Leg 2's tip slips at the touchdown.
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
    /// Slip velocity of Leg 2's tip along the slope (`+x`, down it) \[m/s\]: 0 where the tip is at rest (always
    /// without friction); nonzero only with Coulomb friction, where the tip slips at the touchdown. Left out of
    /// the JSON where 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub slip: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// The names of the section's coordinates, in the order of [`SectionState::coordinate`].
pub const SECTION_COORDINATES: [&str; 4] = ["L2", "thetadot", "L2dot", "slip"];

impl SectionState {
    /// The section state `(L2, dtheta/dt, dL2/dt)` of a tip at rest (`slip = 0`).
    pub const fn at_rest(l2: f64, theta_dot: f64, l2_dot: f64) -> SectionState {
        SectionState {
            l2,
            theta_dot,
            l2_dot,
            slip: 0.0,
        }
    }

    /// The `i`-th coordinate of [`SECTION_COORDINATES`] (`L2`, `thetadot`, `L2dot`, `slip`).
    pub fn coordinate(&self, i: usize) -> f64 {
        [self.l2, self.theta_dot, self.l2_dot, self.slip][i]
    }

    /// This state with its `i`-th coordinate of [`SECTION_COORDINATES`] set to `value`.
    pub fn with_coordinate(&self, i: usize, value: f64) -> SectionState {
        let mut s = *self;
        *[&mut s.l2, &mut s.theta_dot, &mut s.l2_dot, &mut s.slip][i] = value;
        s
    }

    /// The state as the command line prints it, `(L2, thetadot, L2dot) = (0.72, 1, 0)`, with `slip` where the
    /// tip slips; with `precision` digits after the point, or the shortest form that reads back exactly.
    pub fn labelled(&self, precision: Option<usize>) -> String {
        let values = self.values();
        let shown: Vec<String> = values
            .iter()
            .map(|v| match precision {
                Some(p) => format!("{v:.p$}"),
                None => format!("{v}"),
            })
            .collect();
        format!(
            "({}) = ({})",
            SECTION_COORDINATES[..values.len()].join(", "),
            shown.join(", ")
        )
    }

    /// The coordinates `[L2, dtheta/dt, dL2/dt]`, with `slip` after them where the tip slips: what the command
    /// line prints and Python hands back ([`SectionState::from_values`] reads them).
    pub fn values(&self) -> Vec<f64> {
        let n = if self.slips() { 4 } else { 3 };
        (0..n).map(|i| self.coordinate(i)).collect()
    }

    /// The state of three values `[L2, dtheta/dt, dL2/dt]` (the tip at rest) or four (`slip` last), `None` for
    /// any other number of values.
    pub fn from_values(values: &[f64]) -> Option<SectionState> {
        (3..=4).contains(&values.len()).then(|| {
            values
                .iter()
                .enumerate()
                .fold(SectionState::at_rest(0.0, 0.0, 0.0), |s, (i, &v)| {
                    s.with_coordinate(i, v)
                })
        })
    }

    /// Does Leg 2's tip slip at this touchdown (`slip != 0`, only with Coulomb friction)?
    pub fn slips(&self) -> bool {
        self.slip != 0.0
    }

    /// The three coordinates `[L2, dtheta/dt, dL2/dt]` (without `slip`).
    pub fn to_array(&self) -> [f64; 3] {
        [self.l2, self.theta_dot, self.l2_dot]
    }

    /// The section state of a tip at rest from a vector `[L2, dtheta/dt, dL2/dt]`.
    pub fn from_array(s: [f64; 3]) -> SectionState {
        SectionState::at_rest(s[0], s[1], s[2])
    }

    /// Largest coordinate difference between two section states, `max(|dL2|, |dthetadot|, |dL2dot|, |dslip|)`:
    /// the distance every gait comparison uses (same gait, settled walk, period of the returns).
    pub fn distance(&self, other: &SectionState) -> f64 {
        (self.l2 - other.l2)
            .abs()
            .max((self.theta_dot - other.theta_dot).abs())
            .max((self.l2_dot - other.l2_dot).abs())
            .max((self.slip - other.slip).abs())
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
            ("slip", self.slip),
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
        let speed_limit = MAX_SECTION_SPEED * (model.params().gravity.abs() * l0).sqrt();
        if self.theta_dot * l0 > speed_limit {
            return bad(
                "thetadot",
                self.theta_dot,
                "must be at most 100 sqrt(g L0) / L0 (a hub speed of 100 sqrt(g L0), ~280 m/s with the paper's \
                 legs: no walk starts faster, and the impacts of such a start take minutes to integrate)",
            );
        }
        if self.l2_dot.abs() > speed_limit {
            return bad(
                "L2dot",
                self.l2_dot,
                "must be at most 100 sqrt(g L0) in size (~280 m/s with the paper's legs: no walk starts \
                 faster, and the impacts of such a start take minutes to integrate)",
            );
        }
        if self.theta_dot <= 0.0 {
            return bad(
                "thetadot",
                self.theta_dot,
                "must be positive (the wheel rolls forward)",
            );
        }
        if self.slips() && !model.params().has_friction() {
            return bad(
                "slip",
                self.slip,
                "must be 0 without Coulomb friction (a finite `friction`): the tip is held at rest",
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
        section_coords(
            model,
            model.mechanics(),
            (s.l2, s.theta_dot, s.l2_dot),
            s.slips().then_some(s.slip),
        )
    }

    /// The section state of generalized coordinates at the section, Leg 2's tip at rest (`slip = 0`).
    pub fn from_coords(q: &Coords, qd: &Coords) -> SectionState {
        SectionState::at_rest(q[L2], qd[THETA], qd[L2])
    }

    /// The section state of a walk's state at the section, whose active set is `active`: `slip` is the
    /// velocity of Leg 2's tip along the slope where that contact slips with Coulomb friction, else 0.
    pub(crate) fn at_touchdown(
        model: &Model,
        q: &Coords,
        qd: &Coords,
        active: &ActiveSet,
    ) -> SectionState {
        let slip = if active.contact2 && active.slip2 != 0 {
            model.tip(q, qd, Role::Rear.index()).velocity(qd).x
        } else {
            0.0
        };
        SectionState {
            slip,
            ..SectionState::from_coords(q, qd)
        }
    }

    /// The active set just before the touchdown at this section state: Leg 2's tip on the ground (slipping in
    /// the direction of `slip` where it slips), Leg 1 in the air and on its stopper unless it lands shorter
    /// (`touchdown_length`), Leg 2 on its stopper with rigid legs and held at its compression stop where
    /// [`SectionState::rear_held`].
    pub(crate) fn active_before(&self, model: &Model) -> ActiveSet {
        let mut active = ActiveSet {
            contact1: false,
            contact2: true,
            lock1: model.params().lands_on_stopper(),
            lock2: model.params().rigid_legs,
            compression2: self.rear_held(model),
            ..Default::default()
        };
        if self.slips() {
            active.set_slipping(Role::Rear, if self.slip > 0.0 { 1 } else { -1 });
        }
        active
    }
}

/// The state `(q_dagger, q'_dagger)` at the section state `(L2, dtheta/dt, dL2/dt)` over any [`Real`] (the
/// section's own constraint, docs/model.md section 6): `x = z = 0`, `L1 = L0` (the touchdown length), `dL1/dt = 0`; `theta` puts Leg 2's
/// tip on the ground, `L0 cos(theta) = L2 cos(theta + alpha)`, i.e. `tan(theta) = (L2 cos(alpha) - L0) / (L2
/// sin(alpha))`; `(dx, dz)` hold Leg 2's tip at rest (`J_C2 q' = 0`, whose `x`, `z` columns are the identity).
/// With `rigid_legs`, `L2 = L0` and `dL2/dt = 0` exactly. A slipping tip (`slip`, Coulomb friction) moves at
/// `(slip, 0)` instead (`slip` given): `dx` is `slip` more.
pub(crate) fn section_coords<T: Real>(
    model: &Model,
    mech: &Mechanics<T>,
    (l2, theta_dot, l2_dot): (T, T, T),
    slip: Option<T>,
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
        .tip_with(mech, &q, &qd, Role::Rear.index())
        .velocity(&qd);
    // (`-v.x` itself without slip: the same bits as before the slip coordinate, signed zeros included.)
    qd[X] = match slip {
        None => -v.x,
        Some(slip) => slip - v.x,
    };
    qd[Z] = -v.y;
    (q, qd)
}

/// A section state written as `L2,thetadot,L2dot` (or `L2,thetadot,L2dot,slip`) could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "invalid initial state {:?}: {} (expected three numbers L2,thetadot,L2dot, e.g. 0.72,1.0,0.0, or four \
     with the stance tip's slip velocity, L2,thetadot,L2dot,slip)",
    crate::fmt::clip(.text),
    crate::fmt::clip(.reason)
)]
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
        if !(3..=4).contains(&parts.len()) {
            return Err(err(format!("{} values given", parts.len())));
        }
        let values = parts
            .iter()
            .zip(SECTION_COORDINATES)
            .map(|(part, name)| {
                part.parse::<f64>()
                    .map_err(|_| err(format!("{name} = {part:?} is not a number")))
            })
            .collect::<Result<Vec<f64>, _>>()?;
        SectionState::from_values(&values)
            .ok_or_else(|| err(format!("{} values given", values.len())))
    }
}
