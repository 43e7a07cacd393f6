//! Derivatives of the constrained dynamics and of the collision equation with their active set fixed
//! (docs/model.md sections 3, 5 and 10).
//!
//! Both are linear solves `K(y) z = r(y)` with the KKT matrix `K = [M -J^T; J 0]` (inactive rows as identity
//! rows): Eq. (1) with the constraints, `z = (q'', lam)`, and Eq. (5), `z = (q'+ - q'-, lam_I)`. Written as a
//! residual `R(y, z) = 0`, the solution's derivative along a direction of `y` is `dz = -K^-1 (dR/dy)`, the
//! residual differentiated with `z` held at its value. So the walk's own `f64` solve gives `z`, one evaluation
//! of the residual on dual numbers gives `dR/dy` along every direction at once (`M q'' + h` without forming `M`,
//! `Model::generalized_force_with`, and the rows of (C2), differentiated by [`crate::dynamics::Real`]), and
//! one `f64` factorization of `K` solves for all directions: the walk's own where its solve kept it
//! (`contact::NoSlipKkt`, found in the step's log), else one made here the same way (an impact's set). This is
//! the KKT solve differentiated, without running a factorization on dual numbers.
//!
//! **Coulomb slip** (docs/model.md section 12). A slipping contact's tangential force is not a free multiplier but
//! `lambda_t = -s mu lambda_n`, so the residual's first block is `M q'' + h - A^T lam - J_t^T lambda_t(lambda_n,
//! mu)`, its derivative in `lam` the force columns `B` (the slipping normal row's `J_n - s mu J_t`), and
//! `K = [M -B^T; A 0]` is no longer symmetric: [`SlipKkt`] solves it by LU. The residual's derivative gains
//! `-dJ_t^T lambda_t` (the slipping rear tip's tangential row moves with `q`) and `s lambda_n J_t^T dmu` (the
//! friction coefficient as a parameter), and the friction force's derivative is
//! `dlambda_t = -s (mu dlambda_n + lambda_n dmu)`.

use nalgebra::{SMatrix, SVector};

use crate::contact::{
    factor_no_slip, force_columns, ActiveSet, NoSlipKkt, NoSlipSystem, Role, Solved, NROWS,
};
use crate::dynamics::{
    Coords, CoordsOf, EquationsOfMotion, Mechanics, Model, PointJacobian, Real, L1, L2, NQ, X, Z,
};

use super::dual::Dual;

/// Multipliers `[lambda_1, lambda_2, lambda_3, lambda_4, mu_1, mu_2]` over any [`Real`].
type MultipliersOf<T> = SVector<T, NROWS>;

/// The constraint rows `J` of the active units of `active` (zero where inactive) and `dJ/dt q'`.
fn constraint_rows<T: Real>(
    eom: &EquationsOfMotion<T>,
    active: &ActiveSet,
) -> (SMatrix<T, NROWS, NQ>, MultipliersOf<T>) {
    let mask = active.row_mask();
    let mut rows = SMatrix::<T, NROWS, NQ>::zeros();
    let mut jdq = MultipliersOf::<T>::zeros();
    for (row, column) in [(0, X), (1, Z), (4, L1), (5, L2)] {
        if mask[row] {
            rows[(row, column)] = T::one();
        }
    }
    for axis in 0..2 {
        if mask[2 + axis] {
            rows.set_row(2 + axis, &eom.rear_tip.jacobian.row(axis));
            jdq[2 + axis] = eom.rear_tip.velocity_product[axis];
        }
    }
    (rows, jdq)
}

/// The KKT matrix `[M -J^T; J 0]` of the active rows of an active set at one configuration, factored in `f64`
/// as the walk's solve factors it ([`NoSlipKkt`]): solves for many right-hand sides. When Leg 1's tip is held
/// (no-slip (C1), most of the walk) its rows `e_x`, `e_z` fix `x`, `z` and the system is reduced to
/// `(theta, L1, L2, L3)`, as the walk's own solve does.
pub(crate) struct Kkt<'a> {
    /// `M` and the rows of (C2).
    eom: &'a EquationsOfMotion<f64>,
    /// The rows `J` in the fixed stacking (zero where inactive).
    rows: SMatrix<f64, NROWS, NQ>,
    /// The factored system.
    system: &'a NoSlipKkt,
}

