//! The jobs of `vrw animate` and `vrw plot`: read a run directory back and draw it.

use std::path::PathBuf;

use crate::fmt::short;
use crate::output::animate::{write_animation, write_still, AnimateOptions, AnimationReport};
use crate::output::read::{read_run, RunData};
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

/// The most frames `vrw animate` draws: an hour of playback at 25 frames per second. The regular frames
/// number `(to - from) fps / speed + 1` over the window `[from, to]` of simulated time.
pub const MAX_ANIMATION_FRAMES: usize = 90_000;

/// Refuses an animation of more than [`MAX_ANIMATION_FRAMES`] frames, counted before any is planned.
fn check_frame_count(run: &RunData, options: &AnimateOptions) -> Result<(), AppError> {
    let (start, end) = run.time_span();
    let from = options.from.unwrap_or(start).max(start);
    let to = options.to.unwrap_or(end).min(end);
    let frames = ((to - from).max(0.0) * f64::from(options.fps) / options.speed).floor() + 1.0;
    if frames > MAX_ANIMATION_FRAMES as f64 {
        return Err(AppError::InvalidOption {
            option: "speed",
            reason: format!(
                "{} s of simulated time at speed {} and {} frames per second is {} frames, more than \
                 {MAX_ANIMATION_FRAMES}: raise --speed, lower --fps or narrow the window with --from/--to",
                short(to - from),
                short(options.speed),
                options.fps,
                short(frames)
            ),
        });
    }
    Ok(())
}

/// Run `vrw animate`: read the run and write `DIR/walk.gif`.
pub fn run_animate(job: &AnimateJob) -> Result<AnimationReport, AppError> {
    job.options.validate()?;
    let run = read_run(&job.dir)?;
    check_frame_count(&run, &job.options)?;
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
