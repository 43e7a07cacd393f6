//! The walk as an animated GIF (`vrw animate`): the wheel on its slope, frame by frame, from a recorded
//! trajectory.
//!
//! **What a frame shows.** The slope and its ground line; the hub; every leg at its current length
//! (MODEL.md section 1: leg `j` points along `e(psi_j) = (-sin psi_j, -cos psi_j)`, `psi_j = theta + j
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
//! [`SLOW_FRAMES`] extra frames spread over it, starting at its first instant, and those frames say "slow
//! motion" with the phase's real duration.
//!
//! **Encoding.** Frames are drawn with plotters into an RGB buffer and mapped to a fixed palette (the few
//! colours of the drawing and their blends with white, for the anti-aliased edges) through a 15-bit lookup
//! table, which is much faster than quantizing each frame. Each frame stores only the rectangle that
//! changed, with unchanged pixels transparent, which keeps the GIF small.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use rayon::prelude::*;

use super::read::{Geometry, RunData, TipState, TrajectoryRow};
use super::style::{
    font, require_font, PlotError, COLOR_BLUE, COLOR_GREEN, COLOR_ORANGE, COLOR_VERMILLION,
};

/// Extra frames given to a phase that no regular frame falls into.
pub const SLOW_FRAMES: usize = 3;
/// Largest frame rate: GIF delays are whole hundredths of a second and viewers slow down delays below
/// 0.02 s, so faster frame rates would not play at their speed.
pub const MAX_FPS: u32 = 50;
/// Frames drawn in parallel before they are written.
const RENDER_CHUNK: usize = 64;
/// Smallest and largest frame side \[px\].
pub const FRAME_SIDE: std::ops::RangeInclusive<u32> = 160..=4000;

/// What `vrw animate` draws.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimateOptions {
    /// Frames per second of playback. Default 25; at most [`MAX_FPS`].
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
    #[error("invalid {option}: {reason}")]
    InvalidOption {
        /// The option (`--fps`, ...).
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
}