impl Kkt<'_> {
    /// Solve `[M -J^T; J 0] [x; lam] = [f; b]` for `D` right-hand sides (inactive rows of `b` are ignored; their
    /// `lam` is 0).
    fn solve<const D: usize>(
        &self,
        f: &SMatrix<f64, NQ, D>,
        b: &SMatrix<f64, NROWS, D>,
    ) -> (SMatrix<f64, NQ, D>, SMatrix<f64, NROWS, D>) {
        let mut x = SMatrix::<f64, NQ, D>::zeros();
        let mut lam = SMatrix::<f64, NROWS, D>::zeros();
        for c in 0..D {
            match self.system {
                NoSlipKkt::General(system) => {
                    let system = &**system;
                    let k = system.factored.k;
                    let b_c = std::array::from_fn(|i| {
                        if i < k {
                            b[(system.stacked[i], c)]
                        } else {
                            0.0
                        }
                    });
                    let f_c = std::array::from_fn(|l| f[(l, c)]);
                    let (x_c, l_c) = system.factored.solve(&f_c, &b_c);
                    for l in 0..NQ {
                        x[(l, c)] = x_c[l];
                    }
                    for i in 0..k {
                        lam[(system.stacked[i], c)] = l_c[i];
                    }
                }
                NoSlipKkt::Held(system) => self.solve_held(system, (f, b), c, (&mut x, &mut lam)),
                NoSlipKkt::HeldSwinging(system) => {
                    self.solve_held(system, (f, b), c, (&mut x, &mut lam))
                }
            }
        }
        (x, lam)
    }

    /// Column `c` of [`Kkt::solve`] with (C1) held: `x'' = b_x`, `z'' = b_z`, the rest on the `R` coordinates
    /// from `theta` on.
    fn solve_held<const R: usize, const D: usize>(
        &self,
        system: &NoSlipSystem<R, { NROWS - 2 }>,
        (f, b): (&SMatrix<f64, NQ, D>, &SMatrix<f64, NROWS, D>),
        c: usize,
        (x, lam): (&mut SMatrix<f64, NQ, D>, &mut SMatrix<f64, NROWS, D>),
    ) {
        let mass = &self.eom.mass;
        let k = system.factored.k;
        let xz = [b[(0, c)], b[(1, c)]];
        let f_r = std::array::from_fn(|l| {
            f[(2 + l, c)] - mass[(2 + l, 0)] * xz[0] - mass[(2 + l, 1)] * xz[1]
        });
        let b_c = std::array::from_fn(|i| {
            if i < k {
                let row = system.stacked[i];
                b[(row, c)] - self.rows[(row, 0)] * xz[0] - self.rows[(row, 1)] * xz[1]
            } else {
                0.0
            }
        });
        let (x_r, l_c) = system.factored.solve(&f_r, &b_c);
        x[(0, c)] = xz[0];
        x[(1, c)] = xz[1];
        for l in 0..R {
            x[(2 + l, c)] = x_r[l];
        }
        for i in 0..k {
            lam[(system.stacked[i], c)] = l_c[i];
        }
        // lambda_1, lambda_2 from the x and z equations: (M x - f - J_o^T lam_o)_{x,z}.
        for axis in 0..2 {
            let mut v = -f[(axis, c)];
            for j in 0..NQ {
                v += mass[(axis, j)] * x[(j, c)];
            }
            for (&row, l_i) in system.stacked.iter().zip(&l_c).take(k) {
                v -= self.rows[(row, axis)] * l_i;
            }
            lam[(axis, c)] = v;
        }
    }
}

/// Size of the full KKT system `[q''; lam]`.
const NK: usize = NQ + NROWS;

/// The KKT matrix `[M -B^T; A 0]` of an active set with a slipping contact (see the module documentation), its
/// inactive rows identity rows, factored by LU with partial pivoting: the matrix is not symmetric. nalgebra's
/// LU rather than an elimination of our own: unlike the walk's solve, the derivative decides nothing from
/// its pivots, and only frictional walks take this route (the symmetric [`Kkt`] keeps its Schur complement).
struct SlipKkt {
    lu: nalgebra::LU<f64, nalgebra::Const<NK>, nalgebra::Const<NK>>,
    mask: [bool; NROWS],
}

