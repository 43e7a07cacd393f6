//! Maps over two parameters: the gait at every point of an `x` by `y` grid, and the threshold curves across
//! the plane (docs/model.md section 6).
//!
//! **Gaits.** Every row (fixed `y`) is a sweep along `x` with the sweep's rules (`gait_rows_measured` on
//! the `grid` runner): continuation from the left neighbour, a search from the initial state where the
//! family ends, backward fill and family numbers. Rows run in parallel and the map is bitwise identical for any
//! number of threads. So row `j` of a map is exactly the sweep along `x` at `y_j`.
//!
//! **Curves.** The threshold curves (`lambda_4+ = 0`, `lambda_2+ = 0`, `lambda_I4 = 0`, loss of stability, the
//! end of existence, branch switches, folds) are never read off the grid. Every row is searched for the 1-D
//! thresholds of [`find_thresholds`](super::find_thresholds) (refined to `PARAM_TOL` in `x`; the family ends come
//! from the continuations that found the row's gaits, [`super::sweep::SweepPoint::attempts`]), and so are the
//! columns [`curve_columns`] picks, at most `max_columns` of them, evenly spread with both ends (fixed `x`,
//! refined to `PARAM_TOL` in `y`; the column's gaits are those of the rows, and neighbours
//! along the column belong to one family when a verified continuation step in `y` connects them). Each crossing
//! lies on one edge of the grid. Within each cell between two neighbouring rows and two neighbouring refined
//! columns, the crossings of one curve on its edges are joined (two crossings: one segment, as in marching
//! squares; more: the closest pairs first), and the segments are chained into polylines. A polyline's points
//! are all refined crossings; only the straight pieces between them are drawn.
//!
//! The curve of the end of existence joins `gait_lost` and `gait_found` crossings (which of the two a crossing
//! is depends only on the direction of the line it was refined on).

use std::ops::Range;

use rayon::prelude::*;
use serde::Serialize;

use super::parallelism::{measured, Cost, TaskGraph};
use super::sweep::{
    gait_rows_measured, number_families, GaitRow, RangeNames, SweepPoint, SweepSpec,
};
use super::thresholds::{find_thresholds_costed, Threshold};
use crate::family::Parameter;
use crate::fmt::short;
use crate::gait::limit_cycle::GaitOptions;
use crate::meter::carried;
use crate::params::{Config, ConfigError, NumericKey};
use crate::walk::SectionState;

/// The most values along one axis of a map.
pub const MAX_MAP_AXIS_POINTS: usize = 2000;

/// `vrw map`'s horizontal axis: `x_from`, `x_to`, `nx` (at most [`MAX_MAP_AXIS_POINTS`]).
pub const MAP_X_RANGE: RangeNames = RangeNames {
    command: "map x",
    from: "x_from",
    to: "x_to",
    points: "nx",
    max_points: MAX_MAP_AXIS_POINTS,
};

/// `vrw map`'s vertical axis: `y_from`, `y_to`, `ny` (at most [`MAX_MAP_AXIS_POINTS`]).
pub const MAP_Y_RANGE: RangeNames = RangeNames {
    command: "map y",
    from: "y_from",
    to: "y_to",
    points: "ny",
    max_points: MAX_MAP_AXIS_POINTS,
};

/// What to map: two parameters and their ranges.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MapSpec {
    /// The parameter along rows (horizontal axis) and its values.
    pub x: SweepSpec,
    /// The parameter along columns (vertical axis) and its values.
    pub y: SweepSpec,
}