impl AnimateOptions {
    /// Check every option; the error names the option and the value.
    pub fn validate(&self) -> Result<(), AnimateError> {
        let bad = |option, reason: String| Err(AnimateError::InvalidOption { option, reason });
        if !(1..=MAX_FPS).contains(&self.fps) {
            return bad(
                "--fps",
                format!(
                    "{} frames per second is not between 1 and {MAX_FPS}",
                    self.fps
                ),
            );
        }
        if !(self.speed.is_finite() && self.speed > 0.0) {
            return bad(
                "--speed",
                format!("{} is not a positive playback factor", self.speed),
            );
        }
        for (option, v) in [("--from", self.from), ("--to", self.to)] {
            if let Some(v) = v.filter(|v| !v.is_finite()) {
                return bad(option, format!("{v} is not a time"));
            }
        }
        if let (Some(from), Some(to)) = (self.from, self.to) {
            if from >= to {
                return bad(
                    "--from",
                    format!("--from {from} s is not before --to {to} s"),
                );
            }
        }
        for (option, v) in [("--width", self.width), ("--height", self.height)] {
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

/// A short phase shown in slow motion.
#[derive(Debug, Clone, PartialEq)]
pub struct SlowMotion {
    /// The phase, in words.
    pub phase: String,
    /// Its real duration \[s\].
    pub duration: f64,
    /// Frames it is shown in.
    pub frames: usize,
}

/// One planned frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameTime {
    /// Simulated time shown \[s\].
    pub time: f64,
    /// Set on frames added to show a short phase.
    pub slow: Option<SlowMotion>,
}

/// The simulated window `[from, to]` of the animation, clipped to the samples.
fn window(run: &RunData, opts: &AnimateOptions) -> Result<(f64, f64), AnimateError> {
    let (start, end) = run.time_span();
    let from = opts.from.unwrap_or(start).max(start);
    let to = opts.to.unwrap_or(end).min(end);
    if from > to || (from == to && start < end) {
        return Err(AnimateError::EmptyWindow {
            path: run.path("trajectory.csv"),
            from: opts.from.unwrap_or(start),
            to: opts.to.unwrap_or(end),
            start,
            end,
        });
    }
    Ok((from, to))
}

/// The frame times: regular frames every `speed / fps` of simulated time over `[from, to]`, plus
/// [`SLOW_FRAMES`] frames over every phase that no regular frame falls into (see the module doc).
pub fn plan_frames(
    samples: &[TrajectoryRow],
    (from, to): (f64, f64),
    fps: u32,
    speed: f64,
) -> Vec<FrameTime> {
    let h = speed / f64::from(fps);
    let count = ((to - from) / h * (1.0 + 1e-12)).floor() as usize + 1;
    let regular: Vec<f64> = (0..count).map(|k| from + k as f64 * h).collect();
    let mut frames: Vec<FrameTime> = regular
        .iter()
        .map(|&time| FrameTime { time, slow: None })
        .collect();
    // Phases: maximal runs of samples with the same discrete mode, each ending where the next begins.
    let first = samples
        .partition_point(|s| s.time <= from)
        .saturating_sub(1);
    let mut k = first;
    while k < samples.len() && samples[k].time <= to {
        let mode = samples[k].mode();
        let mut e = k + 1;
        while e < samples.len() && samples[e].mode() == mode {
            e += 1;
        }
        let a = samples[k].time.max(from);
        let b = samples.get(e).map_or(to, |s| s.time.min(to));
        let covered = regular
            .iter()
            .any(|&t| a <= t && (t < b || (t == b && b == to)));
        if !covered {
            let n = if b > a { SLOW_FRAMES } else { 1 };
            let slow = SlowMotion {
                phase: samples[k].phase_name(),
                duration: b - a,
                frames: n,
            };
            frames.extend((0..n).map(|m| FrameTime {
                time: a + (b - a) * m as f64 / n as f64,
                slow: Some(slow.clone()),
            }));
        }
        k = e;
    }
    frames.sort_by(|x, y| x.time.total_cmp(&y.time));
    frames
}

/// The wheel at one instant, by physical leg (so that re-indexing at a touchdown does not break the
/// interpolation between samples).
#[derive(Debug, Clone)]
struct Pose {
    /// Hub position in the slope frame \[m\].
    hub: (f64, f64),
    /// Angle `psi` of physical leg 0, unwrapped over the run \[rad\].
    psi0: f64,
    /// Length of each physical leg \[m\].
    lengths: Vec<f64>,
}

/// Per-sample data prepared once: the pose, and the unwrapped leg angle.
struct Track<'a> {
    samples: &'a [TrajectoryRow],
    geometry: Geometry,
    psi0: Vec<f64>,
}

impl<'a> Track<'a> {
    fn new(samples: &'a [TrajectoryRow], geometry: Geometry) -> Track<'a> {
        let alpha = geometry.alpha();
        let mut psi0 = Vec::with_capacity(samples.len());
        let mut prev: Option<f64> = None;
        for s in samples {
            // psi of physical leg p is theta + (p - leg1) alpha.
            let mut v = s.theta - s.leg1 as f64 * alpha;
            if let Some(p) = prev {
                v += std::f64::consts::TAU * ((p - v) / std::f64::consts::TAU).round();
            }
            psi0.push(v);
            prev = Some(v);
        }
        Track {
            samples,
            geometry,
            psi0,
        }
    }

    fn pose_of(&self, k: usize) -> Pose {
        let s = &self.samples[k];
        let n = self.geometry.legs;
        let mut lengths = vec![self.geometry.stopper_length; n];
        lengths[s.leg1 % n] = s.l1;
        lengths[(s.leg1 + 1) % n] = s.l2;
        Pose {
            hub: (s.x + s.l1 * s.theta.sin(), s.z + s.l1 * s.theta.cos()),
            psi0: self.psi0[k],
            lengths,
        }
    }

    /// Index of the sample in force at `t` (the last at or before it; the first if `t` precedes all).
    fn index_at(&self, t: f64) -> usize {
        self.samples
            .partition_point(|s| s.time <= t)
            .saturating_sub(1)
    }

    /// The pose at `t`, interpolated linearly between the samples around it.
    fn pose_at(&self, t: f64) -> Pose {
        let k = self.index_at(t);
        let a = self.pose_of(k);
        let Some(next) = self.samples.get(k + 1) else {
            return a;
        };
        let t0 = self.samples[k].time;
        if next.time <= t0 || t <= t0 {
            return a;
        }
        let w = ((t - t0) / (next.time - t0)).clamp(0.0, 1.0);
        let b = self.pose_of(k + 1);
        let mix = |u: f64, v: f64| u + w * (v - u);
        Pose {
            hub: (mix(a.hub.0, b.hub.0), mix(a.hub.1, b.hub.1)),
            psi0: mix(a.psi0, b.psi0),
            lengths: a
                .lengths
                .iter()
                .zip(&b.lengths)
                .map(|(&u, &v)| mix(u, v))
                .collect(),
        }
    }
}

// Colours of the drawing (every one is in the palette, with its blends towards white).
const INK: RGBColor = RGBColor(30, 30, 30);
const SPOKE: RGBColor = RGBColor(110, 110, 110);
const GROUND: RGBColor = RGBColor(200, 190, 170);
const HATCH: RGBColor = RGBColor(120, 105, 80);
const STOPPER: RGBColor = RGBColor(200, 0, 0);
const SLOW: RGBColor = RGBColor(180, 0, 120);
const PALETTE_BASE: [RGBColor; 11] = [
    INK,
    SPOKE,
    GROUND,
    HATCH,
    STOPPER,
    SLOW,
    COLOR_BLUE,
    COLOR_VERMILLION,
    COLOR_GREEN,
    COLOR_ORANGE,
    RGBColor(0, 0, 0),
];

/// Spacing of the ground hatching, as a fraction of `L0` (each hatch stroke that runs past costs GIF bytes).
const HATCH_SPACING: f64 = 0.2;

/// Leg drawing proportions, as fractions of `L0`.
const HOUSING: f64 = 0.15;
const ROD: f64 = 0.30;
const COILS: usize = 7;
const COIL_HALF_WIDTH: f64 = 0.035;
const DASHPOT_OFFSET: f64 = 0.075;
const DASHPOT_HALF_WIDTH: f64 = 0.022;
const DASHPOT_CUP: f64 = 0.05;

/// Maps slope-frame points to pixels for one frame.
struct View {
    /// Unit vectors of the slope's x and z axes in the world (y up).
    ex: (f64, f64),
    ez: (f64, f64),
    /// World point at the frame's anchor.
    anchor_world: (f64, f64),
    /// Pixel of the anchor.
    anchor_px: (f64, f64),
    /// Pixels per metre.
    scale: f64,
}

impl View {
    fn new(geometry: &Geometry, opts: &AnimateOptions, hub_x: f64) -> View {
        let phi = if opts.horizontal { 0.0 } else { geometry.slope };
        let ex = (phi.cos(), -phi.sin());
        let ez = (phi.sin(), phi.cos());
        let (w, h) = (f64::from(opts.width), f64::from(opts.height));
        let l0 = geometry.stopper_length;
        let header = HEADER_PX as f64 * h / 360.0;
        let scale = ((h - header) / (2.2 * l0)).min(w / (3.0 * l0));
        let anchor_world = (hub_x * ex.0, hub_x * ex.1);
        View {
            ex,
            ez,
            anchor_world,
            anchor_px: (w / 2.0, h - 0.25 * l0 * scale),
            scale,
        }
    }

