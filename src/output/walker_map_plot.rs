//! The map figure of a walker (`vrw map --model NAME`: `map.png`): every grid point's cell coloured by the
//! modulus of its gait's largest Floquet multiplier on a diverging scale white at 1 (blue: stable, red:
//! unstable), grey where there is no gait, a dot where the heel strike would keep double support
//! (`lambda_I4 >= 0`), and the changes of stability bisected along the rows drawn over it, one line per kind.
//! The colour scale is the wheel's map's ([`super::map_plot::colour_bar`]), its cells the basin's
//! ([`super::basin_plot::edges`]).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::basin_plot::{edges, span};
use super::chart::{
    draw_legend_rows, titled, write_png, Axes, Curve, DrawResult, Figure, Label, LegendRow, Marker,
    PlotArea, Sample, Stroke, LEGEND_W,
};
use super::map_plot::{colour_bar, diverging, COLOR_NO_GAIT};
use super::style::{
    LegendLayout, PlotError, COLOR_BLACK, COLOR_BLUE, COLOR_PURPLE, COLOR_VERMILLION,
};

/// Size of a walker's `map.png` \[px\].
pub(crate) const WALKER_MAP_SIZE: (u32, u32) = (2200, 1500);

/// Width of the colour bar with its labels \[px\].
const BAR_W: i32 = 200;

/// One grid point of the map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum MapCell {
    /// No gait there.
    NoGait,
    /// A gait.
    Gait {
        /// The modulus of its largest multiplier.
        largest: f64,
        /// Its heel strike would keep double support (`lambda_I4 >= 0`).
        keeps_double_support: bool,
    },
}

/// What a walker's map figure shows.
#[derive(Debug, Clone)]
pub(crate) struct WalkerMapFigure {
    /// Title.
    pub title: String,
    /// X axis description with unit.
    pub x_label: String,
    /// Y axis description with unit.
    pub y_label: String,
    /// The `x` values (cell centres).
    pub xs: Vec<f64>,
    /// The `y` values.
    pub ys: Vec<f64>,
    /// `cells[iy][ix]` (a row cut short by Ctrl-C is shorter).
    pub cells: Vec<Vec<MapCell>>,
    /// The changes of stability along the rows: `(kind, x, y)` (`x` not finite where the bisection failed).
    pub thresholds: Vec<(&'static str, f64, f64)>,
}

/// The colour and legend text of a kind of threshold.
fn threshold_style(kind: &str) -> (RGBColor, &'static str) {
    match kind {
        "period_doubling" => (COLOR_VERMILLION, "period doubling (bisected)"),
        "neimark_sacker" => (COLOR_PURPLE, "Neimark-Sacker (bisected)"),
        _ => (COLOR_BLUE, "fold (bisected)"),
    }
}

impl WalkerMapFigure {
    /// The scale of the multiplier's modulus: the values present, with 1 on it.
    fn scale(&self) -> std::ops::Range<f64> {
        let values = self.cells.iter().flatten().filter_map(|c| match c {
            MapCell::Gait { largest, .. } => Some(*largest),
            MapCell::NoGait => None,
        });
        super::chart::finite_range(values).map_or(0.0..2.0, |r| r.start.min(1.0)..r.end.max(1.0))
    }

    /// The threshold lines: per kind, the `k`-th threshold of every row joined from row to row (broken where a
    /// row has no `k`-th).
    fn curves(&self) -> Vec<Curve> {
        let mut kinds: Vec<&str> = self.thresholds.iter().map(|t| t.0).collect();
        kinds.sort_unstable();
        kinds.dedup();
        let mut curves = Vec::new();
        for kind in kinds {
            let (color, label) = threshold_style(kind);
            let per_row = |y: f64| -> Vec<f64> {
                self.thresholds
                    .iter()
                    .filter(|t| t.0 == kind && t.2 == y)
                    .map(|t| t.1)
                    .collect()
            };
            let most = self.ys.iter().map(|&y| per_row(y).len()).max().unwrap_or(0);
            for k in 0..most {
                let points = self
                    .ys
                    .iter()
                    .map(|&y| (per_row(y).get(k).copied().unwrap_or(f64::NAN), y))
                    .collect();
                curves.push(Curve {
                    label: label.to_string(),
                    color,
                    stroke: Stroke::Markers,
                    points,
                });
            }
        }
        curves
    }

    /// The cells on `plot`, coloured on `scale`, with a dot where double support would be kept.
    fn draw_cells<DB: DrawingBackend>(
        &self,
        plot: &PlotArea<DB>,
        scale: &std::ops::Range<f64>,
    ) -> DrawResult<DB> {
        let (ex, ey) = (edges(&self.xs), edges(&self.ys));
        let shifted = (scale.start - 1.0)..(scale.end - 1.0);
        for (iy, row) in self.cells.iter().enumerate() {
            for (ix, cell) in row.iter().enumerate() {
                let color = match cell {
                    MapCell::Gait { largest, .. } if largest.is_finite() => {
                        diverging(largest - 1.0, &shifted)
                    }
                    _ => COLOR_NO_GAIT,
                };
                let (a, b) = (
                    plot.rel((ex[ix], ey[iy + 1])),
                    plot.rel((ex[ix + 1], ey[iy])),
                );
                plot.clip.draw_rect(&plot.area, [a, b], color.filled())?;
            }
        }
        for (iy, row) in self.cells.iter().enumerate() {
            for (ix, cell) in row.iter().enumerate() {
                if let MapCell::Gait {
                    keeps_double_support: true,
                    ..
                } = cell
                {
                    let c = plot.rel((self.xs[ix], self.ys[iy]));
                    plot.clip
                        .draw_circle(&plot.area, c, 4, COLOR_BLACK.filled())?;
                }
            }
        }
        Ok(())
    }

