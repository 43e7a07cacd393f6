//! `vrw sweep --model NAME --param KEY`: a walker's gait along one parameter, each value's gait continued from
//! its neighbour's (the shared grid runner's schedule, `study::grid`), with its multipliers and stability:
//! `sweep.csv` (a row per value, the wheel's columns where they mean the same, the section named by the
//! model) and `thresholds.json` (where the largest multiplier's modulus crosses 1, bisected between the two
//! values around it, with the kind of the crossing). The per-value gaits are also the period-1 branch of
//! `vrw orbit --model`. Written once for every walker, on [`super::WalkerModel`].

use std::path::PathBuf;

use nalgebra::DVector;
use serde::Serialize;

use super::walker_model::FoundGait;
use super::walker_output::{write_rows, WalkerOutput};
use super::walkers::{as_map, named, Walker};
use super::{check_interrupted, in_run_on, AppError};
use crate::output;
use crate::study::grid::{run_rows, Evaluated};

/// Steps walked before the gait search at a value that continues no neighbour.
pub const FRESH_TRANSIENT: usize = 20;

/// Thresholds are bisected until their bracket is this narrow, relative to the parameter (at least 1).
pub const THRESHOLD_TOL: f64 = 1e-10;

/// A walker's range of parameter values: `param` from `from` to `to` in `points` values, ends included.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerRange {
    /// The parameter (one of the walker's keys).
    pub param: String,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values.
    pub points: usize,
}

impl WalkerRange {
    /// The values, after the range is checked against `walker` (a key of its, finite and distinct ends that the
    /// walker takes, 2 to `max_points` values); the error names the job's option.
    pub fn values(&self, walker: &Walker, max_points: usize) -> Result<Vec<f64>, AppError> {
        walker.checked_parameter("param", &self.param)?;
        let bad = |option, reason: String| Err(AppError::InvalidOption { option, reason });
        for (option, v) in [("from", self.from), ("to", self.to)] {
            if let Err(e) = walker.with_parameter(&self.param, v) {
                return bad(option, e.to_string());
            }
        }
        if self.from == self.to {
            return bad("from/to", format!("`from` and `to` are both {}", self.from));
        }
        if !(2..=max_points).contains(&self.points) {
            return bad(
                "points",
                format!("{} values is not between 2 and {max_points}", self.points),
            );
        }
        let step = (self.to - self.from) / (self.points - 1) as f64;
        Ok((0..self.points)
            .map(|k| match k {
                k if k + 1 == self.points => self.to,
                k => self.from + k as f64 * step,
            })
            .collect())
    }
}

/// The most values of a walker's sweep.
pub const MAX_WALKER_SWEEP_POINTS: usize = 100_000;

/// What `vrw sweep --model NAME` runs.
#[derive(Debug, Clone)]
pub struct WalkerSweepJob {
    /// The walker (the swept parameter is set value by value).
    pub walker: Walker,
    /// The parameter and its values.
    pub range: WalkerRange,
    /// Where the search at the first value starts (the section's coordinates); default the model's start.
    pub initial: Option<Vec<f64>>,
    /// Output directory.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir`.
    pub overwrite: bool,
}

/// The gait at one value.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkerSweepPoint {
    /// The value.
    pub value: f64,
    /// The gait, or why there is none.
    pub gait: Result<FoundGait, String>,
    /// `invalid_parameter` or the failed search's kind, where there is no gait.
    pub failure: Option<&'static str>,
}

impl WalkerSweepPoint {
    /// `stable`, `unstable`, or the failure's kind.
    pub fn status(&self) -> &'static str {
        match (&self.gait, self.failure) {
            (Ok(g), _) if g.largest_multiplier() < 1.0 => "stable",
            (Ok(_), _) => "unstable",
            (Err(_), kind) => kind.unwrap_or("failed"),
        }
    }
}

/// The gait of `walker` with `param = value`, searched from `from` (a neighbour's gait, without a transient)
/// or else from `start` after [`FRESH_TRANSIENT`] steps.
pub(super) fn gait_at(
    walker: &Walker,
    param: &str,
    value: f64,
    (from, start): (Option<&DVector<f64>>, &DVector<f64>),
) -> WalkerSweepPoint {
    let at = match walker.with_parameter(param, value) {
        Ok(at) => at,
        Err(e) => {
            return WalkerSweepPoint {
                value,
                gait: Err(e.to_string()),
                failure: Some("invalid_parameter"),
            }
        }
    };
    let model = match at.model() {
        Ok(model) => model,
        Err(e) => {
            return WalkerSweepPoint {
                value,
                gait: Err(e.to_string()),
                failure: Some("invalid_model"),
            }
        }
    };
    let gait = match from.map(|s| model.gait(s, 0)) {
        Some(Ok(g)) => Ok(g),
        _ => model.gait(start, FRESH_TRANSIENT),
    };
    WalkerSweepPoint {
        value,
        failure: gait.as_ref().err().map(|e| e.kind()),
        gait: gait.map_err(|e| e.to_string()),
    }
}

