//! The force-level problem of a phase and the impulse problem of a touchdown for any [`Mechanism`]
//! (docs/model.md section 3, the paper's Eqs. (1)-(2) and (5)), with the active constraints as rows:
//!
//! ```text
//! M q'' + h = J^T lambda,   J q'' = -(dJ/dt) q'          (Eq. (1) with (2))
//! M (q'+ - q'-) = J^T Lambda,   J q'+ = 0                (Eq. (5))
//! ```
//!
//! solved through the Schur complement `J M^-1 J^T` (symmetric positive definite for independent rows), over any
//! [`Real`]: `f64` for the walk, dual numbers for its exact derivatives (`super::sensitivity`), which thereby
//! differentiate the very solve the walk makes. This is the general route; a mechanism may solve the same problems its own way where its structure allows (the
//! wheel's reduced solver in `crate::contact`), and `wheel.rs` checks that both agree.

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

use super::{Mechanism, Real};

/// One row of the constraint Jacobian `J`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Row {
    /// The tangential (`x`) row of contact point `i`: its tip does not slide.
    Tangential(usize),
    /// The normal (`z`) row of contact point `i`: its tip stays on the ground.
    Normal(usize),
    /// Coordinate `k` held (a joint at its stopper, or locked): its row of the identity.
    Held(usize),
}

impl Row {
    /// Both rows of contact point `i`: tangential, then normal (the paper's stacking, Eq. (2)).
    pub fn contact(i: usize) -> [Row; 2] {
        [Row::Tangential(i), Row::Normal(i)]
    }
}

/// Why a constrained problem has no unique solution.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ConstrainedError {
    /// `M(q)` is not positive definite (a massless part of the mechanism moves freely).
    #[error("the mass matrix is not positive definite")]
    SingularMass,
    /// The active rows are linearly dependent (`J M^-1 J^T` singular).
    #[error("the active constraints are redundant (J M^-1 J^T is singular)")]
    RedundantRows,
}

/// The accelerations and multipliers of Eq. (1) with `rows` active.
#[derive(Debug, Clone, PartialEq)]
pub struct Accelerations<const N: usize, T: Real = f64> {
    /// `q''`.
    pub qdd: SVector<T, N>,
    /// `lambda`, one per row in the order given (a contact's tangential and normal forces, a held coordinate's
    /// reaction) \[N or N m\].
    pub multipliers: DVector<T>,
}

/// The velocities and impulses of Eq. (5) with `rows` active.
#[derive(Debug, Clone, PartialEq)]
pub struct Impulse<const N: usize, T: Real = f64> {
    /// `q'+`.
    pub qd_plus: SVector<T, N>,
    /// `Lambda`, one per row in the order given \[N s or N m s\].
    pub impulses: DVector<T>,
}

/// `J` and `(dJ/dt) q'` of `rows` at `(q, q')`.
fn rows_of<T: Real, M: Mechanism<N>, const N: usize>(
    mechanism: &M,
    c: &M::Constants<T>,
    (q, qd): (&SVector<T, N>, &SVector<T, N>),
    rows: &[Row],
) -> (DMatrix<T>, DVector<T>) {
    let mut j = DMatrix::zeros(rows.len(), N);
    let mut jdot_qd = DVector::zeros(rows.len());
    for (r, row) in rows.iter().enumerate() {
        match *row {
            Row::Tangential(i) | Row::Normal(i) => {
                let axis = usize::from(matches!(row, Row::Normal(_)));
                let point = mechanism.contact(c, q, qd, i);
                for k in 0..N {
                    j[(r, k)] = point.jacobian[(axis, k)];
                }
                jdot_qd[r] = point.velocity_product[axis];
            }
            Row::Held(k) => j[(r, k)] = T::one(),
        }
    }
    (j, jdot_qd)
}

/// A pivot of the factorization [`ldl_solve`] at most this times the largest diagonal entry of the matrix makes
/// it singular (not positive definite to rounding).
pub const PIVOT_TOL: f64 = 1e-14;

/// `A^-1 b` for a symmetric positive definite `A` by its factorization `A = L D L^T` (unit lower `L`, diagonal
/// `D`), over any [`Real`]; `None` where a pivot of `D` is not above [`PIVOT_TOL`] of `A`'s largest diagonal
/// entry (`A` singular or indefinite).
///
/// Hand-written rather than nalgebra's `Cholesky`: that asks for a `ComplexField` (square roots, and all of
/// nalgebra's scalar traits), which the dual numbers of the derivatives are not; `L D L^T` needs only the field
/// operations, so one code solves for the walk and, on dual numbers, for its derivatives.
pub fn ldl_solve<T: Real>(a: &DMatrix<T>, b: &DMatrix<T>) -> Option<DMatrix<T>> {
    let n = a.nrows();
    let scale = (0..n).map(|i| a[(i, i)].value().abs()).fold(0.0, f64::max);
    let mut l = DMatrix::<T>::identity(n, n);
    let mut d = DVector::<T>::zeros(n);
    for j in 0..n {
        let mut dj = a[(j, j)];
        for k in 0..j {
            dj -= l[(j, k)] * l[(j, k)] * d[k];
        }
        if dj.value().is_nan() || dj.value() <= PIVOT_TOL * scale {
            return None;
        }
        d[j] = dj;
        for i in j + 1..n {
            let mut lij = a[(i, j)];
            for k in 0..j {
                lij -= l[(i, k)] * l[(j, k)] * d[k];
            }
            l[(i, j)] = lij / dj;
        }
    }
    let mut x = b.clone();
    for c in 0..x.ncols() {
        // L y = b, then D z = y, then L^T x = z, in place.
        for i in 0..n {
            for k in 0..i {
                let lx = l[(i, k)] * x[(k, c)];
                x[(i, c)] -= lx;
            }
        }
        for i in 0..n {
            x[(i, c)] /= d[i];
        }
        for i in (0..n).rev() {
            for k in i + 1..n {
                let lx = l[(k, i)] * x[(k, c)];
                x[(i, c)] -= lx;
            }
        }
    }
    Some(x)
}

