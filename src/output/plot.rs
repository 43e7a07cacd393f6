//! Fig. 2 of the paper: the DLS indicators of the walking gait against a swept
//! parameter (the leg viscosity `c`), written as SVG and PNG.
//!
//! Panel (a) plots `lambda_I4` (the impulse indicator, \[N s\]); panel (b) plots
//! `lambda_2+` and `lambda_4+` (the normal forces just after impact, \[N\]); see
//! `docs/model.md` sections 5 and 6 and section 3 of the paper. Points where
//! scuffing of Leg 2 arises are drawn with hollow markers, the others with
//! filled ones. Thresholds (where an indicator crosses zero, where the gait is
//! lost) are drawn as labelled vertical dashed lines through both panels,
//! which share the x axis.
//!
//! Text (the bundled DejaVu Sans), colours and tick labels come from [`super::style`]; the axes, shading,
//! markers, legends and the title from [`super::chart`], at Fig. 2's own proportions.

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::chart::{
    dashed_with, draw_legend_rows, draw_marker, title_size, write_svg_png, Axes, AxisStyle, Band,
    DrawResult, Figure, Label, LegendRow, Marker, PixelRect, PlotArea, Sample, Stroke,
};
pub use super::style::PlotError;
use super::style::{
    draw_rich, font, padded, rich_width, LegendLayout, Seg, COLOR_BLACK, COLOR_BLUE, COLOR_MARK,
    COLOR_VERMILLION,
};
#[cfg(test)]
use super::style::{png_size, FAMILY};

/// One gait on the sweep: the parameter value and its DLS indicators (MODEL.md section 5).
#[derive(Debug, Clone, PartialEq)]
pub struct IndicatorPoint {
    /// Swept parameter value, e.g. the leg viscosity `c` \[N s/m\].
    pub param: f64,
    /// Impulse indicator `lambda_I4` \[N s\]; NaN when there is no gait.
    pub lambda_i4: f64,
    /// Normal force of Leg 1 just after impact, `lambda_2+` \[N\]; NaN when there is no gait.
    pub lambda_2_plus: f64,
    /// Normal force of Leg 2 just after impact, `lambda_4+` \[N\]; NaN when there is no gait.
    pub lambda_4_plus: f64,
    /// Whether scuffing of Leg 2 arises on this gait (drawn with hollow markers).
    pub scuffing: bool,
    /// Gait family (points of different families are never joined by a line); `None` without a gait.
    pub family: Option<usize>,
    /// Step period of the gait \[s\]; NaN when there is no gait.
    pub period: f64,
    /// Largest Floquet multiplier modulus of the gait; NaN when there is no gait.
    pub max_floquet: f64,
}

/// A vertical annotated marker.
#[derive(Debug, Clone, PartialEq)]
pub struct ThresholdMark {
    /// Text drawn verbatim beside the line, e.g. `"λ₄⁺ = 0 at c = 220.1"` or `"c = 220.1"`.
    pub label: String,
    /// Parameter value where the line is drawn (same unit as [`IndicatorPoint::param`]).
    /// Non-finite values are skipped.
    pub value: f64,
}

/// What to draw in Fig. 2.
pub struct Fig2Spec<'a> {
    /// The sweep; may contain NaN indicators for points without a gait: those are skipped.
    pub points: &'a [IndicatorPoint],
    /// Vertical dashed lines with labels (thresholds, loss of the gait).
    pub thresholds: &'a [ThresholdMark],
    /// Label of the x axis with unit, e.g. `"c \[N s/m\]"`.
    pub param_label: &'a str,
    /// Figure title (may be empty: no title is drawn).
    pub title: &'a str,
    /// The x range to show (the whole sweep); `None`: the span of the data and thresholds.
    pub x_range: Option<Range<f64>>,
    /// Parameter intervals without a gait, shaded in every panel.
    pub no_gait: &'a [Range<f64>],
}

/// Size of both the SVG and the PNG, in pixels.
pub const FIG2_SIZE: (u32, u32) = (1600, 1600);

