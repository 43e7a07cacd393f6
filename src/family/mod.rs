//! The step map of the VRW as a one-parameter family (docs/model.md section 11): `P(s; p)` on the free section
//! coordinates, with one configuration key as the parameter, its exact `DP` and `dP/dp`
//! ([`StepMap::eval_with_derivatives`]), the DLS indicators as the borders between its smooth pieces, and the
//! event sequence of the step as the piece.

pub mod curves;
pub mod diagram;
pub(crate) mod end_search;
pub mod monitor;
pub mod natural;
pub mod parameter;

use std::sync::atomic::AtomicBool;

use nalgebra::{DMatrix, DVector};

use crate::continuation::{Evaluation, FamilyMap, MapFailure};
use crate::dynamics::DIFFERENTIABLE_KEYS;
use crate::gait::step_map::{expand, free_coordinates, reduce};
use crate::gait::{
    DerivativeError, SignedOutcome, StepMap, DERIVATIVE_CHECK_TIGHTENING, MAX_PERIOD,
};
use crate::params::ImpactModel;
use crate::walk::{Branch, SectionState, StepReport};
pub use parameter::{ParamPoint, Parameter};

/// The names of the border functions of each step of a period-k gait (up to [`MAX_PERIOD`] steps).
const BORDER_NAMES: [[&str; 3]; MAX_PERIOD] = [
    ["lambda_I4", "lambda_2_plus", "lambda_4_plus"],
    ["lambda_I4@2", "lambda_2_plus@2", "lambda_4_plus@2"],
    ["lambda_I4@3", "lambda_2_plus@3", "lambda_4_plus@3"],
    ["lambda_I4@4", "lambda_2_plus@4", "lambda_4_plus@4"],
    ["lambda_I4@5", "lambda_2_plus@5", "lambda_4_plus@5"],
    ["lambda_I4@6", "lambda_2_plus@6", "lambda_4_plus@6"],
    ["lambda_I4@7", "lambda_2_plus@7", "lambda_4_plus@7"],
    ["lambda_I4@8", "lambda_2_plus@8", "lambda_4_plus@8"],
];

/// What a point of a gait family records: the (first) step's report and the event sequence of the walk.
#[derive(Debug, Clone, PartialEq)]
pub struct GaitInfo {
    /// The report of the step from the point (of its first step for a period-k family).
    pub report: StepReport,
    /// The reports of all its steps (`k` for a period-k family).
    pub cycle: Vec<StepReport>,
    /// The event sequence ([`StepMap::eval_signature`]).
    pub signature: String,
}

impl GaitInfo {
    /// The record of a walk of the step map.
    fn of(signed: SignedOutcome) -> GaitInfo {
        GaitInfo {
            report: signed.outcome.report,
            cycle: signed.cycle,
            signature: signed.signature,
        }
    }

    /// The least period of the gait: the least `j` dividing the family's period `k` with the section state
    /// before the `j+1`-th touchdown within [`LEAST_PERIOD_TOL`] of the first (a family of `P^k` passes
    /// through gaits of any period dividing `k`).
    pub fn least_period(&self) -> usize {
        let k = self.cycle.len().max(1);
        (1..k)
            .filter(|j| k.is_multiple_of(*j))
            .find(|&j| self.cycle[j].section.distance(&self.cycle[0].section) < LEAST_PERIOD_TOL)
            .unwrap_or(k)
    }
}

/// Section states closer than this are one gait's (for [`GaitInfo::least_period`]).
pub const LEAST_PERIOD_TOL: f64 = 1e-6;

/// The VRW's step map (or its `k`-th iterate) with one parameter free.
#[derive(Debug, Clone, Copy)]
pub struct GaitFamily<'a> {
    parameter: Parameter<'a>,
    period: usize,
    /// The section state whose coordinates that are not free (with rigid legs, or Leg 2 held at its
    /// compression stop) every point keeps.
    base: SectionState,
    /// Leg 2 is held at its compression stop at `base`: the map acts on `dtheta/dt` alone
    /// ([`StepMap::on_section_of`]).
    rear_held: bool,
    /// Relative step of the central differences where the map is not differentiable.
    fd_step: f64,
    interrupt: Option<&'a AtomicBool>,
}

impl<'a> GaitFamily<'a> {
    /// The family in `parameter` (exact `dP/dp` for the keys of [`DIFFERENTIABLE_KEYS`], a central difference
    /// for the others), around `base`.
    pub fn new(parameter: Parameter<'a>, base: SectionState) -> GaitFamily<'a> {
        let params = &parameter.config().params;
        GaitFamily {
            parameter,
            period: 1,
            base: base.pinned_under(params),
            rear_held: base.rear_held_under(params),
            fd_step: 1e-6,
            interrupt: None,
        }
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
        self.parameter.key()
    }

    /// The parameter: the configuration and the key free in it.
    pub fn parameter(&self) -> Parameter<'a> {
        self.parameter
    }

