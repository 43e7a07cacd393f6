//! `vrw basin --model NAME`: the basin of attraction of a walker's gait on a 2-D slice of its Poincare section
//! (docs/model.md section 13), as the wheel's (`crate::study::basin`): two of the section's coordinates span a
//! grid, the others are held at the gait's values, and from every grid point the walker walks until one of
//! these happens, which is the point's outcome:
//!
//! - `gait`: a section state comes within `tolerance` of the gait's (largest coordinate difference);
//! - `other`: the returns repeat with a period `k <= MAX_PERIOD` to `SETTLED_TOL` over the last
//!   `RETURN_WINDOW + MAX_PERIOD` returns, away from the gait: another attractor (its period is kept);
//! - the walk fails: the failure's kind (`fell`, `stance_lifts_off`, `stalled`, `stops_in_double_support`, ...);
//! - `undecided`: still walking, none of these, after `max_steps` steps.
//!
//! Every start is independent: the grid runs on the grid runner, rows in parallel, the same for any number
//! of threads. `basin.csv` (a row per start: the grid point, the start and the end by the section's names, the
//! outcome, the steps it took), `basin.json` (counts per outcome, the gait, the slice) and `basin.png` (the
//! wheel's basin figure, [`crate::output::basin_plot`]). Written once for every walker, on [`super::WalkerModel`].

use std::collections::BTreeMap;
use std::path::PathBuf;

use nalgebra::DVector;
use serde::Serialize;

use super::basin::SliceGrid;
use super::walker_model::{FoundGait, WalkerModel};
use super::walker_orbit::least_period;
use super::walker_output::{write_rows, WalkerOutput};
use super::walker_sweep::FRESH_TRANSIENT;
use super::walkers::{as_map, named, start_of, Walker};
use super::{check_interrupted, check_phase_interrupted, in_run_on, AppError, NOTHING_WRITTEN};
use crate::gait::periodicity::{MAX_PERIOD, RETURN_WINDOW};
use crate::output;
use crate::output::basin_plot::{write_basin_figure, BasinFigure};
use crate::study::basin::{OutcomeKind, SETTLED_TOL};
use crate::study::grid::{run_rows, Evaluated};

/// What `vrw basin --model NAME` runs.
#[derive(Debug, Clone)]
pub struct WalkerBasinJob {
    /// The walker.
    pub walker: Walker,
    /// Where the gait search starts (the section's coordinates); default the model's start.
    pub initial: Option<Vec<f64>>,
    /// The horizontal and vertical coordinates of the slice (names of the model's section coordinates).
    pub coordinates: [String; 2],
    /// Their ranges (`None`: from 0 to twice the gait's value, or -1 to 1 where that is 0), the grid, and when
    /// a walk ends.
    pub grid: SliceGrid,
    /// Output directory for `basin.csv`, `basin.json` and `basin.png`.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir`.
    pub overwrite: bool,
}

/// One axis of the slice.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerBasinAxis {
    /// The section coordinate.
    pub coordinate: String,
    /// Its index in the section.
    #[serde(skip)]
    pub index: usize,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values, ends included.
    pub points: usize,
}

impl WalkerBasinAxis {
    /// The `i`-th value.
    pub fn value(&self, i: usize) -> f64 {
        self.from + (self.to - self.from) * (i as f64 / (self.points - 1) as f64)
    }
}

/// What the walk from one start did.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkerOutcome {
    /// Where it went (`gait`, `other`, `undecided` or the walk's failure kind).
    pub kind: OutcomeKind,
    /// Steps walked until the outcome was known (a failure's: the step that failed).
    pub steps: usize,
    /// For `other`, the period of the attractor reached.
    pub period_k: Option<usize>,
    /// The last section state reached (`None` if the first step failed).
    pub end: Option<DVector<f64>>,
    /// The failure in words.
    pub message: Option<String>,
}

impl WalkerOutcome {
    fn new(kind: OutcomeKind, steps: usize, end: Option<DVector<f64>>) -> WalkerOutcome {
        WalkerOutcome {
            kind,
            steps,
            period_k: None,
            end,
            message: None,
        }
    }
}

