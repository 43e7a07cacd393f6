//! The panel, axis and legend drawing every figure shares: a chart's axes and plotting area ([`PlotArea`]:
//! mesh, shading, vertical marks, curves, frame), markers, dashed lines, legend boxes ([`draw_legend_rows`]),
//! titles, and panels of curves stacked on one x axis for the run figures (`run.png`, `steps.png`). What is
//! drawn inside a plotting area is clipped to it ([`Clip`]). Fig. 2
//! (`fig2.png`) draws with the same code at its own proportions ([`AxisStyle`]), and the run figures share
//! its look (bundled font, units on every axis).

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

mod axes;
mod clip;
mod legend;

pub(crate) use axes::{draw_axes_and_curves, Axes, AxisStyle, PlotArea, RUN_AXES};
pub(crate) use clip::Clip;
pub(crate) use legend::{
    draw_legend, draw_legend_rows, draw_marker, Label, LegendRow, Marker, Sample,
};

use super::style::{font, padded, PlotError};

/// Font sizes and layout of the run figures \[px\].
pub(crate) const TITLE_FONT: f64 = 38.0;
/// Axis descriptions.
pub(crate) const AXIS_FONT: f64 = 30.0;
/// Tick labels.
pub(crate) const TICK_FONT: f64 = 24.0;
/// Legend entries.
pub(crate) const LEGEND_FONT: f64 = 24.0;
/// Outer margin.
pub(crate) const MARGIN: i32 = 24;
/// Width reserved right of each panel for its legend.
pub(crate) const LEGEND_W: i32 = 280;
const Y_LABEL_AREA: i32 = 150;
const X_LABEL_AREA: i32 = 90;
const BOTTOM_PAD: i32 = 12;
/// Narrowest shaded band \[px\].
const MIN_BAND_PX: i32 = 3;

/// Dash and gap lengths of [`dashed`] lines \[px\].
pub(crate) const DASH_GAP: (f64, f64) = (12.0, 8.0);

/// How a curve is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Stroke {
    /// A solid line.
    Solid,
    /// A dashed line.
    Dashed,
    /// A solid line with a marker on every point.
    Markers,
}

/// One curve; a non-finite value breaks the line.
#[derive(Debug, Clone)]
pub(crate) struct Curve {
    /// Legend text.
    pub label: String,
    /// Colour.
    pub color: RGBColor,
    /// Line style.
    pub stroke: Stroke,
    /// Points `(x, y)`.
    pub points: Vec<(f64, f64)>,
}

/// A shaded stretch of the x axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Band {
    /// Start.
    pub from: f64,
    /// End.
    pub to: f64,
    /// Fill colour.
    pub color: RGBColor,
}

/// One panel: curves against the shared x.
#[derive(Debug, Clone)]
pub(crate) struct Panel {
    /// Y axis description with unit, e.g. `"θ [rad]"`.
    pub y_label: String,
    /// The curves.
    pub curves: Vec<Curve>,
}

/// Panels stacked on a shared x axis.
#[derive(Debug, Clone)]
pub(crate) struct Stack<'a> {
    /// X axis description with unit.
    pub x_label: &'a str,
    /// X range.
    pub x: Range<f64>,
    /// Shading behind every panel.
    pub bands: &'a [Band],
    /// Vertical lines through every panel (e.g. touchdowns).
    pub marks: &'a [f64],
    /// The panels, top to bottom.
    pub panels: &'a [Panel],
    /// Label only whole numbers on the x axis.
    pub x_integer: bool,
}

/// Pixel ranges (x, y) of a plotting area on the canvas.
pub(crate) type PixelRect = (Range<i32>, Range<i32>);

/// The pixel, relative to an area whose base pixel is `base`, of a data point on the axes `x`, `y` drawn in
/// the plot rectangle `(px, py)` (what [`draw_axes_and_curves`] returns): the ranges' ends on its last
/// pixels.
pub(crate) fn data_to_px(
    x: Range<f64>,
    y: Range<f64>,
    (px, py): PixelRect,
    base: (i32, i32),
) -> impl Fn((f64, f64)) -> (i32, i32) {
    move |(a, b)| {
        let fx = (a - x.start) / (x.end - x.start);
        let fy = (b - y.start) / (y.end - y.start);
        (
            px.start + (fx * f64::from(px.end - px.start - 1)).round() as i32 - base.0,
            py.end - 1 - (fy * f64::from(py.end - py.start - 1)).round() as i32 - base.1,
        )
    }
}

/// The result of a drawing call on backend `DB`.
pub(crate) type DrawResult<DB> =
    Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// The finite range of the curves' y values, padded.
fn y_range(curves: &[Curve]) -> Range<f64> {
    let (lo, hi) = curves
        .iter()
        .flat_map(|c| c.points.iter())
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        });
    if lo.is_finite() && hi > lo {
        padded(lo, hi, 0.08)
    } else if lo.is_finite() {
        // A single value: a range around it on its own scale.
        let half = (0.1 * lo.abs()).max(f64::MIN_POSITIVE.sqrt());
        (lo - half)..(lo + half)
    } else {
        -1.0..1.0
    }
}

/// The finite range of `values` (`None` if there is none).
pub(crate) fn finite_range(values: impl Iterator<Item = f64>) -> Option<Range<f64>> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    lo.is_finite().then_some(lo..hi)
}

/// Draws a dashed polyline in pixel coordinates of `area` ([`DASH_GAP`] pattern).
pub(crate) fn dashed<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    pts: &[(i32, i32)],
    style: ShapeStyle,
) -> DrawResult<DB> {
    dashed_with(area, pts, style, DASH_GAP)
}

