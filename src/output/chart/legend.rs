//! Legend boxes and the markers they share with the plots: rows of a sample (a line with its marker, a
//! colour swatch, hollow markers) and a plain or rich text.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::super::style::{draw_box, draw_rich, font, rich_width, LegendLayout, Seg};
use super::{dashed, Curve, DrawResult, Stroke, LEGEND_FONT};

/// The shape of a marker.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Marker {
    /// A disc.
    Circle,
    /// A triangle pointing up.
    Triangle,
}

/// Draws a marker of size `r` at `at`, filled with `color` or (`hollow`) white with a `color` outline.
pub(crate) fn draw_marker<DB: DrawingBackend>(
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
pub(crate) enum Sample {
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
pub(crate) enum Label<'a> {
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
pub(crate) struct LegendRow<'a> {
    /// What stands left of the text.
    pub sample: Sample,
    /// The text.
    pub label: Label<'a>,
}

/// Draws a legend box at `(x0, y0)` with `rows` in `layout`, texts at font size `size`.
pub(crate) fn draw_legend_rows<DB: DrawingBackend>(
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
pub(crate) fn draw_legend<DB: DrawingBackend>(
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