/// The gaits of `walker` over `values` of `param`, each continued from its neighbour's (the grid runner's
/// schedule); the first value's search starts at `start`. Cut to its complete prefix by Ctrl-C.
pub(super) fn walker_gaits(
    walker: &Walker,
    param: &str,
    values: &[f64],
    start: &DVector<f64>,
) -> Vec<WalkerSweepPoint> {
    run_rows(1, values.len(), |cell, from| {
        let point = gait_at(walker, param, values[cell.col], (from.map(|f| f.1), start));
        let carry = point.gait.as_ref().ok().map(|g| g.section.clone());
        Evaluated { point, carry }
    })
    .into_iter()
    .next()
    .unwrap_or_default()
}

/// Where the gait's stability changes between two values of a sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerThreshold {
    /// `period_doubling` (a real multiplier crossing -1), `fold` (crossing +1) or `neimark_sacker` (a complex
    /// pair crossing the unit circle).
    pub kind: &'static str,
    /// The parameter's value (bisected to `THRESHOLD_TOL`); `NaN` if a search in the bracket failed.
    pub value: f64,
    /// The bracket it was bisected from (two values of the sweep).
    pub bracket: [f64; 2],
    /// The multipliers `[re, im]` at the stable end of the final bracket.
    pub multipliers: Vec<[f64; 2]>,
    /// The gait there, by the section's coordinates.
    #[serde(serialize_with = "as_map")]
    pub section: Vec<(String, f64)>,
    /// Why it was not bisected to the end, if it was not.
    pub note: Option<String>,
}

/// `thresholds.json` of a walker's sweep.
#[derive(Debug, Clone, Serialize)]
pub struct WalkerSweepSummary {
    /// vrw's version.
    pub vrw_version: &'static str,
    /// The model's name.
    pub model: String,
    /// Its parameters (the swept one as given).
    pub parameters: Walker,
    /// The range.
    pub range: WalkerRange,
    /// Values with a gait.
    pub gaits_found: usize,
    /// Values with a stable gait.
    pub stable: usize,
    /// Where stability changes.
    pub thresholds: Vec<WalkerThreshold>,
    /// The files written.
    pub files: Vec<String>,
}

/// Sweep `job.walker`'s gait and write `sweep.csv` and `thresholds.json`, after the options and the output
/// directory are checked.
pub fn run_walker_sweep(job: &WalkerSweepJob) -> Result<WalkerSweepSummary, AppError> {
    let values = job.range.values(&job.walker, MAX_WALKER_SWEEP_POINTS)?;
    let model = job.walker.model()?;
    let start = super::walkers::start_of(model.as_ref(), job.initial.as_deref())?;
    let names = model.section_names();
    output::manifest::check_out_dir(&job.out_dir, "sweep", job.overwrite)?;
    in_run_on(
        &job.out_dir,
        job.overwrite,
        ("sweep", Some(job.walker.name())),
        |run| {
            let points = walker_gaits(&job.walker, &job.range.param, &values, &start);
            let rows = sweep_rows(&job.range.param, &names, &points);
            write_rows(&run.path("sweep.csv"), &rows)?;
            run.add("sweep.csv");
            check_interrupted(points.len(), values.len(), "sweep.csv")?;
            let summary = sweep_summary(
                job,
                (model.name(), &names),
                &points,
                "sweep.csv is complete",
            )?;
            output::write_json(&run.path("thresholds.json"), &summary)?;
            run.add("thresholds.json");
            Ok((summary, None))
        },
    )
}

/// The sweep of [`run_walker_sweep`] at `values` (the range's, [`WalkerRange::values`], or others the caller
/// checked: the Python binding's list) without its files: `thresholds.json`'s fields and the rows of
/// `sweep.csv` (`job.out_dir` and `job.overwrite` are not read). Ctrl-C: an error, nothing kept.
pub fn compute_walker_sweep(
    job: &WalkerSweepJob,
    values: &[f64],
) -> Result<WalkerOutput<WalkerSweepSummary>, AppError> {
    let model = job.walker.model()?;
    let start = super::walkers::start_of(model.as_ref(), job.initial.as_deref())?;
    let names = model.section_names();
    let points = walker_gaits(&job.walker, &job.range.param, values, &start);
    super::check_phase_interrupted(None, "while sweeping", super::NOTHING_WRITTEN)?;
    let summary = sweep_summary(job, (model.name(), &names), &points, super::NOTHING_WRITTEN)?;
    Ok(WalkerOutput {
        summary,
        tables: vec![("sweep.csv", sweep_rows(&job.range.param, &names, &points))],
    })
}

/// `thresholds.json`'s fields for the gaits `points` of `job` (the model's name and section's names given),
/// their thresholds bisected; an error if Ctrl-C cut the bisection short (`kept`: what the job has written).
fn sweep_summary(
    job: &WalkerSweepJob,
    (model, names): (&str, &[String]),
    points: &[WalkerSweepPoint],
    kept: &str,
) -> Result<WalkerSweepSummary, AppError> {
    let thresholds = thresholds(&job.walker, &job.range.param, names, points);
    super::check_phase_interrupted(None, "while bisecting the thresholds", kept)?;
    Ok(WalkerSweepSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        model: model.to_string(),
        parameters: job.walker.clone(),
        range: job.range.clone(),
        gaits_found: points.iter().filter(|p| p.gait.is_ok()).count(),
        stable: points.iter().filter(|p| p.status() == "stable").count(),
        thresholds,
        files: vec!["sweep.csv".to_string(), "thresholds.json".to_string()],
    })
}

