//! The step map of the VRW as a one-parameter family (docs/model.md section 11): `P(s; p)` on the free section
//! coordinates, with one configuration key as the parameter, its exact `DP` and `dP/dp`
//! ([`StepMap::eval_with_derivatives`]), the DLS indicators as the borders between its smooth pieces, and the
//! event sequence of the step as the piece.

use std::sync::atomic::AtomicBool;

use nalgebra::{DMatrix, DVector};

use super::{Evaluation, FamilyMap, MapFailure};
use crate::dynamics::{Model, DIFFERENTIABLE_KEYS};
use crate::gait::{DerivativeError, StepMap};
use crate::params::{Config, ImpactModel};
use crate::walk::{Branch, SectionState, StepReport};

/// What a point of a gait family records: the (first) step's report and the event sequence of the walk.
#[derive(Debug, Clone, PartialEq)]
pub struct GaitInfo {
    /// The report of the step from the point (of its first step for a period-k family).
    pub report: StepReport,
    /// The event sequence ([`StepMap::eval_signature`]).
    pub signature: String,
}

/// The VRW's step map (or its `k`-th iterate) with one parameter free.
#[derive(Debug, Clone, Copy)]
pub struct GaitFamily<'a> {
    config: &'a Config,
    param: &'static str,
    period: usize,
    /// The section state whose coordinates that are not free (with rigid legs) every point keeps.
    base: SectionState,
    /// Relative step of the central differences where the map is not differentiable.
    fd_step: f64,
    interrupt: Option<&'a AtomicBool>,
}

impl<'a> GaitFamily<'a> {
    /// The family of `config` in the numeric key `param` (exact `dP/dp` for the keys of
    /// [`DIFFERENTIABLE_KEYS`], a central difference for the others), around `base`.
    pub fn new(
        config: &'a Config,
        param: &str,
        base: SectionState,
    ) -> Result<GaitFamily<'a>, MapFailure> {
        let Some(&param) = Config::numeric_keys().iter().find(|k| **k == param) else {
            return Err(MapFailure {
                kind: "unknown_parameter".to_string(),
                message: format!(
                    "unknown parameter {param:?}: expected one of {}",
                    Config::numeric_keys().join(", ")
                ),
            });
        };
        Ok(GaitFamily {
            config,
            param,
            period: 1,
            base,
            fd_step: 1e-6,
            interrupt: None,
        })
    }

    /// The same family, whose walks stop when `flag` is set.
    pub fn with_interrupt(self, flag: Option<&'a AtomicBool>) -> GaitFamily<'a> {
        GaitFamily {
            interrupt: flag,
            ..self
        }
    }

    /// The parameter's key.
    pub fn param(&self) -> &'static str {
        self.param
    }

    /// The configuration with the parameter at `p`, and its model.
    fn configured(&self, p: f64) -> Result<(Config, Model), MapFailure> {
        let invalid = |message: String| MapFailure {
            kind: "invalid_parameter".to_string(),
            message,
        };
        let c = self
            .config
            .with(self.param, p)
            .map_err(|e| invalid(e.to_string()))?;
        let model = Model::new(&c.params).map_err(|e| invalid(e.to_string()))?;
        Ok((c, model))
    }

    /// The free coordinates of a section state.
    pub fn reduce(&self, s: &SectionState) -> DVector<f64> {
        if self.config.params.rigid_legs {
            DVector::from_element(1, s.theta_dot)
        } else {
            DVector::from_column_slice(&s.to_array())
        }
    }

    /// The section state of the free coordinates `x`.
    pub fn expand(&self, x: &DVector<f64>) -> SectionState {
        if self.config.params.rigid_legs {
            SectionState {
                theta_dot: x[0],
                ..self.base
            }
        } else {
            SectionState::from_array([x[0], x[1], x[2]])
        }
    }

    /// `P(x; p)` at the parameter `p` (walk failures named by kind).
    fn outcome(&self, x: &DVector<f64>, p: f64) -> Result<DVector<f64>, MapFailure> {
        let (c, model) = self.configured(p)?;
        let map = self.step_map(&model, &c);
        let out = map.eval(&self.expand(x)).map_err(walk_failure)?;
        Ok(self.reduce(&out.next))
    }

    /// The step map of `model`.
    fn step_map<'m>(&self, model: &'m Model, c: &Config) -> StepMap<'m>
    where
        'a: 'm,
    {
        StepMap::new(model, &c.solver)
            .iterated(self.period)
            .with_interrupt(self.interrupt)
    }

    /// `dP/dp` by central differences.
    fn dparam_by_difference(&self, x: &DVector<f64>, p: f64) -> Result<DVector<f64>, MapFailure> {
        let step = self.fd_step * p.abs().max(1.0);
        Ok((self.outcome(x, p + step)? - self.outcome(x, p - step)?) / (2.0 * step))
    }
}

