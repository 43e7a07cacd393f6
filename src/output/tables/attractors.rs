//! The tables of `vrw orbit` and `vrw basin`: `orbit.csv` (the returns of the orbit diagram), `branch.csv`
//! (the period-1 gait along the same values) and `basin.csv` (the outcome of every start of the basin's
//! grid), and their writers.

use std::path::Path;

use super::{header_with, row_with, Cell, Column};
use crate::gait::Gait;
use crate::output::{write_table, OutputError};
use crate::study::basin::BasinPoint;
use crate::study::orbit::OrbitColumn;
use crate::walk::{SectionState, StepReport};

use Cell::{Count, Empty, Real, Text};

/// One row of `orbit.csv`: a value of the diagram and one of its recorded steps (its number from 1 after the
/// transient), or no step for a value whose walk failed before recording anything.
pub(crate) struct OrbitRow<'a> {
    /// The value's column of the diagram.
    pub column: &'a OrbitColumn,
    /// The step number and the step.
    pub step: Option<(usize, &'a StepReport)>,
}

/// A cell of the row's step, [`Cell::Empty`] without one.
fn of_step(r: &OrbitRow, cell: impl Fn(&StepReport) -> Cell) -> Cell {
    r.step.map_or(Empty, |(_, s)| cell(s))
}

/// The columns of `orbit.csv`: the parameter (named after its config key), the outcome of its walk, and per
/// recorded step the section state, the DLS indicators and the branch (docs/model.md sections 4-5).
pub(crate) fn orbit_columns<'a>() -> [Column<OrbitRow<'a>>; 12] {
    [
        Column::param(0, "The parameter's value (its config key's unit).", |r| {
            Real(r.column.value)
        }),
        Column::new(
            "status",
            "walking when every step was walked, otherwise the failure kind.",
            |r| Text(r.column.status.to_string()),
        ),
        Column::new(
            "period_k",
            "Least period of the recorded returns, empty if they do not repeat.",
            |r| r.column.period_k.map_or(Empty, Count),
        ),
        Column::new(
            "step",
            "Number of the recorded step, from 1 after the transient.",
            |r| r.step.map_or(Empty, |(n, _)| Count(n)),
        ),
        Column::new(
            "L2",
            "Length of Leg 2 just before the step's touchdown (section state) [m].",
            |r| of_step(r, |s| Real(s.section.l2)),
        ),
        Column::new(
            "thetadot",
            "Angular velocity of the wheel just before the touchdown [rad/s].",
            |r| of_step(r, |s| Real(s.section.theta_dot)),
        ),
        Column::new(
            "L2dot",
            "Rate of change of Leg 2's length just before the touchdown [m/s].",
            |r| of_step(r, |s| Real(s.section.l2_dot)),
        ),
        Column::new("lambda_I4", "DLS indicator lambda_I4 [N s].", |r| {
            of_step(r, |s| Real(s.indicators.lambda_i4))
        }),
        Column::new("lambda_2_plus", "DLS indicator lambda_2+ [N].", |r| {
            of_step(r, |s| Real(s.indicators.lambda_2_plus))
        }),
        Column::new("lambda_4_plus", "DLS indicator lambda_4+ [N].", |r| {
            of_step(r, |s| Real(s.indicators.lambda_4_plus))
        }),
        Column::new("branch", "Branch of the impact procedure.", |r| {
            of_step(r, |s| Text(s.branch.to_string()))
        }),
        Column::new(
            "continued_from",
            "The value whose end state this walk started from, empty for the initial state.",
            |r| r.column.continued_from.map_or(Empty, Real),
        ),
    ]
}

/// The column of `orbit.csv` with Coulomb friction ([`crate::output::friction_columns`]), last.
fn orbit_slip<'a>() -> Column<OrbitRow<'a>> {
    Column::new(
        "slip",
        "Slip velocity of Leg 2's tip along the slope just before the touchdown (the section's fourth coordinate, \
         0 where the tip is at rest) [m/s].",
        |r| of_step(r, |s| Real(s.section.slip)),
    )
}

