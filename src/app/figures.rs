//! The jobs of `vrw animate` and `vrw plot`: read a run directory back and draw it.

use std::path::PathBuf;

use crate::output::animate::{write_animation, write_still, AnimateOptions, AnimationReport};
use crate::output::read::read_run;
use crate::output::{run_plot, steps_plot};

use super::AppError;

/// What `vrw animate` runs.
#[derive(Debug, Clone)]
pub struct AnimateJob {
    /// A directory written by `vrw simulate` or `vrw gait`; `walk.gif` goes there too.
    pub dir: PathBuf,
    /// Frame rate, speed, window and size.
    pub options: AnimateOptions,
}

/// Run `vrw animate`: read the run and write `DIR/walk.gif`.
pub fn run_animate(job: &AnimateJob) -> Result<AnimationReport, AppError> {
    job.options.validate()?;
    let run = read_run(&job.dir)?;
    Ok(write_animation(
        &run,
        &job.options,
        &job.dir.join("walk.gif"),
    )?)
}

/// Run `vrw animate --still TIME`: write the frame at simulated time `time` as `DIR/walk-frame.png`.
pub fn run_still(job: &AnimateJob, time: f64) -> Result<PathBuf, AppError> {
    job.options.validate()?;
    let run = read_run(&job.dir)?;
    let path = job.dir.join("walk-frame.png");
    write_still(&run, &job.options, time, &path)?;
    Ok(path)
}

/// The files `vrw plot` wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotReport {
    /// `run.png`, `run.svg`, `steps.png`, `steps.svg`.
    pub files: Vec<PathBuf>,
}

/// Run `vrw plot`: read the run and write `DIR/run.{png,svg}` and `DIR/steps.{png,svg}`.
pub fn run_plot(dir: &std::path::Path) -> Result<PlotReport, AppError> {
    let run = read_run(dir)?;
    let mut files = run_plot::write_run_figure(&run)?;
    files.extend(steps_plot::write_steps_figure(&run)?);
    Ok(PlotReport { files })
}
