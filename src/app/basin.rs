//! The job of `vrw basin`: the basin of the gait on a slice of the Poincare section (what the walk from every
//! grid point does), `basin.csv`, `basin.json` and `basin.png`.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::PathBuf;

use serde::Serialize;

use crate::fmt::short;
use crate::gait::{find_gait_any_period, Gait, GaitOptions, StepMap, MAX_PERIOD};
use crate::output;
use crate::output::basin_plot::{write_basin_figure, BasinFigure};
use crate::params::Config;
use crate::study::basin::{basin_measured, Axis, BasinPoint, BasinSpec, Coordinate};
use crate::study::check_part;
use crate::study::parallelism::{measured, Cost, PhaseWork, TaskGraph, WithParallelism};
use crate::walk::SectionState;

use super::{check_interrupted, check_phase_interrupted, in_run, prepared, AppError};
use crate::output::manifest::RunDir;
use crate::output::write_basin_csv;

/// Default range of a coordinate on the basin slice around the gait's value `at`: `L2` from `L0 / 2` (or the
/// compression stop `min_length`, if higher) to `L0`, `dtheta/dt` from a twentieth of the gait's to three
/// times it, `dL2/dt` the gait's plus and minus 1.5 m/s.
pub fn default_basin_range(config: &Config, coordinate: Coordinate, at: f64) -> (f64, f64) {
    let l0 = config.params.stopper_length;
    match coordinate {
        Coordinate::L2 => ((0.5 * l0).max(config.params.min_length), l0),
        Coordinate::ThetaDot => (0.05 * at, 3.0 * at),
        Coordinate::L2Dot => (at - 1.5, at + 1.5),
    }
}

/// The most grid points along one axis of a basin (every walker's).
pub const MAX_BASIN_POINTS: usize = 2000;

/// The most steps walked from one start of a basin (every walker's).
pub const MAX_BASIN_STEPS: usize = 100_000;

/// The grid of a basin's slice and when a walk from one of its starts ends, as every walker's basin takes them
/// (`vrw basin`, with `--model` too).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliceGrid {
    /// The ranges of the horizontal and the vertical coordinate (`None`: the job's default).
    pub ranges: [Option<(f64, f64)>; 2],
    /// Grid points along x and y.
    pub points: [usize; 2],
    /// Steps walked at most from each start.
    pub max_steps: usize,
    /// Distance to a gait state that counts as reaching it (largest coordinate difference).
    pub tolerance: f64,
}

impl SliceGrid {
    /// Check the grid sizes, the ranges, the steps and the tolerance.
    pub(crate) fn validate(&self) -> Result<(), AppError> {
        let invalid = |option, reason| Err(AppError::InvalidOption { option, reason });
        for (option, n) in [("nx", self.points[0]), ("ny", self.points[1])] {
            if !(2..=MAX_BASIN_POINTS).contains(&n) {
                return invalid(
                    option,
                    format!("{n} grid points; use 2 to {MAX_BASIN_POINTS}"),
                );
            }
        }
        for (option, range) in [("x_range", self.ranges[0]), ("y_range", self.ranges[1])] {
            if let Some((a, b)) = range.filter(|(a, b)| !(a.is_finite() && b.is_finite() && a != b))
            {
                return invalid(
                    option,
                    format!(
                        "{},{} is not a range with two different finite ends",
                        short(a),
                        short(b)
                    ),
                );
            }
        }
        if !(1..=MAX_BASIN_STEPS).contains(&self.max_steps) {
            return invalid(
                "max_steps",
                format!("{} steps; use 1 to {MAX_BASIN_STEPS}", self.max_steps),
            );
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return invalid(
                "tolerance",
                format!("{} is not a positive distance", short(self.tolerance)),
            );
        }
        Ok(())
    }
}

/// What `vrw basin` runs.
#[derive(Debug, Clone)]
pub struct BasinJob {
    /// Parameters and solver options.
    pub config: Config,
    /// Where the gait search starts (`None`: [`crate::reference::default_initial`]).
    pub initial: Option<SectionState>,
    /// Horizontal and vertical coordinates of the slice.
    pub coordinates: [Coordinate; 2],
    /// Their ranges (`None`: [`default_basin_range`]), the grid, and when a walk ends.
    pub grid: SliceGrid,
    /// Where `basin.csv`, `basin.json` and `basin.png` go.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir` (its files are removed and listed in the manifest);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    pub overwrite: bool,
}