    /// The legend: the threshold kinds, stable, unstable, no gait, and the double-support dot if present.
    fn legend<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        curves: &[Curve],
        at: (i32, i32),
    ) -> DrawResult<DB> {
        let mut rows: Vec<LegendRow> = Vec::new();
        let mut seen: Vec<&str> = Vec::new();
        for c in curves {
            if seen.contains(&c.label.as_str()) {
                continue;
            }
            seen.push(&c.label);
            rows.push(LegendRow {
                sample: Sample::Line {
                    color: c.color,
                    stroke: c.stroke,
                    width: 3,
                    marker: Some((Marker::Circle, 6)),
                },
                label: Label::Plain(&c.label),
            });
        }
        let scale = self.scale();
        let shifted = (scale.start - 1.0)..(scale.end - 1.0);
        let swatches = [
            (diverging(shifted.start, &shifted), "stable gait (|λ| < 1)"),
            (diverging(shifted.end, &shifted), "unstable gait (|λ| > 1)"),
            (COLOR_NO_GAIT, "no gait"),
        ];
        for (color, label) in swatches {
            rows.push(LegendRow {
                sample: Sample::Swatch(color),
                label: Label::Plain(label),
            });
        }
        let kept = self.cells.iter().flatten().any(|c| {
            matches!(
                c,
                MapCell::Gait {
                    keeps_double_support: true,
                    ..
                }
            )
        });
        if kept {
            rows.push(LegendRow {
                sample: Sample::Line {
                    color: WHITE,
                    stroke: Stroke::Solid,
                    width: 0,
                    marker: Some((Marker::Circle, 4)),
                },
                label: Label::Plain("dot: λI4 ≥ 0"),
            });
        }
        let layout = LegendLayout::new(12, 44, 10, 34, 5);
        draw_legend_rows(area, &rows, &layout, super::chart::LEGEND_FONT, at)
    }
}

impl Figure for WalkerMapFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let area = titled(root, &self.title)?;
        let (w, h) = area.dim_in_pixel();
        let (w, h) = (w as i32, h as i32);
        let right = LEGEND_W + 120 + BAR_W;
        let sub = area.clone().shrink((0, 0), (w - right, h));
        let (ex, ey) = (edges(&self.xs), edges(&self.ys));
        let axes = Axes {
            x: span(&ex),
            y: span(&ey),
            x_label: Some(&self.x_label),
            y_label: &self.y_label,
            x_integer: false,
        };
        let plot = PlotArea::new(&sub, &axes, &super::chart::RUN_AXES)?;
        let scale = self.scale();
        self.draw_cells(&plot, &scale)?;
        let curves = self.curves();
        plot.draw_curves(&curves)?;
        plot.draw_outline()?;
        let base = area.get_base_pixel();
        let (top, bottom) = (plot.py.start - base.1 + 40, plot.py.end - base.1);
        colour_bar(
            &area,
            (w - right + 30, top, bottom),
            &scale,
            1.0,
            "|λ| largest",
        )?;
        self.legend(&area, &curves, (w - LEGEND_W - 100, top))
    }
}

/// Write the walker's map figure as a PNG at `png`.
pub(crate) fn write_walker_map_figure(
    figure: &WalkerMapFigure,
    png: &Path,
) -> Result<(), PlotError> {
    if figure.xs.is_empty() || figure.ys.is_empty() {
        return Err(PlotError::Empty("the map has no points".to_string()));
    }
    write_png(figure, png, WALKER_MAP_SIZE)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A figure with every kind of cell and a threshold line is drawn at its size.
    #[test]
    fn writes_a_png() {
        let dir = tempfile::tempdir().unwrap();
        let gait = |largest, keeps_double_support| MapCell::Gait {
            largest,
            keeps_double_support,
        };
        let figure = WalkerMapFigure {
            title: "test".to_string(),
            x_label: "slope [rad]".to_string(),
            y_label: "hip_mass [kg]".to_string(),
            xs: vec![0.04, 0.05, 0.06],
            ys: vec![5.0, 10.0],
            cells: vec![
                vec![gait(0.5, false), gait(1.5, true), MapCell::NoGait],
                vec![gait(0.7, false), gait(0.9, false)],
            ],
            thresholds: vec![
                ("period_doubling", 0.045, 5.0),
                ("period_doubling", 0.055, 10.0),
            ],
        };
        let png = dir.path().join("map.png");
        write_walker_map_figure(&figure, &png).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(super::super::style::png_size(&bytes), Some(WALKER_MAP_SIZE));
        assert_eq!(figure.curves().len(), 1);
        assert_eq!(figure.curves()[0].points[1], (0.055, 10.0));
    }
}
