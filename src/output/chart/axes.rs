//! A chart's axes and plotting area: the mesh in a given [`AxisStyle`], then shading, vertical marks, curves
//! and the frame drawn in data coordinates ([`PlotArea`]), each clipped to the plotting area ([`Clip`]).

use std::ops::Range;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::super::style::{house_mesh, tick_label, COLOR_MARK};
use super::{
    Band, Clip, Curve, DrawResult, Marker, PixelRect, Stroke, AXIS_FONT, DASH_GAP, MIN_BAND_PX,
    TICK_FONT, X_LABEL_AREA, Y_LABEL_AREA,
};

/// Proportions of a chart's axes \[px\]: fonts, the room for tick labels and descriptions, and how many
/// ticks to label.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AxisStyle {
    /// Tick label font size.
    pub tick_font: f64,
    /// Axis description font size.
    pub axis_font: f64,
    /// Width left of the plot for the y tick labels and description.
    pub y_label_area: i32,
    /// Height below the plot for the x tick labels and description.
    pub x_label_area: i32,
    /// Height below a plot whose x axis is not labelled (a panel above another).
    pub bare_x_area: i32,
    /// Number of y ticks plotters aims at.
    pub y_labels: usize,
    /// Room right of the plot (for a legend).
    pub margin_right: i32,
    /// Narrowest shaded band (so that a short stretch stays visible on a long axis).
    pub min_band_px: i32,
}

/// The axes of the run figures (`run.png`, `steps.png`) and the orbit and basin figures.
pub(crate) const RUN_AXES: AxisStyle = AxisStyle {
    tick_font: TICK_FONT,
    axis_font: AXIS_FONT,
    y_label_area: Y_LABEL_AREA,
    x_label_area: X_LABEL_AREA,
    bare_x_area: 12,
    y_labels: 5,
    margin_right: 0,
    min_band_px: MIN_BAND_PX,
};

/// Runs of consecutive finite points.
fn runs(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for &p in points {
        if p.0.is_finite() && p.1.is_finite() {
            if let Some(r) = out.last_mut() {
                r.push(p);
            }
        } else if out.last().is_some_and(|r| !r.is_empty()) {
            out.push(Vec::new());
        }
    }
    out.retain(|r| !r.is_empty());
    out
}

/// The axes of one chart.
#[derive(Debug, Clone)]
pub(crate) struct Axes<'a> {
    /// X range.
    pub x: Range<f64>,
    /// Y range.
    pub y: Range<f64>,
    /// X axis description with unit; `None`: no x tick labels (a panel above another).
    pub x_label: Option<&'a str>,
    /// Y axis description with unit.
    pub y_label: &'a str,
    /// Label only whole numbers on the x axis (step numbers).
    pub x_integer: bool,
}

/// A chart whose axes are drawn: its plotting area and the map from data to pixels.
pub(crate) struct PlotArea<'a, DB: DrawingBackend> {
    chart: ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    /// The plotting area; it is drawn on in pixels from its top left corner ([`PlotArea::rel`]).
    pub area: DrawingArea<DB, Shift>,
    /// Its pixel columns on the canvas.
    pub px: Range<i32>,
    /// Its pixel rows on the canvas.
    pub py: Range<i32>,
    /// The plotting area in the pixels of [`PlotArea::area`]: whatever is drawn there goes through it.
    pub clip: Clip,
    x: Range<f64>,
    y: Range<f64>,
    min_band_px: i32,
}

impl<'a, DB: DrawingBackend> PlotArea<'a, DB> {
    /// Draws the axes of `axes` in `style` on `area`: grid, ticks, tick labels and descriptions (an empty
    /// `y_label` draws none: the caller writes its own).
    ///
    /// # Errors
    /// When the backend fails.
    pub(crate) fn new(
        area: &'a DrawingArea<DB, Shift>,
        axes: &Axes,
        style: &AxisStyle,
    ) -> Result<Self, DrawingAreaErrorKind<DB::ErrorType>> {
        let (x, y, x_label, y_label) = (&axes.x, &axes.y, axes.x_label, axes.y_label);
        let mut chart = ChartBuilder::on(area)
            .margin_right(style.margin_right)
            .x_label_area_size(if x_label.is_some() {
                style.x_label_area
            } else {
                style.bare_x_area
            })
            .y_label_area_size(style.y_label_area)
            .build_cartesian_2d(x.clone(), y.clone())?;
        let y_fmt = |v: &f64| tick_label(*v, y);
        let x_fmt = |v: &f64| match (axes.x_integer, v.fract() == 0.0) {
            (true, true) => format!("{v:.0}"),
            (true, false) => String::new(),
            (false, _) => tick_label(*v, x),
        };
        let no_fmt = |_: &f64| String::new();
        {
            let mut mesh = chart.configure_mesh();
            house_mesh(&mut mesh, style.tick_font, style.axis_font);
            mesh.y_label_formatter(&y_fmt)
                .x_labels(10)
                .y_labels(style.y_labels);
            if !y_label.is_empty() {
                mesh.y_desc(y_label);
            }
            match x_label {
                Some(label) => mesh.x_desc(label).x_label_formatter(&x_fmt),
                None => mesh.x_label_formatter(&no_fmt),
            };
            mesh.draw()?;
        }
        let (px, py) = chart.plotting_area().get_pixel_range();
        let plot = chart.plotting_area().strip_coord_spec();
        Ok(PlotArea {
            chart,
            clip: Clip::of_area(&plot),
            area: plot,
            px,
            py,
            x: x.clone(),
            y: y.clone(),
            min_band_px: style.min_band_px,
        })
    }