/// `basin.json`.
#[derive(Debug, Clone, Serialize)]
pub struct BasinSummary {
    /// Version of vrw that produced the file.
    pub vrw_version: &'static str,
    /// Parameters and solver options.
    pub config: Config,
    /// The slice and the rules.
    pub spec: BasinSpec,
    /// The gait whose basin it is.
    pub gait: Gait,
    /// Number of grid points per outcome.
    pub outcomes: BTreeMap<String, usize>,
    /// The files written.
    pub files: Vec<String>,
    /// Wall-clock seconds of the grid (printed, not written).
    #[serde(skip)]
    pub seconds: f64,
    /// The work and span of the gait's search and of the walks from the starts
    /// ([`crate::study::parallelism`]); written to `basin.json` (after these fields) by [`run_basin`], in
    /// steps walked.
    #[serde(skip)]
    pub parallelism: Vec<PhaseWork>,
}

impl BasinSummary {
    /// `basin.json`: the summary with its phases' work and span.
    pub fn with_parallelism(&self) -> WithParallelism<'_, BasinSummary> {
        WithParallelism {
            summary: self,
            parallelism: &self.parallelism,
        }
    }
}

impl BasinJob {
    /// Check the options that do not depend on the gait.
    fn validate(&self) -> Result<(), AppError> {
        if self.coordinates[0] == self.coordinates[1] {
            return Err(AppError::InvalidOption {
                option: "x/y",
                reason: format!(
                    "the two axes must be different coordinates (both are {})",
                    self.coordinates[0].name()
                ),
            });
        }
        self.grid.validate()
    }
}

/// Run `vrw basin`: find the gait (any period up to 8), walk from every grid point of the slice through it,
/// write `basin.csv`, `basin.json` and `basin.png`. `progress` is called after every grid point.
pub fn run_basin(
    job: &BasinJob,
    progress: &(dyn Fn(&BasinPoint) + Sync),
) -> Result<BasinSummary, AppError> {
    let (prepared, search) = measured(|| prepare_basin(job));
    let (model, gait, spec) = prepared?;
    in_run(&job.out_dir, job.overwrite, "basin", |run| {
        basin_into(job, &model, (gait, search), spec, run, progress).map(|s| (s, None))
    })
}

/// The basin of [`run_basin`] without writing anything (`job.out_dir` is not used): the summary of
/// `basin.json` (with no files) and every grid point, row by row (what the Python binding returns). An
/// interrupted grid (the library's interrupt flag) is an error, [`AppError::Interrupted`].
pub fn compute_basin(
    job: &BasinJob,
    progress: &(dyn Fn(&BasinPoint) + Sync),
) -> Result<(BasinSummary, Vec<Vec<BasinPoint>>), AppError> {
    compute_basin_part(job, None, progress)
}

/// [`compute_basin`] of the rows `part` of the grid only (`None`: all of them; a basin computed in parts, a
/// study spread over processes): each point exactly as the whole basin has it, `outcomes` counting this
/// part's points.
pub fn compute_basin_part(
    job: &BasinJob,
    part: Option<Range<usize>>,
    progress: &(dyn Fn(&BasinPoint) + Sync),
) -> Result<(BasinSummary, Vec<Vec<BasinPoint>>), AppError> {
    let (prepared, search) = measured(|| prepare_basin(job));
    let (model, gait, spec) = prepared?;
    let part = part.unwrap_or(0..spec.y.points);
    check_part(&part, spec.y.points)?;
    let clock = std::time::Instant::now();
    let (grid, starts) = basin_measured(
        &model,
        &job.config.solver,
        &gait,
        &spec,
        part.clone(),
        progress,
    );
    let seconds = clock.elapsed().as_secs_f64();
    check_interrupted(
        grid.iter().map(Vec::len).sum(),
        spec.x.points * part.len(),
        "no file",
    )?;
    let summary = BasinSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: job.config.clone(),
        spec,
        gait,
        outcomes: outcome_counts(&grid),
        files: Vec::new(),
        seconds,
        parallelism: basin_parallelism(search, &starts),
    };
    Ok((summary, grid))
}

/// The phases of a basin: the gait's search (one task) and the walks from the starts.
fn basin_parallelism(search: Cost, starts: &TaskGraph) -> Vec<PhaseWork> {
    let mut gait = TaskGraph::new();
    gait.task(search, &[]);
    vec![
        PhaseWork::of("gait", &gait),
        PhaseWork::of("starts", starts),
    ]
}

