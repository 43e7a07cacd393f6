//! The orbit diagram (`vrw orbit`: `orbit.png`): against one parameter, the section states and DLS indicators
//! the walk visits after its transient, drawn as points, with the period-1 gait branch from continuation drawn
//! as a line, solid where the gait is stable and dashed where it is not (README,
//! "Orbit diagram, basin of attraction, period-k gaits").

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::{
    data_to_px, draw_axes_and_curves, draw_legend, finite_range, titled, write_png, Axes, Band,
    Clip, Curve, DrawResult, Figure, Stroke, DASH_GAP,
};
use super::style::{padded, PlotError, COLOR_BLACK, COLOR_BLUE, COLOR_MARK, COLOR_VERMILLION};

/// Size of `orbit.png` \[px\].
pub(crate) const ORBIT_SIZE: (u32, u32) = (2400, 1600);

/// Radius of a point of the diagram \[px\].
const DOT: i32 = 3;

/// Width reserved right of the panels for the legend \[px\].
const LEGEND_W: i32 = 470;

/// Shading of the parameter values where the walk fails.
const COLOR_FAILED: RGBColor = RGBColor(235, 235, 235);

/// One point of the period-1 branch: the parameter value, the value drawn, and whether the gait is stable
/// there (`None`: uncertain).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BranchPoint {
    /// The parameter value.
    pub param: f64,
    /// The quantity drawn.
    pub value: f64,
    /// Stable (`Some(true)`), unstable (`Some(false)`) or uncertain (`None`).
    pub stable: Option<bool>,
}

/// One panel: one quantity against the parameter.
#[derive(Debug, Clone)]
pub(crate) struct OrbitPanel {
    /// Y axis description with unit.
    pub y_label: String,
    /// The points the walk visits `(parameter, value)`.
    pub points: Vec<(f64, f64)>,
    /// The period-1 branch, in parameter order; a non-finite value breaks it.
    pub branch: Vec<BranchPoint>,
}

/// The whole figure.
#[derive(Debug, Clone)]
pub(crate) struct OrbitFigure {
    /// Title.
    pub title: String,
    /// X axis description with unit.
    pub param_label: String,
    /// The parameter range.
    pub x: Range<f64>,
    /// Panels, top to bottom.
    pub panels: Vec<OrbitPanel>,
    /// Stretches of the parameter where the walk fails, shaded, with what the legend calls them.
    pub failed: Vec<(Range<f64>, String)>,
}

/// The branch as curves: stable stretches solid (black), unstable ones dashed (vermillion), uncertain ones
/// dashed grey. Consecutive points of one kind form one curve; the point where the kind changes belongs to
/// both stretches so the line has no gap.
fn branch_curves(branch: &[BranchPoint]) -> Vec<Curve> {
    let style = |stable: Option<bool>| match stable {
        Some(true) => ("period-1 gait, stable", COLOR_BLACK, Stroke::Solid),
        Some(false) => ("period-1 gait, unstable", COLOR_VERMILLION, Stroke::Dashed),
        None => ("period-1 gait, uncertain", COLOR_MARK, Stroke::Dashed),
    };
    let mut curves: Vec<Curve> = Vec::new();
    /// The stretch being built: its stability and points.
    type Stretch = (Option<bool>, Vec<(f64, f64)>);
    let mut current: Option<Stretch> = None;
    for p in branch {
        if !p.value.is_finite() {
            if let Some((kind, pts)) = current.take() {
                curves.push(curve(style(kind), pts));
            }
            continue;
        }
        match &mut current {
            Some((kind, pts)) if *kind == p.stable => pts.push((p.param, p.value)),
            _ => {
                let mut start = Vec::new();
                if let Some((kind, pts)) = current.take() {
                    start.push(*pts.last().unwrap_or(&(p.param, p.value)));
                    curves.push(curve(style(kind), pts));
                }
                start.push((p.param, p.value));
                current = Some((p.stable, start));
            }
        }
    }
    if let Some((kind, pts)) = current {
        curves.push(curve(style(kind), pts));
    }
    curves
}

fn curve((label, color, stroke): (&str, RGBColor, Stroke), points: Vec<(f64, f64)>) -> Curve {
    Curve {
        label: label.to_string(),
        color,
        stroke,
        points,
    }
}

/// One legend entry per kind of line drawn.
fn legend_curves(curves: &[Curve]) -> Vec<Curve> {
    let mut seen: Vec<Curve> = Vec::new();
    for c in curves {
        if !seen.iter().any(|s| s.label == c.label) {
            seen.push(Curve {
                points: Vec::new(),
                ..c.clone()
            });
        }
    }
    seen
}

impl OrbitFigure {
    fn y_range(panel: &OrbitPanel) -> Range<f64> {
        let values = panel
            .points
            .iter()
            .map(|p| p.1)
            .chain(panel.branch.iter().map(|b| b.value));
        match finite_range(values) {
            Some(r) => padded(r.start, r.end, 0.06),
            None => -1.0..1.0,
        }
    }
}

