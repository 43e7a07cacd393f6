//! The exact derivatives of a walker's step map checked by a second route (`vrw gait --model NAME
//! --check-jacobian`, and the tests): central differences of the walked map extrapolated by Richardson; and
//! `dP/dp` at a gait, exact or, where the map has none, by those differences ([`parameter_derivative`]). Any map
//! that gives its exact derivatives and its values ([`CheckedMap`]) is checked the same way: the rigid-legged
//! walkers' ([`RigidMap`]) and the walkers' with compliant legs (`super::legged::check`).
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
//! with the steps on either side its error estimate. The exact derivatives' error is estimated by their change
//! at [`CHECK_LOOSENING`] times looser tolerances (conservative: the error falls with the tolerance).

use std::marker::PhantomData;

use nalgebra::{DMatrix, DVector};

use super::rigid::{RigidOptions, RigidWalker};
use super::rigid_derivative::{parameter_value, DerivativeError};
use super::rigid_family::Parametrized;
use super::rigid_gait::{rigid_step_map, EXACT_ROUTE};
use super::sensitivity::NotDifferentiable;
use crate::integrate::Tolerances;
use crate::params::ConfigError;

/// Relative steps of the checking differences (each coordinate's step is one of these times its size, at least
/// 1), from coarse to fine.
pub const CHECK_STEPS: [f64; 5] = [1e-3, 3e-4, 1e-4, 3e-5, 1e-5];

/// The second tolerances of the error estimates are this much looser than the walk's.
pub const CHECK_LOOSENING: f64 = 100.0;

/// The exact derivatives against Richardson-extrapolated central differences (`gait.json`'s `jacobian_check`
/// for every walker).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DerivativeCheck {
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

