//! The walk as an animated GIF (`vrw animate`): the wheel on its slope, frame by frame, from a recorded
//! trajectory.
//!
//! **What a frame shows.** The slope and its ground line; the hub; every leg at its current length
//! (docs/model.md section 1: leg `j` points along `e(psi_j) = (-sin psi_j, -cos psi_j)`, `psi_j = theta + j
//! alpha`, from the hub at `(x + L1 sin theta, z + L1 cos theta)`). Leg 1 (blue) and Leg 2 (vermillion)
//! are drawn as telescopic legs: a housing on the hub, a rod carrying the leg mass (the dot at `a` from the
//! tip), and between them the spring (a zigzag with a fixed number of coils, so compression shows as
//! denser coils) beside a dashpot. The other legs are locked at `L0` and drawn as rigid spokes. Each tip is
//! coloured by its contact state (green: on the ground without slipping; orange: sliding; white: in the
//! air), and the stopper of Leg 1 or Leg 2 is drawn as a red bar at the top of its rod while it holds the
//! leg. The header gives the time, the step number and the phase.
//!
//! **Camera.** It follows the hub along the slope: the point of the slope below the hub stays at a fixed
//! place of the frame, so the ground line does not move and its hatching runs past. The slope is drawn
//! inclined by `phi`, as in the paper's Fig. 1, or horizontal with [`AnimateOptions::horizontal`].
//!
//! **Frame times.** Frame `k` shows simulated time `from + k * speed / fps`, interpolated linearly between
//! the two recorded samples around it (positions are continuous through every event; the re-indexing at a
//! touchdown is undone by drawing physical legs). Contact flags come from the last sample at or before the
//! frame time, so a frame never shows a phase that has not started. The trajectory holds a sample right
//! after every event, so every phase (every interval between changes of contacts, slides or stoppers) is
//! known exactly; a phase that no regular frame falls into (say a slide of 0.03 s at 25 frames/s) gets
//! `SLOW_FRAMES` extra frames spread over it, starting at its first instant, and those frames say "slow
//! motion" with the phase's real duration.
//!
//! **Encoding.** Frames are drawn with plotters into an RGB buffer and mapped to a fixed palette (the few
//! colours of the drawing and their blends with white, for the anti-aliased edges) through a 15-bit lookup
//! table, which is much faster than quantizing each frame. Each frame stores only the rectangle that
//! changed, with unchanged pixels transparent, which keeps the GIF small.

mod draw;
mod encode;
mod plan;
mod pose;
mod stick;

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use super::read::RunData;
use super::style::{png_bytes, require_font, save_png, PlotError};
use draw::Renderer;
pub use plan::{plan_frames, FrameTime, SlowMotion, MAX_ANIMATION_FRAMES};
pub use stick::{
    walker_still_png, write_walker_animation, write_walker_animation_to, write_walker_still,
};

/// Largest frame rate: GIF delays are whole hundredths of a second and viewers slow down delays below
/// 0.02 s, so faster frame rates would not play at their speed.
pub(crate) const MAX_FPS: u32 = 50;
/// Smallest and largest frame side \[px\].
pub(crate) const FRAME_SIDE: std::ops::RangeInclusive<u32> = 160..=4000;

/// What `vrw animate` draws.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimateOptions {
    /// Frames per second of playback. Default 25; at most `MAX_FPS`.
    pub fps: u32,
    /// Playback speed: simulated seconds per second of playback. Default 1.
    pub speed: f64,
    /// Start of the time window \[s\] (`None`: the first sample).
    pub from: Option<f64>,
    /// End of the time window \[s\] (`None`: the last sample).
    pub to: Option<f64>,
    /// Frame width \[px\]. Default 640.
    pub width: u32,
    /// Frame height \[px\]. Default 360.
    pub height: u32,
    /// Draw the slope horizontal instead of inclined by `phi`.
    pub horizontal: bool,
}

impl Default for AnimateOptions {
    fn default() -> Self {
        AnimateOptions {
            fps: 25,
            speed: 1.0,
            from: None,
            to: None,
            width: 640,
            height: 360,
            horizontal: false,
        }
    }
}

/// The animation could not be made.
#[derive(Debug, thiserror::Error)]
pub enum AnimateError {
    /// An option is out of range.
    #[error("invalid `{option}`: {reason}")]
    InvalidOption {
        /// The option, by its field (`fps`, ...; the command line shows its flag).
        option: &'static str,
        /// Why.
        reason: String,
    },
    /// The time window holds no part of the trajectory.
    #[error(
        "the time window [{from}, {to}] s lies outside {path}, which spans [{start}, {end}] s"
    )]
    EmptyWindow {
        /// The trajectory file.
        path: PathBuf,
        /// Start of the window \[s\].
        from: f64,
        /// End of the window \[s\].
        to: f64,
        /// First sample time \[s\].
        start: f64,
        /// Last sample time \[s\].
        end: f64,
    },
    /// A frame could not be drawn.
    #[error(transparent)]
    Draw(#[from] PlotError),
    /// The GIF could not be written.
    #[error("cannot write {path}: {message}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// The library's interrupt flag (Ctrl-C) stopped the encoding after `frames` frames; nothing is written.
    #[error("interrupted (Ctrl-C) after {frames} of {total} frames: no animation is written")]
    Interrupted {
        /// Frames encoded.
        frames: usize,
        /// Frames planned.
        total: usize,
    },
}

