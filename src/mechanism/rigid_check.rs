//! The exact derivatives of a rigid-legged walker's step map checked by a second route (`vrw gait --model NAME
//! --check-jacobian`, and the tests): central differences of the walked map extrapolated by Richardson.
//!
//! A central difference of step `h` has a truncation error `~h^2`, which Richardson's extrapolation
//! `(4 D(h/2) - D(h)) / 3` takes to `~h^4`, and a noise `~rtol / h` from the integration of the perturbed walks,
//! which it does not; the best step depends on the walker. The simplest walker's map is strongly curved (its
//! step's duration moves by ~80 per unit of `theta`): a plain central difference of its `DP` is off by
//! `~0.04 (h / 1e-3)^2` (measured from `h = 3e-3` down to `1e-7`), so the gait search's differences
//! ([`super::rigid_gait::DIFFERENCE_STEP`] `= 1e-6`) are good to `~4e-8` there, and the extrapolation is best
//! near `h = 1e-5`; the compass gait's is best near `1e-4`, where it meets the exact `DP` to `1e-10`, while at
//! `1e-5` its noise is `2e-9` (and its multipliers off by `1e-8`). So the extrapolation is taken at each of
//! [`CHECK_STEPS`], each column at the finer of the two successive steps that agree best, twice its agreement
//! with the steps on either side its error estimate. The exact derivatives' error is estimated by their change at [`CHECK_LOOSENING`] times looser
//! tolerances (conservative: the error falls with the tolerance).

use nalgebra::{DMatrix, DVector};

use super::rigid::{RigidOptions, RigidWalker};
use super::rigid_derivative::{parameter_value, DerivativeError};
use super::rigid_family::Parametrized;
use super::rigid_gait::rigid_step_map;
use crate::params::ConfigError;

/// Relative steps of the checking differences (each coordinate's step is one of these times its size, at least
/// 1), from coarse to fine.
pub const CHECK_STEPS: [f64; 5] = [1e-3, 3e-4, 1e-4, 3e-5, 1e-5];

/// The second tolerances of the error estimates are this much looser than the walk's.
pub const CHECK_LOOSENING: f64 = 100.0;

/// The exact derivatives against Richardson-extrapolated central differences.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RigidDerivativeCheck {
    /// The parameter of the last column, if one was asked for.
    pub parameter: Option<String>,
    /// The exact `DP` (with `dP/dp` as a last column if a parameter was asked for), row-major.
    pub exact: Vec<Vec<f64>>,
    /// Its error estimate: its change at looser tolerances.
    pub exact_error: f64,
    /// The same by central differences extrapolated by Richardson, each column at the finer of the two
    /// successive [`CHECK_STEPS`] that agree best, row-major.
    pub finite_difference: Vec<Vec<f64>>,
    /// Their error estimate: twice the chosen step's agreement with the steps on either side (the largest over
    /// the columns).
    pub finite_difference_error: f64,
    /// The largest entry of `|exact - finite_difference|`.
    pub difference: f64,
    /// `difference <= exact_error + finite_difference_error`.
    pub agree: bool,
    /// Why the check could not be made (the map is not differentiable at the point, or a perturbed walk
    /// failed); `agree` is then false.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
}

impl RigidDerivativeCheck {
    /// A check that could not be made, and why.
    pub fn failed(failure: String) -> RigidDerivativeCheck {
        RigidDerivativeCheck {
            parameter: None,
            exact: Vec::new(),
            exact_error: f64::NAN,
            finite_difference: Vec::new(),
            finite_difference_error: f64::NAN,
            difference: f64::NAN,
            agree: false,
            failure: Some(failure),
        }
    }
}

/// Why the check could not be made.
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    /// The exact derivatives, or a walk of the differences, failed.
    #[error(transparent)]
    Derivative(#[from] DerivativeError),
    /// The parameter moved by the differences' step is invalid.
    #[error(transparent)]
    Parameter(#[from] ConfigError),
}

/// `[DP | dP/dp]` exactly (the last column only with a parameter).
fn exact<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    s: &DVector<f64>,
    param: Option<&str>,
    options: &RigidOptions,
) -> Result<DMatrix<f64>, DerivativeError> {
    let d = walker.step_map_derivative(s, param, 1, options)?;
    let n = s.len();
    let columns = n + usize::from(d.dparam.is_some());
    Ok(DMatrix::from_fn(n, columns, |i, k| match &d.dparam {
        Some(dp) if k == n => dp[i],
        _ => d.jacobian[(i, k)],
    }))
}

