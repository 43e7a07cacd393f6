//! `vrw plot` and `vrw animate` of a walker's run (`vrw simulate --model NAME`): the run read back as its
//! `summary.json` declares it ([`crate::output::walker_run`]), drawn as the run figure (`run.png`, `run.svg`)
//! or the stick figure's animation (`walk.gif`) and stills (`walk-frame.png`), each added to the manifest. The
//! run is checked as the wheel's is ([`super::checked_run`]): one run of `simulate`, finished, or `partial`.

use std::path::{Path, PathBuf};

use super::AppError;
use crate::output::animate::{
    write_walker_animation, write_walker_still, AnimateOptions, AnimationReport,
};
use crate::output::manifest::{Manifest, RunDir, RunStatus};
use crate::output::walker_plot::write_walker_run_figure;
use crate::output::walker_run::{read_walker_run, WalkerRun};
use crate::output::write_atomic;

/// The walker run in `dir` (of the model `model`), checked: written by `vrw simulate`, finished unless
/// `partial`, its trajectory written.
fn checked_walker_run(
    dir: &Path,
    model: &str,
    partial: bool,
) -> Result<(WalkerRun, RunDir), AppError> {
    let refuse = |reason: String| AppError::NotOneRun {
        dir: dir.to_path_buf(),
        reason,
    };
    let manifest = Manifest::read(dir)?;
    if manifest.command != "simulate" {
        return Err(refuse(format!(
            "it holds the `vrw {}` run of the model `{model}`, which has no walk to draw: the figures of a walker \
             draw its `vrw simulate --model {model}` run (from the gait's section state with `--initial`)",
            manifest.command
        )));
    }
    if !manifest.lists("trajectory.csv") {
        return Err(refuse(
            "the run wrote no trajectory.csv (`--no-trajectory`): run `vrw simulate` again without it".into(),
        ));
    }
    let unfinished = match manifest.status {
        RunStatus::Completed | RunStatus::Interrupted => None,
        RunStatus::Running => Some("the run that wrote it did not finish (killed?)".to_string()),
        RunStatus::Failed => Some(format!(
            "the run that wrote it failed: {}",
            manifest.reason.as_deref().unwrap_or("no reason given")
        )),
    };
    let mut run = read_walker_run(dir)?;
    match unfinished {
        Some(why) if !partial => {
            return Err(refuse(format!(
                "{why}; pass `partial` to draw its complete rows anyway"
            )))
        }
        Some(_) => run.info.status = "partial: the run did not finish".to_string(),
        None => {}
    }
    Ok((run, RunDir::reopen(dir, manifest)))
}

/// What an animation of a walker run wrote: the animation's report (none for a still), the file, and what
/// was left out while reading the run.
pub(super) type WalkerAnimation = (Option<AnimationReport>, PathBuf, Vec<String>);

/// `vrw animate` (or `--still TIME`) of the walker run of the model `model` in `dir` (`partial`: a run that
/// did not finish is drawn).
pub(super) fn animate_walker(
    (dir_path, options, partial): (&Path, &AnimateOptions, bool),
    model: &str,
    still: Option<f64>,
) -> Result<WalkerAnimation, AppError> {
    options.validate()?;
    let (run, mut dir) = checked_walker_run(dir_path, model, partial)?;
    let name = if still.is_some() {
        "walk-frame.png"
    } else {
        "walk.gif"
    };
    let path = dir_path.join(name);
    let report = match still {
        Some(time) => {
            write_atomic(&path, |temp| -> Result<_, AppError> {
                Ok(write_walker_still(&run, options, time, temp)?)
            })?;
            None
        }
        None => {
            let mut report = write_atomic(&path, |temp| -> Result<_, AppError> {
                Ok(write_walker_animation(&run, options, temp)?)
            })?;
            report.path.clone_from(&path);
            Some(report)
        }
    };
    dir.add(name);
    dir.write()?;
    Ok((report, path, run.warnings))
}

/// `vrw plot` of the walker run in `dir`: the files written, and what was left out while reading the run.
pub(super) fn plot_walker(
    dir: &Path,
    model: &str,
    partial: bool,
) -> Result<(Vec<PathBuf>, Vec<String>), AppError> {
    let (run, mut run_dir) = checked_walker_run(dir, model, partial)?;
    let files = write_walker_run_figure(&run)?;
    for f in &files {
        if let Some(name) = f.file_name() {
            run_dir.add(&name.to_string_lossy());
        }
    }
    run_dir.write()?;
    Ok((files, run.warnings))
}