impl DerivativeCheck {
    /// A check that could not be made, and why.
    pub fn failed(failure: String) -> DerivativeCheck {
        DerivativeCheck {
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

/// A step map with its exact derivatives, as the check sees it.
pub trait CheckedMap {
    /// Why its exact derivatives (or a walk) failed.
    type Failure: DerivativeFailure;

    /// How the exact derivatives are taken, in words (`gait.json`'s `derivative`).
    const EXACT: &'static str;

    /// `[DP | dP/dp]` at `s` exactly (the last column only with `param`), the walk's tolerances loosened by
    /// the factor `loosening` (1: its own).
    fn exact(
        &self,
        s: &DVector<f64>,
        param: Option<&str>,
        loosening: f64,
    ) -> Result<DMatrix<f64>, CheckError<Self::Failure>>;

    /// `P(s)`, with the parameter `key` moved to `value` where given as `Some((key, value))`.
    fn value(
        &self,
        s: &DVector<f64>,
        moved: Option<(&str, f64)>,
    ) -> Result<DVector<f64>, CheckError<Self::Failure>>;

    /// The value of the parameter `key`, `None` for no such key.
    fn parameter(&self, key: &str) -> Option<f64>;
}

/// An error of a walker's exact derivatives, which may say that the map has none at the point (rather than that
/// a walk failed).
pub trait DerivativeFailure: std::error::Error {
    /// Why the map has no exact derivative at the point, if that is the failure.
    fn not_differentiable(&self) -> Option<&NotDifferentiable>;
}

impl DerivativeFailure for DerivativeError {
    fn not_differentiable(&self) -> Option<&NotDifferentiable> {
        match self {
            DerivativeError::NotDifferentiable(reason) => Some(reason),
            _ => None,
        }
    }
}

/// Why a check, or `dP/dp`, could not be made (`E`: the walker's exact derivatives' error; by default the
/// rigid walkers').
#[derive(Debug, thiserror::Error)]
pub enum CheckError<E = DerivativeError> {
    /// The exact derivatives, or a walk of the differences, failed.
    #[error(transparent)]
    Derivative(E),
    /// The parameter moved by the differences' step is invalid.
    #[error(transparent)]
    Parameter(#[from] ConfigError),
}

/// What the check needs of a kind of walk, given by its options: the integrator's tolerances, and the step map
/// and its exact derivatives of a walker `W` walked with them (the rigid walk's here, the legged walk's in
/// `super::legged::check`).
pub trait Walk<W, const N: usize, const Y: usize>: Copy {
    /// Why the exact derivatives (or a walk) failed.
    type Failure: DerivativeFailure;

    /// How the exact derivatives are taken, in words (`gait.json`'s `derivative`).
    const EXACT: &'static str;

    /// The integrator's tolerances.
    fn tolerances(&mut self) -> &mut Tolerances;

    /// `P(s)` of `walker`.
    fn step_map(&self, walker: &W, s: &DVector<f64>) -> Result<DVector<f64>, Self::Failure>;

    /// `[DP | dP/dp]` of `walker` at `s` exactly (the last column only with `param`).
    fn exact(&self, walker: &W, s: &DVector<f64>, param: Option<&str>) -> Exact<Self::Failure>;

    /// The value of `walker`'s constant `key`, `None` for no such key.
    fn constant(walker: &W, key: &str) -> Option<f64>;
}

/// `[DP | dP/dp]`, or why not.
pub type Exact<E> = Result<DMatrix<f64>, E>;

/// A walker's step map walked with the options `O` of its kind of walk ([`Walk`]), as a [`CheckedMap`].
#[derive(Debug)]
pub struct WalkerMap<'w, W, O, const N: usize, const Y: usize> {
    walker: &'w W,
    options: O,
    dims: PhantomData<[(); N]>,
}

impl<'w, W, O, const N: usize, const Y: usize> WalkerMap<'w, W, O, N, Y> {
    /// The step map of `walker` walked with `options`.
    pub fn new(walker: &'w W, options: O) -> WalkerMap<'w, W, O, N, Y> {
        WalkerMap {
            walker,
            options,
            dims: PhantomData,
        }
    }
}

impl<W, O, const N: usize, const Y: usize> CheckedMap for WalkerMap<'_, W, O, N, Y>
where
    W: Parametrized,
    O: Walk<W, N, Y>,
{
    type Failure = O::Failure;

    const EXACT: &'static str = O::EXACT;

    fn exact(
        &self,
        s: &DVector<f64>,
        param: Option<&str>,
        loosening: f64,
    ) -> Result<DMatrix<f64>, CheckError<O::Failure>> {
        let mut options = self.options;
        let tolerances = options.tolerances();
        tolerances.rtol *= loosening;
        tolerances.atol *= loosening;
        options
            .exact(self.walker, s, param)
            .map_err(CheckError::Derivative)
    }

    fn value(
        &self,
        s: &DVector<f64>,
        moved: Option<(&str, f64)>,
    ) -> Result<DVector<f64>, CheckError<O::Failure>> {
        let at = moved
            .map(|(key, p)| self.walker.with_parameter(key, p))
            .transpose()?;
        let walker = at.as_ref().unwrap_or(self.walker);
        self.options
            .step_map(walker, s)
            .map_err(CheckError::Derivative)
    }

    fn parameter(&self, key: &str) -> Option<f64> {
        O::constant(self.walker, key)
    }
}

/// A rigid-legged walker's step map.
pub type RigidMap<'w, W, const N: usize, const Y: usize> = WalkerMap<'w, W, RigidOptions, N, Y>;

/// The rigid walk ([`super::rigid`]) and its exact derivatives ([`super::rigid_derivative`]).
impl<W: RigidWalker<N, Y>, const N: usize, const Y: usize> Walk<W, N, Y> for RigidOptions {
    type Failure = DerivativeError;

    const EXACT: &'static str = EXACT_ROUTE;

    fn tolerances(&mut self) -> &mut Tolerances {
        &mut self.tolerances
    }

    fn step_map(&self, walker: &W, s: &DVector<f64>) -> Result<DVector<f64>, DerivativeError> {
        Ok(rigid_step_map(walker, s, self)?.0)
    }

    fn exact(&self, walker: &W, s: &DVector<f64>, param: Option<&str>) -> Exact<DerivativeError> {
        let d = walker.step_map_derivative(s, param, 1, self)?;
        Ok(joined(&d.jacobian, d.dparam.as_ref()))
    }

    fn constant(walker: &W, key: &str) -> Option<f64> {
        parameter_value(walker, key)
    }
}

/// `[DP | dP/dp]`: `DP` with `dP/dp` as a last column where there is one.
pub fn joined(jacobian: &DMatrix<f64>, dparam: Option<&DVector<f64>>) -> DMatrix<f64> {
    let n = jacobian.ncols();
    let columns = n + usize::from(dparam.is_some());
    DMatrix::from_fn(jacobian.nrows(), columns, |i, k| match dparam {
        Some(dp) if k == n => dp[i],
        _ => jacobian[(i, k)],
    })
}

/// `[DP | dP/dp]` of `map` at `s` by Richardson-extrapolated central differences ([`richardson_jacobian`]: the
/// columns of the coordinates and of the parameter `param` at its value, each relative to its size), and
/// their error estimate.
fn differences<M: CheckedMap>(
    map: &M,
    s: &DVector<f64>,
    param: Option<(&str, f64)>,
) -> Result<(DMatrix<f64>, f64), CheckError<M::Failure>> {
    let n = s.len();
    let sizes: Vec<f64> = s.iter().copied().chain(param.map(|(_, p)| p)).collect();
    richardson_jacobian(n, &sizes, |k, t| match param {
        Some((key, p)) if k == n => map.value(s, Some((key, p + t))),
        _ => {
            let mut x = s.clone();
            x[k] += t;
            map.value(&x, None)
        }
    })
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

/// Checks the exact `DP` (and `dP/dp` in `param`, one of the map's parameters) of `map` at `s` against
/// Richardson-extrapolated central differences (see the module documentation).
pub fn check_derivatives<M: CheckedMap>(
    map: &M,
    s: &DVector<f64>,
    param: Option<&str>,
) -> Result<DerivativeCheck, CheckError<M::Failure>> {
    let exact_run = map.exact(s, param, 1.0)?;
    let with_value = param.map(|key| (key, map.parameter(key).unwrap_or(f64::NAN)));
    let exact_error = (&exact_run - map.exact(s, param, CHECK_LOOSENING)?).amax();
    let (fd, fd_error) = differences(map, s, with_value)?;
    let difference = (&exact_run - &fd).amax();
    let rows = |m: &DMatrix<f64>| m.row_iter().map(|r| r.iter().copied().collect()).collect();
    Ok(DerivativeCheck {
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

/// Checks the exact `DP` (and `dP/dp` in `param`, one of the walker's keys) of `walker` at `s` against
/// Richardson-extrapolated central differences ([`check_derivatives`] of its [`RigidMap`]).
pub fn check_rigid_derivatives<W, const N: usize, const Y: usize>(
    walker: &W,
    s: &DVector<f64>,
    param: Option<&str>,
    options: &RigidOptions,
) -> Result<DerivativeCheck, CheckError>
where
    W: RigidWalker<N, Y> + Parametrized,
{
    check_derivatives(&RigidMap::<W, N, Y>::new(walker, *options), s, param)
}

/// `dP/dp` at a point, and how it was taken.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterDerivative {
    /// `dP/dp`, one value per section coordinate.
    pub values: DVector<f64>,
    /// How: exactly ([`CheckedMap::EXACT`]), or by Richardson's differences and why the map has no exact
    /// derivative there.
    pub derivative: String,
    /// The differences' error estimate ([`richardson_jacobian`]); `None` where exact.
    pub error: Option<f64>,
}

/// `dP/dp` of `map` at `s` in its parameter `key`: exact, or where the map has no derivative there
/// ([`DerivativeFailure::not_differentiable`]) Richardson-extrapolated central differences with their error
/// estimate, said in [`ParameterDerivative::derivative`].
pub fn parameter_derivative<M: CheckedMap>(
    map: &M,
    s: &DVector<f64>,
    key: &str,
) -> Result<ParameterDerivative, CheckError<M::Failure>> {
    let n = s.len();
    match map.exact(s, Some(key), 1.0) {
        Ok(both) => Ok(ParameterDerivative {
            values: both.column(n).into_owned(),
            derivative: M::EXACT.to_string(),
            error: None,
        }),
        Err(CheckError::Derivative(e)) => {
            let Some(reason) = e.not_differentiable() else {
                return Err(CheckError::Derivative(e));
            };
            let p = map.parameter(key).unwrap_or(f64::NAN);
            let (column, error) =
                richardson_jacobian(n, &[p], |_, t| map.value(s, Some((key, p + t))))?;
            Ok(ParameterDerivative {
                values: column.column(0).into_owned(),
                derivative: format!("richardson_differences (no exact derivative: {reason})"),
                error: Some(error),
            })
        }
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Why the toy map has no exact derivative, or failed.
    #[derive(Debug, thiserror::Error)]
    enum ToyError {
        #[error(transparent)]
        Corner(NotDifferentiable),
        #[error("the walk failed")]
        Failed,
    }

    impl DerivativeFailure for ToyError {
        fn not_differentiable(&self) -> Option<&NotDifferentiable> {
            match self {
                ToyError::Corner(reason) => Some(reason),
                ToyError::Failed => None,
            }
        }
    }

    /// `P(s; p) = (p s0^2, sin(p s1))` in closed form; its "exact" derivatives off by `offset` (a wrong one
    /// must be caught), or, with `corner`, refused as at a point where the map has none; `failing` fails them.
    struct Toy {
        p: f64,
        offset: f64,
        corner: bool,
        failing: bool,
    }

    impl CheckedMap for Toy {
        type Failure = ToyError;
        const EXACT: &'static str = "closed_form";

        fn exact(
            &self,
            s: &DVector<f64>,
            param: Option<&str>,
            _: f64,
        ) -> Result<DMatrix<f64>, CheckError<ToyError>> {
            if self.failing {
                return Err(CheckError::Derivative(ToyError::Failed));
            }
            if self.corner {
                let corner = NotDifferentiable::CoincidentEvents { time: 0.5 };
                return Err(CheckError::Derivative(ToyError::Corner(corner)));
            }
            let p = self.p;
            let jacobian =
                DMatrix::from_row_slice(2, 2, &[2.0 * p * s[0], 0.0, 0.0, p * (p * s[1]).cos()])
                    + DMatrix::repeat(2, 2, self.offset);
            let dparam = DVector::from_vec(vec![s[0] * s[0], s[1] * (p * s[1]).cos()]);
            Ok(joined(&jacobian, param.map(|_| &dparam)))
        }

        fn value(
            &self,
            s: &DVector<f64>,
            moved: Option<(&str, f64)>,
        ) -> Result<DVector<f64>, CheckError<ToyError>> {
            let p = moved.map_or(self.p, |(_, p)| p);
            Ok(DVector::from_vec(vec![p * s[0] * s[0], (p * s[1]).sin()]))
        }

        fn parameter(&self, key: &str) -> Option<f64> {
            (key == "p").then_some(self.p)
        }
    }

    fn toy() -> Toy {
        Toy {
            p: 1.3,
            offset: 0.0,
            corner: false,
            failing: false,
        }
    }

    /// The check passes the closed-form derivatives and catches ones off by 1e-6; `dP/dp` is the exact column
    /// where there is one, Richardson's differences (said, with their error estimate, which covers their
    /// distance from the closed form) where the map has none, and an error where the map failed.
    #[test]
    fn the_check_and_dp_dp_take_the_right_route() {
        let s = DVector::from_vec(vec![0.7, -0.4]);
        let check = check_derivatives(&toy(), &s, Some("p")).unwrap();
        assert!(check.agree && check.difference < 1e-9, "{check:?}");
        assert_eq!(check.exact[0].len(), 3);
        let off = Toy {
            offset: 1e-6,
            ..toy()
        };
        assert!(!check_derivatives(&off, &s, Some("p")).unwrap().agree);

        let exact = parameter_derivative(&toy(), &s, "p").unwrap();
        assert_eq!(
            (exact.derivative.as_str(), exact.error),
            ("closed_form", None)
        );
        let corner = Toy {
            corner: true,
            ..toy()
        };
        let fallback = parameter_derivative(&corner, &s, "p").unwrap();
        assert_eq!(
            fallback.derivative,
            "richardson_differences (no exact derivative: two events at t = 0.5: the step map has a corner \
             there and no derivative)"
        );
        let error = fallback.error.unwrap();
        let gap = (&fallback.values - &exact.values).amax();
        assert!(gap <= error.max(1e-12) && error < 1e-8, "{gap:e} {error:e}");
        let failing = Toy {
            failing: true,
            ..toy()
        };
        assert!(matches!(
            parameter_derivative(&failing, &s, "p"),
            Err(CheckError::Derivative(ToyError::Failed))
        ));
    }
}