/// The number of grid points per outcome.
fn outcome_counts(grid: &[Vec<BasinPoint>]) -> BTreeMap<String, usize> {
    let mut outcomes = BTreeMap::new();
    for p in grid.iter().flatten() {
        *outcomes.entry(p.outcome.kind.to_string()).or_insert(0) += 1;
    }
    outcomes
}

/// The checks and the gait of a basin job, and its slice.
fn prepare_basin(job: &BasinJob) -> Result<(crate::dynamics::Model, Gait, BasinSpec), AppError> {
    job.validate()?;
    let (model, initial) = prepared(&job.config, job.initial)?;
    let map = StepMap::new(&model, &job.config.solver);
    let gait = find_gait_any_period(&map, &initial, &GaitOptions::default(), MAX_PERIOD);
    check_phase_interrupted(None, "while searching the gait", "nothing is computed yet")?;
    let gait = gait.map_err(|e| AppError::InvalidOption {
        option: "basin",
        reason: format!("no gait to draw the basin of: {e}"),
    })?;
    let through = gait.section.to_array();
    let axis = |k: usize| {
        let c = job.coordinates[k];
        let (from, to) = job.grid.ranges[k]
            .unwrap_or_else(|| default_basin_range(&job.config, c, through[c.index()]));
        Axis {
            coordinate: c,
            from,
            to,
            points: job.grid.points[k],
        }
    };
    let spec = BasinSpec {
        x: axis(0),
        y: axis(1),
        through: gait.section,
        max_steps: job.grid.max_steps,
        tolerance: job.grid.tolerance,
    };
    Ok((model, gait, spec))
}

/// The work of [`run_basin`] in its run directory.
fn basin_into(
    job: &BasinJob,
    model: &crate::dynamics::Model,
    (gait, search): (Gait, Cost),
    spec: BasinSpec,
    run: &mut RunDir,
    progress: &(dyn Fn(&BasinPoint) + Sync),
) -> Result<BasinSummary, AppError> {
    let clock = std::time::Instant::now();
    let all_rows = 0..spec.y.points;
    let (grid, starts) =
        basin_measured(model, &job.config.solver, &gait, &spec, all_rows, progress);
    let seconds = clock.elapsed().as_secs_f64();
    let outcomes = outcome_counts(&grid);
    let friction = crate::output::friction_columns(&job.config, &[]);
    write_basin_csv(&run.path("basin.csv"), friction, &grid)?;
    run.add("basin.csv");
    check_interrupted(
        grid.iter().map(Vec::len).sum(),
        spec.x.points * spec.y.points,
        "basin.csv",
    )?;
    let (cx, cy) = (spec.x.coordinate.index(), spec.y.coordinate.index());
    let figure = BasinFigure {
        title: format!(
            "Basin of the {}gait on the slice {} = {:.4} (c = {} N s/m, slope φ = {} rad, impact {})",
            if gait.period_k > 1 {
                format!("period-{} ", gait.period_k)
            } else {
                String::new()
            },
            Coordinate::ALL[3 - cx - cy].name(),
            spec.through.to_array()[3 - cx - cy],
            job.config.params.viscosity,
            job.config.params.slope,
            job.config.params.impact
        ) + &super::settings_note(&job.config, &["viscosity", "slope", "impact"]),
        x_label: spec.x.coordinate.label().to_string(),
        y_label: spec.y.coordinate.label().to_string(),
        xs: (0..spec.x.points).map(|i| spec.x.value(i)).collect(),
        ys: (0..spec.y.points).map(|i| spec.y.value(i)).collect(),
        outcomes: grid
            .iter()
            .map(|row| row.iter().map(|p| p.outcome.kind.to_string()).collect())
            .collect(),
        gait: gait
            .cycle
            .iter()
            .map(|r| {
                let a = r.section.to_array();
                (a[cx], a[cy])
            })
            .collect(),
    };
    write_basin_figure(&figure, &run.path("basin.png"))?;
    run.add("basin.png");
    let summary = BasinSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: job.config.clone(),
        spec,
        gait,
        outcomes,
        files: ["basin.csv", "basin.png", "basin.json"]
            .map(String::from)
            .to_vec(),
        seconds,
        parallelism: basin_parallelism(search, &starts),
    };
    output::write_json(&run.path("basin.json"), &summary.with_parallelism())?;
    run.add("basin.json");
    Ok(summary)
}
