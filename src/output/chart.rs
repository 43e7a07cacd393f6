//! Panels of curves sharing one x axis, for the run figures (`run.png`, `steps.png`): the common layout,
//! axes, shading, vertical marks and legends, in the look of Fig. 2 (bundled font, units on every axis).

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::style::{
    draw_box, font, house_mesh, padded, tick_label, LegendLayout, PlotError, COLOR_MARK,
};

/// Font sizes and layout of the run figures \[px\].
pub const TITLE_FONT: f64 = 38.0;
/// Axis descriptions.
pub const AXIS_FONT: f64 = 30.0;
/// Tick labels.
pub const TICK_FONT: f64 = 24.0;
/// Legend entries.
pub const LEGEND_FONT: f64 = 24.0;
/// Outer margin.
pub const MARGIN: i32 = 24;
/// Width reserved right of each panel for its legend.
pub const LEGEND_W: i32 = 280;
const Y_LABEL_AREA: i32 = 150;
const X_LABEL_AREA: i32 = 90;
const BOTTOM_PAD: i32 = 12;
/// Narrowest shaded band \[px\].
const MIN_BAND_PX: i32 = 3;

/// How a curve is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stroke {
    /// A solid line.
    Solid,
    /// A dashed line.
    Dashed,
    /// A solid line with a marker on every point.
    Markers,
}

/// One curve; a non-finite value breaks the line.
#[derive(Debug, Clone)]
pub struct Curve {
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
pub struct Band {
    /// Start.
    pub from: f64,
    /// End.
    pub to: f64,
    /// Fill colour.
    pub color: RGBColor,
}

/// One panel: curves against the shared x.
#[derive(Debug, Clone)]
pub struct Panel {
    /// Y axis description with unit, e.g. `"θ [rad]"`.
    pub y_label: String,
    /// The curves.
    pub curves: Vec<Curve>,
}

/// Panels stacked on a shared x axis.
#[derive(Debug, Clone)]
pub struct Stack<'a> {
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
pub type PixelRect = (Range<i32>, Range<i32>);

/// The result of a drawing call on backend `DB`.
pub type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

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
pub fn finite_range(values: impl Iterator<Item = f64>) -> Option<Range<f64>> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    lo.is_finite().then_some(lo..hi)
}

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