/// Draws a dashed polyline in pixel coordinates of `area`, with dashes of `dash` and gaps of `gap` pixels.
pub(crate) fn dashed_with<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    pts: &[(i32, i32)],
    style: ShapeStyle,
    (dash, gap): (f64, f64),
) -> DrawResult<DB> {
    let mut pen = 0.0; // distance along the dash pattern
    for seg in pts.windows(2) {
        let (a, b) = (seg[0], seg[1]);
        let (dx, dy) = (f64::from(b.0 - a.0), f64::from(b.1 - a.1));
        let len = dx.hypot(dy);
        let mut s = 0.0;
        while s < len {
            let phase = pen % (dash + gap);
            let step = if phase < dash {
                dash - phase
            } else {
                dash + gap - phase
            }
            .min(len - s);
            if phase < dash {
                let at = |u: f64| {
                    (
                        a.0 + (dx * u / len).round() as i32,
                        a.1 + (dy * u / len).round() as i32,
                    )
                };
                area.draw(&PathElement::new(vec![at(s), at(s + step)], style))?;
            }
            s += step;
            pen += step;
        }
    }
    Ok(())
}

/// Draws the stack into `area`: the panels share the height equally and the x axis is labelled on the
/// bottom panel only; each panel's legend stands right of it. Returns the canvas pixels of each panel's
/// plotting area, top to bottom: everything a panel shows is clipped to it.
pub fn draw_stack<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    stack: &Stack,
) -> Result<Vec<PixelRect>, DrawingAreaErrorKind<DB::ErrorType>> {
    let mut rects = Vec::with_capacity(stack.panels.len());
    let (w, h) = area.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    let n = stack.panels.len().max(1) as i32;
    let inner = (h - X_LABEL_AREA - BOTTOM_PAD) / n;
    for (k, panel) in stack.panels.iter().enumerate() {
        let k = k as i32;
        let last = k == n - 1;
        let top = k * inner;
        let height = if last { h - top - BOTTOM_PAD } else { inner };
        let sub = area.clone().shrink((0, top), (w - LEGEND_W, height));
        let axes = Axes {
            x: stack.x.clone(),
            y: y_range(&panel.curves),
            x_label: last.then_some(stack.x_label),
            y_label: &panel.y_label,
            x_integer: stack.x_integer,
        };
        let (x_px, y_px) =
            draw_axes_and_curves(&sub, &axes, &panel.curves, stack.bands, stack.marks)?;
        let base = area.get_base_pixel();
        draw_legend(
            area,
            &panel.curves,
            &[],
            (w - LEGEND_W + 16, y_px.start - base.1 + 4),
        )?;
        rects.push((x_px, y_px));
    }
    Ok(rects)
}

/// The font size, at most `max`, at which `title` fits the width of `root` within [`MARGIN`] on each side.
pub(crate) fn title_size<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    max: f64,
) -> Result<f64, DrawingAreaErrorKind<DB::ErrorType>> {
    let (w, _) = root.dim_in_pixel();
    let (tw, _) = root.estimate_text_size(title, &font(max))?;
    Ok(max * (f64::from(w as i32 - 2 * MARGIN) / f64::from(tw.max(1))).min(1.0))
}

/// Draws `title` centred at the top of `root` and returns the area below it.
pub(crate) fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<DrawingArea<DB, Shift>, DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let (w, h) = root.dim_in_pixel();
    let size = title_size(root, title, TITLE_FONT)?;
    root.draw(&Text::new(
        title,
        (w as i32 / 2, MARGIN),
        font(size).pos(Pos::new(HPos::Center, VPos::Top)),
    ))?;
    let top = MARGIN + TITLE_FONT as i32 + 16;
    Ok(root.clone().shrink(
        (MARGIN, top),
        (w - 2 * MARGIN as u32, h - top as u32 - MARGIN as u32),
    ))
}

/// A figure that can be drawn on any plotters backend.
pub(crate) trait Figure {
    /// Draws the whole figure on `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB>;
}

/// Draws `figure` as an SVG and a PNG of `size` pixels, each written atomically
/// ([`write_atomic`](crate::output::write_atomic)).
pub fn write_svg_png(
    figure: &impl Figure,
    svg: &Path,
    png: &Path,
    size: (u32, u32),
) -> Result<(), PlotError> {
    super::style::require_font(svg)?;
    crate::output::write_atomic(svg, |temp| {
        let root = SVGBackend::new(temp, size).into_drawing_area();
        figure
            .draw(&root)
            .map_err(|e| PlotError::draw_at(svg)(e.to_string()))?;
        root.present()
            .map_err(|e| PlotError::draw_at(svg)(e.to_string()))
    })?;
    write_png(figure, png, size)
}

/// Write `figure` as a PNG only (figures with tens of thousands of marks, whose SVG would be large), atomically.
pub fn write_png(figure: &impl Figure, png: &Path, size: (u32, u32)) -> Result<(), PlotError> {
    super::style::require_font(png)?;
    crate::output::write_atomic(png, |temp| {
        let mut rgb = vec![0u8; 3 * size.0 as usize * size.1 as usize];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
            figure
                .draw(&root)
                .map_err(|e| PlotError::draw_at(png)(e.to_string()))?;
            root.present()
                .map_err(|e| PlotError::draw_at(png)(e.to_string()))?;
        }
        super::style::save_png(temp, &rgb, size).map_err(|e| e.at(png))
    })
    .map_err(|e| e.renamed(&crate::output::temp_path(png), png))
}