/// One start of the basin.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkerBasinPoint {
    /// Grid column (x index).
    pub ix: usize,
    /// Grid row (y index).
    pub iy: usize,
    /// The start on the section.
    pub start: DVector<f64>,
    /// What the walk from it did.
    pub outcome: WalkerOutcome,
}

/// The gait whose basin it is, as `basin.json` holds it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerBasinGait {
    /// Its fixed point, by the section's coordinates.
    #[serde(serialize_with = "as_map")]
    pub section: Vec<(String, f64)>,
    /// The step's duration.
    pub period: f64,
    /// The Floquet multipliers `[re, im]`, largest modulus first.
    pub floquet_multipliers: Vec<[f64; 2]>,
    /// The largest modulus.
    pub largest_multiplier: f64,
    /// `stable` below 1, else `unstable`.
    pub stability: &'static str,
}

/// `basin.json` of a walker.
#[derive(Debug, Clone, Serialize)]
pub struct WalkerBasinSummary {
    /// vrw's version.
    pub vrw_version: &'static str,
    /// The model's name.
    pub model: String,
    /// Its parameters.
    pub parameters: Walker,
    /// The gait.
    pub gait: WalkerBasinGait,
    /// The horizontal axis.
    pub x: WalkerBasinAxis,
    /// The vertical axis (one grid row per value).
    pub y: WalkerBasinAxis,
    /// The section state the slice passes through (the gait's: its other coordinates are held).
    #[serde(serialize_with = "as_map")]
    pub through: Vec<(String, f64)>,
    /// Steps walked at most from each start.
    pub max_steps: usize,
    /// A return this close to the gait has reached it.
    pub tolerance: f64,
    /// Number of starts per outcome.
    pub outcomes: BTreeMap<String, usize>,
    /// The files written.
    pub files: Vec<String>,
}

impl WalkerBasinJob {
    /// The slice's coordinates `x` and `y` as given, or else the first and the second of `walker`'s section
    /// (the defaults of `vrw basin --model` and `vrw.basin`).
    pub fn slice_coordinates(
        walker: &Walker,
        [x, y]: [Option<&str>; 2],
    ) -> Result<[String; 2], AppError> {
        let names = walker.model()?.section_names();
        if names.len() < 2 {
            return Err(Self::invalid(
                "model",
                format!(
                    "the section of `{}` has one coordinate ({}): a basin's slice needs two",
                    walker.name(),
                    names.join(", ")
                ),
            ));
        }
        let pick =
            |given: Option<&str>, k: usize| given.map_or_else(|| names[k].clone(), String::from);
        Ok([pick(x, 0), pick(y, 1)])
    }

    fn invalid(option: &'static str, reason: String) -> AppError {
        AppError::InvalidOption { option, reason }
    }

    /// Check the options that do not depend on the gait: the coordinates against the section's `names`, and the
    /// grid ([`SliceGrid::validate`]).
    fn validate(&self, names: &[String]) -> Result<[usize; 2], AppError> {
        let index = |option: &'static str, c: &str| {
            names.iter().position(|n| n == c).ok_or_else(|| {
                Self::invalid(
                    option,
                    format!(
                        "{:?} is not a coordinate of the section of `{}`: one of {}",
                        crate::fmt::clip(c),
                        self.walker.name(),
                        names.join(", ")
                    ),
                )
            })
        };
        let axes = [
            index("x", &self.coordinates[0])?,
            index("y", &self.coordinates[1])?,
        ];
        if axes[0] == axes[1] {
            return Err(Self::invalid(
                "x/y",
                format!(
                    "the two axes must be different coordinates (both are {})",
                    self.coordinates[0]
                ),
            ));
        }
        self.grid.validate()?;
        Ok(axes)
    }

    /// The slice's axes through the gait's section state `through`.
    fn axes(&self, indices: [usize; 2], through: &DVector<f64>) -> [WalkerBasinAxis; 2] {
        [0, 1].map(|k| {
            let at = through[indices[k]];
            let (from, to) = self.grid.ranges[k].unwrap_or(if at == 0.0 {
                (-1.0, 1.0)
            } else {
                (0.0, 2.0 * at)
            });
            WalkerBasinAxis {
                coordinate: self.coordinates[k].clone(),
                index: indices[k],
                from,
                to,
                points: self.grid.points[k],
            }
        })
    }
}