impl AnimateOptions {
    /// Check every option; the error names the option (by its field, which the command line shows as its flag)
    /// and the value.
    pub fn validate(&self) -> Result<(), AnimateError> {
        let bad = |option, reason: String| Err(AnimateError::InvalidOption { option, reason });
        if !(1..=MAX_FPS).contains(&self.fps) {
            return bad(
                "fps",
                format!(
                    "{} frames per second is not between 1 and {MAX_FPS}",
                    self.fps
                ),
            );
        }
        if !(self.speed.is_finite() && self.speed > 0.0) {
            return bad(
                "speed",
                format!("{} is not a positive playback factor", self.speed),
            );
        }
        for (option, v) in [("from", self.from), ("to", self.to)] {
            if let Some(v) = v.filter(|v| !v.is_finite()) {
                return bad(option, format!("{v} is not a time"));
            }
        }
        if let (Some(from), Some(to)) = (self.from, self.to) {
            if from >= to {
                return bad(
                    "from/to",
                    format!("`from` {from} s is not before `to` {to} s"),
                );
            }
        }
        for (option, v) in [("width", self.width), ("height", self.height)] {
            if !FRAME_SIDE.contains(&v) {
                return bad(
                    option,
                    format!(
                        "{v} px is not between {} and {} px",
                        FRAME_SIDE.start(),
                        FRAME_SIDE.end()
                    ),
                );
            }
        }
        Ok(())
    }
}

/// What was written.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimationReport {
    /// The GIF.
    pub path: PathBuf,
    /// Number of frames.
    pub frames: usize,
    /// Frames added to show short phases in slow motion.
    pub slow_frames: usize,
    /// Simulated time window shown \[s\].
    pub window: (f64, f64),
    /// Playback duration \[s\].
    pub playback: f64,
    /// Size of the file \[bytes\].
    pub bytes: u64,
}