impl SlipKkt {
    /// Factor the KKT matrix of `active` at `(q, q')` with `M` and the rows of `eom` and the walk's force
    /// columns ([`force_columns`]); `None` if singular.
    fn new(
        model: &Model,
        (q, qd): (&Coords, &Coords),
        eom: &EquationsOfMotion<f64>,
        active: &ActiveSet,
    ) -> Option<SlipKkt> {
        let (rows, _) = constraint_rows(eom, active);
        let columns = force_columns(model, q, qd, active, &rows);
        let mask = active.row_mask();
        let mut k = SMatrix::<f64, NK, NK>::zeros();
        k.fixed_view_mut::<NQ, NQ>(0, 0).copy_from(&eom.mass);
        for (i, on) in mask.into_iter().enumerate() {
            if on {
                for j in 0..NQ {
                    k[(j, NQ + i)] = -columns[(i, j)];
                    k[(NQ + i, j)] = rows[(i, j)];
                }
            } else {
                k[(NQ + i, NQ + i)] = 1.0;
            }
        }
        let lu = k.lu();
        lu.is_invertible().then_some(SlipKkt { lu, mask })
    }

    /// Solve `[M -B^T; A 0] [x; lam] = [f; b]` for `D` right-hand sides (inactive rows of `b` are ignored; their
    /// `lam` is 0).
    fn solve<const D: usize>(
        &self,
        f: &SMatrix<f64, NQ, D>,
        b: &SMatrix<f64, NROWS, D>,
    ) -> Option<(SMatrix<f64, NQ, D>, SMatrix<f64, NROWS, D>)> {
        let mut rhs = SMatrix::<f64, NK, D>::zeros();
        rhs.fixed_rows_mut::<NQ>(0).copy_from(f);
        for (i, on) in self.mask.into_iter().enumerate() {
            if on {
                rhs.row_mut(NQ + i).copy_from(&b.row(i));
            }
        }
        let z = self.lu.solve(&rhs)?;
        Some((
            z.fixed_rows::<NQ>(0).into_owned(),
            z.fixed_rows::<NROWS>(NQ).into_owned(),
        ))
    }
}

/// Solve the KKT system of `active` at `(q, q')` (`eom` its equations of motion there) for `D` right-hand
/// sides: the symmetric [`Kkt`] without slip, [`SlipKkt`] with it. `None` if singular.
fn solve_kkt<const D: usize>(
    (model, q, qd): (&Model, &Coords, &Coords),
    (eom, active, system): (&EquationsOfMotion<f64>, &ActiveSet, Option<&NoSlipKkt>),
    (f, b): (&SMatrix<f64, NQ, D>, &SMatrix<f64, NROWS, D>),
) -> Option<(SMatrix<f64, NQ, D>, SMatrix<f64, NROWS, D>)> {
    if active.any_slip() {
        return SlipKkt::new(model, (q, qd), eom, active)?.solve(f, b);
    }
    // The walk's factors where it gave them, else factored here (an impact's set).
    let factored;
    let system = match system {
        Some(system) => system,
        None => {
            factored = factor_no_slip(eom, active).ok()?;
            &factored
        }
    };
    let (rows, _) = constraint_rows(eom, active);
    Some(Kkt { eom, rows, system }.solve(f, b))
}

/// The friction force's part of the residual's derivative, `s lambda_n J_t^T dmu` for each slipping contact
/// (`friction` carries `dmu`), added to `r1`.
fn add_friction_parts<const D: usize>(
    r1: &mut SMatrix<f64, NQ, D>,
    (eom, active): (&EquationsOfMotion<f64>, &ActiveSet),
    friction: &Dual<D>,
    lam: &SVector<f64, NROWS>,
) {
    for leg in Role::BOTH {
        let s = f64::from(active.slip(leg));
        if s != 0.0 && active.contact(leg) {
            let lambda_n = lam[leg.normal_row()];
            for j in 0..NQ {
                let jt = match leg {
                    Role::Fore => f64::from(u8::from(j == X)),
                    Role::Rear => eom.rear_tip.jacobian[(0, j)],
                };
                for c in 0..D {
                    r1[(j, c)] += s * lambda_n * jt * friction.eps[c];
                }
            }
        }
    }
}

