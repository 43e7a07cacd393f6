//! A legged walker's step map with one parameter free, as a family for the continuation engine
//! ([`crate::continuation`], docs/model.md section 13): its gaits followed through folds, its period doublings
//! and Neimark-Sacker points located by the engine's test functions, and the DLS indicators of its heel strike
//! (`lambda_I4`, `lambda_2+`, `lambda_4+`) as the borders where the heel strike changes its branch (double
//! support or none, a bounce).
//!
//! `DP` and `dP/dp` are the exact derivatives of the replay ([`LeggedDerivatives::exact_step_map`], chained over
//! the `k` steps of `P^k`); where the step map has none (a DLS indicator at zero, a grazing event), Richardson-
//! extrapolated central differences ([`richardson_jacobian`]) marked as not exact, with their error estimate in
//! the point's record ([`LeggedInfo::derivative_error`]).

use std::marker::PhantomData;

use nalgebra::{DMatrix, DVector};

use super::derivative::{LeggedDerivativeError, LeggedDerivatives};
use super::gait::legged_step_map;
use super::walk::{LeggedOptions, StepAccount};
use super::{Legged, LeggedError};
use crate::continuation::{Evaluation, FamilyMap, MapFailure};
use crate::mechanism::derivative_check::richardson_jacobian;
use crate::mechanism::rigid_family::{FreeParameter, Parametrized};
use crate::params::ConfigError;

/// What the family records of a point: its (first) step's duration and heel strike, and the error estimate of
/// its derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeggedInfo {
    /// The duration of the (first) step \[s\].
    pub period: f64,
    /// Its heel strike and audits.
    pub account: StepAccount,
    /// The error estimate of `DP` and `dP/dp` where they are Richardson's differences (`NaN` where they are exact
    /// or were not taken).
    pub derivative_error: f64,
}

/// The step map `P` (or `P^k`) of a legged walker in the parameter `key`.
#[derive(Debug)]
pub struct LeggedFamily<'a, W, const N: usize, const Y: usize> {
    free: FreeParameter<'a, W>,
    period: usize,
    options: LeggedOptions,
    dims: PhantomData<[(); N]>,
}

impl<W, const N: usize, const Y: usize> Clone for LeggedFamily<'_, W, N, Y> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<W, const N: usize, const Y: usize> Copy for LeggedFamily<'_, W, N, Y> {}

impl<'a, W: Legged<N> + Parametrized, const N: usize, const Y: usize> LeggedFamily<'a, W, N, Y> {
    /// The family of `walker` in `key` (one of its [`Parametrized::parameter_keys`]).
    pub fn new(walker: &'a W, key: &str) -> Result<LeggedFamily<'a, W, N, Y>, ConfigError> {
        Ok(LeggedFamily {
            free: FreeParameter::new(walker, key)?,
            period: 1,
            options: LeggedOptions::default(),
            dims: PhantomData,
        })
    }

    /// The same family walked with `options` (an interrupt, tolerances).
    pub fn with_options(self, options: LeggedOptions) -> LeggedFamily<'a, W, N, Y> {
        LeggedFamily { options, ..self }
    }

    /// `P^k(x)` of `walker` and the first step's record.
    fn walked(
        &self,
        walker: &W,
        x: &DVector<f64>,
    ) -> Result<(DVector<f64>, LeggedInfo), MapFailure> {
        let mut s = x.clone();
        let mut info = None;
        for _ in 0..self.period {
            let (next, step) =
                legged_step_map::<W, N, Y>(walker, &s, &self.options).map_err(failure)?;
            info.get_or_insert(LeggedInfo {
                period: step.period,
                account: step.account,
                derivative_error: f64::NAN,
            });
            s = next;
        }
        let info = info.unwrap_or(LeggedInfo {
            period: 0.0,
            account: StepAccount::default(),
            derivative_error: f64::NAN,
        });
        Ok((s, info))
    }
}

/// A failed walk as the continuation engine reports it.
fn failure(e: LeggedError) -> MapFailure {
    MapFailure {
        kind: e.kind().to_string(),
        message: e.to_string(),
    }
}

impl<W: LeggedDerivatives<N> + Parametrized, const N: usize, const Y: usize>
    LeggedFamily<'_, W, N, Y>
{
    /// `P^k(x)` of `walker` with its exact `DP^k` and `dP^k/dp` (the chain rule over the `k` steps) and the first
    /// step's record; `Ok(None)` where a step has no derivative.
    #[allow(clippy::type_complexity)]
    fn exact(
        &self,
        walker: &W,
        x: &DVector<f64>,
    ) -> Result<Option<Evaluation<LeggedInfo>>, MapFailure> {
        let n = x.len();
        let (mut s, mut jacobian, mut dparam) =
            (x.clone(), DMatrix::identity(n, n), DVector::zeros(n));
        let mut info = None;
        for _ in 0..self.period {
            let d = match walker.exact_step_map(&s, Some(self.free.key()), &self.options) {
                Ok(d) => d,
                Err(LeggedDerivativeError::Walk(e)) => return Err(failure(e)),
                Err(_) => return Ok(None),
            };
            let dp = d.dparam.unwrap_or_else(|| DVector::zeros(n));
            dparam = &d.jacobian * dparam + dp;
            jacobian = &d.jacobian * jacobian;
            info.get_or_insert(LeggedInfo {
                period: d.step.period,
                account: d.step.account,
                derivative_error: f64::NAN,
            });
            s = d.value;
        }
        Ok(info.map(|info| Evaluation {
            value: s,
            jacobian,
            dparam,
            exact: true,
            info,
        }))
    }
}