    /// The canvas pixel of the data point `p`.
    pub(crate) fn to_px(&self, p: (f64, f64)) -> (i32, i32) {
        self.chart.backend_coord(&p)
    }

    /// The pixel of the data point `p` relative to the plotting area (what drawing on [`PlotArea::area`]
    /// takes).
    pub(crate) fn rel(&self, p: (f64, f64)) -> (i32, i32) {
        let (a, b) = self.to_px(p);
        (a - self.px.start, b - self.py.start)
    }

    /// Shades `bands` (at least [`AxisStyle::min_band_px`] wide, clipped to the plotting area).
    pub fn draw_bands(&self, bands: &[Band]) -> DrawResult<DB> {
        let (x, y) = (&self.x, &self.y);
        for b in bands {
            let (lo, hi) = (b.from.max(x.start), b.to.min(x.end));
            if hi > lo {
                let (mut a, c) = (self.rel((lo, y.end)), self.rel((hi, y.start)));
                a.0 = a.0.min(c.0 - self.min_band_px);
                self.clip.draw_rect(&self.area, [a, c], b.color.filled())?;
            }
        }
        Ok(())
    }

    /// Draws dashed grey vertical lines at the x values `marks` inside the range.
    pub(crate) fn draw_marks(&self, marks: &[f64]) -> DrawResult<DB> {
        let (x, y) = (&self.x, &self.y);
        for &m in marks.iter().filter(|m| x.contains(m)) {
            self.clip.draw_dashed(
                &self.area,
                &[self.rel((m, y.end)), self.rel((m, y.start))],
                COLOR_MARK.stroke_width(2),
                DASH_GAP,
            )?;
        }
        Ok(())
    }

    /// Draws `curves` (lines 3 px wide, markers of size 6), each broken where a value is not finite and
    /// clipped to the plotting area.
    pub fn draw_curves(&self, curves: &[Curve]) -> DrawResult<DB> {
        for c in curves {
            for run in runs(&c.points) {
                let pts: Vec<(i32, i32)> = run.iter().map(|&p| self.rel(p)).collect();
                let style = c.color.stroke_width(3);
                match c.stroke {
                    Stroke::Dashed => self.clip.draw_dashed(&self.area, &pts, style, DASH_GAP)?,
                    Stroke::Solid | Stroke::Markers => {
                        self.clip.draw_path(&self.area, &pts, style)?
                    }
                }
                if c.stroke == Stroke::Markers {
                    for p in pts {
                        self.clip
                            .draw_marker(&self.area, p, Marker::Circle, c.color, false, 6)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// Frames the plotting area in black (the axes cover its left and bottom sides).
    pub(crate) fn draw_outline(&self) -> DrawResult<DB> {
        let (px, py) = (&self.px, &self.py);
        self.area.draw(&Rectangle::new(
            [(0, 0), (px.end - px.start - 1, py.end - py.start - 1)],
            BLACK.stroke_width(2),
        ))
    }
}

/// Draws `curves` over `bands` and the dashed vertical `marks` on one chart area; returns the plot's pixel
/// rectangle.
pub(crate) fn draw_axes_and_curves<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    axes: &Axes,
    curves: &[Curve],
    bands: &[Band],
    marks: &[f64],
) -> Result<PixelRect, DrawingAreaErrorKind<DB::ErrorType>> {
    let plot = PlotArea::new(area, axes, &RUN_AXES)?;
    plot.draw_bands(bands)?;
    plot.draw_marks(marks)?;
    plot.draw_curves(curves)?;
    plot.draw_outline()?;
    Ok((plot.px, plot.py))
}
