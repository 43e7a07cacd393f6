//! Contacts, stoppers and the constrained dynamics (docs/model.md section 3, paper Eqs. (1)-(2), (5)-(9)).
//!
//! A *constraint unit* is either the no-slip contact of a leg tip with the ground (two rows: tangential and
//! normal) or the stopper of a leg holding it at `L0` (one row, `dL/dt = 0`). The rows are stacked in the
//! fixed order `[C1 tangential, C1 normal, C2 tangential, C2 normal, stopper 1, stopper 2]`, so the multiplier
//! vector is `[lambda_1, lambda_2, lambda_3, lambda_4, mu_1, mu_2]` as in the paper's Eq. (2); inactive rows
//! carry zero. Accelerations and multipliers come from the KKT system
//!
//! ```text
//! [ M   -J^T ] [ q'' ]   [ -h          ]
//! [ J    0   ] [ lam ] = [ -(dJ/dt) q' ]
//! ```
//!
//! solved through the Schur complement `J M^-1 J^T` (both blocks are small and symmetric positive definite).
//! The impulse problem of Eq. (5), `M (q'+ - q'-) = J^T lambda_I`, `J q'+ = 0`, has the same structure.

use nalgebra::SVector;
use serde::Serialize;

use crate::dynamics::{Coords, EquationsOfMotion, Model};
pub(crate) use crate::mechanism::Role;

mod coulomb;
mod solve;

pub(crate) use coulomb::force_columns;
pub(crate) use solve::{factor_no_slip, swing_lock_impulse, NoSlipKkt, NoSlipSystem};

/// Number of constraint rows in the fixed stacking order.
pub(crate) const NROWS: usize = 6;
/// Multipliers `[lambda_1, lambda_2, lambda_3, lambda_4, mu_1, mu_2]`.
pub(crate) type Multipliers = SVector<f64, NROWS>;

/// Relative size below which a pivot of the Schur complement `J M^-1 J^T` means the active constraints are
/// redundant (linearly dependent rows).
pub(crate) const REDUNDANCY_TOL: f64 = 1e-12;

/// The rows of a leg's units in the fixed stacking of the multipliers.
impl Role {
    /// Row of this leg's tangential contact force in the multiplier vector.
    pub fn tangential_row(self) -> usize {
        2 * self.index()
    }

    /// Row of this leg's normal contact force in the multiplier vector.
    pub fn normal_row(self) -> usize {
        2 * self.index() + 1
    }

    /// Row of this leg's stopper (or compression stop: a leg is held at one of them at a time) in the
    /// multiplier vector.
    pub(crate) fn stopper_row(self) -> usize {
        4 + self.index()
    }
}

/// One of a leg's two stroke limits: the extension stopper (`L <= L0`) or the compression stop
/// (`L >= min_length`). A leg held at either has the same constraint row `dL/dt = 0`; they differ in the
/// direction the reaction may push and in the direction that moves the leg into the limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// The stopper at `L0`: its reaction pushes the leg inward.
    Extension,
    /// The compression stop at `min_length`: its reaction pushes the leg outward.
    Compression,
}

impl Stop {
    /// Both limits, the stopper first.
    pub const BOTH: [Stop; 2] = [Stop::Extension, Stop::Compression];

    /// `+1` for the stopper, `-1` for the compression stop: `sign * dL/dt > 0` moves the leg into the limit,
    /// and `-sign * mu` (`mu` the multiplier of the row) is the reaction in its admissible direction.
    pub(crate) fn sign(self) -> f64 {
        match self {
            Stop::Extension => 1.0,
            Stop::Compression => -1.0,
        }
    }
}

/// Which constraint units are active: the contacts (C1), (C2) and the stoppers of Legs 1 and 2.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct ActiveSet {
    /// (C1): the tip of Leg 1 is fixed on the ground.
    pub contact1: bool,
    /// (C2): the tip of Leg 2 is fixed on the ground.
    pub contact2: bool,
    /// Leg 1 is held at `L0` by its stopper.
    pub lock1: bool,
    /// Leg 2 is held at `L0` by its stopper.
    pub lock2: bool,
    /// The contact of Leg 1 slides: only its normal row is active (`lambda_1 = 0`).
    pub slide1: bool,
    /// The contact of Leg 2 slides: only its normal row is active (`lambda_3 = 0`).
    pub slide2: bool,
    /// Leg 1 is held at `min_length` by its compression stop.
    #[serde(skip_serializing_if = "is_false")]
    pub compression1: bool,
    /// Leg 2 is held at `min_length` by its compression stop.
    #[serde(skip_serializing_if = "is_false")]
    pub compression2: bool,
    /// With Coulomb friction (a finite `friction`), the direction in which the sliding tip of Leg 1 slips:
    /// `+1` down the slope (`+x`), `-1` up it; the friction force `-slip1 mu lambda_2` opposes it. 0 for a
    /// frictionless slide and for a contact that does not slide.
    #[serde(skip_serializing_if = "is_zero")]
    pub slip1: i8,
    /// The same for Leg 2's tip (friction force `-slip2 mu lambda_4`).
    #[serde(skip_serializing_if = "is_zero")]
    pub slip2: i8,
}

