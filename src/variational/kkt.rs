//! The constrained dynamics and the collision equation over any [`Real`] (docs/model.md sections 3 and 5),
//! for the dual numbers that carry the derivatives: the KKT system and Eq. (5) with the active set fixed, solved
//! through the Schur complement `J M^-1 J^T` with nalgebra's Cholesky factorization.
//!
//! The walk's own solves ([`crate::contact::constrained_dynamics`], [`crate::contact::impulse`]) are faster,
//! hand-tuned `f64` code (active rows only, a reduced system when Leg 1 is held); these are the plain form of
//! the same equations, which the tests check against them at `f64`. Differentiating a linear solve with the
//! active set fixed is exactly what forward-mode differentiation of this code does: `d lam` and `d q''` solve
//! the same KKT matrix with the differentiated right-hand side.

use nalgebra::{SMatrix, SVector};

use crate::contact::{ActiveSet, NROWS};
use crate::dynamics::{CoordsOf, EquationsOfMotion, Mechanics, Model, Real, L1, L2, NQ, X, Z};

/// Constraint rows in the fixed stacking of [`crate::contact`].
type RowsOf<T> = SMatrix<T, NROWS, NQ>;
/// Multipliers `[lambda_1, lambda_2, lambda_3, lambda_4, mu_1, mu_2]`.
pub(crate) type MultipliersOf<T> = SVector<T, NROWS>;

/// The rows `J` of the active units of `active` and `-dJ/dt q'` (zero where inactive).
fn constraint_rows<T: Real>(
    eom: &EquationsOfMotion<T>,
    active: &ActiveSet,
) -> (RowsOf<T>, MultipliersOf<T>) {
    let mask = active.row_mask();
    let mut rows = RowsOf::<T>::zeros();
    let mut rhs = MultipliersOf::<T>::zeros();
    for (row, column) in [(0, X), (1, Z), (4, L1), (5, L2)] {
        if mask[row] {
            rows[(row, column)] = T::one();
        }
    }
    for axis in 0..2 {
        if mask[2 + axis] {
            rows.set_row(2 + axis, &eom.rear_tip.jacobian.row(axis));
            rhs[2 + axis] = -eom.rear_tip.velocity_product[axis];
        }
    }
    (rows, rhs)
}

/// Solve `[M -J^T; J 0] [x; lam] = [f; b]`, the inactive rows of `active` being identity rows of the Schur
/// complement with zero right-hand side (their `lam` is 0). `None` if `M` or the Schur complement is singular.
fn solve_saddle<T: Real>(
    mass: &SMatrix<T, NQ, NQ>,
    rows: &RowsOf<T>,
    active: &ActiveSet,
    f: &CoordsOf<T>,
    b: &MultipliersOf<T>,
) -> Option<(CoordsOf<T>, MultipliersOf<T>)> {
    let chol = mass.cholesky()?;
    let x_free = chol.solve(f);
    let minv_jt = chol.solve(&rows.transpose());
    let mut schur = rows * minv_jt;
    let mut rhs = b - rows * x_free;
    for (i, on) in active.row_mask().into_iter().enumerate() {
        if !on {
            schur[(i, i)] = T::one();
            rhs[i] = T::zero();
        }
    }
    let lam = schur.cholesky()?.solve(&rhs);
    Some((x_free + minv_jt * lam, lam))
}

/// `q''` and the multipliers of Eq. (1) with the constraints of `active` (as
/// [`crate::contact::constrained_dynamics`]), with the constants `mech`.
pub(crate) fn constrained_dynamics_with<T: Real>(
    model: &Model,
    mech: &Mechanics<T>,
    q: &CoordsOf<T>,
    qd: &CoordsOf<T>,
    active: &ActiveSet,
) -> Option<(CoordsOf<T>, MultipliersOf<T>)> {
    let eom = model.equations_of_motion_with(mech, q, qd);
    let (rows, rhs) = constraint_rows(&eom, active);
    solve_saddle(&eom.mass, &rows, active, &(-eom.bias), &rhs)
}

/// `q'+` of the collision equation (5), `M (q'+ - q'-) = J^T lambda_I`, `J q'+ = 0`, with the units of `active`
/// (as [`crate::contact::impulse`]).
pub(crate) fn impulse_with<T: Real>(
    model: &Model,
    mech: &Mechanics<T>,
    q: &CoordsOf<T>,
    qd_minus: &CoordsOf<T>,
    active: &ActiveSet,
) -> Option<CoordsOf<T>> {
    let eom = model.equations_of_motion_with(mech, q, &CoordsOf::<T>::zeros());
    let (rows, _) = constraint_rows(&eom, active);
    let b = -(rows * qd_minus);
    let (dqd, _) = solve_saddle(&eom.mass, &rows, active, &CoordsOf::<T>::zeros(), &b)?;
    Some(qd_minus + dqd)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{constrained_dynamics, impulse};
    use crate::dynamics::Coords;
    use crate::params::Params;
    use approx::assert_relative_eq;

    /// Every active set (the six flags in all combinations).
    fn all_active_sets() -> impl Iterator<Item = ActiveSet> {
        (0..1u32 << 6).map(|bits| {
            let on = |b: u32| bits & (1 << b) != 0;
            ActiveSet {
                contact1: on(0),
                contact2: on(1),
                lock1: on(2),
                lock2: on(3),
                slide1: on(4),
                slide2: on(5),
            }
        })
    }

    /// At `f64`, the plain solves equal the walk's hand-tuned ones for every active set that both solve.
    #[test]
    fn plain_solves_equal_the_walks_solves() {
        let model = Model::new(&Params {
            hub_inertia: 0.2,
            ..Params::default()
        })
        .unwrap();
        let q = Coords::new(0.01, -0.02, -0.3, 0.97, 0.93);
        let qd = Coords::new(0.2, -0.1, 1.0, -0.2, 0.1);
        let mut compared = 0;
        for active in all_active_sets() {
            let fast = constrained_dynamics(&model, &q, &qd, &active);
            let plain = constrained_dynamics_with(&model, model.mechanics(), &q, &qd, &active);
            if let (Ok(fast), Some((qdd, lam))) = (fast, plain) {
                assert_relative_eq!(fast.qdd, qdd, epsilon = 1e-9, max_relative = 1e-10);
                assert_relative_eq!(fast.multipliers, lam, epsilon = 1e-8, max_relative = 1e-10);
                let fast = impulse(&model, &q, &qd, &active).unwrap();
                let plain = impulse_with(&model, model.mechanics(), &q, &qd, &active).unwrap();
                assert_relative_eq!(fast.qd_plus, plain, epsilon = 1e-12, max_relative = 1e-12);
                compared += 1;
            }
        }
        assert!(compared > 20, "only {compared} active sets compared");
    }
}
