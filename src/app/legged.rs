//! `vrw gait --model telescopic`: the gait of a walker with compliant legs ([`crate::mechanism::legged`],
//! docs/model.md section 13), its multipliers, the DLS indicators and branch of its heel strike, its double
//! support and the audits of its step, in `gait.json`.

use std::path::PathBuf;

use nalgebra::DVector;
use serde::Serialize;

use super::walkers::{as_map, named, TELESCOPIC};
use super::{in_run, AppError, SearchEnded};
use crate::mechanism::legged::gait::{legged_gait, legged_step_map, LeggedGait, LeggedGaitError};
use crate::mechanism::legged::walk::{LeggedOptions, StepAccount};
use crate::mechanism::legged::{Legged, LeggedError};
use crate::mechanism::telescopic::Telescopic;
use crate::output;

/// What `vrw gait --model telescopic` searches.
#[derive(Debug, Clone)]
pub struct LeggedGaitJob {
    /// The walker.
    pub walker: Telescopic,
    /// Where the search starts on the section; default the model's start.
    pub initial: Option<Vec<f64>>,
    /// Steps walked before Newton's method starts.
    pub transient_steps: usize,
    /// Output directory for `gait.json`.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir`.
    pub overwrite: bool,
}

/// A legged walker's gait, as `gait.json` holds it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LeggedGaitRecord {
    /// The fixed point, by the section's names (the heel strike before its impact).
    #[serde(serialize_with = "as_map")]
    pub section: Vec<(String, f64)>,
    /// `max |P(s) - s|` there.
    pub residual: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// The step's duration \[s\].
    pub period: f64,
    /// The Floquet multipliers `[re, im]`, largest modulus first.
    pub floquet_multipliers: Vec<[f64; 2]>,
    /// Their largest modulus.
    pub max_floquet: f64,
    /// How `DP` was taken.
    pub derivative: &'static str,
    /// Its error estimate (the multipliers' accuracy is about as good).
    pub jacobian_error: f64,
    /// The step's heel strike and audits.
    #[serde(flatten)]
    pub step: StepAccount,
}

/// `gait.json` of a legged walker: the gait, or why there is none.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LeggedGaitSummary {
    /// vrw's version.
    pub vrw_version: &'static str,
    /// The model's name.
    pub model: &'static str,
    /// Its parameters.
    pub parameters: Telescopic,
    /// The start, by the section's names.
    #[serde(serialize_with = "as_map")]
    pub initial: Vec<(String, f64)>,
    /// `found`, or the failure's kind.
    #[serde(serialize_with = "crate::fmt::as_text")]
    pub status: SearchEnded,
    /// Why not.
    pub message: Option<String>,
    /// The gait.
    pub gait: Option<LeggedGaitRecord>,
}

/// The walk's options with the library's interrupt flag (Ctrl-C) asked whether to stop.
fn interruptible() -> LeggedOptions {
    LeggedOptions {
        stop: Some(crate::walk::interrupted),
        ..LeggedOptions::default()
    }
}

/// The record of `gait`.
fn record<W: Legged<6>>(walker: &W, gait: &LeggedGait<6>) -> LeggedGaitRecord {
    let step = &gait.step;
    LeggedGaitRecord {
        section: named(&walker.section_names(), &gait.section),
        residual: gait.residual,
        iterations: gait.iterations,
        period: step.period,
        max_floquet: gait
            .multipliers
            .first()
            .map_or(f64::NAN, |[re, im]| re.hypot(*im)),
        floquet_multipliers: gait.multipliers.clone(),
        derivative: "richardson_differences",
        jacobian_error: gait.jacobian_error,
        step: step.account,
    }
}

/// The search from `start`: `transient` steps, then Newton's method.
fn search(
    walker: &Telescopic,
    start: &DVector<f64>,
    transient: usize,
) -> Result<LeggedGait<6>, LeggedGaitError> {
    let options = interruptible();
    let mut s = start.clone();
    for _ in 0..transient {
        s = legged_step_map::<_, 6, 13>(walker, &s, &options)
            .map_err(|source| LeggedGaitError::Step {
                iteration: 0,
                source,
            })?
            .0;
    }
    legged_gait::<_, 6, 13>(walker, &s, &options)
}

/// The failure's short name.
fn failure_kind(e: &LeggedGaitError) -> &'static str {
    match e {
        LeggedGaitError::Step { source, .. } => source.kind(),
        LeggedGaitError::Singular { .. } => "singular",
        LeggedGaitError::NoConvergence { .. } => "no_convergence",
    }
}

/// `vrw gait --model telescopic`: the search, then `gait.json`.
pub fn run_legged_gait(job: &LeggedGaitJob) -> Result<LeggedGaitSummary, AppError> {
    crate::output::manifest::check_out_dir(&job.out_dir, "gait", job.overwrite)?;
    let summary = compute_legged_gait(job)?;
    in_run(&job.out_dir, job.overwrite, "gait", |run| {
        output::write_json(&run.path("gait.json"), &summary)?;
        run.add("gait.json");
        Ok((summary, None))
    })
}

/// The search of [`run_legged_gait`] without its file (the Python binding): `gait.json`'s fields (`job.out_dir`
/// and `job.overwrite` are not read).
pub fn compute_legged_gait(job: &LeggedGaitJob) -> Result<LeggedGaitSummary, AppError> {
    let walker = &job.walker;
    let names = walker.section_names();
    let start = match &job.initial {
        Some(values) if values.len() != names.len() => {
            return Err(AppError::InvalidOption {
                option: "initial",
                reason: format!(
                    "{} values given; the section of `{TELESCOPIC}` has {}: {}",
                    values.len(),
                    names.len(),
                    names.join(", ")
                ),
            })
        }
        Some(values) => DVector::from_column_slice(values),
        None => walker.default_start(),
    };
    if walker.state_at_section(&start).is_none() {
        return Err(AppError::InvalidOption {
            option: "initial",
            reason: format!("{}", LeggedError::OffSection),
        });
    }
    let result = search(walker, &start, job.transient_steps);
    super::check_phase_interrupted(None, "while searching the gait", super::NOTHING_WRITTEN)?;
    Ok(LeggedGaitSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        model: TELESCOPIC,
        parameters: *walker,
        initial: named(&names, &start),
        status: match &result {
            Ok(_) => SearchEnded::Found,
            Err(e) => SearchEnded::Failed(failure_kind(e)),
        },
        message: result.as_ref().err().map(ToString::to_string),
        gait: result.ok().map(|g| record(walker, &g)),
    })
}