/// `M^-1` applied to the columns of `b`.
fn mass_solve<T: Real, const N: usize>(
    mass: &SMatrix<T, N, N>,
    b: &DMatrix<T>,
) -> Result<DMatrix<T>, ConstrainedError> {
    let dense = DMatrix::from_column_slice(N, N, mass.as_slice());
    ldl_solve(&dense, b).ok_or(ConstrainedError::SingularMass)
}

/// The Schur complement's solve `(J M^-1 J^T) x = rhs`, given `M^-1 J^T`.
fn schur_solve<T: Real>(
    j: &DMatrix<T>,
    minv_jt: &DMatrix<T>,
    rhs: &DVector<T>,
) -> Result<DVector<T>, ConstrainedError> {
    if j.nrows() == 0 {
        return Ok(DVector::zeros(0));
    }
    let rhs = DMatrix::from_column_slice(rhs.len(), 1, rhs.as_slice());
    ldl_solve(&(j * minv_jt), &rhs)
        .map(|x| DVector::from_column_slice(x.as_slice()))
        .ok_or(ConstrainedError::RedundantRows)
}

/// `q''` and `lambda` of Eq. (1) at `(q, q')` with `rows` active (see the module documentation).
pub fn accelerations<M: Mechanism<N>, const N: usize>(
    mechanism: &M,
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
    rows: &[Row],
) -> Result<Accelerations<N>, ConstrainedError> {
    accelerations_with(mechanism, &mechanism.constants_f64(), (q, qd), rows)
}

/// [`accelerations`] with the constants `c`, over any [`Real`].
pub fn accelerations_with<T: Real, M: Mechanism<N>, const N: usize>(
    mechanism: &M,
    c: &M::Constants<T>,
    (q, qd): (&SVector<T, N>, &SVector<T, N>),
    rows: &[Row],
) -> Result<Accelerations<N, T>, ConstrainedError> {
    let eq = mechanism.equations(c, q, qd);
    let (j, jdot_qd) = rows_of(mechanism, c, (q, qd), rows);
    // M q'' = -h + J^T lambda, and J q'' = -(dJ/dt) q': (J M^-1 J^T) lambda = J M^-1 h - (dJ/dt) q'.
    let mut b = DMatrix::zeros(N, 1 + rows.len());
    b.set_column(0, &DVector::from_column_slice(eq.bias.as_slice()));
    b.columns_mut(1, rows.len()).copy_from(&j.transpose());
    let minv_b = mass_solve(&eq.mass, &b)?;
    let minv_h = minv_b.column(0).into_owned();
    let minv_jt = minv_b.columns(1, rows.len()).into_owned();
    let lambda = schur_solve(&j, &minv_jt, &(&j * &minv_h - jdot_qd))?;
    let qdd = &minv_jt * &lambda - minv_h;
    Ok(Accelerations {
        qdd: SVector::from_column_slice(qdd.as_slice()),
        multipliers: lambda,
    })
}

/// `q'+` and `Lambda` of Eq. (5) at `q`, arriving with `q'-`, with `rows` active (see the module
/// documentation).
pub fn impulse<M: Mechanism<N>, const N: usize>(
    mechanism: &M,
    q: &SVector<f64, N>,
    qd_minus: &SVector<f64, N>,
    rows: &[Row],
) -> Result<Impulse<N>, ConstrainedError> {
    impulse_with(mechanism, &mechanism.constants_f64(), (q, qd_minus), rows)
}

/// [`impulse`] with the constants `c`, over any [`Real`].
pub fn impulse_with<T: Real, M: Mechanism<N>, const N: usize>(
    mechanism: &M,
    c: &M::Constants<T>,
    (q, qd_minus): (&SVector<T, N>, &SVector<T, N>),
    rows: &[Row],
) -> Result<Impulse<N, T>, ConstrainedError> {
    let eq = mechanism.equations(c, q, qd_minus);
    let (j, _) = rows_of(mechanism, c, (q, qd_minus), rows);
    let minv_jt = mass_solve(&eq.mass, &j.transpose())?;
    // J (q'- + M^-1 J^T Lambda) = 0.
    let v = DVector::from_column_slice(qd_minus.as_slice());
    let impulses = schur_solve(&j, &minv_jt, &-(&j * &v))?;
    let qd_plus = v + &minv_jt * &impulses;
    Ok(Impulse {
        qd_plus: SVector::from_column_slice(qd_plus.as_slice()),
        impulses,
    })
}
