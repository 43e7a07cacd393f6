//! The job of `vrw simulate`: walk N steps, streaming `steps.csv` and `trajectory.csv`, then write
//! `summary.json`; and the same walk held in memory for other fronts ([`compute_simulation`]).

use std::collections::{BTreeMap, VecDeque};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use serde::Serialize;

use crate::dynamics::Model;
use crate::fmt::short;
use crate::output::{self, OutputError};
use crate::params::Config;
use crate::reference::default_initial;
use crate::walk::{simulate_streaming, SectionState, StepReport, Trajectory};

use super::{in_run, AppError};
use crate::output::manifest::RunDir;

/// The smallest trajectory sampling interval `vrw simulate` accepts \[s\].
pub const MIN_SAMPLE_DT: f64 = 1e-6;

/// Accepted range of the trajectory sampling interval `sample_dt` \[s\]: from [`MIN_SAMPLE_DT`] to 100 s
/// (longer than any step, so at most one sample per step besides the events).
pub const SAMPLE_DT_RANGE: [f64; 2] = [MIN_SAMPLE_DT, 100.0];

/// The most steps `vrw simulate` walks (`steps`): `steps.csv` streams, but at about a millisecond a step
/// this is already many minutes.
pub const MAX_SIMULATE_STEPS: usize = 10_000_000;

/// `summary.json` keeps the records of the last this many steps; `steps.csv` has every step.
pub(crate) const SUMMARY_STEPS: usize = 1000;

/// `summary.json` keeps the first this many warnings and counts the rest.
pub(crate) const SUMMARY_WARNINGS: usize = 100;
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
    /// run in `out_dir` is removed, as every file of an earlier run is).
    pub trajectory: bool,
    /// Where `steps.csv`, `trajectory.csv` and `summary.json` go.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir` (its files are removed and listed in the manifest);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    pub overwrite: bool,
    /// Set it (e.g. from a Ctrl-C handler) to stop the walk at the next touchdown; the results so far are
    /// written with the status `interrupted`.
    pub interrupt: Option<Arc<AtomicBool>>,
}

impl SimulateJob {
    /// Checks the job's own settings (the configuration is checked by [`Config::validate`]): `steps` from 1
    /// to [`MAX_SIMULATE_STEPS`], `sample_dt` in [`SAMPLE_DT_RANGE`]. The error names the setting by its
    /// field (the Python keyword; the command line renames it to its flag).
    pub fn validate(&self) -> Result<(), AppError> {
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
                    "{} s is not between {} s (a million samples per simulated second) and {} s",
                    short(self.sample_dt),
                    short(lo),
                    short(hi)
                ),
            });
        }
        Ok(())
    }
}

/// How a walk of `vrw simulate` (or a gait's period) ended. A value until it is written: its text (`running`,
/// `completed`, `interrupted`, or the failure kind `fell`, `stalled`, ...) is `summary.json`'s `status`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WalkEnded {
    /// Still walking (the summary written at the start).
    Running,
    /// Every step asked for was walked.
    Completed,
    /// The interrupt flag (Ctrl-C) stopped it.
    Interrupted,
    /// The walk failed: its kind ([`WalkError::kind`](crate::walk::WalkError::kind)).
    Failed(&'static str),
}

impl std::fmt::Display for WalkEnded {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            WalkEnded::Running => "running",
            WalkEnded::Completed => "completed",
            WalkEnded::Interrupted => "interrupted",
            WalkEnded::Failed(kind) => kind,
        })
    }
}

/// `summary.json`: the parameters used, how the run ended, aggregates over every step, and the records of the
/// last `SUMMARY_STEPS` steps (`steps.csv` has every step).
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
    /// How the walk ended.
    #[serde(serialize_with = "crate::fmt::as_text")]
    pub status: WalkEnded,
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
    /// `ENERGY_RESIDUAL_WARNING`); the first `SUMMARY_WARNINGS` of them.
    pub warnings: Vec<String>,
    /// Number of warnings, including those not listed.
    pub warnings_total: usize,
    /// The most step records `steps` holds (`SUMMARY_STEPS`).
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
            status: WalkEnded::Running,
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

    /// Account for one completed step; returns the warnings its audits raise ([`StepReport::audit_warnings`])
    /// that are listed (the first [`SUMMARY_WARNINGS`] of the run; every one is counted).
    fn add_step(&mut self, report: &StepReport, last: &mut VecDeque<StepReport>) -> Vec<String> {
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
        let mut listed = Vec::new();
        for warning in report.audit_warnings() {
            self.warnings_total += 1;
            if self.warnings.len() < SUMMARY_WARNINGS {
                self.warnings.push(warning.clone());
                listed.push(warning);
            }
        }
        listed
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
    in_run(&job.out_dir, job.overwrite, "simulate", |run| {
        let summary = simulate_into(job, &model, initial, run, observe)?;
        let interrupted =
            (summary.status == WalkEnded::Interrupted).then(|| summary.message.clone());
        Ok((summary, interrupted.flatten()))
    })
}