const NAME_I4: &[Seg] = &[Seg::Text("λ"), Seg::Sub("I4")];
const NAME_2: &[Seg] = &[Seg::Text("λ"), Seg::SubSup("2", "+")];
const NAME_4: &[Seg] = &[Seg::Text("λ"), Seg::SubSup("4", "+")];
const NAME_PERIOD: &[Seg] = &[Seg::Text("period")];
const NAME_FLOQUET: &[Seg] = &[Seg::Text("largest |multiplier|")];
const LABEL_PERIOD: &[Seg] = &[Seg::Text("T [s]")];
const LABEL_FLOQUET: &[Seg] = &[Seg::Text("max |μ|")];
const LABEL_I4: &[Seg] = &[Seg::Text("λ"), Seg::Sub("I4"), Seg::Text(" [N s]")];
const LABEL_PLUS: &[Seg] = &[Seg::Text("λ [N]")];

// Layout, in pixels of the 1600 x 1600 canvas.
const MARGIN: i32 = 24;
const TITLE_H: i32 = 64;
const ROW_H: i32 = 36;
const LEGEND_W: i32 = 320;
const Y_LABEL_AREA: i32 = 140;
const X_LABEL_AREA: i32 = 100;
const TOP_TICK_AREA: i32 = 14;
const PANEL_GAP: i32 = 18;
const TITLE_FONT: f64 = 40.0;
const AXIS_FONT: f64 = 34.0;
const TICK_FONT: f64 = 28.0;
const NOTE_FONT: f64 = 27.0;

/// The axes of Fig. 2's panels: no y description from plotters (each panel writes its own, with subscripts).
const FIG2_AXES: AxisStyle = AxisStyle {
    tick_font: TICK_FONT,
    axis_font: AXIS_FONT,
    y_label_area: Y_LABEL_AREA,
    x_label_area: X_LABEL_AREA,
    bare_x_area: TOP_TICK_AREA,
    y_labels: 7,
    margin_right: LEGEND_W,
    min_band_px: 0,
};
/// Dash and gap of the threshold lines \[px\].
const THRESHOLD_DASH: (f64, f64) = (10.0, 7.0);
/// The legend boxes.
const LEGEND: LegendLayout = LegendLayout::new(16, 56, 12, 40, 6);

const COLOR_I4: RGBColor = COLOR_BLACK;
const COLOR_2: RGBColor = COLOR_BLUE;
const COLOR_4: RGBColor = COLOR_VERMILLION;

/// One plotted indicator: its finite samples sorted by parameter, split into
/// runs that are not interrupted by points without a gait.
struct Series {
    name: &'static [Seg],
    color: RGBColor,
    shape: Marker,
    runs: Vec<Vec<(f64, f64, bool)>>,
}

impl Series {
    fn new(
        name: &'static [Seg],
        color: RGBColor,
        shape: Marker,
        sorted: &[&IndicatorPoint],
        value: fn(&IndicatorPoint) -> f64,
    ) -> Self {
        let mut runs: Vec<Vec<(f64, f64, bool)>> = vec![Vec::new()];
        let mut family = None;
        for p in sorted {
            let v = value(p);
            // A new run after a point without a value, and at every change of gait family (two families are
            // never joined by a line).
            if (!v.is_finite() || p.family != family) && !runs.last().unwrap().is_empty() {
                runs.push(Vec::new());
            }
            if v.is_finite() {
                runs.last_mut().unwrap().push((p.param, v, p.scuffing));
                family = p.family;
            }
        }
        runs.retain(|r| !r.is_empty());
        Series {
            name,
            color,
            shape,
            runs,
        }
    }

    fn samples(&self) -> impl Iterator<Item = &(f64, f64, bool)> {
        self.runs.iter().flatten()
    }

    fn any_scuffing(&self) -> bool {
        self.samples().any(|s| s.2)
    }
}

/// Validated data and axis ranges.
struct Prepared {
    x: Range<f64>,
    /// The panels (a)-(d), each with its series and y range.
    panels: [(Vec<Series>, Range<f64>); 4],
    marks: Vec<ThresholdMark>,
    no_gait: Vec<Range<f64>>,
    marker: i32,
}

