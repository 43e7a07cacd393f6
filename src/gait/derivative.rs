//! The Jacobian of a gait (docs/model.md sections 6 and 10): the exact `DP` (and `dP/dp`) of
//! [`StepMap::eval_with_derivatives`] with an error estimate that comes from the computation, and the
//! finite-difference route kept as its independent check ([`check_jacobian`], `vrw gait --check-jacobian`).
//!
//! **Error estimate.** The exact derivatives are exact for the discretized step map, which differs from the
//! model's by the integration error; so the estimate is the largest difference between `DP` at the run's
//! tolerances and `DP` at tolerances [`DERIVATIVE_CHECK_TIGHTENING`] times tighter (or looser, where the
//! tighter ones would pass the smallest `rtol` the integrator resolves). The stability verdict
//! ([`super::Stability`]) is built on it.

use nalgebra::DMatrix;
use serde::Serialize;

use super::step_map::{DerivativeError, StepMap, StepOutcome};
use crate::walk::SectionState;

/// The factor between the run's integration tolerances and those of the second computation of `DP` whose
/// difference is the error estimate.
pub const DERIVATIVE_CHECK_TIGHTENING: f64 = 100.0;

/// The smallest relative tolerance the error estimate tightens to: below it the integration is at rounding
/// level, and the estimate loosens the tolerances instead.
const TIGHTEST_RTOL: f64 = 1e-14;

/// The factor on the tolerances of `map` for the second computation: `1 / DERIVATIVE_CHECK_TIGHTENING`, or
/// `DERIVATIVE_CHECK_TIGHTENING` where the tighter tolerances would pass [`TIGHTEST_RTOL`].
fn second_tolerance_factor(map: &StepMap) -> f64 {
    if map.options().rtol / DERIVATIVE_CHECK_TIGHTENING >= TIGHTEST_RTOL {
        1.0 / DERIVATIVE_CHECK_TIGHTENING
    } else {
        DERIVATIVE_CHECK_TIGHTENING
    }
}

/// `dP/dp` of a gait for one parameter (`gait.json`'s `dP_dparam`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParamDerivative {
    /// The parameter's key.
    pub parameter: &'static str,
    /// `dP/dp` over the free section coordinates.
    pub values: Vec<f64>,
    /// Its error estimate, as that of `DP`.
    pub error: f64,
}

/// `DP` at a point with its error estimate, and `dP/dp` if asked for.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GaitJacobian {
    /// `DP` over the free coordinates.
    pub(crate) jacobian: DMatrix<f64>,
    /// The largest difference to `DP` at tightened tolerances (`NaN` if not estimated).
    pub(crate) error: f64,
    /// `dP/dp`.
    pub(crate) dparam: Option<ParamDerivative>,
    /// The event sequence of the walk ([`super::StepMap::eval_signature`]).
    pub(crate) signature: String,
    /// The step map's value at the point: the walk of the derivatives (the one [`StepMap::eval`] takes).
    pub(crate) outcome: StepOutcome,
}

/// The exact `DP` of `map` at `s` (and `dP/dp` for `param`), with the error estimate where `estimate.0` (and
/// of `dP/dp` where `estimate.1` too: `GaitOptions::refine_jacobian` and `refine_dparam`).
pub(crate) fn gait_jacobian(
    map: &StepMap,
    s: &SectionState,
    param: Option<&'static str>,
    estimate: (bool, bool),
) -> Result<GaitJacobian, DerivativeError> {
    let map = &map.on_section_of(s);
    let other_map = map.with_tolerances_scaled(second_tolerance_factor(map));
    let other_param = param.filter(|_| estimate.1);
    // The two computations are independent: both cores.
    let (at, other) = crate::meter::join(
        || map.eval_with_derivatives(s, param),
        || {
            estimate
                .0
                .then(|| other_map.eval_with_derivatives(s, other_param))
        },
    );
    let at = at?;
    let (error, dparam_error) = match other.transpose()? {
        Some(other) => {
            let dparam_error = match (&at.dparam, &other.dparam) {
                (Some(a), Some(b)) => (a - b).amax(),
                _ => f64::NAN,
            };
            ((&at.jacobian - &other.jacobian).amax(), dparam_error)
        }
        None => (f64::NAN, f64::NAN),
    };
    Ok(GaitJacobian {
        jacobian: at.jacobian,
        error,
        dparam: param
            .zip(at.dparam)
            .map(|(parameter, values)| ParamDerivative {
                parameter,
                values: values.iter().copied().collect(),
                error: dparam_error,
            }),
        signature: at.signature,
        outcome: at.outcome,
    })
}

