//! `vrw gait --model telescopic` (and `--model walker.toml` for a described walker with telescopic legs): the
//! gait of a walker with compliant legs ([`crate::mechanism::legged`], docs/model.md section 13), its
//! multipliers, the DLS indicators and branch of its heel strike, its double support and the audits of its
//! step, in `gait.json`.

use std::path::PathBuf;

use nalgebra::DVector;
use serde::Serialize;

use super::walkers::{as_map, named, TELESCOPIC};
use super::{in_run, AppError, SearchEnded};
use crate::mechanism::described::{walk, AnyDescribed, Walk};
use crate::mechanism::legged::derivative::LeggedDerivatives;
use crate::mechanism::legged::gait::{
    legged_gait_exact, legged_step_map, LeggedGait, LeggedGaitError,
};
use crate::mechanism::legged::walk::{LeggedOptions, StepAccount};
use crate::mechanism::legged::{Legged, LeggedError};
use crate::mechanism::telescopic::Telescopic;
use crate::output;

/// A walker with compliant legs, with its parameters (`gait.json` writes them by key).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum LeggedWalker {
    /// The compass gait with telescopic legs.
    Telescopic(Telescopic),
    /// A walker described in a file whose `[gait]` table names its legs' strokes
    /// ([`AnyDescribed::walks_compliant`]).
    Described(AnyDescribed),
}

impl LeggedWalker {
    /// The model's name.
    pub fn name(&self) -> &'static str {
        match self {
            LeggedWalker::Telescopic(_) => TELESCOPIC,
            LeggedWalker::Described(w) => w.description().name,
        }
    }
}

/// What `vrw gait --model telescopic` searches.
#[derive(Debug, Clone)]
pub struct LeggedGaitJob {
    /// The walker.
    pub walker: LeggedWalker,
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
    /// Its error estimate (the multipliers' accuracy is about as good): for exact derivatives, their largest
    /// difference from Richardson-extrapolated differences.
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
    pub parameters: LeggedWalker,
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
fn record<W: Legged<N>, const N: usize>(walker: &W, gait: &LeggedGait<N>) -> LeggedGaitRecord {
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
        derivative: gait.derivative,
        jacobian_error: gait.jacobian_error,
        step: step.account,
    }
}

/// The search from `start`: `transient` steps, then Newton's method with the exact derivatives
/// ([`legged_gait_exact`]).
fn search<W: LeggedDerivatives<N>, const N: usize, const Y: usize>(
    walker: &W,
    (start, transient): (&DVector<f64>, usize),
) -> Result<LeggedGait<N>, LeggedGaitError> {
    let options = interruptible();
    let mut s = start.clone();
    for _ in 0..transient {
        s = legged_step_map::<_, N, Y>(walker, &s, &options)
            .map_err(|source| LeggedGaitError::Step {
                iteration: 0,
                source,
            })?
            .0;
    }
    legged_gait_exact::<_, N, Y>(walker, &s, &options)
}

/// The failure's short name.
fn failure_kind(e: &LeggedGaitError) -> &'static str {
    match e {
        LeggedGaitError::Step { source, .. } => source.kind(),
        LeggedGaitError::Singular { .. } => "singular",
        LeggedGaitError::NoConvergence { .. } => "no_convergence",
    }
}

/// The start (`initial`, or the model's), by the section's names, and the search from it: the gait's record, or
/// why there is none.
type Searched = (
    Vec<(String, f64)>,
    Result<LeggedGaitRecord, LeggedGaitError>,
);