/// A walk failure as a map failure.
fn walk_failure(e: crate::walk::WalkError) -> MapFailure {
    MapFailure {
        kind: e.kind().to_string(),
        message: e.to_string(),
    }
}

impl<'a> FamilyMap for GaitFamily<'a> {
    type Info = GaitInfo;

    fn dim(&self) -> usize {
        if self.config.params.rigid_legs {
            1
        } else {
            3
        }
    }

    fn eval(&self, x: &DVector<f64>, p: f64) -> Result<Evaluation<GaitInfo>, MapFailure> {
        let (c, model) = self.configured(p)?;
        let map = self.step_map(&model, &c);
        let s = self.expand(x);
        let key = DIFFERENTIABLE_KEYS
            .contains(&self.param)
            .then_some(self.param);
        match map.eval_with_derivatives(&s, key) {
            Ok(d) => {
                let exact = d.dparam.is_some();
                let dparam = match d.dparam {
                    Some(v) => v,
                    None => self.dparam_by_difference(x, p)?,
                };
                Ok(Evaluation {
                    value: self.reduce(&d.outcome.next),
                    jacobian: d.jacobian,
                    dparam,
                    exact,
                    info: GaitInfo {
                        report: d.outcome.report,
                        signature: d.signature,
                    },
                })
            }
            Err(DerivativeError::Walk(e)) => Err(walk_failure(e)),
            // Not differentiable here (a border, a grazing, two events at once): central differences, or no
            // derivatives where a perturbed walk fails (the point is within the difference step of the end of
            // the map's domain).
            Err(_) => {
                let (out, signature) = map.eval_signature(&s).map_err(walk_failure)?;
                let n = self.dim();
                let jacobian = map
                    .central_jacobian(&s, self.fd_step)
                    .unwrap_or_else(|_| DMatrix::from_element(n, n, f64::NAN));
                let dparam = self
                    .dparam_by_difference(x, p)
                    .unwrap_or_else(|_| DVector::from_element(n, f64::NAN));
                Ok(Evaluation {
                    value: self.reduce(&out.next),
                    jacobian,
                    dparam,
                    exact: false,
                    info: GaitInfo {
                        report: out.report,
                        signature,
                    },
                })
            }
        }
    }

    fn value(&self, x: &DVector<f64>, p: f64) -> Result<DVector<f64>, MapFailure> {
        self.outcome(x, p)
    }

    fn iterated(&self, k: usize) -> GaitFamily<'a> {
        GaitFamily {
            period: self.period * k.max(1),
            ..*self
        }
    }

    fn period(&self) -> usize {
        self.period
    }

    /// The DLS indicators that decide the impact procedure's branch: `lambda_I4` (between (A1) and (A3)) and,
    /// where it is not negative, `lambda_2+` and `lambda_4+` (between (B2), the bounce and (B3)); none for rigid
    /// legs, the traditional impact or a landing with the rear leg in the air.
    fn borders(&self, info: &GaitInfo) -> Vec<(&'static str, f64)> {
        let p = &self.config.params;
        let r = &info.report;
        if p.rigid_legs || p.impact != ImpactModel::Dlsi || r.branch == Branch::RearAirborne {
            return Vec::new();
        }
        let i = &r.indicators;
        let after = if i.lambda_i4 >= 0.0 { 1.0 } else { f64::NAN };
        vec![
            ("lambda_I4", i.lambda_i4),
            ("lambda_2_plus", after * i.lambda_2_plus),
            ("lambda_4_plus", after * i.lambda_4_plus),
        ]
    }

    fn piece(&self, info: &GaitInfo) -> String {
        info.signature.clone()
    }
}
