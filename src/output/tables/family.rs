//! The tables of `vrw continue`: `branch.csv`, one row per point of every family followed, and `curves.csv`,
//! one row per point of every two-parameter curve (docs/model.md section 11), and their writers.

use std::path::Path;

use super::{header, header_with, row, row_with, Cell, Column};
use crate::continuation::{CurvePoint, FamilyPoint};
use crate::family::GaitInfo;
use crate::gait::Stability;
use crate::output::{write_table, OutputError};

use Cell::{Count, Empty, Flag, Real, Text};

/// One row of `branch.csv`: a point of a family, with the family's number and period and the point's
/// stability verdict.
pub struct FamilyRow<'a> {
    /// The family's number (from 1, in the order they were followed).
    pub family: usize,
    /// Steps per period of the family's gaits.
    pub period_k: usize,
    /// The point's index in its family (from 0, in order of arclength).
    pub index: usize,
    /// The point.
    pub point: &'a FamilyPoint<GaitInfo>,
    /// Its stability verdict.
    pub stability: Stability,
}

/// The `k`-th multiplier's real or imaginary part, [`Cell::Empty`] if there is none.
fn multiplier(r: &FamilyRow, k: usize, imaginary: bool) -> Cell {
    r.point
        .multipliers
        .get(k)
        .map_or(Empty, |m| Real(if imaginary { m.im } else { m.re }))
}

/// The `k`-th section coordinate of the point (`L2`, `thetadot`, `L2dot`; with rigid legs only `thetadot`
/// is free, and the others are those of every gait: `L0` and 0).
fn coordinate(r: &FamilyRow, k: usize) -> Cell {
    Real(r.point.info.report.section.to_array()[k])
}

/// The columns of `branch.csv`: which point, the gait there, its stability and its (first) step, in order.
pub(crate) fn family_columns<'a>() -> Vec<Column<FamilyRow<'a>>> {
    let mut columns = Vec::with_capacity(28);
    columns.extend(point_columns());
    columns.extend(gait_columns());
    columns.extend(stability_columns());
    columns.extend(step_columns());
    columns
}

/// The columns of `branch.csv` that say which point it is: family, period, point, arclength, parameter.
fn point_columns<'a>() -> [Column<FamilyRow<'a>>; 6] {
    [
    Column::new("family", "Number of the family (from 1).", |r| {
        Count(r.family)
    }),
    Column::new(
        "period_k",
        "Steps per period of the family's gaits (fixed points of P^k).",
        |r| Count(r.period_k),
    ),
    Column::new(
        "least_period",
        "Least period of the point's gait (divides period_k: a family of P^k passes through gaits of shorter period).",
        |r| Count(r.point.info.least_period()),
    ),
    Column::new(
        "point",
        "Index of the point in its family (from 0, by arclength).",
        |r| Count(r.index),
    ),
    Column::new(
        "arclength",
        "Arclength from the family's first point, in the scaled unknowns (x, p / sigma).",
        |r| Real(r.point.arclength),
    ),
    Column::param(0, "The parameter's value (its config key's unit).", |r| {
        Real(r.point.param)
    }),
]
}

/// The columns of `branch.csv` of the gait at the point: section state, DLS indicators, impact branch and
/// event sequence.
fn gait_columns<'a>() -> [Column<FamilyRow<'a>>; 8] {
    [
    Column::new(
        "L2",
        "Length of Leg 2 at the fixed point (section state) [m].",
        |r| coordinate(r, 0),
    ),
    Column::new(
        "thetadot",
        "Angular velocity of the wheel at the fixed point [rad/s].",
        |r| coordinate(r, 1),
    ),
    Column::new(
        "L2dot",
        "Rate of change of Leg 2's length at the fixed point [m/s].",
        |r| coordinate(r, 2),
    ),
    Column::new("lambda_I4", "DLS indicator lambda_I4 [N s].", |r| {
        Real(r.point.info.report.indicators.lambda_i4)
    }),
    Column::new("lambda_2_plus", "DLS indicator lambda_2+ [N].", |r| {
        Real(r.point.info.report.indicators.lambda_2_plus)
    }),
    Column::new("lambda_4_plus", "DLS indicator lambda_4+ [N].", |r| {
        Real(r.point.info.report.indicators.lambda_4_plus)
    }),
    Column::new(
        "branch",
        "Branch of the impact procedure (of the first step).",
        |r| Text(r.point.info.report.branch.to_string()),
    ),
    Column::new(
        "signature",
        "Event sequence of the step(s): TD and the branch, then LIFT/LAND, SLIDE/STICK, UNLOCK/LOCK with the leg's number; steps of a period-k gait separated by /.",
        |r| Text(r.point.info.signature.clone()),
    ),
]
}

/// The columns of `branch.csv` of the point's stability: Floquet multipliers, verdict, exactness and residual.
fn stability_columns<'a>() -> [Column<FamilyRow<'a>>; 10] {
    [
    Column::new("mu1_re", "Floquet multiplier of largest modulus, real part.", |r| {
        multiplier(r, 0, false)
    }),
    Column::new("mu1_im", "Floquet multiplier of largest modulus, imaginary part.", |r| {
        multiplier(r, 0, true)
    }),
    Column::new("mu2_re", "Second Floquet multiplier, real part (empty with rigid legs).", |r| {
        multiplier(r, 1, false)
    }),
    Column::new("mu2_im", "Second Floquet multiplier, imaginary part.", |r| {
        multiplier(r, 1, true)
    }),
    Column::new("mu3_re", "Third Floquet multiplier, real part.", |r| {
        multiplier(r, 2, false)
    }),
    Column::new("mu3_im", "Third Floquet multiplier, imaginary part.", |r| {
        multiplier(r, 2, true)
    }),
    Column::new("max_floquet", "Largest modulus of the Floquet multipliers.", |r| {
        Real(r.point.max_multiplier())
    }),
    Column::new(
        "stability",
        "stable, unstable or uncertain (the verdict near the unit circle uses the error estimate of DP).",
        |r| Text(r.stability.to_string()),
    ),
    Column::new(
        "exact",
        "DP and dP/dp are exact (variational equations); false: central differences, or none where the map is not differentiable.",
        |r| Flag(r.point.exact),
    ),
    Column::new(
        "residual",
        "max |P(s) - s| by direct evaluation (section coordinates).",
        |r| Real(r.point.residual),
    ),
]
}