    fn px(&self, (x, z): (f64, f64)) -> (i32, i32) {
        let wx = x * self.ex.0 + z * self.ez.0 - self.anchor_world.0;
        let wy = x * self.ex.1 + z * self.ez.1 - self.anchor_world.1;
        (
            (self.anchor_px.0 + wx * self.scale).round() as i32,
            (self.anchor_px.1 - wy * self.scale).round() as i32,
        )
    }
}

/// Header height at the default frame height \[px\].
const HEADER_PX: i32 = 44;

type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// Point at distance `d` from `from` along the unit direction `e`, shifted by `side` along `n`.
fn along(from: (f64, f64), e: (f64, f64), n: (f64, f64), d: f64, side: f64) -> (f64, f64) {
    (from.0 + d * e.0 + side * n.0, from.1 + d * e.1 + side * n.1)
}

/// What the frame shows about one leg.
struct LegState {
    length: f64,
    /// `Some((colour, tip state, stopper locked))` for Leg 1 and Leg 2.
    compliant: Option<(RGBColor, TipState, bool)>,
}

fn tip_color(tip: TipState) -> (RGBColor, bool) {
    match tip {
        TipState::Stuck => (COLOR_GREEN, true),
        TipState::Sliding => (COLOR_ORANGE, true),
        TipState::Air => (WHITE, false),
    }
}

fn draw_tip<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    at: (i32, i32),
    r: i32,
    tip: TipState,
) -> DrawResult<DB> {
    let (color, _) = tip_color(tip);
    root.draw(&Circle::new(at, r, color.filled()))?;
    root.draw(&Circle::new(at, r, INK.stroke_width(2)))
}

/// Draws one leg from the hub along `psi` (MODEL.md section 1).
fn draw_leg<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    view: &View,
    geometry: &Geometry,
    hub: (f64, f64),
    psi: f64,
    leg: &LegState,
) -> DrawResult<DB> {
    let e = (-psi.sin(), -psi.cos());
    let n = (-psi.cos(), psi.sin());
    let l0 = geometry.stopper_length;
    let p = |d: f64, side: f64| view.px(along(hub, e, n, d, side * l0));
    let w = |f: f64| ((f * view.scale / 100.0).round() as u32).max(1);
    let tip_r = (0.045 * l0 * view.scale).round().max(3.0) as i32;
    let Some((color, tip, locked)) = leg.compliant else {
        root.draw(&PathElement::new(
            vec![p(0.0, 0.0), p(leg.length, 0.0)],
            SPOKE.stroke_width(w(3.0)),
        ))?;
        return draw_tip(root, p(leg.length, 0.0), tip_r - 1, TipState::Air);
    };
    let l = leg.length;
    let housing_end = HOUSING * l0;
    let rod_top = (l - ROD * l0).max(housing_end);
    // Housing and rod.
    root.draw(&PathElement::new(
        vec![p(0.0, 0.0), p(housing_end, 0.0)],
        color.stroke_width(w(7.0)),
    ))?;
    root.draw(&PathElement::new(
        vec![p(rod_top, 0.0), p(l, 0.0)],
        color.stroke_width(w(4.0)),
    ))?;
    // Spring: a zigzag of COILS coils between the housing and the rod.
    let mut zig = vec![p(housing_end, 0.0)];
    let segments = 2 * COILS;
    for k in 0..segments {
        let d = housing_end + (rod_top - housing_end) * (k as f64 + 0.5) / segments as f64;
        let side = if k % 2 == 0 {
            COIL_HALF_WIDTH
        } else {
            -COIL_HALF_WIDTH
        };
        zig.push(p(d, side));
    }
    zig.push(p(rod_top, 0.0));
    root.draw(&PathElement::new(zig, INK.stroke_width(w(1.6))))?;
    // Dashpot beside the spring (the textbook symbol): a cup hanging from the housing, a piston on the rod;
    // its links stretch with the leg.
    let span = rod_top - housing_end;
    let mid = housing_end + 0.5 * span;
    let cup = (DASHPOT_CUP * l0).min(0.3 * span);
    let (off, half) = (DASHPOT_OFFSET, DASHPOT_HALF_WIDTH);
    let thin = INK.stroke_width(w(1.6));
    root.draw(&PathElement::new(
        vec![p(housing_end, 0.0), p(housing_end, off), p(mid - cup, off)],
        thin,
    ))?;
    root.draw(&PathElement::new(
        vec![
            p(mid + cup, off - half),
            p(mid - cup, off - half),
            p(mid - cup, off + half),
            p(mid + cup, off + half),
        ],
        thin,
    ))?;
    root.draw(&PathElement::new(
        vec![p(mid, off - 0.7 * half), p(mid, off + 0.7 * half)],
        INK.stroke_width(w(3.0)),
    ))?;
    root.draw(&PathElement::new(
        vec![p(mid, off), p(rod_top, off), p(rod_top, 0.0)],
        thin,
    ))?;
    // Stopper, drawn while it holds the leg at L0.
    if locked {
        root.draw(&PathElement::new(
            vec![p(rod_top, -0.05), p(rod_top, 0.05)],
            STOPPER.stroke_width(w(5.0)),
        ))?;
    }
    // Leg mass at `a` from the tip.
    let mass_r = (0.028 * l0 * view.scale).round().max(2.0) as i32;
    root.draw(&Circle::new(
        p(l - geometry.leg_mass_offset, 0.0),
        mass_r,
        color.filled(),
    ))?;
    draw_tip(root, p(l, 0.0), tip_r, tip)
}