impl Figure for OrbitFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let area = titled(root, &self.title)?;
        let (w, h) = area.dim_in_pixel();
        let (w, h) = (w as i32, h as i32);
        let n = self.panels.len().max(1) as i32;
        let inner = h / n;
        for (k, panel) in self.panels.iter().enumerate() {
            let k = k as i32;
            let last = k == n - 1;
            let sub = area.clone().shrink(
                (0, k * inner),
                (w - LEGEND_W, if last { h - k * inner } else { inner }),
            );
            let y = Self::y_range(panel);
            let axes = Axes {
                x: self.x.clone(),
                y: y.clone(),
                x_label: last.then_some(self.param_label.as_str()),
                y_label: &panel.y_label,
                x_integer: false,
            };
            let curves = branch_curves(&panel.branch);
            // Axes first (no curves), then the points, then the branch on top.
            let bands: Vec<Band> = self
                .failed
                .iter()
                .map(|(r, _)| Band {
                    from: r.start,
                    to: r.end,
                    color: COLOR_FAILED,
                })
                .collect();
            let (px, py) = draw_axes_and_curves(&sub, &axes, &[], &bands, &[])?;
            let base = sub.get_base_pixel();
            let to_px = data_to_px(self.x.clone(), y.clone(), (px.clone(), py.clone()), base);
            let clip = Clip::new(
                px.start - base.0..px.end - base.0,
                py.start - base.1..py.end - base.1,
            );
            for &p in &panel.points {
                if p.0.is_finite() && p.1.is_finite() && y.contains(&p.1) {
                    clip.draw_circle(&sub, to_px(p), DOT, COLOR_BLUE.filled())?;
                }
            }
            for c in &curves {
                let pts: Vec<(i32, i32)> = c.points.iter().map(|&p| to_px(p)).collect();
                let style = c.color.stroke_width(3);
                match c.stroke {
                    Stroke::Dashed => clip.draw_dashed(&sub, &pts, style, DASH_GAP)?,
                    _ => clip.draw_path(&sub, &pts, style)?,
                }
            }
            let mut legend = legend_curves(&curves);
            legend.insert(
                0,
                Curve {
                    label: "walk after the transient".to_string(),
                    color: COLOR_BLUE,
                    stroke: Stroke::Markers,
                    points: Vec::new(),
                },
            );
            if k == 0 {
                let mut swatches: Vec<(String, RGBColor)> = Vec::new();
                for (_, label) in &self.failed {
                    if !swatches.iter().any(|s| &s.0 == label) {
                        swatches.push((label.clone(), COLOR_FAILED));
                    }
                }
                let area_base = area.get_base_pixel();
                draw_legend(
                    &area,
                    &legend,
                    &swatches,
                    (w - LEGEND_W + 16, py.start - area_base.1 + 4),
                )?;
            }
        }
        Ok(())
    }
}

/// Write the orbit diagram as a PNG at `png`.
pub(crate) fn write_orbit_figure(figure: &OrbitFigure, png: &Path) -> Result<(), PlotError> {
    if figure
        .panels
        .iter()
        .all(|p| p.points.is_empty() && p.branch.is_empty())
    {
        return Err(PlotError::Empty(
            "the orbit diagram has no points".to_string(),
        ));
    }
    write_png(figure, png, ORBIT_SIZE)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bp(param: f64, stable: Option<bool>) -> BranchPoint {
        BranchPoint {
            param,
            value: param,
            stable,
        }
    }

    /// The branch splits where its stability changes, without a gap, and breaks at a missing gait.
    #[test]
    fn branch_splits_by_stability_without_gaps() {
        let branch = [
            bp(0.0, Some(true)),
            bp(1.0, Some(true)),
            bp(2.0, Some(false)),
            bp(3.0, Some(false)),
            BranchPoint {
                param: 4.0,
                value: f64::NAN,
                stable: None,
            },
            bp(5.0, Some(false)),
        ];
        let curves = branch_curves(&branch);
        assert_eq!(curves.len(), 3);
        assert_eq!(curves[0].stroke, Stroke::Solid);
        assert_eq!(curves[1].points.first(), Some(&(1.0, 1.0)));
        assert_eq!(curves[1].stroke, Stroke::Dashed);
        assert_eq!(curves[2].points, vec![(5.0, 5.0)]);
        assert_eq!(legend_curves(&curves).len(), 2);
    }

    #[test]
    fn writes_a_png_and_refuses_an_empty_figure() {
        let dir = tempfile::tempdir().unwrap();
        let figure = OrbitFigure {
            failed: vec![(4.5..5.0, "walk fails: rolled back".to_string())],
            title: "test".to_string(),
            param_label: "c [N s/m]".to_string(),
            x: 0.0..5.0,
            panels: vec![OrbitPanel {
                y_label: "dθ/dt [rad/s]".to_string(),
                points: vec![(1.0, 1.0), (2.0, 1.5), (2.0, 0.5)],
                branch: vec![bp(0.0, Some(true)), bp(5.0, Some(false))],
            }],
        };
        let png = dir.path().join("orbit.png");
        write_orbit_figure(&figure, &png).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(super::super::style::png_size(&bytes), Some(ORBIT_SIZE));
        let empty = OrbitFigure {
            panels: vec![],
            ..figure
        };
        assert!(matches!(
            write_orbit_figure(&empty, &png),
            Err(PlotError::Empty(_))
        ));
    }
}