/// Walk `walker` from `start` until its outcome is known (see the module documentation).
pub(super) fn classify(
    walker: &Walker,
    gait: &DVector<f64>,
    start: &DVector<f64>,
    (max_steps, tolerance): (usize, f64),
) -> WalkerOutcome {
    let near_gait = |s: &DVector<f64>| (s - gait).amax() < tolerance;
    if near_gait(start) {
        return WalkerOutcome::new(OutcomeKind::Gait, 0, Some(start.clone()));
    }
    let model = match walker.model() {
        Ok(model) => model,
        Err(e) => {
            return WalkerOutcome {
                message: Some(e.to_string()),
                ..WalkerOutcome::new(OutcomeKind::Failed("invalid_model"), 0, None)
            }
        }
    };
    let window = MAX_PERIOD + RETURN_WINDOW;
    let mut returns: Vec<DVector<f64>> = Vec::new();
    for step in 1..=max_steps {
        let from = returns.last().unwrap_or(start);
        let s = match model.step(from, None) {
            Ok(walked) => walked.section,
            Err(e) => {
                return WalkerOutcome {
                    message: Some(e.to_string()),
                    ..WalkerOutcome::new(OutcomeKind::Failed(e.kind()), step, returns.pop())
                }
            }
        };
        if near_gait(&s) {
            return WalkerOutcome::new(OutcomeKind::Gait, step, Some(s));
        }
        returns.push(s);
        if returns.len() >= window {
            let last = &returns[returns.len() - window..];
            if let Some(k) = least_period(last, MAX_PERIOD, SETTLED_TOL) {
                return WalkerOutcome {
                    period_k: Some(k),
                    ..WalkerOutcome::new(OutcomeKind::Other, step, returns.pop())
                };
            }
        }
    }
    WalkerOutcome::new(OutcomeKind::Undecided, max_steps, returns.pop())
}

/// The basin on the slice `axes` through `gait`: a point per grid point, row by row (rows are `y` values),
/// rows cut to their complete prefix by Ctrl-C. `progress` is called after every point.
pub(super) fn walker_basin_points(
    walker: &Walker,
    (gait, axes): (&DVector<f64>, &[WalkerBasinAxis; 2]),
    (max_steps, tolerance): (usize, f64),
    progress: &(dyn Fn(&WalkerBasinPoint) + Sync),
) -> Vec<Vec<WalkerBasinPoint>> {
    let [x, y] = axes;
    run_rows(y.points, x.points, |cell, _: Option<(usize, &())>| {
        let mut start = gait.clone();
        start[x.index] = x.value(cell.col);
        start[y.index] = y.value(cell.row);
        let outcome = classify(walker, gait, &start, (max_steps, tolerance));
        let point = WalkerBasinPoint {
            ix: cell.col,
            iy: cell.row,
            start,
            outcome,
        };
        progress(&point);
        Evaluated { point, carry: None }
    })
}

/// What a basin's grid runs on: the section's coordinates, the gait and the slice's axes.
struct Slice {
    names: Vec<String>,
    found: FoundGait,
    axes: [WalkerBasinAxis; 2],
}

/// The slice of `job` on `model`, after the options are checked and, between the checks and the gait search,
/// `before_search` (the command line's check of its output directory).
fn slice(
    job: &WalkerBasinJob,
    model: &dyn WalkerModel,
    before_search: impl FnOnce() -> Result<(), AppError>,
) -> Result<Slice, AppError> {
    let names = model.section_names();
    let indices = job.validate(&names)?;
    let start = start_of(model, job.initial.as_deref())?;
    before_search()?;
    let found = model.gait(&start, FRESH_TRANSIENT);
    check_phase_interrupted(None, "while searching the gait", NOTHING_WRITTEN)?;
    let found = found.map_err(|e| AppError::InvalidOption {
        option: "basin",
        reason: format!("no gait to draw the basin of: {e}"),
    })?;
    let axes = job.axes(indices, &found.section);
    Ok(Slice { names, found, axes })
}