fn is_false(b: &bool) -> bool {
    !*b
}

fn is_zero(x: &i8) -> bool {
    *x == 0
}

impl ActiveSet {
    /// Is the ground contact of `leg` active?
    pub fn contact(&self, leg: Role) -> bool {
        match leg {
            Role::Fore => self.contact1,
            Role::Rear => self.contact2,
        }
    }

    /// Is the stopper of `leg` active?
    pub fn lock(&self, leg: Role) -> bool {
        match leg {
            Role::Fore => self.lock1,
            Role::Rear => self.lock2,
        }
    }

    /// Is `leg` held at its `stop`?
    pub fn held(&self, leg: Role, stop: Stop) -> bool {
        match (stop, leg) {
            (Stop::Extension, _) => self.lock(leg),
            (Stop::Compression, Role::Fore) => self.compression1,
            (Stop::Compression, Role::Rear) => self.compression2,
        }
    }

    /// Is `leg` held at either of its stops (its length constraint row active)?
    pub(crate) fn length_held(&self, leg: Role) -> bool {
        self.held(leg, Stop::Extension) || self.held(leg, Stop::Compression)
    }

    /// Does the contact of `leg` slide (normal constraint only)?
    pub(crate) fn slide(&self, leg: Role) -> bool {
        match leg {
            Role::Fore => self.slide1,
            Role::Rear => self.slide2,
        }
    }

    /// The direction in which the tip of `leg` slips with Coulomb friction (`+1` down the slope, `-1` up), 0
    /// when it does not (a sticking or open contact, or a frictionless slide).
    pub fn slip(&self, leg: Role) -> i8 {
        match leg {
            Role::Fore => self.slip1,
            Role::Rear => self.slip2,
        }
    }

    /// Does any contact slip with Coulomb friction?
    pub(crate) fn any_slip(&self) -> bool {
        self.slip1 != 0 || self.slip2 != 0
    }

    /// Set the ground contact of `leg` as a no-slip contact (`on`) or open it.
    pub(crate) fn set_contact(&mut self, leg: Role, on: bool) {
        self.set_slide(leg, on, false, 0);
    }

    /// Make the contact of `leg` a frictionless sliding one (normal row only).
    pub(crate) fn set_sliding(&mut self, leg: Role) {
        self.set_slide(leg, true, true, 0);
    }

    /// Make the contact of `leg` slip in `direction` (`+1` or `-1`) with Coulomb friction: its normal row, and
    /// a tangential force `-direction mu lambda_n`.
    pub(crate) fn set_slipping(&mut self, leg: Role, direction: i8) {
        self.set_slide(leg, true, true, direction);
    }

    fn set_slide(&mut self, leg: Role, contact: bool, slide: bool, slip: i8) {
        match leg {
            Role::Fore => (self.contact1, self.slide1, self.slip1) = (contact, slide, slip),
            Role::Rear => (self.contact2, self.slide2, self.slip2) = (contact, slide, slip),
        }
    }

    /// Set the stopper of `leg`.
    pub(crate) fn set_lock(&mut self, leg: Role, on: bool) {
        match leg {
            Role::Fore => self.lock1 = on,
            Role::Rear => self.lock2 = on,
        }
    }

    /// Hold `leg` at its `stop` (`on`) or free it from that stop.
    pub(crate) fn set_held(&mut self, leg: Role, stop: Stop, on: bool) {
        match (stop, leg) {
            (Stop::Extension, _) => self.set_lock(leg, on),
            (Stop::Compression, Role::Fore) => self.compression1 = on,
            (Stop::Compression, Role::Rear) => self.compression2 = on,
        }
    }

    /// Which rows of the fixed stacking are active.
    pub(crate) fn row_mask(&self) -> [bool; NROWS] {
        [
            self.contact1 && !self.slide1,
            self.contact1,
            self.contact2 && !self.slide2,
            self.contact2,
            self.length_held(Role::Fore),
            self.length_held(Role::Rear),
        ]
    }

