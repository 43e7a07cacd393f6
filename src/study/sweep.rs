//! Parameter sweeps with continuation (docs/model.md section 6, the paper's Fig. 2).
//!
//! Every point follows its neighbour's gait family in verified continuation steps (see
//! [`crate::family::natural`]), with the neighbour's `DP` as the Newton matrix. A point the family does not reach
//! is searched from the sweep's initial state with a full transient, and so are the points after it until a gait
//! is found again. Gaits found that way are then followed backwards to fill in points the search from the
//! initial state missed, and every gait gets a family number: points of one family are connected by
//! continuation, so a change of family between neighbours is a branch switch, never a silent jump.
//!
//! Parallelism (rayon) with results bitwise identical for any number of threads comes from the grid runner
//! ([`super::grid`]): a sweep is one row of [`gait_rows_measured`], which continues every [`COARSE_STRIDE`]-th point in
//! order (the coarse pass) and then the points between two coarse points from the left one, all intervals in
//! parallel; a map is many rows, run in parallel. Inside each point the exact Jacobian and the second one of
//! its error estimate run in parallel as well.

use std::ops::Range;

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;

use super::grid::{run_rows_measured, Evaluated, GridRun};
use super::parallelism::{measured, Cost, TaskGraph};
use crate::dynamics::DIFFERENTIABLE_KEYS;
use crate::family::natural::{FollowOutcome, GaitPoint, NaturalContinuation, Tangent, PARAM_TOL};
use crate::family::Parameter;
use crate::fmt::short;
use crate::gait::limit_cycle::{
    gait_at_converged, solve_fixed_point, Gait, GaitOptions, Stability,
};
use crate::gait::period_k::{find_gait_any_period, periodic_gait_at};
use crate::gait::periodicity::{MAX_PERIOD, SAME_GAIT_TOL};
use crate::gait::step_map::free_coordinates;
use crate::meter::carried;
use crate::params::{Config, ConfigError, NumericKey};
use crate::walk::{SectionState, SECTION_COORDINATES};

/// The most points a sweep may have.
pub const MAX_SWEEP_POINTS: usize = 100_000;

/// What to sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepSpec {
    /// A numeric key of the configuration ([`Config::numeric_keys`]), e.g. `viscosity`.
    pub param: String,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values, evenly spaced, ends included (2 to `MAX_SWEEP_POINTS`).
    pub points: usize,
}

/// How a command names a range of parameter values in its errors (the fields of its job, which the command
/// line shows as their flags), and the most values it takes: each command states its own limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RangeNames {
    /// The command and axis, e.g. `sweep` or `map y`.
    pub command: &'static str,
    /// The first value's field, e.g. `from` or `y_from`.
    pub from: &'static str,
    /// The last value's field.
    pub to: &'static str,
    /// The number of values' field, e.g. `points` or `ny`.
    pub points: &'static str,
    /// The most values.
    pub max_points: usize,
}

/// `vrw sweep`'s range: `from`, `to`, `points` (at most [`MAX_SWEEP_POINTS`]).
pub const SWEEP_RANGE: RangeNames = RangeNames {
    command: "sweep",
    from: "from",
    to: "to",
    points: "points",
    max_points: MAX_SWEEP_POINTS,
};

impl SweepSpec {
    /// Check the specification against a configuration as `vrw sweep`'s ([`SWEEP_RANGE`]); see
    /// [`SweepSpec::validate_as`].
    pub fn validate(&self, config: &Config) -> Result<(), ConfigError> {
        self.validate_as(config, &SWEEP_RANGE)
    }

