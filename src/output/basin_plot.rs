//! The basin figure (`vrw basin`: `basin.png`): a slice of the Poincare section, every grid cell coloured by
//! what the walk from it did (reached the gait, settled elsewhere, or failed, and how), with the gait marked
//! (README, "Orbit diagram, basin of attraction, period-k gaits").

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::chart::{
    draw_axes_and_curves, draw_legend, titled, write_png, Axes, Clip, DrawResult, Figure, LEGEND_W,
};
use super::style::{
    font, PlotError, COLOR_BLUE, COLOR_GREEN, COLOR_MARK, COLOR_ORANGE, COLOR_PURPLE,
    COLOR_VERMILLION,
};

/// Size of `basin.png` \[px\].
pub(crate) const BASIN_SIZE: (u32, u32) = (2000, 1500);

/// The colour of an outcome (`gait`, `other`, `undecided`, `invalid_start` or a failure kind).
pub(crate) fn outcome_color(outcome: &str) -> RGBColor {
    match outcome {
        "gait" => COLOR_GREEN,
        "other" => COLOR_BLUE,
        "rolled_back" => COLOR_ORANGE,
        "fell" => COLOR_VERMILLION,
        "chatter" => COLOR_PURPLE,
        "undecided" => RGBColor(200, 200, 200),
        "invalid_start" => RGBColor(255, 255, 255),
        "stalled" => RGBColor(86, 180, 233),
        "rear_leg_in_contact" => RGBColor(240, 228, 66),
        "rear_leg_not_locked" => RGBColor(120, 80, 40),
        // The walkers' failures (`vrw basin --model`).
        "stance_lifts_off" => RGBColor(204, 102, 119),
        "stops_in_double_support" => RGBColor(136, 34, 85),
        _ => COLOR_MARK,
    }
}

/// The legend text of an outcome.
fn outcome_label(outcome: &str) -> String {
    match outcome {
        "gait" => "reaches the gait".to_string(),
        "other" => "settles on another gait".to_string(),
        "undecided" => "undecided".to_string(),
        "invalid_start" => "not a section state".to_string(),
        kind => format!("fails: {}", kind.replace('_', " ")),
    }
}

/// The figure's data.
#[derive(Debug, Clone)]
pub(crate) struct BasinFigure {
    /// Title.
    pub title: String,
    /// X axis description with unit.
    pub x_label: String,
    /// Y axis description with unit.
    pub y_label: String,
    /// Grid values along x (cell centres, increasing or decreasing).
    pub xs: Vec<f64>,
    /// Grid values along y.
    pub ys: Vec<f64>,
    /// Outcome of each cell, row-major: `outcomes[iy][ix]`.
    pub outcomes: Vec<Vec<String>>,
    /// The gait's section states on the slice `(x, y)` (one for a period-1 gait, `k` for period k; states off
    /// the slice are still drawn at their projection).
    pub gait: Vec<(f64, f64)>,
}

/// Cell edges around the centres `v` (half a spacing beyond the ends).
pub(crate) fn edges(v: &[f64]) -> Vec<f64> {
    let n = v.len();
    if n < 2 {
        let c = v.first().copied().unwrap_or(0.0);
        return vec![c - 0.5, c + 0.5];
    }
    let mut e = Vec::with_capacity(n + 1);
    e.push(v[0] - 0.5 * (v[1] - v[0]));
    for w in v.windows(2) {
        e.push(0.5 * (w[0] + w[1]));
    }
    e.push(v[n - 1] + 0.5 * (v[n - 1] - v[n - 2]));
    e
}

/// The range the cell edges `e` span, increasing.
pub(crate) fn span(e: &[f64]) -> Range<f64> {
    let (a, b) = (e[0], e[e.len() - 1]);
    a.min(b)..a.max(b)
}

impl BasinFigure {
    /// The gait's states inside the plot on `sub`, as white circles with a cross; `to_px` maps the slice to
    /// `sub`'s pixels.
    fn draw_gait<DB: DrawingBackend>(
        &self,
        sub: &DrawingArea<DB, Shift>,
        clip: &Clip,
        to_px: &impl Fn((f64, f64)) -> (i32, i32),
    ) -> DrawResult<DB> {
        for &g in &self.gait {
            let p = to_px(g);
            if !clip.contains(p) {
                continue;
            }
            clip.draw_circle(sub, p, 14, WHITE.filled())?;
            clip.draw_circle(sub, p, 14, BLACK.stroke_width(3))?;
            if clip.contains((p.0 - 8, p.1 - 8)) && clip.contains((p.0 + 8, p.1 + 8)) {
                sub.draw(&Cross::new(p, 8, BLACK.stroke_width(3)))?;
            } else {
                for arm in [[(-8, -8), (8, 8)], [(-8, 8), (8, -8)]] {
                    let ends = arm.map(|(dx, dy)| (p.0 + dx, p.1 + dy));
                    clip.draw_path(sub, &ends, BLACK.stroke_width(3))?;
                }
            }
        }
        Ok(())
    }