/// Draws a dashed polyline in pixel coordinates of `area`.
pub fn dashed<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    pts: &[(i32, i32)],
    style: ShapeStyle,
) -> DrawResult<DB> {
    const DASH: f64 = 12.0;
    const GAP: f64 = 8.0;
    let mut pen = 0.0; // distance along the dash pattern
    for seg in pts.windows(2) {
        let (a, b) = (seg[0], seg[1]);
        let (dx, dy) = (f64::from(b.0 - a.0), f64::from(b.1 - a.1));
        let len = dx.hypot(dy);
        let mut s = 0.0;
        while s < len {
            let phase = pen % (DASH + GAP);
            let step = if phase < DASH {
                DASH - phase
            } else {
                DASH + GAP - phase
            }
            .min(len - s);
            if phase < DASH {
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

/// Draws a legend box with one entry per curve (and extra `(label, colour)` swatches) at `(x0, y0)`.
pub fn draw_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    curves: &[Curve],
    swatches: &[(String, RGBColor)],
    (x0, y0): (i32, i32),
) -> DrawResult<DB> {
    const LINE: i32 = 34;
    const SAMPLE_W: i32 = 44;
    let entries = curves.len() + swatches.len();
    if entries == 0 {
        return Ok(());
    }
    let mut text_w = 0;
    for label in curves
        .iter()
        .map(|c| &c.label)
        .chain(swatches.iter().map(|s| &s.0))
    {
        text_w = text_w.max(root.estimate_text_size(label, &font(LEGEND_FONT))?.0 as i32);
    }
    let layout = LegendLayout::new(12, SAMPLE_W, 10, LINE, 5);
    let (sx, tx, mut y) = layout.frame(root, (x0, y0), entries, text_w)?;
    for c in curves {
        let line = [(sx, y), (sx + SAMPLE_W, y)];
        match c.stroke {
            Stroke::Dashed => dashed(root, &line, c.color.stroke_width(3))?,
            Stroke::Solid | Stroke::Markers => {
                root.draw(&PathElement::new(line.to_vec(), c.color.stroke_width(3)))?
            }
        }
        if c.stroke == Stroke::Markers {
            root.draw(&Circle::new((sx + SAMPLE_W / 2, y), 6, c.color.filled()))?;
        }
        root.draw(&Text::new(
            c.label.as_str(),
            (tx, y),
            font(LEGEND_FONT).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        y += LINE;
    }
    for (label, color) in swatches {
        draw_box(root, [(sx, y - 11), (sx + SAMPLE_W, y + 11)], *color)?;
        root.draw(&Text::new(
            label.as_str(),
            (tx, y),
            font(LEGEND_FONT).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        y += LINE;
    }
    Ok(())
}

/// The axes of one chart.
#[derive(Debug, Clone)]
pub struct Axes<'a> {
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

/// Draws `curves` over `bands` and the dashed vertical `marks` on one chart area; returns the plot's pixel
/// rectangle.
pub fn draw_axes_and_curves<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    axes: &Axes,
    curves: &[Curve],
    bands: &[Band],
    marks: &[f64],
) -> Result<PixelRect, DrawingAreaErrorKind<DB::ErrorType>> {
    let (x, y, x_label, y_label) = (&axes.x, &axes.y, axes.x_label, axes.y_label);
    let mut chart = ChartBuilder::on(area)
        .x_label_area_size(if x_label.is_some() { X_LABEL_AREA } else { 12 })
        .y_label_area_size(Y_LABEL_AREA)
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
        house_mesh(&mut mesh, TICK_FONT, AXIS_FONT);
        mesh.y_desc(y_label)
            .y_label_formatter(&y_fmt)
            .x_labels(10)
            .y_labels(5);
        match x_label {
            Some(label) => mesh.x_desc(label).x_label_formatter(&x_fmt),
            None => mesh.x_label_formatter(&no_fmt),
        };
        mesh.draw()?;
    }
    let (px, py) = chart.plotting_area().get_pixel_range();
    let plot = chart.plotting_area().strip_coord_spec();
    let rel = |p: (f64, f64)| {
        let (a, b) = chart.backend_coord(&p);
        (a - px.start, b - py.start)
    };
    for b in bands {
        let (lo, hi) = (b.from.max(x.start), b.to.min(x.end));
        if hi > lo {
            // At least MIN_BAND_PX wide, so that a short phase stays visible on a long run.
            let (mut a, c) = (rel((lo, y.end)), rel((hi, y.start)));
            a.0 = a.0.min(c.0 - MIN_BAND_PX);
            plot.draw(&Rectangle::new([a, c], b.color.filled()))?;
        }
    }
    for &m in marks.iter().filter(|m| x.contains(m)) {
        dashed(
            &plot,
            &[rel((m, y.end)), rel((m, y.start))],
            COLOR_MARK.stroke_width(2),
        )?;
    }
    for c in curves {
        for run in runs(&c.points) {
            let pts: Vec<(i32, i32)> = run.iter().map(|&p| rel(p)).collect();
            match c.stroke {
                Stroke::Dashed => dashed(&plot, &pts, c.color.stroke_width(3))?,
                Stroke::Solid | Stroke::Markers => {
                    plot.draw(&PathElement::new(pts.clone(), c.color.stroke_width(3)))?
                }
            }
            if c.stroke == Stroke::Markers {
                for p in pts {
                    plot.draw(&Circle::new(p, 6, c.color.filled()))?;
                }
            }
        }
    }
    plot.draw(&Rectangle::new(
        [(0, 0), (px.end - px.start - 1, py.end - py.start - 1)],
        BLACK.stroke_width(2),
    ))?;
    Ok((px, py))
}

/// Draws the stack into `area`: the panels share the height equally and the x axis is labelled on the
/// bottom panel only; each panel's legend stands right of it.
pub fn draw_stack<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    stack: &Stack,
) -> DrawResult<DB> {
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
        let (_, y_px) = draw_axes_and_curves(&sub, &axes, &panel.curves, stack.bands, stack.marks)?;
        let base = area.get_base_pixel();
        draw_legend(
            area,
            &panel.curves,
            &[],
            (w - LEGEND_W + 16, y_px.start - base.1 + 4),
        )?;
    }
    Ok(())
}

/// Draws `title` centred at the top of `root` and returns the area below it.
pub fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<DrawingArea<DB, Shift>, DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let (w, h) = root.dim_in_pixel();
    let (tw, _) = root.estimate_text_size(title, &font(TITLE_FONT))?;
    let size = TITLE_FONT * (f64::from(w as i32 - 2 * MARGIN) / f64::from(tw.max(1))).min(1.0);
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
pub trait Figure {
    /// Draws the whole figure on `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB>;
}

/// Draws `figure` as an SVG and a PNG of `size` pixels.
pub fn write_svg_png(
    figure: &impl Figure,
    svg: &Path,
    png: &Path,
    size: (u32, u32),
) -> Result<(), PlotError> {
    super::style::require_font(svg)?;
    {
        let root = SVGBackend::new(svg, size).into_drawing_area();
        figure
            .draw(&root)
            .map_err(|e| PlotError::draw_at(svg)(e.to_string()))?;
        root.present()
            .map_err(|e| PlotError::draw_at(svg)(e.to_string()))?;
    }
    write_png(figure, png, size)
}

/// Write `figure` as a PNG only (figures with tens of thousands of marks, whose SVG would be large).
pub fn write_png(figure: &impl Figure, png: &Path, size: (u32, u32)) -> Result<(), PlotError> {
    super::style::require_font(png)?;
    let root = BitMapBackend::new(png, size).into_drawing_area();
    figure
        .draw(&root)
        .map_err(|e| PlotError::draw_at(png)(e.to_string()))?;
    root.present()
        .map_err(|e| PlotError::draw_at(png)(e.to_string()))
}
