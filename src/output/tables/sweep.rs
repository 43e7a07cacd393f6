//! `sweep.csv`: one row per value of a one-parameter sweep (the parameter value, the status and the gait's
//! scalars), and its writer. The gait columns are shared with `map.csv` ([`super::map`]).

use std::path::Path;

use super::{fixed_names, header_with, row_with, Cell, Column};
use crate::gait::Gait;
use crate::output::{write_table, OutputError};
use crate::params::Config;
use crate::study::SweepPoint;

use Cell::{Count, Empty, Flag, Real, Text};

/// A cell of the point's gait, [`Cell::Empty`] where no gait was found.
pub(crate) fn of_gait(p: &SweepPoint, cell: impl Fn(&Gait) -> Cell) -> Cell {
    p.gait.as_ref().map_or(Empty, cell)
}

/// The columns of `sweep.csv`: the swept parameter (named after its config key), the status, the gait's
/// scalars (empty where no gait was found) and the failure message.
pub(crate) const SWEEP: [Column<SweepPoint>; 25] = [
    Column::param(
        0,
        "The swept parameter's value (its config key's unit).",
        |p| Real(p.value),
    ),
    Column::new(
        "status",
        "The gait's stability verdict (stable, unstable, uncertain), or why no gait was found.",
        |p| Text(p.status.to_string()),
    ),
    Column::new(
        "L2",
        "Length of Leg 2 at the gait's fixed point [m].",
        |p| of_gait(p, |g| Real(g.section.l2)),
    ),
    Column::new(
        "thetadot",
        "Angular velocity of the wheel at the gait's fixed point [rad/s].",
        |p| of_gait(p, |g| Real(g.section.theta_dot)),
    ),
    Column::new(
        "L2dot",
        "Rate of change of Leg 2's length at the gait's fixed point [m/s].",
        |p| of_gait(p, |g| Real(g.section.l2_dot)),
    ),
    Column::new("theta", "theta at the section [rad].", |p| {
        of_gait(p, |g| Real(g.theta))
    }),
    Column::new("lambda_I4", "DLS indicator lambda_I4 [N s].", |p| {
        of_gait(p, |g| Real(g.lambda_i4))
    }),
    Column::new("lambda_2_plus", "DLS indicator lambda_2+ [N].", |p| {
        of_gait(p, |g| Real(g.lambda_2_plus))
    }),
    Column::new("lambda_4_plus", "DLS indicator lambda_4+ [N].", |p| {
        of_gait(p, |g| Real(g.lambda_4_plus))
    }),
    Column::new("branch", "Branch of the impact procedure.", |p| {
        of_gait(p, |g| Text(g.branch.to_string()))
    }),
    Column::new("period", "Step period [s].", |p| {
        of_gait(p, |g| Real(g.period))
    }),
    Column::new("step_length", "Step length [m].", |p| {
        of_gait(p, |g| Real(g.step_length))
    }),
    Column::new("speed", "Mean speed [m/s].", |p| {
        of_gait(p, |g| Real(g.speed))
    }),
    Column::new(
        "dls_duration",
        "Double-limb support per step: both tips on the ground without slipping [s].",
        |p| of_gait(p, |g| Real(g.dls_duration)),
    ),
    Column::new(
        "rear_contact_duration",
        "Time Leg 2's tip touches the ground per step, sticking or sliding [s].",
        |p| of_gait(p, |g| Real(g.rear_contact_duration)),
    ),
    Column::new(
        "scuffing",
        "Leg 2 scuffs (re-contacts or slides after its lift-off).",
        |p| of_gait(p, |g| Flag(g.scuffing)),
    ),
    Column::new("bounce", "Leg 1 bounces.", |p| {
        of_gait(p, |g| Flag(g.bounce))
    }),
    Column::new(
        "stability",
        "What the Floquet multipliers and their error estimate show.",
        |p| of_gait(p, |g| Text(g.stability.to_string())),
    ),
    Column::new(
        "max_floquet",
        "Largest modulus of the Floquet multipliers.",
        |p| of_gait(p, |g| Real(g.max_floquet)),
    ),
    Column::new(
        "jacobian_error",
        "Estimated error of the Jacobian entries, NaN if not refined.",
        |p| of_gait(p, |g| Real(g.jacobian_error)),
    ),
    Column::new("residual", "max |P(s*) - s*| at the fixed point.", |p| {
        of_gait(p, |g| Real(g.residual))
    }),
    Column::new("iterations", "Newton iterations used.", |p| {
        of_gait(p, |g| Count(g.iterations))
    }),
    Column::new(
        "family",
        "Gait family: points with the same number are connected by continuation.",
        |p| of_gait(p, |_| p.family.map_or(Empty, Count)),
    ),
    Column::new("period_k", "Steps per period of the gait.", |p| {
        of_gait(p, |g| Count(g.period_k))
    }),
    Column::new("message", "The failure, in words (empty if none).", |p| {
        Text(p.message.clone().unwrap_or_default())
    }),
];

/// Columns of `sweep.csv` after the parameter column.
pub const SWEEP_COLUMNS: [&str; 24] = fixed_names(&SWEEP, 1);

/// The columns of `sweep.csv` and `map.csv` with Coulomb friction ([`friction_columns`]), last: only there, so
/// that every other sweep's and map's file is as it was before the option existed.
pub(crate) const FRICTION_GAIT_COLUMNS: [Column<SweepPoint>; 2] = [
    Column::new(
        "slip",
        "Slip velocity of Leg 2's tip along the slope at the gait's fixed point, the section's fourth coordinate \
         (0 where the tip is at rest there) [m/s].",
        |p| of_gait(p, |g| Real(g.section.slip)),
    ),
    Column::new(
        "signature",
        "The gait's stick/slip sequence: the events of its step (TD, its branch, SLIP1/SLIP2 for a tip that \
         slips through the touchdown, SLIDE/STICK/REVERSE for each slip start, stop and reversal, LIFT, LOCK, \
         ...), empty where it was not recorded.",
        |p| of_gait(p, |g| g.signature.clone().map_or(Empty, Text)),
    ),
];

/// Do the tables of a job over `config` that sweeps the keys `swept` have the columns of Coulomb friction
/// (`slip` and `signature`)? Where its `friction` is finite or swept.
pub fn friction_columns(config: &Config, swept: &[&str]) -> bool {
    config.params.has_friction() || swept.contains(&"friction")
}

/// The header of `sweep.csv` for a sweep of `param`: the parameter, then [`SWEEP_COLUMNS`], then with Coulomb
/// friction (`friction`, see [`friction_columns`]) `slip` and `signature`.
pub fn sweep_header(param: &str, friction: bool) -> Vec<&str> {
    header_with(&SWEEP, &[param], (&FRICTION_GAIT_COLUMNS, friction))
}

/// One row of `sweep.csv`, in the order of [`sweep_header`]: the parameter value, the status and the gait's
/// scalars ([`Cell::Empty`] where no gait was found).
pub fn sweep_row(p: &SweepPoint, friction: bool) -> Vec<Cell> {
    row_with(&SWEEP, (&FRICTION_GAIT_COLUMNS, friction), p)
}

/// Write `sweep.csv`: one row per sweep point (see [`sweep_row`]).
pub fn write_sweep_csv(
    path: &Path,
    param: &str,
    friction: bool,
    points: &[SweepPoint],
) -> Result<(), OutputError> {
    write_table(
        path,
        &sweep_header(param, friction),
        points.iter().map(|p| sweep_row(p, friction)),
    )
}
