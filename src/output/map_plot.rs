//! The map figure (`map.png`, `map.svg`): heat maps of the gait over two parameters, with the threshold curves
//! drawn over them as lines.
//!
//! Four panels share the axes: `lambda_I4`, `lambda_2+` and `lambda_4+` of the gait at every grid point, on a
//! diverging colour scale that is white at zero (blue below, red above, each side scaled to its own extreme, so
//! the sign is what shows), and the existence of a gait with its impact branch (unstable gaits dotted). Points
//! without a gait are grey. The threshold curves ([`crate::study::map`]) are polylines through refined crossings,
//! drawn with a white halo over every panel; marked points (e.g. the paper's thresholds) are white circles with a
//! label.
//!
//! Text (the bundled DejaVu Sans), colours and axes come from [`super::style`] and `chart`.

use std::ops::Range;
use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::chart::{
    dashed, titled, write_svg_png, Clip, DrawResult, Figure, AXIS_FONT, DASH_GAP, LEGEND_FONT,
    TICK_FONT,
};
use super::style::{
    draw_box, font, house_mesh, tick_label, LegendLayout, PlotError, COLOR_BLACK, COLOR_BLUE,
    COLOR_FRAME, COLOR_GREEN, COLOR_MARK, COLOR_ORANGE, COLOR_PURPLE, COLOR_VERMILLION,
};
use crate::gait::Stability;
use crate::study::{GaitMap, ThresholdCurve};
use crate::walk::Branch;

/// A labelled point on the map.
#[derive(Debug, Clone, PartialEq)]
pub struct MapMark {
    /// Text beside it.
    pub label: String,
    /// Its `x` \[unit of the x parameter\].
    pub x: f64,
    /// Its `y` \[unit of the y parameter\].
    pub y: f64,
}

/// What the map figure shows.
pub(crate) struct MapFigure<'a> {
    /// The gaits.
    pub map: &'a GaitMap,
    /// The threshold curves.
    pub curves: &'a [ThresholdCurve],
    /// Marked points.
    pub marks: &'a [MapMark],
    /// X axis description with unit.
    pub x_label: String,
    /// Y axis description with unit.
    pub y_label: String,
    /// Title.
    pub title: String,
}

/// Size of the figure \[px\].
pub(crate) const MAP_SIZE: (u32, u32) = (2600, 1900);
/// Width right of the panels for the legends \[px\].
const LEGEND_W: i32 = 430;
/// Width of a colour bar with its tick labels and description \[px\].
const BAR_W: i32 = 190;
const Y_LABEL_AREA: i32 = 130;
const X_LABEL_AREA: i32 = 90;
/// Height of a legend row \[px\].
const LEGEND_LINE: i32 = 36;
/// Width of a legend sample (line or swatch) \[px\].
const LEGEND_SAMPLE_W: i32 = 50;
/// The proportions of the legend boxes.
const LEGEND_LAYOUT: LegendLayout = LegendLayout::new(12, LEGEND_SAMPLE_W, 10, LEGEND_LINE, 6);

/// The chart of a panel, in the map's parameters.
type MapChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Grey of points without a gait.
pub(crate) const COLOR_NO_GAIT: RGBColor = RGBColor(200, 200, 200);
const NEGATIVE: RGBColor = RGBColor(33, 102, 172);
const ZERO: RGBColor = RGBColor(247, 247, 247);
const POSITIVE: RGBColor = RGBColor(178, 24, 43);

/// The colour of `v` on the diverging scale of `range` (white at zero, each side scaled to its extreme).
pub(crate) fn diverging(v: f64, range: &Range<f64>) -> RGBColor {
    let mix = |a: RGBColor, b: RGBColor, t: f64| {
        let t = t.clamp(0.0, 1.0);
        let c = |x: u8, y: u8| (f64::from(x) + (f64::from(y) - f64::from(x)) * t).round() as u8;
        RGBColor(c(a.0, b.0), c(a.1, b.1), c(a.2, b.2))
    };
    if v >= 0.0 {
        mix(ZERO, POSITIVE, v / range.end.max(f64::MIN_POSITIVE))
    } else {
        mix(ZERO, NEGATIVE, v / range.start.min(-f64::MIN_POSITIVE))
    }
}