    /// The configuration and the model at the parameter value `p` ([`Parameter::at`]), the broken rule as an
    /// `invalid_parameter` failure where `p` leaves the valid domain.
    pub fn at(&self, p: f64) -> Result<ParamPoint, MapFailure> {
        self.parameter.at(p).map_err(invalid_parameter)
    }

    /// `P(x; p, q)` with `DP` and `dP/dp`: this family in the configuration with the key `second` at `q` (a
    /// two-parameter curve's map, [`crate::continuation::curve`]).
    pub fn eval_with(
        &self,
        second: &str,
        x: &DVector<f64>,
        p: f64,
        q: f64,
    ) -> Result<Evaluation<GaitInfo>, MapFailure> {
        self.with_second(second, q, |family| family.eval(x, p))
    }

    /// `P(x; p)`'s record of its walk (without derivatives): the steps' reports and event sequence.
    pub fn value_with_info(&self, x: &DVector<f64>, p: f64) -> Result<GaitInfo, MapFailure> {
        self.walked(x, p).map(|(_, info)| info)
    }

    /// `P(x; p, q)` and what the map records, without derivatives (`jacobian` and `dparam` empty, `exact`
    /// false): a two-parameter curve's [`crate::continuation::CurveProblem::observe`].
    pub fn observe_with(
        &self,
        second: &str,
        x: &DVector<f64>,
        p: f64,
        q: f64,
    ) -> Result<Evaluation<GaitInfo>, MapFailure> {
        let (value, info) = self.with_second(second, q, |family| family.walked(x, p))?;
        Ok(Evaluation {
            value,
            jacobian: DMatrix::zeros(0, 0),
            dparam: DVector::zeros(0),
            exact: false,
            info,
        })
    }

    /// `f` of this family in the configuration with the key `second` at `q`.
    fn with_second<R>(
        &self,
        second: &str,
        q: f64,
        f: impl FnOnce(&GaitFamily) -> Result<R, MapFailure>,
    ) -> Result<R, MapFailure> {
        let config = self
            .parameter
            .fixing(second, q)
            .map_err(invalid_parameter)?;
        f(&GaitFamily {
            parameter: self.parameter.of(&config),
            ..*self
        })
    }

    /// `P(x; p)` and its walk's record, without derivatives.
    fn walked(&self, x: &DVector<f64>, p: f64) -> Result<(DVector<f64>, GaitInfo), MapFailure> {
        let at = self.at(p)?;
        let signed = self
            .step_map(&at)
            .eval_signature(&self.section_at(x, p))
            .map_err(walk_failure)?;
        Ok((self.reduce(&signed.outcome.next), GaitInfo::of(signed)))
    }

    /// The indices of the free coordinates ([`crate::walk::SECTION_COORDINATES`]): `dtheta/dt` alone with rigid
    /// legs or Leg 2 held at its compression stop, else `(L2, dtheta/dt, dL2/dt)`; and `slip` where Leg 2's tip
    /// slips at `base` (Coulomb friction).
    fn free(&self) -> &'static [usize] {
        free_coordinates(
            self.parameter.config().params.rigid_legs || self.rear_held,
            self.base.slips(),
        )
    }

    /// The free coordinates of a section state.
    pub fn reduce(&self, s: &SectionState) -> DVector<f64> {
        reduce(self.free(), s)
    }

    /// The section state of the free coordinates `x`.
    pub fn expand(&self, x: &DVector<f64>) -> SectionState {
        expand(self.free(), &self.base, x)
    }

    /// The section state of the free coordinates `x` at the parameter `p`: [`GaitFamily::expand`], except that a
    /// family held at its compression stop in `min_length` holds Leg 2 at the stop of `p` (`L2 = p`): the stop
    /// moves with the parameter, and the held leg with it.
    pub fn section_at(&self, x: &DVector<f64>, p: f64) -> SectionState {
        let s = self.expand(x);
        if self.rear_held && self.param() == "min_length" {
            SectionState { l2: p, ..s }
        } else {
            s
        }
    }

    /// `P(x; p)` at the parameter `p` (walk failures named by kind).
    fn outcome(&self, x: &DVector<f64>, p: f64) -> Result<DVector<f64>, MapFailure> {
        let at = self.at(p)?;
        let map = self.step_map(&at);
        let out = map.eval(&self.section_at(x, p)).map_err(walk_failure)?;
        Ok(self.reduce(&out.next))
    }

    /// The step map at `at`.
    fn step_map<'m>(&self, at: &'m ParamPoint) -> StepMap<'m>
    where
        'a: 'm,
    {
        at.step_map()
            .with_rear_held(self.rear_held)
            .with_slip(self.base.slips())
            .iterated(self.period)
            .with_interrupt(self.interrupt)
    }

    /// The error estimate of the exact `DP` at `(x, p)` (as a gait's, [`crate::gait::DERIVATIVE_CHECK_TIGHTENING`]):
    /// the largest difference between `jacobian` and `DP` at tolerances that many times tighter; `NaN` where
    /// it cannot be computed.
    pub fn jacobian_error(&self, x: &DVector<f64>, p: f64, jacobian: &DMatrix<f64>) -> f64 {
        let Ok(at) = self.at(p) else {
            return f64::NAN;
        };
        let tighter = self
            .step_map(&at)
            .with_tolerances_scaled(1.0 / DERIVATIVE_CHECK_TIGHTENING);
        match tighter.eval_with_derivatives(&self.section_at(x, p), None) {
            Ok(d) if d.jacobian.shape() == jacobian.shape() => (&d.jacobian - jacobian).amax(),
            _ => f64::NAN,
        }
    }

    /// `dP/dp` by central differences.
    fn dparam_by_difference(&self, x: &DVector<f64>, p: f64) -> Result<DVector<f64>, MapFailure> {
        let step = self.fd_step * p.abs().max(1.0);
        Ok((self.outcome(x, p + step)? - self.outcome(x, p - step)?) / (2.0 * step))
    }
}

