//! The continuation engine (docs/model.md section 11), free of the wheel (it imports no module of it): families
//! of fixed points of a map `P(x; p)` followed by pseudo-arclength continuation through folds ([`arclength`],
//! with its [`corrector`]), branch switching at period doublings and border collisions ([`switch`]), special
//! points detected by test functions and located by solving an extended system ([`special`]), and the curves
//! of special points in two parameters ([`curve`]), and quantities monitored along a family with their extrema
//! ([`monitor`]). The wheel's step map as such a family is
//! `crate::family::GaitFamily`.
//!
//! Everything here works on any [`FamilyMap`]: a map of `R^n` with one parameter that gives its value, its
//! Jacobian `DP` and `dP/dp` (the VRW's come from its step map's exact derivatives), and,
//! optionally, the smooth functions whose zeros are the borders between its smooth pieces and a name for the
//! piece a point lies on. The reference families of [`crate::reference`] (the quadratic map, with a fold and a
//! period-doubling cascade in closed form, and the delayed logistic map, with a Neimark-Sacker point) are
//! followed by the same code in the tests.

pub mod arclength;
pub mod corrector;
pub mod curve;
pub mod monitor;
pub mod special;
pub mod switch;
#[cfg(test)]
mod tests;

use nalgebra::{DMatrix, DVector};

pub use arclength::{continue_family, ContinuationError, Family, FamilyEnd};
pub use corrector::{ContinuationOptions, FamilyPoint};
pub use curve::{
    continue_curve, curve_at, curve_at_p2, Curve, CurveEnd, CurveOptions, CurvePoint, CurveProblem,
};
pub use special::{SpecialKind, SpecialPoint};
pub use switch::{switch_at_border, switch_at_period_doubling};

/// One evaluation of a family's map: `P(x; p)`, `DP`, `dP/dp` and what the map records of the point.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation<I> {
    /// `P(x; p)`.
    pub value: DVector<f64>,
    /// `DP(x; p)`.
    pub jacobian: DMatrix<f64>,
    /// `dP/dp(x; p)`.
    pub dparam: DVector<f64>,
    /// The derivatives are exact (variational equations); false where the map is not differentiable at the
    /// point and they are central differences.
    pub exact: bool,
    /// What the map records of the point (the VRW: the step's report and its event sequence).
    pub info: I,
}

/// Why a family's map could not be evaluated at a point: a kind (`rolled_back`, `fell`,
/// `invalid_parameter`, ...) and the message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct MapFailure {
    /// What kind of failure (the walk's failure kind for the VRW); [`MapFailure::INTERRUPTED`] when the work
    /// was stopped from outside.
    pub kind: String,
    /// The failure in words.
    pub message: String,
}

impl MapFailure {
    /// The kind of a failure that is no property of the map: its evaluation was stopped from outside (the
    /// interrupt flag, Ctrl-C). Continuation stops there with [`FamilyEnd::Interrupted`], never a family end.
    pub const INTERRUPTED: &'static str = "interrupted";

    /// Was the evaluation stopped from outside?
    pub fn interrupted(&self) -> bool {
        self.kind == Self::INTERRUPTED
    }
}

/// A one-parameter family of maps `P(x; p)` of `R^n` whose fixed points are followed.
pub trait FamilyMap: Sync {
    /// What the map records of a point besides its state.
    type Info: Clone + std::fmt::Debug + Send;

    /// `n`.
    fn dim(&self) -> usize;

    /// `P(x; p)` with its derivatives.
    fn eval(&self, x: &DVector<f64>, p: f64) -> Result<Evaluation<Self::Info>, MapFailure>;

    /// `P(x; p)` alone (the corrector's iterations need no derivatives).
    fn value(&self, x: &DVector<f64>, p: f64) -> Result<DVector<f64>, MapFailure>;

    /// The map iterated `k` times (`P^k`, whose fixed points include the period-k orbits of `P`).
    fn iterated(&self, k: usize) -> Self
    where
        Self: Sized;

    /// Steps of `P` per evaluation (`k` of `P^k`).
    fn period(&self) -> usize;

    /// Smooth functions of the point whose zeros are borders between the map's smooth pieces, by name (the
    /// VRW: the DLS indicators). A sign change between two points of a family is a border collision, located
    /// where the function is zero. `NaN` values are not compared.
    fn borders(&self, _info: &Self::Info) -> Vec<(&'static str, f64)> {
        Vec::new()
    }

    /// The border function `name` of [`FamilyMap::borders`] at the point (`NaN` if it has none of that name).
    fn border(&self, info: &Self::Info, name: &str) -> f64 {
        self.borders(info)
            .into_iter()
            .find(|(other, _)| *other == name)
            .map_or(f64::NAN, |(_, g)| g)
    }

    /// The smooth piece of the map the point lies on (the VRW: the event sequence of its step); a change along
    /// a family is a border collision.
    fn piece(&self, _info: &Self::Info) -> String {
        String::new()
    }

    /// Can two successive points of a family be one family's? A step whose two ends cannot is a jump to
    /// another family (the VRW: the least period changes where the longer orbit's phases are far apart, which
    /// no branch point of one family does), and is rejected like a step that jumps.
    fn same_family(&self, _a: &Self::Info, _b: &Self::Info) -> bool {
        true
    }
}
