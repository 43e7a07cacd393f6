//! `vrw simulate --model NAME`: a walker walks N steps from its default start (or `initial`, a section state
//! by its coordinates), written as the wheel's walk is: `steps.csv` (a row per step: the section state at its
//! start, its duration and stride, `lambda_I4`, the impact's loss, the energy audit, scuffs), `trajectory.csv`
//! (the coordinates named by the model, the energies, the drawing's points) and `summary.json` (how the walk
//! ended, the model, its parameters and drawing), streamed as the walk goes, with the manifest. Written once
//! for every walker, on [`WalkerModel`].

use std::path::PathBuf;

use nalgebra::DVector;
use serde::Serialize;

use super::walker_model::{Sampling, WalkerModel, WalkerSample, WalkerStep};
use super::walker_output::WalkerOutput;
use super::walkers::{as_map, named, Walker};
use super::{in_run_on, AppError, WalkEnded, MAX_SIMULATE_STEPS, SAMPLE_DT_RANGE};
use crate::mechanism::legged::walk::StepAccount;
use crate::output::walker_run::{
    legged_step_values, walker_steps_header, walker_trajectory_header, StickFigure,
};
use crate::output::{self, CsvStream};

/// What `vrw simulate --model NAME` runs.
#[derive(Debug, Clone)]
pub struct WalkerSimulateJob {
    /// The walker.
    pub walker: Walker,
    /// Where the walk starts on the section (the model's section coordinates); default the model's start.
    pub initial: Option<Vec<f64>>,
    /// Steps (heel strikes) to walk.
    pub steps: usize,
    /// Sampling interval of `trajectory.csv`, in the model's time unit.
    pub sample_dt: f64,
    /// Write `trajectory.csv`.
    pub trajectory: bool,
    /// Output directory.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir`.
    pub overwrite: bool,
}

impl WalkerSimulateJob {
    /// Checks `steps` and `sample_dt` as the wheel's simulation does.
    fn validate(&self) -> Result<(), AppError> {
        if !(1..=MAX_SIMULATE_STEPS).contains(&self.steps) {
            return Err(AppError::InvalidOption {
                option: "steps",
                reason: format!(
                    "{} steps is not between 1 and {MAX_SIMULATE_STEPS}",
                    self.steps
                ),
            });
        }
        let [lo, hi] = SAMPLE_DT_RANGE;
        if !(self.sample_dt.is_finite() && (lo..=hi).contains(&self.sample_dt)) {
            return Err(AppError::InvalidOption {
                option: "sample_dt",
                reason: format!(
                    "{} is not between {} and {} (in the model's time unit)",
                    crate::fmt::short(self.sample_dt),
                    crate::fmt::short(lo),
                    crate::fmt::short(hi)
                ),
            });
        }
        Ok(())
    }
}

/// A row of a walker's `steps.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerStepRecord {
    /// The step's number, from 1.
    pub step: usize,
    /// The walk's time at its start.
    pub time: f64,
    /// The section state at its start, by the section's coordinates.
    #[serde(serialize_with = "as_map")]
    pub section: Vec<(String, f64)>,
    /// Its duration.
    pub period: f64,
    /// How far the stance foot moves along the slope.
    pub stride: f64,
    /// `stride / period`.
    pub speed: f64,
    /// The heel strike's DLS indicator.
    #[serde(rename = "lambda_I4")]
    pub lambda_i4: f64,
    /// The energy the heel strike takes.
    pub impact_loss: f64,
    /// `T + V` at the start.
    pub energy_start: f64,
    /// The largest change of `T + V` over single support (the energy audit).
    pub energy_drift: f64,
    /// Crossings of the ground by the swing foot ignored as scuffing.
    pub scuffs: usize,
    /// What a step of a walker with compliant legs has besides ([`WalkerStep::legged`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub legged: Option<StepAccount>,
}

impl WalkerStepRecord {
    /// The record of step `step` started at `time` from the section state `start`, by the names `names`.
    fn new(
        step: usize,
        time: f64,
        (names, start): (&[String], &DVector<f64>),
        s: &WalkerStep,
    ) -> Self {
        WalkerStepRecord {
            step,
            time,
            section: names.iter().cloned().zip(start.iter().copied()).collect(),
            period: s.period,
            stride: s.stride,
            speed: s.stride / s.period,
            lambda_i4: s.lambda_i4,
            impact_loss: s.impact_loss,
            energy_start: s.energy_start,
            energy_drift: s.energy_drift,
            scuffs: s.scuffs,
            legged: s.legged,
        }
    }