/// Draw the basin of `job.walker`'s gait and write `basin.csv`, `basin.json` and `basin.png`, after the
/// options, the gait and the output directory are checked. `progress` is called after every start.
/// Interrupted (Ctrl-C) among the starts, `basin.csv` keeps the complete ones of every row.
pub fn run_walker_basin(
    job: &WalkerBasinJob,
    progress: &(dyn Fn(&WalkerBasinPoint) + Sync),
) -> Result<WalkerBasinSummary, AppError> {
    let model = job.walker.model()?;
    let Slice { names, found, axes } = slice(job, model.as_ref(), || {
        output::manifest::check_out_dir(&job.out_dir, "basin", job.overwrite)?;
        Ok(())
    })?;
    in_run_on(
        &job.out_dir,
        job.overwrite,
        ("basin", Some(job.walker.name())),
        |run| {
            let grid = walker_basin_points(
                &job.walker,
                (&found.section, &axes),
                (job.grid.max_steps, job.grid.tolerance),
                progress,
            );
            write_rows(&run.path("basin.csv"), &basin_rows(&names, &grid))?;
            run.add("basin.csv");
            let total = axes[0].points * axes[1].points;
            check_interrupted(grid.iter().map(Vec::len).sum(), total, "basin.csv")?;
            let summary = summary(job, (model.name(), &names), &found, axes, &grid);
            write_basin_figure(&figure(&summary, &found, &grid), &run.path("basin.png"))?;
            run.add("basin.png");
            output::write_json(&run.path("basin.json"), &summary)?;
            run.add("basin.json");
            Ok((summary, None))
        },
    )
}

/// The basin of [`run_walker_basin`] without its files and figure (the Python binding): `basin.json`'s fields
/// (`files` the table's) and the rows of `basin.csv` (`job.out_dir` and `job.overwrite` are not read).
/// `progress` is called after every start. Interrupted (Ctrl-C): an error, nothing kept.
pub fn compute_walker_basin(
    job: &WalkerBasinJob,
    progress: &(dyn Fn(&WalkerBasinPoint) + Sync),
) -> Result<WalkerOutput<WalkerBasinSummary>, AppError> {
    let model = job.walker.model()?;
    let Slice { names, found, axes } = slice(job, model.as_ref(), || Ok(()))?;
    let grid = walker_basin_points(
        &job.walker,
        (&found.section, &axes),
        (job.grid.max_steps, job.grid.tolerance),
        progress,
    );
    let total = axes[0].points * axes[1].points;
    check_interrupted(grid.iter().map(Vec::len).sum(), total, "no file")?;
    let tables = vec![("basin.csv", basin_rows(&names, &grid))];
    let summary = WalkerBasinSummary {
        files: vec!["basin.csv".to_string()],
        ..summary(job, (model.name(), &names), &found, axes, &grid)
    };
    Ok(WalkerOutput { summary, tables })
}

/// `basin.json`'s fields.
fn summary(
    job: &WalkerBasinJob,
    (model, names): (&str, &[String]),
    found: &FoundGait,
    [x, y]: [WalkerBasinAxis; 2],
    grid: &[Vec<WalkerBasinPoint>],
) -> WalkerBasinSummary {
    let mut outcomes = BTreeMap::new();
    for p in grid.iter().flatten() {
        *outcomes.entry(p.outcome.kind.to_string()).or_insert(0) += 1;
    }
    let largest = found.largest_multiplier();
    WalkerBasinSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        model: model.to_string(),
        parameters: job.walker.clone(),
        gait: WalkerBasinGait {
            section: named(names, &found.section),
            period: found.step.period,
            floquet_multipliers: found.multipliers.clone(),
            largest_multiplier: largest,
            stability: if largest < 1.0 { "stable" } else { "unstable" },
        },
        x,
        y,
        through: named(names, &found.section),
        max_steps: job.grid.max_steps,
        tolerance: job.grid.tolerance,
        outcomes,
        files: ["basin.csv", "basin.png", "basin.json"]
            .map(String::from)
            .to_vec(),
    }
}

