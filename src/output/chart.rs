//! The panel, axis and legend drawing every figure shares: a chart's axes and plotting area ([`PlotArea`]:
//! mesh, shading, vertical marks, curves, frame), markers, dashed lines, legend boxes ([`draw_legend_rows`]),
//! titles, and panels of curves stacked on one x axis for the run figures (`run.png`, `steps.png`). Fig. 2
//! (`fig2.png`) draws with the same code at its own proportions ([`AxisStyle`]), and the run figures share
//! its look (bundled font, units on every axis).

use std::ops::Range;
use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::style::{
    draw_box, draw_rich, font, house_mesh, padded, rich_width, tick_label, LegendLayout, PlotError,
    Seg, COLOR_MARK,
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

/// Proportions of a chart's axes \[px\]: fonts, the room for tick labels and descriptions, and how many
/// ticks to label.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisStyle {
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
pub const RUN_AXES: AxisStyle = AxisStyle {
    tick_font: TICK_FONT,
    axis_font: AXIS_FONT,
    y_label_area: Y_LABEL_AREA,
    x_label_area: X_LABEL_AREA,
    bare_x_area: 12,
    y_labels: 5,
    margin_right: 0,
    min_band_px: MIN_BAND_PX,
};

/// Dash and gap lengths of [`dashed`] lines \[px\].
pub const DASH_GAP: (f64, f64) = (12.0, 8.0);

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

/// Draws a dashed polyline in pixel coordinates of `area` ([`DASH_GAP`] pattern).
pub fn dashed<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    pts: &[(i32, i32)],
    style: ShapeStyle,
) -> DrawResult<DB> {
    dashed_with(area, pts, style, DASH_GAP)
}

/// Draws a dashed polyline in pixel coordinates of `area`, with dashes of `dash` and gaps of `gap` pixels.
pub fn dashed_with<DB: DrawingBackend>(
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

/// The shape of a marker.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Marker {
    /// A disc.
    Circle,
    /// A triangle pointing up.
    Triangle,
}

/// Draws a marker of size `r` at `at`, filled with `color` or (`hollow`) white with a `color` outline.
pub fn draw_marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    at: (i32, i32),
    shape: Marker,
    color: RGBColor,
    hollow: bool,
    r: i32,
) -> DrawResult<DB> {
    match shape {
        Marker::Circle => {
            if hollow {
                area.draw(&Circle::new(at, r, WHITE.filled()))?;
                area.draw(&Circle::new(at, r, color.stroke_width(2)))?;
            } else {
                area.draw(&Circle::new(at, r, color.filled()))?;
            }
        }
        Marker::Triangle => {
            let s = r + 2;
            let h = (s as f64 * 0.87).round() as i32;
            let pts = vec![
                (at.0, at.1 - s),
                (at.0 - h, at.1 + s / 2),
                (at.0 + h, at.1 + s / 2),
            ];
            if hollow {
                area.draw(&Polygon::new(pts.clone(), WHITE.filled()))?;
                let mut closed = pts.clone();
                closed.push(pts[0]);
                area.draw(&PathElement::new(closed, color.stroke_width(2)))?;
            } else {
                area.draw(&Polygon::new(pts, color.filled()))?;
            }
        }
    }
    Ok(())
}

/// What a legend row shows left of its text.
#[derive(Debug, Clone, PartialEq)]
pub enum Sample {
    /// A line of `width` pixels in `stroke`, with a filled marker `(shape, size)` in its middle if any.
    Line {
        /// Colour.
        color: RGBColor,
        /// Dashed or solid (a solid line for [`Stroke::Markers`]).
        stroke: Stroke,
        /// Line width \[px\].
        width: u32,
        /// Marker in the middle of the line.
        marker: Option<(Marker, i32)>,
    },
    /// A framed box filled with the colour.
    Swatch(RGBColor),
    /// Hollow markers `(shape, colour)` of size `r` spread evenly over the sample's width.
    Hollow {
        /// The markers, left to right.
        markers: Vec<(Marker, RGBColor)>,
        /// Their size \[px\].
        r: i32,
    },
}