/// Range of the y values of `series`, always including `reference` (the reference line: 0, or 1 for the
/// multipliers).
fn y_range(series: &[Series], reference: f64) -> Range<f64> {
    let (lo, hi) = series
        .iter()
        .flat_map(|s| s.samples())
        .fold((0.0_f64, reference), |(lo, hi), s| {
            (lo.min(s.1), hi.max(s.1))
        });
    let (lo, hi) = if hi > lo { (lo, hi) } else { (-1.0, 1.0) };
    let r = padded(lo, hi, 0.07);
    // Keep the zero line on the frame only when no data lies below it.
    let start = if lo >= 0.0 { 0.0 } else { r.start };
    start..r.end
}

impl Prepared {
    fn new(spec: &Fig2Spec) -> Result<Self, PlotError> {
        if spec.points.is_empty() {
            return Err(PlotError::Empty("the sweep has no points".into()));
        }
        let mut sorted: Vec<&IndicatorPoint> =
            spec.points.iter().filter(|p| p.param.is_finite()).collect();
        sorted.sort_by(|a, b| a.param.total_cmp(&b.param));
        let panel_a = vec![Series::new(
            NAME_I4,
            COLOR_I4,
            Marker::Circle,
            &sorted,
            |p| p.lambda_i4,
        )];
        let panel_b = vec![
            Series::new(NAME_2, COLOR_2, Marker::Circle, &sorted, |p| {
                p.lambda_2_plus
            }),
            Series::new(NAME_4, COLOR_4, Marker::Triangle, &sorted, |p| {
                p.lambda_4_plus
            }),
        ];
        let panel_c = vec![Series::new(
            NAME_PERIOD,
            COLOR_I4,
            Marker::Circle,
            &sorted,
            |p| p.period,
        )];
        let panel_d = vec![Series::new(
            NAME_FLOQUET,
            COLOR_BLUE,
            Marker::Circle,
            &sorted,
            |p| p.max_floquet,
        )];
        let xs: Vec<f64> = [&panel_a, &panel_b, &panel_c, &panel_d]
            .into_iter()
            .flatten()
            .flat_map(|s| s.samples().map(|s| s.0))
            .collect();
        if xs.is_empty() {
            return Err(PlotError::Empty(format!(
                "none of the {} points has a gait",
                spec.points.len()
            )));
        }
        let marks: Vec<ThresholdMark> = spec
            .thresholds
            .iter()
            .filter(|m| m.value.is_finite())
            .cloned()
            .collect();
        let x = match &spec.x_range {
            Some(r) if r.end > r.start => r.clone(),
            _ => {
                let (lo, hi) = xs
                    .iter()
                    .copied()
                    .chain(marks.iter().map(|m| m.value))
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                        (lo.min(v), hi.max(v))
                    });
                let mut x = padded(lo, hi, 0.03);
                if lo >= 0.0 && x.start < 0.0 {
                    x.start = 0.0;
                }
                x
            }
        };
        let n = [&panel_a, &panel_b]
            .into_iter()
            .flatten()
            .map(|s| s.samples().count())
            .max()
            .unwrap_or(1)
            .max(1) as i32;
        let marker = (1100 / n / 2).clamp(4, 7);
        let (y_a, y_b, y_c, y_d) = (
            y_range(&panel_a, 0.0),
            y_range(&panel_b, 0.0),
            y_range(&panel_c, 0.0),
            y_range(&panel_d, 1.0),
        );
        Ok(Prepared {
            x,
            panels: [
                (panel_a, y_a),
                (panel_b, y_b),
                (panel_c, y_c),
                (panel_d, y_d),
            ],
            marks,
            no_gait: spec.no_gait.to_vec(),
            marker,
        })
    }
}

/// Writes Fig. 2 (DLS indicators against the swept parameter) to `svg_path`
/// and `png_path`, both [`FIG2_SIZE`] pixels.
///
/// Panel (a): `lambda_I4`, y label "λ_I4 \[N s\]" (with a real subscript);
/// panel (b): `lambda_2+` and `lambda_4+`, y label "λ \[N\]"; shared x axis labelled
/// `spec.param_label`. Points with a NaN indicator are skipped (and break the
/// connecting line); scuffing points get hollow markers; each threshold is a
/// dashed vertical line labelled with its text.
///
/// # Errors
/// [`PlotError::Empty`] if there are no points or no point has a finite
/// parameter and indicator (nothing is written then); [`PlotError::Draw`] if a
/// file cannot be drawn or written.
pub fn write_fig2(spec: &Fig2Spec, svg_path: &Path, png_path: &Path) -> Result<(), PlotError> {
    let data = Prepared::new(spec)?;
    write_svg_png(&Fig2 { spec, data: &data }, svg_path, png_path, FIG2_SIZE)
}

