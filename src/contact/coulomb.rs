//! Coulomb slip in the constrained dynamics (docs/model.md section 12): the KKT system and the impulse problem
//! when a ground contact slips with a finite friction coefficient `mu`.
//!
//! A slipping contact keeps its normal row `J_n q'' = -(dJ_n/dt) q'` (the tip stays on the ground) and its
//! tangential force is not a free multiplier but `lambda_t = -s mu lambda_n` (`s = +-1` the direction of the
//! slip), so the generalized force of the contact is `(J_n - s mu J_t)^T lambda_n`. The force columns `B` then
//! differ from the constraint rows `A` in the slipping rows, and
//!
//! ```text
//! [ M   -B^T ] [ q'' ]   [ -h          ]        (A M^-1 B^T) lambda = b - A M^-1 f,
//! [ A    0   ] [ lam ] = [ -(dA/dt) q' ]   i.e. q'' = M^-1 (f + B^T lambda)
//! ```
//!
//! with a Schur complement `A M^-1 B^T` that is no longer symmetric. It is solved by Gaussian elimination with
//! the sticking rows (contacts, stoppers: a symmetric positive definite block) first and the slipping normal
//! rows last, so that each slipping row's pivot is its effective normal inverse mass `w` given the other
//! units. `w <= 0` is the Painleve case: with the slip held, a pushing normal force would accelerate the tip
//! into the ground (or a pulling one away from it), so that the force-level problem has no solution or two
//! ([`ContactError::Painleve`]). The impulse problem `M (q'+ - q'-) = B^T Lambda`, `A q'+ = 0` has the same
//! structure (a Coulomb impulse `Lambda_t = -s mu Lambda_n`).
//!
//! Hand-written elimination (at most six rows) rather than nalgebra's LU: the order of the pivots is what
//! tells the Painleve case from a redundant set, and a pivoting LU would reorder them.

use nalgebra::SMatrix;

use super::solve::{complete_held_leg_one, constraint_rows, held_leg_one_system, Rows};
use super::{
    ActiveSet, ConstrainedDynamics, ContactError, ImpulseSolution, Multipliers, Role, NROWS,
    REDUNDANCY_TOL,
};
use crate::dynamics::{Coords, EquationsOfMotion, Model, L1, L2, NQ};

/// Accelerations and multipliers of Eq. (1) with the units of `active`, some of whose contacts slip with
/// Coulomb friction (`active.slip1`, `active.slip2`); the tangential multiplier of a slipping contact is its
/// friction force `-s mu lambda_n`.
pub(crate) fn slipping_dynamics(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: &ActiveSet,
) -> Result<ConstrainedDynamics, ContactError> {
    slipping_dynamics_with(model, q, qd, active, false)
}

/// [`slipping_dynamics`] solved through the Painleve case (`through_painleve`): a slipping row with a negative
/// pivot `w` is eliminated as any other (only a vanishing one is refused, as redundant), so that the caller can
/// see whether that slip's forces would be consistent (a second solution of the force-level problem).
pub(crate) fn slipping_dynamics_with(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: &ActiveSet,
    through_painleve: bool,
) -> Result<ConstrainedDynamics, ContactError> {
    if active.contact1 && !active.slide1 && active.slip2 != 0 {
        // The common slip (the rear tip after a touchdown), reduced as the no-slip solve is.
        let eom = model.equations_of_motion(q, qd);
        return if eom.swing {
            rear_slip::<{ NQ - 2 }>(model, &eom, active, through_painleve)
        } else {
            rear_slip::<{ NQ - 3 }>(model, &eom, active, through_painleve)
        };
    }
    let (m, h) = model.mass_and_bias(q, qd);
    let (rows, jdq) = constraint_rows(model, q, qd, active);
    let columns = force_columns(model, q, qd, active, &rows);
    let system = (&rows, &columns, active);
    let (qdd, multipliers) = solve(&m, system, &(-h), &(-jdq), through_painleve)?;
    Ok(ConstrainedDynamics {
        qdd,
        multipliers: with_friction(model, active, multipliers),
    })
}