    /// The legend at x `lx` of `area`: the outcomes present, in a fixed order, then the gait marker.
    fn draw_outcome_legend<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        lx: i32,
    ) -> DrawResult<DB> {
        let mut kinds: Vec<&str> = Vec::new();
        for o in self.outcomes.iter().flatten() {
            if !kinds.contains(&o.as_str()) {
                kinds.push(o);
            }
        }
        let order = |k: &str| match k {
            "gait" => 0,
            "other" => 1,
            "undecided" => 3,
            "invalid_start" => 4,
            _ => 2,
        };
        kinds.sort_by(|a, b| order(a).cmp(&order(b)).then(a.cmp(b)));
        let swatches: Vec<(String, RGBColor)> = kinds
            .iter()
            .map(|k| (outcome_label(k), outcome_color(k)))
            .collect();
        draw_legend(area, &[], &swatches, (lx, 20))?;
        let gy = 20 + 34 * swatches.len() as i32 + 40;
        area.draw(&Circle::new((lx + 30, gy), 14, BLACK.stroke_width(3)))?;
        area.draw(&Cross::new((lx + 30, gy), 8, BLACK.stroke_width(3)))?;
        let label = match self.gait.len() {
            0 | 1 => "the gait".to_string(),
            k => format!("the gait ({k} states)"),
        };
        area.draw(&Text::new(
            label,
            (lx + 60, gy),
            font(24.0).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        Ok(())
    }
}

impl Figure for BasinFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let area = titled(root, &self.title)?;
        let (w, h) = area.dim_in_pixel();
        let (w, h) = (w as i32, h as i32);
        let sub = area.clone().shrink((0, 0), (w - LEGEND_W - 40, h));
        let (ex, ey) = (edges(&self.xs), edges(&self.ys));
        let (x, y) = (span(&ex), span(&ey));
        let axes = Axes {
            x: x.clone(),
            y: y.clone(),
            x_label: Some(&self.x_label),
            y_label: &self.y_label,
            x_integer: false,
        };
        let (px, py) = draw_axes_and_curves(&sub, &axes, &[], &[], &[])?;
        let base = sub.get_base_pixel();
        let to_px = |(a, b): (f64, f64)| {
            let fx = (a - x.start) / (x.end - x.start);
            let fy = (b - y.start) / (y.end - y.start);
            (
                px.start + (fx * f64::from(px.end - px.start)).round() as i32 - base.0,
                py.end - (fy * f64::from(py.end - py.start)).round() as i32 - base.1,
            )
        };
        for (iy, row) in self.outcomes.iter().enumerate() {
            for (ix, outcome) in row.iter().enumerate() {
                let (a, b) = (to_px((ex[ix], ey[iy])), to_px((ex[ix + 1], ey[iy + 1])));
                sub.draw(&Rectangle::new([a, b], outcome_color(outcome).filled()))?;
            }
        }
        sub.draw(&Rectangle::new(
            [
                (px.start - base.0, py.start - base.1),
                (px.end - 1 - base.0, py.end - 1 - base.1),
            ],
            BLACK.stroke_width(2),
        ))?;
        let clip = Clip::new(
            px.start - base.0..px.end - base.0,
            py.start - base.1..py.end - base.1,
        );
        self.draw_gait(&sub, &clip, &to_px)?;
        self.draw_outcome_legend(&area, w - LEGEND_W - 24)?;
        Ok(())
    }
}

/// Write the basin figure as a PNG at `png`.
pub(crate) fn write_basin_figure(figure: &BasinFigure, png: &Path) -> Result<(), PlotError> {
    if figure.xs.is_empty() || figure.ys.is_empty() || figure.outcomes.is_empty() {
        return Err(PlotError::Empty("the basin has no grid points".to_string()));
    }
    write_png(figure, png, BASIN_SIZE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_surround_the_centres() {
        assert_eq!(edges(&[0.0, 1.0, 2.0]), vec![-0.5, 0.5, 1.5, 2.5]);
        assert_eq!(edges(&[1.0]), vec![0.5, 1.5]);
    }

    #[test]
    fn writes_a_png() {
        let dir = tempfile::tempdir().unwrap();
        let figure = BasinFigure {
            title: "test".to_string(),
            x_label: "L2 [m]".to_string(),
            y_label: "dθ/dt [rad/s]".to_string(),
            xs: vec![0.5, 0.75, 1.0],
            ys: vec![0.5, 1.0],
            outcomes: vec![
                vec!["gait".into(), "rolled_back".into(), "other".into()],
                vec!["fell".into(), "gait".into(), "invalid_start".into()],
            ],
            gait: vec![(0.75, 1.0)],
        };
        let png = dir.path().join("basin.png");
        write_basin_figure(&figure, &png).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(super::super::style::png_size(&bytes), Some(BASIN_SIZE));
    }
}
