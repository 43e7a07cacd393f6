//! The steps figure (`vrw plot`: `steps.png`, `steps.svg`): how the walk settles onto its gait.
//!
//! Left, against the step number: the three DLS indicators of each touchdown (`lambda_I4`, and `lambda_2+`,
//! `lambda_4+`; docs/model.md section 5), the period and the DLS duration, the energy audit (loss of `T + V`
//! against the damper, impact and stopper losses) and its residual (docs/model.md section 7). Right: the phase
//! portrait of Leg 2 over the last step, `L2` against `dL2/dt`, coloured by the contact state of its tip,
//! with `L0` dashed.

use std::path::PathBuf;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::{
    draw_axes_and_curves, draw_legend, draw_stack, finite_range, titled, write_svg_png, Axes,
    Curve, DrawResult, Figure, Panel, Stack, Stroke, LEGEND_W,
};
use super::read::{RunData, StepRow, TipState, TrajectoryRow};
use super::style::{
    padded, PlotError, COLOR_BLACK, COLOR_BLUE, COLOR_GREEN, COLOR_MARK, COLOR_ORANGE,
    COLOR_PURPLE, COLOR_VERMILLION,
};

/// Size of `steps.png` and `steps.svg` \[px\].
pub const STEPS_SIZE: (u32, u32) = (2400, 1500);

/// Share of the width given to the panels against the step number.
const LEFT_SHARE: f64 = 0.58;

fn per_step(label: &str, color: RGBColor, steps: &[StepRow], value: fn(&StepRow) -> f64) -> Curve {
    Curve {
        label: label.to_string(),
        color,
        stroke: Stroke::Markers,
        points: steps.iter().map(|s| (s.step as f64, value(s))).collect(),
    }
}

/// The samples of the last step: from its touchdown to the end of the trajectory or the next re-indexing.
fn last_step_samples<'a>(run: &'a RunData, last: &StepRow) -> &'a [TrajectoryRow] {
    let s = &run.samples;
    let start = s.partition_point(|r| r.time < last.time);
    let Some(first) = s.get(start) else {
        return &[];
    };
    let end = start
        + s[start..]
            .iter()
            .take_while(|r| r.leg1 == first.leg1)
            .count();
    &s[start..end]
}

/// `(L2, dL2/dt)` curves of Leg 2 split by its tip state; each segment takes the state of its first sample.
fn portrait(samples: &[TrajectoryRow]) -> Vec<Curve> {
    let states = [
        (TipState::Stuck, "tip on ground, no slip", COLOR_GREEN),
        (TipState::Sliding, "tip sliding", COLOR_ORANGE),
        (TipState::Air, "tip in the air", COLOR_MARK),
    ];
    let mut curves: Vec<Curve> = states
        .iter()
        .map(|&(_, label, color)| Curve {
            label: label.to_string(),
            color,
            stroke: Stroke::Solid,
            points: Vec::new(),
        })
        .collect();
    let mut previous: Option<usize> = None;
    for pair in samples.windows(2) {
        let state = pair[0].tips()[1];
        let k = states.iter().position(|s| s.0 == state).unwrap_or(2);
        if previous != Some(k) {
            curves[k].points.push((f64::NAN, f64::NAN));
            curves[k].points.push((pair[0].l2, pair[0].l2_dot));
        }
        curves[k].points.push((pair[1].l2, pair[1].l2_dot));
        previous = Some(k);
    }
    curves.retain(|c| c.points.iter().any(|p| p.0.is_finite()));
    curves
}

struct StepsFigure {
    title: String,
    x: std::ops::Range<f64>,
    panels: Vec<Panel>,
    portrait: Vec<Curve>,
    portrait_title: String,
    l0: f64,
}

