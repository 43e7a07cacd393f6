//! The derivatives `vrw gait --model NAME` writes beside a walker's gait (docs/model.md section 13): `dP/dp` in
//! one of its parameters (`--parameter KEY`, `gait.json`'s `dP_dparam`) and the check of the exact `DP` and
//! `dP/dp` against Richardson-extrapolated central differences (`--check-jacobian`, `jacobian_check`). One
//! code for every walker: the rigid-legged walkers' step maps and those of the walkers with compliant legs are
//! both a [`CheckedMap`].

use nalgebra::DVector;

use super::legged::legged_interruptible;
use super::walker_model::interruptible;
use super::AppError;
use crate::mechanism::derivative_check::{
    check_derivatives, parameter_derivative, CheckedMap, DerivativeCheck, ParameterDerivative,
    RigidMap,
};
use crate::mechanism::legged::check::LeggedMap;
use crate::mechanism::legged::derivative::LeggedDerivatives;
use crate::mechanism::rigid::RigidWalker;
use crate::mechanism::rigid_family::Parametrized;

/// What a gait search asks of its gait's derivatives.
#[derive(Debug, Clone, Copy)]
pub(super) struct Asked<'a> {
    /// `dP/dp` in this parameter (one of the walker's keys).
    pub parameter: Option<&'a str>,
    /// The check of the exact `DP` (and `dP/dp`) against Richardson-extrapolated differences.
    pub check: bool,
}

/// A gait's derivatives, as asked.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct GaitDerivatives {
    /// `dP/dp` in [`Asked::parameter`].
    pub dp_dparam: Option<ParameterDerivative>,
    /// The check of [`Asked::check`] (a check that could not be made says why).
    pub jacobian_check: Option<DerivativeCheck>,
}

/// The derivatives `asked` of `map` at the gait `section`.
fn gait_derivatives<M: CheckedMap>(
    map: &M,
    section: &DVector<f64>,
    asked: Asked<'_>,
) -> Result<GaitDerivatives, AppError> {
    let jacobian_check = asked.check.then(|| {
        check_derivatives(map, section, asked.parameter)
            .unwrap_or_else(|e| DerivativeCheck::failed(e.to_string()))
    });
    let dp_dparam = asked
        .parameter
        .map(|key| parameter_derivative(map, section, key))
        .transpose()
        .map_err(|e| AppError::InvalidOption {
            option: "parameter",
            reason: e.to_string(),
        })?;
    Ok(GaitDerivatives {
        dp_dparam,
        jacobian_check,
    })
}

/// The derivatives `asked` of the rigid-legged `walker` at its gait `section`.
pub(super) fn rigid_gait_derivatives<W, const N: usize, const Y: usize>(
    walker: &W,
    section: &DVector<f64>,
    asked: Asked<'_>,
) -> Result<GaitDerivatives, AppError>
where
    W: RigidWalker<N, Y> + Parametrized,
{
    let map = RigidMap::<W, N, Y>::new(walker, interruptible());
    gait_derivatives(&map, section, asked)
}

/// The derivatives `asked` of `walker`, a walker with compliant legs, at its gait `section`.
pub(super) fn legged_gait_derivatives<W, const N: usize, const Y: usize>(
    walker: &W,
    section: &DVector<f64>,
    asked: Asked<'_>,
) -> Result<GaitDerivatives, AppError>
where
    W: LeggedDerivatives<N> + Parametrized,
{
    let map = LeggedMap::<W, N, Y>::new(walker, legged_interruptible());
    gait_derivatives(&map, section, asked)
}