    /// The row as `steps.csv` holds it ([`walker_steps_header`]).
    fn row(&self) -> Vec<String> {
        let mut row = vec![self.step.to_string(), output::num(self.time)];
        row.extend(self.section.iter().map(|(_, v)| output::num(*v)));
        row.extend(
            [
                self.period,
                self.stride,
                self.speed,
                self.lambda_i4,
                self.impact_loss,
                self.energy_start,
                self.energy_drift,
            ]
            .map(output::num),
        );
        row.push(self.scuffs.to_string());
        if let Some(a) = &self.legged {
            row.extend(legged_step_values(a));
        }
        row
    }
}

/// A walker's `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct WalkerSimulateSummary {
    /// vrw's version.
    pub vrw_version: &'static str,
    /// The model's name.
    pub model: String,
    /// Its parameters.
    pub parameters: Walker,
    /// The slope \[rad\].
    pub slope: f64,
    /// The names of the coordinates.
    pub coordinates: Vec<String>,
    /// What a drawing shows.
    pub figure: StickFigure,
    /// The start, by the section's coordinates.
    #[serde(serialize_with = "as_map")]
    pub initial: Vec<(String, f64)>,
    /// Steps asked for.
    pub steps_requested: usize,
    /// Steps walked.
    pub steps_completed: usize,
    /// `completed`, `interrupted`, `running` (while it walks) or the failure's kind (`fell`, ...).
    #[serde(serialize_with = "crate::fmt::as_text")]
    pub status: WalkEnded,
    /// The failure or the interruption in words.
    pub message: Option<String>,
    /// The walk's time at the last heel strike.
    pub end_time: f64,
    /// How far the stance foot moved along the slope.
    pub distance: f64,
    /// The largest energy audit of a step.
    pub max_energy_drift: f64,
    /// The last step walked.
    pub last_step: Option<WalkerStepRecord>,
    /// The files written.
    pub files: Vec<String>,
}

/// Walk `job.walker` and write its run, after the options and the output directory are checked. An
/// interrupted walk (Ctrl-C) keeps its complete steps, and the manifest says `interrupted`.
pub fn run_walker_simulate(job: &WalkerSimulateJob) -> Result<WalkerSimulateSummary, AppError> {
    job.validate()?;
    let model = job.walker.model()?;
    let start = super::walkers::start_of(model.as_ref(), job.initial.as_deref())?;
    output::manifest::check_out_dir(&job.out_dir, "simulate", job.overwrite)?;
    in_run_on(
        &job.out_dir,
        job.overwrite,
        ("simulate", Some(job.walker.name())),
        |run| {
            let mut files = vec!["steps.csv".to_string()];
            if job.trajectory {
                files.push("trajectory.csv".to_string());
            }
            files.push("summary.json".to_string());
            let mut summary = WalkerSimulateSummary::start(job, model.as_ref(), &start);
            summary.files.clone_from(&files);
            output::write_json(&run.path("summary.json"), &summary)?;
            let names: Vec<&str> = files.iter().map(String::as_str).collect();
            run.add_streaming(&names)?;
            let section = model.section_names();
            let mut steps = CsvStream::create(
                &run.path("steps.csv"),
                walker_steps_header(&section, model.legged()),
            )?;
            let mut trajectory = match job.trajectory {
                true => Some(CsvStream::create(
                    &run.path("trajectory.csv"),
                    walker_trajectory_header(&model.coordinates(), &model.figure()),
                )?),
                false => None,
            };
            let mut to_steps = |row| steps.write(row).map_err(AppError::from);
            let mut to_trajectory = |row| match trajectory.as_mut() {
                Some(csv) => csv.write(row).map_err(AppError::from),
                None => Ok(()),
            };
            let sinks = RowSinks {
                steps: &mut to_steps,
                trajectory: job.trajectory.then_some(&mut to_trajectory),
            };
            walk(job, model.as_ref(), start, &mut summary, sinks)?;
            output::write_json(&run.path("summary.json"), &summary)?;
            let interrupted = (summary.status == WalkEnded::Interrupted).then(|| {
                format!(
                    "interrupted (Ctrl-C) after {} of {} steps",
                    summary.steps_completed, summary.steps_requested
                )
            });
            Ok((summary, interrupted))
        },
    )
}

