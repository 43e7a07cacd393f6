//! A walker's run figure (`vrw plot` of a `vrw simulate --model NAME` run: `run.png`, `run.svg`): every
//! coordinate the model names against time, one panel each, and the energies (`T`, `V`, `T + V`) below, with
//! every heel strike a dashed vertical line. Curves break at each heel strike, where the legs exchange roles.

use std::path::PathBuf;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::{
    draw_stack, titled, write_svg_png, Curve, DrawResult, Figure, Panel, Stack, Stroke,
};
use super::style::{PlotError, COLOR_BLACK, COLOR_BLUE, COLOR_VERMILLION};
use super::walker_run::WalkerRun;

/// Size of a walker's `run.png` and `run.svg` \[px\].
pub const WALKER_RUN_SIZE: (u32, u32) = (1600, 1800);

/// The figure: its title, time range, heel strikes and panels.
struct WalkerRunFigure {
    title: String,
    x: std::ops::Range<f64>,
    strikes: Vec<f64>,
    panels: Vec<Panel>,
}

/// The column `name` against time, broken (a NaN) where the step changes.
fn series(run: &WalkerRun, name: &str) -> Vec<(f64, f64)> {
    let Some(values) = run.column(name) else {
        return Vec::new();
    };
    let mut points = Vec::with_capacity(values.len() + 64);
    for (k, v) in values.iter().enumerate() {
        if k > 0 && run.step_at(k) != run.step_at(k - 1) {
            points.push((run.rows[k][0], f64::NAN));
        }
        points.push((run.rows[k][0], *v));
    }
    points
}

impl WalkerRunFigure {
    fn new(run: &WalkerRun) -> Result<WalkerRunFigure, PlotError> {
        let (start, end) = run.time_span();
        if end <= start {
            return Err(PlotError::Empty(format!(
                "{} spans no time",
                run.dir.join("trajectory.csv").display()
            )));
        }
        let curve = |label: &str, color, name: &str| Curve {
            label: label.to_string(),
            color,
            stroke: Stroke::Solid,
            points: series(run, name),
        };
        let mut panels: Vec<Panel> = run
            .info
            .coordinates
            .iter()
            .map(|c| Panel {
                y_label: c.clone(),
                curves: vec![curve(c, COLOR_BLUE, c)],
            })
            .collect();
        panels.push(Panel {
            y_label: "energy".to_string(),
            curves: vec![
                curve("kinetic T", COLOR_BLUE, "kinetic"),
                curve("potential V", COLOR_VERMILLION, "potential"),
                curve("T + V", COLOR_BLACK, "energy"),
            ],
        });
        let strikes = (1..run.rows.len())
            .filter(|&k| run.step_at(k) != run.step_at(k - 1))
            .map(|k| run.rows[k][0])
            .collect();
        Ok(WalkerRunFigure {
            title: format!(
                "The {} walker on slope {} rad: {}",
                run.info.model, run.info.slope, run.info.status
            ),
            x: start..end,
            strikes,
            panels,
        })
    }
}

impl Figure for WalkerRunFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let body = titled(root, &self.title)?;
        draw_stack(
            &body,
            &Stack {
                x_label: "time (the model's unit); dashed: heel strikes",
                x: self.x.clone(),
                bands: &[],
                marks: &self.strikes,
                panels: &self.panels,
                x_integer: false,
            },
        )
        .map(|_| ())
    }
}

/// Writes the walker run's `run.png` and `run.svg` into its directory and returns their paths.
pub fn write_walker_run_figure(run: &WalkerRun) -> Result<Vec<PathBuf>, PlotError> {
    let figure = WalkerRunFigure::new(run)?;
    let (png, svg) = (run.dir.join("run.png"), run.dir.join("run.svg"));
    write_svg_png(&figure, &svg, &png, WALKER_RUN_SIZE)?;
    Ok(vec![png, svg])
}
