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

mod data;
mod draw;

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::{write_svg_png, DrawResult, Figure};
pub(crate) use super::style::PlotError;
#[cfg(test)]
use super::style::{png_size, FAMILY};
use data::Prepared;
use draw::draw_fig2;

/// One gait on the sweep: the parameter value and its DLS indicators (docs/model.md section 5).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct IndicatorPoint {
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
    /// Steps per period of the gait (a period-k gait, `k > 1`, is drawn dashed); 1 without a gait.
    pub period_k: usize,
    /// Largest Floquet multiplier modulus of the gait; NaN when there is no gait.
    pub max_floquet: f64,
}

/// A vertical annotated marker.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ThresholdMark {
    /// Text drawn verbatim beside the line, e.g. `"λ₄⁺ = 0 at c = 220.1"` or `"c = 220.1"`.
    pub label: String,
    /// Parameter value where the line is drawn (same unit as [`IndicatorPoint::param`]).
    /// Non-finite values are skipped.
    pub value: f64,
}

/// What to draw in Fig. 2.
pub(crate) struct Fig2Spec<'a> {
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
pub(crate) const FIG2_SIZE: (u32, u32) = (1600, 1600);

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
pub(crate) fn write_fig2(
    spec: &Fig2Spec,
    svg_path: &Path,
    png_path: &Path,
) -> Result<(), PlotError> {
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
                    period_k: 1,
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
}