/// The walk of [`run_walker_simulate`] without its files (the Python binding): `summary.json`'s fields (`files`
/// empty) and the rows of `steps.csv` and, with `job.trajectory`, `trajectory.csv` (`job.out_dir` and
/// `job.overwrite` are not read). A walk interrupted (Ctrl-C) or ended early says so in its `status`, as the
/// command line's.
pub fn compute_walker_simulate(
    job: &WalkerSimulateJob,
) -> Result<WalkerOutput<WalkerSimulateSummary>, AppError> {
    job.validate()?;
    let model = job.walker.model()?;
    let start = super::walkers::start_of(model.as_ref(), job.initial.as_deref())?;
    let mut summary = WalkerSimulateSummary::start(job, model.as_ref(), &start);
    let mut steps = vec![walker_steps_header(&model.section_names(), model.legged())];
    let mut trajectory = vec![walker_trajectory_header(
        &model.coordinates(),
        &model.figure(),
    )];
    let mut to_steps = |row| {
        steps.push(row);
        Ok(())
    };
    let mut to_trajectory = |row| {
        trajectory.push(row);
        Ok(())
    };
    let sinks = RowSinks {
        steps: &mut to_steps,
        trajectory: job.trajectory.then_some(&mut to_trajectory),
    };
    walk(job, model.as_ref(), start, &mut summary, sinks)?;
    let mut tables = vec![("steps.csv", steps)];
    if job.trajectory {
        tables.push(("trajectory.csv", trajectory));
    }
    Ok(WalkerOutput { summary, tables })
}

/// Where a walk's rows go as it walks: `steps.csv`'s, and `trajectory.csv`'s (`None`: no trajectory).
struct RowSinks<'a> {
    steps: &'a mut dyn FnMut(Vec<String>) -> Result<(), AppError>,
    trajectory: Option<&'a mut dyn FnMut(Vec<String>) -> Result<(), AppError>>,
}

impl WalkerSimulateSummary {
    /// The summary before the first step (`running`).
    fn start(job: &WalkerSimulateJob, model: &dyn WalkerModel, start: &DVector<f64>) -> Self {
        WalkerSimulateSummary {
            vrw_version: env!("CARGO_PKG_VERSION"),
            model: model.name().to_string(),
            parameters: job.walker.clone(),
            slope: model.slope(),
            coordinates: model.coordinates(),
            figure: model.figure(),
            initial: named(&model.section_names(), start),
            steps_requested: job.steps,
            steps_completed: 0,
            status: WalkEnded::Running,
            message: None,
            end_time: 0.0,
            distance: 0.0,
            max_energy_drift: 0.0,
            last_step: None,
            files: Vec::new(),
        }
    }
}

/// The walk of [`run_walker_simulate`]: every step's row written as it is walked, and its samples (written
/// only once the step is complete, so that an interrupted step leaves no half of itself).
fn walk(
    job: &WalkerSimulateJob,
    model: &dyn WalkerModel,
    mut s: DVector<f64>,
    summary: &mut WalkerSimulateSummary,
    sinks: RowSinks<'_>,
) -> Result<(), AppError> {
    let RowSinks {
        steps,
        mut trajectory,
    } = sinks;
    let names = model.section_names();
    let (mut time, mut stance_x) = (0.0, 0.0);
    summary.status = WalkEnded::Completed;
    for k in 1..=job.steps {
        let mut samples: Vec<WalkerSample> = Vec::new();
        let mut sink = |sample| samples.push(sample);
        let sampling = trajectory.is_some().then_some(Sampling {
            start: time,
            dt: job.sample_dt,
            sink: &mut sink,
        });
        let step = match model.step(&s, sampling) {
            Ok(step) => step,
            Err(e) => {
                summary.status = match e.is_interrupted() {
                    true => WalkEnded::Interrupted,
                    false => WalkEnded::Failed(e.kind()),
                };
                summary.message = Some(format!("step {k}: {e}"));
                break;
            }
        };
        if let Some(sink) = trajectory.as_deref_mut() {
            for sample in &samples {
                sink(trajectory_row(k, stance_x, sample))?;
            }
        }
        let record = WalkerStepRecord::new(k, time, (&names, &s), &step);
        steps(record.row())?;
        time += step.period;
        stance_x += step.stride;
        summary.steps_completed = k;
        summary.end_time = time;
        summary.distance = stance_x;
        summary.max_energy_drift = summary.max_energy_drift.max(step.energy_drift);
        summary.last_step = Some(record);
        s = step.section;
    }
    Ok(())
}

/// A row of `trajectory.csv` ([`walker_trajectory_header`]) of step `step`, the stance foot at `stance_x`.
fn trajectory_row(step: usize, stance_x: f64, s: &WalkerSample) -> Vec<String> {
    let mut row = vec![output::num(s.time), step.to_string(), output::num(stance_x)];
    row.extend(s.q.iter().chain(&s.qd).map(|v| output::num(*v)));
    row.extend([s.kinetic, s.potential, s.kinetic + s.potential].map(output::num));
    row.extend(
        s.points
            .iter()
            .flat_map(|p| [output::num(p[0] + stance_x), output::num(p[1])]),
    );
    row
}
