//! `vrw continue --model NAME` for the walkers other than the wheel (docs/model.md section 13): the family of
//! the start's gait in one parameter by pseudo-arclength continuation (`crate::continuation`), for a
//! rigid-legged walker with its exact derivatives ([`RigidFamily`]), for a walker with compliant legs with
//! Richardson-extrapolated differences ([`LeggedFamily`]); `branch.csv` (a row per point) and
//! `special_points.json`.

use std::path::PathBuf;

use nalgebra::DVector;
use serde::Serialize;

use super::legged::{legged_interruptible, search_legged_gait};
use super::walker_model::{interruptible, search_gait};
use super::walker_output::{write_rows, WalkerOutput};
use super::walkers::{as_map, named, rigid_start, unreachable_walk, Walker};
use super::{in_run_on, AppError};
use crate::continuation::{
    continue_family, ContinuationOptions, FamilyEnd, FamilyMap, FamilyPoint, SpecialKind,
};
use crate::mechanism::legged::derivative::LeggedDerivatives;
use crate::mechanism::legged::family::{LeggedFamily, LeggedInfo};
use crate::mechanism::rigid::RigidWalker;
use crate::mechanism::rigid_family::{Parametrized, RigidFamily, RigidInfo};
use crate::mechanism::rigid_gait::{DIFFERENCE_STEP, EXACT_ROUTE};
use crate::output;
use crate::output::walker_run::branch_text;

/// What `vrw continue --model NAME` follows.
#[derive(Debug, Clone)]
pub struct WalkerContinueJob {
    /// The walker.
    pub walker: Walker,
    /// The parameter followed.
    pub param: String,
    /// Where the first gait is searched (default the parameter's value in the walker).
    pub start: Option<f64>,
    /// The range followed.
    pub range: (f64, f64),
    /// Most points in each direction.
    pub max_points: usize,
    /// Largest continuation step (scaled unknowns).
    pub max_step: f64,
    /// Output directory for `branch.csv` and `special_points.json`.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir`.
    pub overwrite: bool,
}

/// `special_points.json` of a walker's family.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerContinueSummary {
    /// vrw's version.
    pub vrw_version: &'static str,
    /// The model's name.
    pub model: &'static str,
    /// Its parameters (the followed one at the start's value).
    pub parameters: Walker,
    /// The parameter followed.
    pub param: String,
    /// Where the family was started.
    pub start: f64,
    /// Points on the family (rows of `branch.csv`).
    pub points: usize,
    /// How the family ends at its first point and at its last.
    pub ends: [FamilyEnd; 2],
    /// Its special points.
    pub special_points: Vec<WalkerSpecialPoint>,
    /// How `DP` was taken.
    pub derivative: String,
}

/// A special point of a walker's family.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerSpecialPoint {
    /// `LP`, `PD`, `NS` or `BC` (the DLS indicator `lambda_I4` crossing zero).
    pub kind: SpecialKind,
    /// The parameter's value.
    pub value: f64,
    /// Solved for (`true`), or only bracketed between two points of the family.
    pub located: bool,
    /// Why it is not located, or how it was.
    pub note: Option<String>,
    /// The multipliers there `[re, im]`.
    pub multipliers: Vec<[f64; 2]>,
    /// The fixed point, by the section's coordinates.
    #[serde(serialize_with = "as_map")]
    pub section: Vec<(String, f64)>,
}

/// Follow the family of `job.walker`'s gait in `job.param` by pseudo-arclength continuation and write
/// `branch.csv` (a row per point) and `special_points.json`, after the output directory is checked.
pub fn run_walker_continuation(job: &WalkerContinueJob) -> Result<WalkerContinueSummary, AppError> {
    crate::output::manifest::check_out_dir(&job.out_dir, "continue", job.overwrite)?;
    let WalkerOutput { summary, tables } = compute_walker_continuation(job)?;
    in_run_on(
        &job.out_dir,
        job.overwrite,
        ("continue", Some(job.walker.name())),
        |run| {
            for (name, rows) in &tables {
                write_rows(&run.path(name), rows)?;
                run.add(name);
            }
            output::write_json(&run.path("special_points.json"), &summary)?;
            run.add("special_points.json");
            Ok((summary, None))
        },
    )
}

