//! `vrw map --model NAME`: a walker's gait over a grid of two of its parameters (docs/model.md section 13).
//!
//! **Gaits.** The first column (`x` at its first value) is a sweep along `y` ([`walker_gaits`]: each value's
//! gait continued from its neighbour's by Newton's method, the grid runner's schedule); then every row (fixed
//! `y`) continues its first point's gait along `x` from left to right ([`gait_at`]), rows in parallel on the
//! grid runner, so that a family is followed across the plane. A point whose neighbour has no gait is searched
//! from the model's start (or `initial`) after a transient walk, as the sweep's are. The map is bitwise the
//! same for any number of threads.
//!
//! **Thresholds.** Along every row, each change of stability between two neighbouring points is bisected
//! as the sweep bisects it (`walker_sweep::thresholds`, to `THRESHOLD_TOL`), with its kind (period
//! doubling, fold, Neimark-Sacker): the stability boundary at the rows' `y`, to far below the grid's spacing.
//!
//! `map.csv` (a row per point: `x`, `y`, the sweep's columns: status, the section named by the model,
//! `lambda_I4`, period, step length, speed, impact loss, stability, multipliers), `map.json` (the axes, counts
//! per status, the thresholds) and `map.png` ([`crate::output::walker_map_plot`]). Written once for every
//! walker, on [`super::WalkerModel`].

use std::collections::BTreeMap;
use std::path::PathBuf;

use nalgebra::DVector;
use rayon::prelude::*;
use serde::Serialize;

use super::walker_output::{write_rows, WalkerOutput};
use super::walker_sweep::{
    gait_at, sweep_rows, thresholds, walker_gaits, WalkerRange, WalkerSweepPoint, WalkerThreshold,
};
use super::walkers::{start_of, Walker};
use super::{check_interrupted, check_phase_interrupted, in_run_on, AppError};
use crate::output;
use crate::output::walker_map_plot::{write_walker_map_figure, MapCell, WalkerMapFigure};
use crate::study::grid::{run_rows, Evaluated};
use crate::study::map::{MAP_X_RANGE, MAP_Y_RANGE};
use crate::study::RangeNames;

/// What `vrw map --model NAME` runs.
#[derive(Debug, Clone)]
pub struct WalkerMapJob {
    /// The walker (the two mapped parameters are set point by point).
    pub walker: Walker,
    /// The parameter along rows (horizontal axis) and its values.
    pub x: WalkerRange,
    /// The parameter along columns (vertical axis) and its values.
    pub y: WalkerRange,
    /// Where the search at the first point starts (the section's coordinates); default the model's start.
    pub initial: Option<Vec<f64>>,
    /// Bisect every change of stability along the rows (`map.json`'s `thresholds`, marks on `map.png`).
    pub thresholds: bool,
    /// Output directory for `map.csv`, `map.json` and `map.png`.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir`.
    pub overwrite: bool,
}

/// The gaits of a walker's map.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkerMap {
    /// The `x` values (columns).
    pub xs: Vec<f64>,
    /// The `y` values (rows).
    pub ys: Vec<f64>,
    /// `rows[j][i]` is the gait at `(xs[i], ys[j])` (its `value` is `xs[i]`); rows cut short by Ctrl-C hold
    /// their complete prefix.
    pub rows: Vec<Vec<WalkerSweepPoint>>,
}

/// A change of stability along a row of the map.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerMapThreshold {
    /// The row's `y` value.
    pub y: f64,
    /// The threshold in `x`, bisected.
    #[serde(flatten)]
    pub threshold: WalkerThreshold,
}

/// `map.json` of a walker.
#[derive(Debug, Clone, Serialize)]
pub struct WalkerMapSummary {
    /// vrw's version.
    pub vrw_version: &'static str,
    /// The model's name.
    pub model: String,
    /// Its parameters (the mapped ones as given).
    pub parameters: Walker,
    /// The horizontal axis.
    pub x: WalkerRange,
    /// The vertical axis.
    pub y: WalkerRange,
    /// Points of the map.
    pub points: usize,
    /// Points with a gait.
    pub gaits_found: usize,
    /// Points per status: `stable`, `unstable`, or the failure's kind.
    pub statuses: BTreeMap<String, usize>,
    /// Gaits whose heel strike would keep double support (`lambda_I4 >= 0`: the rear foot would have to be
    /// pushed off; for a rigid walker it stops there).
    pub keeps_double_support: usize,
    /// Every change of stability along the rows, bisected (empty without [`WalkerMapJob::thresholds`]).
    pub thresholds: Vec<WalkerMapThreshold>,
    /// The files written.
    pub files: Vec<String>,
    /// Where the interrupt flag stopped the job and what is kept ([`compute_walker_map`]: the gaits without
    /// thresholds); `None` (and not written) when it did not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interrupted: Option<String>,
}

