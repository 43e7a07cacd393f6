//! The jobs the command line runs, as library functions (STYLE.md point 2: all science lives in the library).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::dynamics::Model;
use crate::error::WalkError;
use crate::gait::{
    find_gait, find_thresholds, sweep_values, Gait, GaitOptions, StepMap, SweepPoint, SweepSpec,
    Threshold,
};
use crate::output::plot::{
    write_fig2 as write_fig2_files, Fig2Spec, IndicatorPoint, ThresholdMark,
};
use crate::output::{self, OutputError};
use crate::params::{Config, ConfigError};
use crate::walk::{simulate, SectionState, StepReport, Trajectory, WalkRun};

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
    /// A bad command-line value that is not a model parameter.
    #[error("invalid {option}: {reason}")]
    InvalidOption {
        /// The option.
        option: &'static str,
        /// Why.
        reason: String,
    },
}

/// The default starting point on the Poincare section (MODEL.md section 6): `(0.72, 1.0, 0.0)`, or, with
/// `rigid_legs`, `(L0, 1.0, 0.0)` since rigid legs stay at `L0`.
pub fn default_initial(config: &Config) -> SectionState {
    let l2 = if config.params.rigid_legs {
        config.params.stopper_length
    } else {
        0.72
    };
    SectionState {
        l2,
        theta_dot: 1.0,
        l2_dot: 0.0,
    }
}

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
    /// Where `steps.csv`, `trajectory.csv` and `summary.json` go.
    pub out_dir: PathBuf,
}

/// `summary.json`: the parameters used, how the run ended and every step.
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
    /// `completed`, or the failure kind (`fell`, `stalled`, ...).
    pub status: String,
    /// The failure, in words, if any.
    pub message: Option<String>,
    /// Simulated time reached \[s\].
    pub end_time: f64,
    /// Largest `|energy_residual|` over the steps \[J\].
    pub max_abs_energy_residual: f64,
    /// Per-step records.
    pub steps: Vec<StepReport>,
}

impl SimulateSummary {
    fn new(job: &SimulateJob, initial: SectionState, run: &WalkRun) -> SimulateSummary {
        SimulateSummary {
            vrw_version: env!("CARGO_PKG_VERSION"),
            config: job.config.clone(),
            initial,
            steps_requested: job.steps,
            steps_completed: run.steps.len(),
            status: run
                .failure
                .as_ref()
                .map_or("completed", WalkError::kind)
                .to_string(),
            message: run.failure.as_ref().map(ToString::to_string),
            end_time: run.time,
            max_abs_energy_residual: run
                .steps
                .iter()
                .map(|s| s.energy.residual.abs())
                .fold(0.0, f64::max),
            steps: run.steps.clone(),
        }
    }

    /// Did the walk complete every requested step?
    pub fn completed(&self) -> bool {
        self.message.is_none()
    }
}

/// Run `vrw simulate`: walk, then write the three result files (also when the walk stopped early: every
/// completed step is kept).
pub fn run_simulate(job: &SimulateJob) -> Result<SimulateSummary, AppError> {
    let (summary, trajectory) = compute_simulation(job, true)?;
    let trajectory = trajectory.unwrap_or_else(|| Trajectory::new(job.sample_dt));
    write_simulation(&job.out_dir, &summary, &trajectory)?;
    Ok(summary)
}

/// The walk of [`run_simulate`] without writing anything (`job.out_dir` is not used): the summary, and the
/// trajectory sampled every `job.sample_dt` if `record_trajectory`.
pub fn compute_simulation(
    job: &SimulateJob,
    record_trajectory: bool,
) -> Result<(SimulateSummary, Option<Trajectory>), AppError> {
    job.config.validate()?;
    if !(job.sample_dt.is_finite() && job.sample_dt > 0.0) {
        return Err(AppError::InvalidOption {
            option: "--sample-dt",
            reason: format!("{} is not a positive time step", job.sample_dt),
        });
    }
    let model = Model::new(&job.config.params)?;
    let initial = job.initial.unwrap_or_else(|| default_initial(&job.config));
    let mut trajectory = record_trajectory.then(|| Trajectory::new(job.sample_dt));
    let run = simulate(
        &model,
        &job.config.solver,
        &initial,
        job.steps,
        trajectory.as_mut(),
    )?;
    Ok((SimulateSummary::new(job, initial, &run), trajectory))
}