/// Fig. 2 ready to draw.
struct Fig2<'a> {
    spec: &'a Fig2Spec<'a>,
    data: &'a Prepared,
}

impl Figure for Fig2<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        draw_fig2(root, self.spec, self.data)
    }
}

const SCUFF_NOTE: &str = "scuffing of Leg 2";

/// Assigns each threshold label a row of the label strip (row 0 is next to
/// the plot). `labels` holds each line's x and its text's x interval. A label
/// must not overlap another label in its row, its text must not be crossed by
/// the line of a label further up, and its own line must not cross a label
/// below it. Greedy, from the rightmost line leftwards, lowest free row first.
fn label_rows(labels: &[(i32, Range<i32>)]) -> Vec<usize> {
    const GAP: i32 = 16;
    let mut order: Vec<usize> = (0..labels.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(labels[i].0));
    let mut rows = vec![0usize; labels.len()];
    let covers = |r: &Range<i32>, x: i32| r.start - GAP / 2 <= x && x <= r.end + GAP / 2;
    for (k, &i) in order.iter().enumerate() {
        let (xi, ref ti) = labels[i];
        let placed = &order[..k];
        let free = |row: usize| {
            placed.iter().all(|&j| {
                let (xj, ref tj) = labels[j];
                match row.cmp(&rows[j]) {
                    std::cmp::Ordering::Equal => {
                        ti.end + GAP <= tj.start || tj.end + GAP <= ti.start
                    }
                    std::cmp::Ordering::Less => !covers(ti, xj),
                    std::cmp::Ordering::Greater => !covers(tj, xi),
                }
            })
        };
        let top = placed.iter().map(|&j| rows[j] + 1).max().unwrap_or(0);
        rows[i] = (0..=top).find(|&r| free(r)).unwrap_or(top);
    }
    rows
}

/// Draws a threshold line from `y0` down to `y1` at `x` (nothing if `y1` is not below `y0`).
fn dashed_vline<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    x: i32,
    y0: i32,
    y1: i32,
) -> DrawResult<DB> {
    if y0 >= y1 {
        return Ok(());
    }
    dashed_with(
        root,
        &[(x, y0), (x, y1)],
        COLOR_MARK.stroke_width(2),
        THRESHOLD_DASH,
    )
}

struct Panel {
    tag: &'static str,
    y_label: &'static [Seg],
    top: i32,
    height: i32,
    bottom_axis: bool,
    /// The y value of the solid reference line (0, or 1 for the multipliers).
    reference: f64,
}

/// Fill of the parameter intervals without a gait.
const NO_GAIT_FILL: RGBColor = RGBColor(228, 228, 228);

