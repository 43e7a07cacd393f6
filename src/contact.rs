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

use nalgebra::{SMatrix, SVector};
use serde::Serialize;

use crate::dynamics::{Coords, Model, L1, L2, NQ};

/// Number of constraint rows in the fixed stacking order.
pub const NROWS: usize = 6;
/// Multipliers `[lambda_1, lambda_2, lambda_3, lambda_4, mu_1, mu_2]`.
pub type Multipliers = SVector<f64, NROWS>;
type Rows = SMatrix<f64, NROWS, NQ>;

/// Relative size below which a pivot of the Schur complement `J M^-1 J^T` means the active constraints are
/// redundant (linearly dependent rows).
pub const REDUNDANCY_TOL: f64 = 1e-12;

/// One of the two legs in `q`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Leg {
    /// Leg 1, the fore stance leg (`j = 0`).
    One,
    /// Leg 2, the rear leg (`j = 1`).
    Two,
}

impl Leg {
    /// Both legs, Leg 1 first.
    pub const BOTH: [Leg; 2] = [Leg::One, Leg::Two];

    /// The leg index `j` of docs/model.md section 1.
    pub fn index(self) -> usize {
        match self {
            Leg::One => 0,
            Leg::Two => 1,
        }
    }

    /// Index of this leg's length in `q`.
    pub fn length_coordinate(self) -> usize {
        match self {
            Leg::One => L1,
            Leg::Two => L2,
        }
    }

    /// Row of this leg's normal contact force in the multiplier vector.
    pub fn normal_row(self) -> usize {
        2 * self.index() + 1
    }

    /// Row of this leg's stopper in the multiplier vector.
    pub fn stopper_row(self) -> usize {
        4 + self.index()
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
}

impl ActiveSet {
    /// Is the ground contact of `leg` active?
    pub fn contact(&self, leg: Leg) -> bool {
        match leg {
            Leg::One => self.contact1,
            Leg::Two => self.contact2,
        }
    }

    /// Is the stopper of `leg` active?
    pub fn lock(&self, leg: Leg) -> bool {
        match leg {
            Leg::One => self.lock1,
            Leg::Two => self.lock2,
        }
    }

    /// Does the contact of `leg` slide (normal constraint only)?
    pub fn slide(&self, leg: Leg) -> bool {
        match leg {
            Leg::One => self.slide1,
            Leg::Two => self.slide2,
        }
    }

    /// Set the ground contact of `leg` as a no-slip contact (`on`) or open it.
    pub fn set_contact(&mut self, leg: Leg, on: bool) {
        match leg {
            Leg::One => (self.contact1, self.slide1) = (on, false),
            Leg::Two => (self.contact2, self.slide2) = (on, false),
        }
    }

    /// Make the contact of `leg` a sliding one (normal row only).
    pub fn set_sliding(&mut self, leg: Leg) {
        match leg {
            Leg::One => (self.contact1, self.slide1) = (true, true),
            Leg::Two => (self.contact2, self.slide2) = (true, true),
        }
    }

    /// Set the stopper of `leg`.
    pub fn set_lock(&mut self, leg: Leg, on: bool) {
        match leg {
            Leg::One => self.lock1 = on,
            Leg::Two => self.lock2 = on,
        }
    }

    /// Which rows of the fixed stacking are active.
    pub fn row_mask(&self) -> [bool; NROWS] {
        [
            self.contact1 && !self.slide1,
            self.contact1,
            self.contact2 && !self.slide2,
            self.contact2,
            self.lock1,
            self.lock2,
        ]
    }

    /// Double-limb support in the paper's sense: (C1) and (C2) both hold, both tips on the ground without
    /// slipping.
    pub fn double_support(&self) -> bool {
        self.contact1 && self.contact2 && !self.slide1 && !self.slide2
    }