/// The search of [`run_legged_gait`] for `walker`, from `job.initial` or `default_start`.
fn compute<W: LeggedDerivatives<N>, const N: usize, const Y: usize>(
    walker: &W,
    default_start: DVector<f64>,
    job: &LeggedGaitJob,
) -> Result<Searched, AppError> {
    let names = walker.section_names();
    let start = match &job.initial {
        Some(values) if values.len() != names.len() => {
            return Err(AppError::InvalidOption {
                option: "initial",
                reason: format!(
                    "{} values given; the section of `{}` has {}: {}",
                    values.len(),
                    job.walker.name(),
                    names.len(),
                    names.join(", ")
                ),
            })
        }
        Some(values) => DVector::from_column_slice(values),
        None => default_start,
    };
    if walker.state_at_section(&start).is_none() {
        return Err(AppError::InvalidOption {
            option: "initial",
            reason: format!("{}", LeggedError::OffSection),
        });
    }
    let result = search::<W, N, Y>(walker, (&start, job.transient_steps));
    super::check_phase_interrupted(None, "while searching the gait", super::NOTHING_WRITTEN)?;
    Ok((named(&names, &start), result.map(|g| record(walker, &g))))
}

/// Where a described walker's search starts (its `[gait]` table's `start`), checked on its section with the
/// contact conditions' reason where it is not (as `initial` where that is given with the section's length);
/// a walker that does not walk by the compliant walk is refused, saying why.
fn described_start(w: &AnyDescribed, initial: Option<&[f64]>) -> Result<DVector<f64>, AppError> {
    let model = |reason: String| AppError::InvalidOption {
        option: "model",
        reason,
    };
    match walk(w.description()) {
        Ok(Walk::Compliant) => {}
        Ok(Walk::Rigid) => {
            return Err(model(format!(
                "`{}` has rigid legs (its [gait] table names no strokes): it walks as a rigid biped, not by the \
                 compliant walk",
                w.description().name
            )))
        }
        Err(e) => return Err(model(e.to_string())),
    }
    let (names, start) = match w.description().gait.as_ref() {
        Some(g) => (g.section_names.clone(), g.start.clone()),
        None => (Vec::new(), Vec::new()),
    };
    let start = DVector::from_vec(start);
    let (option, checked) = match initial {
        Some(values) if values.len() == start.len() => {
            ("initial", DVector::from_column_slice(values))
        }
        _ => ("model", start.clone()),
    };
    w.check_section(&checked).map_err(|e| {
        let at: Vec<String> = named(&names, &checked)
            .iter()
            .map(|(n, v)| format!("{n} = {v}"))
            .collect();
        AppError::InvalidOption {
            option,
            reason: format!("at the section's {}: {e}", at.join(", ")),
        }
    })?;
    Ok(start)
}

/// `vrw gait --model telescopic` (or a described walker with telescopic legs): the search, then `gait.json`.
pub fn run_legged_gait(job: &LeggedGaitJob) -> Result<LeggedGaitSummary, AppError> {
    crate::output::manifest::check_out_dir(&job.out_dir, "gait", job.overwrite)?;
    let (initial, result) = match &job.walker {
        LeggedWalker::Telescopic(w) => compute::<_, 6, 13>(w, w.default_start(), job)?,
        LeggedWalker::Described(any) => {
            let start = described_start(any, job.initial.as_deref())?;
            crate::with_legged_described!(
                any, w, N, Y => compute::<_, N, Y>(w, start, job)?,
                _ => return Err(AppError::InvalidOption {
                    option: "model",
                    reason: format!(
                        "`{}` has {} coordinates: a walker with telescopic legs needs at least 4",
                        any.description().name,
                        any.description().coordinates.len()
                    ),
                })
            )
        }
    };
    let summary = LeggedGaitSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        model: job.walker.name(),
        parameters: job.walker.clone(),
        initial,
        status: match &result {
            Ok(_) => SearchEnded::Found,
            Err(e) => SearchEnded::Failed(failure_kind(e)),
        },
        message: result.as_ref().err().map(ToString::to_string),
        gait: result.ok(),
    };
    in_run(&job.out_dir, job.overwrite, "gait", |run| {
        output::write_json(&run.path("gait.json"), &summary)?;
        run.add("gait.json");
        Ok((summary, None))
    })
}