/// The axis `range` checked against `walker` as the sweep checks it, its errors naming the map's options
/// (`names`: `x_from`, `nx`, ...; the parameter's option is `names.command`'s last word, `x` or `y`).
fn axis_values(
    walker: &Walker,
    range: &WalkerRange,
    names: &RangeNames,
) -> Result<Vec<f64>, AppError> {
    let param = if names.from == MAP_X_RANGE.from {
        "x"
    } else {
        "y"
    };
    let both = if param == "x" {
        "x_from/x_to"
    } else {
        "y_from/y_to"
    };
    range.values(walker, names.max_points).map_err(|e| match e {
        AppError::InvalidOption { option, reason } => AppError::InvalidOption {
            option: match option {
                "param" => param,
                "from" => names.from,
                "to" => names.to,
                "points" => names.points,
                "from/to" => both,
                other => other,
            },
            reason,
        },
        e => e,
    })
}

impl WalkerMapJob {
    /// The axes' values, after the axes are checked: two different parameters of the walker, each range as a
    /// sweep's, and the walker valid at the four corners.
    fn values(&self) -> Result<(Vec<f64>, Vec<f64>), AppError> {
        let bad = |option, reason: String| Err(AppError::InvalidOption { option, reason });
        if self.x.param == self.y.param {
            return bad(
                "x/y",
                format!(
                    "the two axes must be different parameters (both are {})",
                    self.x.param
                ),
            );
        }
        self.walker.checked_parameter("x", &self.x.param)?;
        self.walker.checked_parameter("y", &self.y.param)?;
        let xs = axis_values(&self.walker, &self.x, &MAP_X_RANGE)?;
        let ys = axis_values(&self.walker, &self.y, &MAP_Y_RANGE)?;
        for x in [self.x.from, self.x.to] {
            for y in [self.y.from, self.y.to] {
                let corner = self
                    .walker
                    .with_parameter(&self.x.param, x)
                    .and_then(|w| w.with_parameter(&self.y.param, y));
                if let Err(e) = corner {
                    return bad(
                        "x/y",
                        format!(
                            "the corner {} = {x}, {} = {y} of the map leaves the model's domain: {e}",
                            self.x.param, self.y.param
                        ),
                    );
                }
            }
        }
        Ok((xs, ys))
    }
}

/// The gaits of `job`'s map from `start` (see the module documentation); `progress` is called after every
/// point. Rows cut short by Ctrl-C keep their complete prefix (none if the first column was cut).
pub(super) fn walker_map_gaits(
    job: &WalkerMapJob,
    (xs, ys): (Vec<f64>, Vec<f64>),
    start: &DVector<f64>,
    progress: &(dyn Fn(&WalkerSweepPoint) + Sync),
) -> Result<WalkerMap, AppError> {
    let (xp, yp) = (job.x.param.as_str(), job.y.param.as_str());
    let first = job.walker.with_parameter(xp, xs[0])?;
    let column = walker_gaits(&first, yp, &ys, start);
    let row_walkers = ys
        .iter()
        .map(|&y| job.walker.with_parameter(yp, y))
        .collect::<Result<Vec<Walker>, _>>()?;
    let rows = match column.len() == ys.len() {
        false => Vec::new(),
        true => run_rows(ys.len(), xs.len(), |cell, from| {
            let point = match cell.col {
                0 => WalkerSweepPoint {
                    value: xs[0],
                    ..column[cell.row].clone()
                },
                col => gait_at(
                    &row_walkers[cell.row],
                    xp,
                    xs[col],
                    (from.map(|f| f.1), start),
                ),
            };
            progress(&point);
            let carry = point.gait.as_ref().ok().map(|g| g.section.clone());
            Evaluated { point, carry }
        }),
    };
    Ok(WalkerMap { xs, ys, rows })
}

/// Every change of stability along the rows of `map`, bisected, rows in parallel (each row's in order).
fn row_thresholds(
    job: &WalkerMapJob,
    names: &[String],
    map: &WalkerMap,
) -> Result<Vec<WalkerMapThreshold>, AppError> {
    let per_row: Vec<Result<Vec<WalkerMapThreshold>, AppError>> = map
        .ys
        .par_iter()
        .zip(&map.rows)
        .map(|(&y, row)| {
            let walker = job.walker.with_parameter(&job.y.param, y)?;
            Ok(thresholds(&walker, &job.x.param, names, row)
                .into_iter()
                .map(|threshold| WalkerMapThreshold { y, threshold })
                .collect())
        })
        .collect();
    Ok(per_row.into_iter().collect::<Result<Vec<_>, _>>()?.concat())
}