/// The friction forces' derivatives `dlambda_t = -s (mu dlambda_n + lambda_n dmu)` of the slipping contacts
/// of `active`, written into their tangential rows of `dlam`.
fn friction_derivatives<const D: usize>(
    active: &ActiveSet,
    friction: &Dual<D>,
    lam: &SVector<f64, NROWS>,
    dlam: &mut SMatrix<f64, NROWS, D>,
) {
    for leg in Role::BOTH {
        let s = f64::from(active.slip(leg));
        if s != 0.0 && active.contact(leg) {
            let (t, n) = (leg.tangential_row(), leg.normal_row());
            for c in 0..D {
                dlam[(t, c)] = -s * (friction.re * dlam[(n, c)] + lam[n] * friction.eps[c]);
            }
        }
    }
}

/// Duals over the configuration `(q, q')` and the constants `mech`, `D` directions each.
type Duals<const D: usize> = (CoordsOf<Dual<D>>, CoordsOf<Dual<D>>, Mechanics<Dual<D>>);

/// The parts of `dR/dy` that come from the configuration: `dM z1` (for a vector `z1` held fixed) and the
/// derivatives of the rows of (C2), `dJ_C2^T lam_C2` and `dJ_C2 z2`, on the derivative parts only (the rows of
/// (C1) and of the stoppers are constant).
struct ResidualParts<const D: usize> {
    /// `M` and the rows, real parts.
    eom: EquationsOfMotion<f64>,
    /// `dR1 = dM z1 - dJ^T lam` (and `dh` where the caller adds it), `NQ x D`.
    r1: SMatrix<f64, NQ, D>,
    /// `dR2 = dJ z2` on the active rows of (C2), `NROWS x D`.
    r2: SMatrix<f64, NROWS, D>,
}

/// The rows of (C2) differentiated, `-dJ_C2^T lam_C2` into `r1` and `dJ_C2 z2` into `r2` (active rows), from
/// the dual Jacobian of Leg 2's tip.
fn add_rear_tip_parts<const D: usize>(
    jacobian: &PointJacobian<Dual<D>>,
    active: &ActiveSet,
    (z2, lam): (&Coords, &SVector<f64, NROWS>),
    (r1, r2): (&mut SMatrix<f64, NQ, D>, &mut SMatrix<f64, NROWS, D>),
) {
    let mask = active.row_mask();
    // A slipping rear tip's tangential row carries its friction force in `lam` (`-s mu lambda_n`): it moves
    // with `q` as the active rows do, but is no constraint (no `r2`).
    let slipping = active.contact2 && active.slip2 != 0;
    for axis in 0..2 {
        let row = 2 + axis;
        if !(mask[row] || axis == 0 && slipping) {
            continue;
        }
        for j in 0..NQ {
            let dj = &jacobian[(axis, j)].eps;
            for c in 0..D {
                r1[(j, c)] -= dj[c] * lam[row];
                if mask[row] {
                    r2[(row, c)] += dj[c] * z2[j];
                }
            }
        }
    }
}

fn residual_parts<const D: usize>(
    eom: &EquationsOfMotion<Dual<D>>,
    active: &ActiveSet,
    z1: &Coords,
    z2: &Coords,
    lam: &SVector<f64, NROWS>,
) -> ResidualParts<D> {
    let mut r1 = SMatrix::<f64, NQ, D>::zeros();
    let mut r2 = SMatrix::<f64, NROWS, D>::zeros();
    for i in 0..NQ {
        for j in 0..NQ {
            let (m, z) = (&eom.mass[(i, j)].eps, z1[j]);
            for c in 0..D {
                r1[(i, c)] += m[c] * z;
            }
        }
    }
    add_rear_tip_parts(
        &eom.rear_tip.jacobian,
        active,
        (z2, lam),
        (&mut r1, &mut r2),
    );
    let re = |x: &Dual<D>| x.re;
    let eom = EquationsOfMotion {
        mass: eom.mass.map(|x| re(&x)),
        bias: eom.bias.map(|x| re(&x)),
        rear_tip: crate::dynamics::PointKinematics {
            position: eom.rear_tip.position.map(|x| re(&x)),
            jacobian: eom.rear_tip.jacobian.map(|x| re(&x)),
            velocity_product: eom.rear_tip.velocity_product.map(|x| re(&x)),
        },
        swing: eom.swing,
    };
    ResidualParts { eom, r1, r2 }
}

