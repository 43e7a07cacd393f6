//! `vrw gait --model NAME` for the walkers behind the mechanism interface other than the wheel (docs/model.md
//! section 13): the simplest walking model, the compass gait, and the bipeds described in a TOML file
//! (`--model path/to/walker.toml`, [`crate::mechanism::described`]). Their parameters are read as a
//! configuration is (a flat TOML file, `--set key=value`), the gait is searched from the model's start after a
//! transient walk, and `gait.json` holds it with its section named by the model's coordinates.

use std::path::{Path, PathBuf};

use nalgebra::DVector;
use serde::Serialize;

use super::walker_model::{interruptible, search_gait, RigidModel, WalkerModel};
use super::walker_output::{write_rows, WalkerOutput};
use super::{in_run, AppError, SearchEnded};
use crate::continuation::{
    continue_family, ContinuationOptions, FamilyEnd, FamilyPoint, SpecialKind,
};
use crate::mechanism::compass::Compass;
use crate::mechanism::described::{self, AnyDescribed};
use crate::mechanism::rigid::RigidWalker;
use crate::mechanism::rigid_check::{check_rigid_derivatives, RigidDerivativeCheck};
use crate::mechanism::rigid_derivative::{parameter_value, DerivativeError};
use crate::mechanism::rigid_family::{Parametrized, RigidFamily, RigidInfo};
use crate::mechanism::rigid_gait::{rigid_step_map, RigidGait, DIFFERENCE_STEP, EXACT_ROUTE};
use crate::mechanism::simplest::Simplest;
use crate::output;
use crate::params::read_walker_parameters;
use crate::params::ConfigError;

/// The models `--model` takes by name: the wheel (`vrw`, the default) and the walkers of this file; any other
/// name that ends in `.toml` or names a file is a description ([`crate::mechanism::described`]).
pub const MODELS: [&str; 4] = ["vrw", "simplest", "compass", TELESCOPIC];

/// The model name of the compass gait with telescopic legs ([`crate::mechanism::telescopic`]), which walks by
/// the legged walk (`super::legged`).
pub const TELESCOPIC: &str = "telescopic";

/// A walker other than the wheel, with its parameters.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Walker {
    /// The simplest walking model.
    Simplest(Simplest),
    /// The compass gait.
    Compass(Compass),
    /// A walker described in a file.
    Described(AnyDescribed),
}

impl Walker {
    /// The walker `name` with its parameters from `file` and `overrides` (see
    /// [`read_walker_parameters`]), validated; `None` for the wheel (`vrw`).
    pub fn load<S: AsRef<str>>(
        name: &str,
        file: Option<&Path>,
        overrides: &[S],
    ) -> Result<Option<Walker>, AppError> {
        let walker = match name {
            "vrw" => return Ok(None),
            "simplest" => {
                let w: Simplest = read_walker_parameters(file, overrides)?;
                w.validate()?;
                Walker::Simplest(w)
            }
            "compass" => {
                let w: Compass = read_walker_parameters(file, overrides)?;
                w.validate()?;
                Walker::Compass(w)
            }
            TELESCOPIC => {
                return Err(AppError::InvalidOption {
                    option: "model",
                    reason: "the compass gait with telescopic legs (`telescopic`) walks in `vrw gait` only so \
                             far (docs/model.md section 13)"
                        .to_string(),
                })
            }
            other if other.ends_with(".toml") || Path::new(other).is_file() => {
                let model = |reason: String| AppError::InvalidOption {
                    option: "model",
                    reason,
                };
                let w = described::load(Path::new(other)).map_err(|e| model(e.to_string()))?;
                Walker::Described(w.with_parameters(file, overrides)?)
            }
            other => {
                return Err(AppError::InvalidOption {
                    option: "model",
                    reason: format!(
                        "unknown model {:?}: one of {}, or a description file (`.toml`)",
                        crate::fmt::clip(other),
                        MODELS.join(", ")
                    ),
                })
            }
        };
        Ok(Some(walker))
    }

