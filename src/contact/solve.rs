//! The solves of the constrained dynamics (docs/model.md section 3): the KKT system of accelerations and
//! multipliers, reduced when Leg 1's tip is held, and the impulse problem of Eq. (5).

use nalgebra::{SMatrix, SVector};

use super::{
    ActiveSet, ConstrainedDynamics, ContactError, ImpulseSolution, Multipliers, Role, NROWS,
    REDUNDANCY_TOL,
};
use crate::dynamics::{Coords, EquationsOfMotion, Model, L1, L2, L3, NQ, X, Z};

pub(super) type Rows = SMatrix<f64, NROWS, NQ>;

/// Rows `J` of the active constraints and `dJ/dt q'`, zero where inactive.
pub(super) fn constraint_rows(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: &ActiveSet,
) -> (Rows, Multipliers) {
    let mut rows = Rows::zeros();
    let mut jdq = Multipliers::zeros();
    let hub = model.hub(q, qd);
    for leg in Role::BOTH {
        if active.contact(leg) {
            let tip = model.leg_point_from_hub(model.mechanics(), &hub, (q, qd), leg.index(), 0.0);
            let r = 2 * leg.index();
            rows.fixed_view_mut::<2, NQ>(r, 0).copy_from(&tip.jacobian);
            jdq.fixed_rows_mut::<2>(r).copy_from(&tip.velocity_product);
            if active.slide(leg) {
                rows.row_mut(r).fill(0.0);
                jdq[r] = 0.0;
            }
        }
        if active.length_held(leg) {
            rows[(leg.stopper_row(), Model::stroke_coordinate(leg))] = 1.0;
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
    solve_saddle_rows(m, rows, &active.row_mask(), active, f, b)
}

/// [`solve_saddle`] for `K` stacked rows of which `mask` says which are active.
fn solve_saddle_rows<const K: usize>(
    m: &SMatrix<f64, NQ, NQ>,
    rows: &SMatrix<f64, K, NQ>,
    mask: &[bool],
    active: &ActiveSet,
    f: &Coords,
    b: &SVector<f64, K>,
) -> Result<(Coords, SVector<f64, K>), ContactError> {
    let chol = m.cholesky().ok_or(ContactError::SingularMass)?;
    let x_free = chol.solve(f);
    let minv_jt = chol.solve(&rows.transpose());
    let lam = solve_schur(rows * minv_jt, b - rows * x_free, mask, active)?;
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
///
/// Only the active rows enter the solve (see [`Factored`]); when Leg 1's tip is held (most of the walk)
/// the system is first reduced to `(theta, L1, L2)`, and `L3` while a leg swings (`solve_with_fixed_leg_one`).
/// Same result as `solve_saddle` on the full stacking (tested for every active set).
pub(super) fn no_slip_dynamics(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    active: &ActiveSet,
) -> Result<ConstrainedDynamics, ContactError> {
    no_slip_dynamics_of(&model.equations_of_motion(q, qd), active)
}

/// [`no_slip_dynamics`] from the equations of motion `eom` at the state.
pub(super) fn no_slip_dynamics_of(
    eom: &EquationsOfMotion,
    active: &ActiveSet,
) -> Result<ConstrainedDynamics, ContactError> {
    if active.contact1 && !active.slide1 {
        // `(theta, L1, L2)`, and `L3` while a leg swings: a constant size, so that the small loops unroll.
        return if eom.swing {
            solve_with_fixed_leg_one::<{ NQ - 2 }>(eom, active)
        } else {
            solve_with_fixed_leg_one::<{ NQ - 3 }>(eom, active)
        };
    }
    // The general case (Leg 1 sliding or off the ground): all the coordinates.
    general_system(eom, active).general_dynamics(eom, active)
}

/// The KKT system when Leg 1's tip is held (no-slip (C1), most of the walk): its rows are `e_x`, `e_z` with
/// `dJ/dt q' = 0`, so `x'' = z'' = 0` and the system reduces exactly to the three coordinates
/// `(theta, L1, L2[, L3])` with the remaining active rows ((C2), stoppers); `lambda_1`, `lambda_2` then follow from
/// the `x` and `z` equations. Same result as [`solve_saddle`] (tested), at a fraction of the cost.
fn solve_with_fixed_leg_one<const R: usize>(
    eom: &EquationsOfMotion,
    active: &ActiveSet,
) -> Result<ConstrainedDynamics, ContactError> {
    held_dynamics(eom, &mut held_system::<R>(eom, active), active)
}

/// The KKT system of the general case (Leg 1 sliding or off the ground) over all the coordinates, not yet
/// factored: `M` (`L3` left out while no leg swings) and the active rows.
#[inline(always)]
fn general_system(eom: &EquationsOfMotion, active: &ActiveSet) -> NoSlipSystem<NQ, NROWS> {
    let mask = active.row_mask();
    let rear = &eom.rear_tip;
    // Leg 1's tip is the point (x, z): constant rows, dJ/dt q' = 0.
    let candidates: [([f64; NQ], f64); NROWS] = [
        (unit_row(X), 0.0),
        (unit_row(Z), 0.0),
        (
            std::array::from_fn(|k| rear.jacobian[(0, k)]),
            -rear.velocity_product.x,
        ),
        (
            std::array::from_fn(|k| rear.jacobian[(1, k)]),
            -rear.velocity_product.y,
        ),
        (unit_row(L1), 0.0),
        (unit_row(L2), 0.0),
    ];
    // Without a swinging leg `L3` is left out (its row of M is the identity's, with no force).
    let n = if eom.swing { NQ } else { NQ - 1 };
    let mut m = Ldl::<NQ>::zeros(n);
    for i in 0..n {
        for j in 0..=i {
            m.l[i][j] = eom.mass[(i, j)];
        }
    }
    let mut system = NoSlipSystem::new(m);
    for (stacked, (row, rhs)) in candidates.into_iter().enumerate() {
        if mask[stacked] {
            system.push(row, rhs, stacked);
        }
    }
    system
}

/// The KKT system with Leg 1's tip held, not yet factored: `M_rr`, the block of `(theta, L1, L2[, L3])`, and the
/// rows of (C2) and the stoppers restricted to those coordinates.
#[inline(always)]
fn held_system<const R: usize>(
    eom: &EquationsOfMotion,
    active: &ActiveSet,
) -> NoSlipSystem<R, { NROWS - 2 }> {
    let mut system = NoSlipSystem::new(held_leg_one_system::<R>(eom).0);
    let rear = &eom.rear_tip;
    let mask = active.row_mask();
    for axis in 0..2 {
        if mask[2 + axis] {
            let row = std::array::from_fn(|k| rear.jacobian[(axis, 2 + k)]);
            system.push(row, -rear.velocity_product[axis], 2 + axis);
        }
    }
    for (stacked, coordinate) in [(4, L1), (5, L2)] {
        if mask[stacked] {
            system.push(unit_row(coordinate - 2), 0.0, stacked);
        }
    }
    system
}

/// The KKT system of [`no_slip_dynamics`] (see [`Factored`]: filled in, then factored in place), with the
/// stacked position of each of its rows (in the stacking of all [`NROWS`]) and their right-hand sides
/// `-dJ/dt q'`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NoSlipSystem<const N: usize, const K: usize> {
    /// `M` (or its block of the coordinates from `theta` on) with the active rows.
    pub(crate) factored: Factored<N, K>,
    /// The position of row `i` in the stacking.
    pub(crate) stacked: [usize; K],
    /// `b_i` of `a_i . q'' = b_i`.
    rhs: [f64; K],
}

impl<const N: usize, const K: usize> NoSlipSystem<N, K> {
    /// The system with `M` (filled in, not factored: `chol`) and no rows yet.
    #[inline(always)]
    fn new(chol: Ldl<N>) -> Self {
        NoSlipSystem {
            factored: Factored {
                chol,
                w: [[0.0; N]; K],
                k: 0,
                schur: Ldl::zeros(0),
            },
            stacked: [0; K],
            rhs: [0.0; K],
        }
    }

    /// Add the row `a . x = rhs`, row `stacked` of the stacking.
    #[inline(always)]
    fn push(&mut self, a: [f64; N], rhs: f64, stacked: usize) {
        let k = self.factored.k;
        self.factored.w[k] = a;
        self.rhs[k] = rhs;
        self.stacked[k] = stacked;
        self.factored.k += 1;
    }

    /// The multipliers `lam` of the rows in the stacking of all [`NROWS`] (0 for the inactive ones).
    fn multipliers(&self, lam: &[f64; K]) -> Multipliers {
        let mut multipliers = Multipliers::zeros();
        for (i, &stacked) in self.stacked[..self.factored.k].iter().enumerate() {
            multipliers[stacked] = lam[i];
        }
        multipliers
    }
}

impl NoSlipSystem<NQ, NROWS> {
    /// Factor the general case in place and solve it: the accelerations and multipliers.
    fn general_dynamics(
        &mut self,
        eom: &EquationsOfMotion,
        active: &ActiveSet,
    ) -> Result<ConstrainedDynamics, ContactError> {
        let f = std::array::from_fn(|i| -eom.bias[i]);
        let (x, lam) = self.factored.factor_solve(&f, &self.rhs, active)?;
        Ok(ConstrainedDynamics {
            qdd: Coords::from(x),
            multipliers: self.multipliers(&lam),
        })
    }
}

/// The no-slip KKT system of an active set at one state, factored as the walk factors it: what
/// [`no_slip_dynamics`] solves once and the derivatives of the dynamics (`crate::variational`) solve again for
/// their right-hand sides, with the walk's factors. (The walk's own path, [`no_slip_dynamics_of`], builds the
/// same system on its stack and drops it after the solve.)
#[derive(Debug, Clone)]
pub(crate) enum NoSlipKkt {
    /// Leg 1's tip sliding or off the ground: all the coordinates (`L3` left out while no leg swings); boxed,
    /// since it is three times the size of the others and rare.
    General(Box<NoSlipSystem<NQ, NROWS>>),
    /// Leg 1's tip held: `(theta, L1, L2)` with the rows of (C2) and the stoppers (see
    /// `solve_with_fixed_leg_one`).
    Held(NoSlipSystem<{ NQ - 3 }, { NROWS - 2 }>),
    /// As `Held`, with `L3` while a leg swings.
    HeldSwinging(NoSlipSystem<{ NQ - 2 }, { NROWS - 2 }>),
}

/// Factor the no-slip KKT system of `active` with the equations of motion `eom`: an error where the walk's
/// solve fails (`M` not positive definite, redundant rows).
pub(crate) fn factor_no_slip(
    eom: &EquationsOfMotion,
    active: &ActiveSet,
) -> Result<NoSlipKkt, ContactError> {
    let mut kkt = NoSlipKkt::unfactored(eom, active);
    kkt.factor_dynamics(eom, active)?;
    Ok(kkt)
}

impl NoSlipKkt {
    /// The no-slip KKT system of `active` with the equations of motion `eom`, filled in, not yet factored.
    pub(crate) fn unfactored(eom: &EquationsOfMotion, active: &ActiveSet) -> NoSlipKkt {
        if active.contact1 && !active.slide1 {
            if eom.swing {
                NoSlipKkt::HeldSwinging(held_system(eom, active))
            } else {
                NoSlipKkt::Held(held_system(eom, active))
            }
        } else {
            NoSlipKkt::General(Box::new(general_system(eom, active)))
        }
    }

    /// Factor in place ([`Factored::factor_solve`]) and solve: the accelerations and multipliers of Eq. (1),
    /// bit for bit the walk's ([`no_slip_dynamics`], which does the same on its stack).
    pub(crate) fn factor_dynamics(
        &mut self,
        eom: &EquationsOfMotion,
        active: &ActiveSet,
    ) -> Result<ConstrainedDynamics, ContactError> {
        match self {
            NoSlipKkt::General(system) => system.general_dynamics(eom, active),
            NoSlipKkt::Held(system) => held_dynamics(eom, system, active),
            NoSlipKkt::HeldSwinging(system) => held_dynamics(eom, system, active),
        }
    }
}

/// The accelerations and multipliers with Leg 1's tip held: the reduced system factored in place and solved.
#[inline(always)]
fn held_dynamics<const R: usize>(
    eom: &EquationsOfMotion,
    system: &mut NoSlipSystem<R, { NROWS - 2 }>,
    active: &ActiveSet,
) -> Result<ConstrainedDynamics, ContactError> {
    let f_r = std::array::from_fn(|i| -eom.bias[2 + i]);
    let (qdd_r, lam) = system.factored.factor_solve(&f_r, &system.rhs, active)?;
    Ok(complete_held_leg_one(eom, &qdd_r, system.multipliers(&lam)))
}

/// The reduced KKT system with Leg 1's tip held: `M_rr`, the block of `(theta, L1, L2[, L3])` (to factor), and
/// `-h_r`.
pub(super) fn held_leg_one_system<const R: usize>(eom: &EquationsOfMotion) -> (Ldl<R>, [f64; R]) {
    let (m, h) = (&eom.mass, &eom.bias);
    let mut m_rr = Ldl::<R>::zeros(R);
    for i in 0..R {
        for j in 0..=i {
            m_rr.l[i][j] = m[(2 + i, 2 + j)];
        }
    }
    (m_rr, std::array::from_fn(|i| -h[2 + i]))
}

/// The solution of the reduced system completed: `q''` from `q_r''` (`x'' = z'' = 0`), and `lambda_1`,
/// `lambda_2` from the `x` and `z` equations, `(M q'' + h)_{x,z} = lambda_{1,2} + (other rows)^T lambda`, where
/// only Leg 2's contact has `x`, `z` components (the identity, as for every point; with slip its tangential
/// multiplier is the friction force). `multipliers` holds the other rows' already.
pub(super) fn complete_held_leg_one<const R: usize>(
    eom: &EquationsOfMotion,
    qdd_r: &[f64; R],
    mut multipliers: Multipliers,
) -> ConstrainedDynamics {
    let (m, h) = (&eom.mass, &eom.bias);
    let mut qdd = Coords::zeros();
    for k in 0..R {
        qdd[2 + k] = qdd_r[k];
    }
    for axis in 0..2 {
        let generalized = (0..R).map(|k| m[(axis, 2 + k)] * qdd_r[k]).sum::<f64>() + h[axis];
        multipliers[axis] = generalized - multipliers[2 + axis];
    }
    ConstrainedDynamics { qdd, multipliers }
}

/// The row `e_i` of `N` unknowns: a stopper's `dL/dt = 0`, or a coordinate of Leg 1's tip.
fn unit_row<const N: usize>(i: usize) -> [f64; N] {
    std::array::from_fn(|k| if k == i { 1.0 } else { 0.0 })
}

/// A KKT system `[M -A^T; A 0]` over `N` unknowns with `k <= K` rows `a_i`, factored through the Schur
/// complement: `M = L D L^T`, `W_i = L^-1 a_i`, `S = A M^-1 A^T = W D^-1 W^T = L_S D_S L_S^T`. Filled in
/// ([`NoSlipSystem`]) and factored in place ([`Factored::factor_solve`]), so that neither the walk's solve nor the
/// log of its evaluations moves it; solves for any right-hand side ([`Factored::solve`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Factored<const N: usize, const K: usize> {
    /// `M` before [`Factored::factor_solve`], `M = L D L^T` after.
    chol: Ldl<N>,
    /// The rows `a_i` before, `W_i = L^-1 a_i` after.
    w: [[f64; N]; K],
    /// The number of rows.
    pub(crate) k: usize,
    /// `S = L_S D_S L_S^T`.
    schur: Ldl<K>,
}

impl<const N: usize, const K: usize> Factored<N, K> {
    /// Factor in place and solve `[M -A^T; A 0] [x; lam] = [f; b]` (`b` beyond the `k` rows ignored) in the same
    /// pass, as the walk needs both: an error where `M` is not positive definite or the rows (of `active`) are
    /// redundant. The test for redundancy sees the Schur complement of all `K` stacked rows of which the
    /// inactive ones are identity rows, so when some row of the stacking is inactive, its pivot 1 enters the
    /// largest diagonal and the smallest pivot (the same algorithm as [`solve_saddle`] / [`solve_schur`], on
    /// the active rows only). The solution is the one [`Factored::solve`] gives with the factors, bit for bit
    /// (the same operations, fused here with the factorization's loops).
    #[inline(always)]
    fn factor_solve(
        &mut self,
        f: &[f64; N],
        b: &[f64; K],
        active: &ActiveSet,
    ) -> Result<([f64; N], [f64; K]), ContactError> {
        let Factored { chol, w, k, schur } = self;
        let k = *k;
        if !chol.factor() {
            return Err(ContactError::SingularMass);
        }
        // M = L D L^T; with g = L^-1 f and W_i = L^-1 a_i: a_i . M^-1 f = W_i . D^-1 g, S_ij = W_i . D^-1 W_j.
        let mut g = *f;
        chol.forward(&mut g);
        for w_i in &mut w[..k] {
            chol.forward(w_i);
        }
        let scaled_dot =
            |u: &[f64; N], v: &[f64; N]| (0..N).map(|l| u[l] * v[l] * chol.d_inv[l]).sum::<f64>();
        // The leading `k x k` block of the Schur complement: its lower triangle is all `factor` reads.
        schur.n = k;
        let mut lam = [0.0; K];
        for i in 0..k {
            lam[i] = b[i] - scaled_dot(&w[i], &g);
            for j in 0..=i {
                schur.l[i][j] = scaled_dot(&w[i], &w[j]);
            }
        }
        // The identity rows of the inactive units, if any, as `solve_schur` sees them.
        let (diagonal, pivot) = if k < K {
            (1.0, 1.0)
        } else {
            (f64::NEG_INFINITY, f64::INFINITY)
        };
        let scale = (0..k).map(|i| schur.l[i][i]).fold(diagonal, f64::max);
        let redundant = ContactError::RedundantConstraints(*active);
        if !schur.factor() {
            return Err(redundant);
        }
        // A rank-deficient Schur complement can still factor with a rounding-sized pivot: reject tiny pivots.
        let min_pivot = schur.d[..k].iter().copied().fold(pivot, f64::min);
        if min_pivot < REDUNDANCY_TOL * scale {
            return Err(redundant);
        }
        schur.forward(&mut lam);
        schur.backward_scaled(&mut lam);
        Ok((Self::combine(chol, w, k, g, &lam), lam))
    }

    /// `x = M^-1 (f + A^T lam) = L^-T D^-1 (g + sum_i lam_i W_i)`.
    #[inline(always)]
    fn combine(
        chol: &Ldl<N>,
        w: &[[f64; N]; K],
        k: usize,
        g: [f64; N],
        lam: &[f64; K],
    ) -> [f64; N] {
        let mut x = g;
        for (lam_i, w_i) in lam.iter().zip(w).take(k) {
            for (x_l, w_l) in x.iter_mut().zip(w_i) {
                *x_l += lam_i * w_l;
            }
        }
        chol.backward_scaled(&mut x);
        x
    }

    /// Solve `[M -A^T; A 0] [x; lam] = [f; b]` (`b` beyond the `k` rows ignored): with `g = L^-1 f`,
    /// `S lam = b - W D^-1 g` and `x = M^-1 (f + A^T lam) = L^-T D^-1 (g + sum_i lam_i W_i)`.
    #[inline(always)]
    pub(crate) fn solve(&self, f: &[f64; N], b: &[f64; K]) -> ([f64; N], [f64; K]) {
        let chol = &self.chol;
        let mut g = *f;
        chol.forward(&mut g);
        let mut lam = [0.0; K];
        for i in 0..self.k {
            let wg: f64 = (0..N).map(|l| self.w[i][l] * g[l] * chol.d_inv[l]).sum();
            lam[i] = b[i] - wg;
        }
        self.schur.forward(&mut lam);
        self.schur.backward_scaled(&mut lam);
        (Self::combine(chol, &self.w, self.k, g, &lam), lam)
    }
}

/// `A = L D L^T` of a small symmetric positive definite matrix (`L` unit lower triangular), stored in `N x N`
/// arrays of which the leading `n x n` block is used.
///
/// Hand-written rather than nalgebra's `Cholesky` because the right-hand side spends most of its time in
/// factorizations and solves of size 1 to 5, where nalgebra's generic code (column views, `axpy`, square roots)
/// costs several times these plain loops; [`solve_saddle`] keeps the nalgebra version as the reference. The
/// factorization works in place (fill `l` with `A`, then [`Ldl::factor`]) so that no matrix is moved around.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ldl<const N: usize> {
    /// `A` before [`Ldl::factor`] (its lower triangle is read), `L` below the diagonal after.
    pub(crate) l: [[f64; N]; N],
    /// The pivots `D` (the squares of the diagonal of the Cholesky factor).
    pub(crate) d: [f64; N],
    /// `1 / D`, so that the solves multiply rather than divide.
    pub(crate) d_inv: [f64; N],
    n: usize,
}