/// `DP` at `s` for Newton's method: exact where the map is differentiable, else one central difference with
/// relative step `fd_step` (a Newton matrix need not be exact).
pub(crate) fn newton_jacobian(
    map: &StepMap,
    s: &SectionState,
    fd_step: f64,
) -> Result<DMatrix<f64>, crate::walk::WalkError> {
    match map.eval_with_derivatives(s, None) {
        Ok(d) => Ok(d.jacobian),
        Err(DerivativeError::Walk(e)) => Err(e),
        Err(_) => map.central_jacobian(s, fd_step),
    }
}

/// The exact `DP` against the finite-difference one (`vrw gait --check-jacobian`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JacobianCheck {
    /// The exact `DP`, row-major.
    pub exact: Vec<Vec<f64>>,
    /// Its error estimate (tightened tolerances).
    pub exact_error: f64,
    /// `DP` by central differences with Richardson extrapolation, row-major, at the tighter of the run's
    /// tolerances and the second computation's ([`check_jacobian`]).
    pub finite_difference: Vec<Vec<f64>>,
    /// The relative integration tolerance of [`JacobianCheck::finite_difference`].
    pub finite_difference_rtol: f64,
    /// The finite difference's own error estimate: its truncation (the extrapolated against the plain
    /// difference) plus its noise (its change from the looser tolerances, see [`check_jacobian`]).
    pub finite_difference_error: f64,
    /// The largest entry of `|exact - finite_difference|`.
    pub difference: f64,
    /// `difference <= exact_error + finite_difference_error`: the two routes agree within their errors.
    pub agree: bool,
    /// Why the check could not be made (the map is not differentiable at the point, or a perturbed walk of the
    /// finite differences failed); `agree` is then false.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
}

impl JacobianCheck {
    /// A check that could not be made, and why.
    pub fn failed(failure: String) -> JacobianCheck {
        JacobianCheck {
            exact: Vec::new(),
            exact_error: f64::NAN,
            finite_difference: Vec::new(),
            finite_difference_rtol: f64::NAN,
            finite_difference_error: f64::NAN,
            difference: f64::NAN,
            agree: false,
            failure: Some(failure),
        }
    }
}

/// Compare the exact `DP` of `map` at `s` with central differences of relative step `fd_step` extrapolated
/// by Richardson.
///
/// A central difference's error is its truncation (`~h^2`, which Richardson's extrapolation removes to
/// `~h^4` and whose spread against the plain difference estimates it) plus the integration noise of the
/// perturbed walks divided by the step (`~rtol / h`), which the spread does not see: on a period-5 gait of
/// stiff legs (`slope = 0.2`, `c = 300`, `k = 3000`) the noise at the default tolerances was 70 times the
/// spread, and the check failed although `DP` was right. So the differences are taken at both tolerances of
/// the exact `DP`'s error estimate (the run's and 100 times tighter, or looser where that would pass the
/// integrator's limit); the check uses the ones at the tighter tolerances, whose noise is bounded by their
/// change from the looser ones (a conservative bound: the noise falls with the tolerance).
pub fn check_jacobian(
    map: &StepMap,
    s: &SectionState,
    fd_step: f64,
) -> Result<JacobianCheck, DerivativeError> {
    let map = &map.on_section_of(s);
    let exact = gait_jacobian(map, s, None, (true, true))?;
    let factor = second_tolerance_factor(map);
    let other = map.with_tolerances_scaled(factor);
    // The two sets of walks are independent: both cores.
    let (at_run, at_other) =
        crate::meter::join(|| map.jacobian(s, fd_step), || other.jacobian(s, fd_step));
    let (at_run, at_other) = (at_run?, at_other?);
    let noise = (&at_run.0 - &at_other.0).amax();
    let ((fd, spread), tighter) = if factor < 1.0 {
        (at_other, &other)
    } else {
        (at_run, map)
    };
    let fd_error = spread + noise;
    let difference = (&exact.jacobian - &fd).amax();
    let rows = |m: &DMatrix<f64>| m.row_iter().map(|r| r.iter().copied().collect()).collect();
    Ok(JacobianCheck {
        exact: rows(&exact.jacobian),
        exact_error: exact.error,
        finite_difference: rows(&fd),
        finite_difference_rtol: tighter.options().rtol,
        finite_difference_error: fd_error,
        difference,
        agree: difference <= exact.error + fd_error,
        failure: None,
    })
}
