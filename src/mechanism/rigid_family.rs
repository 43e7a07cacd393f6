//! A rigid-legged walker's step map with one parameter free, as a family for the continuation engine
//! ([`crate::continuation`]): its gaits followed through folds, its period doublings and Neimark-Sacker points
//! located by the engine's test functions, and its DLS indicator `lambda_I4` as the border where the heel
//! strike would stop the walker in double support (docs/model.md section 13).
//!
//! `DP` and `dP/dp` are exact ([`super::rigid_derivative`]: the variational equations over the walk's steps, in
//! the parameter through the constants as dual numbers). Where the map has no derivative (a grazing heel
//! strike, `lambda_I4` at 0) a point fails (`not_differentiable`), or, where the options ask for it
//! ([`RigidOptions::difference_fallback`]), takes central differences ([`DIFFERENCE_STEP`]) marked as not exact.

use std::marker::PhantomData;

use nalgebra::DVector;

use super::rigid::{rigid_step, RigidError, RigidOptions, RigidWalker};
use super::rigid_derivative::DerivativeError;
use super::rigid_gait::{central_jacobian, DIFFERENCE_STEP};
use crate::continuation::{Evaluation, FamilyMap, MapFailure};
use crate::params::ConfigError;

/// A walker whose parameters can be set one at a time, by key.
pub trait Parametrized: Sized {
    /// The keys of its real-valued parameters.
    fn parameter_keys(&self) -> Vec<&'static str>;

    /// The same walker with the parameter `key` at `value`, validated.
    fn with_parameter(&self, key: &str, value: f64) -> Result<Self, ConfigError>;
}

/// A walker with one of its parameters free: the family's walker and key, and the walker at a value of it.
#[derive(Debug)]
pub struct FreeParameter<'a, W> {
    walker: &'a W,
    key: &'static str,
}

impl<W> Clone for FreeParameter<'_, W> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<W> Copy for FreeParameter<'_, W> {}

impl<'a, W: Parametrized> FreeParameter<'a, W> {
    /// `walker` with `key` free (one of its [`Parametrized::parameter_keys`], else an error naming them).
    pub fn new(walker: &'a W, key: &str) -> Result<FreeParameter<'a, W>, ConfigError> {
        let keys = walker.parameter_keys();
        let key =
            keys.iter()
                .copied()
                .find(|k| *k == key)
                .ok_or_else(|| ConfigError::UnknownKey {
                    key: key.to_string(),
                    known: keys.join(", "),
                })?;
        Ok(FreeParameter { walker, key })
    }

    /// The walker.
    pub fn walker(&self) -> &'a W {
        self.walker
    }

    /// The free key.
    pub fn key(&self) -> &'static str {
        self.key
    }

    /// The walker at the parameter value `p` (an invalid value fails the point, `invalid_parameter`).
    pub fn at(&self, p: f64) -> Result<W, MapFailure> {
        self.walker
            .with_parameter(self.key, p)
            .map_err(|e| MapFailure {
                kind: "invalid_parameter".to_string(),
                message: e.to_string(),
            })
    }
}

/// What the family records of a point: its step's duration and DLS indicator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidInfo {
    /// The duration of the (first) step.
    pub period: f64,
    /// `lambda_I4` of the (first) heel strike.
    pub lambda_i4: f64,
}

/// The step map `P` (or `P^k`) of `walker` in the parameter `key`.
#[derive(Debug)]
pub struct RigidFamily<'a, W, const N: usize, const Y: usize> {
    free: FreeParameter<'a, W>,
    period: usize,
    options: RigidOptions,
    dims: PhantomData<[(); N]>,
}

impl<W, const N: usize, const Y: usize> Clone for RigidFamily<'_, W, N, Y> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<W, const N: usize, const Y: usize> Copy for RigidFamily<'_, W, N, Y> {}