/// Draws one panel; returns the pixel rectangle of its plotting area.
fn draw_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    panel: &Panel,
    series: &[Series],
    x: &Range<f64>,
    y: &Range<f64>,
    data: &Prepared,
    param_label: &str,
) -> Result<PixelRect, DrawingAreaErrorKind<DB::ErrorType>> {
    let (w, _) = root.dim_in_pixel();
    let area = root
        .clone()
        .shrink((MARGIN, panel.top), (w as i32 - 2 * MARGIN, panel.height));
    let axes = Axes {
        x: x.clone(),
        y: y.clone(),
        x_label: panel.bottom_axis.then_some(param_label),
        y_label: "",
        x_integer: false,
    };
    let plot = PlotArea::new(&area, &axes, &FIG2_AXES)?;
    let (px, py) = (plot.px.clone(), plot.py.clone());
    // Intervals without a gait, under everything else.
    let no_gait: Vec<Band> = data
        .no_gait
        .iter()
        .map(|span| Band {
            from: span.start,
            to: span.end,
            color: NO_GAIT_FILL,
        })
        .collect();
    plot.draw_bands(&no_gait)?;
    // Reference line.
    plot.area.draw(&PathElement::new(
        vec![
            plot.rel((x.start, panel.reference)),
            plot.rel((x.end, panel.reference)),
        ],
        BLACK.stroke_width(2),
    ))?;
    if series.iter().all(|s| s.runs.is_empty()) {
        plot.area.draw(&Text::new(
            "not defined for these gaits (e.g. rigid legs)",
            ((px.end - px.start) / 2, (py.end - py.start) / 4),
            font(NOTE_FONT).pos(Pos::new(HPos::Center, VPos::Center)),
        ))?;
    }
    // Thresholds inside the plot.
    for m in &data.marks {
        dashed_vline(root, plot.to_px((m.value, 0.0)).0, py.start, py.end)?;
    }
    // Lines, then markers on top.
    for s in series {
        for run in &s.runs {
            plot.area.draw(&PathElement::new(
                run.iter()
                    .map(|&(a, b, _)| plot.rel((a, b)))
                    .collect::<Vec<_>>(),
                s.color.stroke_width(2),
            ))?;
        }
    }
    for s in series {
        for &(a, b, scuff) in s.samples() {
            draw_marker(
                &plot.area,
                plot.rel((a, b)),
                s.shape,
                s.color,
                scuff,
                data.marker,
            )?;
        }
    }
    plot.draw_outline()?;
    // Axis label, rotated and centred on the plot's height.
    let label_w = rich_width(root, panel.y_label, AXIS_FONT)?;
    draw_rich(
        root,
        panel.y_label,
        (MARGIN + 6, (py.start + py.end + label_w) / 2),
        AXIS_FONT,
        true,
    )?;
    // Panel tag, top left of the figure beside the plot.
    root.draw(&Text::new(
        panel.tag,
        (MARGIN, py.start - 4),
        font(AXIS_FONT),
    ))?;
    // Legend, to the right of the plot: a row per series, and one for the hollow markers of scuffing.
    let mut rows: Vec<LegendRow> = series
        .iter()
        .map(|s| LegendRow {
            sample: Sample::Line {
                color: s.color,
                stroke: Stroke::Solid,
                width: 2,
                marker: Some((s.shape, 7)),
            },
            label: Label::Rich(s.name),
        })
        .collect();
    let scuff: Vec<(Marker, RGBColor)> = series
        .iter()
        .filter(|s| s.any_scuffing())
        .map(|s| (s.shape, s.color))
        .collect();
    if !scuff.is_empty() {
        rows.push(LegendRow {
            sample: Sample::Hollow {
                markers: scuff,
                r: 7,
            },
            label: Label::Plain(SCUFF_NOTE),
        });
    }
    draw_legend_rows(root, &rows, &LEGEND, NOTE_FONT, (px.end + 28, py.start + 6))?;
    Ok((px, py))
}