    /// The model's name.
    pub fn name(&self) -> &'static str {
        match self {
            Walker::Simplest(w) => RigidWalker::name(w),
            Walker::Compass(w) => RigidWalker::name(w),
            Walker::Described(w) => w.description().name,
        }
    }

    /// What the walker offers the jobs ([`WalkerModel`]): the one place a job meets the kind of walker.
    ///
    /// A described walker walks in `vrw gait` and `vrw continue` only so far: the other jobs refuse it.
    pub fn model(&self) -> Result<Box<dyn WalkerModel + '_>, AppError> {
        Ok(match self {
            Walker::Simplest(w) => Box::new(RigidModel::<_, 2, 4>::new(w, Simplest::default_start)),
            Walker::Compass(w) => Box::new(RigidModel::<_, 4, 8>::new(w, Compass::default_start)),
            Walker::Described(w) => {
                return Err(AppError::InvalidOption {
                    option: "model",
                    reason: format!(
                        "the described walker `{}` walks in `vrw gait` and `vrw continue` so far (docs/model.md \
                         section 13)",
                        w.description().name
                    ),
                })
            }
        })
    }

    /// The keys of its parameters (those `continue --param` follows and `gait --parameter` differentiates in).
    pub fn parameter_keys(&self) -> Vec<&'static str> {
        match self {
            Walker::Simplest(w) => w.parameter_keys(),
            Walker::Compass(w) => w.parameter_keys(),
            Walker::Described(w) => w.parameters().into_iter().map(|(k, _)| k).collect(),
        }
    }

    /// The same walker with the parameter `key` at `value`, validated.
    pub fn with_parameter(&self, key: &str, value: f64) -> Result<Walker, ConfigError> {
        Ok(match self {
            Walker::Simplest(w) => Walker::Simplest(w.with_parameter(key, value)?),
            Walker::Compass(w) => Walker::Compass(w.with_parameter(key, value)?),
            Walker::Described(w) => Walker::Described(w.with_value(key, value)?),
        })
    }

    /// The value of the parameter `key`, if the walker has it.
    pub fn parameter(&self, key: &str) -> Option<f64> {
        if let Walker::Described(w) = self {
            return w
                .parameters()
                .into_iter()
                .find(|(k, _)| *k == key)
                .map(|(_, v)| v);
        }
        serde_json::to_value(self)
            .ok()?
            .get(key)
            .and_then(serde_json::Value::as_f64)
    }

    /// The parameter `key`, checked to be one of the walker's (the error names the job's option `option`).
    pub fn checked_parameter(&self, option: &'static str, key: &str) -> Result<f64, AppError> {
        let known = self.parameter_keys();
        match self.parameter(key).filter(|_| known.contains(&key)) {
            Some(value) => Ok(value),
            None => Err(AppError::InvalidOption {
                option,
                reason: format!(
                    "the model `{}` has no parameter {:?}: one of {}",
                    self.name(),
                    crate::fmt::clip(key),
                    known.join(", ")
                ),
            }),
        }
    }

    /// `key` is one of its parameters, or an error for `option` naming them.
    fn check_parameter(&self, key: &str, option: &'static str) -> Result<(), AppError> {
        let keys = self.parameter_keys();
        if keys.contains(&key) {
            return Ok(());
        }
        Err(AppError::InvalidOption {
            option,
            reason: format!(
                "`{}` is not a parameter of the model `{}`: one of {}",
                crate::fmt::clip(key),
                self.name(),
                keys.join(", ")
            ),
        })
    }
}

/// The section state a job starts from: `initial` (checked against the model's section), or the model's
/// default start.
pub(super) fn start_of(
    model: &dyn WalkerModel,
    initial: Option<&[f64]>,
) -> Result<DVector<f64>, AppError> {
    let names = model.section_names();
    match initial {
        Some(values) if values.len() != names.len() => Err(AppError::InvalidOption {
            option: "initial",
            reason: format!(
                "{} values given; the section of `{}` has {}: {}",
                values.len(),
                model.name(),
                names.len(),
                names.join(", ")
            ),
        }),
        Some(values) if values.iter().any(|v| !v.is_finite()) => Err(AppError::InvalidOption {
            option: "initial",
            reason: format!("{values:?} holds a value that is not a finite number"),
        }),
        Some(values) => Ok(DVector::from_column_slice(values)),
        None => Ok(model.default_start()),
    }
}