    /// Double-limb support in the paper's sense: (C1) and (C2) both hold, both tips on the ground without
    /// slipping.
    pub(crate) fn double_support(&self) -> bool {
        self.contact1 && self.contact2 && !self.slide1 && !self.slide2
    }

    /// The support phase named by its contacts (docs/model.md section 4).
    pub(crate) fn phase(&self) -> Phase {
        match (self.contact1, self.contact2) {
            (true, true) => Phase::DoubleSupport,
            (true, false) => Phase::SingleSupport,
            (false, true) => Phase::RearSupport,
            (false, false) => Phase::Flight,
        }
    }
}

#[cfg(test)]
impl ActiveSet {
    /// Every active set: the six flags in all combinations (a sliding flag without its contact is the same as no
    /// contact), for tests that check a solve on all of them.
    pub(crate) fn all() -> impl Iterator<Item = ActiveSet> {
        (0..1u32 << 6).map(|bits| {
            let on = |b: u32| bits & (1 << b) != 0;
            ActiveSet {
                contact1: on(0),
                contact2: on(1),
                lock1: on(2),
                lock2: on(3),
                slide1: on(4),
                slide2: on(5),
                // The compression stops have the stoppers' rows: the sets above cover their solves.
                compression1: false,
                compression2: false,
                slip1: 0,
                slip2: 0,
            }
        })
    }
}

/// Support phase, named by which tips are on the ground.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Phase {
    /// Both Leg 1 and Leg 2 on the ground (DLS).
    DoubleSupport,
    /// Only Leg 1 on the ground (SLS).
    SingleSupport,
    /// Only Leg 2 on the ground (Leg 1 bounced).
    RearSupport,
    /// No leg on the ground.
    Flight,
}

impl std::fmt::Display for Phase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Phase::DoubleSupport => "DLS",
            Phase::SingleSupport => "SLS",
            Phase::RearSupport => "rear support",
            Phase::Flight => "flight",
        })
    }
}

/// The constraint system could not be solved.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ContactError {
    /// `M(q)` lost positive definiteness (a degenerate configuration).
    #[error("mass matrix is not positive definite")]
    SingularMass,
    /// The active constraints are redundant (e.g. both legs on the ground and both on their stoppers).
    #[error("active constraints are redundant ({0})")]
    RedundantConstraints(ActiveSet),
    /// A slipping contact's effective normal inverse mass is not positive (the Painleve case of Coulomb
    /// friction): with the slip held, the force-level problem has no solution or several.
    #[error(
        "Painleve case: with {0}, friction makes the slipping tip's effective normal inverse mass non-positive \
         (no consistent contact force, or several)"
    )]
    Painleve(ActiveSet),
    /// A slip in the Painleve case (`w <= 0`) has consistent forces: the force-level problem has that solution
    /// besides the one preferred (`other`), or only that one, whose normal force holds the tip on the ground
    /// only because friction drives it into it. Either is the Painleve paradox (non-uniqueness, or a solution
    /// no smooth contact would reach), reported rather than picked.
    #[error(
        "Painleve case: the slip of {slip} has consistent contact forces with a non-positive effective normal inverse          mass{}",
        other.map_or(" (the only consistent mode, held on the ground by friction alone)".to_string(),
            |o| format!(", and so has {o}: the force-level problem has two solutions"))
    )]
    PainleveSlip {
        /// The consistent set with the slip in the Painleve case.
        slip: ActiveSet,
        /// The consistent set the enumeration would have preferred, if any.
        other: Option<ActiveSet>,
    },
    /// With Coulomb friction, no choice of modes (off, stick, slip either way) of an impact's units gives impulses
    /// that satisfy the contact laws (each pushes, sticks inside the cone or slips the way the tip moves after the
    /// impact): the impulse-level problem has no solution. The units the impact would have preferred.
    #[error(
        "no impulse satisfies the contact laws with Coulomb friction (no consistent mode for the impact; preferred \
         units: {0})"
    )]
    InconsistentImpact(ActiveSet),
}