fn draw_fig2<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    spec: &Fig2Spec,
    data: &Prepared,
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let (w, h) = root.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    let mut top = MARGIN;
    if !spec.title.is_empty() {
        // Shrink a long title to fit the width.
        let size = title_size(root, spec.title, TITLE_FONT)?;
        root.draw(&Text::new(
            spec.title,
            (w / 2, top + ((TITLE_FONT - size) / 2.0) as i32),
            font(size).pos(Pos::new(HPos::Center, VPos::Top)),
        ))?;
        top += TITLE_H;
    }
    // Threshold label strip: the x positions are known before drawing, since
    // both panels share the same horizontal layout.
    let plot_x0 = MARGIN + Y_LABEL_AREA;
    let plot_x1 = w - MARGIN - LEGEND_W;
    let span = data.x.end - data.x.start;
    let px_of = |v: f64| {
        plot_x0 + ((v - data.x.start) / span * f64::from(plot_x1 - plot_x0 - 1)).round() as i32
    };
    // Each label starts right of its line, or ends left of it where it would
    // leave the canvas.
    let mut xw = Vec::with_capacity(data.marks.len());
    for m in &data.marks {
        let (tw, _) = root.estimate_text_size(&m.label, &font(NOTE_FONT))?;
        let x = px_of(m.value);
        let tw = tw as i32;
        let text = if x + 8 + tw <= w - MARGIN / 2 {
            (x + 8)..(x + 8 + tw)
        } else {
            (x - 8 - tw)..(x - 8)
        };
        xw.push((x, text));
    }
    let rows = label_rows(&xw);
    let n_rows = rows.iter().map(|r| r + 1).max().unwrap_or(0) as i32;
    let strip = if n_rows > 0 { n_rows * ROW_H + 10 } else { 16 };
    let label_top = top;
    top += strip;

    // Four panels sharing the x axis; only the last one has its tick labels.
    const TAGS: [&str; 4] = ["(a)", "(b)", "(c)", "(d)"];
    const LABELS: [&[Seg]; 4] = [LABEL_I4, LABEL_PLUS, LABEL_PERIOD, LABEL_FLOQUET];
    const SHARES: [i32; 4] = [30, 30, 20, 20];
    let avail = h - MARGIN - top - X_LABEL_AREA - 3 * (TOP_TICK_AREA + PANEL_GAP);
    let mut py_a = 0..0;
    let mut panel_top = top;
    for k in 0..4 {
        let last = k == 3;
        let inner = avail * SHARES[k] / 100;
        let panel = Panel {
            tag: TAGS[k],
            y_label: LABELS[k],
            top: panel_top,
            height: if last {
                h - MARGIN - panel_top
            } else {
                inner + TOP_TICK_AREA
            },
            bottom_axis: last,
            reference: if k == 3 { 1.0 } else { 0.0 },
        };
        let (series, y) = &data.panels[k];
        let (_, py) = draw_panel(root, &panel, series, &data.x, y, data, spec.param_label)?;
        if k == 0 {
            py_a = py;
        }
        panel_top += inner + TOP_TICK_AREA + PANEL_GAP;
    }
    // Threshold labels and the dashed lines up to them.
    for ((m, (x, text)), &row) in data.marks.iter().zip(&xw).zip(&rows) {
        let y_text = label_top + strip - 10 - (row as i32) * ROW_H - ROW_H / 2;
        dashed_vline(root, *x, y_text, py_a.start)?;
        root.draw(&Text::new(
            m.label.as_str(),
            (text.start, y_text),
            font(NOTE_FONT).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Synthetic sweep shaped like the paper's Fig. 2.
    fn synthetic() -> Vec<IndicatorPoint> {
        (0..60)
            .map(|k| {
                let c = 1.0 + 299.0 * k as f64 / 59.0;
                IndicatorPoint {
                    param: c,
                    lambda_i4: 2.0 + 3.0 * (-c / 80.0).exp(),
                    lambda_2_plus: -5.0 + 105.0 * (1.0 - (-(c - 1.0) / 60.0).exp()) / 0.993,
                    lambda_4_plus: 60.0 - 60.0 * c / 220.1,
                    scuffing: c < 30.0,
                    family: Some(0),
                    period: 2.0 + c / 100.0,
                    max_floquet: 0.1 + c / 1000.0,
                }
            })
            .collect()
    }

    fn marks() -> Vec<ThresholdMark> {
        vec![
            ThresholdMark {
                label: "λ₂⁺ = 0: c = 4.0".into(),
                value: 4.0,
            },
            ThresholdMark {
                label: "λ₄⁺ = 0: c = 220.1".into(),
                value: 220.1,
            },
        ]
    }

    #[test]
    fn writes_svg_and_png_for_synthetic_sweep() {
        let dir = tempfile::tempdir().unwrap();
        let (svg, png) = (dir.path().join("fig2.svg"), dir.path().join("fig2.png"));
        let mut points = synthetic();
        points[10].lambda_i4 = f64::NAN;
        points[11].lambda_2_plus = f64::NAN;
        let marks = marks();
        let spec = Fig2Spec {
            points: &points,
            thresholds: &marks,
            param_label: "c [N s/m]",
            title: "DLS indicators vs leg viscosity",
            x_range: None,
            no_gait: &[],
        };
        write_fig2(&spec, &svg, &png).unwrap();
        let png_bytes = std::fs::read(&png).unwrap();
        assert_eq!(png_size(&png_bytes), Some(FIG2_SIZE));
        let svg_text = std::fs::read_to_string(&svg).unwrap();
        assert!(svg_text.starts_with("<svg"));
        for label in [
            "c [N s/m]",
            "\nI4\n",
            "[N s]",
            "λ [N]",
            "λ₄⁺ = 0: c = 220.1",
            "(b)",
        ] {
            assert!(svg_text.contains(label), "SVG lacks {label:?}");
        }
        assert!(svg_text.contains(&format!("font-family=\"{FAMILY}\"")));
    }

    #[test]
    fn empty_sweep_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let spec = Fig2Spec {
            points: &[],
            thresholds: &[],
            param_label: "c [N s/m]",
            title: "",
            x_range: None,
            no_gait: &[],
        };
        let (svg, png) = (dir.path().join("a.svg"), dir.path().join("a.png"));
        let err = write_fig2(&spec, &svg, &png).unwrap_err();
        assert!(matches!(err, PlotError::Empty(_)), "{err}");
        assert!(!svg.exists() && !png.exists());
    }

    /// The point with its DLS indicators undefined (as with rigid legs).
    fn without_indicators(p: IndicatorPoint) -> IndicatorPoint {
        IndicatorPoint {
            lambda_i4: f64::NAN,
            lambda_2_plus: f64::NAN,
            lambda_4_plus: f64::NAN,
            ..p
        }
    }

    #[test]
    fn all_nan_sweep_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let points: Vec<IndicatorPoint> = synthetic()
            .into_iter()
            .map(|p| IndicatorPoint {
                period: f64::NAN,
                max_floquet: f64::NAN,
                family: None,
                ..without_indicators(p)
            })
            .collect();
        let marks = marks();
        let spec = Fig2Spec {
            points: &points,
            thresholds: &marks,
            param_label: "c [N s/m]",
            title: "",
            x_range: None,
            no_gait: &[],
        };
        let err =
            write_fig2(&spec, &dir.path().join("a.svg"), &dir.path().join("a.png")).unwrap_err();
        assert!(matches!(err, PlotError::Empty(_)), "{err}");
    }

    /// A sweep with rigid legs has gaits but no DLS indicators: it used to fail with "no data to plot"; it
    /// draws what exists (period, largest multiplier) over the whole range, with the no-gait part shaded.
    #[test]
    fn sweep_without_indicators_draws_period_and_multipliers() {
        let dir = tempfile::tempdir().unwrap();
        let points: Vec<IndicatorPoint> = synthetic().into_iter().map(without_indicators).collect();
        let no_gait = [250.0..300.0];
        let spec = Fig2Spec {
            points: &points,
            thresholds: &[],
            param_label: "c [N s/m]",
            title: "",
            x_range: Some(0.0..300.0),
            no_gait: &no_gait,
        };
        let (svg, png) = (dir.path().join("a.svg"), dir.path().join("a.png"));
        write_fig2(&spec, &svg, &png).unwrap();
        let svg_text = std::fs::read_to_string(&svg).unwrap();
        for label in ["T [s]", "max |μ|", "not defined for these gaits", "(d)"] {
            assert!(svg_text.contains(label), "SVG lacks {label:?}");
        }
    }

    #[test]
    fn unwritable_path_is_a_draw_error() {
        let points = synthetic();
        let spec = Fig2Spec {
            points: &points,
            thresholds: &[],
            param_label: "c [N s/m]",
            title: "",
            x_range: None,
            no_gait: &[],
        };
        let bad = Path::new("/nonexistent-dir/for/sure/fig2.svg");
        let err = write_fig2(&spec, bad, &bad.with_extension("png")).unwrap_err();
        assert!(matches!(err, PlotError::Draw { .. }), "{err}");
    }

    #[test]
    fn close_threshold_labels_stack_without_covering_lines() {
        // Two lines 10 px apart with 100 px labels, one far away.
        let right = |x: i32| (x, (x + 8)..(x + 108));
        let rows = label_rows(&[right(100), right(110), right(600)]);
        assert_eq!(rows, vec![1, 0, 0]);
        // A label turned to the left of its line (at the right edge) and an
        // overlapping label to its left: different rows, and the upper label's
        // line must miss the lower label's text.
        let all = [right(1250), (1420, 1312..1412)];
        let rows = label_rows(&all);
        assert_ne!(rows[0], rows[1]);
        let (lo, hi) = if rows[0] < rows[1] { (0, 1) } else { (1, 0) };
        // The upper label's line passes the lower row: it must miss that text.
        let (x_hi, _) = &all[hi];
        let (_, t_lo) = &all[lo];
        assert!(!t_lo.contains(x_hi));
    }
}