/// A parameter value outside the valid domain as a map failure.
fn invalid_parameter(e: crate::params::ConfigError) -> MapFailure {
    MapFailure {
        kind: "invalid_parameter".to_string(),
        message: e.to_string(),
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
        self.free().len()
    }

    fn eval(&self, x: &DVector<f64>, p: f64) -> Result<Evaluation<GaitInfo>, MapFailure> {
        let at = self.at(p)?;
        let map = self.step_map(&at);
        let s = self.section_at(x, p);
        let key = DIFFERENTIABLE_KEYS
            .contains(&self.param())
            .then_some(self.param());
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
                        cycle: d.cycle,
                        signature: d.signature,
                    },
                })
            }
            Err(DerivativeError::Walk(e)) => Err(walk_failure(e)),
            // Not differentiable here (a border, a grazing, two events at once): central differences, or no
            // derivatives where a perturbed walk fails (the point is within the difference step of the end of
            // the map's domain).
            Err(_) => {
                let signed = map.eval_signature(&s).map_err(walk_failure)?;
                let n = self.dim();
                let jacobian = map
                    .central_jacobian(&s, self.fd_step)
                    .unwrap_or_else(|_| DMatrix::from_element(n, n, f64::NAN));
                let dparam = self
                    .dparam_by_difference(x, p)
                    .unwrap_or_else(|_| DVector::from_element(n, f64::NAN));
                Ok(Evaluation {
                    value: self.reduce(&signed.outcome.next),
                    jacobian,
                    dparam,
                    exact: false,
                    info: GaitInfo::of(signed),
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

    /// The DLS indicators that decide the impact procedure's branch at each step's touchdown: `lambda_I4`
    /// (between (A1) and (A3)) and, where it is not negative, `lambda_2+` and `lambda_4+` (between (B2), the
    /// bounce and (B3)); named with the step's number after the first (`lambda_2_plus@2`); none for rigid
    /// legs, the traditional impact or a landing with the rear leg in the air.
    fn borders(&self, info: &GaitInfo) -> Vec<(&'static str, f64)> {
        let p = &self.parameter.config().params;
        if p.rigid_legs || p.impact != ImpactModel::Dlsi {
            return Vec::new();
        }
        let mut borders = Vec::new();
        for (r, names) in info.cycle.iter().zip(BORDER_NAMES) {
            if r.branch == Branch::RearAirborne {
                continue;
            }
            let i = &r.indicators;
            let after = if i.lambda_i4 >= 0.0 { 1.0 } else { f64::NAN };
            borders.extend([
                (names[0], i.lambda_i4),
                (names[1], after * i.lambda_2_plus),
                (names[2], after * i.lambda_4_plus),
            ]);
        }
        borders
    }

    fn piece(&self, info: &GaitInfo) -> String {
        info.signature.clone()
    }

    /// The same least period, or a change where the longer orbit's phases lie within [`PHASE_MERGE_TOL`] of
    /// each other (near the branch point of a period doubling, where they merge).
    fn same_family(&self, a: &GaitInfo, b: &GaitInfo) -> bool {
        let (pa, pb) = (a.least_period(), b.least_period());
        if pa == pb {
            return true;
        }
        let (longer, shorter) = if pa > pb { (a, pb) } else { (b, pa) };
        longer
            .cycle
            .get(shorter)
            .zip(longer.cycle.first())
            .is_some_and(|(x, y)| x.section.distance(&y.section) < PHASE_MERGE_TOL)
    }
}

/// Near a period doubling the two phases of the period-2 orbit are close (their distance grows like the square
/// root of the distance to the branch point); a change of least period between two points of a family whose
/// longer orbit has its phases farther apart than this is a jump to another family.
pub const PHASE_MERGE_TOL: f64 = 0.05;

#[cfg(test)]
mod tests;