/// Draws the ground: a filled band under the slope line, hatching every [`HATCH_SPACING`] `L0` and a labelled tick
/// every metre of slope distance (they run past as the camera follows the hub).
fn draw_ground<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    view: &View,
    hub_x: f64,
    l0: f64,
    (w, h): (i32, i32),
) -> DrawResult<DB> {
    let reach = 0.6 * f64::from(w) / view.scale;
    let (x0, x1) = (hub_x - reach, hub_x + reach);
    // The band, in pixels of the frame.
    let (left, right) = (view.px((x0, 0.0)), view.px((x1, 0.0)));
    let y_at = |x: i32| left.1 + (right.1 - left.1) * (x - left.0) / (right.0 - left.0).max(1);
    root.draw(&Polygon::new(
        vec![
            (0, y_at(0)),
            (w - 1, y_at(w - 1)),
            (w - 1, h - 1),
            (0, h - 1),
        ],
        GROUND.filled(),
    ))?;
    let hatch = HATCH_SPACING * l0;
    let per_metre = (1.0 / hatch).round().max(1.0) as i64;
    let mut k = (x0 / hatch).floor() as i64;
    while (k as f64) * hatch <= x1 {
        let x = k as f64 * hatch;
        // Plotters clamps points outside the frame to its edge: draw only strokes inside it.
        let stroke = [view.px((x, 0.0)), view.px((x - 0.6 * hatch, -0.6 * hatch))];
        if stroke.iter().all(|p| (0..w).contains(&p.0)) {
            root.draw(&PathElement::new(stroke.to_vec(), HATCH.stroke_width(2)))?;
        }
        let at = view.px((x, -0.12 * l0));
        if k % per_metre == 0 && (20..w - 20).contains(&at.0) {
            root.draw(&PathElement::new(
                vec![view.px((x, 0.0)), view.px((x, -0.08 * l0))],
                INK.stroke_width(2),
            ))?;
            root.draw(&Text::new(
                format!("{:.0} m", x),
                at,
                font(13.0).pos(Pos::new(HPos::Center, VPos::Top)),
            ))?;
        }
        k += 1;
    }
    root.draw(&PathElement::new(
        vec![(0, y_at(0)), (w - 1, y_at(w - 1))],
        INK.stroke_width(2),
    ))
}