impl<const N: usize> Ldl<N> {
    /// An `n x n` matrix of zeros to fill in before [`Ldl::factor`].
    pub(crate) fn zeros(n: usize) -> Self {
        Ldl {
            l: [[0.0; N]; N],
            d: [0.0; N],
            d_inv: [0.0; N],
            n,
        }
    }

    /// Factor in place; `false` when a pivot is not positive (or not a number), as nalgebra's
    /// `Cholesky::new` fails.
    pub(crate) fn factor(&mut self) -> bool {
        let (l, d, d_inv) = (&mut self.l, &mut self.d, &mut self.d_inv);
        for j in 0..self.n {
            let mut pivot = l[j][j];
            for k in 0..j {
                pivot -= l[j][k] * l[j][k] * d[k];
            }
            if pivot.is_nan() || pivot <= 0.0 {
                return false;
            }
            d[j] = pivot;
            d_inv[j] = 1.0 / pivot;
            for i in j + 1..self.n {
                let mut s = l[i][j];
                for k in 0..j {
                    s -= l[i][k] * l[j][k] * d[k];
                }
                l[i][j] = s * d_inv[j];
            }
        }
        true
    }

    /// `b <- L^-1 b`.
    pub(crate) fn forward(&self, b: &mut [f64; N]) {
        for i in 0..self.n {
            for k in 0..i {
                b[i] -= self.l[i][k] * b[k];
            }
        }
    }