/// The rows of a walker's `basin.csv`, its header first: the grid point, the start by the section's names,
/// the outcome, the steps it took, the period of another attractor, the end (`end_` and the names), and the
/// failure in words.
fn basin_rows(names: &[String], grid: &[Vec<WalkerBasinPoint>]) -> Vec<Vec<String>> {
    let mut header: Vec<String> = vec!["ix".into(), "iy".into()];
    header.extend(names.iter().cloned());
    header.extend(["outcome", "steps", "period_k"].map(String::from));
    header.extend(names.iter().map(|n| format!("end_{n}")));
    header.push("message".into());
    let row = |p: &WalkerBasinPoint| {
        let o = &p.outcome;
        let mut row = vec![p.ix.to_string(), p.iy.to_string()];
        row.extend(p.start.iter().map(|v| output::num(*v)));
        row.extend([
            o.kind.to_string(),
            o.steps.to_string(),
            o.period_k.map_or(String::new(), |k| k.to_string()),
        ]);
        match &o.end {
            Some(end) => row.extend(end.iter().map(|v| output::num(*v))),
            None => row.extend(std::iter::repeat_n(String::new(), names.len())),
        }
        row.push(o.message.clone().unwrap_or_default());
        row
    };
    std::iter::once(header)
        .chain(grid.iter().flatten().map(row))
        .collect()
}