/// `[DP | dP/dp]` by Richardson-extrapolated central differences at each of [`CHECK_STEPS`], each column taken
/// at the finer of the two successive steps that agree best, and its error estimate (the largest over the
/// columns of twice its agreement with the steps on either side).
fn differences<W, const N: usize, const Y: usize>(
    walker: &W,
    s: &DVector<f64>,
    param: Option<(&str, f64)>,
    options: &RigidOptions,
) -> Result<(DMatrix<f64>, f64), CheckError>
where
    W: RigidWalker<N, Y> + Parametrized,
{
    let n = s.len();
    let columns = n + usize::from(param.is_some());
    // P at (s + t e_k) (the coordinate k) or at the parameter p + t (k = n).
    let at = |k: usize, t: f64| -> Result<DVector<f64>, CheckError> {
        let walked = if k < n {
            let mut x = s.clone();
            x[k] += t;
            rigid_step_map(walker, &x, options)
        } else {
            let (key, p) = param.expect("a parameter's column");
            rigid_step_map(&walker.with_parameter(key, p + t)?, s, options)
        };
        Ok(walked.map_err(DerivativeError::from)?.0)
    };
    let sizes: Vec<f64> = (0..columns)
        .map(|k| {
            if k < n {
                s[k]
            } else {
                param.map_or(0.0, |(_, p)| p)
            }
        })
        .collect();
    richardson_jacobian(n, &sizes, at)
}

/// The Jacobian of a map into `R^rows` whose columns are the directions `k` of `sizes` (each of the size
/// `sizes[k]`), from `at(k, t)`, the map with direction `k` moved by `t`: Richardson-extrapolated central
/// differences at each of [`CHECK_STEPS`] (relative to the size, at least 1), each column taken at the finer of
/// the two successive steps that agree best; with its error estimate (the largest over the columns of twice
/// its agreement with the steps on either side). Hand-written: the difference crates take one step.
pub fn richardson_jacobian<E>(
    rows: usize,
    sizes: &[f64],
    at: impl Fn(usize, f64) -> Result<DVector<f64>, E>,
) -> Result<(DMatrix<f64>, f64), E> {
    let columns = sizes.len();
    let (mut chosen, mut error) = (DMatrix::zeros(rows, columns), 0.0f64);
    for (k, size) in sizes.iter().enumerate() {
        let central =
            |h: f64| -> Result<DVector<f64>, E> { Ok((at(k, h)? - at(k, -h)?) / (2.0 * h)) };
        let mut extrapolated = Vec::with_capacity(CHECK_STEPS.len());
        for step in CHECK_STEPS {
            let h = step * size.abs().max(1.0);
            extrapolated.push((central(0.5 * h)? * 4.0 - central(h)?) / 3.0);
        }
        // The finer of the two successive steps that agree best; its error, twice the larger of its agreements
        // with the steps on either side (two values whose noise differs agree closer than either is right, by up
        // to about that).
        let agreement: Vec<f64> = extrapolated
            .windows(2)
            .map(|pair| (&pair[1] - &pair[0]).amax())
            .collect();
        let i = (0..agreement.len())
            .min_by(|&a, &b| agreement[a].total_cmp(&agreement[b]))
            .expect("at least two steps");
        let (best, spread) = (
            &extrapolated[i + 1],
            2.0 * agreement[i].max(agreement.get(i + 1).copied().unwrap_or(0.0)),
        );
        chosen.set_column(k, best);
        error = error.max(spread);
    }
    Ok((chosen, error))
}

/// Checks the exact `DP` (and `dP/dp` in `param`, one of the walker's keys) of `walker` at `s` against
/// Richardson-extrapolated central differences (see the module documentation).
pub fn check_rigid_derivatives<W, const N: usize, const Y: usize>(
    walker: &W,
    s: &DVector<f64>,
    param: Option<&str>,
    options: &RigidOptions,
) -> Result<RigidDerivativeCheck, CheckError>
where
    W: RigidWalker<N, Y> + Parametrized,
{
    let mut looser = *options;
    looser.tolerances.rtol *= CHECK_LOOSENING;
    looser.tolerances.atol *= CHECK_LOOSENING;
    let exact_run = exact(walker, s, param, options)?;
    let with_value = param.map(|key| (key, parameter_value(walker, key).unwrap_or(f64::NAN)));
    let exact_error = (&exact_run - exact(walker, s, param, &looser)?).amax();
    let (fd, fd_error) = differences(walker, s, with_value, options)?;
    let difference = (&exact_run - &fd).amax();
    let rows = |m: &DMatrix<f64>| m.row_iter().map(|r| r.iter().copied().collect()).collect();
    Ok(RigidDerivativeCheck {
        parameter: param.map(str::to_string),
        exact: rows(&exact_run),
        exact_error,
        finite_difference: rows(&fd),
        finite_difference_error: fd_error,
        difference,
        agree: difference <= exact_error + fd_error,
        failure: None,
    })
}