/// The active units in words, e.g. `Leg 1 tip fixed, Leg 2 tip sliding, Leg 2 stopper locked`.
impl std::fmt::Display for ActiveSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut units = Vec::new();
        for (contact, slide, slip, lock, compression, leg) in [
            (
                self.contact1,
                self.slide1,
                self.slip1,
                self.lock1,
                self.compression1,
                1,
            ),
            (
                self.contact2,
                self.slide2,
                self.slip2,
                self.lock2,
                self.compression2,
                2,
            ),
        ] {
            match (contact, slide, slip.signum()) {
                (true, false, _) => units.push(format!("Leg {leg} tip fixed")),
                (true, true, 0) => units.push(format!("Leg {leg} tip sliding")),
                (true, true, 1) => units.push(format!("Leg {leg} tip slipping forward")),
                (true, true, _) => units.push(format!("Leg {leg} tip slipping backward")),
                (false, ..) => {}
            }
            if lock {
                units.push(format!("Leg {leg} stopper locked"));
            }
            if compression {
                units.push(format!("Leg {leg} compression stop locked"));
            }
        }
        if units.is_empty() {
            f.write_str("no contact, no stopper")
        } else {
            f.write_str(&units.join(", "))
        }
    }
}

/// Constrained accelerations and multipliers at one instant (the solution of the KKT system).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstrainedDynamics {
    /// `q''`.
    pub qdd: Coords,
    /// `[lambda_1, lambda_2, lambda_3, lambda_4, mu_1, mu_2]`; zero for inactive rows. `lambda_2`, `lambda_4`
    /// are the normal forces on Legs 1 and 2 (positive pushes the tip up); `mu_i` is the generalized force of
    /// stopper `i` on `L_i` (negative pushes the leg inward, as a stopper must).
    pub multipliers: Multipliers,
}

impl ConstrainedDynamics {
    /// Normal ground force on `leg` \[N\] (positive pushes up).
    pub(crate) fn normal_force(&self, leg: Role) -> f64 {
        self.multipliers[leg.normal_row()]
    }

    /// Reaction of `leg`'s `stop` \[N\], positive when it pushes the leg the way that stop may (inward for the
    /// stopper, outward for the compression stop).
    pub(crate) fn stop_reaction(&self, leg: Role, stop: Stop) -> f64 {
        -stop.sign() * self.multipliers[leg.stopper_row()]
    }
}

/// The largest pull among the unilateral units of `active` for multipliers (forces or impulses) in the fixed
/// stacking: a negative normal multiplier (the ground pulling a tip down), a positive stopper multiplier (a
/// stopper pulling its leg outward) or a negative one of a compression stop (pulling its leg inward), 0 if
/// nothing pulls. Stoppers are skipped when `bilateral_stoppers` (rigid
/// legs, where they act both ways). This is the contact audit of every step (docs/model.md section 4).
pub(crate) fn largest_pull(
    multipliers: &Multipliers,
    active: &ActiveSet,
    bilateral_stoppers: bool,
) -> f64 {
    let mut pull: f64 = 0.0;
    for leg in Role::BOTH {
        if active.contact(leg) {
            pull = pull.max(-multipliers[leg.normal_row()]);
        }
        if active.lock(leg) && !bilateral_stoppers {
            pull = pull.max(multipliers[leg.stopper_row()]);
        }
        if active.held(leg, Stop::Compression) {
            pull = pull.max(-multipliers[leg.stopper_row()]);
        }
    }
    pull
}

/// Accelerations and multipliers of Eq. (1) with the constraints of `active` (docs/model.md section 3): the KKT
/// system of the no-slip contacts and stoppers, or, when a contact slips with Coulomb friction, its
/// non-symmetric form (section 12).
///
/// Only the active rows enter the no-slip solve; when Leg 1's tip is held (most of the walk) the system is first
/// reduced to `(theta, L1, L2)`, and `L3` while a leg swings. Same result as the general saddle-point solve on
/// the full stacking (tested for every active set).
pub fn constrained_dynamics(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: &ActiveSet,
) -> Result<ConstrainedDynamics, ContactError> {
    if active.any_slip() {
        coulomb::slipping_dynamics(model, q, qd, active)
    } else {
        solve::no_slip_dynamics(model, q, qd, active)
    }
}

/// What the derivatives of the dynamics (`crate::variational`) reuse of the walk's solve at a state: its
/// equations of motion and, without slip, its factored KKT system.
#[derive(Debug)]
pub(crate) struct Solved {
    /// `M`, `h` and Leg 2's tip.
    pub(crate) eom: EquationsOfMotion,
    /// The factored system ([`NoSlipKkt`]; `None` with a slipping contact, or where it did not factor).
    pub(crate) kkt: Option<NoSlipKkt>,
}