/// The text of a legend row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Label<'a> {
    /// Plain text, centred on the row.
    Plain(&'a str),
    /// Rich text (subscripts), its line box centred on the row.
    Rich(&'a [Seg]),
}

impl Label<'_> {
    /// Width at font size `size` \[px\].
    fn width<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        size: f64,
    ) -> Result<i32, DrawingAreaErrorKind<DB::ErrorType>> {
        match self {
            Label::Plain(t) => Ok(root.estimate_text_size(t, &font(size))?.0 as i32),
            Label::Rich(segs) => rich_width(root, segs, size),
        }
    }
}

/// One row of a legend: a sample and its text.
#[derive(Debug, Clone, PartialEq)]
pub struct LegendRow<'a> {
    /// What stands left of the text.
    pub sample: Sample,
    /// The text.
    pub label: Label<'a>,
}

/// Draws a legend box at `(x0, y0)` with `rows` in `layout`, texts at font size `size`.
pub fn draw_legend_rows<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[LegendRow],
    layout: &LegendLayout,
    size: f64,
    (x0, y0): (i32, i32),
) -> DrawResult<DB> {
    if rows.is_empty() {
        return Ok(());
    }
    let mut text_w = 0;
    for row in rows {
        text_w = text_w.max(row.label.width(root, size)?);
    }
    let sample_w = layout.sample_w;
    let (sx, tx, mut y) = layout.frame(root, (x0, y0), rows.len(), text_w)?;
    for row in rows {
        match &row.sample {
            Sample::Line {
                color,
                stroke,
                width,
                marker,
            } => {
                let line = [(sx, y), (sx + sample_w, y)];
                match stroke {
                    Stroke::Dashed => dashed(root, &line, color.stroke_width(*width))?,
                    Stroke::Solid | Stroke::Markers => {
                        root.draw(&PathElement::new(line.to_vec(), color.stroke_width(*width)))?
                    }
                }
                if let Some((shape, r)) = marker {
                    draw_marker(root, (sx + sample_w / 2, y), *shape, *color, false, *r)?;
                }
            }
            Sample::Swatch(color) => {
                draw_box(root, [(sx, y - 11), (sx + sample_w, y + 11)], *color)?
            }
            Sample::Hollow { markers, r } => {
                let step = sample_w / (markers.len() as i32 + 1);
                for (k, &(shape, color)) in markers.iter().enumerate() {
                    draw_marker(
                        root,
                        (sx + step * (k as i32 + 1), y),
                        shape,
                        color,
                        true,
                        *r,
                    )?;
                }
            }
        }
        match row.label {
            Label::Plain(text) => root.draw(&Text::new(
                text,
                (tx, y),
                font(size).pos(Pos::new(HPos::Left, VPos::Center)),
            ))?,
            Label::Rich(segs) => draw_rich(root, segs, (tx, y - size as i32 / 2), size, false)?,
        }
        y += layout.line;
    }
    Ok(())
}