/// The columns of `branch.csv` of the gait's (first) step: period, speed, double-limb support, scuffing.
fn step_columns<'a>() -> [Column<FamilyRow<'a>>; 4] {
    [
        Column::new("period", "Time of the (first) step [s].", |r| {
            Real(r.point.info.report.period)
        }),
        Column::new("speed", "Mean speed of the (first) step [m/s].", |r| {
            Real(r.point.info.report.speed)
        }),
        Column::new(
            "dls_duration",
            "Double-limb support of the (first) step [s].",
            |r| Real(r.point.info.report.dls_duration),
        ),
        Column::new(
            "scuffing",
            "Leg 2 re-contacts or slides after its lift-off in the (first) step.",
            |r| Flag(r.point.info.report.scuffing),
        ),
    ]
}

/// The column of `branch.csv` with Coulomb friction ([`crate::output::friction_columns`]), last: the point's
/// slip velocity, so that a family whose stance tip slips at the section has its whole section state.
fn slip_column<'a>() -> Column<FamilyRow<'a>> {
    Column::new(
        "slip",
        "Slip velocity of Leg 2's tip along the slope at the point's section state, the fourth coordinate of a \
         family whose stance tip slips at touchdown (0 where it is at rest) [m/s].",
        |r| Real(r.point.info.report.section.slip),
    )
}

/// The header of `branch.csv` for the parameter `param` (with `slip` last where `friction`).
pub fn family_header(param: &str, friction: bool) -> Vec<&str> {
    header_with(&family_columns(), &[param], (&[slip_column()], friction))
}

/// One row of `branch.csv` (with `slip` last where `friction`).
pub fn family_row(r: &FamilyRow, friction: bool) -> Vec<Cell> {
    row_with(&family_columns(), (&[slip_column()], friction), r)
}

/// Write `branch.csv` for families along `param` (with `slip` last where `friction`).
pub(crate) fn write_family_csv(
    path: &Path,
    param: &str,
    friction: bool,
    rows: &[FamilyRow],
) -> Result<(), OutputError> {
    write_table(
        path,
        &family_header(param, friction),
        rows.iter().map(|r| family_row(r, friction)),
    )
}

/// One row of `curves.csv`: a point of a two-parameter curve.
pub struct CurveRow<'a> {
    /// The curve's number (from 1).
    pub curve: usize,
    /// The condition followed: a border function (`lambda_2_plus`) or a test function of `DP` (`det(DP - I)`).
    pub condition: &'a str,
    /// The point.
    pub point: &'a CurvePoint<GaitInfo>,
}

/// The columns of `curves.csv`: the curve, both parameters (named after their keys) and the gait there.
pub(crate) fn curve_columns<'a>() -> [Column<CurveRow<'a>>; 10] {
    [
        Column::new(
            "curve",
            "Number of the curve (from 1; special_points.json's curves).",
            |r| Count(r.curve),
        ),
        Column::new(
            "condition",
            "The function that is zero along the curve: a DLS indicator (a border collision's curve) or a test \
             function of DP (det(DP - I) for a fold, det(DP + I) for a period doubling, the bialternate product \
             for a Neimark-Sacker point).",
            |r| Text(r.condition.to_string()),
        ),
        Column::param(0, "The followed parameter (its config key's unit).", |r| {
            Real(r.point.p1)
        }),
        Column::param(1, "The second parameter (its config key's unit).", |r| {
            Real(r.point.p2)
        }),
        Column::new("L2", "Length of Leg 2 at the fixed point [m].", |r| {
            Real(r.point.info.report.section.l2)
        }),
        Column::new(
            "thetadot",
            "Angular velocity at the fixed point [rad/s].",
            |r| Real(r.point.info.report.section.theta_dot),
        ),
        Column::new(
            "L2dot",
            "Rate of change of Leg 2's length at the fixed point [m/s].",
            |r| Real(r.point.info.report.section.l2_dot),
        ),
        Column::new(
            "test_value",
            "The condition's function minus its offset (zero to the corrector's accuracy).",
            |r| Real(r.point.test_value),
        ),
        Column::new("residual", "max |P(s) - s| (section coordinates).", |r| {
            Real(r.point.residual)
        }),
        Column::new(
            "arclength",
            "Arclength from the curve's first point (scaled unknowns).",
            |r| Real(r.point.arclength),
        ),
    ]
}

/// Write `curves.csv` for curves in `(param, param2)`.
pub(crate) fn write_curves_csv(
    path: &Path,
    params: (&str, &str),
    rows: &[CurveRow],
) -> Result<(), OutputError> {
    write_table(path, &curve_header(params), rows.iter().map(curve_row))
}

/// The header of `curves.csv` for curves in `(param, param2)`.
pub fn curve_header<'a>((param, param2): (&'a str, &'a str)) -> Vec<&'a str> {
    header(&curve_columns(), &[param, param2])
}

/// One row of `curves.csv`.
pub fn curve_row(r: &CurveRow) -> Vec<Cell> {
    row(&curve_columns(), r)
}