/// The KKT system with Leg 1's tip held and Leg 2's tip slipping, reduced to the `R` coordinates
/// `(theta, L1, L2[, L3])` as the no-slip solve does (`x'' = z'' = 0`; `lambda_1`, `lambda_2` from the `x`, `z`
/// equations): `M_rr = L D L^T`, and with `W_i = L^-1 a_i` (rows), `V_i = L^-1 b_i` (force columns), the
/// Schur complement `S_ij = W_i . D^-1 V_j`, eliminated with the slipping row last by [`eliminate`]. Same
/// result as the general solve (tested).
fn rear_slip<const R: usize>(
    model: &Model,
    eom: &EquationsOfMotion,
    active: &ActiveSet,
    through_painleve: bool,
) -> Result<ConstrainedDynamics, ContactError> {
    let rear = &eom.rear_tip;
    let slip = f64::from(active.slip2) * model.params().friction;
    let (mut chol, mut g) = held_leg_one_system::<R>(eom);
    if !chol.factor() {
        return Err(ContactError::SingularMass);
    }
    chol.forward(&mut g);
    // The rows (stoppers first, the slipping normal row last), their force columns, right-hand sides and
    // places in the stacking, each row and column as L^-1 of itself.
    let mut rows: Vec<([f64; R], [f64; R], f64, usize)> = Vec::with_capacity(3);
    for (held, coordinate, stacked) in [
        (active.length_held(Role::Fore), L1, 4),
        (active.length_held(Role::Rear), L2, 5),
    ] {
        if held {
            let mut unit = [0.0; R];
            unit[coordinate - 2] = 1.0;
            chol.forward(&mut unit);
            rows.push((unit, unit, 0.0, stacked));
        }
    }
    let mut normal: [f64; R] = std::array::from_fn(|k| rear.jacobian[(1, 2 + k)]);
    let mut column: [f64; R] =
        std::array::from_fn(|k| normal[k] - slip * rear.jacobian[(0, 2 + k)]);
    chol.forward(&mut normal);
    chol.forward(&mut column);
    rows.push((normal, column, -rear.velocity_product.y, 3));
    // The Schur complement in the stacking, the inactive rows (the slipping tip's tangential one at least)
    // identity rows, eliminated in the order of `rows`.
    let dot = |u: &[f64; R], v: &[f64; R]| (0..R).map(|l| u[l] * v[l] * chol.d_inv[l]).sum::<f64>();
    let mut schur = SMatrix::<f64, NROWS, NROWS>::identity();
    let mut rhs = Multipliers::zeros();
    for (a_i, _, b_i, i) in &rows {
        rhs[*i] = b_i - dot(a_i, &g);
        for (_, v_j, _, j) in &rows {
            schur[(*i, *j)] = dot(a_i, v_j);
        }
    }
    let order: Vec<usize> = rows.iter().map(|row| row.3).collect();
    let mut multipliers = eliminate(schur, rhs, &order, &|i| i == 3, active, through_painleve)?;
    let mut x = g;
    for (_, column, _, stacked) in &rows {
        for (x_l, column_l) in x.iter_mut().zip(column) {
            *x_l += multipliers[*stacked] * column_l;
        }
    }
    chol.backward_scaled(&mut x);
    multipliers[2] = -slip * multipliers[3];
    Ok(complete_held_leg_one(eom, &x, multipliers))
}

/// The collision equation (5) with the units of `active`, some of whose contacts slip through the impact with
/// a Coulomb impulse `Lambda_t = -s mu Lambda_n` (reported in the tangential row).
pub(crate) fn slipping_impulse(
    model: &Model,
    q: &Coords,
    qd_minus: &Coords,
    active: &ActiveSet,
) -> Result<ImpulseSolution, ContactError> {
    let m = model.mass_matrix(q);
    let (rows, _) = constraint_rows(model, q, qd_minus, active);
    let columns = force_columns(model, q, qd_minus, active, &rows);
    let rhs = -(rows * qd_minus);
    let system = (&rows, &columns, active);
    let (dqd, impulses) = solve(&m, system, &Coords::zeros(), &rhs, false)?;
    Ok(ImpulseSolution {
        qd_plus: qd_minus + dqd,
        impulses: with_friction(model, active, impulses),
    })
}

/// The force columns `B` (as rows): the constraint rows, except that a slipping contact's normal row carries
/// its friction, `J_n - s mu J_t`.
pub(crate) fn force_columns(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: &ActiveSet,
    rows: &Rows,
) -> Rows {
    let mu = model.params().friction;
    let mut columns = *rows;
    for leg in Role::BOTH {
        let s = active.slip(leg);
        if s != 0 && active.contact(leg) {
            let tip = model.tip(q, qd, leg.index());
            let n = leg.normal_row();
            for k in 0..NQ {
                columns[(n, k)] -= f64::from(s) * mu * tip.jacobian[(0, k)];
            }
        }
    }
    columns
}

