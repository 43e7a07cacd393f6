//! A walker's walk as an animated GIF or a still (`vrw animate` of a `vrw simulate --model NAME` run): the stick
//! figure its `summary.json` declares ([`StickFigure`]), drawn from the points `trajectory.csv` holds: the legs
//! as lines from the hip to the feet (each physical leg in its colour, blue and vermillion, as the wheel's Leg 1
//! and Leg 2: the stance and swing legs exchange roles at every heel strike), the springs (and dampers) of
//! compliant legs as coils, the masses as dots, the feet as small circles over them (green on the ground), the
//! ground along the slope. The camera follows the hip along the slope, as the wheel's does; frames are regular,
//! `speed / fps` of the model's time apart, each interpolated linearly between the two samples around it (the
//! points are continuous through a heel strike), and are encoded as the wheel's are (`encode.rs`: its palette
//! holds every colour used here).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::super::style::{
    font, png_bytes, require_font, save_png, PlotError, COLOR_BLUE, COLOR_GREEN, COLOR_VERMILLION,
};
use super::super::walker_run::WalkerRun;
use super::draw::{GROUND, INK};
use super::plan::FrameTime;
use super::{encode, AnimateError, AnimateOptions, AnimationReport, MAX_ANIMATION_FRAMES};

/// The row in force at `t` (the last at or before it).
fn row_at(run: &WalkerRun, t: f64) -> usize {
    run.rows.partition_point(|r| r[0] <= t).saturating_sub(1)
}

/// The points at `t`, interpolated between the rows around it, and the step then.
fn pose_at(run: &WalkerRun, t: f64) -> (Vec<[f64; 2]>, usize) {
    let k = row_at(run, t);
    let a = run.points_at(k);
    let step = run.step_at(k);
    let Some(next) = run.rows.get(k + 1) else {
        return (a, step);
    };
    let t0 = run.rows[k][0];
    if next[0] <= t0 || t <= t0 {
        return (a, step);
    }
    let w = ((t - t0) / (next[0] - t0)).clamp(0.0, 1.0);
    let b = run.points_at(k + 1);
    let mixed = a
        .iter()
        .zip(&b)
        .map(|(p, q)| [p[0] + w * (q[0] - p[0]), p[1] + w * (q[1] - p[1])])
        .collect();
    (mixed, step)
}

/// Slope frame to pixels: the hip's place along the slope at the frame's centre, the ground near the bottom.
struct View {
    ex: (f64, f64),
    ez: (f64, f64),
    anchor: f64,
    scale: f64,
    size: (f64, f64),
}

impl View {
    fn px(&self, [x, z]: [f64; 2]) -> (i32, i32) {
        let x = x - self.anchor;
        let wx = x * self.ex.0 + z * self.ez.0;
        let wy = x * self.ex.1 + z * self.ez.1;
        (
            (0.5 * self.size.0 + wx * self.scale).round() as i32,
            (0.82 * self.size.1 - wy * self.scale).round() as i32,
        )
    }
}