/// [`constrained_dynamics`] with what its solve computed on the way ([`Solved`]): the same numbers.
pub(crate) fn constrained_dynamics_solved(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: &ActiveSet,
) -> (Result<ConstrainedDynamics, ContactError>, Solved) {
    let mut solved = Solved {
        eom: model.equations_of_motion(q, qd),
        kkt: None,
    };
    let dynamics = solve_into(model, (q, qd), active, &mut solved);
    (dynamics, solved)
}

/// [`constrained_dynamics`] at `(q, q')` given its equations of motion in `solved.eom`, the factored KKT system
/// written into `solved.kkt` (in place: a log of the walk's evaluations keeps them, see `crate::walk`).
pub(crate) fn solve_into(
    model: &Model,
    (q, qd): (&Coords, &Coords),
    active: &ActiveSet,
    solved: &mut Solved,
) -> Result<ConstrainedDynamics, ContactError> {
    if active.any_slip() {
        solved.kkt = None;
        return coulomb::slipping_dynamics(model, q, qd, active);
    }
    // Filled in and factored where it is kept (a log's slot), not moved there afterwards.
    let kkt = solved
        .kkt
        .insert(NoSlipKkt::unfactored(&solved.eom, active));
    let dynamics = kkt.factor_dynamics(&solved.eom, active);
    if dynamics.is_err() {
        solved.kkt = None;
    }
    dynamics
}

/// [`constrained_dynamics`] of a set with a slipping contact, solved through the Painleve case (a slipping
/// row with a negative effective normal inverse mass eliminated as any other): whether that slip's forces are
/// consistent tells a second solution of the force-level problem, or the only one, from none.
pub(crate) fn dynamics_through_painleve(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: &ActiveSet,
) -> Result<ConstrainedDynamics, ContactError> {
    coulomb::slipping_dynamics_with(model, q, qd, active, true)
}

/// The collision equation (5): `M (q'+ - q'-) = J^T lambda_I`, `J q'+ = 0`, with the units of `active` (a
/// slipping contact takes a Coulomb impulse, docs/model.md section 12).
pub fn impulse(
    model: &Model,
    q: &Coords,
    qd_minus: &Coords,
    active: &ActiveSet,
) -> Result<ImpulseSolution, ContactError> {
    if active.any_slip() {
        coulomb::slipping_impulse(model, q, qd_minus, active)
    } else {
        solve::no_slip_impulse(model, q, qd_minus, active)
    }
}

/// The signed distance of a contact force (or impulse) `(lambda_t, lambda_n)` from the edge of the friction
/// cone `|lambda_t| <= mu lambda_n` in the force plane, `(|lambda_t| - mu lambda_n) / sqrt(1 + mu^2)`: positive
/// outside the cone, negative inside (for a pushing force). In newtons whatever `mu`, so that one tolerance
/// serves a cone of any opening.
pub(crate) fn cone_distance(mu: f64, lambda_t: f64, lambda_n: f64) -> f64 {
    (lambda_t.abs() - mu * lambda_n) / (1.0 + mu * mu).sqrt()
}

/// The largest distance outside the friction cone ([`cone_distance`]) of the force of a sticking contact of
/// `active`, for multipliers (forces or impulses) in the fixed stacking; 0 if every one is inside, and always
/// without friction (`mu` infinite). The friction audit of every step (docs/model.md section 12).
pub(crate) fn cone_excess(multipliers: &Multipliers, active: &ActiveSet, mu: f64) -> f64 {
    if mu == f64::INFINITY {
        return 0.0;
    }
    let mut excess: f64 = 0.0;
    for leg in Role::BOTH {
        if active.contact(leg) && !active.slide(leg) {
            let (t, n) = (
                multipliers[leg.tangential_row()],
                multipliers[leg.normal_row()],
            );
            excess = excess.max(cone_distance(mu, t, n));
        }
    }
    excess
}

/// Result of an impulse problem (paper Eq. (5)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpulseSolution {
    /// Velocity just after the impact.
    pub qd_plus: Coords,
    /// Impulses in the fixed stacking; `lambda_I4 = impulses[3]` is DLS indicator 1.
    pub impulses: Multipliers,
}

impl ImpulseSolution {
    /// Normal impulse on `leg` \[N s\].
    pub fn normal_impulse(&self, leg: Role) -> f64 {
        self.impulses[leg.normal_row()]
    }

    /// Impulse of `leg`'s `stop` \[N s\], positive in the direction that stop may push.
    pub(crate) fn stop_impulse(&self, leg: Role, stop: Stop) -> f64 {
        -stop.sign() * self.impulses[leg.stopper_row()]
    }
}