/// The friction force (impulse) `-s mu lambda_n` of each slipping contact in its tangential row.
fn with_friction(model: &Model, active: &ActiveSet, mut lam: Multipliers) -> Multipliers {
    let mu = model.params().friction;
    for leg in Role::BOTH {
        let s = active.slip(leg);
        if s != 0 && active.contact(leg) {
            let n = leg.normal_row();
            lam[n - 1] = -f64::from(s) * mu * lam[n];
        }
    }
    lam
}

/// Solve `M x = f + B^T lam`, `A x = b` on the active rows of `active` (`system = (A, B, active)`, see the
/// module documentation); through the Painleve case where `through_painleve` ([`eliminate`]).
///
/// `M^-1 B^T` is solved for the active rows' columns only (one Cholesky factor, one solve per active row
/// rather than a 6 x 6 solve with six right-hand sides), and the elimination runs over the active rows: an
/// inactive row is an identity row of the Schur complement with a zero right-hand side, whose multiplier is 0.
fn solve(
    m: &SMatrix<f64, NQ, NQ>,
    (rows, columns, active): (&Rows, &Rows, &ActiveSet),
    f: &Coords,
    b: &Multipliers,
    through_painleve: bool,
) -> Result<(Coords, Multipliers), ContactError> {
    let chol = m.cholesky().ok_or(ContactError::SingularMass)?;
    let x_free = chol.solve(f);
    let mask = active.row_mask();
    let mut minv_bt = SMatrix::<f64, NQ, NROWS>::zeros();
    for i in (0..NROWS).filter(|&i| mask[i]) {
        minv_bt.set_column(i, &chol.solve(&columns.row(i).transpose()));
    }
    let mut schur = SMatrix::<f64, NROWS, NROWS>::identity();
    let mut rhs = Multipliers::zeros();
    for i in (0..NROWS).filter(|&i| mask[i]) {
        rhs[i] = b[i] - rows.row(i).dot(&x_free.transpose());
        for j in (0..NROWS).filter(|&j| mask[j]) {
            schur[(i, j)] = rows.row(i).dot(&minv_bt.column(j).transpose());
        }
    }
    let slipping = |i: usize| {
        Role::BOTH
            .into_iter()
            .any(|leg| active.slip(leg) != 0 && active.contact(leg) && leg.normal_row() == i)
    };
    // The active rows, sticking ones first, the slipping normal rows last.
    let mut order = [0; NROWS];
    let sticking = (0..NROWS).filter(|&i| mask[i] && !slipping(i));
    let count = sticking
        .chain((0..NROWS).filter(|&i| mask[i] && slipping(i)))
        .zip(order.iter_mut())
        .map(|(i, place)| *place = i)
        .count();
    let lam = eliminate(
        schur,
        rhs,
        &order[..count],
        &slipping,
        active,
        through_painleve,
    )?;
    Ok((x_free + minv_bt * lam, lam))
}