impl<W, const N: usize, const Y: usize> FamilyMap for LeggedFamily<'_, W, N, Y>
where
    W: LeggedDerivatives<N> + Parametrized + Sync,
{
    type Info = LeggedInfo;

    fn dim(&self) -> usize {
        self.free.walker().section_names().len()
    }

    /// `P^k(x; p)` with its exact `DP` and `dP/dp`, or where the map has none Richardson-extrapolated central
    /// differences ([`richardson_jacobian`]: the columns of `x`'s coordinates and of the parameter, each relative
    /// to its size).
    fn eval(&self, x: &DVector<f64>, p: f64) -> Result<Evaluation<LeggedInfo>, MapFailure> {
        let walker = self.free.at(p)?;
        if let Some(exact) = self.exact(&walker, x)? {
            return Ok(exact);
        }
        let (value, mut info) = self.walked(&walker, x)?;
        let n = x.len();
        let sizes: Vec<f64> = x.iter().copied().chain([p]).collect();
        let (both, error) = richardson_jacobian(n, &sizes, |k, t| {
            if k < n {
                let mut moved = x.clone();
                moved[k] += t;
                Ok(self.walked(&walker, &moved)?.0)
            } else {
                Ok(self.walked(&self.free.at(p + t)?, x)?.0)
            }
        })?;
        info.derivative_error = error;
        Ok(Evaluation {
            value,
            jacobian: both.columns(0, n).into_owned(),
            dparam: both.column(n).into_owned(),
            exact: false,
            info,
        })
    }

    fn value(&self, x: &DVector<f64>, p: f64) -> Result<DVector<f64>, MapFailure> {
        let walker = self.free.at(p)?;
        Ok(self.walked(&walker, x)?.0)
    }

    fn iterated(&self, k: usize) -> Self {
        LeggedFamily {
            period: self.period * k.max(1),
            ..*self
        }
    }

    fn period(&self) -> usize {
        self.period
    }

    /// The DLS indicators of the first heel strike: `lambda_I4` (negative: the rear tip leaves at once, (A3)),
    /// and, where (A1) was taken, `lambda_2+` (negative: the fore tip bounces) and `lambda_4+` (negative: (B3),
    /// no double support); `NaN` where not defined.
    fn borders(&self, info: &LeggedInfo) -> Vec<(&'static str, f64)> {
        let a = &info.account;
        vec![
            ("lambda_I4", a.lambda_i4),
            ("lambda_2+", a.lambda_2_plus.unwrap_or(f64::NAN)),
            ("lambda_4+", a.lambda_4_plus.unwrap_or(f64::NAN)),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanism::legged::gait::legged_gait_exact;
    use crate::mechanism::rigid_gait::multipliers;
    use crate::mechanism::telescopic::Telescopic;

    /// The continuation's `DP` at the telescopic walker's gait is the exact one and gives the gait search's
    /// multipliers, and its `dP/dp` in the viscosity agrees with a plain central difference of a coarser step
    /// (a second route, good to its truncation).
    #[test]
    fn the_familys_dp_agrees_with_the_gaits_multipliers() {
        let w = Telescopic::default();
        let options = LeggedOptions::default();
        let gait = legged_gait_exact::<_, 6, 13>(&w, &w.default_start(), &options).unwrap();
        let family = LeggedFamily::<_, 6, 13>::new(&w, "viscosity").unwrap();
        let e = family.eval(&gait.section, w.viscosity).unwrap();
        assert!(e.exact);
        assert!((&e.value - &gait.section).amax() < 1e-10);
        let (a, b) = (multipliers(&e.jacobian), &gait.multipliers);
        for (x, y) in a.iter().zip(b) {
            let d = (x[0] - y[0]).hypot(x[1] - y[1]);
            assert!(d < 1e-9, "{a:?} against {b:?}");
        }
        // P^2's derivatives by the chain rule: DP^2 at a fixed point is DP squared.
        let twice = family.iterated(2).eval(&gait.section, w.viscosity).unwrap();
        assert!((&twice.jacobian - &e.jacobian * &e.jacobian).amax() < 1e-9);
        let h = 1.0;
        let at = |c: f64| family.value(&gait.section, c).unwrap();
        let plain = (at(w.viscosity + h) - at(w.viscosity - h)) / (2.0 * h);
        assert!(
            (&plain - &e.dparam).amax() < 1e-6,
            "{plain} against {}",
            e.dparam
        );
        assert_eq!(
            family.borders(&e.info)[0],
            ("lambda_I4", gait.step.account.lambda_i4)
        );
    }

    /// A key the walker does not have is refused by name, with the keys it has.
    #[test]
    fn an_unknown_key_is_refused_by_name() {
        let w = Telescopic::default();
        let e = LeggedFamily::<_, 6, 13>::new(&w, "stifness").unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("stifness") && text.contains("viscosity"),
            "{text}"
        );
    }
}