    /// Check the specification against a configuration: a known numeric key, two different finite ends,
    /// 2 to `names.max_points` points, and a configuration that is valid with the parameter at either end
    /// (the rules on one key are intervals, so the whole range is then valid), before anything is computed.
    /// Errors name the command and its flags (`names`).
    pub fn validate_as(&self, config: &Config, names: &RangeNames) -> Result<(), ConfigError> {
        let parameter = Parameter::named(config, &self.param)?;
        let invalid = |value: String, reason: &str| ConfigError::InvalidValue {
            key: format!("{} {}", names.command, self.param),
            value,
            reason: reason.to_string(),
        };
        if !(self.from.is_finite() && self.to.is_finite()) || self.from == self.to {
            return Err(invalid(
                format!(
                    "`{}` {} `{}` {}",
                    names.from,
                    short(self.from),
                    names.to,
                    short(self.to)
                ),
                "the range must have two different finite ends",
            ));
        }
        if !(2..=names.max_points).contains(&self.points) {
            return Err(invalid(
                format!("`{}` {}", names.points, self.points),
                &format!(
                    "{} takes between 2 and {} values per axis",
                    names.command, names.max_points
                ),
            ));
        }
        for (field, value) in [(names.from, self.from), (names.to, self.to)] {
            if let Err(e) = parameter.at(value) {
                return Err(invalid(
                    format!("`{field}` {}", short(value)),
                    &format!("the range leaves the valid domain: {e}"),
                ));
            }
        }
        Ok(())
    }

    /// The parameter values.
    pub fn values(&self) -> Vec<f64> {
        let n = self.points - 1;
        (0..=n)
            .map(|i| self.from + (self.to - self.from) * (i as f64 / n as f64))
            .collect()
    }
}

/// What a sweep point found: a gait with its stability verdict, or why there is none. A value until it is
/// written: its text (`stable`, `rolled_back`, `invalid_parameter`, ...) is the `status` of the tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointStatus {
    /// A gait, with its stability verdict.
    Gait(Stability),
    /// No gait: the kind of the search's failure ([`crate::gait::GaitError::kind`]: `rolled_back`,
    /// `no_convergence`, ...).
    NoGait(&'static str),
    /// The value leaves the parameter's valid domain.
    InvalidParameter,
}

impl std::fmt::Display for PointStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PointStatus::Gait(stability) => stability.fmt(f),
            PointStatus::NoGait(kind) => f.write_str(kind),
            PointStatus::InvalidParameter => f.write_str("invalid_parameter"),
        }
    }
}

/// The result at one parameter value.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepPoint {
    /// The parameter value.
    pub value: f64,
    /// The gait's stability verdict, or why no gait was found.
    #[serde(serialize_with = "crate::fmt::as_text")]
    pub status: PointStatus,
    /// The failure, in words.
    pub message: Option<String>,
    /// The gait, if found.
    pub gait: Option<Gait>,
    /// Index of the sweep point this gait was continued from (verified from both sides, see
    /// [`crate::family::natural`]); `None` if it was found from the sweep's initial state.
    #[serde(skip)]
    pub continued_from: Option<usize>,
    /// Gait family: points with the same number are connected by continuation; numbered from 0 in parameter
    /// order. `None` without a gait.
    pub family: Option<usize>,
    /// The continuations toward this point that did not reach it (from the left neighbour in the sweep, from
    /// the right one in the backward fill), kept so that the threshold search between the same two points
    /// reuses them instead of following the family to its end a second time ([`FollowAttempt`]).
    #[serde(skip)]
    pub attempts: Vec<FollowAttempt>,
}

/// A continuation that did not reach its target: where it started, where it was going and where it led (the
/// family's end bracketed to `PARAM_TOL`, or given up). `NaturalContinuation::follow` is a
/// deterministic function of its start, target and Newton matrix, so a threshold search that would follow the
/// same family from the same start to the same target takes this result as it is.
#[derive(Debug, Clone, PartialEq)]
pub struct FollowAttempt {
    /// The gait followed from.
    pub from: GaitPoint,
    /// The value followed to.
    pub target: f64,
    /// Where it led (never [`FollowOutcome::Reached`]).
    pub followed: FollowOutcome,
}

impl SweepPoint {
    /// The recorded continuation toward this point from `from` (same value and bitwise the same section state),
    /// if there is one.
    pub(crate) fn attempt_from(&self, from: &GaitPoint) -> Option<&FollowOutcome> {
        self.attempts
            .iter()
            .find(|a| a.from == *from && a.target == self.value)
            .map(|a| &a.followed)
    }
}

