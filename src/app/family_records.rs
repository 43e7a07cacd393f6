//! The records `vrw continue` writes into `special_points.json` (docs/model.md section 11): families with
//! their ends and causes, special points with their sides.

use serde::Serialize;

use crate::continuation::monitor::ExtremumKind;
use crate::continuation::special::Side;
use crate::continuation::{SpecialKind, SpecialPoint};
use crate::family::diagram::EndRecord;
use crate::family::{GaitFamily, GaitInfo};
use crate::gait::Stability;

/// One family in `special_points.json`.
#[derive(Debug, Clone, Serialize)]
pub struct FamilyRecord {
    /// Its number (`family` in `branch.csv`), from 1.
    pub family: usize,
    /// Steps per period of its gaits.
    pub period_k: usize,
    /// Points in `branch.csv`.
    pub points: usize,
    /// Where it came from: `start`, or the special point (index into `special_points`) it was switched to
    /// from.
    pub origin: String,
    /// How it ends at its first point and at its last.
    pub ends: [EndRecord; 2],
}

/// The section state of a point, as written.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct SectionRecord {
    /// `L2` \[m\].
    #[serde(rename = "L2")]
    pub l2: f64,
    /// `dtheta/dt` \[rad/s\].
    pub thetadot: f64,
    /// `dL2/dt` \[m/s\].
    #[serde(rename = "L2dot")]
    pub l2dot: f64,
}

/// One side of a border collision, as written.
#[derive(Debug, Clone, Serialize)]
pub struct SideRecord {
    /// Where its multipliers were taken.
    pub param: f64,
    /// The event sequence there.
    pub signature: String,
    /// Its multipliers `[re, im]`.
    pub multipliers: Vec<[f64; 2]>,
}

/// One special point in `special_points.json`.
#[derive(Debug, Clone, Serialize)]
pub struct SpecialRecord {
    /// The family it lies on.
    pub family: usize,
    /// `LP`, `PD`, `NS`, `BC` or `EX`.
    pub kind: SpecialKind,
    /// The parameter.
    pub param: f64,
    /// The gait's section state there (`null` fields if unknown).
    pub section: SectionRecord,
    /// Arclength along its family.
    pub arclength: f64,
    /// The parameters of the two family points it was detected between.
    pub bracket: [f64; 2],
    /// Located by solving (false: detected only, see `note`).
    pub located: bool,
    /// How.
    pub method: String,
    /// `max |P(s) - s|` there.
    pub residual: f64,
    /// The test function there.
    pub test_value: f64,
    /// The multipliers there `[re, im]`.
    pub multipliers: Vec<[f64; 2]>,
    /// For a border collision: the indicator crossing zero, or `event sequence`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub border: Option<String>,
    /// For a border collision: the two sides, in the order the family was followed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sides: Option<Vec<SideRecord>>,
    /// The event sequence there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub signature: Option<String>,
    /// Why it is not located, or what else is worth knowing.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// For an extremum of a monitored quantity (`EX`, `--extremum`): which, its kind and value.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub extremum: Option<ExtremumRecord>,
}

/// The extremum part of a special point in `special_points.json`.
#[derive(Debug, Clone, Serialize)]
pub struct ExtremumRecord {
    /// The monitored quantity.
    pub quantity: String,
    /// `max` or `min`.
    pub extremum: ExtremumKind,
    /// `smooth` (a zero of its derivative along the family) or `corner` (it is not smooth there).
    pub shape: &'static str,
    /// At a corner: why the quantity is not smooth there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub corner: Option<String>,
    /// The quantity there.
    pub value: f64,
    /// The parameters of the located bracket (width at most `1e-8`).
    pub located_bracket: [f64; 2],
    /// The gait's speed there \[m/s\].
    pub speed: f64,
    /// How its derivative along the family was computed, with the step.
    pub derivative: String,
}

/// A special point as written.
pub(crate) fn special_record(family: usize, s: &SpecialPoint<GaitInfo>) -> SpecialRecord {
    let pairs = |m: &[nalgebra::Complex<f64>]| m.iter().map(|z| [z.re, z.im]).collect();
    let section = s.info.as_ref().map_or(
        SectionRecord {
            l2: f64::NAN,
            thetadot: f64::NAN,
            l2dot: f64::NAN,
        },
        |i| SectionRecord {
            l2: i.report.section.l2,
            thetadot: i.report.section.theta_dot,
            l2dot: i.report.section.l2_dot,
        },
    );
    let side = |side: &Side| SideRecord {
        param: side.param,
        signature: side.piece.clone(),
        multipliers: pairs(&side.multipliers),
    };
    SpecialRecord {
        family,
        kind: s.kind,
        param: s.param,
        section,
        arclength: s.arclength,
        bracket: s.bracket,
        located: s.located,
        method: s.method.clone(),
        residual: s.residual,
        test_value: s.test_value,
        multipliers: pairs(&s.multipliers),
        border: s.border.clone(),
        sides: s
            .sides
            .as_ref()
            .map(|sides| sides.iter().map(side).collect()),
        signature: s.info.as_ref().map(|i| i.signature.clone()),
        note: s.note.clone(),
        extremum: None,
    }
}

/// The stability verdict of a family point: from its multipliers, with the error estimate of its `DP`
/// within [`STABILITY_BAND`] of the unit circle; uncertain without derivatives.
pub(super) fn point_stability(
    map: &GaitFamily,
    p: &crate::continuation::FamilyPoint<GaitInfo>,
) -> Stability {
    let max = p.max_multiplier();
    if !p.has_derivatives() || !max.is_finite() {
        return Stability::Uncertain;
    }
    if (max - 1.0).abs() > STABILITY_BAND {
        return Stability::judge(max, 0.0);
    }
    Stability::judge(max, map.jacobian_error(&p.x, p.param, &p.jacobian))
}

/// Within this of the unit circle, a point's stability verdict uses the error estimate of its `DP` (a second
/// `DP` at tighter tolerances); farther out the exact `DP`'s error (below `1e-6` wherever it was estimated)
/// cannot change it.
pub const STABILITY_BAND: f64 = 1e-3;
