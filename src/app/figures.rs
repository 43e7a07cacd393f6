//! The jobs of `vrw animate` and `vrw plot`: check that a run directory holds one run of `simulate` or
//! `gait`, read it back and draw it; the figures are added to the run's manifest.
//!
//! **Which directories are drawn.** The directory's `manifest.json` must say that `simulate` or `gait` wrote
//! it, and every data file there (`steps.csv`, `trajectory.csv`, `summary.json`, `gait.json`) must be listed
//! in it. A run that `completed` or was `interrupted` (Ctrl-C: its rows are complete) is drawn. A run still
//! `running` (killed, or not finished yet) or `failed` is refused, unless `partial` is set (`--partial`): then
//! its complete rows are drawn and the figures say "partial".

use std::path::{Path, PathBuf};

use crate::output::animate::{write_animation, write_still, AnimateOptions, AnimationReport};
use crate::output::manifest::{Manifest, RunDir, RunStatus};
use crate::output::read::{read_run, RunData};
use crate::output::walker_run::walker_model_of;
use crate::output::{run_plot, steps_plot, write_atomic};

use super::AppError;

/// The most frames `vrw animate` draws (see [`write_animation`]).
pub use crate::output::animate::MAX_ANIMATION_FRAMES;

/// What `vrw animate` runs.
#[derive(Debug, Clone)]
pub struct AnimateJob {
    /// A directory written by `vrw simulate` or `vrw gait`; `walk.gif` goes there too.
    pub dir: PathBuf,
    /// Frame rate, speed, window and size.
    pub options: AnimateOptions,
    /// Draw the complete rows of a run that did not finish (see the module documentation).
    pub partial: bool,
}

/// The data files a run directory of `simulate` or `gait` may hold.
const DATA_FILES: [&str; 4] = ["steps.csv", "trajectory.csv", "summary.json", "gait.json"];

/// Read the run in `dir` if its files belong to one run of `simulate` or `gait` that may be drawn (see the
/// module documentation), with its run directory to add figures to.
pub fn checked_run(dir: &Path, partial: bool) -> Result<(RunData, RunDir), AppError> {
    if !dir.is_dir() {
        return Err(crate::output::read::ReadError::NotADirectory {
            path: dir.to_path_buf(),
        }
        .into());
    }
    let refuse = |reason: String| AppError::NotOneRun {
        dir: dir.to_path_buf(),
        reason,
    };
    let manifest = Manifest::read(dir)?;
    if !["simulate", "gait"].contains(&manifest.command.as_str()) {
        return Err(refuse(format!(
            "it holds the output of `vrw {}`, not of `vrw simulate` or `vrw gait`",
            manifest.command
        )));
    }
    for f in DATA_FILES {
        if dir.join(f).exists() && !manifest.lists(f) {
            return Err(refuse(format!(
                "{f} does not belong to the run that wrote the directory (it is not in manifest.json); \
                 run `vrw {}` again",
                manifest.command
            )));
        }
    }
    let unfinished = match manifest.status {
        RunStatus::Completed | RunStatus::Interrupted => None,
        RunStatus::Running => Some("the run that wrote it did not finish (killed?)".to_string()),
        RunStatus::Failed => Some(format!(
            "the run that wrote it failed: {}",
            manifest.reason.as_deref().unwrap_or("no reason given")
        )),
    };
    if let Some(why) = &unfinished {
        if !partial {
            return Err(refuse(format!(
                "{why}; pass `partial` to draw its complete rows anyway"
            )));
        }
    }
    if manifest.command == "gait" && !manifest.lists("steps.csv") && manifest.lists("gait.json") {
        return Err(refuse(
            "the gait search that wrote it found no gait (see gait.json): there is no walk to draw"
                .into(),
        ));
    }
    let mut run = read_run(dir)?;
    if unfinished.is_some() {
        run.status = "partial: the run did not finish".to_string();
    }
    Ok((run, RunDir::reopen(dir, manifest)))
}

/// What `vrw animate` did.
#[derive(Debug, Clone)]
pub struct AnimateOutcome {
    /// The animation written.
    pub report: AnimationReport,
    /// What was left out while reading the run (an incomplete last row).
    pub warnings: Vec<String>,
}

/// Run `vrw animate`: read the run and write `DIR/walk.gif`.
pub fn run_animate(job: &AnimateJob) -> Result<AnimateOutcome, AppError> {
    if let Some(model) = walker_model_of(&job.dir) {
        let walker = (job.dir.as_path(), &job.options, job.partial);
        let (report, _, warnings) = super::walker_figures::animate_walker(walker, &model, None)?;
        let report = report.ok_or_else(|| unreachable_still(&job.dir))?;
        return Ok(AnimateOutcome { report, warnings });
    }
    job.options.validate()?;
    let (run, mut dir) = checked_run(&job.dir, job.partial)?;
    let path = job.dir.join("walk.gif");
    let mut report = write_atomic(&path, |temp| -> Result<_, AppError> {
        Ok(write_animation(&run, &job.options, temp)?)
    })?;
    report.path = path;
    dir.add("walk.gif");
    dir.write()?;
    Ok(AnimateOutcome {
        report,
        warnings: run.warnings,
    })
}

/// Run `vrw animate --still TIME`: write the frame at simulated time `time` as `DIR/walk-frame.png`.
pub fn run_still(job: &AnimateJob, time: f64) -> Result<PathBuf, AppError> {
    if let Some(model) = walker_model_of(&job.dir) {
        let walker = (job.dir.as_path(), &job.options, job.partial);
        return Ok(super::walker_figures::animate_walker(walker, &model, Some(time))?.1);
    }
    job.options.validate()?;
    let (run, mut dir) = checked_run(&job.dir, job.partial)?;
    let path = job.dir.join("walk-frame.png");
    write_atomic(&path, |temp| -> Result<_, AppError> {
        Ok(write_still(&run, &job.options, time, temp)?)
    })?;
    dir.add("walk-frame.png");
    dir.write()?;
    Ok(path)
}

/// The error of an animation that wrote a still instead (never: [`super::walker_figures::animate_walker`]
/// returns an outcome whenever it is asked for no still).
fn unreachable_still(dir: &Path) -> AppError {
    AppError::NotOneRun {
        dir: dir.to_path_buf(),
        reason: "no animation was written".to_string(),
    }
}

/// The files `vrw plot` wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotReport {
    /// `run.png`, `run.svg`, `steps.png`, `steps.svg`.
    pub files: Vec<PathBuf>,
    /// What was left out while reading the run (an incomplete last row).
    pub warnings: Vec<String>,
}

/// Run `vrw plot`: read the run and write `DIR/run.{png,svg}` and `DIR/steps.{png,svg}`; `partial` draws a
/// run that did not finish (see the module documentation).
pub fn run_plot(dir: &Path, partial: bool) -> Result<PlotReport, AppError> {
    if let Some(model) = walker_model_of(dir) {
        let (files, warnings) = super::walker_figures::plot_walker(dir, &model, partial)?;
        return Ok(PlotReport { files, warnings });
    }
    let (run, mut run_dir) = checked_run(dir, partial)?;
    let mut files = run_plot::write_run_figure(&run)?;
    files.extend(steps_plot::write_steps_figure(&run)?);
    for f in &files {
        if let Some(name) = f.file_name() {
            run_dir.add(&name.to_string_lossy());
        }
    }
    run_dir.write()?;
    Ok(PlotReport {
        files,
        warnings: run.warnings,
    })
}