/// Write `orbit.csv` for a diagram along `param`: one row per recorded step; a value whose walk failed
/// before recording anything has one row with empty step fields. With `slip` last where `friction`.
pub(crate) fn write_orbit_csv(
    path: &Path,
    param: &str,
    friction: bool,
    columns: &[OrbitColumn],
) -> Result<(), OutputError> {
    write_table(
        path,
        &orbit_header(param, friction),
        orbit_rows(columns, friction),
    )
}

/// The header of `orbit.csv` along `param` (with `slip` last where `friction`).
pub fn orbit_header(param: &str, friction: bool) -> Vec<&str> {
    header_with(&orbit_columns(), &[param], (&[orbit_slip()], friction))
}

/// The rows of `orbit.csv`: every recorded step of every value (one empty row for a value with none), with
/// `slip` last where `friction`.
pub fn orbit_rows(columns: &[OrbitColumn], friction: bool) -> Vec<Vec<Cell>> {
    let (table, slip) = (orbit_columns(), [orbit_slip()]);
    columns
        .iter()
        .flat_map(|column| {
            let steps = column.returns.iter().enumerate();
            let steps: Vec<_> = steps.map(|(n, s)| Some((n + 1, s))).collect();
            let steps = if steps.is_empty() { vec![None] } else { steps };
            steps.into_iter().map(move |step| OrbitRow { column, step })
        })
        .map(|r| row_with(&table, (&slip, friction), &r))
        .collect()
}

/// A cell of the branch's gait, [`Cell::Empty`] where there is none.
fn of_gait(b: &(f64, Option<Gait>), cell: impl Fn(&Gait) -> Cell) -> Cell {
    b.1.as_ref().map_or(Empty, cell)
}

/// The columns of `branch.csv`: the parameter (named after its config key) and the period-1 gait's section
/// state, DLS indicators and stability (empty where there is no gait).
pub(crate) const BRANCH: [Column<(f64, Option<Gait>)>; 9] = [
    Column::param(0, "The parameter's value (its config key's unit).", |b| {
        Real(b.0)
    }),
    Column::new(
        "L2",
        "Length of Leg 2 at the gait's fixed point [m].",
        |b| of_gait(b, |g| Real(g.section.l2)),
    ),
    Column::new(
        "thetadot",
        "Angular velocity of the wheel at the gait's fixed point [rad/s].",
        |b| of_gait(b, |g| Real(g.section.theta_dot)),
    ),
    Column::new(
        "L2dot",
        "Rate of change of Leg 2's length at the gait's fixed point [m/s].",
        |b| of_gait(b, |g| Real(g.section.l2_dot)),
    ),
    Column::new("lambda_I4", "DLS indicator lambda_I4 [N s].", |b| {
        of_gait(b, |g| Real(g.lambda_i4))
    }),
    Column::new("lambda_2_plus", "DLS indicator lambda_2+ [N].", |b| {
        of_gait(b, |g| Real(g.lambda_2_plus))
    }),
    Column::new("lambda_4_plus", "DLS indicator lambda_4+ [N].", |b| {
        of_gait(b, |g| Real(g.lambda_4_plus))
    }),
    Column::new(
        "max_floquet",
        "Largest modulus of the Floquet multipliers.",
        |b| of_gait(b, |g| Real(g.max_floquet)),
    ),
    Column::new(
        "stability",
        "What the Floquet multipliers and their error estimate show.",
        |b| of_gait(b, |g| Text(g.stability.to_string())),
    ),
];

/// The column of the orbit diagram's `branch.csv` with Coulomb friction, last.
const BRANCH_SLIP: Column<(f64, Option<Gait>)> = Column::new(
    "slip",
    "Slip velocity of Leg 2's tip at the gait's fixed point (the section's fourth coordinate, 0 where the tip is \
     at rest) [m/s].",
    |b| of_gait(b, |g| Real(g.section.slip)),
);

/// Write `branch.csv` for a branch along `param`: the period-1 gait at each value (empty where there is none),
/// with `slip` last where `friction`.
pub(crate) fn write_branch_csv(
    path: &Path,
    param: &str,
    friction: bool,
    branch: &[(f64, Option<Gait>)],
) -> Result<(), OutputError> {
    write_table(
        path,
        &branch_header(param, friction),
        branch_rows(branch, friction),
    )
}