/// Map `job.walker`'s gait and write `map.csv`, `map.json` and `map.png`, after the options and the output
/// directory are checked. `progress` is called after every point. Interrupted (Ctrl-C) among the gaits,
/// `map.csv` keeps the complete points of every row; among the thresholds, `map.csv` is complete and no
/// threshold is kept.
pub fn run_walker_map(
    job: &WalkerMapJob,
    progress: &(dyn Fn(&WalkerSweepPoint) + Sync),
) -> Result<WalkerMapSummary, AppError> {
    let values = job.values()?;
    let model = job.walker.model()?;
    let start = start_of(model.as_ref(), job.initial.as_deref())?;
    let names = model.section_names();
    let model_name = model.name().to_string();
    output::manifest::check_out_dir(&job.out_dir, "map", job.overwrite)?;
    in_run_on(
        &job.out_dir,
        job.overwrite,
        ("map", Some(job.walker.name())),
        |run| {
            let map = walker_map_gaits(job, values, &start, progress)?;
            write_rows(&run.path("map.csv"), &map_rows(job, &names, &map))?;
            run.add("map.csv");
            let done = map.rows.iter().map(Vec::len).sum();
            check_interrupted(done, map.xs.len() * map.ys.len(), "map.csv")?;
            let thresholds = match job.thresholds {
                true => row_thresholds(job, &names, &map)?,
                false => Vec::new(),
            };
            check_phase_interrupted(
                None,
                "while bisecting the thresholds",
                "map.csv is complete; no threshold is kept",
            )?;
            let mut files = vec!["map.csv".to_string()];
            let figure = map_figure(job, &model_name, &map, &thresholds);
            write_walker_map_figure(&figure, &run.path("map.png"))?;
            run.add("map.png");
            files.extend(["map.png", "map.json"].map(String::from));
            let summary = summary(job, &model_name, &map, thresholds, files);
            output::write_json(&run.path("map.json"), &summary)?;
            run.add("map.json");
            Ok((summary, None))
        },
    )
}

/// The map of [`run_walker_map`] without its files and figure (the Python binding): `map.json`'s fields (`files`
/// the table's) and the rows of `map.csv` (`job.out_dir` and `job.overwrite` are not read). `progress` is called
/// after every point.
///
/// Interrupted (Ctrl-C) while the thresholds are bisected (the gaits being complete), it returns the gaits with
/// no threshold and says so in [`WalkerMapSummary::interrupted`] (the Python front hands them on with its
/// `KeyboardInterrupt`, as the wheel's map); interrupted among the gaits, it is [`AppError::Interrupted`].
pub fn compute_walker_map(
    job: &WalkerMapJob,
    progress: &(dyn Fn(&WalkerSweepPoint) + Sync),
) -> Result<WalkerOutput<WalkerMapSummary>, AppError> {
    let values = job.values()?;
    let model = job.walker.model()?;
    let start = start_of(model.as_ref(), job.initial.as_deref())?;
    let names = model.section_names();
    let map = walker_map_gaits(job, values, &start, progress)?;
    let done = map.rows.iter().map(Vec::len).sum();
    check_interrupted(done, map.xs.len() * map.ys.len(), "no file")?;
    let thresholds = match job.thresholds {
        true => row_thresholds(job, &names, &map)?,
        false => Vec::new(),
    };
    let stopped = check_phase_interrupted(
        None,
        "while bisecting the thresholds",
        "the map's gaits are complete; no threshold is kept",
    );
    let tables = vec![("map.csv", map_rows(job, &names, &map))];
    let files = vec!["map.csv".to_string()];
    let summary = match stopped {
        Ok(()) => summary(job, model.name(), &map, thresholds, files),
        Err(AppError::Interrupted { during, kept }) => WalkerMapSummary {
            interrupted: Some(format!("{during}; {kept}")),
            ..summary(job, model.name(), &map, Vec::new(), files)
        },
        Err(e) => return Err(e),
    };
    Ok(WalkerOutput { summary, tables })
}