    /// `y <- L^-T D^-1 y`, so that `forward` then `backward_scaled` solve `A x = b`.
    pub(crate) fn backward_scaled(&self, y: &mut [f64; N]) {
        for i in (0..self.n).rev() {
            y[i] *= self.d_inv[i];
            for k in i + 1..self.n {
                y[i] -= self.l[k][i] * y[k];
            }
        }
    }
}

/// The collision equation (5): `M (q'+ - q'-) = J^T lambda_I`, `J q'+ = 0`, with the units of `active`.
pub(super) fn no_slip_impulse(
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

/// The stopper impact of the swinging leg (`L3`, `rear_exit = "continue"`): the collision equation (5) with the
/// units of `active` and the row `dL3/dt = 0`, whose impulse (the last one returned) stops the leg on its
/// stopper. Returns `q'+` and the impulses of the units of `active`, and of the stopper.
pub(crate) fn swing_lock_impulse(
    model: &Model,
    q: &Coords,
    qd_minus: &Coords,
    active: &ActiveSet,
) -> Result<(ImpulseSolution, f64), ContactError> {
    const K: usize = NROWS + 1;
    let m = model.mass_matrix(q);
    let (rows, _) = constraint_rows(model, q, qd_minus, active);
    let mut stacked = SMatrix::<f64, K, NQ>::zeros();
    stacked.fixed_rows_mut::<NROWS>(0).copy_from(&rows);
    stacked[(NROWS, L3)] = 1.0;
    let mut mask = [true; K];
    mask[..NROWS].copy_from_slice(&active.row_mask());
    let (dqd, lam) = solve_saddle_rows(
        &m,
        &stacked,
        &mask,
        active,
        &Coords::zeros(),
        &(-(stacked * qd_minus)),
    )?;
    let solution = ImpulseSolution {
        qd_plus: qd_minus + dqd,
        impulses: lam.fixed_rows::<NROWS>(0).into_owned(),
    };
    Ok((solution, lam[NROWS]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{constrained_dynamics, impulse};
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
        let q = Coords::new(0.0, 0.0, theta, l1, l2, 0.0);
        (q, Coords::new(0.0, 0.0, 1.0, -0.2, 0.1, 0.0))
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
        assert!(sol.normal_force(Role::Fore) > 0.0 && sol.normal_force(Role::Rear) > 0.0);
        assert!(sol.qdd[THETA].is_finite());
    }

    /// The solve on the active rows only (with Leg 1 held: reduced to `(theta, L1, L2)`) equals the general
    /// saddle-point solve on the full stacking, results and errors, for every active set, at a double-support
    /// state, a state with Leg 2 near its stopper and a lifted state, with and without hub inertia.
    #[test]
    fn active_row_solves_equal_the_general_solve_for_every_active_set() {
        for hub_inertia in [0.0, 0.3] {
            let model = Model::new(&Params {
                hub_inertia,
                ..Params::default()
            })
            .unwrap();
            let (q_dls, qd_dls) = dls_state(&model);
            let states = [
                (q_dls, qd_dls),
                (
                    Coords::new(0.0, 0.0, -0.3, 0.97, 0.99, 0.0),
                    Coords::new(0.0, 0.0, 1.0, -0.2, 0.1, 0.0),
                ),
                (
                    // With a swinging leg.
                    Coords::new(0.2, 0.05, 0.4, 0.93, 1.0, 0.96),
                    Coords::new(0.7, -0.3, 1.4, 0.25, -0.6, 0.3),
                ),
            ];
            let mut solved = 0;
            for (q, qd) in states {
                for active in ActiveSet::all() {
                    let fast = constrained_dynamics(&model, &q, &qd, &active);
                    let (m, h) = model.mass_and_bias(&q, &qd);
                    let (rows, jdq) = constraint_rows(&model, &q, &qd, &active);
                    let general = solve_saddle(&m, &rows, &active, &(-h), &(-jdq));
                    match (fast, general) {
                        (Ok(fast), Ok((qdd, lam))) => {
                            assert_relative_eq!(
                                fast.qdd,
                                qdd,
                                epsilon = 1e-10,
                                max_relative = 1e-12
                            );
                            assert_relative_eq!(
                                fast.multipliers,
                                lam,
                                epsilon = 1e-9,
                                max_relative = 1e-12
                            );
                            solved += 1;
                        }
                        (Err(fast), Err(general)) => assert_eq!(fast, general, "{active:?}"),
                        (fast, general) => panic!("{active:?}: {fast:?} but {general:?}"),
                    }
                }
            }
            // Most sets are regular: at most the 4-unit ones with both stoppers and a fixed tip are redundant.
            assert!(solved > 3 * 64 / 2, "only {solved} sets solved");
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
        let q = Coords::new(0.0, 0.0, -model.alpha() / 2.0, l0, l0, 0.0);
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
