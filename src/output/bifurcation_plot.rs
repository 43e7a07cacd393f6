//! The bifurcation diagram (`vrw continue`: `bifurcation.png`, `bifurcation.svg`): one quantity of the gaits
//! against the parameter, every family in its own colour, solid where its gaits are stable and dashed where
//! they are not, and its special points marked and labelled (`LP`, `PD`, `NS`, `BC`).

use std::ops::Range;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::chart::{
    data_to_px, draw_axes_and_curves, draw_legend, draw_marker, finite_range, titled, Axes, Curve,
    DrawResult, Figure, Marker, Stroke, LEGEND_FONT,
};
use super::style::{
    font, padded, COLOR_BLACK, COLOR_BLUE, COLOR_GREEN, COLOR_MARK, COLOR_ORANGE, COLOR_PURPLE,
    COLOR_VERMILLION,
};

/// Size of `bifurcation.png` \[px\].
pub(crate) const BIFURCATION_SIZE: (u32, u32) = (2400, 1400);

/// Width reserved right of the panel for the legend \[px\].
const LEGEND_W: i32 = 520;

/// Radius of a special point's marker \[px\].
const SPECIAL_R: i32 = 9;

/// The families' colours, in order (the colour-blind-safe palette of the other figures).
const FAMILY_COLORS: [RGBColor; 7] = [
    COLOR_BLUE,
    COLOR_VERMILLION,
    COLOR_GREEN,
    COLOR_ORANGE,
    COLOR_PURPLE,
    COLOR_SKY,
    COLOR_BLACK,
];

/// Sky blue of the same palette (Okabe and Ito).
const COLOR_SKY: RGBColor = RGBColor(86, 180, 233);

/// One family of the diagram.
#[derive(Debug, Clone)]
pub(crate) struct DiagramFamily {
    /// Legend text.
    pub label: String,
    /// One line per phase of its gaits (`k` for a period-k family, whose steps each have their own value),
    /// each of points in order of arclength: parameter, value drawn, stable (`None`: uncertain or unknown).
    pub phases: Vec<Vec<(f64, f64, Option<bool>)>>,
    /// Where it ends without reaching the range's end or closing (the first phase's last value), and why
    /// (`rolled_back`, `stalled`, ...): marked with a cross and the word.
    pub ends: Vec<(f64, f64, String)>,
}

/// One special point of the diagram.
#[derive(Debug, Clone)]
pub(crate) struct DiagramSpecial {
    /// The family it belongs to (index into [`BifurcationFigure::families`]).
    pub family: usize,
    /// Parameter.
    pub param: f64,
    /// Value drawn.
    pub value: f64,
    /// Label (`LP`, `PD`, `NS`, `BC`).
    pub label: String,
}

/// The whole figure.
#[derive(Debug, Clone)]
pub(crate) struct BifurcationFigure {
    /// Title.
    pub title: String,
    /// X axis description with unit.
    pub param_label: String,
    /// Y axis description with unit.
    pub y_label: String,
    /// The parameter range.
    pub x: Range<f64>,
    /// The families.
    pub families: Vec<DiagramFamily>,
    /// The special points.
    pub special: Vec<DiagramSpecial>,
    /// The legend explains the line styles and special points (a diagram of families; not the plane of
    /// two-parameter curves).
    pub styles_in_legend: bool,
}

/// The colour of family `k`.
fn family_color(k: usize) -> RGBColor {
    FAMILY_COLORS[k % FAMILY_COLORS.len()]
}

/// A family as curves: each phase's line, stable stretches solid, the others dashed.
fn family_curves(k: usize, family: &DiagramFamily) -> Vec<Curve> {
    family
        .phases
        .iter()
        .flat_map(|phase| phase_curves(family_color(k), &family.label, phase))
        .collect()
}

/// One phase's line as curves: stable stretches solid, the others dashed; the point where the verdict
/// changes belongs to both stretches, so the line has no gap.
fn phase_curves(color: RGBColor, label: &str, phase: &[(f64, f64, Option<bool>)]) -> Vec<Curve> {
    let mut curves: Vec<Curve> = Vec::new();
    let mut current: Option<(bool, Vec<(f64, f64)>)> = None;
    let stroke = |stable: bool| {
        if stable {
            Stroke::Solid
        } else {
            Stroke::Dashed
        }
    };
    for &(p, v, stable) in phase {
        let stable = stable == Some(true);
        match &mut current {
            Some((kind, pts)) if *kind == stable => pts.push((p, v)),
            _ => {
                let mut start = Vec::new();
                if let Some((kind, pts)) = current.take() {
                    start.push(*pts.last().unwrap_or(&(p, v)));
                    curves.push(Curve {
                        label: label.to_string(),
                        color,
                        stroke: stroke(kind),
                        points: pts,
                    });
                }
                start.push((p, v));
                current = Some((stable, start));
            }
        }
    }
    if let Some((kind, pts)) = current {
        curves.push(Curve {
            label: label.to_string(),
            color,
            stroke: stroke(kind),
            points: pts,
        });
    }
    curves
}

impl BifurcationFigure {
    /// The special points inside the parameter range on `panel`, as circles with their labels; `to_px` maps
    /// data to the panel's pixels.
    fn draw_specials<DB: DrawingBackend>(
        &self,
        panel: &DrawingArea<DB, Shift>,
        to_px: &impl Fn((f64, f64)) -> (i32, i32),
    ) -> DrawResult<DB> {
        for sp in &self.special {
            if !(sp.param.is_finite() && sp.value.is_finite() && self.x.contains(&sp.param)) {
                continue;
            }
            let at = to_px((sp.param, sp.value));
            draw_marker(
                panel,
                at,
                Marker::Circle,
                family_color(sp.family),
                true,
                SPECIAL_R,
            )?;
            panel.draw(&Text::new(
                sp.label.clone(),
                (at.0 + SPECIAL_R + 4, at.1 - SPECIAL_R - 4),
                font(LEGEND_FONT).pos(Pos::new(HPos::Left, VPos::Bottom)),
            ))?;
        }
        Ok(())
    }