impl MapSpec {
    /// Check the specification: each axis as a sweep ([`SweepSpec::validate`]), two different parameters, at
    /// most [`MAX_MAP_AXIS_POINTS`] values per axis, and a valid configuration at the four corners (the rules
    /// that join two keys are linear inequalities, so the whole rectangle is then valid).
    pub fn validate(&self, config: &Config) -> Result<(), ConfigError> {
        self.x.validate_as(config, &MAP_X_RANGE)?;
        self.y.validate_as(config, &MAP_Y_RANGE)?;
        let invalid = |key: &str, value: String, reason: String| ConfigError::InvalidValue {
            key: key.to_string(),
            value,
            reason,
        };
        if self.x.param == self.y.param {
            return Err(invalid(
                "map",
                format!("`x` {} `y` {}", self.x.param, self.y.param),
                "the two axes must be different parameters".to_string(),
            ));
        }
        for x in [self.x.from, self.x.to] {
            for y in [self.y.from, self.y.to] {
                let mut corner = config.clone();
                corner.set_numeric(&self.x.param, x)?;
                corner.set_numeric(&self.y.param, y)?;
                if let Err(e) = corner.validate() {
                    return Err(invalid(
                        "map",
                        format!(
                            "{} = {}, {} = {}",
                            self.x.param,
                            short(x),
                            self.y.param,
                            short(y)
                        ),
                        format!("a corner of the map leaves the valid domain: {e}"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The configuration with the `y` parameter at `y` (a row's configuration).
    fn with_y(&self, config: &Config, y: f64) -> Config {
        let mut c = config.clone();
        // Validated: the key exists.
        let _ = c.set_numeric(&self.y.param, y);
        c
    }

    /// The configuration with the `x` parameter at `x` (a column's configuration).
    fn with_x(&self, config: &Config, x: f64) -> Config {
        let mut c = config.clone();
        let _ = c.set_numeric(&self.x.param, x);
        c
    }
}

/// The gaits of a map.
#[derive(Debug, Clone, PartialEq)]
pub struct GaitMap {
    /// What was mapped.
    pub spec: MapSpec,
    /// The `x` values (columns).
    pub xs: Vec<f64>,
    /// The `y` values (rows).
    pub ys: Vec<f64>,
    /// `rows[j][i]` is the point at `(xs[i], ys[j])`; its `value` is `xs[i]`, its family is numbered within
    /// row `j`.
    pub rows: Vec<Vec<SweepPoint>>,
}

/// The gait at every point of the map, rows continued along `x` with the sweep's rules, rows in parallel
/// (see the module documentation). `progress` is called after every point.
pub fn map_gaits(
    config: &Config,
    spec: &MapSpec,
    initial: &SectionState,
    options: &GaitOptions,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<GaitMap, ConfigError> {
    let all = 0..spec.y.points;
    map_gaits_measured(config, spec, all, initial, options, progress).map(|m| m.0)
}

/// The rows `part` (indices of `y` values, within `0..spec.y.points`) of [`map_gaits`]: each row's points
/// exactly as the whole map has them, so a map computed in parts (a study spread over processes) is the map.
/// The returned map has those rows and their `ys` only. With their task graph: a task per point on the grid
/// runner's schedule and one per row (its backward fill and family numbers) ([`super::parallelism`]).
pub fn map_gaits_measured(
    config: &Config,
    spec: &MapSpec,
    part: Range<usize>,
    initial: &SectionState,
    options: &GaitOptions,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<(GaitMap, TaskGraph), ConfigError> {
    spec.validate(config)?;
    options.validate()?;
    check_part(&part, spec.y.points)?;
    let xs = spec.x.values();
    let ys = spec.y.values();
    let key = NumericKey::new(&spec.x.param)?;
    let rows: Vec<GaitRow> = ys
        .iter()
        .map(|&y| GaitRow {
            config: spec.with_y(config, y),
            key,
            values: xs.clone(),
        })
        .collect();
    let (rows, graph) = gait_rows_measured(&rows, part.clone(), initial, options, progress);
    let map = GaitMap {
        spec: spec.clone(),
        xs,
        ys: ys[part].to_vec(),
        rows,
    };
    Ok((map, graph))
}

/// A part of a grid's rows must be a non-empty range of its `rows` rows.
pub fn check_part(part: &Range<usize>, rows: usize) -> Result<(), ConfigError> {
    if part.start < part.end && part.end <= rows {
        return Ok(());
    }
    Err(ConfigError::InvalidValue {
        key: "rows".to_string(),
        value: format!("{}..{}", part.start, part.end),
        reason: format!("a part of the grid's rows is a non-empty range within 0..{rows}"),
    })
}

/// Which grid line a crossing was refined on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Along {
    /// A row: `y` fixed at `ys[line]`, refined in `x`.
    X,
    /// A column: `x` fixed at `xs[line]`, refined in `y`.
    Y,
}

/// Where a curve point comes from: the 1-D threshold it is.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RefinedOn {
    /// The direction it was refined in.
    pub along: Along,
    /// The row (for [`Along::X`]) or column (for [`Along::Y`]) index.
    pub line: usize,
    /// The 1-D threshold's name (`gait_lost`, `lambda_4_plus = 0`, ...).
    pub threshold: String,
}

/// A threshold curve across the map: a polyline through refined crossings.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThresholdCurve {
    /// `lambda_4_plus = 0`, `lambda_2_plus = 0`, `lambda_I4 = 0`, `stability_lost`, `existence_end`
    /// (`gait_lost` and `gait_found`), `branch_switch`, `fold` or `unconfirmed`.
    pub name: String,
    /// The points `[x, y]`, in order along the curve.
    pub points: Vec<[f64; 2]>,
    /// For each point, the line it was refined on.
    pub refined_on: Vec<RefinedOn>,
    /// The curve is closed (its last point joins its first).
    pub closed: bool,
    /// How the curve was computed.
    pub method: CurveMethod,
}

/// How a threshold curve of a map was computed.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CurveMethod {
    /// The refined crossings of the rows and refined columns, joined cell by cell (see the module
    /// documentation); `refined_on` says where each point comes from.
    Crossings,
    /// Followed by pseudo-arclength continuation of the fixed point together with `border = offset` in both
    /// parameters (docs/model.md section 11), from the crossing `seed` of a row (`refined_on` is empty: the
    /// points are the curve's own).
    Continuation(ContinuedCurve),
}

/// A threshold curve followed by continuation: where from, how it ends, and its check against the rows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContinuedCurve {
    /// The row crossing it was started from.
    pub seed: RefinedOn,
    /// The function that is zero along the curve: a DLS indicator (`lambda_2_plus`, ...) or a test function
    /// of `DP` (`det(DP - I)` for a fold, `det(DP + I)` for a period doubling, `bialternate product`).
    pub condition: String,
    /// The value of that function followed: for an indicator, a small number on the side of the gaits it was
    /// started from; 0 for a test function.
    pub offset: f64,
    /// How it ends at its first point and at its last (`left_range`, `max_points`, or the failure).
    pub ends: [String; 2],
    /// The largest `|P(x) - x|` of its points.
    pub max_residual: f64,
    /// The largest `|border - offset|` of its points.
    pub max_test_value: f64,
    /// The rows and refined columns whose crossing of the same threshold lies on it: the curve solved for at
    /// the line's `y` (a row) or `x` (a column) is within [`LINE_CHECK_TOL`] of the line's refined threshold
    /// (the lines are the curve's second route; their crossings on it are drawn by it).
    pub lines_checked: usize,
    /// The largest of those differences (`NaN` if no line was checked).
    pub max_line_difference: f64,
    /// Crossings of the same threshold within one grid cell of the curve but not on it (farther than
    /// [`LINE_CHECK_TOL`], or the curve could not be solved for on their line): another border nearby, such
    /// as a period-2 family's where the curve is a period-1 family's; they keep their curves through the
    /// crossings.
    pub near_misses: Vec<NearMiss>,
    /// How it was computed, in words.
    pub description: String,
}

/// A crossing near a continued curve but not on it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NearMiss {
    /// The line's direction.
    pub along: Along,
    /// The line.
    pub line: usize,
    /// The line's refined threshold.
    pub value: f64,
    /// Its distance from the curve on that line (`NaN`: the curve could not be solved for there).
    pub difference: f64,
}

/// A continued curve agrees with the lines' refined thresholds when none differs by more than this: a line's
/// threshold is the middle of a bracket at most `PARAM_TOL` wide, and the curve lies `offset / |grad border|`
/// (about `1e-7`) from the border.
pub const LINE_CHECK_TOL: f64 = 2.0 * crate::family::natural::PARAM_TOL;

/// A 1-D threshold of a row or a column.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LineThreshold {
    /// The line.
    pub along: Along,
    /// Its index.
    pub line: usize,
    /// The threshold, in the line's parameter.
    pub threshold: Threshold,
}

/// The curves of a map, and the 1-D thresholds they come from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MapCurves {
    /// The curves.
    pub curves: Vec<ThresholdCurve>,
    /// Every 1-D threshold of the rows and columns, including those that could not be refined (`value` NaN,
    /// with the reason in `detail`), which are in no curve.
    pub thresholds: Vec<LineThreshold>,
}

/// The curve a 1-D threshold belongs to.
pub(crate) fn curve_name(threshold: &str) -> &str {
    match threshold {
        "gait_lost" | "gait_found" => "existence_end",
        // One curve where the largest multiplier crosses the unit circle, whichever side is stable along a
        // line (rows and columns cross it in different directions); it keeps its established name.
        "stability_regained" | "period_doubling" => "stability_lost",
        other => other,
    }
}

/// The most columns [`map_curves`] refines by default (`vrw map --curve-columns`).
pub const DEFAULT_CURVE_COLUMNS: usize = 25;

/// The columns the curves are refined on, for `nx` columns and at most `max_columns` of them (at least 2):
/// every `ceil((nx - 1) / (max_columns - 1))`-th column from the first, and the last; all of them when
/// `max_columns >= nx`.
pub fn curve_columns(nx: usize, max_columns: usize) -> Vec<usize> {
    if nx == 0 {
        return Vec::new();
    }
    let stride = (nx - 1).div_ceil(max_columns.max(2) - 1).max(1);
    let mut columns: Vec<usize> = (0..nx).step_by(stride).collect();
    if columns.last() != Some(&(nx - 1)) {
        columns.push(nx - 1);
    }
    columns
}

/// The 1-D thresholds of every row of `map` and of the columns [`curve_columns`] picks (at most `max_columns`),
/// and the curves through them (see the module documentation).
///
/// # Errors
/// A parameter of the map's spec is not a numeric key.
pub fn map_curves(
    config: &Config,
    map: &GaitMap,
    options: &GaitOptions,
    max_columns: usize,
) -> Result<MapCurves, ConfigError> {
    map_curves_measured(config, map, options, max_columns).map(|c| c.0)
}

/// [`map_curves`] with its task graph ([`super::parallelism`]): every refinement of a row's or column's
/// threshold search is a task (a column's after the task that numbers its families). The rows and the columns
/// are searched together, all lines in parallel.
pub fn map_curves_measured(
    config: &Config,
    map: &GaitMap,
    options: &GaitOptions,
    max_columns: usize,
) -> Result<(MapCurves, TaskGraph), ConfigError> {
    let columns = curve_columns(map.xs.len(), max_columns);
    let spec = &map.spec;
    let keys = (
        NumericKey::new(&spec.x.param)?,
        NumericKey::new(&spec.y.param)?,
    );
    let lines: Vec<(Along, usize)> = (0..map.rows.len())
        .map(|j| (Along::X, j))
        .chain(columns.iter().map(|&i| (Along::Y, i)))
        .collect();
    let searched: Vec<LineSearch> = lines
        .par_iter()
        .with_max_len(1)
        .map(carried(|&(along, line): &(Along, usize)| {
            line_search(config, map, options, keys, along, line)
        }))
        .collect();
    let mut graph = TaskGraph::new();
    let mut thresholds: Vec<LineThreshold> = Vec::new();
    for s in searched {
        let after: Vec<usize> = s.families.map(|c| graph.task(c, &[])).into_iter().collect();
        for cost in s.refinements {
            graph.task(cost, &after);
        }
        thresholds.extend(s.thresholds);
    }
    let curves = connect(&map.xs, &map.ys, &columns, &thresholds);
    Ok((MapCurves { curves, thresholds }, graph))
}

/// One line's threshold search and its tasks.
struct LineSearch {
    thresholds: Vec<LineThreshold>,
    /// A column's family numbers (a row's come with its gaits).
    families: Option<Cost>,
    /// Each refinement.
    refinements: Vec<Cost>,
}

/// The thresholds of row `line` (`Along::X`) or column `line` (`Along::Y`) of `map`, `keys` the `x` and `y`
/// keys.
fn line_search(
    config: &Config,
    map: &GaitMap,
    options: &GaitOptions,
    keys: (NumericKey, NumericKey),
    along: Along,
    line: usize,
) -> LineSearch {
    let spec = &map.spec;
    let (thresholds, families) = match along {
        Along::X => {
            let c = spec.with_y(config, map.ys[line]);
            let parameter = Parameter::new(&c, keys.0);
            (
                find_thresholds_costed(parameter, &map.rows[line], options),
                None,
            )
        }
        Along::Y => {
            let c = spec.with_x(config, map.xs[line]);
            let mut points: Vec<SweepPoint> = map
                .rows
                .iter()
                .zip(&map.ys)
                .map(|(row, &y)| SweepPoint {
                    value: y,
                    continued_from: None,
                    family: None,
                    // The rows' continuations were along x: none of them is a step along this column.
                    attempts: Vec::new(),
                    ..row[line].clone()
                })
                .collect();
            let parameter = Parameter::new(&c, keys.1);
            let ((), families) = measured(|| number_families(parameter, &mut points, options));
            (
                find_thresholds_costed(parameter, &points, options),
                Some(families),
            )
        }
    };
    LineSearch {
        thresholds: line_thresholds(along, line, thresholds.0),
        families,
        refinements: thresholds.1,
    }
}

fn line_thresholds(along: Along, line: usize, thresholds: Vec<Threshold>) -> Vec<LineThreshold> {
    let mut thresholds: Vec<LineThreshold> = thresholds
        .into_iter()
        .map(|threshold| LineThreshold {
            along,
            line,
            threshold,
        })
        .collect();
    thresholds.sort_by(|a, b| a.threshold.value.total_cmp(&b.threshold.value));
    thresholds
}

/// A refined crossing on a grid edge.
#[derive(Debug, Clone, Copy)]
struct Crossing<'a> {
    /// Index of the threshold it comes from.
    index: usize,
    /// The edge: the lower-left grid point `(i, j)` and the direction of the edge.
    edge: (usize, usize, Along),
    /// In grid units (`i + fraction`, `j + fraction`), for distances.
    grid: [f64; 2],
    point: [f64; 2],
    name: &'a str,
}

/// Position of `v` in `values` (exact: the grid brackets are copies of the grid values).
fn grid_index(values: &[f64], v: f64) -> Option<usize> {
    values.iter().position(|&x| x == v)
}

/// Join the refined crossings into curves (see the module documentation); `columns` are the refined columns.
fn connect(
    xs: &[f64],
    ys: &[f64],
    columns: &[usize],
    thresholds: &[LineThreshold],
) -> Vec<ThresholdCurve> {
    let fraction = |values: &[f64], k: usize, v: f64| {
        let step = values.get(k + 1).map_or(1.0, |next| next - values[k]);
        k as f64 + (v - values[k]) / step
    };
    let crossings: Vec<Crossing> = thresholds
        .iter()
        .enumerate()
        .filter(|(_, t)| t.threshold.value.is_finite())
        .filter_map(|(index, t)| {
            let th = &t.threshold;
            let lo = th.grid_bracket[0].min(th.grid_bracket[1]);
            let name = curve_name(&th.name);
            match t.along {
                Along::X => {
                    let i = grid_index(xs, lo)?;
                    let (x, y) = (th.value, ys[t.line]);
                    Some(Crossing {
                        index,
                        edge: (i, t.line, Along::X),
                        grid: [fraction(xs, i, x), t.line as f64],
                        point: [x, y],
                        name,
                    })
                }
                Along::Y => {
                    let j = grid_index(ys, lo)?;
                    let (x, y) = (xs[t.line], th.value);
                    Some(Crossing {
                        index,
                        edge: (t.line, j, Along::Y),
                        grid: [t.line as f64, fraction(ys, j, y)],
                        point: [x, y],
                        name,
                    })
                }
            }
        })
        .collect();
    let mut names: Vec<&str> = crossings.iter().map(|c| c.name).collect();
    names.sort_unstable();
    names.dedup();
    let mut curves = Vec::new();
    for name in names {
        let own: Vec<&Crossing> = crossings.iter().filter(|c| c.name == name).collect();
        for chain in chains(columns, ys.len(), &own) {
            let closed = chain.len() > 2 && chain.first() == chain.last();
            let chain = if closed {
                &chain[..chain.len() - 1]
            } else {
                &chain[..]
            };
            curves.push(ThresholdCurve {
                name: name.to_string(),
                points: chain.iter().map(|&k| own[k].point).collect(),
                refined_on: chain
                    .iter()
                    .map(|&k| {
                        let t = &thresholds[own[k].index];
                        RefinedOn {
                            along: t.along,
                            line: t.line,
                            threshold: t.threshold.name.clone(),
                        }
                    })
                    .collect(),
                closed,
                method: CurveMethod::Crossings,
            });
        }
    }
    curves
}

/// The crossings of one curve (indices into `own`) chained into polylines: segments within each cell, then
/// chains through shared crossings. A cell lies between two neighbouring refined `columns` and two neighbouring
/// rows (one grid cell wide when every column is refined). A closed chain repeats its first index at the end.
fn chains(columns: &[usize], ny: usize, own: &[&Crossing]) -> Vec<Vec<usize>> {
    let distance = |a: usize, b: usize| {
        let (p, q) = (own[a].grid, own[b].grid);
        (p[0] - q[0]).hypot(p[1] - q[1])
    };
    // Crossings by edge; an edge may carry more than one crossing of a curve only by a refinement oddity, and
    // then each is kept.
    let mut by_edge: std::collections::BTreeMap<(usize, usize, u8), Vec<usize>> =
        std::collections::BTreeMap::new();
    for (k, c) in own.iter().enumerate() {
        let (i, j, along) = c.edge;
        by_edge
            .entry((i, j, u8::from(along == Along::Y)))
            .or_default()
            .push(k);
    }
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); own.len()];
    for pair in columns.windows(2) {
        let (left, right) = (pair[0], pair[1]);
        for j in 0..ny.saturating_sub(1) {
            // The cell's edges: bottom, top (the grid edges of rows j and j + 1 between the two columns), left,
            // right (the two columns between rows j and j + 1).
            let edges = (left..right)
                .flat_map(|i| [(i, j, 0), (i, j + 1, 0)])
                .chain([(left, j, 1), (right, j, 1)]);
            let mut here: Vec<usize> = edges
                .filter_map(|e| by_edge.get(&e))
                .flatten()
                .copied()
                .collect();
            here.sort_unstable();
            for (a, b) in pair_up(&here, &distance) {
                neighbours[a].push(b);
                neighbours[b].push(a);
            }
        }
    }
    let mut used = vec![false; own.len()];
    let mut out = Vec::new();
    let walk = |start: usize, used: &mut Vec<bool>| {
        let mut chain = vec![start];
        used[start] = true;
        let mut current = start;
        loop {
            let next = neighbours[current].iter().copied().find(|&n| !used[n]);
            match next {
                Some(n) => {
                    used[n] = true;
                    chain.push(n);
                    current = n;
                }
                None => {
                    if chain.len() > 2 && neighbours[current].contains(&start) {
                        chain.push(start);
                    }
                    return chain;
                }
            }
        }
    };
    // Open chains start at their ends (a crossing with at most one neighbour), then what is left is closed.
    for k in 0..own.len() {
        if !used[k] && neighbours[k].len() <= 1 {
            out.push(walk(k, &mut used));
        }
    }
    for k in 0..own.len() {
        if !used[k] {
            out.push(walk(k, &mut used));
        }
    }
    out
}