/// The gait a point of a row continues from.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Previous<'a> {
    /// Its index in the row.
    pub index: usize,
    /// Its parameter value.
    pub value: f64,
    /// The gait.
    pub gait: &'a Gait,
    /// How closely a family end met on the way is bracketed ([`NaturalContinuation::follow_to`]).
    pub end_tol: f64,
}

/// The gait at `value`, followed from `previous` (a neighbouring gait at another value) in verified
/// continuation steps if given; if the family does not reach `value`, searched from `initial` with the full
/// transient, for a period-k gait too if Newton's method fails on `P` ([`find_gait_any_period`]).
pub(crate) fn gait_at_value(
    parameter: Parameter,
    value: f64,
    initial: &SectionState,
    previous: Option<Previous>,
    options: &GaitOptions,
) -> SweepPoint {
    let at = match parameter.at(value) {
        Ok(at) => at,
        Err(e) => {
            return SweepPoint {
                value,
                status: PointStatus::InvalidParameter,
                message: Some(e.to_string()),
                gait: None,
                continued_from: None,
                family: None,
                attempts: Vec::new(),
            }
        }
    };
    let map = at.step_map();
    let options = &with_swept_parameter(options, parameter.key());
    let mut attempts = Vec::new();
    let continued = previous.and_then(|p| {
        match follow_gait(parameter, p.value, p.gait, value, options, p.end_tol) {
            Ok(g) => Some((p.index, g)),
            Err(attempt) => {
                attempts.extend(attempt);
                None
            }
        }
    });
    let (continued_from, result) = match continued {
        Some((index, g)) => (Some(index), Ok(g)),
        None => (
            None,
            find_gait_any_period(&map, initial, options, MAX_PERIOD),
        ),
    };
    match result {
        Ok(g) => SweepPoint {
            value,
            status: PointStatus::Gait(g.stability),
            message: None,
            gait: Some(g),
            continued_from,
            family: None,
            attempts,
        },
        Err(e) => SweepPoint {
            value,
            status: PointStatus::NoGait(e.kind()),
            message: Some(e.to_string()),
            gait: None,
            continued_from: None,
            family: None,
            attempts,
        },
    }
}

/// The tangent `ds*/dp = (I - DP)^-1 dP/dp` of the family of `g`, the gait at `from`, where its `dP/dp` is for
/// `parameter` (a sweep asks for it: [`with_swept_parameter`]): the predictor of the first continuation step.
pub(crate) fn family_tangent(parameter: &Parameter, from: f64, g: &Gait) -> Option<Tangent> {
    let d = g
        .dp_dparam
        .as_ref()
        .filter(|d| d.parameter == parameter.key())?;
    let dp = g.jacobian_guess()?;
    let n = dp.nrows();
    let rigid = parameter.config().params.rigid_legs;
    let free = free_coordinates(rigid || g.rear_held, g.section.slips());
    if free.len() != n || d.values.len() != n {
        return None;
    }
    let rates = (DMatrix::identity(n, n) - dp)
        .lu()
        .solve(&DVector::from_column_slice(&d.values))?;
    let mut full = [0.0; SECTION_COORDINATES.len()];
    for (k, &i) in free.iter().enumerate() {
        full[i] = rates[k];
    }
    Some(Tangent {
        at: from,
        rates: full,
    })
}

/// The options of a sweep along `param`: with `dP/dp` for it where it is differentiable (and no other
/// parameter was asked for), whose tangent predicts the next point ([`family_tangent`]); that `dP/dp` needs
/// no error estimate.
fn with_swept_parameter(options: &GaitOptions, param: &str) -> GaitOptions {
    let key = DIFFERENTIABLE_KEYS.iter().copied().find(|&k| k == param);
    match (options.parameter, key) {
        (None, Some(key)) => GaitOptions {
            parameter: Some(key),
            refine_dparam: false,
            ..*options
        },
        _ => *options,
    }
}