/// `vrw JOB --model NAME` for a job that takes only the wheel so far: `Ok` for the wheel (`vrw`), else an error
/// naming the model and the job (never the wheel's job run in its place).
pub fn wheel_only(model: &str, job: &str) -> Result<(), AppError> {
    if model == "vrw" {
        return Ok(());
    }
    let walker = Walker::load(model, None, &[] as &[&str])?;
    let name = walker
        .as_ref()
        .map_or(model.to_string(), |w| w.name().to_string());
    Err(AppError::InvalidOption {
        option: "model",
        reason: format!(
            "`vrw {job}` takes only the wheel (`vrw`) so far; the model `{name}` walks in `vrw simulate`, \
             `vrw gait`, `vrw sweep`, `vrw orbit` and `vrw continue` (and `vrw plot` and `vrw animate` of \
             its simulate run); docs/model.md section 13"
        ),
    })
}

/// What `vrw gait --model NAME` searches.
#[derive(Debug, Clone)]
pub struct WalkerGaitJob {
    /// The walker.
    pub walker: Walker,
    /// Where the search starts on the section (the model's coordinates); default the model's start.
    pub initial: Option<Vec<f64>>,
    /// Steps walked before Newton's method starts.
    pub transient_steps: usize,
    /// Also `dP/dp` at the gait for this parameter (one of the walker's keys).
    pub parameter: Option<String>,
    /// Check the exact `DP` (and `dP/dp`) at the gait against Richardson-extrapolated central differences.
    pub check_jacobian: bool,
    /// Output directory for `gait.json`.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir`.
    pub overwrite: bool,
}

/// `gait.json` of a walker: the gait, or why there is none.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerGaitSummary {
    /// vrw's version.
    pub vrw_version: &'static str,
    /// The model's name.
    pub model: &'static str,
    /// Its parameters.
    pub parameters: Walker,
    /// Where the search started (the transient walk from it), by the section's coordinates.
    #[serde(serialize_with = "as_map")]
    pub initial: Vec<(String, f64)>,
    /// `found`, or the failure's kind.
    #[serde(serialize_with = "crate::fmt::as_text")]
    pub status: SearchEnded,
    /// The failure, in words.
    pub message: Option<String>,
    /// The gait.
    pub gait: Option<WalkerGait>,
    /// The exact derivatives against central differences, if asked for ([`WalkerGaitJob::check_jacobian`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jacobian_check: Option<RigidDerivativeCheck>,
}

/// A walker's gait as `gait.json` holds it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerGait {
    /// The fixed point on the section just after a heel strike, by the model's coordinates.
    #[serde(serialize_with = "as_map")]
    pub section: Vec<(String, f64)>,
    /// `max |P(s) - s|` at it.
    pub residual: f64,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// The step's duration (in the model's time unit: seconds for the compass gait, `sqrt(l/g)` for the
    /// simplest walker).
    pub period: f64,
    /// The Floquet multipliers `[re, im]`, largest modulus first.
    pub floquet_multipliers: Vec<[f64; 2]>,
    /// The largest modulus.
    pub largest_multiplier: f64,
    /// `stable` below 1, else `unstable`.
    pub stability: &'static str,
    /// How `DP` was taken.
    pub derivative: String,
    /// The heel strike's DLS indicator: the rear foot's normal impulse with both feet held (negative: the rear
    /// foot leaves, the traditional impact).
    #[serde(rename = "lambda_I4")]
    pub lambda_i4: f64,
    /// The energy the heel strike takes.
    pub impact_loss: f64,
    /// The largest change of `T + V` over the step's integration (conserved in single support): its energy
    /// audit.
    pub energy_drift: f64,
    /// Crossings of the ground by the swing foot ignored as scuffing.
    pub scuffs: usize,
    /// `dP/dp` at the gait for the parameter asked for ([`WalkerGaitJob::parameter`]).
    #[serde(rename = "dP_dparam", skip_serializing_if = "Option::is_none")]
    pub dp_dparam: Option<WalkerParamDerivative>,
}