    /// The support phase named by its contacts (docs/model.md section 4).
    pub fn phase(&self) -> Phase {
        match (self.contact1, self.contact2) {
            (true, true) => Phase::DoubleSupport,
            (true, false) => Phase::SingleSupport,
            (false, true) => Phase::RearSupport,
            (false, false) => Phase::Flight,
        }
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
}

/// The active units in words, e.g. `Leg 1 tip fixed, Leg 2 tip sliding, Leg 2 stopper locked`.
impl std::fmt::Display for ActiveSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut units = Vec::new();
        for (contact, slide, lock, leg) in [
            (self.contact1, self.slide1, self.lock1, 1),
            (self.contact2, self.slide2, self.lock2, 2),
        ] {
            match (contact, slide) {
                (true, false) => units.push(format!("Leg {leg} tip fixed")),
                (true, true) => units.push(format!("Leg {leg} tip sliding")),
                (false, _) => {}
            }
            if lock {
                units.push(format!("Leg {leg} stopper locked"));
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
    pub fn normal_force(&self, leg: Leg) -> f64 {
        self.multipliers[leg.normal_row()]
    }

    /// Stopper reaction on `leg` \[N\], positive when it pushes the leg inward (its only admissible direction).
    pub fn stopper_reaction(&self, leg: Leg) -> f64 {
        -self.multipliers[leg.stopper_row()]
    }
}

/// The largest pull among the unilateral units of `active` for multipliers (forces or impulses) in the fixed
/// stacking: a negative normal multiplier (the ground pulling a tip down) or a positive stopper multiplier (a
/// stopper pulling its leg outward), 0 if nothing pulls. Stoppers are skipped when `bilateral_stoppers` (rigid
/// legs, where they act both ways). This is the contact audit of every step (MODEL.md section 4).
pub fn largest_pull(
    multipliers: &Multipliers,
    active: &ActiveSet,
    bilateral_stoppers: bool,
) -> f64 {
    let mut pull: f64 = 0.0;
    for leg in Leg::BOTH {
        if active.contact(leg) {
            pull = pull.max(-multipliers[leg.normal_row()]);
        }
        if active.lock(leg) && !bilateral_stoppers {
            pull = pull.max(multipliers[leg.stopper_row()]);
        }
    }
    pull
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
    pub fn normal_impulse(&self, leg: Leg) -> f64 {
        self.impulses[leg.normal_row()]
    }

    /// Stopper impulse on `leg` \[N s\], positive when inward.
    pub fn stopper_impulse(&self, leg: Leg) -> f64 {
        -self.impulses[leg.stopper_row()]
    }
}

/// Rows `J` of the active constraints and `dJ/dt q'`, zero where inactive.
fn constraint_rows(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: &ActiveSet,
) -> (Rows, Multipliers) {
    let mut rows = Rows::zeros();
    let mut jdq = Multipliers::zeros();
    let hub = model.hub(q, qd);
    for leg in Leg::BOTH {
        if active.contact(leg) {
            let tip = model.leg_point_from_hub(&hub, q, qd, leg.index(), 0.0);
            let r = 2 * leg.index();
            rows.fixed_view_mut::<2, NQ>(r, 0).copy_from(&tip.jacobian);
            jdq.fixed_rows_mut::<2>(r).copy_from(&tip.velocity_product);
            if active.slide(leg) {
                rows.row_mut(r).fill(0.0);
                jdq[r] = 0.0;
            }
        }
        if active.lock(leg) {
            rows[(leg.stopper_row(), leg.length_coordinate())] = 1.0;
        }
    }
    (rows, jdq)
}

/// Solve `[M -J^T; J 0] [x; lam] = [f; b]` with the rows of `active`, through the Schur complement.
fn solve_saddle(
    m: &SMatrix<f64, NQ, NQ>,
    rows: &Rows,
    active: &ActiveSet,
    f: &Coords,
    b: &Multipliers,
) -> Result<(Coords, Multipliers), ContactError> {
    let chol = m.cholesky().ok_or(ContactError::SingularMass)?;
    let x_free = chol.solve(f);
    let minv_jt = chol.solve(&rows.transpose());
    let lam = solve_schur(
        rows * minv_jt,
        b - rows * x_free,
        &active.row_mask(),
        active,
    )?;
    Ok((x_free + minv_jt * lam, lam))
}

/// Solve `S lam = rhs` for the Schur complement `S = J M^-1 J^T` of `K` stacked rows of which `mask` says
/// which are active: inactive rows become identity rows with zero right-hand side (so their `lam` is 0).
fn solve_schur<const K: usize>(
    mut schur: SMatrix<f64, K, K>,
    mut rhs: SVector<f64, K>,
    mask: &[bool],
    active: &ActiveSet,
) -> Result<SVector<f64, K>, ContactError> {
    for (i, on) in mask.iter().enumerate() {
        if !on {
            schur[(i, i)] = 1.0;
            rhs[i] = 0.0;
        }
    }
    let scale = schur.diagonal().max();
    let redundant = ContactError::RedundantConstraints(*active);
    let chol_s = schur.cholesky().ok_or(redundant)?;
    // A rank-deficient Schur complement can still factor with a rounding-sized pivot: reject tiny pivots.
    let min_pivot = chol_s.l_dirty().diagonal().map(|d| d * d).min();
    if min_pivot < REDUNDANCY_TOL * scale {
        return Err(redundant);
    }
    Ok(chol_s.solve(&rhs))
}

/// Accelerations and multipliers of Eq. (1) with the constraints of `active` (docs/model.md section 3).
pub fn constrained_dynamics(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: &ActiveSet,
) -> Result<ConstrainedDynamics, ContactError> {
    let (m, h) = model.mass_and_bias(q, qd);
    let (rows, jdq) = constraint_rows(model, q, qd, active);
    if active.contact1 && !active.slide1 {
        return solve_with_fixed_leg_one(&m, &h, &rows, &jdq, active);
    }
    let (qdd, multipliers) = solve_saddle(&m, &rows, active, &(-h), &(-jdq))?;
    Ok(ConstrainedDynamics { qdd, multipliers })
}

/// The KKT system when Leg 1's tip is held (no-slip (C1), most of the walk): its rows are `e_x`, `e_z` with
/// `dJ/dt q' = 0`, so `x'' = z'' = 0` and the system reduces exactly to the three coordinates
/// `(theta, L1, L2)`; `lambda_1`, `lambda_2` then follow from the `x` and `z` equations. Same result as
/// [`solve_saddle`] (tested), at about half the cost.
fn solve_with_fixed_leg_one(
    m: &SMatrix<f64, NQ, NQ>,
    h: &Coords,
    rows: &Rows,
    jdq: &Multipliers,
    active: &ActiveSet,
) -> Result<ConstrainedDynamics, ContactError> {
    const R: usize = NQ - 2;
    let m_rr = m.fixed_view::<R, R>(2, 2).into_owned();
    let chol = m_rr.cholesky().ok_or(ContactError::SingularMass)?;
    let h_r = h.fixed_rows::<R>(2).into_owned();
    // Remaining rows (C2, stoppers) restricted to (theta, L1, L2); C1's rows are eliminated.
    let mut rows_r = SMatrix::<f64, 4, R>::zeros();
    let mask = active.row_mask();
    for i in 0..4 {
        if mask[i + 2] {
            rows_r.set_row(i, &rows.fixed_view::<1, R>(i + 2, 2));
        }
    }
    let x_free = chol.solve(&(-h_r));
    let minv_jt = chol.solve(&rows_r.transpose());
    let rhs = -jdq.fixed_rows::<4>(2) - rows_r * x_free;
    let lam_rest = solve_schur(rows_r * minv_jt, rhs, &mask[2..], active)?;
    let qdd_r = x_free + minv_jt * lam_rest;
    let mut qdd = Coords::zeros();
    qdd.fixed_rows_mut::<R>(2).copy_from(&qdd_r);
    let mut multipliers = Multipliers::zeros();
    multipliers.fixed_rows_mut::<4>(2).copy_from(&lam_rest);
    // x and z equations: (M q'' + h)_{x,z} = lambda_{1,2} + (other rows)^T lambda.
    let generalized = m * qdd + h - rows.transpose() * multipliers;
    multipliers[0] = generalized[0];
    multipliers[1] = generalized[1];
    Ok(ConstrainedDynamics { qdd, multipliers })
}

/// The collision equation (5): `M (q'+ - q'-) = J^T lambda_I`, `J q'+ = 0`, with the units of `active`.
pub fn impulse(
    model: &Model,
    q: &Coords,
    qd_minus: &Coords,
    active: &ActiveSet,
) -> Result<ImpulseSolution, ContactError> {
    let m = model.mass_matrix(q);
    let (rows, _) = constraint_rows(model, q, qd_minus, active);
    // Unknowns dq' = q'+ - q'-: M dq' - J^T lam = 0, J dq' = -J q'-.
    let (dqd, impulses) = solve_saddle(&m, &rows, active, &Coords::zeros(), &(-(rows * qd_minus)))?;
    Ok(ImpulseSolution {
        qd_plus: qd_minus + dqd,
        impulses,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{THETA, X, Z};
    use crate::params::Params;
    use approx::assert_relative_eq;

    const SOLVE_TOL: f64 = 1e-10;

    fn model() -> Model {
        Model::new(&Params::default()).unwrap()
    }

    /// A double-support configuration: Leg 1 tip at the origin, Leg 2 tip on the ground too.
    fn dls_state(model: &Model) -> (Coords, Coords) {
        let (l1, l2) = (0.9, 0.85);
        let alpha = model.alpha();
        // solve z_tip2 = 0 for theta: l1 cos th = l2 cos(th + alpha)
        let theta = ((l2 * alpha.cos() - l1) / (l2 * alpha.sin())).atan();
        let q = Coords::new(0.0, 0.0, theta, l1, l2);
        (q, Coords::new(0.0, 0.0, 1.0, -0.2, 0.1))
    }

    #[test]
    fn kkt_solution_satisfies_equations_of_motion_and_constraints() {
        let model = model();
        let (q, qd) = dls_state(&model);
        let active = ActiveSet {
            contact1: true,
            contact2: true,
            ..Default::default()
        };
        let sol = constrained_dynamics(&model, &q, &qd, &active).unwrap();
        let (m, h) = model.mass_and_bias(&q, &qd);
        let (rows, jdq) = constraint_rows(&model, &q, &qd, &active);
        assert_relative_eq!(
            m * sol.qdd + h,
            rows.transpose() * sol.multipliers,
            epsilon = 1e-8
        );
        assert_relative_eq!(rows * sol.qdd, -jdq, epsilon = SOLVE_TOL);
        // Leg 1 tip fixed means x'' = z'' = 0.
        assert_relative_eq!(sol.qdd[X], 0.0, epsilon = SOLVE_TOL);
        assert_relative_eq!(sol.qdd[Z], 0.0, epsilon = SOLVE_TOL);
        // the hub is supported: both normal forces push up, summing to roughly the weight
        assert!(sol.normal_force(Leg::One) > 0.0 && sol.normal_force(Leg::Two) > 0.0);
        assert!(sol.qdd[THETA].is_finite());
    }

    /// The reduced solve with Leg 1 held equals the general saddle-point solve, for every active set with C1.
    #[test]
    fn fixed_leg_one_fast_path_equals_the_general_solve() {
        let model = model();
        let (q, qd) = dls_state(&model);
        for (contact2, slide2, lock1, lock2) in [
            (false, false, false, false),
            (true, false, false, false),
            (true, true, false, false),
            (false, false, true, true),
            (true, false, true, false),
        ] {
            let active = ActiveSet {
                contact1: true,
                contact2,
                slide2,
                lock1,
                lock2,
                ..Default::default()
            };
            let fast = constrained_dynamics(&model, &q, &qd, &active).unwrap();
            let (m, h) = model.mass_and_bias(&q, &qd);
            let (rows, jdq) = constraint_rows(&model, &q, &qd, &active);
            let (qdd, lam) = solve_saddle(&m, &rows, &active, &(-h), &(-jdq)).unwrap();
            assert_relative_eq!(fast.qdd, qdd, epsilon = 1e-10, max_relative = 1e-12);
            assert_relative_eq!(fast.multipliers, lam, epsilon = 1e-9, max_relative = 1e-12);
        }
    }

    #[test]
    fn impulse_stops_constrained_points_and_never_adds_energy() {
        let model = model();
        let (q, mut qd) = dls_state(&model);
        qd[X] = 0.3;
        qd[Z] = -0.5;
        for active in [
            ActiveSet {
                contact1: true,
                ..Default::default()
            },
            ActiveSet {
                contact1: true,
                contact2: true,
                ..Default::default()
            },
            ActiveSet {
                contact1: true,
                lock1: true,
                lock2: true,
                ..Default::default()
            },
        ] {
            let sol = impulse(&model, &q, &qd, &active).unwrap();
            let (rows, _) = constraint_rows(&model, &q, &qd, &active);
            assert_relative_eq!((rows * sol.qd_plus).norm(), 0.0, epsilon = SOLVE_TOL);
            let t_minus = model.kinetic_energy(&q, &qd);
            let t_plus = model.kinetic_energy(&q, &sol.qd_plus);
            assert!(
                t_plus <= t_minus + 1e-12,
                "{active:?}: {t_plus} > {t_minus}"
            );
            // momentum is conserved in every constraint-free direction: M (q'+ - q'-) lies in range(J^T)
            let m = model.mass_matrix(&q);
            assert_relative_eq!(
                m * (sol.qd_plus - qd),
                rows.transpose() * sol.impulses,
                epsilon = 1e-10
            );
        }
    }

    #[test]
    fn redundant_constraints_are_an_error_not_a_panic() {
        let model = model();
        // Both legs at L0 and both tips on the ground: theta = -alpha/2 makes the configuration symmetric.
        let l0 = model.params().stopper_length;
        let q = Coords::new(0.0, 0.0, -model.alpha() / 2.0, l0, l0);
        let all = ActiveSet {
            contact1: true,
            contact2: true,
            lock1: true,
            lock2: true,
            ..Default::default()
        };
        let err = constrained_dynamics(&model, &q, &Coords::zeros(), &all).unwrap_err();
        assert_eq!(err, ContactError::RedundantConstraints(all));
    }
}