/// The gait at `value` of the family of `g`, the gait at `from`: the family followed in verified steps
/// ([`NaturalContinuation::follow`]), then the full gait (with `DP`) where it lands. If the family does not reach
/// `value`, the attempt (for [`SweepPoint::attempts`]); `Err(None)` if it reaches it but the gait there cannot be
/// completed.
fn follow_gait(
    parameter: Parameter,
    from: f64,
    g: &Gait,
    value: f64,
    options: &GaitOptions,
    end_tol: f64,
) -> Result<Gait, Option<FollowAttempt>> {
    let guess = g.jacobian_guess();
    let start = GaitPoint {
        value: from,
        section: g.section,
    };
    let cont = NaturalContinuation::new(parameter, options).with_period(g.period_k);
    let tangent = family_tangent(&parameter, from, g);
    let p = match cont.follow_to(start, value, (guess.as_ref(), tangent), end_tol) {
        FollowOutcome::Reached(p) => p,
        followed => {
            return Err(Some(FollowAttempt {
                from: start,
                target: value,
                followed,
            }))
        }
    };
    // The family reached `value`, which is in the parameter's domain.
    let at = parameter.at(value).map_err(|_| None)?;
    let map = at.step_map();
    let opts = GaitOptions {
        transient_steps: 0,
        ..*options
    };
    if g.period_k == 1 {
        return gait_at_converged(&map, &p.section, &opts, guess.as_ref()).map_err(|_| None);
    }
    let fp = solve_fixed_point(&map.iterated(g.period_k), &p.section, &opts, guess.as_ref())
        .map_err(|_| None)?;
    periodic_gait_at(&map, &fp, g.period_k, &opts)
        .ok()
        // The family keeps its period: a point where the gait's least period drops is not continued.
        .filter(|gait| gait.period_k == g.period_k)
        .ok_or(None)
}

/// The point's gait if continuation can start from it: any gait (a period-k gait is continued as a fixed
/// point of `P^k`).
fn continuable(point: &SweepPoint) -> Option<&Gait> {
    point.gait.as_ref()
}

/// Points without a gait just left of a gait (or of a stretch of gaits) may be misses of the search from the
/// initial state: follow each such gait backwards, from right to left, and fill in the points its family
/// reaches. Sequential and in a fixed order, so deterministic.
fn backfill(parameter: Parameter, points: &mut [SweepPoint], options: &GaitOptions) {
    for i in (1..points.len()).rev() {
        let (left, right) = points.split_at_mut(i);
        let (a, b) = (&mut left[i - 1], &right[0]);
        let (None, Some(gb)) = (&a.gait, continuable(b)) else {
            continue;
        };
        if a.status == PointStatus::InvalidParameter {
            continue;
        }
        match follow_gait(parameter, b.value, gb, a.value, options, PARAM_TOL) {
            Ok(g) => {
                a.status = PointStatus::Gait(g.stability);
                a.message = None;
                a.gait = Some(g);
                a.continued_from = Some(i);
            }
            Err(attempt) => a.attempts.extend(attempt),
        }
    }
}

/// Number the gait families: a point continued from another shares its family; a point found from the initial
/// state starts a new one, unless a verified continuation step connects it to its left neighbour's gait.
pub(crate) fn number_families(
    parameter: Parameter,
    points: &mut [SweepPoint],
    options: &GaitOptions,
) {
    // Roots of the continuation forest: a gait found from the initial state is its own root.
    let root_of = |i: usize| {
        let mut j = i;
        for _ in 0..=points.len() {
            points[j].gait.as_ref()?;
            match points[j].continued_from {
                Some(k) if points[k].gait.is_some() => j = k,
                _ => return Some(j),
            }
        }
        None
    };
    let mut root: Vec<Option<usize>> = (0..points.len()).map(root_of).collect();
    // Fresh gaits that continue their left neighbour's family join it.
    for i in 1..points.len() {
        let (Some(ri), Some(rl)) = (root[i], root[i - 1]) else {
            continue;
        };
        if ri == rl || points[i].continued_from.is_some() {
            continue;
        }
        let (a, b) = (&points[i - 1], &points[i]);
        let (Some(ga), Some(gb)) = (&a.gait, &b.gait) else {
            continue;
        };
        if ga.period_k != gb.period_k {
            continue;
        }
        let start = GaitPoint {
            value: a.value,
            section: ga.section,
        };
        let connected = NaturalContinuation::new(parameter, options)
            .with_period(ga.period_k)
            .step(&start, b.value, ga.jacobian_guess().as_ref())
            .is_some_and(|p| p.section.distance(&gb.section) <= SAME_GAIT_TOL);
        if connected {
            for r in root.iter_mut().filter(|r| **r == Some(ri)) {
                *r = Some(rl);
            }
        }
    }
    let mut ids: Vec<usize> = Vec::new();
    for (p, r) in points.iter_mut().zip(&root) {
        p.family = r.map(|r| match ids.iter().position(|&x| x == r) {
            Some(k) => k,
            None => {
                ids.push(r);
                ids.len() - 1
            }
        });
    }
}