/// `dP/dp` of a walker's step map at its gait, by the section's coordinates.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerParamDerivative {
    /// The parameter.
    pub parameter: String,
    /// `dP/dp`, one value per section coordinate.
    #[serde(serialize_with = "as_map")]
    pub values: Vec<(String, f64)>,
    /// How it was taken.
    pub derivative: String,
}

/// Search the gait of `job.walker` and write `gait.json` (also without a gait, with the reason), after the
/// output directory is checked.
pub fn run_walker_gait(job: &WalkerGaitJob) -> Result<WalkerGaitSummary, AppError> {
    crate::output::manifest::check_out_dir(&job.out_dir, "gait", job.overwrite)?;
    let summary = compute_walker_gait(job)?;
    in_run(&job.out_dir, job.overwrite, "gait", |run| {
        output::write_json(&run.path("gait.json"), &summary)?;
        run.add("gait.json");
        Ok((summary, None))
    })
}

/// The search of [`run_walker_gait`] without its file (the Python binding): `gait.json`'s fields (`job.out_dir`
/// and `job.overwrite` are not read).
pub fn compute_walker_gait(job: &WalkerGaitJob) -> Result<WalkerGaitSummary, AppError> {
    if let Some(key) = &job.parameter {
        job.walker.check_parameter(key, "parameter")?;
    }
    Ok(match &job.walker {
        Walker::Simplest(w) => compute(w, w.default_start(), job)?,
        Walker::Compass(w) => compute(w, w.default_start(), job)?,
        Walker::Described(w) => {
            let start = rigid_start(w, job.initial.as_deref())?;
            crate::with_rigid_described!(w, w => compute(w, start, job)?, _ => unreachable_walk(w)?)
        }
    })
}

/// The search of [`run_walker_gait`] for `walker`, from `job.initial` or `start`.
fn compute<W: RigidWalker<N, Y> + Parametrized, const N: usize, const Y: usize>(
    walker: &W,
    start: DVector<f64>,
    job: &WalkerGaitJob,
) -> Result<WalkerGaitSummary, AppError> {
    let names = walker.section_names();
    let start = match &job.initial {
        Some(values) if values.len() != names.len() => {
            return Err(AppError::InvalidOption {
                option: "initial",
                reason: format!(
                    "{} values given; the section of `{}` has {}: {}",
                    values.len(),
                    walker.name(),
                    names.len(),
                    names.join(", ")
                ),
            })
        }
        Some(values) => DVector::from_column_slice(values),
        None => start,
    };
    let result = search_gait(walker, &start, job.transient_steps);
    super::check_phase_interrupted(None, "while searching the gait", super::NOTHING_WRITTEN)?;
    let jacobian_check = match (&result, job.check_jacobian) {
        (Ok(g), true) => Some(
            check_rigid_derivatives(
                walker,
                &g.section,
                job.parameter.as_deref(),
                &interruptible(),
            )
            .unwrap_or_else(|e| RigidDerivativeCheck::failed(e.to_string())),
        ),
        _ => None,
    };
    let dp_dparam = match (&result, &job.parameter) {
        (Ok(g), Some(key)) => Some(param_derivative(walker, g, key)?),
        _ => None,
    };
    Ok(WalkerGaitSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        model: walker.name(),
        parameters: job.walker.clone(),
        initial: named(&names, &start),
        status: match &result {
            Ok(_) => SearchEnded::Found,
            Err(e) => SearchEnded::Failed(super::walker_model::search_kind(e)),
        },
        message: result.as_ref().err().map(ToString::to_string),
        gait: result.ok().map(|g| WalkerGait {
            dp_dparam,
            ..gait_record(&g, named(&names, &g.section))
        }),
        jacobian_check,
    })
}