/// Draws the frame at `t` of `run` on `root`.
fn draw_frame<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    run: &WalkerRun,
    opts: &AnimateOptions,
    (t, height): (f64, f64),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let figure = &run.info.figure;
    let (points, step) = pose_at(run, t);
    let phi = if opts.horizontal { 0.0 } else { run.info.slope };
    let size = (f64::from(opts.width), f64::from(opts.height));
    let hip = figure.masses.first().map_or([0.0, 0.0], |&m| points[m]);
    let view = View {
        ex: (phi.cos(), -phi.sin()),
        ez: (phi.sin(), phi.cos()),
        anchor: hip[0],
        scale: 0.6 * size.1 / height.max(1e-9),
        size,
    };
    let reach = size.0 / view.scale;
    let (left, right) = (
        view.px([hip[0] - reach, 0.0]),
        view.px([hip[0] + reach, 0.0]),
    );
    root.draw(&Polygon::new(
        vec![
            left,
            right,
            (right.0, size.1 as i32 + 10),
            (left.0, size.1 as i32 + 10),
        ],
        GROUND.filled(),
    ))?;
    root.draw(&PathElement::new(vec![left, right], INK.stroke_width(2)))?;
    let colours = [COLOR_BLUE, COLOR_VERMILLION];
    for (k, [a, b]) in figure.links.iter().enumerate() {
        let colour = colours[(k + step) % 2];
        root.draw(&PathElement::new(
            vec![view.px(points[*a]), view.px(points[*b])],
            colour.stroke_width(5),
        ))?;
    }
    for (k, [a, b]) in figure.springs.iter().enumerate() {
        let colour = colours[(k + step) % 2];
        root.draw(&PathElement::new(
            coil(view.px(points[*a]), view.px(points[*b])),
            colour.stroke_width(2),
        ))?;
    }
    for (k, &m) in figure.masses.iter().enumerate() {
        let r = if k == 0 { 11 } else { 7 };
        root.draw(&Circle::new(view.px(points[m]), r, INK.filled()))?;
    }
    // The feet over the masses: a foot that carries mass still shows whether it stands.
    for (k, &f) in figure.feet.iter().enumerate() {
        let fill = if k == 0 { COLOR_GREEN } else { WHITE };
        root.draw(&Circle::new(view.px(points[f]), 5, fill.filled()))?;
        root.draw(&Circle::new(view.px(points[f]), 5, INK.stroke_width(2)))?;
    }
    let text = size.1 / 20.0;
    root.draw(&Text::new(
        format!("{} walker   t = {:.3}   step {step}", run.info.model, t),
        (12, 10),
        font(text),
    ))?;
    root.draw(&Text::new(
        format!(
            "slope {} rad{}; blue and vermillion: the two legs; green foot: stance",
            run.info.slope,
            if opts.horizontal {
                ", drawn horizontal"
            } else {
                ""
            }
        ),
        (12, 10 + (1.4 * text) as i32),
        font(0.75 * text),
    ))?;
    Ok(())
}

/// Zigzag turns of a drawn spring.
const COIL_TURNS: usize = 6;

/// Half the width of a drawn spring \[px\].
const COIL_HALF_WIDTH: f64 = 6.0;

/// A spring (and its damper) from `a` to `b` in pixels, drawn as a zigzag of [`COIL_TURNS`] turns: it
/// tightens as the leg shortens.
fn coil(a: (i32, i32), b: (i32, i32)) -> Vec<(i32, i32)> {
    let (dx, dy) = (f64::from(b.0 - a.0), f64::from(b.1 - a.1));
    let length = dx.hypot(dy).max(1e-9);
    let (nx, ny) = (
        -dy / length * COIL_HALF_WIDTH,
        dx / length * COIL_HALF_WIDTH,
    );
    let corners = 2 * COIL_TURNS;
    let mut path = vec![a];
    for i in 0..corners {
        let along = (i as f64 + 0.5) / corners as f64;
        let side = if i % 2 == 0 { 1.0 } else { -1.0 };
        path.push((
            (f64::from(a.0) + along * dx + side * nx).round() as i32,
            (f64::from(a.1) + along * dy + side * ny).round() as i32,
        ));
    }
    path.push(b);
    path
}

/// The hip's largest height above the ground over the run (the frame's scale).
fn hip_height(run: &WalkerRun) -> f64 {
    let hip = run.info.figure.masses.first().copied().unwrap_or(0);
    (0..run.rows.len())
        .map(|k| run.points_at(k)[hip][1])
        .fold(0.0, f64::max)
}

/// The frames of the window the options give, checked.
fn frames(
    run: &WalkerRun,
    opts: &AnimateOptions,
    path: &Path,
) -> Result<((f64, f64), Vec<FrameTime>), AnimateError> {
    opts.validate()?;
    let (start, end) = run.time_span();
    let (from, to) = (
        opts.from.unwrap_or(start).max(start),
        opts.to.unwrap_or(end).min(end),
    );
    if from >= to {
        return Err(AnimateError::EmptyWindow {
            path: run.dir.join("trajectory.csv"),
            from: opts.from.unwrap_or(start),
            to: opts.to.unwrap_or(end),
            start,
            end,
        });
    }
    let h = opts.speed / f64::from(opts.fps);
    let count = ((to - from) / h * (1.0 + 1e-12)).floor() + 1.0;
    if count > MAX_ANIMATION_FRAMES as f64 {
        return Err(AnimateError::InvalidOption {
            option: "speed",
            reason: format!("{count} frames, more than {MAX_ANIMATION_FRAMES}: raise `speed`, lower `fps` or narrow the window with `from`/`to`"),
        });
    }
    require_font(path)?;
    let frames = (0..count as usize)
        .map(|k| FrameTime {
            time: from + k as f64 * h,
            slow: None,
        })
        .collect();
    Ok(((from, to), frames))
}