/// `map.json`'s fields.
fn summary(
    job: &WalkerMapJob,
    model: &str,
    map: &WalkerMap,
    thresholds: Vec<WalkerMapThreshold>,
    files: Vec<String>,
) -> WalkerMapSummary {
    let points = || map.rows.iter().flatten();
    let mut statuses = BTreeMap::new();
    for p in points() {
        *statuses.entry(p.status().to_string()).or_insert(0) += 1;
    }
    WalkerMapSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        model: model.to_string(),
        parameters: job.walker.clone(),
        x: job.x.clone(),
        y: job.y.clone(),
        points: map.xs.len() * map.ys.len(),
        gaits_found: points().filter(|p| p.gait.is_ok()).count(),
        statuses,
        keeps_double_support: points()
            .filter(|p| p.gait.as_ref().is_ok_and(|g| g.step.lambda_i4 >= 0.0))
            .count(),
        thresholds,
        files,
        interrupted: None,
    }
}

/// The rows of a walker's `map.csv`, its header first: `x`'s and `y`'s values, then the sweep's columns
/// ([`sweep_rows`]).
fn map_rows(job: &WalkerMapJob, names: &[String], map: &WalkerMap) -> Vec<Vec<String>> {
    let (xp, yp) = (&job.x.param, &job.y.param);
    let mut header = sweep_rows(xp, names, &[]).remove(0);
    header.insert(1, yp.clone());
    let mut rows = vec![header];
    for (&y, row) in map.ys.iter().zip(&map.rows) {
        for mut r in sweep_rows(xp, names, row).into_iter().skip(1) {
            r.insert(1, output::num(y));
            rows.push(r);
        }
    }
    rows
}

/// The figure of `map`: the largest multiplier's modulus at every point, the thresholds over it.
fn map_figure(
    job: &WalkerMapJob,
    model: &str,
    map: &WalkerMap,
    thresholds: &[WalkerMapThreshold],
) -> WalkerMapFigure {
    let cells = map
        .rows
        .iter()
        .map(|row| {
            row.iter()
                .map(|p| match &p.gait {
                    Ok(g) => MapCell::Gait {
                        largest: g.largest_multiplier(),
                        keeps_double_support: g.step.lambda_i4 >= 0.0,
                    },
                    Err(_) => MapCell::NoGait,
                })
                .collect()
        })
        .collect();
    WalkerMapFigure {
        title: format!(
            "Gaits of the {model} walker over ({}, {}){}",
            job.x.param,
            job.y.param,
            others_note(&job.walker, &[&job.x.param, &job.y.param])
        ),
        x_label: super::axis_label(&job.x.param),
        y_label: super::axis_label(&job.y.param),
        xs: map.xs.clone(),
        ys: map.ys.clone(),
        cells,
        thresholds: thresholds
            .iter()
            .map(|t| (t.threshold.kind, t.threshold.value, t.y))
            .collect(),
    }
}