/// A colour-bar label: three significant digits, a true minus sign.
fn bar_label(v: f64) -> String {
    if v == 0.0 {
        return "0".to_string();
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}").replace('-', "\u{2212}")
}

/// Colour of an impact branch on the existence panel.
pub(crate) fn branch_color(b: Branch) -> RGBColor {
    let light = |c: RGBColor| {
        let t = |x: u8| (255.0 - 0.55 * (255.0 - f64::from(x))).round() as u8;
        RGBColor(t(c.0), t(c.1), t(c.2))
    };
    match b {
        Branch::Dls => light(COLOR_GREEN),
        Branch::Sls => light(COLOR_ORANGE),
        Branch::SlsB3 => light(COLOR_PURPLE),
        Branch::Bounce => light(COLOR_BLUE),
        Branch::RearAirborne => RGBColor(240, 228, 66),
    }
}

const BRANCHES: [Branch; 5] = [
    Branch::Dls,
    Branch::Sls,
    Branch::SlsB3,
    Branch::Bounce,
    Branch::RearAirborne,
];

/// How a curve is drawn: colour, dashed, legend text.
pub(crate) fn curve_style(name: &str) -> (RGBColor, bool, &'static str) {
    match name {
        "existence_end" => (COLOR_BLACK, false, "end of the gait"),
        "lambda_4_plus = 0" => (COLOR_VERMILLION, false, "λ₄⁺ = 0"),
        "lambda_2_plus = 0" => (COLOR_BLUE, false, "λ₂⁺ = 0"),
        "lambda_I4 = 0" => (COLOR_GREEN, false, "λI4 = 0"),
        "stability_lost" => (COLOR_PURPLE, true, "stability lost"),
        "branch_switch" => (COLOR_ORANGE, true, "branch switch"),
        "fold" => (COLOR_BLACK, true, "fold"),
        _ => (COLOR_MARK, true, "end, unconfirmed"),
    }
}

/// The colours of the most frequent sequences (Okabe and Ito's palette, as every figure's lines).
pub(crate) const PALETTE: [RGBColor; 7] = [
    COLOR_BLUE,
    COLOR_ORANGE,
    COLOR_GREEN,
    COLOR_VERMILLION,
    COLOR_PURPLE,
    RGBColor(86, 180, 233),
    RGBColor(240, 228, 66),
];

/// The colour of a gait whose sequence is `signature` among `list` (the most frequent first): its palette
/// colour, [`COLOR_MARK`] past the palette or where it was not recorded.
pub(crate) fn signature_color(list: &[String], signature: Option<&str>) -> RGBColor {
    signature
        .and_then(|s| list.iter().position(|l| l == s))
        .and_then(|i| PALETTE.get(i).copied())
        .unwrap_or(COLOR_MARK)
}