/// One row of gait points: a configuration and the values one of its parameters takes along the row.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GaitRow {
    /// Parameters and solver options (`key` is overridden point by point).
    pub config: Config,
    /// The numeric key that varies along the row.
    pub key: NumericKey,
    /// Its values, in the order they are continued.
    pub values: Vec<f64>,
}

/// The gaits along the rows `part` (within `0..rows.len()`) of `rows`, each row continued with the sweep's rules
/// (see the module documentation), each exactly as the whole grid has it: continuation from the left neighbour
/// on the [`super::grid`] runner's schedule, a search from `initial` where the family does not reach, then the
/// backward fill of misses and family numbers within the row. Rows run in parallel, and the results are
/// bitwise identical for any number of threads. `progress` is called after every point. A row's values that
/// leave the valid domain give points with the status `invalid_parameter`. Once the library's
/// [`interrupt_flag`](super::grid::interrupt_flag) is set, each row is cut to its complete prefix, without the
/// backward fill and the family numbers (also where the flag was set during them).
///
/// With the rows, their task graph ([`super::parallelism`]): a task per point on the grid runner's schedule,
/// then one per row (its backward fill and family numbers) after the row's points.
pub(crate) fn gait_rows_measured(
    rows: &[GaitRow],
    part: Range<usize>,
    initial: &SectionState,
    options: &GaitOptions,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> (Vec<Vec<SweepPoint>>, TaskGraph) {
    let cols = rows.iter().map(|r| r.values.len()).max().unwrap_or(0);
    let GridRun {
        rows: mut points,
        mut graph,
        row_done,
    } = run_rows_measured(
        part.clone(),
        rows.len(),
        cols,
        |cell, from: Option<(usize, &Gait)>| {
            let row = &rows[cell.row];
            let Some(&value) = row.values.get(cell.col) else {
                // A shorter row: nothing here (dropped below).
                return Evaluated {
                    point: None,
                    carry: None,
                };
            };
            // A coarse point continues the previous coarse point over several grid intervals: where that
            // family ends, its end is needed only to a grid interval (the fill between the two brackets it to
            // `PARAM_TOL` from the neighbouring point, which is what thresholds use).
            let previous = from.map(|(j, g)| {
                let end_tol = if cell.col - j > 1 {
                    (value - row.values[j]).abs() / (cell.col - j) as f64
                } else {
                    PARAM_TOL
                };
                Previous {
                    index: j,
                    value: row.values[j],
                    gait: g,
                    end_tol,
                }
            });
            let parameter = Parameter::new(&row.config, row.key);
            let point = gait_at_value(parameter, value, initial, previous, options);
            progress(&point);
            Evaluated {
                carry: continuable(&point).cloned(),
                point: Some(point),
            }
        },
    );
    let finished: Vec<(Vec<SweepPoint>, Cost)> = rows[part]
        .par_iter()
        .zip(points.par_iter_mut())
        .map(carried(
            |(row, points): (&GaitRow, &mut Vec<Option<SweepPoint>>)| {
                measured(|| {
                    let mut points: Vec<SweepPoint> = points.drain(..).flatten().collect();
                    // An interrupted row keeps its points as computed (no further searches); so does a row whose
                    // backward fill or family numbers the flag cut short (their walks stop with it).
                    if crate::walk::interrupted() {
                        return points;
                    }
                    let computed = points.clone();
                    let parameter = Parameter::new(&row.config, row.key);
                    backfill(parameter, &mut points, options);
                    number_families(parameter, &mut points, options);
                    if crate::walk::interrupted() {
                        return computed;
                    }
                    points
                })
            },
        ))
        .collect();
    let rows = finished
        .into_iter()
        .zip(row_done)
        .map(|((points, cost), done)| {
            graph.task(cost, &[done]);
            points
        })
        .collect();
    (rows, graph)
}

/// Sweep `spec.param` over its range with continuation, calling `progress` after each point: one row of
/// `gait_rows_measured`.
pub fn sweep(
    config: &Config,
    spec: &SweepSpec,
    initial: &SectionState,
    options: &GaitOptions,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<Vec<SweepPoint>, ConfigError> {
    spec.validate(config)?;
    sweep_values(
        config,
        &spec.param,
        &spec.values(),
        initial,
        options,
        progress,
    )
}

/// Checks a list of values of the real-valued key `param` before a `command` (`sweep`, ...) computes
/// anything: 1 to `max_points` of them, each finite, and the configuration valid at the smallest and the
/// largest (the rules on one key are intervals, so it is then valid at every value). The error names the
/// command, the key, the value, its position in the list, and the rule it breaks.
pub fn check_values(
    config: &Config,
    param: &str,
    values: &[f64],
    command: &str,
    max_points: usize,
) -> Result<(), ConfigError> {
    let parameter = Parameter::named(config, param)?;
    let invalid = |value: String, reason: String| ConfigError::InvalidValue {
        key: format!("{command} {param}"),
        value,
        reason,
    };
    let n = values.len();
    if !(1..=max_points).contains(&n) {
        return Err(invalid(
            format!("{n} values"),
            format!("{command} takes between 1 and {max_points} values"),
        ));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(invalid(
            short(values[i]),
            format!("value {} of {n} is not a finite number", i + 1),
        ));
    }
    let by_value = |a: &&f64, b: &&f64| a.total_cmp(b);
    let ends = [
        values.iter().min_by(by_value),
        values.iter().max_by(by_value),
    ];
    for &value in ends.into_iter().flatten() {
        if let Err(e) = parameter.at(value) {
            let i = values.iter().position(|v| *v == value).unwrap_or(0);
            let rule = match &e {
                ConfigError::InvalidValue { key, reason, .. } if key == param => reason.clone(),
                other => other.to_string(),
            };
            return Err(invalid(
                short(value),
                format!("value {} of {n} is outside the valid domain: {rule}", i + 1),
            ));
        }
    }
    Ok(())
}

/// Sweep the real-valued key `param` over the given `values` (in the order given) with continuation, as
/// [`sweep`] does over a [`SweepSpec`]'s evenly spaced values: one row of `gait_rows_measured`.
///
/// Before anything is computed, the values are checked against the parameter's domain ([`check_values`])
/// and the settings against their ranges ([`GaitOptions::validate`]): a value outside the domain is an error
/// naming it and the rule, never a point without a gait (whose edge would pass for a threshold).
pub fn sweep_values(
    config: &Config,
    param: &str,
    values: &[f64],
    initial: &SectionState,
    options: &GaitOptions,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<Vec<SweepPoint>, ConfigError> {
    let row = checked_row(config, param, values, options)?;
    let (mut rows, _) = gait_rows_measured(&[row], 0..1, initial, options, progress);
    Ok(rows.pop().unwrap_or_default())
}

/// The row of [`sweep_values`] (`param` over `values` on `config`), its values and `options` checked first;
/// [`gait_rows_measured`] of it alone is the sweep with its task graph.
pub(crate) fn checked_row(
    config: &Config,
    param: &str,
    values: &[f64],
    options: &GaitOptions,
) -> Result<GaitRow, ConfigError> {
    check_values(config, param, values, "sweep", MAX_SWEEP_POINTS)?;
    options.validate()?;
    Ok(GaitRow {
        config: config.clone(),
        key: NumericKey::new(param)?,
        values: values.to_vec(),
    })
}