/// The header of the orbit diagram's `branch.csv` along `param` (with `slip` last where `friction`).
pub fn branch_header(param: &str, friction: bool) -> Vec<&str> {
    header_with(&BRANCH, &[param], (&[BRANCH_SLIP], friction))
}

/// The rows of the orbit diagram's `branch.csv` (with `slip` last where `friction`).
pub fn branch_rows(branch: &[(f64, Option<Gait>)], friction: bool) -> Vec<Vec<Cell>> {
    branch
        .iter()
        .map(|b| row_with(&BRANCH, (&[BRANCH_SLIP], friction), b))
        .collect()
}

/// A coordinate of the section state where the walk ended, [`Cell::Empty`] if none was reached.
fn of_end(p: &BasinPoint, coordinate: impl Fn(&SectionState) -> f64) -> Cell {
    p.outcome
        .end
        .as_ref()
        .map_or(Empty, |e| Real(coordinate(e)))
}

/// The columns of `basin.csv`: the grid point, its start on the section, and what the walk from it did.
pub(crate) const BASIN: [Column<BasinPoint>; 11] = [
    Column::new("ix", "Grid column (x index, from 0).", |p| Count(p.ix)),
    Column::new("iy", "Grid row (y index, from 0).", |p| Count(p.iy)),
    Column::new("L2", "Start: length of Leg 2 [m].", |p| Real(p.start.l2)),
    Column::new(
        "thetadot",
        "Start: angular velocity of the wheel [rad/s].",
        |p| Real(p.start.theta_dot),
    ),
    Column::new(
        "L2dot",
        "Start: rate of change of Leg 2's length [m/s].",
        |p| Real(p.start.l2_dot),
    ),
    Column::new(
        "outcome",
        "gait, other, undecided, invalid_start or the walk's failure kind.",
        |p| Text(p.outcome.kind.to_string()),
    ),
    Column::new("steps", "Steps walked until the outcome was known.", |p| {
        Count(p.outcome.steps)
    }),
    Column::new(
        "period_k",
        "For other, the period of the attractor reached (empty otherwise).",
        |p| p.outcome.period_k.map_or(Empty, Count),
    ),
    Column::new("end_L2", "End: length of Leg 2 [m].", |p| {
        of_end(p, |e| e.l2)
    }),
    Column::new(
        "end_thetadot",
        "End: angular velocity of the wheel [rad/s].",
        |p| of_end(p, |e| e.theta_dot),
    ),
    Column::new(
        "end_L2dot",
        "End: rate of change of Leg 2's length [m/s].",
        |p| of_end(p, |e| e.l2_dot),
    ),
];

/// The columns of `basin.csv` with Coulomb friction, last: the slip velocity of the start (the gait's, held on
/// the slice) and of the end.
const BASIN_SLIP: [Column<BasinPoint>; 2] = [
    Column::new(
        "slip",
        "Start: slip velocity of Leg 2's tip, the gait's (0 where the tip is at rest) [m/s].",
        |p| Real(p.start.slip),
    ),
    Column::new(
        "end_slip",
        "End: slip velocity of Leg 2's tip [m/s].",
        |p| of_end(p, |e| e.slip),
    ),
];

/// The header of `basin.csv` (with `slip` and `end_slip` last where `friction`).
pub fn basin_header(friction: bool) -> Vec<&'static str> {
    header_with(&BASIN, &[], (&BASIN_SLIP, friction))
}

/// One row of `basin.csv` (with `slip` and `end_slip` last where `friction`).
pub fn basin_row(p: &BasinPoint, friction: bool) -> Vec<Cell> {
    row_with(&BASIN, (&BASIN_SLIP, friction), p)
}

/// Write `basin.csv`: one row per grid point, row by row.
pub(crate) fn write_basin_csv(
    path: &Path,
    friction: bool,
    grid: &[Vec<BasinPoint>],
) -> Result<(), OutputError> {
    write_table(
        path,
        &basin_header(friction),
        grid.iter().flatten().map(|p| basin_row(p, friction)),
    )
}