/// Writes the animation of the walker run `run` to `path` (see the module documentation).
pub fn write_walker_animation(
    run: &WalkerRun,
    opts: &AnimateOptions,
    path: &Path,
) -> Result<AnimationReport, AnimateError> {
    let planned = frames(run, opts, path)?;
    let file = std::fs::File::create(path).map_err(|e| AnimateError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    encoded(run, opts, planned, std::io::BufWriter::new(file), path)
}

/// Writes the animation of the walker run `run` to `out`: the bytes [`write_walker_animation`] writes to a file
/// (errors and the report name `name`), e.g. into a `Vec<u8>` for a front that shows the GIF without a file.
pub fn write_walker_animation_to(
    run: &WalkerRun,
    opts: &AnimateOptions,
    out: impl std::io::Write,
    name: &Path,
) -> Result<AnimationReport, AnimateError> {
    let planned = frames(run, opts, name)?;
    encoded(run, opts, planned, out, name)
}

/// Draws and encodes the planned frames of `run` into `out`.
fn encoded(
    run: &WalkerRun,
    opts: &AnimateOptions,
    (window, frames): ((f64, f64), Vec<FrameTime>),
    out: impl std::io::Write,
    path: &Path,
) -> Result<AnimationReport, AnimateError> {
    let height = hip_height(run);
    let bytes = encode::write_gif(
        out,
        path,
        (opts.width, opts.height),
        opts.fps,
        &frames,
        |root, frame| {
            let fail = PlotError::draw_at(path);
            draw_frame(root, run, opts, (frame.time, height)).map_err(|e| fail(e.to_string()))?;
            root.present().map_err(|e| fail(e.to_string()))
        },
    )?;
    Ok(AnimationReport {
        path: path.to_path_buf(),
        frames: frames.len(),
        slow_frames: 0,
        window,
        playback: encode::centis(frames.len(), opts.fps) as f64 / 100.0,
        bytes,
    })
}

/// Writes the frame at `time` of the walker run `run` as a PNG at `path`.
pub fn write_walker_still(
    run: &WalkerRun,
    opts: &AnimateOptions,
    time: f64,
    path: &Path,
) -> Result<(), AnimateError> {
    let rgb = walker_still_rgb(run, opts, time, path)?;
    Ok(save_png(path, &rgb, (opts.width, opts.height))?)
}

/// The frame at `time` of the walker run `run` as the bytes of a PNG: the file [`write_walker_still`] writes
/// (errors name `name`).
pub fn walker_still_png(
    run: &WalkerRun,
    opts: &AnimateOptions,
    time: f64,
    name: &Path,
) -> Result<Vec<u8>, AnimateError> {
    let rgb = walker_still_rgb(run, opts, time, name)?;
    Ok(png_bytes(name, &rgb, (opts.width, opts.height))?)
}

/// The RGB bitmap of the frame at `time` of the walker run `run` (errors name `path`, the file being made).
fn walker_still_rgb(
    run: &WalkerRun,
    opts: &AnimateOptions,
    time: f64,
    path: &Path,
) -> Result<Vec<u8>, AnimateError> {
    let walk = (time, run.time_span(), run.dir.join("trajectory.csv"));
    super::frame_rgb(opts, walk, path, |root| {
        let fail = PlotError::draw_at(path);
        draw_frame(root, run, opts, (time, hip_height(run))).map_err(|e| fail(e.to_string()))?;
        Ok(root.present().map_err(|e| fail(e.to_string()))?)
    })
}