/// Writes the animation of `run` to `path` (see the module doc).
///
/// # Errors
/// [`AnimateError::InvalidOption`] for an option out of range or more than [`MAX_ANIMATION_FRAMES`] frames,
/// [`AnimateError::EmptyWindow`] when the time window misses the trajectory, [`AnimateError::Draw`] /
/// [`AnimateError::Write`] when a frame cannot be drawn or the file written.
pub fn write_animation(
    run: &RunData,
    opts: &AnimateOptions,
    path: &Path,
) -> Result<AnimationReport, AnimateError> {
    let (window, frames) = planned(run, opts, path)?;
    let file = File::create(path).map_err(|e| AnimateError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    encoded(run, opts, (window, &frames), BufWriter::new(file), path)
}

/// Writes the animation of `run` to `out`: the bytes [`write_animation`] writes to a file (errors and the
/// report name `name`), e.g. into a `Vec<u8>` for a front that shows the GIF without a file.
///
/// # Errors
/// As [`write_animation`].
pub fn write_animation_to(
    run: &RunData,
    opts: &AnimateOptions,
    out: impl Write,
    name: &Path,
) -> Result<AnimationReport, AnimateError> {
    let (window, frames) = planned(run, opts, name)?;
    encoded(run, opts, (window, &frames), out, name)
}

/// The checked options' window and frames (errors name `path`, the file being made).
fn planned(
    run: &RunData,
    opts: &AnimateOptions,
    path: &Path,
) -> Result<((f64, f64), Vec<FrameTime>), AnimateError> {
    opts.validate()?;
    plan::check_frame_count(run, opts)?;
    let window = plan::window(run, opts)?;
    require_font(path)?;
    Ok((
        window,
        plan_frames(&run.samples, window, opts.fps, opts.speed),
    ))
}

/// Draws and encodes the planned `frames` of `run` into `out`.
fn encoded(
    run: &RunData,
    opts: &AnimateOptions,
    (window, frames): ((f64, f64), &[FrameTime]),
    out: impl Write,
    path: &Path,
) -> Result<AnimationReport, AnimateError> {
    let renderer = Renderer::new(run, opts);
    let bytes = encode::write_gif(
        out,
        path,
        (opts.width, opts.height),
        opts.fps,
        frames,
        |root, frame| renderer.draw(root, frame, path),
    )?;
    Ok(AnimationReport {
        path: path.to_path_buf(),
        frames: frames.len(),
        slow_frames: frames.iter().filter(|f| f.slow.is_some()).count(),
        window,
        playback: encode::centis(frames.len(), opts.fps) as f64 / 100.0,
        bytes,
    })
}

/// Writes one frame of the animation, at simulated time `time`, as a PNG (for documents and for checking a
/// picture without a GIF viewer).
///
/// # Errors
/// As [`write_animation`]; a `time` outside the trajectory is an [`AnimateError::EmptyWindow`].
pub(crate) fn write_still(
    run: &RunData,
    opts: &AnimateOptions,
    time: f64,
    path: &Path,
) -> Result<(), AnimateError> {
    let rgb = still_rgb(run, opts, time, path)?;
    Ok(save_png(path, &rgb, (opts.width, opts.height))?)
}

/// One frame of the animation, at simulated time `time`, as the bytes of a PNG: the file `vrw animate --still`
/// writes (errors name `name`).
///
/// # Errors
/// As [`write_animation`]; a `time` outside the trajectory is an [`AnimateError::EmptyWindow`].
pub fn still_png(
    run: &RunData,
    opts: &AnimateOptions,
    time: f64,
    name: &Path,
) -> Result<Vec<u8>, AnimateError> {
    let rgb = still_rgb(run, opts, time, name)?;
    Ok(png_bytes(name, &rgb, (opts.width, opts.height))?)
}

/// The RGB bitmap of the frame at `time` (errors name `path`, the file being made).
fn still_rgb(
    run: &RunData,
    opts: &AnimateOptions,
    time: f64,
    path: &Path,
) -> Result<Vec<u8>, AnimateError> {
    let walk = (time, run.time_span(), run.path("trajectory.csv"));
    frame_rgb(opts, walk, path, |root| {
        let frame = FrameTime { time, slow: None };
        Ok(Renderer::new(run, opts).draw(root, &frame, path)?)
    })
}

/// The RGB bitmap of one frame, at `time` of a walk spanning `span` whose samples are `trajectory`, drawn by
/// `draw` once the options and the time are checked: the wheel's stills and the walkers' (errors name `path`,
/// the file being made; a time outside the walk names `trajectory`).
pub(super) fn frame_rgb(
    opts: &AnimateOptions,
    (time, (start, end), trajectory): (f64, (f64, f64), PathBuf),
    path: &Path,
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), AnimateError>,
) -> Result<Vec<u8>, AnimateError> {
    opts.validate()?;
    if !(start..=end).contains(&time) {
        return Err(AnimateError::EmptyWindow {
            path: trajectory,
            from: time,
            to: time,
            start,
            end,
        });
    }
    require_font(path)?;
    let size = (opts.width, opts.height);
    let mut rgb = vec![0u8; 3 * size.0 as usize * size.1 as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        draw(&root)?;
    }
    Ok(rgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_options_are_named() {
        let bad = |o: AnimateOptions, needle: &str| {
            let e = o.validate().unwrap_err().to_string();
            assert!(e.contains(needle), "{e}");
        };
        let d = AnimateOptions::default;
        bad(AnimateOptions { fps: 0, ..d() }, "`fps`");
        bad(AnimateOptions { fps: 60, ..d() }, "fps");
        bad(AnimateOptions { speed: 0.0, ..d() }, "speed");
        bad(
            AnimateOptions {
                from: Some(3.0),
                to: Some(1.0),
                ..d()
            },
            "`to`",
        );
        bad(AnimateOptions { height: 5, ..d() }, "`height`");
        assert!(d().validate().is_ok());
    }

    /// The GIF written to a writer is the file's, and the report counts its bytes.
    #[test]
    fn gif_in_memory_is_the_file() {
        let config = crate::params::Config::default();
        let job = crate::app::SimulateJob {
            config: config.clone(),
            initial: None,
            steps: 1,
            sample_dt: 0.01,
            trajectory: true,
            out_dir: PathBuf::new(),
            overwrite: false,
            interrupt: None,
        };
        let (summary, trajectory) = crate::app::compute_simulation(&job, true).unwrap();
        let samples = trajectory.unwrap().samples;
        let run = super::super::read::run_from_walk(
            &config,
            &summary.status.to_string(),
            &summary.steps,
            &samples,
        )
        .unwrap();
        let opts = AnimateOptions {
            fps: 5,
            width: 160,
            height: 160,
            ..AnimateOptions::default()
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("walk.gif");
        let file = write_animation(&run, &opts, &path).unwrap();
        let mut bytes = Vec::new();
        let memory = write_animation_to(&run, &opts, &mut bytes, &path).unwrap();
        assert_eq!(bytes, std::fs::read(&path).unwrap());
        assert_eq!(memory, file);
        assert_eq!(memory.bytes, bytes.len() as u64);
        let png = still_png(&run, &opts, 0.5, &path).unwrap();
        write_still(&run, &opts, 0.5, &path).unwrap();
        assert_eq!(png, std::fs::read(&path).unwrap());
    }
}