impl StepsFigure {
    fn new(run: &RunData) -> Result<StepsFigure, PlotError> {
        let steps = &run.steps;
        let Some(last) = steps.last() else {
            return Err(PlotError::Empty(format!(
                "{} has no step",
                run.path("steps.csv").display()
            )));
        };
        let first = steps[0].step as f64;
        let x = padded(first, last.step as f64, 0.04);
        let x = if last.step as f64 > first {
            x
        } else {
            (first - 1.0)..(first + 1.0)
        };
        let panels = vec![
            Panel {
                y_label: "λI4 [N s]".into(),
                curves: vec![per_step("λI4", COLOR_BLACK, steps, |s| s.lambda_i4)],
            },
            Panel {
                y_label: "λ⁺ [N]".into(),
                curves: vec![
                    per_step("λ₂⁺", COLOR_BLUE, steps, |s| s.lambda_2_plus),
                    per_step("λ₄⁺", COLOR_VERMILLION, steps, |s| s.lambda_4_plus),
                ],
            },
            Panel {
                y_label: "time [s]".into(),
                curves: vec![
                    per_step("period", COLOR_BLACK, steps, |s| s.period),
                    per_step("DLS duration", COLOR_BLUE, steps, |s| s.dls_duration),
                ],
            },
            Panel {
                y_label: "energy [J]".into(),
                curves: vec![
                    per_step("loss of T + V", COLOR_BLACK, steps, |s| s.energy_loss),
                    per_step("damper", COLOR_BLUE, steps, |s| s.damper_loss),
                    per_step("impacts", COLOR_VERMILLION, steps, |s| s.impact_loss),
                    per_step("stoppers", COLOR_PURPLE, steps, |s| s.stopper_loss),
                ],
            },
            Panel {
                y_label: "audit residual [J]".into(),
                curves: vec![per_step("residual", COLOR_BLACK, steps, |s| {
                    s.energy_residual
                })],
            },
        ];
        let samples = last_step_samples(run, last);
        let name = run.dir.file_name().map_or_else(
            || run.dir.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        Ok(StepsFigure {
            title: format!(
                "{name}: DLS indicators, period and energy audit per step; Leg 2 over the last step ({})",
                last.step
            ),
            x,
            panels,
            portrait: portrait(samples),
            portrait_title: format!(
                "step {}, t = {:.3} .. {:.3} s",
                last.step,
                samples.first().map_or(last.time, |s| s.time),
                samples.last().map_or(last.time, |s| s.time)
            ),
            l0: run.geometry.stopper_length,
        })
    }
}

impl Figure for StepsFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let body = titled(root, &self.title)?;
        let (w, h) = body.dim_in_pixel();
        let left_w = (f64::from(w) * LEFT_SHARE) as u32;
        let (left, right) = body.split_horizontally(left_w);
        draw_stack(
            &left,
            &Stack {
                x_label: "step number",
                x: self.x.clone(),
                bands: &[],
                marks: &[],
                panels: &self.panels,
                x_integer: true,
            },
        )?;
        // Phase portrait, a square-ish plot with its legend under the title.
        let right = right.shrink((40, 0), (w - left_w - 40, h));
        let (rw, _) = right.dim_in_pixel();
        right.draw(&Text::new(
            format!("Leg 2, {}", self.portrait_title),
            (0, 0),
            super::style::font(super::chart::AXIS_FONT),
        ))?;
        let plot_area = right.clone().shrink(
            (0, 60),
            (rw.saturating_sub(LEGEND_W as u32 / 4), h - 60 - 200),
        );
        let xs = finite_range(
            self.portrait
                .iter()
                .flat_map(|c| c.points.iter().map(|p| p.0))
                .chain([self.l0]),
        );
        let ys = finite_range(
            self.portrait
                .iter()
                .flat_map(|c| c.points.iter().map(|p| p.1)),
        );
        let (Some(xs), Some(ys)) = (xs, ys) else {
            return Ok(());
        };
        let axes = Axes {
            x: padded(xs.start, xs.end, 0.06),
            y: padded(ys.start, ys.end, 0.08),
            x_label: Some("L₂ [m]"),
            y_label: "dL₂/dt [m/s]",
            x_integer: false,
        };
        draw_axes_and_curves(&plot_area, &axes, &self.portrait, &[], &[self.l0])?;
        let l0_note = Curve {
            label: format!("L₀ = {} m", self.l0),
            color: COLOR_MARK,
            stroke: Stroke::Dashed,
            points: Vec::new(),
        };
        let mut legend = self.portrait.clone();
        legend.push(l0_note);
        draw_legend(&right, &legend, &[], (170, h as i32 - 190))
    }
}

/// Writes `steps.png` and `steps.svg` into the run directory and returns their paths.
///
/// # Errors
/// [`PlotError::Empty`] if `steps.csv` has no step; [`PlotError::Draw`] if a file cannot be written.
pub fn write_steps_figure(run: &RunData) -> Result<Vec<PathBuf>, PlotError> {
    let figure = StepsFigure::new(run)?;
    let (png, svg) = (run.path("steps.png"), run.path("steps.svg"));
    write_svg_png(&figure, &svg, &png, STEPS_SIZE)?;
    Ok(vec![png, svg])
}
