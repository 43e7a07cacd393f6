//! The jobs the command line runs, as library functions (STYLE.md point 2: all science lives in the library).

mod attractors;
mod figures;
mod map;

pub use attractors::{
    default_basin_range, run_basin, run_orbit, BasinJob, BasinSummary, OrbitJob, OrbitSummary,
};
pub use figures::{run_animate, run_plot, run_still, AnimateJob, PlotReport};
pub use map::{run_map, MapJob, MapSummary};

use std::collections::{BTreeMap, VecDeque};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use serde::Serialize;

use crate::dynamics::Model;
use crate::fmt::short;
use crate::gait::{
    find_gait_any_period, find_thresholds, sweep_values, Gait, GaitOptions, SecondRoute, StepMap,
    SweepPoint, SweepSpec, Threshold, MAX_PERIOD,
};
use crate::output::plot::{
    write_fig2 as write_fig2_files, Fig2Spec, IndicatorPoint, ThresholdMark,
};
use crate::output::{self, OutputError};
use crate::params::{Config, ConfigError};
use crate::reference::default_initial;
use crate::walk::WalkError;
use crate::walk::{simulate_streaming, SectionState, StepReport, Trajectory};

/// A job could not run or could not write its results.
#[derive(Debug, thiserror::Error)]
pub enum AppError {
    /// Bad parameters.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A bad initial state or a walk that could not start.
    #[error(transparent)]
    Walk(#[from] WalkError),
    /// Results could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// A run directory could not be read back.
    #[error(transparent)]
    Read(#[from] crate::output::read::ReadError),
    /// The animation could not be made.
    #[error(transparent)]
    Animate(#[from] crate::output::animate::AnimateError),
    /// A figure could not be drawn.
    #[error(transparent)]
    Plot(#[from] crate::output::style::PlotError),
    /// A bad command-line value that is not a model parameter.
    #[error("invalid {option}: {reason}")]
    InvalidOption {
        /// The option.
        option: &'static str,
        /// Why.
        reason: String,
    },
}

/// A step whose energy audit leaves more than this unexplained \[J\] is reported as a warning (on stderr by the
/// command line and in `summary.json`): the integration or an event is then not to be trusted.
pub const ENERGY_RESIDUAL_WARNING: f64 = 1e-6;

/// The smallest trajectory sampling interval `vrw simulate` accepts \[s\].
pub const MIN_SAMPLE_DT: f64 = 1e-6;

/// `summary.json` keeps the records of the last this many steps; `steps.csv` has every step.
pub const SUMMARY_STEPS: usize = 1000;

/// `summary.json` keeps the first this many warnings and counts the rest.
pub const SUMMARY_WARNINGS: usize = 100;
/// Default sampling interval of `trajectory.csv` \[s\].
pub const DEFAULT_SAMPLE_DT: f64 = 0.005;

/// What `vrw simulate` runs.
#[derive(Debug, Clone)]
pub struct SimulateJob {
    /// Parameters and solver options (validated by the job).
    pub config: Config,
    /// Start on the Poincare section (`None`: [`default_initial`]).
    pub initial: Option<SectionState>,
    /// Number of steps to walk.
    pub steps: usize,
    /// Trajectory sampling interval \[s\].
    pub sample_dt: f64,
    /// Write `trajectory.csv` (`false`: only `steps.csv` and `summary.json`; a `trajectory.csv` of an earlier
    /// run in `out_dir` is removed, since it would not match).
    pub trajectory: bool,
    /// Where `steps.csv`, `trajectory.csv` and `summary.json` go.
    pub out_dir: PathBuf,
    /// Set it (e.g. from a Ctrl-C handler) to stop the walk at the next touchdown; the results so far are
    /// written with the status `interrupted`.
    pub interrupt: Option<Arc<AtomicBool>>,
}

/// `summary.json`: the parameters used, how the run ended, aggregates over every step, and the records of the
/// last [`SUMMARY_STEPS`] steps (`steps.csv` has every step).
#[derive(Debug, Clone, Serialize)]
pub struct SimulateSummary {
    /// Version of vrw that produced the file.
    pub vrw_version: &'static str,
    /// Parameters and solver options used.
    pub config: Config,
    /// Initial section state.
    pub initial: SectionState,
    /// Steps asked for.
    pub steps_requested: usize,
    /// Steps completed.
    pub steps_completed: usize,
    /// `completed`, `interrupted` (Ctrl-C), or the failure kind (`fell`, `stalled`, ...).
    pub status: String,
    /// The failure or the interruption, in words, if any.
    pub message: Option<String>,
    /// Simulated time reached \[s\]: the last touchdown, or the time of the failure.
    pub end_time: f64,
    /// Largest `|energy_residual|` over all steps \[J\].
    pub max_abs_energy_residual: f64,
    /// Steps with `scuffing` (Leg 2 slid or came back to the ground), over all steps.
    pub scuffing_steps: usize,
    /// Steps with `bounce` (Leg 1 left the ground), over all steps.
    pub bounce_steps: usize,
    /// Number of steps per impact branch (`DLS`, `SLS`, ...), over all steps.
    pub branches: BTreeMap<String, usize>,
    /// Files written to the output directory.
    pub files: Vec<String>,
    /// What may make the numbers untrustworthy (e.g. a step whose energy residual exceeds
    /// [`ENERGY_RESIDUAL_WARNING`]); the first [`SUMMARY_WARNINGS`] of them.
    pub warnings: Vec<String>,
    /// Number of warnings, including those not listed.
    pub warnings_total: usize,
    /// The most step records `steps` holds ([`SUMMARY_STEPS`]).
    pub steps_limit: usize,
    /// Records of the last `min(steps_completed, steps_limit)` steps, in order; `steps.csv` has every step.
    pub steps: Vec<StepReport>,
}

impl SimulateSummary {
    fn new(job: &SimulateJob, initial: SectionState) -> SimulateSummary {
        SimulateSummary {
            vrw_version: env!("CARGO_PKG_VERSION"),
            config: job.config.clone(),
            initial,
            steps_requested: job.steps,
            steps_completed: 0,
            status: String::new(),
            message: None,
            end_time: 0.0,
            max_abs_energy_residual: 0.0,
            scuffing_steps: 0,
            bounce_steps: 0,
            branches: BTreeMap::new(),
            files: Vec::new(),
            warnings: Vec::new(),
            warnings_total: 0,
            steps_limit: SUMMARY_STEPS,
            steps: Vec::new(),
        }
    }

    /// Account for one completed step; returns the warning it raises, if any.
    fn add_step(&mut self, report: &StepReport, last: &mut VecDeque<StepReport>) -> Option<String> {
        self.steps_completed += 1;
        let residual = report.energy.residual;
        self.max_abs_energy_residual = self.max_abs_energy_residual.max(residual.abs());
        self.scuffing_steps += usize::from(report.scuffing);
        self.bounce_steps += usize::from(report.bounce);
        *self.branches.entry(report.branch.to_string()).or_default() += 1;
        if last.len() == SUMMARY_STEPS {
            last.pop_front();
        }
        last.push_back(*report);
        // A NaN residual is a warning too.
        let within = residual.abs() <= ENERGY_RESIDUAL_WARNING;
        let warning = (!within).then(|| {
            format!(
                "step {}: energy residual {} J exceeds {} J (the energy audit does not close)",
                report.step,
                short(residual),
                short(ENERGY_RESIDUAL_WARNING)
            )
        })?;
        self.warnings_total += 1;
        (self.warnings.len() < SUMMARY_WARNINGS).then(|| {
            self.warnings.push(warning.clone());
            warning
        })
    }

    /// Did the walk complete every requested step?
    pub fn completed(&self) -> bool {
        self.message.is_none()
    }
}

/// What `vrw simulate` reports while it runs.
#[derive(Debug, Clone, Copy)]
pub enum SimulateEvent<'a> {
    /// A step is done (its row is in `steps.csv`).
    Step(&'a StepReport),
    /// Something the user should know (also listed in `summary.json`).
    Warning(&'a str),
}

/// Run `vrw simulate`: walk, streaming every step to `steps.csv` and the samples to `trajectory.csv` as they
/// are computed, then write `summary.json`. Memory does not grow with the number of steps. A walk that stops
/// early (a failure, or the [`SimulateJob::interrupt`] flag) keeps every completed step. `observe` sees every
/// step and warning as it happens.
pub fn run_simulate(
    job: &SimulateJob,
    observe: &mut dyn FnMut(SimulateEvent),
) -> Result<SimulateSummary, AppError> {
    let (model, initial) = simulation_setup(job)?;
    let dir = &job.out_dir;
    output::ensure_dir(dir)?;
    let mut steps_csv = output::StepsCsv::create(&dir.join("steps.csv"))?;
    let trajectory_path = dir.join("trajectory.csv");
    let mut trajectory = if job.trajectory {
        let sink = output::TrajectoryCsv::create(&trajectory_path)?;
        Some(Trajectory::streaming(job.sample_dt, Box::new(sink)))
    } else {
        // A trajectory.csv left by an earlier run would not match the new steps.csv.
        remove_stale(&trajectory_path)?;
        None
    };
    let write_row = |report: &StepReport| -> Result<(), AppError> { Ok(steps_csv.write(report)?) };
    let mut summary = walk_job(
        job,
        &model,
        initial,
        trajectory.as_mut(),
        write_row,
        observe,
    )?;
    if let Some(source) = trajectory.as_mut().and_then(Trajectory::take_error) {
        return Err(OutputError::Io {
            path: trajectory_path,
            source,
        }
        .into());
    }
    summary.files.push("steps.csv".to_string());
    if job.trajectory {
        summary.files.push("trajectory.csv".to_string());
    }
    summary.files.push("summary.json".to_string());
    output::write_json(&dir.join("summary.json"), &summary)?;
    Ok(summary)
}

/// The walk of [`run_simulate`] without writing anything (`job.out_dir` and `job.trajectory` are not used),
/// for other fronts (the Python binding): the summary with **every** step record (not only the last
/// [`SUMMARY_STEPS`]), and the trajectory sampled every `job.sample_dt` if `record_trajectory`. It is held in
/// memory, so it suits runs of moderate length.
pub fn compute_simulation(
    job: &SimulateJob,
    record_trajectory: bool,
) -> Result<(SimulateSummary, Option<Trajectory>), AppError> {
    let (model, initial) = simulation_setup(job)?;
    let mut trajectory = record_trajectory.then(|| Trajectory::new(job.sample_dt));
    let mut all = Vec::new();
    let mut summary = walk_job(
        job,
        &model,
        initial,
        trajectory.as_mut(),
        |report| {
            all.push(*report);
            Ok(())
        },
        &mut |_| {},
    )?;
    summary.steps_limit = all.len();
    summary.steps = all;
    Ok((summary, trajectory))
}

/// Validate a simulate job: its configuration, its sampling interval, its model and its start.
fn simulation_setup(job: &SimulateJob) -> Result<(Model, SectionState), AppError> {
    job.config.validate()?;
    if !(job.sample_dt.is_finite() && job.sample_dt > 0.0) {
        return Err(AppError::InvalidOption {
            option: "--sample-dt",
            reason: format!("{} is not a positive time step", short(job.sample_dt)),
        });
    }
    if job.sample_dt < MIN_SAMPLE_DT {
        return Err(AppError::InvalidOption {
            option: "--sample-dt",
            reason: format!(
                "{} s is below {} s (a million samples per simulated second)",
                short(job.sample_dt),
                short(MIN_SAMPLE_DT)
            ),
        });
    }
    let model = Model::new(&job.config.params)?;
    let initial = job.initial.unwrap_or_else(|| default_initial(&job.config));
    initial.validate(&model)?;
    Ok((model, initial))
}

/// Walk the job's steps, handing each report to `on_step` and then each step and warning to `observe`, and
/// build the
/// summary (aggregates, the last [`SUMMARY_STEPS`] records, status).
fn walk_job(
    job: &SimulateJob,
    model: &Model,
    initial: SectionState,
    trajectory: Option<&mut Trajectory>,
    mut on_step: impl FnMut(&StepReport) -> Result<(), AppError>,
    observe: &mut dyn FnMut(SimulateEvent),
) -> Result<SimulateSummary, AppError> {
    let mut summary = SimulateSummary::new(job, initial);
    let mut last = VecDeque::new();
    let end = simulate_streaming(
        model,
        &job.config.solver,
        &initial,
        job.steps,
        trajectory,
        job.interrupt.as_deref(),
        |report| -> Result<(), AppError> {
            on_step(report)?;
            let warning = summary.add_step(report, &mut last);
            observe(SimulateEvent::Step(report));
            if let Some(w) = &warning {
                observe(SimulateEvent::Warning(w));
            }
            Ok(())
        },
    )?;
    summary.end_time = end.time;
    summary.steps = last.into();
    (summary.status, summary.message) = match (&end.failure, end.interrupted) {
        (Some(e), _) => (e.kind().to_string(), Some(e.to_string())),
        (None, true) => (
            "interrupted".to_string(),
            Some(format!(
                "interrupted after {} of {} steps",
                end.steps, job.steps
            )),
        ),
        (None, false) => ("completed".to_string(), None),
    };
    Ok(summary)
}

/// The validated configuration's model and the start on the section (`initial`, or [`default_initial`]),
/// checked against the model: what every job that walks needs first.
fn prepared(
    config: &Config,
    initial: Option<SectionState>,
) -> Result<(Model, SectionState), AppError> {
    config.validate()?;
    let model = Model::new(&config.params)?;
    let initial = initial.unwrap_or_else(|| default_initial(config));
    initial.validate(&model)?;
    Ok((model, initial))
}

/// Remove `path` if it exists (an output file of an earlier run that this run does not rewrite).
fn remove_stale(path: &std::path::Path) -> Result<(), OutputError> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(OutputError::Io {
            path: path.to_path_buf(),
            source: e,
        }),
        _ => Ok(()),
    }
}

/// What `vrw gait` runs.
#[derive(Debug, Clone)]
pub struct GaitJob {
    /// Parameters and solver options.
    pub config: Config,
    /// Where the search starts (`None`: [`default_initial`]).
    pub initial: Option<SectionState>,
    /// Search settings.
    pub options: GaitOptions,
    /// Where `gait.json` goes, and one period of the gait in the files of `vrw simulate`.
    pub out_dir: PathBuf,
}

/// `gait.json`: the parameters, and the gait or why none was found.
#[derive(Debug, Clone, Serialize)]
pub struct GaitSummary {
    /// Version of vrw that produced the file.
    pub vrw_version: &'static str,
    /// Parameters and solver options used.
    pub config: Config,
    /// Search settings.
    pub options: GaitOptions,
    /// Initial section state of the search.
    pub initial: SectionState,
    /// `found`, or the failure kind.
    pub status: String,
    /// The failure, in words, if any.
    pub message: Option<String>,
    /// The gait, if found (its fields are also flattened into the top level of the JSON).
    #[serde(flatten)]
    pub gait: Option<Gait>,
}

/// The smallest Newton tolerance `vrw gait` accepts: the step map is computed to about 1e-13 (integration
/// and event-location tolerances, rounding over a step of thousands of solves), so a smaller
/// `max |P(s) - s|` cannot be reached reliably.
pub const MIN_GAIT_TOLERANCE: f64 = 1e-13;

/// Run `vrw gait`: search the gait (period 1, or if Newton's method fails there and the walk settles, period
/// `k <= MAX_PERIOD`) and write `gait.json` (also when no gait is found, with the reason), and
/// for a gait found, one period of it as `steps.csv`, `trajectory.csv` and `summary.json`
/// ([`write_gait_period`]).
pub fn run_gait(job: &GaitJob) -> Result<GaitSummary, AppError> {
    let summary = compute_gait(job)?;
    output::ensure_dir(&job.out_dir)?;
    output::write_json(&job.out_dir.join("gait.json"), &summary)?;
    if let Some(gait) = &summary.gait {
        write_gait_period(job, gait)?;
    }
    Ok(summary)
}

/// The search of [`run_gait`] without writing anything (`job.out_dir` is not used). A search that finds no
/// gait is a summary with its status and message, not an error.
pub fn compute_gait(job: &GaitJob) -> Result<GaitSummary, AppError> {
    let tolerance = job.options.tolerance;
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(AppError::InvalidOption {
            option: "--tolerance",
            reason: format!("{} is not a positive number", short(tolerance)),
        });
    }
    if tolerance < MIN_GAIT_TOLERANCE {
        return Err(AppError::InvalidOption {
            option: "--tolerance",
            reason: format!(
                "{} is below what the step map can reach (about {}, set by rtol, atol and \
                 event_time_tol and by rounding); use --tolerance {} or more",
                short(tolerance),
                short(MIN_GAIT_TOLERANCE),
                short(MIN_GAIT_TOLERANCE)
            ),
        });
    }
    job.config.validate()?;
    let model = Model::new(&job.config.params)?;
    let initial = job.initial.unwrap_or_else(|| default_initial(&job.config));
    initial.validate(&model)?;
    let map = StepMap::new(&model, &job.config.solver);
    let result = find_gait_any_period(&map, &initial, &job.options, MAX_PERIOD);
    let summary = GaitSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: job.config.clone(),
        options: job.options,
        initial,
        status: result
            .as_ref()
            .map_or_else(|e| e.kind(), |_| "found")
            .to_string(),
        message: result.as_ref().err().map(ToString::to_string),
        gait: result.ok(),
    };
    Ok(summary)
}

/// Walk one period (`period_k` steps) from the gait's fixed point, sampled every [`DEFAULT_SAMPLE_DT`], and write it beside
/// `gait.json` in the format of `vrw simulate` (`steps.csv`, `trajectory.csv`, `summary.json`), so that
/// `vrw plot` and `vrw animate` work on a gait directly.
pub fn write_gait_period(job: &GaitJob, gait: &Gait) -> Result<SimulateSummary, AppError> {
    run_simulate(
        &SimulateJob {
            config: job.config.clone(),
            initial: Some(gait.section),
            steps: gait.period_k,
            sample_dt: DEFAULT_SAMPLE_DT,
            trajectory: true,
            out_dir: job.out_dir.clone(),
            interrupt: None,
        },
        &mut |_| {},
    )
}

/// What `vrw sweep` runs.
#[derive(Debug, Clone)]
pub struct SweepJob {
    /// Parameters and solver options (the swept key is overridden point by point).
    pub config: Config,
    /// The parameter and its range.
    pub spec: SweepSpec,
    /// Where the search at the first point starts (`None`: [`default_initial`]).
    pub initial: Option<SectionState>,
    /// Search settings.
    pub options: GaitOptions,
    /// Search every threshold again by a second route (the whole sweep with the other integrator) and record
    /// in each whether it is confirmed ([`SecondRoute`]).
    pub second_route: bool,
    /// Where `sweep.csv`, `thresholds.json`, `fig2.svg` and `fig2.png` go.
    pub out_dir: PathBuf,
}

/// The configuration of the second route for a result computed with `config`: the other integrator, and the
/// route's name.
pub fn second_route_config(config: &Config) -> (Config, String) {
    let mut second = config.clone();
    second.solver.integrator = config.solver.integrator.other();
    let route = format!("integrator = {}", second.solver.integrator);
    (second, route)
}

/// `thresholds.json`.
#[derive(Debug, Clone, Serialize)]
pub struct SweepSummary {
    /// Version of vrw that produced the file.
    pub vrw_version: &'static str,
    /// Parameters and solver options (the swept key at its configured value).
    pub config: Config,
    /// The sweep.
    pub spec: SweepSpec,
    /// Points with a gait / all points.
    pub gaits_found: usize,
    /// Number of sweep points.
    pub points: usize,
    /// Every located threshold, in parameter order.
    pub thresholds: Vec<Threshold>,
    /// Wall-clock seconds spent on the sweep and on the thresholds (printed, not written: files are
    /// reproducible).
    #[serde(skip)]
    pub seconds: [f64; 2],
    /// Wall-clock seconds spent on the second route (0 without it; printed, not written).
    #[serde(skip)]
    pub second_route_seconds: f64,
    /// The files this run wrote into the output directory (Fig. 2 only if some point has a gait; an earlier
    /// run's figure is removed rather than left beside this run's tables).
    pub files: Vec<String>,
}

/// Run `vrw sweep`: the sweep, its thresholds, `sweep.csv`, `thresholds.json` and Fig. 2. `progress` is called
/// after every sweep point. `sweep.csv` is written before the thresholds are searched, so a later failure loses
/// nothing already computed.
pub fn run_sweep(
    job: &SweepJob,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<SweepSummary, AppError> {
    let (_, initial) = prepared(&job.config, job.initial)?;
    job.spec.validate(&job.config)?;
    output::ensure_dir(&job.out_dir)?;
    let csv = job.out_dir.join("sweep.csv");
    let result = compute_sweep(
        &job.config,
        &job.spec.param,
        &job.spec.values(),
        Some(initial),
        &job.options,
        progress,
        &mut |points| Ok(output::write_sweep_csv(&csv, &job.spec.param, points)?),
    )?;
    let gaits_found = result.points.iter().filter(|p| p.gait.is_some()).count();
    let figures = ["fig2.svg", "fig2.png"];
    let mut files = vec!["sweep.csv".to_string(), "thresholds.json".to_string()];
    if gaits_found > 0 {
        files.extend(figures.map(String::from));
    }
    let mut summary = SweepSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: job.config.clone(),
        spec: job.spec.clone(),
        gaits_found,
        points: result.points.len(),
        thresholds: result.thresholds,
        seconds: result.seconds,
        second_route_seconds: 0.0,
        files,
    };
    let thresholds_json = job.out_dir.join("thresholds.json");
    output::write_json(&thresholds_json, &summary)?;
    if gaits_found > 0 {
        write_fig2(job, &result.points, &summary.thresholds)?;
    } else {
        // A figure of an earlier sweep must not stand beside this sweep's tables.
        for f in figures {
            remove_stale(&job.out_dir.join(f))?;
        }
    }
    if job.second_route {
        // Everything of the first route is written: nothing is lost if this fails.
        let clock = std::time::Instant::now();
        let (second_config, route) = second_route_config(&job.config);
        let second = compute_sweep(
            &second_config,
            &job.spec.param,
            &job.spec.values(),
            Some(initial),
            &job.options,
            progress,
            &mut |_| Ok(()),
        )?;
        for t in &mut summary.thresholds {
            t.second_route = Some(SecondRoute::check(t, &second.thresholds, &route));
        }
        summary.second_route_seconds = clock.elapsed().as_secs_f64();
        output::write_json(&thresholds_json, &summary)?;
    }
    Ok(summary)
}

/// A sweep and its thresholds, as [`compute_sweep`] returns them.
#[derive(Debug, Clone)]
pub struct SweepResult {
    /// One point per parameter value, in the order given.
    pub points: Vec<SweepPoint>,
    /// Every located threshold, in parameter order.
    pub thresholds: Vec<Threshold>,
    /// Wall-clock seconds spent on the sweep and on the thresholds.
    pub seconds: [f64; 2],
}

/// The computation of [`run_sweep`] without writing anything: sweep `param` over `values` with continuation
/// (starting at `initial`, `None`: [`default_initial`]), then locate the thresholds between the points.
/// `progress` is called after every point; `swept` receives the points before the thresholds are searched
/// (where `vrw sweep` writes `sweep.csv`).
pub fn compute_sweep(
    config: &Config,
    param: &str,
    values: &[f64],
    initial: Option<SectionState>,
    options: &GaitOptions,
    progress: &(dyn Fn(&SweepPoint) + Sync),
    swept: &mut dyn FnMut(&[SweepPoint]) -> Result<(), AppError>,
) -> Result<SweepResult, AppError> {
    let (_, initial) = prepared(config, initial)?;
    let clock = std::time::Instant::now();
    let points = sweep_values(config, param, values, &initial, options, progress)?;
    let sweep_seconds = clock.elapsed().as_secs_f64();
    swept(&points)?;
    // The thresholds read the parameter's name from the spec; the range is the values' span.
    let spec = SweepSpec {
        param: param.to_string(),
        from: values.first().copied().unwrap_or(f64::NAN),
        to: values.last().copied().unwrap_or(f64::NAN),
        points: values.len(),
    };
    let clock = std::time::Instant::now();
    let mut thresholds = find_thresholds(config, &spec, &points, options);
    let threshold_seconds = clock.elapsed().as_secs_f64();
    thresholds.sort_by(|a, b| a.value.total_cmp(&b.value));
    Ok(SweepResult {
        points,
        thresholds,
        seconds: [sweep_seconds, threshold_seconds],
    })
}

fn write_fig2(
    job: &SweepJob,
    points: &[SweepPoint],
    thresholds: &[Threshold],
) -> Result<(), AppError> {
    // Points without a gait are NaN, so the curves break there instead of bridging the gap; a change of
    // family breaks them too.
    let indicator_points: Vec<IndicatorPoint> = points
        .iter()
        .map(|p| match &p.gait {
            Some(g) => IndicatorPoint {
                param: p.value,
                lambda_i4: g.lambda_i4,
                lambda_2_plus: g.lambda_2_plus,
                lambda_4_plus: g.lambda_4_plus,
                scuffing: g.scuffing,
                family: p.family,
                period: g.period,
                max_floquet: g.max_floquet,
            },
            None => IndicatorPoint {
                param: p.value,
                lambda_i4: f64::NAN,
                lambda_2_plus: f64::NAN,
                lambda_4_plus: f64::NAN,
                scuffing: false,
                family: None,
                period: f64::NAN,
                max_floquet: f64::NAN,
            },
        })
        .collect();
    let symbol = |t: &Threshold| match t.name.as_str() {
        "lambda_4_plus = 0" => "λ₄⁺ = 0",
        "lambda_2_plus = 0" => "λ₂⁺ = 0",
        "lambda_I4 = 0" => "λI4 = 0",
        "stability_lost" => "unstable",
        "gait_lost" => "gait lost",
        "gait_found"
            if t.detail
                .as_deref()
                .is_some_and(|d| d.contains("found again")) =>
        {
            "gait found again"
        }
        "gait_found" => "gait found",
        "branch_switch" => "branch switch",
        "fold" => "fold",
        _ => "unconfirmed end",
    };
    let marks: Vec<ThresholdMark> = thresholds
        .iter()
        .filter(|t| t.value.is_finite())
        .map(|t| ThresholdMark {
            label: format!(
                "{}: {} = {:.2}",
                symbol(t),
                short_name(&job.spec.param),
                t.value
            ),
            value: t.value,
        })
        .collect();
    let no_gait = no_gait_spans(points, thresholds);
    let title = format!(
        "Gaits along {}: {} (hollow: scuffing of Leg 2; grey: no gait)",
        short_name(&job.spec.param),
        fixed_parameters(&job.config, &job.spec.param)
    );
    let label = axis_label(&job.spec.param);
    let (lo, hi) = (
        job.spec.from.min(job.spec.to),
        job.spec.from.max(job.spec.to),
    );
    let spec = Fig2Spec {
        points: &indicator_points,
        thresholds: &marks,
        param_label: &label,
        title: &title,
        x_range: Some(lo..hi),
        no_gait: &no_gait,
    };
    write_fig2_files(
        &spec,
        &job.out_dir.join("fig2.svg"),
        &job.out_dir.join("fig2.png"),
    )
    .map_err(|e| AppError::InvalidOption {
        option: "figure",
        reason: e.to_string(),
    })
}

/// The parameter intervals without a gait: each maximal run of sweep points without one, from the end of the
/// family on its left (the located threshold in that grid interval, else the midpoint) to the start of the
/// family on its right (likewise), or to the end of the sweep.
fn no_gait_spans(points: &[SweepPoint], thresholds: &[Threshold]) -> Vec<std::ops::Range<f64>> {
    let edge = |a: &SweepPoint, b: &SweepPoint| {
        let (lo, hi) = (a.value.min(b.value), a.value.max(b.value));
        thresholds
            .iter()
            .map(|t| t.value)
            .find(|v| v.is_finite() && lo <= *v && *v <= hi)
            .unwrap_or(0.5 * (a.value + b.value))
    };
    let mut spans = Vec::new();
    let mut i = 0;
    while i < points.len() {
        if points[i].gait.is_some() {
            i += 1;
            continue;
        }
        let start = i;
        while i < points.len() && points[i].gait.is_none() {
            i += 1;
        }
        let a = if start == 0 {
            points[0].value
        } else {
            edge(&points[start - 1], &points[start])
        };
        let b = if i == points.len() {
            points[i - 1].value
        } else {
            edge(&points[i - 1], &points[i])
        };
        spans.push(a.min(b)..a.max(b));
    }
    spans
}

/// The main parameters other than the swept one, for titles: `c = 50 N s/m, k = 500 N/m, φ = 0.1 rad, ...`.
fn fixed_parameters(config: &Config, swept: &str) -> String {
    let p = &config.params;
    let mut parts: Vec<String> = [
        ("viscosity", p.viscosity),
        ("stiffness", p.stiffness),
        ("slope", p.slope),
    ]
    .iter()
    .filter(|(key, _)| *key != swept)
    .map(|(key, v)| {
        let unit = axis_label(key);
        let unit = unit
            .split_once('[')
            .map_or("", |(_, u)| u.trim_end_matches(']'));
        format!("{} = {} {unit}", short_name(key), short(*v))
    })
    .collect();
    parts.push(format!("impact {}", p.impact));
    if p.rigid_legs {
        parts.push("rigid legs".to_string());
    }
    parts.join(", ")
}

/// Short symbol of a parameter for labels (`c` for viscosity, ...).
fn short_name(param: &str) -> &str {
    match param {
        "viscosity" => "c",
        "stiffness" => "k",
        "slope" => "φ",
        "hub_mass" => "mH",
        "leg_mass" => "m",
        other => other,
    }
}

/// Axis label with unit.
fn axis_label(param: &str) -> String {
    let unit = match param {
        "viscosity" => "N s/m",
        "stiffness" => "N/m",
        "slope" => "rad",
        "hub_mass" | "leg_mass" => "kg",
        "hub_inertia" => "kg m²",
        "gravity" => "m/s²",
        "leg_mass_offset" | "stopper_length" | "spring_natural_length" => "m",
        _ => "",
    };
    if unit.is_empty() {
        short_name(param).to_string()
    } else {
        format!("{} [{unit}]", short_name(param))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::walk::{simulate, Sample, SampleSink};
    use std::sync::atomic::Ordering;
    use std::sync::Mutex;

    fn job(dir: &std::path::Path, steps: usize, trajectory: bool) -> SimulateJob {
        SimulateJob {
            config: Config::default(),
            initial: None,
            steps,
            sample_dt: 0.005,
            trajectory,
            out_dir: dir.to_path_buf(),
            interrupt: None,
        }
    }

    fn rows(path: &std::path::Path) -> usize {
        std::fs::read_to_string(path).unwrap().lines().count() - 1
    }

    /// The interrupt flag (what Ctrl-C sets) stops the walk at the next touchdown; everything computed is
    /// written, with the status `interrupted`.
    #[test]
    fn interrupted_run_keeps_what_was_computed() {
        let dir = tempfile::tempdir().unwrap();
        let flag = Arc::new(AtomicBool::new(false));
        let mut job = job(dir.path(), 1_000_000, true);
        job.interrupt = Some(Arc::clone(&flag));
        let mut seen = 0;
        let summary = run_simulate(&job, &mut |event| {
            if let SimulateEvent::Step(_) = event {
                seen += 1;
                if seen == 3 {
                    flag.store(true, Ordering::Relaxed);
                }
            }
        })
        .unwrap();
        assert_eq!(summary.status, "interrupted");
        assert_eq!(summary.steps_completed, 3);
        assert_eq!(rows(&dir.path().join("steps.csv")), 3);
        let written: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.path().join("summary.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(written["status"], "interrupted");
        assert_eq!(written["end_time"], summary.end_time);
        assert!(rows(&dir.path().join("trajectory.csv")) > 3);
    }

    /// summary.json keeps only the last [`SUMMARY_STEPS`] step records; steps.csv has every step.
    #[test]
    fn summary_keeps_the_last_steps_and_csv_every_step() {
        let dir = tempfile::tempdir().unwrap();
        let steps = SUMMARY_STEPS + 7;
        let summary = run_simulate(&job(dir.path(), steps, false), &mut |_| {}).unwrap();
        assert_eq!(summary.status, "completed");
        assert_eq!(summary.steps.len(), SUMMARY_STEPS);
        assert_eq!(summary.steps[0].step, 8);
        assert_eq!(summary.steps.last().unwrap().step, steps);
        assert_eq!(rows(&dir.path().join("steps.csv")), steps);
        assert!(!dir.path().join("trajectory.csv").exists());
        assert_eq!(summary.branches.values().sum::<usize>(), steps);
    }

    /// A step whose energy audit does not close is a warning, counted and listed.
    #[test]
    fn energy_residual_above_the_bound_warns() {
        let config = Config::default();
        let model = Model::new(&config.params).unwrap();
        let run = simulate(&model, &config.solver, &default_initial(&config), 1, None).unwrap();
        let mut report = run.steps[0];
        let dir = tempfile::tempdir().unwrap();
        let mut summary =
            SimulateSummary::new(&job(dir.path(), 1, false), default_initial(&config));
        let mut last = VecDeque::new();
        assert_eq!(summary.add_step(&report, &mut last), None);
        report.energy.residual = 10.0 * ENERGY_RESIDUAL_WARNING;
        let warning = summary.add_step(&report, &mut last).unwrap();
        assert!(warning.contains("energy residual 1e-5 J"), "{warning}");
        report.energy.residual = f64::NAN;
        assert!(summary.add_step(&report, &mut last).is_some());
        assert_eq!(summary.warnings.len(), 2);
        assert_eq!(summary.warnings_total, 2);
    }

    /// A sink that collects the samples it is handed.
    struct Collect(Arc<Mutex<Vec<Sample>>>);

    impl SampleSink for Collect {
        fn write(&mut self, sample: &Sample) -> std::io::Result<()> {
            self.0.lock().unwrap().push(sample.clone());
            Ok(())
        }
    }

    /// A sink that fails once it has taken `left` samples (a full disk).
    struct FailAfter(usize);

    impl SampleSink for FailAfter {
        fn write(&mut self, _: &Sample) -> std::io::Result<()> {
            self.0 = self
                .0
                .checked_sub(1)
                .ok_or(std::io::ErrorKind::StorageFull)?;
            Ok(())
        }
    }

    /// A trajectory whose sink fails stops the walk at once, and the error is not lost.
    #[test]
    fn failing_trajectory_sink_stops_the_walk() {
        let config = Config::default();
        let model = Model::new(&config.params).unwrap();
        let mut trajectory = Trajectory::streaming(0.01, Box::new(FailAfter(10)));
        let end = simulate_streaming(
            &model,
            &config.solver,
            &default_initial(&config),
            1000,
            Some(&mut trajectory),
            None,
            |_| Ok::<(), WalkError>(()),
        )
        .unwrap();
        assert!(end.steps < 2, "{end:?}");
        assert_eq!(
            trajectory.take_error().map(|e| e.kind()),
            Some(std::io::ErrorKind::StorageFull)
        );
    }

    /// A streaming trajectory hands out exactly the samples an in-memory one keeps, and keeps none.
    #[test]
    fn streaming_trajectory_matches_the_in_memory_one() {
        let config = Config::default();
        let model = Model::new(&config.params).unwrap();
        let start = default_initial(&config);
        let mut kept = Trajectory::new(0.01);
        simulate(&model, &config.solver, &start, 2, Some(&mut kept)).unwrap();
        let streamed = Arc::new(Mutex::new(Vec::new()));
        let mut streaming = Trajectory::streaming(0.01, Box::new(Collect(Arc::clone(&streamed))));
        simulate(&model, &config.solver, &start, 2, Some(&mut streaming)).unwrap();
        assert!(streaming.samples.is_empty());
        assert_eq!(streaming.len(), kept.len());
        assert_eq!(*streamed.lock().unwrap(), kept.samples);
    }
}
