//! The run figure (`vrw plot`: `run.png`, `run.svg`): the walk against time.
//!
//! Five panels share the time axis: the angle `theta` of Leg 1 from the slope normal, its rate, the leg
//! lengths `L1`, `L2` with the stopper length `L0` dashed, the normal ground forces `lambda_2` (Leg 1) and
//! `lambda_4` (Leg 2), and the tangential ones `lambda_1`, `lambda_3` (docs/model.md section 3). The background
//! is shaded by phase (DLS, a sliding tip, SLS, rear support, flight) and every touchdown is a dashed
//! vertical line. Curves break at each touchdown, where the legs are re-indexed (docs/model.md section 5).

use std::path::PathBuf;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::{
    dashed, draw_stack, titled, write_svg_png, Band, Curve, DrawResult, Figure, Panel, PixelRect,
    Stack, Stroke,
};
use super::read::{RunData, TipState, TrajectoryRow};
use super::style::{draw_box, PlotError, COLOR_BLUE, COLOR_MARK, COLOR_VERMILLION};

/// Size of `run.png` and `run.svg` \[px\].
pub const RUN_SIZE: (u32, u32) = (1600, 2000);

/// The phases the figures shade, by which tips are on the ground.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PhaseKind {
    /// Both tips on the ground, neither sliding.
    DoubleSupport,
    /// A tip on the ground slides.
    Sliding,
    /// Only Leg 1 on the ground.
    SingleSupport,
    /// Only Leg 2 on the ground.
    RearSupport,
    /// No tip on the ground.
    Flight,
}

impl PhaseKind {
    /// The phase of a sample.
    pub(crate) fn of(s: &TrajectoryRow) -> PhaseKind {
        let [a, b] = s.tips();
        if a == TipState::Sliding || b == TipState::Sliding {
            return PhaseKind::Sliding;
        }
        match (a == TipState::Stuck, b == TipState::Stuck) {
            (true, true) => PhaseKind::DoubleSupport,
            (true, false) => PhaseKind::SingleSupport,
            (false, true) => PhaseKind::RearSupport,
            (false, false) => PhaseKind::Flight,
        }
    }

    /// Legend text.
    pub(crate) fn label(self) -> &'static str {
        match self {
            PhaseKind::DoubleSupport => "DLS",
            PhaseKind::Sliding => "a tip slides",
            PhaseKind::SingleSupport => "SLS",
            PhaseKind::RearSupport => "rear support",
            PhaseKind::Flight => "flight",
        }
    }

    /// Shading colour.
    pub(crate) fn color(self) -> RGBColor {
        match self {
            PhaseKind::DoubleSupport => RGBColor(222, 235, 247),
            PhaseKind::Sliding => RGBColor(253, 208, 162),
            PhaseKind::SingleSupport => RGBColor(255, 247, 188),
            PhaseKind::RearSupport => RGBColor(218, 218, 235),
            PhaseKind::Flight => RGBColor(252, 187, 161),
        }
    }
}

/// Shaded phase intervals: sample `k`'s phase holds until sample `k + 1`.
pub(crate) fn phase_bands(samples: &[TrajectoryRow]) -> Vec<(Band, PhaseKind)> {
    let mut out: Vec<(Band, PhaseKind)> = Vec::new();
    for pair in samples.windows(2) {
        let kind = PhaseKind::of(&pair[0]);
        match out.last_mut() {
            Some((band, k)) if *k == kind => band.to = pair[1].time,
            _ => out.push((
                Band {
                    from: pair[0].time,
                    to: pair[1].time,
                    color: kind.color(),
                },
                kind,
            )),
        }
    }
    out
}

/// `(time, value)` points of the samples, with a break (NaN) wherever the legs are re-indexed.
pub(crate) fn series(
    samples: &[TrajectoryRow],
    value: impl Fn(&TrajectoryRow) -> f64,
) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(samples.len() + 64);
    for (k, s) in samples.iter().enumerate() {
        if k > 0 && samples[k - 1].leg1 != s.leg1 {
            out.push((f64::NAN, f64::NAN));
        }
        out.push((s.time, value(s)));
    }
    out
}

fn curve(label: &str, color: RGBColor, points: Vec<(f64, f64)>) -> Curve {
    Curve {
        label: label.to_string(),
        color,
        stroke: Stroke::Solid,
        points,
    }
}

/// A panel of one quantity of Leg 1 (blue) and Leg 2 (vermillion).
fn two_legs(
    samples: &[TrajectoryRow],
    y_label: &str,
    names: [&str; 2],
    value: fn(&TrajectoryRow) -> [f64; 2],
) -> Panel {
    Panel {
        y_label: y_label.to_string(),
        curves: vec![
            curve(
                &format!("{} (Leg 1)", names[0]),
                COLOR_BLUE,
                series(samples, |r| value(r)[0]),
            ),
            curve(
                &format!("{} (Leg 2)", names[1]),
                COLOR_VERMILLION,
                series(samples, |r| value(r)[1]),
            ),
        ],
    }
}

struct RunFigure {
    title: String,
    bands: Vec<(Band, PhaseKind)>,
    touchdowns: Vec<f64>,
    x: std::ops::Range<f64>,
    panels: Vec<Panel>,
}