/// The family of [`run_walker_continuation`] without its files (the Python binding): `special_points.json`'s
/// fields and the rows of `branch.csv` (`job.out_dir` and `job.overwrite` are not read).
pub fn compute_walker_continuation(
    job: &WalkerContinueJob,
) -> Result<WalkerOutput<WalkerContinueSummary>, AppError> {
    let (summary, rows) = match &job.walker {
        Walker::Simplest(w) => follow(w, w.default_start(), job)?,
        Walker::Compass(w) => follow(w, w.default_start(), job)?,
        Walker::Telescopic(w) => follow_legged::<_, 6, 13>(w, w.default_start(), job)?,
        Walker::Described(any) if any.walks_compliant() => crate::with_legged_described!(
            any, w, N, Y => follow_legged::<_, N, Y>(w, super::walker_described::described_start(w), job)?,
            _ => unreachable_walk(any)?
        ),
        Walker::Described(w) => {
            let start = rigid_start(w, None)?;
            crate::with_rigid_described!(w, w => follow(w, start, job)?, _ => unreachable_walk(w)?)
        }
    };
    Ok(WalkerOutput {
        summary,
        tables: vec![("branch.csv", rows)],
    })
}

/// The family of [`run_walker_continuation`] for the rigid walker `walker` (its first gait searched from
/// `section`), and the rows of `branch.csv` (its header first).
fn follow<W, const N: usize, const Y: usize>(
    walker: &W,
    section: DVector<f64>,
    job: &WalkerContinueJob,
) -> Result<(WalkerContinueSummary, Vec<Vec<String>>), AppError>
where
    W: RigidWalker<N, Y> + Parametrized + Sync,
{
    let family: RigidFamily<W, N, Y> = RigidFamily::new(walker, &job.param)
        .map_err(|e| param_error(e.to_string()))?
        .with_options(interruptible());
    let start = job.start.unwrap_or(current_value(job)?);
    let at_start = walker.with_parameter(&job.param, start)?;
    let gait = search_gait(&at_start, &section, TRANSIENT_STEPS)
        .map_err(|e| param_error(format!("no gait at {} = {start}: {e}", job.param)))?;
    follow_family(
        &family,
        (&gait.section, start),
        &walker.section_names(),
        job,
    )
}

/// The family of [`run_walker_continuation`] for the walker with compliant legs `walker` (its first gait
/// searched from `section`), and the rows of `branch.csv` (its header first).
fn follow_legged<W, const N: usize, const Y: usize>(
    walker: &W,
    section: DVector<f64>,
    job: &WalkerContinueJob,
) -> Result<(WalkerContinueSummary, Vec<Vec<String>>), AppError>
where
    W: LeggedDerivatives<N> + Parametrized + Sync,
{
    let family: LeggedFamily<W, N, Y> = LeggedFamily::new(walker, &job.param)
        .map_err(|e| param_error(e.to_string()))?
        .with_options(legged_interruptible());
    let start = job.start.unwrap_or(current_value(job)?);
    let at_start = walker.with_parameter(&job.param, start)?;
    let gait = search_legged_gait::<W, N, Y>(&at_start, &section, TRANSIENT_STEPS)
        .map_err(|e| param_error(format!("no gait at {} = {start}: {e}", job.param)))?;
    follow_family(
        &family,
        (&gait.section, start),
        &walker.section_names(),
        job,
    )
}

/// An error of `continue --param`.
fn param_error(reason: String) -> AppError {
    AppError::InvalidOption {
        option: "param",
        reason,
    }
}

/// The family of `family` from its gait `(section, start)` (the parameter's value), followed as `job` asks;
/// its summary and the rows of `branch.csv`, the section by `names`.
fn follow_family<F>(
    family: &F,
    (section, start): (&DVector<f64>, f64),
    names: &[&str],
    job: &WalkerContinueJob,
) -> Result<(WalkerContinueSummary, Vec<Vec<String>>), AppError>
where
    F: FamilyMap,
    F::Info: PointRecord,
{
    let mut continuation = ContinuationOptions::for_range(job.range.0, job.range.1);
    continuation.max_points = job.max_points;
    continuation.max_step = job.max_step;
    continuation.initial_step = continuation.initial_step.min(job.max_step);
    super::check_phase_interrupted(
        None,
        "while searching the first gait",
        super::NOTHING_WRITTEN,
    )?;
    let followed = continue_family(family, section, start, &continuation)
        .map_err(|e| param_error(e.to_string()))?;
    super::check_phase_interrupted(None, "while following the family", super::NOTHING_WRITTEN)?;
    let summary = WalkerContinueSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        model: job.walker.name(),
        parameters: job.walker.clone(),
        param: job.param.clone(),
        start,
        points: followed.points.len(),
        ends: followed.ends.clone(),
        special_points: followed
            .special
            .iter()
            .map(|s| WalkerSpecialPoint {
                kind: s.kind,
                value: s.param,
                located: s.located,
                note: s.note.clone(),
                multipliers: s.multipliers.iter().map(|z| [z.re, z.im]).collect(),
                section: named(names, &s.x),
            })
            .collect(),
        derivative: F::Info::route(&followed.points),
    };
    let rows = branch_rows(&job.param, names, &followed.points);
    Ok((summary, rows))
}