/// One heat-map panel's content.
pub(crate) enum Layer<'a> {
    /// A gait quantity on the diverging scale, with its colour-bar description.
    Indicator(&'static str, fn(&crate::gait::Gait) -> f64),
    /// Existence and branch.
    Branch,
    /// The gait's stick/slip sequence: the colour of its place in the list (the most frequent first, see
    /// `signature_plot`), [`COLOR_MARK`] past the palette.
    Signature(&'a [String]),
}

impl MapFigure<'_> {
    fn axes(&self) -> (Range<f64>, Range<f64>) {
        let half = |v: &[f64]| {
            let step = if v.len() > 1 { v[1] - v[0] } else { 1.0 };
            let (a, b) = (v[0] - 0.5 * step, v[v.len() - 1] + 0.5 * step);
            if a < b {
                a..b
            } else {
                b..a
            }
        };
        (half(&self.map.xs), half(&self.map.ys))
    }

    /// The half-widths of a cell.
    fn cell(&self) -> (f64, f64) {
        let step = |v: &[f64]| {
            if v.len() > 1 {
                0.5 * (v[1] - v[0])
            } else {
                0.5
            }
        };
        (step(&self.map.xs), step(&self.map.ys))
    }

    /// One heat-map panel: `heading` above, the cells of `layer`, the curves and marks over them, and the colour
    /// bar of an indicator on the right.
    pub(crate) fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        layer: &Layer,
        heading: &str,
    ) -> DrawResult<DB> {
        let (w, h) = area.dim_in_pixel();
        let bar_w = if matches!(layer, Layer::Indicator(..)) {
            BAR_W
        } else {
            0
        };
        let (x, y) = self.axes();
        let heading_h = 44;
        area.draw(&Text::new(
            heading.to_string(),
            (Y_LABEL_AREA, 6),
            font(AXIS_FONT).pos(Pos::new(HPos::Left, VPos::Top)),
        ))?;
        let chart_area = area
            .clone()
            .shrink((0, heading_h), (w as i32 - bar_w, h as i32 - heading_h));
        let mut chart = ChartBuilder::on(&chart_area)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(x.clone(), y.clone())?;
        let x_fmt = |v: &f64| tick_label(*v, &x);
        let y_fmt = |v: &f64| tick_label(*v, &y);
        {
            let mut mesh = chart.configure_mesh();
            house_mesh(&mut mesh, TICK_FONT, AXIS_FONT);
            mesh.x_desc(self.x_label.as_str())
                .y_desc(self.y_label.as_str())
                .x_label_formatter(&x_fmt)
                .y_label_formatter(&y_fmt)
                .x_labels(8)
                .y_labels(8)
                .disable_mesh();
            mesh.draw()?;
        }
        let range = self.layer_range(layer);
        self.draw_cells(&mut chart, layer, &range)?;
        let (px, py) = chart.plotting_area().get_pixel_range();
        let plot = chart.plotting_area().strip_coord_spec();
        let clip = Clip::of_area(&plot);
        let rel = |p: [f64; 2]| {
            let (a, b) = chart.backend_coord(&(p[0], p[1]));
            (a - px.start, b - py.start)
        };
        self.draw_curves(&plot, &clip, &rel)?;
        self.draw_marks(&plot, &clip, &rel)?;
        plot.draw(&Rectangle::new(
            [(0, 0), (px.end - px.start - 1, py.end - py.start - 1)],
            BLACK.stroke_width(2),
        ))?;
        if let Layer::Indicator(desc, _) = layer {
            let base = area.get_base_pixel();
            let top = py.start - base.1;
            let bottom = py.end - base.1;
            colour_bar(
                area,
                (w as i32 - bar_w + 20, top, bottom),
                &range,
                0.0,
                desc,
            )?;
        }
        Ok(())
    }

    /// The colour scale of `layer`: an indicator's finite range with zero on it, `0..1` for the others.
    fn layer_range(&self, layer: &Layer) -> Range<f64> {
        match layer {
            Layer::Indicator(_, f) => {
                let values = self
                    .map
                    .rows
                    .iter()
                    .flatten()
                    .filter_map(|p| p.gait.as_ref().map(f));
                // Zero is always on the scale: the sign is what matters.
                super::chart::finite_range(values)
                    .map_or(-1.0..1.0, |r| r.start.min(0.0)..r.end.max(0.0))
            }
            Layer::Branch | Layer::Signature(_) => 0.0..1.0,
        }
    }

    /// One cell per map point in the colour of `layer` (on the scale `range`), with a dot on an unstable gait
    /// of the branch and signature layers.
    fn draw_cells<DB: DrawingBackend>(
        &self,
        chart: &mut MapChart<DB>,
        layer: &Layer,
        range: &Range<f64>,
    ) -> DrawResult<DB> {
        let (hx, hy) = self.cell();
        for (row, &yv) in self.map.rows.iter().zip(&self.map.ys) {
            for p in row {
                let color = match (&p.gait, layer) {
                    (None, _) => COLOR_NO_GAIT,
                    (Some(g), Layer::Indicator(_, f)) => {
                        let v = f(g);
                        if v.is_finite() {
                            diverging(v, range)
                        } else {
                            COLOR_NO_GAIT
                        }
                    }
                    (Some(g), Layer::Branch) => branch_color(g.branch),
                    (Some(g), Layer::Signature(list)) => {
                        signature_color(list, g.signature.as_deref())
                    }
                };
                chart.draw_series(std::iter::once(Rectangle::new(
                    [(p.value - hx, yv - hy), (p.value + hx, yv + hy)],
                    color.filled(),
                )))?;
                if let (Some(g), Layer::Branch | Layer::Signature(_)) = (&p.gait, layer) {
                    if g.stability != Stability::Stable {
                        chart.draw_series(std::iter::once(Circle::new(
                            (p.value, yv),
                            2,
                            COLOR_BLACK.filled(),
                        )))?;
                    }
                }
            }
        }
        Ok(())
    }

    /// The threshold curves on `plot` with a white halo (a single point as a dot), clipped; `rel` maps a data
    /// point to the plot's pixels.
    fn draw_curves<DB: DrawingBackend>(
        &self,
        plot: &DrawingArea<DB, Shift>,
        clip: &Clip,
        rel: &impl Fn([f64; 2]) -> (i32, i32),
    ) -> DrawResult<DB> {
        for curve in self.curves {
            let (color, is_dashed, _) = curve_style(&curve.name);
            let mut pts: Vec<(i32, i32)> = curve.points.iter().map(|&p| rel(p)).collect();
            if curve.closed {
                pts.push(pts[0]);
            }
            if pts.len() == 1 {
                clip.draw_circle(plot, pts[0], 5, WHITE.filled())?;
                clip.draw_circle(plot, pts[0], 3, color.filled())?;
                continue;
            }
            clip.draw_path(plot, &pts, WHITE.stroke_width(7))?;
            if is_dashed {
                clip.draw_dashed(plot, &pts, color.stroke_width(3), DASH_GAP)?;
            } else {
                clip.draw_path(plot, &pts, color.stroke_width(3))?;
            }
        }
        Ok(())
    }

    /// The marked points inside the clip on `plot`, as white circles with their labels on a light box; `rel`
    /// maps a data point to the plot's pixels.
    fn draw_marks<DB: DrawingBackend>(
        &self,
        plot: &DrawingArea<DB, Shift>,
        clip: &Clip,
        rel: &impl Fn([f64; 2]) -> (i32, i32),
    ) -> DrawResult<DB> {
        for m in self.marks {
            let c = rel([m.x, m.y]);
            if !clip.contains(c) {
                continue;
            }
            clip.draw_circle(plot, c, 10, WHITE.filled())?;
            clip.draw_circle(plot, c, 10, COLOR_BLACK.stroke_width(3))?;
            clip.draw_circle(plot, c, 3, COLOR_BLACK.filled())?;
            let style = font(LEGEND_FONT).pos(Pos::new(HPos::Left, VPos::Bottom));
            let at = (c.0 + 14, c.1 - 8);
            let (tw, th) = plot.estimate_text_size(&m.label, &font(LEGEND_FONT))?;
            plot.draw(&Rectangle::new(
                [
                    (at.0 - 3, at.1 - th as i32 - 2),
                    (at.0 + tw as i32 + 3, at.1 + 2),
                ],
                WHITE.mix(0.8).filled(),
            ))?;
            plot.draw(&Text::new(m.label.clone(), at, style))?;
        }
        Ok(())
    }

    /// The legends: curves, branches, no gait, unstable, marks.
    fn legends<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        (x0, y0): (i32, i32),
    ) -> DrawResult<DB> {
        let y = self.curve_legend(area, (x0, y0))?;
        self.existence_legend(area, (x0, y))
    }

    /// The legend of the curves drawn (none without curves) at `(x0, y0)`; returns the y below it.
    fn curve_legend<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        (x0, y0): (i32, i32),
    ) -> Result<i32, DrawingAreaErrorKind<DB::ErrorType>> {
        let mut names: Vec<&str> = self.curves.iter().map(|c| c.name.as_str()).collect();
        names.sort_unstable();
        names.dedup();
        let mut y = y0;
        if !names.is_empty() {
            area.draw(&Text::new(
                "curves",
                (x0, y),
                font(LEGEND_FONT).pos(Pos::new(HPos::Left, VPos::Top)),
            ))?;
            y += LEGEND_LINE;
            let mut text_w = 0;
            for n in &names {
                text_w = text_w.max(legend_text_w(area, curve_style(n).2)?);
            }
            let (sx, tx, mut cy) = LEGEND_LAYOUT.frame(area, (x0, y), names.len(), text_w)?;
            for n in &names {
                let (color, is_dashed, label) = curve_style(n);
                let line = [(sx, cy), (sx + LEGEND_SAMPLE_W, cy)];
                if is_dashed {
                    dashed(area, &line, color.stroke_width(3))?;
                } else {
                    area.draw(&PathElement::new(line.to_vec(), color.stroke_width(3)))?;
                }
                area.draw(&Text::new(
                    label,
                    (tx, cy),
                    font(LEGEND_FONT).pos(Pos::new(HPos::Left, VPos::Center)),
                ))?;
                cy += LEGEND_LINE;
            }
            y += names.len() as i32 * LEGEND_LINE + 2 * 6 + LEGEND_LINE;
        }
        Ok(y)
    }

    /// The legend of existence and branch at `(x0, y)`: a swatch per branch present, no gait, and the dot of
    /// an unstable gait.
    fn existence_legend<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        (x0, mut y): (i32, i32),
    ) -> DrawResult<DB> {
        let present = |b: Branch| {
            self.map
                .rows
                .iter()
                .flatten()
                .any(|p| p.gait.as_ref().is_some_and(|g| g.branch == b))
        };
        let mut swatches: Vec<(String, RGBColor)> = BRANCHES
            .iter()
            .filter(|&&b| present(b))
            .map(|&b| (format!("gait, branch {b}"), branch_color(b)))
            .collect();
        swatches.push(("no gait".to_string(), COLOR_NO_GAIT));
        area.draw(&Text::new(
            "existence and branch",
            (x0, y),
            font(LEGEND_FONT).pos(Pos::new(HPos::Left, VPos::Top)),
        ))?;
        y += LEGEND_LINE;
        let mut text_w = legend_text_w(area, "dot: unstable or uncertain")?;
        for (s, _) in &swatches {
            text_w = text_w.max(legend_text_w(area, s)?);
        }
        let (sx, tx, mut cy) = LEGEND_LAYOUT.frame(area, (x0, y), swatches.len() + 1, text_w)?;
        for (label, color) in &swatches {
            draw_box(
                area,
                [(sx, cy - 12), (sx + LEGEND_SAMPLE_W, cy + 12)],
                *color,
            )?;
            area.draw(&Text::new(
                label.clone(),
                (tx, cy),
                font(LEGEND_FONT).pos(Pos::new(HPos::Left, VPos::Center)),
            ))?;
            cy += LEGEND_LINE;
        }
        draw_box(
            area,
            [(sx, cy - 12), (sx + LEGEND_SAMPLE_W, cy + 12)],
            branch_color(Branch::Dls),
        )?;
        area.draw(&Circle::new(
            (sx + LEGEND_SAMPLE_W / 2, cy),
            3,
            COLOR_BLACK.filled(),
        ))?;
        area.draw(&Text::new(
            "dot: unstable or uncertain",
            (tx, cy),
            font(LEGEND_FONT).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        Ok(())
    }
}

/// A vertical colour bar at `(x, top, bottom)` for the values `range` on the diverging scale white at `centre`
/// ([`diverging`] of `v - centre`), with ticks at its ends and at `centre` (if inside) and `desc` above it.
pub(crate) fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, top, bottom): (i32, i32, i32),
    range: &Range<f64>,
    centre: f64,
    desc: &str,
) -> DrawResult<DB> {
    const BAR: i32 = 28;
    let span = (range.end - range.start).max(f64::MIN_POSITIVE);
    let shifted = (range.start - centre)..(range.end - centre);
    let to_px =
        |v: f64| bottom - ((v - range.start) / span * f64::from(bottom - top)).round() as i32;
    for py in top..bottom {
        let v = range.start + f64::from(bottom - py) / f64::from(bottom - top) * span;
        area.draw(&Rectangle::new(
            [(x, py), (x + BAR, py + 1)],
            diverging(v - centre, &shifted).filled(),
        ))?;
    }
    area.draw(&Rectangle::new(
        [(x, top), (x + BAR, bottom)],
        COLOR_FRAME.stroke_width(1),
    ))?;
    let mut ticks = vec![range.start, range.end];
    if range.start < centre && range.end > centre {
        ticks.push(centre);
    }
    for v in ticks {
        let py = to_px(v);
        area.draw(&PathElement::new(
            vec![(x + BAR, py), (x + BAR + 8, py)],
            BLACK.stroke_width(2),
        ))?;
        area.draw(&Text::new(
            bar_label(v),
            (x + BAR + 12, py),
            font(TICK_FONT).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
    }
    area.draw(&Text::new(
        desc.to_string(),
        (x, top - 10),
        font(TICK_FONT).pos(Pos::new(HPos::Left, VPos::Bottom)),
    ))?;
    Ok(())
}

/// The width of `s` in the legend font \[px\].
fn legend_text_w<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: &str,
) -> Result<i32, DrawingAreaErrorKind<DB::ErrorType>> {
    area.estimate_text_size(s, &font(LEGEND_FONT))
        .map(|(w, _)| w as i32)
}

impl Figure for MapFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let body = titled(root, &self.title)?;
        let (w, h) = body.dim_in_pixel();
        let (w, h) = (w as i32, h as i32);
        let panels_w = w - LEGEND_W;
        let (pw, ph) = (panels_w / 2, h / 2);
        let layers = [
            (
                Layer::Indicator("λI4 [N s]", |g| g.lambda_i4),
                "(a) λI4, impulse on Leg 2 at touchdown",
            ),
            (
                Layer::Indicator("λ₂⁺ [N]", |g| g.lambda_2_plus),
                "(b) λ₂⁺, normal force on Leg 1 after impact",
            ),
            (
                Layer::Indicator("λ₄⁺ [N]", |g| g.lambda_4_plus),
                "(c) λ₄⁺, normal force on Leg 2 after impact",
            ),
            (Layer::Branch, "(d) gait: existence and impact branch"),
        ];
        for (k, (layer, heading)) in layers.iter().enumerate() {
            let (col, row) = ((k % 2) as i32, (k / 2) as i32);
            let area = body
                .clone()
                .shrink((col * pw, row * ph), (pw - 20, ph - 10));
            self.panel(&area, layer, heading)?;
        }
        let legend_area = body.clone().shrink((panels_w, 0), (LEGEND_W, h));
        self.legends(&legend_area, (10, 60))
    }
}

/// Write the map figure as SVG and PNG ([`MAP_SIZE`]).
pub(crate) fn write_map_figure(
    figure: &MapFigure,
    svg: &Path,
    png: &Path,
) -> Result<(), PlotError> {
    has_points(figure.map)?;
    write_svg_png(figure, svg, png, MAP_SIZE)
}

/// An error for a map without points (nothing to draw).
pub(crate) fn has_points(map: &GaitMap) -> Result<(), PlotError> {
    if map.xs.is_empty() || map.ys.is_empty() {
        return Err(PlotError::Empty("the map has no points".to_string()));
    }
    Ok(())
}