fn write_simulation(
    dir: &Path,
    summary: &SimulateSummary,
    trajectory: &Trajectory,
) -> Result<(), OutputError> {
    output::ensure_dir(dir)?;
    output::write_steps_csv(&dir.join("steps.csv"), &summary.steps)?;
    output::write_trajectory_csv(&dir.join("trajectory.csv"), &trajectory.samples)?;
    output::write_json(&dir.join("summary.json"), summary)
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
    /// Where `gait.json` goes.
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

/// Run `vrw gait`: search the gait and write `gait.json` (also when no gait is found, with the reason).
pub fn run_gait(job: &GaitJob) -> Result<GaitSummary, AppError> {
    let summary = compute_gait(job)?;
    output::ensure_dir(&job.out_dir)?;
    output::write_json(&job.out_dir.join("gait.json"), &summary)?;
    Ok(summary)
}

/// The search of [`run_gait`] without writing anything (`job.out_dir` is not used). A search that finds no
/// gait is a summary with its status and message, not an error.
pub fn compute_gait(job: &GaitJob) -> Result<GaitSummary, AppError> {
    job.config.validate()?;
    let model = Model::new(&job.config.params)?;
    let initial = job.initial.unwrap_or_else(|| default_initial(&job.config));
    initial.validate(&model)?;
    let map = StepMap::new(&model, &job.config.solver);
    let result = find_gait(&map, &initial, &job.options, None);
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
    /// Where `sweep.csv`, `thresholds.json`, `fig2.svg` and `fig2.png` go.
    pub out_dir: PathBuf,
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
}

/// Run `vrw sweep`: the sweep, its thresholds, `sweep.csv`, `thresholds.json` and Fig. 2. `progress` is called
/// after every sweep point. `sweep.csv` is written before the thresholds are searched, so a later failure loses
/// nothing already computed.
pub fn run_sweep(
    job: &SweepJob,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<SweepSummary, AppError> {
    job.config.validate()?;
    job.spec.validate(&job.config)?;
    output::ensure_dir(&job.out_dir)?;
    let csv = job.out_dir.join("sweep.csv");
    let result = compute_sweep(
        &job.config,
        &job.spec.param,
        &job.spec.values(),
        job.initial,
        &job.options,
        progress,
        &mut |points| Ok(output::write_sweep_csv(&csv, &job.spec.param, points)?),
    )?;
    let summary = SweepSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: job.config.clone(),
        spec: job.spec.clone(),
        gaits_found: result.points.iter().filter(|p| p.gait.is_some()).count(),
        points: result.points.len(),
        thresholds: result.thresholds,
        seconds: result.seconds,
    };
    output::write_json(&job.out_dir.join("thresholds.json"), &summary)?;
    if summary.gaits_found > 0 {
        write_fig2(job, &result.points, &summary.thresholds)?;
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
    config.validate()?;
    let model = Model::new(&config.params)?;
    let initial = initial.unwrap_or_else(|| default_initial(config));
    initial.validate(&model)?;
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
    // Points without a gait are NaN, so the curves break there instead of bridging the gap.
    let indicator_points: Vec<IndicatorPoint> = points
        .iter()
        .map(|p| match &p.gait {
            Some(g) => IndicatorPoint {
                param: p.value,
                lambda_i4: g.lambda_i4,
                lambda_2_plus: g.lambda_2_plus,
                lambda_4_plus: g.lambda_4_plus,
                scuffing: g.scuffing,
            },
            None => IndicatorPoint {
                param: p.value,
                lambda_i4: f64::NAN,
                lambda_2_plus: f64::NAN,
                lambda_4_plus: f64::NAN,
                scuffing: false,
            },
        })
        .collect();
    let symbol = |name: &str| match name {
        "lambda_4_plus = 0" => "λ₄⁺ = 0",
        "lambda_2_plus = 0" => "λ₂⁺ = 0",
        "lambda_I4 = 0" => "λI4 = 0",
        "stability_lost" => "unstable",
        _ => "gait lost",
    };
    let marks: Vec<ThresholdMark> = thresholds
        .iter()
        .filter(|t| t.value.is_finite())
        .map(|t| ThresholdMark {
            label: format!(
                "{}: {} = {:.2}",
                symbol(&t.name),
                short_name(&job.spec.param),
                t.value
            ),
            value: t.value,
        })
        .collect();
    let p = &job.config.params;
    let title = format!(
        "DLS indicators of the gait, slope φ = {} rad, impact {} (hollow: scuffing of Leg 2)",
        p.slope, p.impact
    );
    let label = axis_label(&job.spec.param);
    let spec = Fig2Spec {
        points: &indicator_points,
        thresholds: &marks,
        param_label: &label,
        title: &title,
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