impl RunFigure {
    fn new(run: &RunData) -> Result<RunFigure, PlotError> {
        let s = &run.samples;
        let (t0, t1) = run.time_span();
        if t1 <= t0 {
            return Err(PlotError::Empty(format!(
                "{} holds a single instant",
                run.path("trajectory.csv").display()
            )));
        }
        let l0 = run.geometry.stopper_length;
        let level = |label: String, y: f64| Curve {
            label,
            color: COLOR_MARK,
            stroke: Stroke::Dashed,
            points: vec![(t0, y), (t1, y)],
        };
        let mut lengths = vec![
            curve("L₁ (Leg 1)", COLOR_BLUE, series(s, |r| r.l1)),
            curve("L₂ (Leg 2)", COLOR_VERMILLION, series(s, |r| r.l2)),
            level(format!("L₀ = {l0} m"), l0),
        ];
        // The compression stop, where there is one.
        let min = run.geometry.min_length;
        if min > 0.0 {
            lengths.push(level(format!("min_length = {min} m"), min));
        }
        let panels = vec![
            Panel {
                y_label: "θ of Leg 1 [rad]".into(),
                curves: vec![curve("θ", COLOR_BLUE, series(s, |r| r.theta))],
            },
            Panel {
                y_label: "dθ/dt [rad/s]".into(),
                curves: vec![curve("dθ/dt", COLOR_BLUE, series(s, |r| r.theta_dot))],
            },
            Panel {
                y_label: "leg length [m]".into(),
                curves: lengths,
            },
            two_legs(s, "normal force [N]", ["λ₂", "λ₄"], |r| {
                [r.lambda_2, r.lambda_4]
            }),
            two_legs(s, "tangential force [N]", ["λ₁", "λ₃"], |r| {
                [r.lambda_1, r.lambda_3]
            }),
        ];
        let name = run.dir.file_name().map_or_else(
            || run.dir.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let title = format!(
            "{name}: {} step{} ({}), c = {} N s/m, slope φ = {} rad",
            run.steps.len(),
            if run.steps.len() == 1 { "" } else { "s" },
            run.status,
            run.geometry.viscosity,
            run.geometry.slope
        );
        Ok(RunFigure {
            title,
            bands: phase_bands(s),
            touchdowns: run.steps.iter().map(|r| r.time).collect(),
            x: t0..t1,
            panels,
        })
    }
}

/// Height of the phase legend row under the title \[px\].
const PHASE_ROW: i32 = 52;

/// Draws one swatch per phase present, in a row at `(x0, y)`, plus the touchdown line.
fn draw_phase_row<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    kinds: &[PhaseKind],
    y: i32,
) -> DrawResult<DB> {
    let style = super::style::font(super::chart::LEGEND_FONT);
    let mut x = 150;
    area.draw(&Text::new("phases:", (x - 110, y), style.clone()))?;
    for k in kinds {
        draw_box(area, [(x, y), (x + 40, y + 24)], k.color())?;
        area.draw(&Text::new(k.label(), (x + 50, y), style.clone()))?;
        x += 50 + area.estimate_text_size(k.label(), &style)?.0 as i32 + 40;
    }
    dashed(
        area,
        &[(x, y + 12), (x + 40, y + 12)],
        COLOR_MARK.stroke_width(2),
    )?;
    area.draw(&Text::new("touchdown", (x + 50, y), style))?;
    Ok(())
}

impl RunFigure {
    /// Draws the figure; returns the canvas pixels of the panels' plotting areas.
    fn draw_panels<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<Vec<PixelRect>, DrawingAreaErrorKind<DB::ErrorType>> {
        let body = titled(root, &self.title)?;
        let mut kinds: Vec<PhaseKind> = Vec::new();
        for (_, k) in &self.bands {
            if !kinds.contains(k) {
                kinds.push(*k);
            }
        }
        draw_phase_row(&body, &kinds, 0)?;
        let (w, h) = body.dim_in_pixel();
        let panels = body
            .clone()
            .shrink((0, PHASE_ROW), (w, h - PHASE_ROW as u32));
        let bands: Vec<Band> = self.bands.iter().map(|(b, _)| *b).collect();
        draw_stack(
            &panels,
            &Stack {
                x_label: "time t [s]",
                x: self.x.clone(),
                bands: &bands,
                marks: &self.touchdowns,
                panels: &self.panels,
                x_integer: false,
            },
        )
    }
}

impl Figure for RunFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        self.draw_panels(root).map(|_| ())
    }
}

/// Draws the run figure of `run` on `root` (of [`RUN_SIZE`]) and returns the canvas pixels of its five
/// panels' plotting areas, top to bottom; whatever a panel shows stays inside its area.
///
/// # Errors
/// [`PlotError::Empty`] if the trajectory spans no time; [`PlotError::Draw`] (naming `run.png`) if the
/// backend fails.
pub fn draw_run_figure<DB: DrawingBackend>(
    run: &RunData,
    root: &DrawingArea<DB, Shift>,
) -> Result<Vec<PixelRect>, PlotError> {
    super::style::require_font(&run.path("run.png"))?;
    RunFigure::new(run)?
        .draw_panels(root)
        .map_err(|e| PlotError::draw_at(&run.path("run.png"))(e.to_string()))
}

/// Writes `run.png` and `run.svg` into the run directory and returns their paths.
///
/// # Errors
/// [`PlotError::Empty`] if the trajectory spans no time; [`PlotError::Draw`] if a file cannot be written.
pub fn write_run_figure(run: &RunData) -> Result<Vec<PathBuf>, PlotError> {
    let figure = RunFigure::new(run)?;
    let (png, svg) = (run.path("run.png"), run.path("run.svg"));
    write_svg_png(&figure, &svg, &png, RUN_SIZE)?;
    Ok(vec![png, svg])
}