/// The legend in the top right corner.
fn draw_legend<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, w: i32) -> DrawResult<DB> {
    let size = 14.0;
    let x = w - 190;
    let mut y = 8;
    // What each legend entry shows: a tip, a stopper bar, or a leg's colour.
    enum Key {
        Tip(TipState),
        Bar(RGBColor, u32),
    }
    let entries = [
        ("tip on ground, no slip", Key::Tip(TipState::Stuck)),
        ("tip sliding", Key::Tip(TipState::Sliding)),
        ("tip in the air", Key::Tip(TipState::Air)),
        ("stopper locked", Key::Bar(STOPPER, 4)),
        ("Leg 1", Key::Bar(COLOR_BLUE, 5)),
        ("Leg 2", Key::Bar(COLOR_VERMILLION, 5)),
    ];
    for (label, key) in entries {
        match key {
            Key::Tip(t) => draw_tip(root, (x, y + 8), 5, t)?,
            Key::Bar(color, width) => root.draw(&PathElement::new(
                vec![(x - 7, y + 8), (x + 7, y + 8)],
                color.stroke_width(width),
            ))?,
        }
        root.draw(&Text::new(
            label,
            (x + 14, y + 8),
            font(size).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        y += 18;
    }
    Ok(())
}

/// Everything a frame needs besides the pose.
struct FrameText {
    time: f64,
    step: Option<usize>,
    phase: String,
    speed: f64,
    slow: Option<SlowMotion>,
}

fn draw_frame<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    geometry: &Geometry,
    opts: &AnimateOptions,
    pose: &Pose,
    legs: &[LegState],
    text: &FrameText,
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let (w, h) = (opts.width as i32, opts.height as i32);
    let hub_x = pose.hub.0;
    let view = View::new(geometry, opts, hub_x);
    draw_ground(root, &view, hub_x, geometry.stopper_length, (w, h))?;
    // Rigid spokes first, then Leg 2 and Leg 1 on top.
    let alpha = geometry.alpha();
    let mut order: Vec<usize> = (0..legs.len()).collect();
    order.sort_by_key(|&p| legs[p].compliant.is_some());
    for p in order {
        let psi = pose.psi0 + p as f64 * alpha;
        draw_leg(root, &view, geometry, pose.hub, psi, &legs[p])?;
    }
    let hub_r = (0.07 * geometry.stopper_length * view.scale)
        .round()
        .max(4.0) as i32;
    root.draw(&Circle::new(view.px(pose.hub), hub_r, INK.filled()))?;
    // Header.
    let size = 17.0 * f64::from(h) / 360.0;
    let step = text
        .step
        .map_or_else(|| "before step 1".to_string(), |s| format!("step {s}"));
    root.draw(&Text::new(
        format!("t = {:.3} s    {step}    {}", text.time, text.phase),
        (12, 10),
        font(size),
    ))?;
    let (line, color) = match &text.slow {
        Some(s) => (
            format!(
                "slow motion: {} lasts {:.4} s, shown in {} frames",
                s.phase, s.duration, s.frames
            ),
            SLOW,
        ),
        None if text.speed != 1.0 => (format!("playback {}x real time", text.speed), INK),
        None => ("real time".to_string(), INK),
    };
    root.draw(&Text::new(
        line,
        (12, 10 + (size * 1.3) as i32),
        font(size * 0.8).color(&color),
    ))?;
    let slope = if opts.horizontal {
        format!("slope φ = {} rad, drawn horizontal", geometry.slope)
    } else {
        format!("slope φ = {} rad", geometry.slope)
    };
    root.draw(&Text::new(
        slope,
        (12, 10 + (size * 2.4) as i32),
        font(size * 0.7),
    ))?;
    draw_legend(root, w)
}

/// `a` moved `k / 8` of the way towards `b`.
fn blend(a: RGBColor, b: RGBColor, k: i32) -> [u8; 3] {
    let mix = |u: u8, v: u8| (i32::from(u) + (i32::from(v) - i32::from(u)) * k / 8) as u8;
    [mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2)]
}

/// The fixed palette: white, each drawing colour with its blends towards white, a grey ramp, and the blends
/// of the ink and the hatching with the ground (text and lines drawn on the ground).
fn palette() -> Vec<[u8; 3]> {
    let mut colors: Vec<[u8; 3]> = vec![[255, 255, 255]];
    for base in PALETTE_BASE {
        colors.extend((0..4).map(|k| blend(base, WHITE, 2 * k)));
    }
    colors.extend((0..12).map(|k| {
        let g = (k * 255 / 11) as u8;
        [g, g, g]
    }));
    for base in [INK, HATCH] {
        colors.extend((1..4).map(|k| blend(base, GROUND, 2 * k)));
    }
    colors.truncate(63);
    colors
}