/// Draws a legend box with one entry per curve (and extra `(label, colour)` swatches) at `(x0, y0)`.
pub fn draw_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    curves: &[Curve],
    swatches: &[(String, RGBColor)],
    at: (i32, i32),
) -> DrawResult<DB> {
    let lines = curves.iter().map(|c| LegendRow {
        sample: Sample::Line {
            color: c.color,
            stroke: c.stroke,
            width: 3,
            marker: (c.stroke == Stroke::Markers).then_some((Marker::Circle, 6)),
        },
        label: Label::Plain(&c.label),
    });
    let boxes = swatches.iter().map(|(label, color)| LegendRow {
        sample: Sample::Swatch(*color),
        label: Label::Plain(label),
    });
    let rows: Vec<LegendRow> = lines.chain(boxes).collect();
    let layout = LegendLayout::new(12, 44, 10, 34, 5);
    draw_legend_rows(root, &rows, &layout, LEGEND_FONT, at)
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

/// A chart whose axes are drawn: its plotting area and the map from data to pixels.
pub struct PlotArea<'a, DB: DrawingBackend> {
    chart: ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    /// The plotting area; it is drawn on in pixels from its top left corner ([`PlotArea::rel`]).
    pub area: DrawingArea<DB, Shift>,
    /// Its pixel columns on the canvas.
    pub px: Range<i32>,
    /// Its pixel rows on the canvas.
    pub py: Range<i32>,
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
    pub fn new(
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
            area: plot,
            px,
            py,
            x: x.clone(),
            y: y.clone(),
            min_band_px: style.min_band_px,
        })
    }

    /// The canvas pixel of the data point `p`.
    pub fn to_px(&self, p: (f64, f64)) -> (i32, i32) {
        self.chart.backend_coord(&p)
    }

    /// The pixel of the data point `p` relative to the plotting area (what drawing on [`PlotArea::area`]
    /// takes).
    pub fn rel(&self, p: (f64, f64)) -> (i32, i32) {
        let (a, b) = self.to_px(p);
        (a - self.px.start, b - self.py.start)
    }

    /// Shades `bands` (clipped to the x range, at least [`AxisStyle::min_band_px`] wide).
    pub fn draw_bands(&self, bands: &[Band]) -> DrawResult<DB> {
        let (x, y) = (&self.x, &self.y);
        for b in bands {
            let (lo, hi) = (b.from.max(x.start), b.to.min(x.end));
            if hi > lo {
                let (mut a, c) = (self.rel((lo, y.end)), self.rel((hi, y.start)));
                a.0 = a.0.min(c.0 - self.min_band_px);
                self.area.draw(&Rectangle::new([a, c], b.color.filled()))?;
            }
        }
        Ok(())
    }

    /// Draws dashed grey vertical lines at the x values `marks` inside the range.
    pub fn draw_marks(&self, marks: &[f64]) -> DrawResult<DB> {
        let (x, y) = (&self.x, &self.y);
        for &m in marks.iter().filter(|m| x.contains(m)) {
            dashed(
                &self.area,
                &[self.rel((m, y.end)), self.rel((m, y.start))],
                COLOR_MARK.stroke_width(2),
            )?;
        }
        Ok(())
    }

    /// Draws `curves` (lines 3 px wide, markers of size 6), each broken where a value is not finite.
    pub fn draw_curves(&self, curves: &[Curve]) -> DrawResult<DB> {
        for c in curves {
            for run in runs(&c.points) {
                let pts: Vec<(i32, i32)> = run.iter().map(|&p| self.rel(p)).collect();
                match c.stroke {
                    Stroke::Dashed => dashed(&self.area, &pts, c.color.stroke_width(3))?,
                    Stroke::Solid | Stroke::Markers => self
                        .area
                        .draw(&PathElement::new(pts.clone(), c.color.stroke_width(3)))?,
                }
                if c.stroke == Stroke::Markers {
                    for p in pts {
                        draw_marker(&self.area, p, Marker::Circle, c.color, false, 6)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// Frames the plotting area in black (the axes cover its left and bottom sides).
    pub fn draw_outline(&self) -> DrawResult<DB> {
        let (px, py) = (&self.px, &self.py);
        self.area.draw(&Rectangle::new(
            [(0, 0), (px.end - px.start - 1, py.end - py.start - 1)],
            BLACK.stroke_width(2),
        ))
    }
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
    let plot = PlotArea::new(area, axes, &RUN_AXES)?;
    plot.draw_bands(bands)?;
    plot.draw_marks(marks)?;
    plot.draw_curves(curves)?;
    plot.draw_outline()?;
    Ok((plot.px, plot.py))
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

/// The font size, at most `max`, at which `title` fits the width of `root` within [`MARGIN`] on each side.
pub fn title_size<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    max: f64,
) -> Result<f64, DrawingAreaErrorKind<DB::ErrorType>> {
    let (w, _) = root.dim_in_pixel();
    let (tw, _) = root.estimate_text_size(title, &font(max))?;
    Ok(max * (f64::from(w as i32 - 2 * MARGIN) / f64::from(tw.max(1))).min(1.0))
}

/// Draws `title` centred at the top of `root` and returns the area below it.
pub fn titled<DB: DrawingBackend>(
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