/// The walker's parameters that differ from its model's defaults, but for those in `shown`, as a figure's
/// title names them: ` [hip_mass = 8]`, or nothing.
pub(super) fn others_note(walker: &Walker, shown: &[&str]) -> String {
    let others: Vec<String> = super::walker_orbit::non_default_parameters(walker)
        .into_iter()
        .filter(|(k, _)| !shown.contains(&k.as_str()))
        .map(|(k, v)| format!("{k} = {v}"))
        .collect();
    match others.is_empty() {
        true => String::new(),
        false => format!(" [{}]", others.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::{run_walker_continuation, WalkerContinueJob};
    use crate::continuation::SpecialKind;

    /// The compass gait over `slope` (`nx` values from `from` to `to`) and `hip_mass` (`ny` values from `low` to
    /// `high`), written to `out`.
    fn compass_map(
        out: &std::path::Path,
        (from, to, nx): (f64, f64, usize),
        (low, high, ny): (f64, f64, usize),
    ) -> WalkerMapJob {
        let walker = Walker::load("compass", None, &[] as &[&str])
            .unwrap()
            .unwrap();
        let range = |param: &str, from, to, points| WalkerRange {
            param: param.to_string(),
            from,
            to,
            points,
        };
        WalkerMapJob {
            walker,
            x: range("slope", from, to, nx),
            y: range("hip_mass", low, high, ny),
            initial: None,
            thresholds: true,
            out_dir: out.to_path_buf(),
            overwrite: false,
        }
    }

    /// The located period doubling of `vrw continue --model compass --param slope` from 0.04 to 0.09, started
    /// at `slope = start`, with `hip_mass` at `hip_mass`.
    fn continued_period_doubling(dir: &std::path::Path, hip_mass: f64, start: f64) -> f64 {
        let walker = Walker::load("compass", None, &[format!("hip_mass={hip_mass}")])
            .unwrap()
            .unwrap();
        let continued = run_walker_continuation(&WalkerContinueJob {
            walker,
            param: "slope".to_string(),
            start: Some(start),
            range: (0.04, 0.09),
            max_points: 300,
            max_step: 0.1,
            out_dir: dir.join(format!("continue-{hip_mass}")),
            overwrite: false,
        })
        .unwrap();
        continued
            .special_points
            .iter()
            .find(|s| s.kind == SpecialKind::PeriodDoubling && s.located)
            .expect("a located period doubling")
            .value
    }

    /// The map without its files ([`compute_walker_map`], the Python binding's) is the one `vrw map --model`
    /// writes: its table is `map.csv` cell for cell, its summary `map.json` but for the files listed.
    #[test]
    fn the_computed_map_is_the_written_one() {
        let tmp = tempfile::tempdir().unwrap();
        let job = compass_map(&tmp.path().join("map"), (0.07, 0.08, 3), (8.0, 12.0, 2));
        let written = run_walker_map(&job, &|_| {}).unwrap();
        let computed = compute_walker_map(&job, &|_| {}).unwrap();
        let csv = std::fs::read_to_string(tmp.path().join("map").join("map.csv")).unwrap();
        let rows: Vec<String> = computed.tables[0].1.iter().map(|r| r.join(",")).collect();
        assert_eq!(computed.tables[0].0, "map.csv");
        assert_eq!(csv.lines().collect::<Vec<_>>(), rows);
        let mut summary = serde_json::to_value(&computed.summary).unwrap();
        summary["files"] = serde_json::to_value(&written.files).unwrap();
        assert_eq!(summary, serde_json::to_value(&written).unwrap());
        assert_eq!(computed.summary.thresholds.len(), 2);
    }

    /// `map.csv`, `map.json` and `map.png` are the same bytes for 1 and 2 threads.
    #[test]
    fn the_map_is_the_same_for_one_and_two_threads() {
        let tmp = tempfile::tempdir().unwrap();
        let files = |threads: usize| {
            let out = tmp.path().join(threads.to_string());
            let job = compass_map(&out, (0.07, 0.08, 6), (8.0, 12.0, 3));
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| run_walker_map(&job, &|_| {})).unwrap();
            ["map.csv", "map.json", "map.png"].map(|f| std::fs::read(out.join(f)).unwrap())
        };
        let (one, two) = (files(1), files(2));
        assert_eq!(String::from_utf8_lossy(&one[0]).lines().count(), 1 + 6 * 3);
        // Every row crosses the period doubling: three bisections, each run on both pools.
        let summary: serde_json::Value = serde_json::from_slice(&one[1]).unwrap();
        assert_eq!(summary["thresholds"].as_array().map(Vec::len), Some(3));
        assert_eq!(one, two);
    }

    /// At `hip_mass = 10` the map's stability boundary (the last stable and the first unstable point of the
    /// row) brackets the period doubling `vrw continue --model compass --param slope` locates, and every row's
    /// bisected threshold (`hip_mass` = 5, 10, 15, 20) equals continue's at that hip mass to 1e-9.
    #[test]
    fn the_stability_boundary_is_the_period_doubling_continue_locates() {
        let tmp = tempfile::tempdir().unwrap();
        let job = compass_map(&tmp.path().join("map"), (0.04, 0.09, 11), (5.0, 20.0, 4));
        let summary = run_walker_map(&job, &|_| {}).unwrap();
        let csv = std::fs::read_to_string(tmp.path().join("map").join("map.csv")).unwrap();
        let row: Vec<(f64, String)> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|c| c[1] == "10")
            .map(|c| (c[0].parse().unwrap(), c[2].to_string()))
            .collect();
        assert_eq!(row.len(), 11);
        let last_stable = row
            .iter()
            .filter(|(_, s)| s == "stable")
            .map(|r| r.0)
            .fold(f64::NAN, f64::max);
        let first_unstable = row
            .iter()
            .filter(|(_, s)| s == "unstable")
            .map(|r| r.0)
            .fold(f64::NAN, f64::min);
        assert!(first_unstable - last_stable < 0.005 + 1e-12, "{row:?}");
        let pd = continued_period_doubling(tmp.path(), 10.0, last_stable);
        assert!(last_stable < pd && pd < first_unstable, "{pd} {row:?}");
        assert_eq!(summary.thresholds.len(), 4);
        for t in &summary.thresholds {
            assert_eq!(t.threshold.kind, "period_doubling");
            // Started a grid step below the bracket's stable end: there the gait is well inside its stable
            // side, while further down the stance foot lifts off at light hips.
            let start = t.threshold.bracket[0] - 0.005;
            let pd = continued_period_doubling(tmp.path(), t.y, start);
            assert!((t.threshold.value - pd).abs() < 1e-9, "{}: {pd}", t.y);
        }
    }
}