    /// The families' ends inside the parameter range on `panel`, as crosses with the word of why they end;
    /// `to_px` maps data to the panel's pixels and `right` is the plot's right edge in them.
    fn draw_ends<DB: DrawingBackend>(
        &self,
        panel: &DrawingArea<DB, Shift>,
        to_px: &impl Fn((f64, f64)) -> (i32, i32),
        right: i32,
    ) -> DrawResult<DB> {
        // The rectangles of the words written at the families' ends.
        let mut words: Vec<(i32, i32, i32, i32)> = Vec::new();
        for (k, family) in self.families.iter().enumerate() {
            for (param, value, why) in &family.ends {
                if !(param.is_finite() && value.is_finite() && self.x.contains(param)) {
                    continue;
                }
                let at = to_px((*param, *value));
                let style = family_color(k).stroke_width(3);
                let r = SPECIAL_R;
                panel.draw(&PathElement::new(
                    vec![(at.0 - r, at.1 - r), (at.0 + r, at.1 + r)],
                    style,
                ))?;
                panel.draw(&PathElement::new(
                    vec![(at.0 - r, at.1 + r), (at.0 + r, at.1 - r)],
                    style,
                ))?;
                // The word right of the cross, or left of it where it would leave the plot; none at a border
                // (its BC label says it) or where it would overlap a word already written.
                if why == "border" {
                    continue;
                }
                let style = font(LEGEND_FONT * 0.8);
                let (tw, th) = panel.estimate_text_size(why, &style)?;
                let (tw, th) = (tw as i32, th as i32);
                let (x, h_pos, left) = if at.0 + r + 4 + tw > right {
                    (at.0 - r - 4, HPos::Right, at.0 - r - 4 - tw)
                } else {
                    (at.0 + r + 4, HPos::Left, at.0 + r + 4)
                };
                let rect = (left, at.1 + r + 4, left + tw, at.1 + r + 4 + th);
                let overlaps = |o: &(i32, i32, i32, i32)| {
                    rect.0 < o.2 && o.0 < rect.2 && rect.1 < o.3 && o.1 < rect.3
                };
                if words.iter().any(overlaps) {
                    continue;
                }
                words.push(rect);
                panel.draw(&Text::new(
                    why.clone(),
                    (x, at.1 + r + 4),
                    style.pos(Pos::new(h_pos, VPos::Top)),
                ))?;
            }
        }
        Ok(())
    }

    /// The legend's rows: a row per family, then the line styles and special points where they are drawn.
    fn legend(&self) -> Vec<Curve> {
        let mut legend: Vec<Curve> = self
            .families
            .iter()
            .enumerate()
            .map(|(k, f)| Curve {
                label: f.label.clone(),
                color: family_color(k),
                stroke: Stroke::Solid,
                points: Vec::new(),
            })
            .collect();
        // The line styles' and special points' rows only where they are drawn.
        let styles = if self.styles_in_legend { 4 } else { 0 };
        legend.push(Curve {
            label: "stable".to_string(),
            color: COLOR_BLACK,
            stroke: Stroke::Solid,
            points: Vec::new(),
        });
        legend.push(Curve {
            label: "unstable or uncertain".to_string(),
            color: COLOR_BLACK,
            stroke: Stroke::Dashed,
            points: Vec::new(),
        });
        for label in [
            "LP fold, PD period doubling",
            "NS torus, BC border collision",
        ] {
            legend.push(Curve {
                label: label.to_string(),
                color: COLOR_MARK,
                stroke: Stroke::Markers,
                points: Vec::new(),
            });
        }
        legend.truncate(self.families.len() + styles);
        legend
    }
}

impl Figure for BifurcationFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let area = titled(root, &self.title)?;
        let (w, h) = area.dim_in_pixel();
        let (w, h) = (w as i32, h as i32);
        let panel = area.clone().shrink((0, 0), (w - LEGEND_W, h));
        let values = self
            .families
            .iter()
            .flat_map(|f| f.phases.iter().flatten().map(|p| p.1))
            .chain(self.special.iter().map(|s| s.value));
        let y = finite_range(values).map_or(-1.0..1.0, |r| padded(r.start, r.end, 0.08));
        let axes = Axes {
            x: self.x.clone(),
            y: y.clone(),
            x_label: Some(self.param_label.as_str()),
            y_label: &self.y_label,
            x_integer: false,
        };
        let curves: Vec<Curve> = self
            .families
            .iter()
            .enumerate()
            .flat_map(|(k, f)| family_curves(k, f))
            .collect();
        let (px, py) = draw_axes_and_curves(&panel, &axes, &curves, &[], &[])?;
        let base = panel.get_base_pixel();
        let to_px = data_to_px(self.x.clone(), y.clone(), (px.clone(), py.clone()), base);
        self.draw_specials(&panel, &to_px)?;
        self.draw_ends(&panel, &to_px, px.end - base.0)?;
        let area_base = area.get_base_pixel();
        draw_legend(
            &area,
            &self.legend(),
            &[],
            (w - LEGEND_W + 16, py.start - area_base.1 + 4),
        )?;
        Ok(())
    }
}
