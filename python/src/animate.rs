//! `vrw._vrw.animate`: the animation of `vrw animate` (or its still frame) of a walk computed in memory, as
//! bytes, without files.
//!
//! The walk is `simulate`'s (the same [`SimulateJob`], so the same steps and samples), read back with
//! [`run_from_walk`] as `vrw animate` reads the run directory `vrw simulate` writes for it, and drawn with
//! [`write_animation_to`] (or [`still_png`]), the code behind `walk.gif` (`walk-frame.png`): the bytes are
//! those of the file. The options are checked as the command line checks them, with its messages, before the
//! walk.

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use pyo3::types::PyBytes;

use vrw::app::{
    compute_simulation, compute_walker_simulate, AppError, SimulateJob, WalkerSimulateJob,
};
use vrw::output::animate::{
    still_png, walker_still_png, write_animation_to, write_walker_animation_to, AnimateError,
    AnimateOptions,
};
use vrw::output::read::run_from_walk;
use vrw::output::walker_run::walker_run_from_walk;

use super::{
    app_error, config_error, count, interruptible, real, sample_dt_arg, section, steps_arg,
    LibConfigError, Params,
};

/// Walk `steps` steps from `initial` as `simulate` does (with its trajectory sampled every `sample_dt`) and
/// draw the walk as `vrw animate` does: the bytes of the GIF `walk.gif` it writes for the run directory
/// `vrw simulate` writes, or with `still` (a time \[s\]) the PNG `walk-frame.png` of `vrw animate --still`.
///
/// The options are the command line's (`from_` is `--from`), with its defaults, ranges and messages: an
/// option out of range, more than `MAX_ANIMATION_FRAMES` frames or a time window outside the walk raises
/// `vrw.ConfigError` (before the walk, where the options alone tell). The GIL is released while the walk is
/// computed and drawn; Ctrl-C raises `KeyboardInterrupt` (the walk stops at once, the drawing between two
/// chunks of frames). Another walker's (`Params(model=...)`): its walk of `vrw simulate --model` (`initial` its
/// section's coordinates) drawn as `vrw animate` draws that run's directory: its stick figure.
#[pyfunction]
#[pyo3(signature = (params, steps = 20, initial = None, sample_dt = 0.005, *, fps = 25, speed = 1.0, from_ = None, to = None, width = 640, height = 360, horizontal = false, still = None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn animate<'py>(
    py: Python<'py>,
    params: &Params,
    #[pyo3(from_py_with = steps_arg)] steps: usize,
    initial: Option<Vec<f64>>,
    #[pyo3(from_py_with = sample_dt_arg)] sample_dt: f64,
    #[pyo3(from_py_with = fps_arg)] fps: u32,
    #[pyo3(from_py_with = speed_arg)] speed: f64,
    from_: Option<f64>,
    to: Option<f64>,
    #[pyo3(from_py_with = width_arg)] width: u32,
    #[pyo3(from_py_with = height_arg)] height: u32,
    horizontal: bool,
    still: Option<f64>,
) -> PyResult<Bound<'py, PyBytes>> {
    let options = AnimateOptions {
        fps,
        speed,
        from: from_,
        to,
        width,
        height,
        horizontal,
    };
    options
        .validate()
        .map_err(|e| animate_error(AppError::Animate(e)))?;
    // The library's flag: the walk and the encoding of the frames both read it.
    let flag = vrw::gait::interrupt_flag();
    if let Some(w) = params.walker() {
        let job = WalkerSimulateJob {
            walker: w.walker.clone(),
            initial,
            steps,
            sample_dt,
            trajectory: true,
            out_dir: PathBuf::new(),
            overwrite: false,
        };
        let bytes = interruptible(py, flag, || draw_walker(&job, &options, still))?
            .map_err(animate_error)?;
        return Ok(PyBytes::new(py, &bytes));
    }
    let job = SimulateJob {
        config: params.wheel("animate")?.clone(),
        initial: section(initial)?,
        steps,
        sample_dt,
        trajectory: true,
        out_dir: PathBuf::new(),
        overwrite: false,
        interrupt: None,
    };
    let bytes = interruptible(py, flag, || draw(&job, &options, still))?.map_err(animate_error)?;
    Ok(PyBytes::new(py, &bytes))
}

/// The walk of `job`, drawn: the GIF, or the PNG of the frame at `still`.
fn draw(
    job: &SimulateJob,
    options: &AnimateOptions,
    still: Option<f64>,
) -> Result<Vec<u8>, AppError> {
    let (summary, trajectory) = compute_simulation(job, true)?;
    let samples = trajectory.map(|t| t.samples).unwrap_or_default();
    let run = run_from_walk(
        &job.config,
        &summary.status.to_string(),
        &summary.steps,
        &samples,
    )?;
    Ok(match still {
        Some(time) => still_png(&run, options, time, Path::new("walk-frame.png"))?,
        None => {
            let mut gif = Vec::new();
            write_animation_to(&run, options, &mut gif, Path::new("walk.gif"))?;
            gif
        }
    })
}

/// The walk of a walker's `job` (`vrw simulate --model`'s), drawn as `vrw animate` draws its directory: the GIF,
/// or the PNG of the frame at `still`.
fn draw_walker(
    job: &WalkerSimulateJob,
    options: &AnimateOptions,
    still: Option<f64>,
) -> Result<Vec<u8>, AppError> {
    let out = compute_walker_simulate(job)?;
    let trajectory = out
        .tables
        .iter()
        .find(|(name, _)| *name == "trajectory.csv")
        .map_or(&[] as &[Vec<String>], |(_, rows)| rows);
    let run = walker_run_from_walk(&out.summary, trajectory)?;
    Ok(match still {
        Some(time) => walker_still_png(&run, options, time, Path::new("walk-frame.png"))?,
        None => {
            let mut gif = Vec::new();
            write_walker_animation_to(&run, options, &mut gif, Path::new("walk.gif"))?;
            gif
        }
    })
}

/// A bad option (a value out of range, too many frames, a window outside the walk) is a `vrw.ConfigError`;
/// everything else as the other jobs map it.
fn animate_error(e: AppError) -> PyErr {
    match e {
        AppError::Animate(
            e @ (AnimateError::InvalidOption { .. } | AnimateError::EmptyWindow { .. }),
        ) => super::ConfigError::new_err(e.to_string()),
        e => app_error(e),
    }
}

/// A frame rate or a size \[px\]: a non-negative integer of at most 32 bits (named in its errors; its range
/// is checked with the other options).
fn option_u32(name: &str, value: &Bound<'_, PyAny>) -> PyResult<u32> {
    let n = count(name, value)?;
    u32::try_from(n).map_err(|_| {
        config_error(LibConfigError::InvalidValue {
            key: name.to_string(),
            value: n.to_string(),
            reason: "is out of range".to_string(),
        })
    })
}

/// `animate`'s `fps`, named in its errors.
fn fps_arg(value: &Bound<'_, PyAny>) -> PyResult<u32> {
    option_u32("fps", value)
}

/// `animate`'s `width`, named in its errors.
fn width_arg(value: &Bound<'_, PyAny>) -> PyResult<u32> {
    option_u32("width", value)
}

/// `animate`'s `height`, named in its errors.
fn height_arg(value: &Bound<'_, PyAny>) -> PyResult<u32> {
    option_u32("height", value)
}

/// `animate`'s `speed`, named in its errors.
fn speed_arg(value: &Bound<'_, PyAny>) -> PyResult<f64> {
    real("speed", value)
}