/// The derivatives of `q''` and of the multipliers of the constrained dynamics with `active` (Eq. (1) with
/// the KKT system of docs/model.md section 3) along the `D` directions of the duals, at the solution
/// `(qdd, lam)` the walk's solve gave at their real parts. `None` if the KKT matrix is singular.
pub(crate) fn dynamics_derivative<const D: usize>(
    model: &Model,
    (q, qd, mech): &Duals<D>,
    (solved, active): (&Solved, &ActiveSet),
    (qdd, lam): (&Coords, &SVector<f64, NROWS>),
) -> Option<(SMatrix<f64, NQ, D>, SMatrix<f64, NROWS, D>)> {
    // R = [M q'' + h - J^T lam; J q'' + dJ/dt q'] with (q'', lam) held: `M q'' + h` on duals without forming M
    // (`Model::generalized_force_with`), the rows of (C2) from Leg 2's tip.
    let (force, rear_tip) = model.generalized_force_with(mech, q, qd, qdd);
    let mut r1 = SMatrix::<f64, NQ, D>::from_fn(|i, c| force[i].eps[c]);
    let mut r2 = SMatrix::<f64, NROWS, D>::zeros();
    add_rear_tip_parts(&rear_tip.jacobian, active, (qdd, lam), (&mut r1, &mut r2));
    let mask = active.row_mask();
    for axis in 0..2 {
        if mask[2 + axis] {
            for c in 0..D {
                r2[(2 + axis, c)] += rear_tip.velocity_product[axis].eps[c];
            }
        }
    }
    let (q_real, qd_real) = (q.map(|x| x.re), qd.map(|x| x.re));
    add_friction_parts(&mut r1, (&solved.eom, active), &mech.friction, lam);
    let at = (model, &q_real, &qd_real);
    let system = (&solved.eom, active, solved.kkt.as_ref());
    let (dqdd, mut dlam) = solve_kkt(at, system, (&-r1, &-r2))?;
    friction_derivatives(active, &mech.friction, lam, &mut dlam);
    Some((dqdd, dlam))
}