/// Pair the crossings of one cell: two make a segment; of more, the closest pairs are taken first
/// (an odd one out is left as the end of a curve).
fn pair_up(here: &[usize], distance: &dyn Fn(usize, usize) -> f64) -> Vec<(usize, usize)> {
    match here.len() {
        0 | 1 => Vec::new(),
        2 => vec![(here[0], here[1])],
        _ => {
            // Greedy by distance: exact for four points in the usual saddle case, and deterministic.
            let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
            for (ia, &a) in here.iter().enumerate() {
                for &b in &here[ia + 1..] {
                    pairs.push((distance(a, b), a, b));
                }
            }
            pairs.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)).then(p.2.cmp(&q.2)));
            let mut taken: Vec<usize> = Vec::new();
            let mut out = Vec::new();
            for (_, a, b) in pairs {
                if !taken.contains(&a) && !taken.contains(&b) {
                    taken.extend([a, b]);
                    out.push((a, b));
                }
            }
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn crossing(index: usize, edge: (usize, usize, Along), grid: [f64; 2]) -> Crossing<'static> {
        Crossing {
            index,
            edge,
            grid,
            point: grid,
            name: "c",
        }
    }

    /// A straight curve across three cells of one row of cells, and a closed loop around one grid point.
    #[test]
    fn crossings_chain_into_open_and_closed_curves() {
        // The line y = 0.5 crosses the columns 0..3 (vertical edges of cells (0,0), (1,0), (2,0)).
        let line: Vec<Crossing> = (0..4)
            .map(|i| crossing(i, (i, 0, Along::Y), [i as f64, 0.5]))
            .collect();
        let refs: Vec<&Crossing> = line.iter().rev().collect();
        let found = chains(&[0, 1, 2, 3], 2, &refs);
        assert_eq!(found.len(), 1);
        let order: Vec<usize> = found[0].iter().map(|&k| refs[k].index).collect();
        assert!(order == [0, 1, 2, 3] || order == [3, 2, 1, 0], "{order:?}");
        // A small loop around the grid point (1, 1): four crossings on the four edges meeting there.
        let ring = [
            crossing(0, (0, 1, Along::X), [0.5, 1.0]),
            crossing(1, (1, 0, Along::Y), [1.0, 0.5]),
            crossing(2, (1, 1, Along::X), [1.5, 1.0]),
            crossing(3, (1, 1, Along::Y), [1.0, 1.5]),
        ];
        let refs: Vec<&Crossing> = ring.iter().collect();
        let found = chains(&[0, 1, 2], 3, &refs);
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].len(), 5, "closed: {found:?}");
        assert_eq!(found[0].first(), found[0].last());
    }

    /// With only columns 0 and 3 refined, a cell spans three grid cells: a curve entering through column 0 and
    /// crossing rows 1 and 2 is still one polyline.
    #[test]
    fn crossings_chain_across_cells_between_refined_columns() {
        let curve = [
            crossing(0, (0, 0, Along::Y), [0.0, 0.5]),
            crossing(1, (1, 1, Along::X), [1.5, 1.0]),
            crossing(2, (2, 2, Along::X), [2.5, 2.0]),
        ];
        let refs: Vec<&Crossing> = curve.iter().collect();
        let found = chains(&[0, 3], 3, &refs);
        assert_eq!(found.len(), 1, "{found:?}");
        let order: Vec<usize> = found[0].iter().map(|&k| refs[k].index).collect();
        assert!(order == [0, 1, 2] || order == [2, 1, 0], "{order:?}");
    }

    #[test]
    fn curve_columns_spread_evenly_and_keep_both_ends() {
        assert_eq!(curve_columns(5, 3), [0, 2, 4]);
        assert_eq!(curve_columns(21, 25), (0..21).collect::<Vec<_>>());
        assert_eq!(curve_columns(4, 2), [0, 3]);
        assert_eq!(curve_columns(1, 25), [0]);
        assert!(curve_columns(0, 25).is_empty());
        let hundred = curve_columns(100, DEFAULT_CURVE_COLUMNS);
        assert!(hundred.len() <= DEFAULT_CURVE_COLUMNS, "{hundred:?}");
        assert_eq!((hundred[0], hundred[hundred.len() - 1]), (0, 99));
    }
}