/// `dP/dp` of `walker`'s step map at its gait `g` in the parameter `key`: exact, or central differences where
/// the map is not differentiable there (said in `derivative`).
fn param_derivative<W: RigidWalker<N, Y> + Parametrized, const N: usize, const Y: usize>(
    walker: &W,
    g: &RigidGait<N>,
    key: &str,
) -> Result<WalkerParamDerivative, AppError> {
    let options = interruptible();
    let names = walker.section_names();
    let failed = |reason: String| AppError::InvalidOption {
        option: "parameter",
        reason,
    };
    let (values, derivative) = match walker.step_map_derivative(&g.section, Some(key), 1, &options)
    {
        Ok(d) => (d.dparam.unwrap_or_default(), EXACT_ROUTE.to_string()),
        Err(DerivativeError::NotDifferentiable(reason)) => {
            let value = parameter_value(walker, key).unwrap_or(f64::NAN);
            let h = DIFFERENCE_STEP * value.abs().max(1.0);
            let at = |p: f64| -> Result<DVector<f64>, AppError> {
                let moved = walker.with_parameter(key, p)?;
                Ok(rigid_step_map(&moved, &g.section, &options)
                    .map_err(|e| failed(e.to_string()))?
                    .0)
            };
            let values = (at(value + h)? - at(value - h)?) / (2.0 * h);
            let route = format!(
                "central differences, relative step {DIFFERENCE_STEP:e} (no exact derivative: {reason})"
            );
            (values, route)
        }
        Err(e) => return Err(failed(e.to_string())),
    };
    Ok(WalkerParamDerivative {
        parameter: key.to_string(),
        values: named(&names, &values),
        derivative,
    })
}

/// Values by the section's coordinate names.
pub(super) fn named<S: AsRef<str>>(names: &[S], x: &DVector<f64>) -> Vec<(String, f64)> {
    names
        .iter()
        .map(|n| n.as_ref().to_string())
        .zip(x.iter().copied())
        .collect()
}

/// `gait.json`'s record of `g`.
fn gait_record<const N: usize>(g: &RigidGait<N>, section: Vec<(String, f64)>) -> WalkerGait {
    let largest = g.largest_multiplier();
    WalkerGait {
        section,
        residual: g.residual,
        newton_iterations: g.iterations,
        period: g.step.period,
        floquet_multipliers: g.multipliers.clone(),
        largest_multiplier: largest,
        stability: if largest < 1.0 { "stable" } else { "unstable" },
        derivative: g.derivative.to_string(),
        lambda_i4: g.step.lambda_i4,
        impact_loss: g.step.impact_loss,
        energy_drift: g.step.energy_drift,
        scuffs: g.step.scuffs,
        dp_dparam: None,
    }
}

/// Named values as a JSON object, in their order.
pub(super) fn as_map<S: serde::Serializer>(
    pairs: &[(String, f64)],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut map = serializer.serialize_map(Some(pairs.len()))?;
    for (name, value) in pairs {
        map.serialize_entry(name, value)?;
    }
    map.end()
}

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
    in_run(&job.out_dir, job.overwrite, "continue", |run| {
        for (name, rows) in &tables {
            write_rows(&run.path(name), rows)?;
            run.add(name);
        }
        output::write_json(&run.path("special_points.json"), &summary)?;
        run.add("special_points.json");
        Ok((summary, None))
    })
}

