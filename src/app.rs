//! The jobs the command line runs, as library functions (STYLE.md point 2: all science lives in the library).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::dynamics::Model;
use crate::error::WalkError;
use crate::gait::{find_gait, Gait, GaitOptions, StepMap};
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
    /// Trajectory sampling interval [s].
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
    /// Simulated time reached [s].
    pub end_time: f64,
    /// Largest `|energy_residual|` over the steps [J].
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
    job.config.validate()?;
    if !(job.sample_dt.is_finite() && job.sample_dt > 0.0) {
        return Err(AppError::InvalidOption {
            option: "--sample-dt",
            reason: format!("{} is not a positive time step", job.sample_dt),
        });
    }
    let model = Model::new(&job.config.params)?;
    let initial = job.initial.unwrap_or_else(|| default_initial(&job.config));
    let mut trajectory = Trajectory::new(job.sample_dt);
    let run = simulate(
        &model,
        &job.config.solver,
        &initial,
        job.steps,
        Some(&mut trajectory),
    )?;
    let summary = SimulateSummary::new(job, initial, &run);
    write_simulation(&job.out_dir, &summary, &trajectory)?;
    Ok(summary)
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
        status: result.as_ref().map_or_else(|e| e.kind(), |_| "found").to_string(),
        message: result.as_ref().err().map(ToString::to_string),
        gait: result.ok(),
    };
    output::ensure_dir(&job.out_dir)?;
    output::write_json(&job.out_dir.join("gait.json"), &summary)?;
    Ok(summary)
}