impl<'a, W: RigidWalker<N, Y> + Parametrized, const N: usize, const Y: usize>
    RigidFamily<'a, W, N, Y>
{
    /// The family of `walker` in `key` (one of its [`Parametrized::parameter_keys`]).
    pub fn new(walker: &'a W, key: &str) -> Result<RigidFamily<'a, W, N, Y>, ConfigError> {
        Ok(RigidFamily {
            free: FreeParameter::new(walker, key)?,
            period: 1,
            options: RigidOptions::default(),
            dims: PhantomData,
        })
    }

    /// The same family walked with `options` (an interrupt, tolerances).
    pub fn with_options(self, options: RigidOptions) -> RigidFamily<'a, W, N, Y> {
        RigidFamily { options, ..self }
    }

    /// `P^k(x)` with `DP` and `dP/dp` by central differences ([`DIFFERENCE_STEP`]), not exact.
    fn differences(
        &self,
        walker: &W,
        x: &DVector<f64>,
        p: f64,
    ) -> Result<Evaluation<RigidInfo>, MapFailure> {
        let (value, info) = self.walked(walker, x)?;
        let jacobian = central_jacobian(x, |x| Ok(self.walked(walker, x)?.0))?;
        let h = DIFFERENCE_STEP * p.abs().max(1.0);
        let at = |p: f64| -> Result<DVector<f64>, MapFailure> {
            Ok(self.walked(&self.free.at(p)?, x)?.0)
        };
        let dparam = (at(p + h)? - at(p - h)?) / (2.0 * h);
        Ok(Evaluation {
            value,
            jacobian,
            dparam,
            exact: false,
            info,
        })
    }

    /// `P^k(x)` of `walker` and the first step's record.
    fn walked(
        &self,
        walker: &W,
        x: &DVector<f64>,
    ) -> Result<(DVector<f64>, RigidInfo), MapFailure> {
        let (mut q, mut qd) = walker.state_at_section(x);
        let mut info = None;
        for _ in 0..self.period {
            let step = rigid_step(walker, &q, &qd, &self.options).map_err(failure)?;
            info.get_or_insert(RigidInfo {
                period: step.period,
                lambda_i4: step.lambda_i4,
            });
            (q, qd) = (step.q, step.qd);
        }
        let info = info.unwrap_or(RigidInfo {
            period: 0.0,
            lambda_i4: f64::NAN,
        });
        Ok((walker.section_of(&q, &qd), info))
    }
}

/// A failed walk as the continuation engine reports it.
fn failure(e: RigidError) -> MapFailure {
    MapFailure {
        kind: e.kind().to_string(),
        message: e.to_string(),
    }
}

impl<W, const N: usize, const Y: usize> FamilyMap for RigidFamily<'_, W, N, Y>
where
    W: RigidWalker<N, Y> + Parametrized + Sync,
{
    type Info = RigidInfo;

    fn dim(&self) -> usize {
        self.free.walker().section_names().len()
    }

    fn eval(&self, x: &DVector<f64>, p: f64) -> Result<Evaluation<RigidInfo>, MapFailure> {
        let walker = self.free.at(p)?;
        match walker.step_map_derivative(x, Some(self.free.key()), self.period, &self.options) {
            Ok(d) => Ok(Evaluation {
                value: d.value,
                jacobian: d.jacobian,
                dparam: d.dparam.expect("the parameter was asked for"),
                exact: true,
                info: RigidInfo {
                    period: d.step.period,
                    lambda_i4: d.step.lambda_i4,
                },
            }),
            Err(DerivativeError::Walk(e)) => Err(failure(e)),
            Err(DerivativeError::NotDifferentiable(_)) if self.options.difference_fallback => {
                self.differences(&walker, x, p)
            }
            Err(e) => Err(MapFailure {
                kind: match e {
                    DerivativeError::UnknownParameter { .. } => "unknown_parameter",
                    _ => "not_differentiable",
                }
                .to_string(),
                message: e.to_string(),
            }),
        }
    }

    fn value(&self, x: &DVector<f64>, p: f64) -> Result<DVector<f64>, MapFailure> {
        let walker = self.free.at(p)?;
        Ok(self.walked(&walker, x)?.0)
    }

    fn iterated(&self, k: usize) -> Self {
        RigidFamily {
            period: self.period * k.max(1),
            ..*self
        }
    }

    fn period(&self) -> usize {
        self.period
    }

    /// `lambda_I4` of the first heel strike: where it turns positive, the walker stops in double support.
    fn borders(&self, info: &RigidInfo) -> Vec<(&'static str, f64)> {
        vec![("lambda_I4", info.lambda_i4)]
    }
}
