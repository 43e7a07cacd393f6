//! Drawing Fig. 2: the title, the strip of threshold labels, the four panels on the shared x axis (with
//! their rich-text y labels, tags and legends) and the threshold lines through them.

use std::ops::Range;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::super::chart::{
    dashed_with, draw_legend_rows, title_size, Axes, AxisStyle, Band, DrawResult, Label, LegendRow,
    Marker, PixelRect, PlotArea, Sample, Stroke,
};
use super::super::style::{draw_rich, font, rich_width, LegendLayout, Seg, COLOR_MARK};
use super::data::{Prepared, Series};
use super::Fig2Spec;

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

const SCUFF_NOTE: &str = "scuffing of Leg 2";

/// The legend of the dashed lines of period-k gaits.
const MULTI_STEP_NOTE: &str = "period k > 1";

/// Dash and gap of a period-k gait's line \[px\].
const MULTI_STEP_DASH: (f64, f64) = (8.0, 5.0);

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
    plot.draw_bands(&no_gait_bands(data))?;
    // Reference line.
    plot.clip.draw_path(
        &plot.area,
        &[
            plot.rel((x.start, panel.reference)),
            plot.rel((x.end, panel.reference)),
        ],
        BLACK.stroke_width(2),
    )?;
    if series.iter().all(|s| s.runs.is_empty()) {
        plot.area.draw(&Text::new(
            "not defined for these gaits (e.g. rigid legs)",
            ((px.end - px.start) / 2, (py.end - py.start) / 4),
            font(NOTE_FONT).pos(Pos::new(HPos::Center, VPos::Center)),
        ))?;
    }
    // Thresholds inside the plot.
    for m in &data.marks {
        let at = plot.to_px((m.value, 0.0)).0;
        if px.contains(&at) {
            dashed_vline(root, at, py.start, py.end)?;
        }
    }
    draw_series(&plot, series, data.marker)?;
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
    // Legend, to the right of the plot.
    let rows = legend_rows(series);
    draw_legend_rows(root, &rows, &LEGEND, NOTE_FONT, (px.end + 28, py.start + 6))?;
    Ok((px, py))
}

/// The intervals of the parameter without a gait, as grey bands.
fn no_gait_bands(data: &Prepared) -> Vec<Band> {
    data.no_gait
        .iter()
        .map(|span| Band {
            from: span.start,
            to: span.end,
            color: NO_GAIT_FILL,
        })
        .collect()
}

/// The series' lines (a period-k gait's dashed), then their markers of size `marker` on top.
fn draw_series<DB: DrawingBackend>(
    plot: &PlotArea<DB>,
    series: &[Series],
    marker: i32,
) -> DrawResult<DB> {
    for s in series {
        for (run, &multi) in s.runs.iter().zip(&s.multi_step) {
            let pts: Vec<(i32, i32)> = run.iter().map(|&(a, b, _)| plot.rel((a, b))).collect();
            if multi {
                plot.clip.draw_dashed(
                    &plot.area,
                    &pts,
                    s.color.stroke_width(2),
                    MULTI_STEP_DASH,
                )?;
            } else {
                plot.clip
                    .draw_path(&plot.area, &pts, s.color.stroke_width(2))?;
            }
        }
    }
    for s in series {
        for &(a, b, scuff) in s.samples() {
            plot.clip.draw_marker(
                &plot.area,
                plot.rel((a, b)),
                s.shape,
                s.color,
                scuff,
                marker,
            )?;
        }
    }
    Ok(())
}

/// A panel's legend rows: one per series, one for the hollow markers of scuffing and one for the dashed
/// lines of period-k gaits (each where it occurs).
fn legend_rows(series: &[Series]) -> Vec<LegendRow<'_>> {
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
    if series.iter().any(Series::any_multi_step) {
        rows.push(LegendRow {
            sample: Sample::Line {
                color: BLACK,
                stroke: Stroke::Dashed,
                width: 2,
                marker: None,
            },
            label: Label::Plain(MULTI_STEP_NOTE),
        });
    }
    rows
}

/// Draws the whole of Fig. 2 on `root`.
pub(super) fn draw_fig2<DB: DrawingBackend>(
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