/// The basin figure (the wheel's): the outcome of every start, the gait marked.
fn figure(
    summary: &WalkerBasinSummary,
    found: &FoundGait,
    grid: &[Vec<WalkerBasinPoint>],
) -> BasinFigure {
    let (x, y) = (&summary.x, &summary.y);
    let held: Vec<String> = summary
        .through
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != x.index && *k != y.index)
        .map(|(_, (n, v))| format!("{n} = {v:.6}"))
        .collect();
    let slice = match held.is_empty() {
        true => String::new(),
        false => format!(" on the slice {}", held.join(", ")),
    };
    BasinFigure {
        title: format!(
            "Basin of the {} walker's gait{slice}, {} steps at most{}",
            summary.model,
            summary.max_steps,
            super::walker_map::others_note(&summary.parameters, &[])
        ),
        x_label: x.coordinate.clone(),
        y_label: y.coordinate.clone(),
        xs: (0..x.points).map(|i| x.value(i)).collect(),
        ys: (0..y.points).map(|i| y.value(i)).collect(),
        outcomes: grid
            .iter()
            .map(|row| row.iter().map(|p| p.outcome.kind.to_string()).collect())
            .collect(),
        gait: vec![(found.section[x.index], found.section[y.index])],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::{run_walker_simulate, WalkEnded, WalkerSimulateJob};

    /// The simplest walker's basin at slope 0.009 on `n x n` starts around its gait, written to `out`.
    fn simplest_basin(out: &std::path::Path, n: usize) -> WalkerBasinJob {
        let walker = Walker::load("simplest", None, &["slope=0.009"])
            .unwrap()
            .unwrap();
        WalkerBasinJob {
            walker,
            initial: None,
            coordinates: ["theta".to_string(), "theta_dot".to_string()],
            grid: SliceGrid {
                ranges: [Some((0.15, 0.25)), Some((-0.25, -0.15))],
                points: [n, n],
                max_steps: 100,
                tolerance: 1e-3,
            },
            out_dir: out.to_path_buf(),
            overwrite: false,
        }
    }

    /// The basin without its files ([`compute_walker_basin`], the Python binding's) is the one `vrw basin
    /// --model` writes: its table is `basin.csv` cell for cell, its summary `basin.json` but for the files
    /// listed.
    #[test]
    fn the_computed_basin_is_the_written_one() {
        let tmp = tempfile::tempdir().unwrap();
        let job = simplest_basin(&tmp.path().join("basin"), 5);
        let written = run_walker_basin(&job, &|_| {}).unwrap();
        let computed = compute_walker_basin(&job, &|_| {}).unwrap();
        let csv = std::fs::read_to_string(tmp.path().join("basin").join("basin.csv")).unwrap();
        let rows: Vec<String> = computed.tables[0].1.iter().map(|r| r.join(",")).collect();
        assert_eq!(computed.tables[0].0, "basin.csv");
        assert_eq!(csv.lines().collect::<Vec<_>>(), rows);
        let mut summary = serde_json::to_value(&computed.summary).unwrap();
        summary["files"] = serde_json::to_value(&written.files).unwrap();
        assert_eq!(summary, serde_json::to_value(&written).unwrap());
    }

    /// `basin.csv`, `basin.json` and `basin.png` are the same bytes for 1 and 2 threads.
    #[test]
    fn the_basin_is_the_same_for_one_and_two_threads() {
        let tmp = tempfile::tempdir().unwrap();
        let files = |threads: usize| {
            let out = tmp.path().join(threads.to_string());
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let summary = pool
                .install(|| run_walker_basin(&simplest_basin(&out, 9), &|_| {}))
                .unwrap();
            assert!(summary.outcomes.len() >= 2, "{:?}", summary.outcomes);
            ["basin.csv", "basin.json", "basin.png"].map(|f| std::fs::read(out.join(f)).unwrap())
        };
        assert_eq!(files(1), files(2));
    }

    /// Every start's outcome is what `vrw simulate --model simplest --initial START` walks: a failure of the
    /// same kind at the same step, or, for a start that reaches the gait at step `k`, a walk whose step
    /// `k + 1` starts within the tolerance of the gait (and no earlier one does).
    #[test]
    fn each_outcome_is_the_simulated_walk_from_its_start() {
        let tmp = tempfile::tempdir().unwrap();
        let job = simplest_basin(&tmp.path().join("basin"), 7);
        let found = job.walker.model().unwrap().gait(
            &job.walker.model().unwrap().default_start(),
            FRESH_TRANSIENT,
        );
        let gait = found.unwrap().section;
        let summary = run_walker_basin(&job, &|_| {}).unwrap();
        let axes = [summary.x.clone(), summary.y.clone()];
        let grid = walker_basin_points(&job.walker, (&gait, &axes), (100, 1e-3), &|_| {});
        let mut kinds = std::collections::BTreeSet::new();
        for (k, p) in grid
            .iter()
            .flatten()
            .enumerate()
            .filter(|(k, _)| k % 4 == 0)
        {
            let o = &p.outcome;
            kinds.insert(o.kind.to_string());
            let steps = match o.kind {
                OutcomeKind::Gait => o.steps + 1,
                _ => o.steps.max(1),
            };
            let walked = run_walker_simulate(&WalkerSimulateJob {
                walker: job.walker.clone(),
                initial: Some(p.start.iter().copied().collect()),
                steps,
                sample_dt: 0.01,
                trajectory: false,
                out_dir: tmp.path().join(format!("walk{k}")),
                overwrite: false,
            })
            .unwrap();
            let table =
                std::fs::read_to_string(tmp.path().join(format!("walk{k}/steps.csv"))).unwrap();
            // The section state at each step's start (the section's two columns after `step` and `time`).
            let starts: Vec<DVector<f64>> = table
                .lines()
                .skip(1)
                .map(|l| {
                    let c: Vec<f64> = l
                        .split(',')
                        .skip(2)
                        .take(2)
                        .map(|v| v.parse().unwrap())
                        .collect();
                    DVector::from_vec(c)
                })
                .collect();
            let near = |s: &DVector<f64>| (s - &gait).amax() < 1e-3;
            match o.kind {
                OutcomeKind::Failed(kind) => {
                    assert_eq!(walked.status, WalkEnded::Failed(kind), "{p:?}");
                    assert_eq!(walked.steps_completed, o.steps - 1, "{p:?}");
                    assert!(!starts.iter().any(near), "{p:?}");
                }
                OutcomeKind::Gait => {
                    assert_eq!(walked.status, WalkEnded::Completed, "{p:?}");
                    assert!(near(&starts[o.steps]), "{p:?}");
                    assert!(!starts[..o.steps].iter().any(near), "{p:?}");
                }
                _ => panic!("no other outcome on this slice: {p:?}"),
            }
        }
        assert_eq!(kinds.len(), 2, "{kinds:?}");
    }
}