/// The family of [`run_walker_continuation`] without its files (the Python binding): `special_points.json`'s
/// fields and the rows of `branch.csv` (`job.out_dir` and `job.overwrite` are not read).
pub fn compute_walker_continuation(
    job: &WalkerContinueJob,
) -> Result<WalkerOutput<WalkerContinueSummary>, AppError> {
    let (summary, rows) = match &job.walker {
        Walker::Simplest(w) => follow(w, w.default_start(), job)?,
        Walker::Compass(w) => follow(w, w.default_start(), job)?,
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

/// The family of [`run_walker_continuation`] for `walker`, and the rows of `branch.csv` (its header first).
fn follow<W, const N: usize, const Y: usize>(
    walker: &W,
    section: DVector<f64>,
    job: &WalkerContinueJob,
) -> Result<(WalkerContinueSummary, Vec<Vec<String>>), AppError>
where
    W: RigidWalker<N, Y> + Parametrized + Sync,
{
    let invalid = |reason: String| AppError::InvalidOption {
        option: "param",
        reason,
    };
    let family: RigidFamily<W, N, Y> = RigidFamily::new(walker, &job.param)
        .map_err(|e| invalid(e.to_string()))?
        .with_options(interruptible());
    let start = job.start.unwrap_or(current_value(job)?);
    let at_start = walker.with_parameter(&job.param, start)?;
    let gait = search_gait(&at_start, &section, TRANSIENT_STEPS)
        .map_err(|e| invalid(format!("no gait at {} = {start}: {e}", job.param)))?;
    let mut continuation = ContinuationOptions::for_range(job.range.0, job.range.1);
    continuation.max_points = job.max_points;
    continuation.max_step = job.max_step;
    continuation.initial_step = continuation.initial_step.min(job.max_step);
    super::check_phase_interrupted(
        None,
        "while searching the first gait",
        super::NOTHING_WRITTEN,
    )?;
    let followed = continue_family(&family, &gait.section, start, &continuation)
        .map_err(|e| invalid(e.to_string()))?;
    super::check_phase_interrupted(None, "while following the family", super::NOTHING_WRITTEN)?;
    let names = walker.section_names();
    let summary = WalkerContinueSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        model: walker.name(),
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
                section: named(&names, &s.x),
            })
            .collect(),
        derivative: family_route(&followed.points),
    };
    let rows = branch_rows(&job.param, &names, &followed.points);
    Ok((summary, rows))
}

/// The rows of a walker's `branch.csv`, its header first: the parameter, the section's coordinates, the largest
/// multiplier, the step's period and `lambda_I4`.
fn branch_rows(param: &str, names: &[&str], points: &[FamilyPoint<RigidInfo>]) -> Vec<Vec<String>> {
    let header = [param.to_string()]
        .into_iter()
        .chain(names.iter().map(|n| n.to_string()))
        .chain(["largest_multiplier", "period", "lambda_I4"].map(String::from))
        .collect();
    let row = |p: &FamilyPoint<RigidInfo>| {
        [p.param]
            .into_iter()
            .chain(p.x.iter().copied())
            .chain([p.max_multiplier(), p.info.period, p.info.lambda_i4])
            .map(|v| v.to_string())
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

/// Where a described walker's gait search starts (its `[gait]` table's `start`), or why it cannot walk: no
/// `[gait]` table, or joints that need the compliant walk ([`described::NotWalkable`]); and whether that start
/// (or `initial`, where given with the section's length) completes to a state after a heel strike.
fn rigid_start(w: &AnyDescribed, initial: Option<&[f64]>) -> Result<DVector<f64>, AppError> {
    let invalid = |option: &'static str, reason: String| AppError::InvalidOption { option, reason };
    let gait = described::walkable(w.description()).map_err(|e| invalid("model", e.to_string()))?;
    let start = DVector::from_column_slice(&gait.start);
    let (option, checked) = match initial {
        Some(values) if values.len() == gait.start.len() => {
            ("initial", DVector::from_column_slice(values))
        }
        _ => ("model", start.clone()),
    };
    w.check_section(&checked).map_err(|e| {
        let named: Vec<String> = named(&gait.section_names, &checked)
            .iter()
            .map(|(n, v)| format!("{n} = {v}"))
            .collect();
        invalid(
            option,
            format!("at the section's {}: {e}", named.join(", ")),
        )
    })?;
    Ok(start)
}

/// The error for a described walker with fewer than 3 coordinates, which its `[gait]` check already refuses
/// (the contact conditions fix three positions on the section).
fn unreachable_walk<T>(w: &AnyDescribed) -> Result<T, AppError> {
    Err(AppError::InvalidOption {
        option: "model",
        reason: format!(
            "`{}` has {} coordinates: a biped with rigid legs needs at least 3",
            w.description().name,
            w.description().coordinates.len()
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
