//! The gait quantities monitored along a gait family (`vrw continue --extremum`, docs/model.md section 11):
//! functions of the fixed point, read from the (first) step's report or, for the largest multiplier's
//! modulus, from `DP`; named as the wheel's tables name them.

use super::GaitInfo;
use crate::continuation::corrector::multipliers;
use crate::continuation::monitor::{At, Monitor};

/// The quantities that can be monitored, by the names of the wheel's tables (`branch.csv`, `sweep.csv`,
/// `steps.csv`).
pub const MONITORED_QUANTITIES: [&str; 11] = [
    "speed",
    "period",
    "step_length",
    "dls_duration",
    "rear_contact_duration",
    "lambda_I4",
    "lambda_2_plus",
    "lambda_4_plus",
    "max_floquet",
    "damper_loss",
    "impact_loss",
];

/// One of [`MONITORED_QUANTITIES`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GaitQuantity(&'static str);

impl GaitQuantity {
    /// The quantity named `name`; `None` if it is not one of [`MONITORED_QUANTITIES`].
    pub fn named(name: &str) -> Option<GaitQuantity> {
        MONITORED_QUANTITIES
            .iter()
            .find(|q| **q == name)
            .map(|q| GaitQuantity(q))
    }

    /// All of them, in [`MONITORED_QUANTITIES`]'s order.
    pub fn all() -> Vec<GaitQuantity> {
        MONITORED_QUANTITIES
            .iter()
            .map(|q| GaitQuantity(q))
            .collect()
    }

    /// Its unit and meaning.
    pub fn doc(&self) -> &'static str {
        match self.0 {
            "speed" => "mean speed of the (first) step [m/s]",
            "period" => "time of the (first) step [s]",
            "step_length" => "step length of the (first) step [m]",
            "dls_duration" => "double-limb support of the (first) step [s]",
            "rear_contact_duration" => {
                "time Leg 2's tip touches the ground in the (first) step [s]"
            }
            "lambda_I4" => "DLS indicator lambda_I4 [N s]",
            "lambda_2_plus" => "DLS indicator lambda_2+ [N]",
            "lambda_4_plus" => "DLS indicator lambda_4+ [N]",
            "max_floquet" => "largest modulus of the Floquet multipliers",
            "damper_loss" => "energy the dampers dissipate in the (first) step [J]",
            _ => "kinetic energy lost in the impacts of the (first) step [J]",
        }
    }
}

impl Monitor<GaitInfo> for GaitQuantity {
    fn name(&self) -> &str {
        self.0
    }

    fn value(&self, at: &At<'_, GaitInfo>) -> f64 {
        let r = &at.info.report;
        match self.0 {
            "speed" => r.speed,
            "period" => r.period,
            "step_length" => r.step_length,
            "dls_duration" => r.dls_duration,
            "rear_contact_duration" => r.rear_contact_duration,
            "lambda_I4" => r.indicators.lambda_i4,
            "lambda_2_plus" => r.indicators.lambda_2_plus,
            "lambda_4_plus" => r.indicators.lambda_4_plus,
            "max_floquet" => multipliers(at.jacobian)
                .first()
                .map_or(f64::NAN, |m| m.norm()),
            "damper_loss" => r.energy.damper,
            _ => r.energy.impact,
        }
    }

    /// The largest multiplier's modulus: a positive or a negative real multiplier, or a complex pair (where
    /// two real multipliers meet and become a pair, or a pair splits, or two multipliers cross in modulus, it
    /// has a corner). Every other quantity: one piece.
    fn shape(&self, at: &At<'_, GaitInfo>) -> String {
        if self.0 != "max_floquet" {
            return String::new();
        }
        match multipliers(at.jacobian).first() {
            None => String::new(),
            Some(m) if m.im != 0.0 => "a complex pair of largest modulus".to_string(),
            Some(m) if m.re >= 0.0 => "a positive real multiplier of largest modulus".to_string(),
            Some(_) => "a negative real multiplier of largest modulus".to_string(),
        }
    }
}
