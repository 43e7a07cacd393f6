//! `map.csv`: one row per point of a two-parameter gait map (both parameter values, the status and the gait's
//! main scalars), and its writer.

use std::path::Path;

use super::sweep::{of_gait, FRICTION_GAIT_COLUMNS};
use super::{header, optional, row, Cell, Column};
use crate::output::{write_table, OutputError};
use crate::study::{GaitMap, SweepPoint};

use Cell::{Count, Empty, Flag, Real, Text};

/// One row of `map.csv`: a point of the map and the `y` value of its row (its `value` is the `x` value).
pub(crate) struct MapPoint<'a> {
    /// The `y` value.
    pub y: f64,
    /// The point.
    pub point: &'a SweepPoint,
}

/// The columns of `map.csv`: both parameters (named after their config keys), the status (the stability
/// verdict, or why no gait was found), the gait's scalars (empty where no gait was found) and the failure
/// message.
pub(crate) fn map_columns<'a>() -> [Column<MapPoint<'a>>; 15] {
    [
        Column::param(0, "The x parameter's value (its config key's unit).", |m| {
            Real(m.point.value)
        }),
        Column::param(1, "The y parameter's value (its config key's unit).", |m| {
            Real(m.y)
        }),
        Column::new(
            "status",
            "The gait's stability verdict (stable, unstable, uncertain), or why no gait was found.",
            |m| Text(m.point.status.to_string()),
        ),
        Column::new("branch", "Branch of the impact procedure.", |m| {
            of_gait(m.point, |g| Text(g.branch.to_string()))
        }),
        Column::new(
            "family",
            "Gait family, numbered within the row: points with the same number are connected by \
             continuation along x.",
            |m| of_gait(m.point, |_| m.point.family.map_or(Empty, Count)),
        ),
        Column::new("period_k", "Steps per period of the gait.", |m| {
            of_gait(m.point, |g| Count(g.period_k))
        }),
        Column::new("lambda_I4", "DLS indicator lambda_I4 [N s].", |m| {
            of_gait(m.point, |g| Real(g.lambda_i4))
        }),
        Column::new("lambda_2_plus", "DLS indicator lambda_2+ [N].", |m| {
            of_gait(m.point, |g| Real(g.lambda_2_plus))
        }),
        Column::new("lambda_4_plus", "DLS indicator lambda_4+ [N].", |m| {
            of_gait(m.point, |g| Real(g.lambda_4_plus))
        }),
        Column::new("period", "Step period [s].", |m| {
            of_gait(m.point, |g| Real(g.period))
        }),
        Column::new("speed", "Mean speed [m/s].", |m| {
            of_gait(m.point, |g| Real(g.speed))
        }),
        Column::new(
            "max_floquet",
            "Largest modulus of the Floquet multipliers.",
            |m| of_gait(m.point, |g| Real(g.max_floquet)),
        ),
        Column::new(
            "stability",
            "What the Floquet multipliers and their error estimate show.",
            |m| of_gait(m.point, |g| Text(g.stability.to_string())),
        ),
        Column::new(
            "scuffing",
            "Leg 2 scuffs (re-contacts or slides after its lift-off).",
            |m| of_gait(m.point, |g| Flag(g.scuffing)),
        ),
        Column::new("message", "The failure, in words (empty if none).", |m| {
            Text(m.point.message.clone().unwrap_or_default())
        }),
    ]
}

/// Write `map.csv`: one row per map point, row by row (`y` outer, `x` inner): both parameter values, the status
/// (the stability verdict, or why no gait was found), the impact branch, the gait family (numbered within the
/// row), `period_k`, the three DLS indicators, period, speed, the largest Floquet multiplier modulus and the stability
/// verdict; empty gait fields where no gait was found.
/// With Coulomb friction (`friction`, see [`crate::output::friction_columns`]), each gait's `slip` and stick/slip `signature`
/// last.
pub(crate) fn write_map_csv(path: &Path, map: &GaitMap, friction: bool) -> Result<(), OutputError> {
    write_table(
        path,
        &map_header(&map.spec.x.param, &map.spec.y.param, friction),
        map_rows(map, friction),
    )
}

/// The header of `map.csv` for a map over `x` and `y` (with the columns of Coulomb friction where `friction`,
/// [`crate::output::friction_columns`]).
pub fn map_header<'a>(x: &'a str, y: &'a str, friction: bool) -> Vec<&'a str> {
    let mut names = header(&map_columns(), &[x, y]);
    names.extend(header(optional(&FRICTION_GAIT_COLUMNS, friction), &[]));
    names
}

/// The rows of `map.csv`: every point of the map, row by row (`y`), each row along `x`.
pub fn map_rows(map: &GaitMap, friction: bool) -> Vec<Vec<Cell>> {
    let columns = map_columns();
    map.rows
        .iter()
        .zip(&map.ys)
        .flat_map(|(points, &y)| points.iter().map(move |point| MapPoint { y, point }))
        .map(|m| {
            let mut cells = row(&columns, &m);
            cells.extend(row(optional(&FRICTION_GAIT_COLUMNS, friction), m.point));
            cells
        })
        .collect()
}