/// A 15-bit RGB to palette index lookup table (nearest colour in RGB distance).
fn lookup(palette: &[[u8; 3]]) -> Vec<u8> {
    let mut lut = vec![0u8; 1 << 15];
    for (key, slot) in lut.iter_mut().enumerate() {
        let c = [
            ((key >> 10) & 31) as i32 * 8 + 4,
            ((key >> 5) & 31) as i32 * 8 + 4,
            (key & 31) as i32 * 8 + 4,
        ];
        let mut best = (i32::MAX, 0usize);
        for (i, p) in palette.iter().enumerate() {
            let d: i32 = (0..3).map(|j| (c[j] - i32::from(p[j])).pow(2)).sum();
            if d < best.0 {
                best = (d, i);
            }
        }
        *slot = best.1 as u8;
    }
    lut
}

/// Writes the animation of `run` to `path` (see the module doc).
///
/// # Errors
/// [`AnimateError::InvalidOption`] for an option out of range, [`AnimateError::EmptyWindow`] when the time
/// window misses the trajectory, [`AnimateError::Draw`] / [`AnimateError::Write`] when a frame cannot be drawn
/// or the file written.
pub fn write_animation(
    run: &RunData,
    opts: &AnimateOptions,
    path: &Path,
) -> Result<AnimationReport, AnimateError> {
    opts.validate()?;
    let window = window(run, opts)?;
    require_font(path)?;
    let frames = plan_frames(&run.samples, window, opts.fps, opts.speed);
    let write_err = |message: String| AnimateError::Write {
        path: path.to_path_buf(),
        message,
    };
    let palette = palette();
    let lut = lookup(&palette);
    let transparent = palette.len() as u8;
    let mut flat: Vec<u8> = palette.iter().flatten().copied().collect();
    flat.extend([255, 0, 255]);
    let (w, h) = (opts.width as usize, opts.height as usize);
    let file = File::create(path).map_err(|e| write_err(e.to_string()))?;
    let mut encoder = gif::Encoder::new(BufWriter::new(file), w as u16, h as u16, &flat)
        .map_err(|e| write_err(e.to_string()))?;
    encoder
        .set_repeat(gif::Repeat::Infinite)
        .map_err(|e| write_err(e.to_string()))?;

    let renderer = Renderer::new(run, opts);
    let centis = |k: usize| (k as f64 * 100.0 / f64::from(opts.fps)).round() as u64;
    // Frames are drawn, mapped to the palette and LZW-compressed in parallel, a chunk at a time, and written
    // in order.
    let mut previous: Option<Vec<u8>> = None;
    for (c, chunk) in frames.chunks(RENDER_CHUNK).enumerate() {
        let indexed: Vec<Vec<u8>> = chunk
            .par_iter()
            .map_init(
                || vec![255u8; w * h * 3],
                |rgb, frame| {
                    {
                        let root = BitMapBackend::with_buffer(rgb, (opts.width, opts.height))
                            .into_drawing_area();
                        renderer.draw(&root, frame, path)?;
                    }
                    Ok(rgb
                        .chunks_exact(3)
                        .map(|px| {
                            lut[(usize::from(px[0] >> 3) << 10)
                                | (usize::from(px[1] >> 3) << 5)
                                | usize::from(px[2] >> 3)]
                        })
                        .collect())
                },
            )
            .collect::<Result<_, PlotError>>()?;
        let encoded: Vec<gif::Frame<'static>> = (0..indexed.len())
            .into_par_iter()
            .map(|i| {
                let k = c * RENDER_CHUNK + i;
                let before = if i == 0 {
                    previous.as_deref()
                } else {
                    Some(indexed[i - 1].as_slice())
                };
                let delay = (centis(k + 1) - centis(k)) as u16;
                let mut frame = changed_rect(before, &indexed[i], w, h, transparent, delay);
                frame.make_lzw_pre_encoded();
                frame
            })
            .collect();
        for frame in &encoded {
            encoder
                .write_lzw_pre_encoded_frame(frame)
                .map_err(|e| write_err(e.to_string()))?;
        }
        previous = indexed.into_iter().last();
    }
    let mut out = encoder.into_inner().map_err(|e| write_err(e.to_string()))?;
    out.flush().map_err(|e| write_err(e.to_string()))?;
    let bytes = std::fs::metadata(path)
        .map_err(|e| write_err(e.to_string()))?
        .len();
    Ok(AnimationReport {
        path: path.to_path_buf(),
        frames: frames.len(),
        slow_frames: frames.iter().filter(|f| f.slow.is_some()).count(),
        window,
        playback: centis(frames.len()) as f64 / 100.0,
        bytes,
    })
}

/// Draws frames of one run.
struct Renderer<'a> {
    run: &'a RunData,
    opts: &'a AnimateOptions,
    track: Track<'a>,
}