/// The rows of a walker's `sweep.csv`, its header first: the value, the status, the section, `lambda_I4`,
/// the step's period, stride and speed, the impact's loss, stability, `max_floquet`, the multipliers, the
/// search's residual and iterations, and the failure.
pub(super) fn sweep_rows(
    param: &str,
    names: &[String],
    points: &[WalkerSweepPoint],
) -> Vec<Vec<String>> {
    let dim = names.len();
    let mut header: Vec<String> = vec![param.to_string(), "status".to_string()];
    header.extend(names.iter().cloned());
    header.extend(
        [
            "lambda_I4",
            "period",
            "step_length",
            "speed",
            "impact_loss",
            "stability",
            "max_floquet",
        ]
        .map(String::from),
    );
    header.extend(
        (1..=dim).flat_map(|k| [format!("multiplier_{k}_re"), format!("multiplier_{k}_im")]),
    );
    header.extend(["residual", "iterations", "message"].map(String::from));
    let row = |p: &WalkerSweepPoint| {
        let mut row = vec![output::num(p.value), p.status().to_string()];
        match &p.gait {
            Ok(g) => {
                let s = &g.step;
                row.extend(g.section.iter().map(|v| output::num(*v)));
                row.extend(
                    [
                        s.lambda_i4,
                        s.period,
                        s.stride,
                        s.stride / s.period,
                        s.impact_loss,
                    ]
                    .map(output::num),
                );
                row.push(
                    if g.largest_multiplier() < 1.0 {
                        "stable"
                    } else {
                        "unstable"
                    }
                    .to_string(),
                );
                row.push(output::num(g.largest_multiplier()));
                row.extend(g.multipliers.iter().flat_map(|m| m.map(output::num)));
                row.extend([
                    output::num(g.residual),
                    g.iterations.to_string(),
                    String::new(),
                ]);
            }
            Err(message) => {
                row.extend(std::iter::repeat_n(String::new(), header.len() - 3));
                row.push(message.clone());
            }
        }
        row
    };
    std::iter::once(header.clone())
        .chain(points.iter().map(row))
        .collect()
}

/// Every change of stability between two neighbouring values with gaits, bisected.
pub(super) fn thresholds(
    walker: &Walker,
    param: &str,
    names: &[String],
    points: &[WalkerSweepPoint],
) -> Vec<WalkerThreshold> {
    points
        .windows(2)
        .filter_map(|pair| match (&pair[0].gait, &pair[1].gait) {
            (Ok(a), Ok(b)) if (a.largest_multiplier() < 1.0) != (b.largest_multiplier() < 1.0) => {
                Some(bisect(
                    walker,
                    param,
                    names,
                    [(pair[0].value, a), (pair[1].value, b)],
                ))
            }
            _ => None,
        })
        .collect()
}

/// The value between the two ends (with their gaits) where the largest multiplier's modulus is 1, by
/// bisection: each midpoint's gait continued from the nearer end's.
fn bisect(
    walker: &Walker,
    param: &str,
    names: &[String],
    ends: [(f64, &FoundGait); 2],
) -> WalkerThreshold {
    let bracket = [ends[0].0, ends[1].0];
    let stable_first = ends[0].1.largest_multiplier() < 1.0;
    let (mut lo, mut hi) = (ends[0].0, ends[1].0);
    let (mut at_lo, mut at_hi) = (ends[0].1.clone(), ends[1].1.clone());
    let mut note = None;
    while (hi - lo).abs() > THRESHOLD_TOL * lo.abs().max(1.0) {
        let mid = 0.5 * (lo + hi);
        let point = gait_at(walker, param, mid, (Some(&at_lo.section), &at_lo.section));
        match point.gait {
            Ok(g) if (g.largest_multiplier() < 1.0) == stable_first => (lo, at_lo) = (mid, g),
            Ok(g) => (hi, at_hi) = (mid, g),
            Err(e) => {
                note = Some(format!("no gait at {param} = {mid}: {e}"));
                break;
            }
        }
    }
    let stable = if stable_first { &at_lo } else { &at_hi };
    let crossing = if stable_first { &at_hi } else { &at_lo };
    WalkerThreshold {
        kind: match crossing.multipliers.first() {
            Some([_, im]) if *im != 0.0 => "neimark_sacker",
            Some([re, _]) if *re < 0.0 => "period_doubling",
            _ => "fold",
        },
        value: if note.is_some() {
            f64::NAN
        } else {
            0.5 * (lo + hi)
        },
        bracket,
        multipliers: stable.multipliers.clone(),
        section: named(names, &stable.section),
        note,
    }
}
