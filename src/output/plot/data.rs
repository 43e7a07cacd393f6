//! Fig. 2's data: the sweep's indicators sorted by parameter and split into the runs a line joins (never
//! across a point without a gait or a change of gait family), the axis ranges and the marker size.

use std::ops::Range;

use plotters::style::RGBColor;

use super::super::chart::Marker;
use super::super::style::{padded, Seg, COLOR_BLACK, COLOR_BLUE, COLOR_VERMILLION};
use super::{Fig2Spec, IndicatorPoint, PlotError, ThresholdMark};

const NAME_I4: &[Seg] = &[Seg::Text("λ"), Seg::Sub("I4")];
const NAME_2: &[Seg] = &[Seg::Text("λ"), Seg::SubSup("2", "+")];
const NAME_4: &[Seg] = &[Seg::Text("λ"), Seg::SubSup("4", "+")];
const NAME_PERIOD: &[Seg] = &[Seg::Text("period")];
const NAME_FLOQUET: &[Seg] = &[Seg::Text("largest |multiplier|")];

const COLOR_I4: RGBColor = COLOR_BLACK;
const COLOR_2: RGBColor = COLOR_BLUE;
const COLOR_4: RGBColor = COLOR_VERMILLION;

/// `(param, value, scuffing)` of the points one line joins.
type Run = Vec<(f64, f64, bool)>;

/// One plotted indicator: its finite samples sorted by parameter, split into
/// runs that are not interrupted by points without a gait.
pub(super) struct Series {
    /// Legend text.
    pub(super) name: &'static [Seg],
    /// Colour.
    pub(super) color: RGBColor,
    /// Marker shape.
    pub(super) shape: Marker,
    /// Runs of `(param, value, scuffing)` joined by a line.
    pub(super) runs: Vec<Vec<(f64, f64, bool)>>,
    /// Whether each run's gaits have a period of several steps (drawn dashed).
    pub(super) multi_step: Vec<bool>,
}

impl Series {
    fn new(
        name: &'static [Seg],
        color: RGBColor,
        shape: Marker,
        sorted: &[&IndicatorPoint],
        value: fn(&IndicatorPoint) -> f64,
    ) -> Self {
        // Each run with whether its gaits have several steps per period.
        let mut runs: Vec<(Run, bool)> = vec![(Vec::new(), false)];
        let mut family = None;
        for p in sorted {
            let v = value(p);
            // A new run after a point without a value, and at every change of gait family (two families are
            // never joined by a line).
            if (!v.is_finite() || p.family != family) && !runs.last().unwrap().0.is_empty() {
                runs.push((Vec::new(), false));
            }
            if v.is_finite() {
                let run = runs.last_mut().unwrap();
                run.0.push((p.param, v, p.scuffing));
                run.1 = p.period_k > 1;
                family = p.family;
            }
        }
        runs.retain(|r| !r.0.is_empty());
        let (runs, multi_step) = runs.into_iter().unzip();
        Series {
            name,
            color,
            shape,
            runs,
            multi_step,
        }
    }

    pub(super) fn samples(&self) -> impl Iterator<Item = &(f64, f64, bool)> {
        self.runs.iter().flatten()
    }

    pub(super) fn any_scuffing(&self) -> bool {
        self.samples().any(|s| s.2)
    }

    pub(super) fn any_multi_step(&self) -> bool {
        self.multi_step.iter().any(|&m| m)
    }
}

/// Validated data and axis ranges.
pub(super) struct Prepared {
    /// The x range shown.
    pub(super) x: Range<f64>,
    /// The panels (a)-(d), each with its series and y range.
    pub(super) panels: [(Vec<Series>, Range<f64>); 4],
    /// The finite thresholds.
    pub(super) marks: Vec<ThresholdMark>,
    /// Intervals without a gait.
    pub(super) no_gait: Vec<Range<f64>>,
    /// Marker size \[px\].
    pub(super) marker: i32,
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

/// The series of the panels (a)-(d) of the points `sorted` by parameter: `lambda_I4`; `lambda_2+` and
/// `lambda_4+`; the period; the largest multiplier.
fn panel_series(sorted: &[&IndicatorPoint]) -> [Vec<Series>; 4] {
    let panel_a = vec![Series::new(
        NAME_I4,
        COLOR_I4,
        Marker::Circle,
        sorted,
        |p| p.lambda_i4,
    )];
    let panel_b = vec![
        Series::new(NAME_2, COLOR_2, Marker::Circle, sorted, |p| p.lambda_2_plus),
        Series::new(NAME_4, COLOR_4, Marker::Triangle, sorted, |p| {
            p.lambda_4_plus
        }),
    ];
    let panel_c = vec![Series::new(
        NAME_PERIOD,
        COLOR_I4,
        Marker::Circle,
        sorted,
        |p| p.period,
    )];
    let panel_d = vec![Series::new(
        NAME_FLOQUET,
        COLOR_BLUE,
        Marker::Circle,
        sorted,
        |p| p.max_floquet,
    )];
    [panel_a, panel_b, panel_c, panel_d]
}

/// The x range shown: `given` if it is not empty, else the span of the samples `xs` and the `marks`, padded
/// (and not below zero when they are not).
fn x_range(given: Option<&Range<f64>>, xs: &[f64], marks: &[ThresholdMark]) -> Range<f64> {
    match given {
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
    }
}

/// The marker size \[px\]: smaller the more samples the densest series of panels (a) and (b) has.
fn marker_size(panel_a: &[Series], panel_b: &[Series]) -> i32 {
    let n = [panel_a, panel_b]
        .into_iter()
        .flatten()
        .map(|s| s.samples().count())
        .max()
        .unwrap_or(1)
        .max(1) as i32;
    (1100 / n / 2).clamp(4, 7)
}

impl Prepared {
    /// The series, axis ranges and marker size of `spec`; an error if it has no points or no gait.
    pub(super) fn new(spec: &Fig2Spec) -> Result<Self, PlotError> {
        if spec.points.is_empty() {
            return Err(PlotError::Empty("the sweep has no points".into()));
        }
        let mut sorted: Vec<&IndicatorPoint> =
            spec.points.iter().filter(|p| p.param.is_finite()).collect();
        sorted.sort_by(|a, b| a.param.total_cmp(&b.param));
        let [panel_a, panel_b, panel_c, panel_d] = panel_series(&sorted);
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
        let x = x_range(spec.x_range.as_ref(), &xs, &marks);
        let marker = marker_size(&panel_a, &panel_b);
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