impl<'a> Renderer<'a> {
    fn new(run: &'a RunData, opts: &'a AnimateOptions) -> Renderer<'a> {
        Renderer {
            run,
            opts,
            track: Track::new(&run.samples, run.geometry),
        }
    }

    /// Draws the frame at `frame.time` on `root` (errors name `path`, the file being made).
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        frame: &FrameTime,
        path: &Path,
    ) -> Result<(), PlotError> {
        let pose = self.track.pose_at(frame.time);
        let sample = &self.run.samples[self.track.index_at(frame.time)];
        let legs = leg_states(&self.run.geometry, &pose, sample);
        let text = FrameText {
            time: frame.time,
            step: self.run.step_at(frame.time).map(|s| s.step),
            phase: sample.phase_name(),
            speed: self.opts.speed,
            slow: frame.slow.clone(),
        };
        let fail = PlotError::draw_at(path);
        draw_frame(root, &self.run.geometry, self.opts, &pose, &legs, &text)
            .map_err(|e| fail(e.to_string()))?;
        root.present().map_err(|e| fail(e.to_string()))
    }
}

/// Writes one frame of the animation, at simulated time `time`, as a PNG (for documents and for checking a
/// picture without a GIF viewer).
///
/// # Errors
/// As [`write_animation`]; a `time` outside the trajectory is an [`AnimateError::EmptyWindow`].
pub fn write_still(
    run: &RunData,
    opts: &AnimateOptions,
    time: f64,
    path: &Path,
) -> Result<(), AnimateError> {
    opts.validate()?;
    let (start, end) = run.time_span();
    if !(start..=end).contains(&time) {
        return Err(AnimateError::EmptyWindow {
            path: run.path("trajectory.csv"),
            from: time,
            to: time,
            start,
            end,
        });
    }
    require_font(path)?;
    let root = BitMapBackend::new(path, (opts.width, opts.height)).into_drawing_area();
    let frame = FrameTime { time, slow: None };
    Ok(Renderer::new(run, opts).draw(&root, &frame, path)?)
}

/// What each physical leg shows at a frame: its length, and for Leg 1 and Leg 2 their colour, tip state and
/// stopper.
fn leg_states(geometry: &Geometry, pose: &Pose, sample: &TrajectoryRow) -> Vec<LegState> {
    let n = geometry.legs;
    let [tip1, tip2] = sample.tips();
    pose.lengths
        .iter()
        .enumerate()
        .map(|(p, &length)| LegState {
            length,
            compliant: if p == sample.leg1 % n {
                Some((COLOR_BLUE, tip1, sample.lock1))
            } else if p == (sample.leg1 + 1) % n {
                Some((COLOR_VERMILLION, tip2, sample.lock2))
            } else {
                None
            },
        })
        .collect()
}