/// What a walker's `branch.csv` and `special_points.json` say of a family's point beyond its parameter,
/// section and largest multiplier.
trait PointRecord: Sized {
    /// The columns' names.
    fn columns() -> Vec<&'static str>;
    /// The point's values, as the columns.
    fn values(&self) -> Vec<String>;
    /// How the family's `DP` and `dP/dp` were taken, in words.
    fn route(points: &[FamilyPoint<Self>]) -> String;
}

impl PointRecord for RigidInfo {
    /// The step's period and `lambda_I4`.
    fn columns() -> Vec<&'static str> {
        vec!["period", "lambda_I4"]
    }

    fn values(&self) -> Vec<String> {
        [self.period, self.lambda_i4]
            .map(|v| v.to_string())
            .to_vec()
    }

    fn route(points: &[FamilyPoint<Self>]) -> String {
        family_route(points)
    }
}

impl PointRecord for LeggedInfo {
    /// The step's period, the heel strike's DLS indicators and branch, the double support's duration and the
    /// error estimate of the point's derivatives.
    fn columns() -> Vec<&'static str> {
        vec![
            "period",
            "lambda_I4",
            "lambda_2+",
            "lambda_4+",
            "branch",
            "dls_duration",
            "derivative_error",
        ]
    }

    fn values(&self) -> Vec<String> {
        let a = &self.account;
        let text = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
        vec![
            self.period.to_string(),
            a.lambda_i4.to_string(),
            text(a.lambda_2_plus),
            text(a.lambda_4_plus),
            branch_text(a.branch),
            a.dls_duration.to_string(),
            text(Some(self.derivative_error).filter(|e| e.is_finite())),
        ]
    }

    /// Exact at every point, or Richardson-extrapolated central differences at the points where the step map has
    /// no derivative (counted, with their largest error estimate).
    fn route(points: &[FamilyPoint<Self>]) -> String {
        let by_differences: Vec<f64> = points
            .iter()
            .filter(|p| p.has_derivatives() && !p.exact)
            .map(|p| p.info.derivative_error)
            .collect();
        if by_differences.is_empty() {
            return EXACT_ROUTE.to_string();
        }
        let error = by_differences
            .iter()
            .copied()
            .filter(|e| e.is_finite())
            .fold(0.0, f64::max);
        format!(
            "{EXACT_ROUTE}; Richardson-extrapolated central differences at {} point(s) where the step map is not \
             differentiable (largest error estimate {error:.0e})",
            by_differences.len()
        )
    }
}

/// The rows of a walker's `branch.csv`, its header first: the parameter, the section's coordinates, the largest
/// multiplier, and the point's record ([`PointRecord`]).
fn branch_rows<I: PointRecord>(
    param: &str,
    names: &[&str],
    points: &[FamilyPoint<I>],
) -> Vec<Vec<String>> {
    let header = [param.to_string()]
        .into_iter()
        .chain(names.iter().map(|n| n.to_string()))
        .chain(["largest_multiplier".to_string()])
        .chain(I::columns().into_iter().map(String::from))
        .collect();
    let row = |p: &FamilyPoint<I>| {
        [p.param]
            .into_iter()
            .chain(p.x.iter().copied())
            .chain([p.max_multiplier()])
            .map(|v| v.to_string())
            .chain(p.info.values())
            .collect()
    };
    std::iter::once(header)
        .chain(points.iter().map(row))
        .collect()
}

/// The transient walk before a family's first gait is searched.
const TRANSIENT_STEPS: usize = 20;

/// The followed parameter's value in the job's walker.
fn current_value(job: &WalkerContinueJob) -> Result<f64, AppError> {
    let value = serde_json::to_value(&job.walker)
        .ok()
        .and_then(|v| v.get(&job.param).and_then(serde_json::Value::as_f64));
    value.ok_or_else(|| AppError::InvalidOption {
        option: "param",
        reason: format!(
            "the model `{}` has no parameter {:?}",
            job.walker.name(),
            crate::fmt::clip(&job.param)
        ),
    })
}

/// How a family's `DP` and `dP/dp` were taken: exactly, or by central differences at the points where the
/// step map has no derivative (counted).
fn family_route<I>(points: &[FamilyPoint<I>]) -> String {
    let by_differences = points
        .iter()
        .filter(|p| p.has_derivatives() && !p.exact)
        .count();
    if by_differences == 0 {
        EXACT_ROUTE.to_string()
    } else {
        format!(
            "{EXACT_ROUTE}; central differences, relative step {DIFFERENCE_STEP:e}, at {by_differences} \
             point(s) where the step map is not differentiable"
        )
    }
}