/// The derivative of `q'+` of the collision equation (5) with the units of `active` along the `D` directions
/// of the duals `(q, q'-)`, at the solution `(q'+ - q'-, lam_I)` the walk's solve gave. `None` if singular.
pub(crate) fn impulse_derivative<const D: usize>(
    model: &Model,
    (q, qd_minus, mech): &Duals<D>,
    active: &ActiveSet,
    (dqd, impulses): (&Coords, &SVector<f64, NROWS>),
) -> Option<SMatrix<f64, NQ, D>> {
    let eom = model.equations_of_motion_with(mech, q, &CoordsOf::zeros());
    let qd_real = qd_minus.map(|x| x.re);
    // R = [M dq' - J^T lam_I; J (q'- + dq')] with (dq', lam_I) held; J dq'- enters through q'-'s derivatives.
    let qd_plus = qd_real + dqd;
    let ResidualParts {
        eom: real,
        mut r1,
        mut r2,
    } = residual_parts(&eom, active, dqd, &qd_plus, impulses);
    add_friction_parts(&mut r1, (&real, active), &mech.friction, impulses);
    let (rows, _) = constraint_rows(&real, active);
    let dqd_minus = SMatrix::<f64, NQ, D>::from_fn(|i, c| qd_minus[i].eps[c]);
    let mask = active.row_mask();
    let j_dqd = rows * dqd_minus;
    for (r, on) in mask.into_iter().enumerate() {
        if on {
            for c in 0..D {
                r2[(r, c)] += j_dqd[(r, c)];
            }
        }
    }
    let at = (model, &q.map(|x| x.re), &qd_real);
    let (ddqd, _) = solve_kkt(at, (&real, active, None), (&-r1, &-r2))?;
    Some(dqd_minus + ddqd)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{constrained_dynamics, constrained_dynamics_solved, impulse};
    use crate::params::Params;
    use crate::variational::dual::{dual, seeded};

    /// The derivatives of `q''`, the multipliers and `q'+` along a direction in `(q, q', k)` equal central
    /// differences of the walk's own solves, for every active set they solve.
    #[test]
    fn solve_derivatives_match_finite_differences_for_every_active_set() {
        let params = Params {
            hub_inertia: 0.2,
            ..Params::default()
        };
        let compared = compare_solve_derivatives(&params, ActiveSet::all(), "stiffness");
        assert!(compared > 20, "only {compared} active sets compared");
    }

    /// The same with Coulomb slip (the non-symmetric KKT system): every set whose contacts slip either way,
    /// along a direction that moves the friction coefficient too.
    #[test]
    fn slipping_solve_derivatives_match_finite_differences() {
        let params = Params {
            hub_inertia: 0.2,
            friction: 0.4,
            ..Params::default()
        };
        let slipping = ActiveSet::all().flat_map(|set| {
            [(1, 0), (-1, 0), (0, 1), (0, -1), (1, -1), (-1, 1)]
                .into_iter()
                .filter_map(move |(s1, s2)| {
                    let mut set = set;
                    for (leg, s) in [(Role::Fore, s1), (Role::Rear, s2)] {
                        if s != 0 {
                            if !set.contact(leg) {
                                return None;
                            }
                            set.set_slipping(leg, s);
                        }
                    }
                    Some(set)
                })
        });
        let slipping: Vec<ActiveSet> = slipping.collect();
        let compared = compare_solve_derivatives(&params, slipping.iter().copied(), "friction");
        assert!(compared > 20, "only {compared} slipping sets compared");
    }

    /// The derivatives of `q''`, the multipliers and `q'+` along one direction in `(q, q', key)` against central
    /// differences, for each of `sets` the walk's solves solve: how many were compared.
    fn compare_solve_derivatives(
        params: &Params,
        sets: impl Iterator<Item = ActiveSet>,
        key: &'static str,
    ) -> usize {
        let model = Model::new(params).unwrap();
        let q = Coords::new(0.01, -0.02, -0.3, 0.97, 0.93, 0.95);
        let qd = Coords::new(0.2, -0.1, 1.0, -0.2, 0.1, 0.3);
        let dir_q = Coords::new(0.3, -0.2, 0.5, 0.1, -0.4, 0.2);
        let dir_qd = Coords::new(-0.5, 0.2, 0.3, 0.6, 0.1, -0.1);
        let h = 1e-6;
        let mut compared = 0;
        for active in sets {
            let at = |s: f64| {
                let mut p = params.clone();
                match key {
                    "friction" => p.friction += s,
                    _ => p.stiffness += s,
                }
                let m = Model::new(&p).unwrap();
                let (q, qd) = (q + dir_q * s, qd + dir_qd * s);
                (
                    constrained_dynamics(&m, &q, &qd, &active),
                    impulse(&m, &q, &qd, &active),
                )
            };
            let (Ok(d0), Ok(i0)) = at(0.0) else { continue };
            let (Ok(dp), Ok(ip)) = at(h) else { continue };
            let (Ok(dm), Ok(im)) = at(-h) else { continue };
            let mech = seeded::<1>(&model, Some(key), 0);
            let one = |x: f64, e: f64| dual(x, SVector::<f64, 1>::new(e));
            let qd_ = CoordsOf::from_fn(|i, _| one(q[i], dir_q[i]));
            let qdd_ = CoordsOf::from_fn(|i, _| one(qd[i], dir_qd[i]));
            let duals = (qd_, qdd_, mech);
            let (_, solved) = constrained_dynamics_solved(&model, &q, &qd, &active);
            let (dqdd, dlam) = dynamics_derivative(
                &model,
                &duals,
                (&solved, &active),
                (&d0.qdd, &d0.multipliers),
            )
            .unwrap();
            let fd_qdd = (dp.qdd - dm.qdd) / (2.0 * h);
            let fd_lam = (dp.multipliers - dm.multipliers) / (2.0 * h);
            let scale = 1.0 + fd_qdd.amax() + fd_lam.amax();
            assert!((dqdd.column(0) - fd_qdd).amax() < 1e-6 * scale, "{active}");
            assert!((dlam.column(0) - fd_lam).amax() < 1e-6 * scale, "{active}");
            let dqd_plus =
                impulse_derivative(&model, &duals, &active, (&(i0.qd_plus - qd), &i0.impulses))
                    .unwrap();
            let fd_plus = (ip.qd_plus - im.qd_plus) / (2.0 * h);
            assert!(
                (dqd_plus.column(0) - fd_plus).amax() < 1e-6 * (1.0 + fd_plus.amax()),
                "{active}"
            );
            compared += 1;
        }
        compared
    }
}
