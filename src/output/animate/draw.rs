//! Drawing one frame: the camera (slope frame to pixels), the ground, the legs (telescopic Leg 1 and Leg 2
//! with spring, dashpot and stopper; rigid spokes for the others), the hub, the header and the legend.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::super::chart::DrawResult;
use super::super::read::{Geometry, RunData, TipState};
use super::super::style::{
    font, PlotError, COLOR_BLUE, COLOR_GREEN, COLOR_ORANGE, COLOR_VERMILLION,
};
use super::plan::{FrameTime, SlowMotion};
use super::pose::{leg_states, LegState, Pose, Track};
use super::AnimateOptions;

// Colours of the drawing (every one is in the palette, with its blends towards white).
pub(super) const INK: RGBColor = RGBColor(30, 30, 30);
const SPOKE: RGBColor = RGBColor(110, 110, 110);
pub(super) const GROUND: RGBColor = RGBColor(200, 190, 170);
pub(super) const HATCH: RGBColor = RGBColor(120, 105, 80);
const STOPPER: RGBColor = RGBColor(200, 0, 0);
const SLOW: RGBColor = RGBColor(180, 0, 120);
/// The drawing's colours, from which the GIF palette is made.
pub(super) const PALETTE_BASE: [RGBColor; 11] = [
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

/// Point at distance `d` from `from` along the unit direction `e`, shifted by `side` along `n`.
fn along(from: (f64, f64), e: (f64, f64), n: (f64, f64), d: f64, side: f64) -> (f64, f64) {
    (from.0 + d * e.0 + side * n.0, from.1 + d * e.1 + side * n.1)
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

/// Draws one leg from the hub along `psi` (docs/model.md section 1).
fn draw_leg<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    view: &View,
    geometry: &Geometry,
    hub: (f64, f64),
    psi: f64,
    leg: &LegState,
) -> DrawResult<DB> {
    let axes = LegAxes {
        view,
        hub,
        e: (-psi.sin(), -psi.cos()),
        n: (-psi.cos(), psi.sin()),
        l0: geometry.stopper_length,
    };
    let l0 = axes.l0;
    let tip_r = (0.045 * l0 * view.scale).round().max(3.0) as i32;
    let Some((color, tip, locked)) = leg.compliant else {
        root.draw(&PathElement::new(
            vec![axes.p(0.0, 0.0), axes.p(leg.length, 0.0)],
            SPOKE.stroke_width(axes.w(3.0)),
        ))?;
        return draw_tip(root, axes.p(leg.length, 0.0), tip_r - 1, TipState::Air);
    };
    let l = leg.length;
    let housing_end = HOUSING * l0;
    let rod_top = (l - ROD * l0).max(housing_end);
    // Housing and rod.
    root.draw(&PathElement::new(
        vec![axes.p(0.0, 0.0), axes.p(housing_end, 0.0)],
        color.stroke_width(axes.w(7.0)),
    ))?;
    root.draw(&PathElement::new(
        vec![axes.p(rod_top, 0.0), axes.p(l, 0.0)],
        color.stroke_width(axes.w(4.0)),
    ))?;
    draw_spring(root, &axes, housing_end, rod_top)?;
    draw_dashpot(root, &axes, housing_end, rod_top)?;
    // Stopper, drawn while it holds the leg at L0 (or the compression stop at min_length).
    if locked {
        root.draw(&PathElement::new(
            vec![axes.p(rod_top, -0.05), axes.p(rod_top, 0.05)],
            STOPPER.stroke_width(axes.w(5.0)),
        ))?;
    }
    // Leg mass at `a` from the tip.
    let mass_r = (0.028 * l0 * view.scale).round().max(2.0) as i32;
    root.draw(&Circle::new(
        axes.p(l - geometry.leg_mass_offset, 0.0),
        mass_r,
        color.filled(),
    ))?;
    draw_tip(root, axes.p(l, 0.0), tip_r, tip)
}

/// A leg's own axes in a frame: pixels of points along and across it, and stroke widths in the view's scale.
struct LegAxes<'a> {
    /// The frame's camera.
    view: &'a View,
    /// The hub, where the leg starts (slope frame) \[m\].
    hub: (f64, f64),
    /// Unit vector along the leg, from the hub to the tip.
    e: (f64, f64),
    /// Unit vector across the leg.
    n: (f64, f64),
    /// `L0` \[m\], the unit of the offsets across the leg.
    l0: f64,
}

impl LegAxes<'_> {
    /// The pixel at `d` \[m\] along the leg from the hub and `side` (a fraction of `L0`) across it.
    fn p(&self, d: f64, side: f64) -> (i32, i32) {
        self.view
            .px(along(self.hub, self.e, self.n, d, side * self.l0))
    }

    /// A stroke width of `f` pixels at 100 pixels per metre, in the view's scale (at least 1).
    fn w(&self, f: f64) -> u32 {
        ((f * self.view.scale / 100.0).round() as u32).max(1)
    }
}

/// The spring: a zigzag of [`COILS`] coils between the housing's end and the rod's top.
fn draw_spring<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    axes: &LegAxes,
    housing_end: f64,
    rod_top: f64,
) -> DrawResult<DB> {
    let mut zig = vec![axes.p(housing_end, 0.0)];
    let segments = 2 * COILS;
    for k in 0..segments {
        let d = housing_end + (rod_top - housing_end) * (k as f64 + 0.5) / segments as f64;
        let side = if k % 2 == 0 {
            COIL_HALF_WIDTH
        } else {
            -COIL_HALF_WIDTH
        };
        zig.push(axes.p(d, side));
    }
    zig.push(axes.p(rod_top, 0.0));
    root.draw(&PathElement::new(zig, INK.stroke_width(axes.w(1.6))))
}

/// The dashpot beside the spring (the textbook symbol): a cup hanging from the housing, a piston on the rod;
/// its links stretch with the leg.
fn draw_dashpot<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    axes: &LegAxes,
    housing_end: f64,
    rod_top: f64,
) -> DrawResult<DB> {
    let p = |d: f64, side: f64| axes.p(d, side);
    let span = rod_top - housing_end;
    let mid = housing_end + 0.5 * span;
    let cup = (DASHPOT_CUP * axes.l0).min(0.3 * span);
    let (off, half) = (DASHPOT_OFFSET, DASHPOT_HALF_WIDTH);
    let thin = INK.stroke_width(axes.w(1.6));
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
        INK.stroke_width(axes.w(3.0)),
    ))?;
    root.draw(&PathElement::new(
        vec![p(mid, off), p(rod_top, off), p(rod_top, 0.0)],
        thin,
    ))
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

/// The legend in the top right corner (`compression`: the legs have a compression stop, whose lock is drawn
/// as the stopper's).
fn draw_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    w: i32,
    compression: bool,
) -> DrawResult<DB> {
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
        (
            if compression {
                "stop locked (L0 or min)"
            } else {
                "stopper locked"
            },
            Key::Bar(STOPPER, 4),
        ),
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
    draw_legend(root, w, geometry.min_length > 0.0)
}

/// Draws frames of one run.
pub(super) struct Renderer<'a> {
    run: &'a RunData,
    opts: &'a AnimateOptions,
    track: Track<'a>,
}

impl<'a> Renderer<'a> {
    pub(super) fn new(run: &'a RunData, opts: &'a AnimateOptions) -> Renderer<'a> {
        Renderer {
            run,
            opts,
            track: Track::new(&run.samples, run.geometry),
        }
    }

    /// Draws the frame at `frame.time` on `root` (errors name `path`, the file being made).
    pub(super) fn draw<DB: DrawingBackend>(
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