/// Gaussian elimination of `S lam = rhs` with the pivots taken in `order`; a slipping row (`slipping`) whose
/// pivot is not positive is the Painleve case (eliminated all the same where `through_painleve`, unless it
/// vanishes), a tiny pivot a redundant set.
fn eliminate(
    mut s: SMatrix<f64, NROWS, NROWS>,
    mut rhs: Multipliers,
    order: &[usize],
    slipping: &dyn Fn(usize) -> bool,
    active: &ActiveSet,
    through_painleve: bool,
) -> Result<Multipliers, ContactError> {
    let scale = s.diagonal().abs().max();
    for (k, &p) in order.iter().enumerate() {
        let pivot = s[(p, p)];
        let painleve = slipping(p) && pivot <= 0.0;
        if painleve && !(through_painleve && pivot.abs() >= REDUNDANCY_TOL * scale) {
            return Err(ContactError::Painleve(*active));
        }
        if pivot.abs() < REDUNDANCY_TOL * scale || pivot.is_nan() {
            return Err(ContactError::RedundantConstraints(*active));
        }
        for &r in &order[k + 1..] {
            let factor = s[(r, p)] / pivot;
            if factor != 0.0 {
                for &c in &order[k..] {
                    s[(r, c)] -= factor * s[(p, c)];
                }
                rhs[r] -= factor * rhs[p];
            }
        }
    }
    let mut lam = Multipliers::zeros();
    for (k, &p) in order.iter().enumerate().rev() {
        let mut sum = rhs[p];
        for &c in &order[k + 1..] {
            sum -= s[(p, c)] * lam[c];
        }
        lam[p] = sum / s[(p, p)];
    }
    Ok(lam)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{constrained_dynamics, impulse};
    use crate::dynamics::{THETA, X, Z};
    use crate::params::Params;
    use approx::assert_relative_eq;

    fn model(friction: f64) -> Model {
        Model::new(&Params {
            friction,
            ..Params::default()
        })
        .unwrap()
    }

    /// A double-support state with Leg 2's tip moving along the ground.
    fn state(model: &Model) -> (Coords, Coords) {
        let (l1, l2) = (0.9, 0.85);
        let alpha = model.alpha();
        let theta = ((l2 * alpha.cos() - l1) / (l2 * alpha.sin())).atan();
        let q = Coords::new(0.0, 0.0, theta, l1, l2, 0.0);
        (q, Coords::new(0.0, 0.0, 1.0, -0.2, 0.1, 0.0))
    }

    /// With slip, the equations of motion hold with the friction force in the tangential row, the slipping tip
    /// stays on the ground, and the friction force is `-s mu lambda_n`.
    #[test]
    fn slipping_dynamics_satisfy_the_equations_of_motion_with_coulomb_friction() {
        let model = model(0.4);
        let (q, qd) = state(&model);
        for s in [1, -1] {
            let mut active = ActiveSet {
                contact1: true,
                ..Default::default()
            };
            active.set_slipping(Role::Rear, s);
            let d = constrained_dynamics(&model, &q, &qd, &active).unwrap();
            let (m, h) = model.mass_and_bias(&q, &qd);
            // The full rows, the tangential one of Leg 2 included, carry the friction force.
            let stick = ActiveSet {
                contact1: true,
                contact2: true,
                ..Default::default()
            };
            let (rows, jdq) = constraint_rows(&model, &q, &qd, &stick);
            assert_relative_eq!(
                m * d.qdd + h,
                rows.transpose() * d.multipliers,
                epsilon = 1e-9
            );
            assert_relative_eq!(
                d.multipliers[2],
                -f64::from(s) * 0.4 * d.multipliers[3],
                epsilon = 1e-12
            );
            let normal = rows.row(3) * d.qdd;
            assert_relative_eq!(normal[0], -jdq[3], epsilon = 1e-9);
            assert_relative_eq!(d.qdd[X], 0.0, epsilon = 1e-12);
            assert_relative_eq!(d.qdd[Z], 0.0, epsilon = 1e-12);
            assert!(d.qdd[THETA].is_finite());
        }
    }

    /// The reduced solve of a rear slip equals the general one, with and without the stoppers held and with a
    /// swinging leg.
    #[test]
    fn the_reduced_rear_slip_equals_the_general_solve() {
        let model = model(0.7);
        let (q, qd) = state(&model);
        let swinging = (
            Coords::new(0.0, 0.0, 0.4, 0.93, 1.0, 0.96),
            Coords::new(0.0, 0.0, 1.4, 0.25, -0.6, 0.3),
        );
        let mut compared = 0;
        for (q, qd) in [(q, qd), swinging] {
            for (lock1, lock2, s) in [
                (false, false, 1),
                (true, false, -1),
                (false, true, 1),
                (true, true, -1),
            ] {
                let mut active = ActiveSet {
                    contact1: true,
                    lock1,
                    lock2,
                    ..Default::default()
                };
                active.set_slipping(Role::Rear, s);
                let (m, h) = model.mass_and_bias(&q, &qd);
                let (rows, jdq) = constraint_rows(&model, &q, &qd, &active);
                let columns = force_columns(&model, &q, &qd, &active, &rows);
                let general = solve(&m, (&rows, &columns, &active), &(-h), &(-jdq), false)
                    .map(|(qdd, lam)| (qdd, with_friction(&model, &active, lam)));
                match (slipping_dynamics(&model, &q, &qd, &active), general) {
                    (Ok(fast), Ok((qdd, lam))) => {
                        assert_relative_eq!(fast.qdd, qdd, epsilon = 1e-10, max_relative = 1e-11);
                        assert_relative_eq!(
                            fast.multipliers,
                            lam,
                            epsilon = 1e-9,
                            max_relative = 1e-11
                        );
                        compared += 1;
                    }
                    (Err(a), Err(b)) => assert_eq!(a, b),
                    (a, b) => panic!("{active:?}: {a:?} but {b:?}"),
                }
            }
        }
        assert!(compared >= 6, "{compared}");
    }

    /// With `mu = 0` a slip is the frictionless slide, in either direction.
    #[test]
    fn frictionless_slip_is_the_slide() {
        let model = model(0.0);
        let (q, qd) = state(&model);
        let mut slide = ActiveSet {
            contact1: true,
            ..Default::default()
        };
        slide.set_sliding(Role::Rear);
        let expected = constrained_dynamics(&model, &q, &qd, &slide).unwrap();
        let expected_impulse = impulse(&model, &q, &qd, &slide).unwrap();
        for s in [1, -1] {
            let mut active = slide;
            active.set_slipping(Role::Rear, s);
            let d = constrained_dynamics(&model, &q, &qd, &active).unwrap();
            assert_relative_eq!(d.qdd, expected.qdd, epsilon = 1e-10);
            assert_relative_eq!(d.multipliers, expected.multipliers, epsilon = 1e-9);
            let i = impulse(&model, &q, &qd, &active).unwrap();
            assert_relative_eq!(i.qd_plus, expected_impulse.qd_plus, epsilon = 1e-12);
        }
    }

    /// A Coulomb impulse stops the normal velocity, leaves the tangential one in the slip direction's
    /// half-line for a consistent choice, and never adds kinetic energy when it is consistent.
    #[test]
    fn coulomb_impulse_stops_the_normal_velocity_and_dissipates() {
        let model = model(0.3);
        let (q, _) = state(&model);
        // Leg 2's tip comes down and moves up the slope.
        let qd = Coords::new(0.0, 0.0, -1.2, 0.3, -0.2, 0.0);
        let mut consistent = 0;
        for s in [1, -1] {
            let mut active = ActiveSet {
                contact1: true,
                ..Default::default()
            };
            active.set_slipping(Role::Rear, s);
            let sol = impulse(&model, &q, &qd, &active).unwrap();
            let tip = model.tip(&q, &qd, Role::Rear.index());
            let v = tip.velocity(&sol.qd_plus);
            assert_relative_eq!(v.y, 0.0, epsilon = 1e-12);
            assert_relative_eq!(
                sol.impulses[2],
                -f64::from(s) * 0.3 * sol.impulses[3],
                epsilon = 1e-12
            );
            if f64::from(s) * v.x >= 0.0 && sol.impulses[3] >= 0.0 {
                consistent += 1;
                let lost = model.kinetic_energy(&q, &qd) - model.kinetic_energy(&q, &sol.qd_plus);
                assert!(lost >= -1e-12, "{lost}");
            }
        }
        assert_eq!(consistent, 1);
    }

    /// The Painleve case: a tip slipping on a rigid wheel whose effective normal inverse mass with friction,
    /// `w = J_n P (J_n - s mu J_t)^T` (`P` the inverse mass with the stoppers held), is not positive has no
    /// force solution, and is named; where `w > 0` the solve succeeds.
    #[test]
    fn a_non_positive_effective_normal_inverse_mass_is_the_painleve_case() {
        use crate::dynamics::{L1, L2, L3};
        let model = Model::new(&Params {
            rigid_legs: true,
            friction: 5.0,
            ..Params::default()
        })
        .unwrap();
        let mut seen = (0, 0);
        for i in -12..=12 {
            let q = Coords::new(0.0, 0.0, 0.1 * f64::from(i), 1.0, 1.0, 0.0);
            let qd = Coords::new(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
            let m = model.mass_matrix(&q);
            let minv = m.try_inverse().unwrap();
            let mut g = SMatrix::<f64, 3, NQ>::zeros();
            for (row, coord) in [L1, L2, L3].into_iter().enumerate() {
                g[(row, coord)] = 1.0;
            }
            let p = minv
                - minv
                    * g.transpose()
                    * (g * minv * g.transpose()).try_inverse().unwrap()
                    * g
                    * minv;
            let j = model.tip(&q, &qd, 0).jacobian;
            for s in [1i8, -1] {
                let column = j.row(1) - f64::from(s) * 5.0 * j.row(0);
                let w = (j.row(1) * p * column.transpose())[0];
                let mut active = ActiveSet {
                    lock1: true,
                    lock2: true,
                    ..Default::default()
                };
                active.set_slipping(Role::Fore, s);
                match constrained_dynamics(&model, &q, &qd, &active) {
                    Err(ContactError::Painleve(_)) => {
                        assert!(w <= 1e-12, "theta {i}: w = {w}");
                        seen.0 += 1;
                    }
                    Ok(_) => {
                        assert!(w > 0.0, "theta {i}: w = {w}");
                        seen.1 += 1;
                    }
                    Err(e) => panic!("theta {i}: {e}"),
                }
            }
        }
        assert!(seen.0 > 0 && seen.1 > 0, "{seen:?}");
    }
}