/// The GIF frame for `current`: the whole frame first, then only the rectangle that changed since `previous`,
/// its unchanged pixels transparent.
fn changed_rect(
    previous: Option<&[u8]>,
    current: &[u8],
    w: usize,
    h: usize,
    transparent: u8,
    delay: u16,
) -> gif::Frame<'static> {
    let mut frame = match previous {
        None => gif::Frame::from_indexed_pixels(w as u16, h as u16, current.to_vec(), None),
        Some(prev) => {
            let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
            for y in 0..h {
                let row = y * w..(y + 1) * w;
                let (a, b) = (&prev[row.clone()], &current[row]);
                if a == b {
                    continue;
                }
                let first = a.iter().zip(b).position(|(u, v)| u != v).unwrap_or(0);
                let last = w
                    - 1
                    - a.iter()
                        .rev()
                        .zip(b.iter().rev())
                        .position(|(u, v)| u != v)
                        .unwrap_or(0);
                x0 = x0.min(first);
                x1 = x1.max(last);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
            if x0 > x1 {
                (x0, y0, x1, y1) = (0, 0, 0, 0);
            }
            let (fw, fh) = (x1 - x0 + 1, y1 - y0 + 1);
            let mut buffer = Vec::with_capacity(fw * fh);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let i = y * w + x;
                    buffer.push(if prev[i] == current[i] {
                        transparent
                    } else {
                        current[i]
                    });
                }
            }
            let mut f =
                gif::Frame::from_indexed_pixels(fw as u16, fh as u16, buffer, Some(transparent));
            f.left = x0 as u16;
            f.top = y0 as u16;
            f
        }
    };
    frame.delay = delay;
    frame.dispose = gif::DisposalMethod::Keep;
    frame
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sample at `time` with the given contacts and slides of Leg 2 (Leg 1 stuck, leg 0 is Leg 1).
    fn sample(time: f64, contact2: bool, slide2: bool) -> TrajectoryRow {
        TrajectoryRow {
            time,
            x: 0.0,
            z: 0.0,
            theta: -0.5 + 0.1 * time,
            l1: 0.9,
            l2: 0.8,
            theta_dot: 0.1,
            l1_dot: 0.0,
            l2_dot: 0.0,
            contact1: true,
            contact2,
            slide1: false,
            slide2,
            lock1: false,
            lock2: !contact2,
            lambda_1: 0.0,
            lambda_2: 1.0,
            lambda_3: 0.0,
            lambda_4: 1.0,
            leg1: 0,
        }
    }

    /// Samples every 0.005 s over [0, 1] s with a 0.03 s slide of Leg 2 starting at 0.405 s (between the
    /// frames at 0.40 and 0.44 s of 25 frames/s), then single support.
    fn with_short_slide() -> Vec<TrajectoryRow> {
        let mut out = Vec::new();
        for k in 0..=200 {
            let t = k as f64 * 0.005;
            if t > 0.405 && t < 0.4051 {
                out.push(sample(0.405, true, true));
            }
            let (contact2, slide2) = if t < 0.405 {
                (true, false)
            } else if t < 0.435 {
                (true, true)
            } else {
                (false, false)
            };
            if (t - 0.435).abs() < 1e-12 {
                out.push(sample(0.435, false, false));
                continue;
            }
            out.push(sample(t, contact2, slide2));
        }
        out
    }

    #[test]
    fn regular_frames_cover_the_window() {
        let samples = with_short_slide();
        let frames = plan_frames(&samples, (0.0, 1.0), 25, 1.0);
        let regular: Vec<&FrameTime> = frames.iter().filter(|f| f.slow.is_none()).collect();
        assert_eq!(regular.len(), 26, "0, 0.04, ..., 1.0");
        assert!(frames.windows(2).all(|w| w[0].time <= w[1].time));
    }

    #[test]
    fn short_slide_gets_slow_motion_frames() {
        let samples = with_short_slide();
        let frames = plan_frames(&samples, (0.0, 1.0), 25, 1.0);
        let slow: Vec<&FrameTime> = frames.iter().filter(|f| f.slow.is_some()).collect();
        assert_eq!(slow.len(), SLOW_FRAMES);
        for f in &slow {
            assert!((0.405..0.435).contains(&f.time), "{}", f.time);
            let s = f.slow.as_ref().unwrap();
            assert!(s.phase.contains("slides"), "{}", s.phase);
            assert!((s.duration - 0.03).abs() < 1e-12);
        }
        // The first slow frame is the event instant itself.
        assert_eq!(slow[0].time, 0.405);
    }

    #[test]
    fn slide_covered_by_a_regular_frame_is_not_slowed() {
        let samples = with_short_slide();
        // At 50 frames/s a frame falls at 0.42 s, inside the slide.
        let frames = plan_frames(&samples, (0.0, 1.0), 50, 1.0);
        assert!(frames.iter().all(|f| f.slow.is_none()));
    }

    #[test]
    fn pose_is_continuous_through_reindexing() {
        // A touchdown at 0.5 s: theta drops by alpha and Leg 1 moves to the previous physical leg; the wheel
        // itself does not move.
        let geometry = Geometry {
            legs: 8,
            stopper_length: 1.0,
            spring_natural_length: 1.02,
            leg_mass_offset: 0.3,
            slope: 0.1,
            viscosity: 50.0,
        };
        let alpha = geometry.alpha();
        let before = TrajectoryRow {
            leg1: 0,
            theta: 0.3,
            ..sample(0.5, true, false)
        };
        let after = TrajectoryRow {
            leg1: 7,
            theta: 0.3 - alpha,
            ..sample(0.5, true, false)
        };
        let samples = [before, after];
        let track = Track::new(&samples, geometry);
        assert!((track.psi0[0] - track.psi0[1]).abs() < 1e-12);
    }

    #[test]
    fn bad_options_are_named() {
        let bad = |o: AnimateOptions, needle: &str| {
            let e = o.validate().unwrap_err().to_string();
            assert!(e.contains(needle), "{e}");
        };
        let d = AnimateOptions::default;
        bad(AnimateOptions { fps: 0, ..d() }, "--fps");
        bad(AnimateOptions { fps: 60, ..d() }, "--fps");
        bad(AnimateOptions { speed: 0.0, ..d() }, "--speed");
        bad(
            AnimateOptions {
                from: Some(3.0),
                to: Some(1.0),
                ..d()
            },
            "--to",
        );
        bad(AnimateOptions { height: 5, ..d() }, "--height");
        assert!(d().validate().is_ok());
    }

    #[test]
    fn palette_fits_a_gif_with_its_transparent_index() {
        let p = palette();
        assert!(p.len() < 256);
        let lut = lookup(&p);
        assert_eq!(lut[(31 << 10) | (31 << 5) | 31], 0, "white maps to white");
    }
}
