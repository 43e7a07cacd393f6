//! The stick/slip figure of a map with Coulomb friction (`signatures.png`, `signatures.svg`): one panel over the
//! map's two parameters, each gait coloured by its step's stick/slip sequence (the `signature` column of
//! `map.csv`: the touchdown's branch, then each slip start, stop and reversal, lift-off and lock), the most
//! frequent sequences first, with the full sequences in the legend; unstable or uncertain gaits dotted, points
//! without a gait grey, the threshold curves and marks as on the map figure ([`super::map_plot`]).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::chart::{titled, write_svg_png, DrawResult, Figure, LEGEND_FONT, TICK_FONT};
use super::map_plot::{has_points, Layer, MapFigure, COLOR_NO_GAIT, PALETTE};
use super::style::{draw_box, font, PlotError, COLOR_MARK};
use crate::study::GaitMap;

/// Size of the figure \[px\]: the panel on the left, the sequences' legend on the right.
const SIZE: (u32, u32) = (2800, 1300);
/// Width of the panel \[px\].
const PANEL_W: i32 = 1200;

/// The distinct stick/slip sequences of the map's gaits with their number of points, the most frequent first
/// (ties in the order of the text).
pub(crate) fn signature_counts(map: &GaitMap) -> Vec<(String, usize)> {
    let mut counts: Vec<(String, usize)> = Vec::new();
    for signature in map
        .rows
        .iter()
        .flatten()
        .filter_map(|p| p.gait.as_ref().and_then(|g| g.signature.clone()))
    {
        match counts.iter_mut().find(|(s, _)| *s == signature) {
            Some((_, n)) => *n += 1,
            None => counts.push((signature, 1)),
        }
    }
    counts.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    counts
}

/// The figure: the map's panel of sequences and their legend.
pub(crate) struct SignatureFigure<'a> {
    /// The map figure whose axes, curves and marks the panel shares.
    pub map: &'a MapFigure<'a>,
}

impl Figure for SignatureFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let title = format!("Stick/slip sequences: {}", self.map.title);
        let body = titled(root, &title)?;
        let (w, h) = body.dim_in_pixel();
        let counts = signature_counts(self.map.map);
        let list: Vec<String> = counts.iter().map(|(s, _)| s.clone()).collect();
        let panel = body.clone().shrink((0, 0), (PANEL_W, h as i32 - 10));
        self.map.panel(
            &panel,
            &Layer::Signature(&list),
            "sequence of the gait's step (dot: unstable or uncertain)",
        )?;
        let legend = body
            .clone()
            .shrink((PANEL_W + 20, 40), (w as i32 - PANEL_W - 20, h as i32 - 40));
        const LINE: i32 = 40;
        const SAMPLE_W: i32 = 50;
        let text = |s: String, at: (i32, i32), size: f64| {
            legend.draw(&Text::new(
                s,
                at,
                font(size).pos(Pos::new(HPos::Left, VPos::Center)),
            ))
        };
        let mut y = 20;
        let others: usize = counts.iter().skip(PALETTE.len()).map(|(_, n)| n).sum();
        for (i, (signature, n)) in counts.iter().take(PALETTE.len()).enumerate() {
            draw_box(&legend, [(0, y - 14), (SAMPLE_W, y + 14)], PALETTE[i])?;
            text(format!("{n} points"), (SAMPLE_W + 14, y), LEGEND_FONT)?;
            text(signature.clone(), (SAMPLE_W + 180, y), TICK_FONT)?;
            y += LINE;
        }
        if others > 0 {
            draw_box(&legend, [(0, y - 14), (SAMPLE_W, y + 14)], COLOR_MARK)?;
            text(format!("{others} points"), (SAMPLE_W + 14, y), LEGEND_FONT)?;
            let kinds = counts.len() - PALETTE.len();
            text(
                format!("{kinds} other sequences (map.csv's signature column)"),
                (SAMPLE_W + 180, y),
                TICK_FONT,
            )?;
            y += LINE;
        }
        draw_box(&legend, [(0, y - 14), (SAMPLE_W, y + 14)], COLOR_NO_GAIT)?;
        text("no gait".to_string(), (SAMPLE_W + 14, y), LEGEND_FONT)?;
        y += 2 * LINE;
        let words = [
            "TD: touchdown, then its branch (DLS, SLS, ...)",
            "SLIP1, SLIP2: Leg 1's / Leg 2's tip slips through the touchdown",
            "SLIDE1, SLIDE2: a slip starts; STICK1, STICK2: it stops and sticks",
            "REVERSE1, REVERSE2: it stops and slips the other way",
            "LIFT2: Leg 2 leaves the ground; LOCK2: its stopper locks",
        ];
        for line in words {
            text(line.to_string(), (0, y), TICK_FONT)?;
            y += LINE - 6;
        }
        Ok(())
    }
}

/// Write the stick/slip figure of `figure`'s map as SVG and PNG.
pub(crate) fn write_signature_figure(
    figure: &MapFigure,
    svg: &Path,
    png: &Path,
) -> Result<(), PlotError> {
    has_points(figure.map)?;
    write_svg_png(&SignatureFigure { map: figure }, svg, png, SIZE)
}