/// The walk of [`run_simulate`] into the run directory `run` (also the period that `vrw gait` writes beside
/// `gait.json`). `summary.json` is written first with the status `running` (so that the complete rows of a
/// killed run can still be drawn, `vrw plot --partial`), then the streamed tables, listed in the manifest at
/// once, then the final `summary.json`.
pub(super) fn simulate_into(
    job: &SimulateJob,
    model: &Model,
    initial: SectionState,
    run: &mut RunDir,
    observe: &mut dyn FnMut(SimulateEvent),
) -> Result<SimulateSummary, AppError> {
    let mut files = vec!["steps.csv".to_string()];
    if job.trajectory {
        files.push("trajectory.csv".to_string());
    }
    files.push("summary.json".to_string());
    let mut running = SimulateSummary::new(job, initial);
    running.status = WalkEnded::Running;
    running.files.clone_from(&files);
    output::write_json(&run.path("summary.json"), &running)?;
    let names: Vec<&str> = files.iter().map(String::as_str).collect();
    run.add_streaming(&names)?;
    let mut steps_csv = output::StepsCsv::create(
        &run.path("steps.csv"),
        output::StepsColumns::of(&job.config.params),
    )?;
    let trajectory_path = run.path("trajectory.csv");
    let mut trajectory = if job.trajectory {
        let sink = output::TrajectoryCsv::create(&trajectory_path, job.config.params.rear_exit)?;
        Some(Trajectory::streaming(job.sample_dt, Box::new(sink)))
    } else {
        None
    };
    let write_row = |report: &StepReport| -> Result<(), AppError> { Ok(steps_csv.write(report)?) };
    let mut summary = walk_job(job, model, initial, trajectory.as_mut(), write_row, observe)?;
    if let Some(source) = trajectory.as_mut().and_then(Trajectory::take_error) {
        return Err(OutputError::Io {
            path: trajectory_path,
            source,
        }
        .into());
    }
    summary.files = files;
    output::write_json(&run.path("summary.json"), &summary)?;
    Ok(summary)
}

/// The walk of [`run_simulate`] without writing anything (`job.out_dir` and `job.trajectory` are not used),
/// for other fronts (the Python binding): the summary with **every** step record (not only the last
/// `SUMMARY_STEPS`), and the trajectory sampled every `job.sample_dt` if `record_trajectory`. It is held in
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
    job.validate()?;
    job.config.validate()?;
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
            let warnings = summary.add_step(report, &mut last);
            observe(SimulateEvent::Step(report));
            for w in &warnings {
                observe(SimulateEvent::Warning(w));
            }
            Ok(())
        },
    )?;
    summary.end_time = end.time;
    summary.steps = last.into();
    (summary.status, summary.message) = match (&end.failure, end.interrupted) {
        (Some(e), _) => (WalkEnded::Failed(e.kind()), Some(e.to_string())),
        (None, true) => (
            WalkEnded::Interrupted,
            Some(format!(
                "interrupted after {} of {} steps",
                end.steps, job.steps
            )),
        ),
        (None, false) => (WalkEnded::Completed, None),
    };
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::walk::{simulate, Sample, SampleSink, WalkError};
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
            overwrite: false,
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
        assert_eq!(summary.status, WalkEnded::Interrupted);
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
        assert_eq!(summary.status, WalkEnded::Completed);
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
        assert_eq!(summary.add_step(&report, &mut last), Vec::<String>::new());
        report.energy.residual = 10.0 * crate::walk::ENERGY_RESIDUAL_WARNING;
        let warning = summary.add_step(&report, &mut last);
        assert!(warning[0].contains("energy residual 1e-5 J"), "{warning:?}");
        report.energy.residual = f64::NAN;
        assert_eq!(summary.add_step(&report, &mut last).len(), 1);
        assert_eq!(summary.warnings.len(), 2);
        assert_eq!(summary.warnings_total, 2);
        // A Zeno stopper lock above its tolerance is a warning too.
        report.energy.residual = 0.0;
        report.contact.zeno_impulse = 2.0 * crate::walk::ZENO_IMPULSE_WARNING;
        let warning = summary.add_step(&report, &mut last);
        assert!(
            warning[0].contains("Zeno stopper lock impulse 0.002 N s exceeds 0.001 N s"),
            "{warning:?}"
        );
    }

    /// Every contact audit value above its tolerance is a warning in `summary.json` and for the terminal, as
    /// the energy residual is: a pulling impact after flight once went unsaid.
    #[test]
    fn contact_audit_above_its_tolerance_warns() {
        use crate::walk::{PENETRATION_WARNING, PULL_FORCE_WARNING, STOPPER_OVERRUN_WARNING};
        let config = Config::default();
        let model = Model::new(&config.params).unwrap();
        let run = simulate(&model, &config.solver, &default_initial(&config), 1, None).unwrap();
        let clean = run.steps[0];
        assert!(
            clean.audit_warnings().is_empty(),
            "{:?}",
            clean.audit_warnings()
        );
        type Spoil = fn(&mut StepReport);
        let cases: [(&str, Spoil); 5] = [
            ("pulling force 2e-6 N exceeds 1e-6 N", |r| {
                r.contact.pull_force = 2.0 * PULL_FORCE_WARNING
            }),
            ("pulling impulse 8.5 N s exceeds 1e-9 N s", |r| {
                r.contact.pull_impulse = 8.5
            }),
            ("penetration 2e-9 m exceeds 1e-9 m", |r| {
                r.contact.penetration = 2.0 * PENETRATION_WARNING
            }),
            ("stopper overrun 2e-8 m exceeds 1e-8 m", |r| {
                r.contact.stopper_overrun = 2.0 * STOPPER_OVERRUN_WARNING
            }),
            ("pulling force NaN N", |r| r.contact.pull_force = f64::NAN),
        ];
        let dir = tempfile::tempdir().unwrap();
        for (expected, spoil) in cases {
            let mut report = clean;
            spoil(&mut report);
            let mut summary =
                SimulateSummary::new(&job(dir.path(), 1, false), default_initial(&config));
            let listed = summary.add_step(&report, &mut VecDeque::new());
            assert_eq!(listed.len(), 1, "{expected}: {listed:?}");
            assert!(listed[0].contains(expected), "{expected}: {listed:?}");
            assert_eq!(summary.warnings, listed);
        }
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
