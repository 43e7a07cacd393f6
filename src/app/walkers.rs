//! `vrw gait --model NAME` for the walkers behind the mechanism interface other than the wheel (docs/model.md
//! section 13): the simplest walking model, the compass gait, and the bipeds described in a TOML file
//! (`--model path/to/walker.toml`, [`crate::mechanism::described`]). Their parameters are read as a
//! configuration is (a flat TOML file, `--set key=value`), the gait is searched from the model's start after a
//! transient walk, and `gait.json` holds it with its section named by the model's coordinates.

use std::path::{Path, PathBuf};

use nalgebra::DVector;
use serde::Serialize;

use super::legged::LeggedModel;
use super::walker_derivatives::{
    legged_gait_derivatives, rigid_gait_derivatives, Asked, GaitDerivatives,
};
use super::walker_model::{
    found_rigid, search_gait, FoundGait, RigidModel, WalkerGaitError, WalkerModel,
};
use super::{in_run_on, AppError, SearchEnded};
use crate::mechanism::compass::Compass;
use crate::mechanism::derivative_check::{DerivativeCheck, ParameterDerivative};
use crate::mechanism::described::{self, AnyDescribed, Walk};
use crate::mechanism::legged::walk::StepAccount;
use crate::mechanism::rigid::RigidWalker;
use crate::mechanism::rigid_family::Parametrized;
use crate::mechanism::simplest::Simplest;
use crate::mechanism::telescopic::Telescopic;
use crate::mechanism::Mechanism;
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
    /// The compass gait with telescopic legs, walking by the legged walk.
    Telescopic(Telescopic),
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
                let w: Telescopic = read_walker_parameters(file, overrides)?;
                w.validate()?;
                Walker::Telescopic(w)
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
            Walker::Telescopic(w) => Mechanism::name(w),
            Walker::Described(w) => w.description().name,
        }
    }

    /// What the walker offers the jobs ([`WalkerModel`]): the one place a job meets the kind of walker.
    ///
    pub fn model(&self) -> Result<Box<dyn WalkerModel + '_>, AppError> {
        Ok(match self {
            Walker::Simplest(w) => Box::new(RigidModel::<_, 2, 4>::new(w, Simplest::default_start)),
            Walker::Compass(w) => Box::new(RigidModel::<_, 4, 8>::new(w, Compass::default_start)),
            Walker::Telescopic(w) => {
                Box::new(LeggedModel::<_, 6, 13>::new(w, Telescopic::default_start))
            }
            Walker::Described(w) => {
                let walk =
                    described::walk(w.description()).map_err(|e| AppError::InvalidOption {
                        option: "model",
                        reason: e.to_string(),
                    })?;
                use super::walker_described::described_start as start;
                match walk {
                    Walk::Rigid => crate::with_rigid_described!(
                        w,
                        w => Box::new(RigidModel::new(w, start)),
                        _ => unreachable_walk(w)?
                    ),
                    Walk::Compliant => crate::with_legged_described!(
                        w, w, N, Y => Box::new(LeggedModel::<_, N, Y>::new(w, start)),
                        _ => unreachable_walk(w)?
                    ),
                }
            }
        })
    }

    /// The keys of its parameters (those `continue --param` follows and `gait --parameter` differentiates in).
    pub fn parameter_keys(&self) -> Vec<&'static str> {
        match self {
            Walker::Simplest(w) => w.parameter_keys(),
            Walker::Compass(w) => w.parameter_keys(),
            Walker::Telescopic(w) => w.parameter_keys(),
            Walker::Described(w) => w.parameters().into_iter().map(|(k, _)| k).collect(),
        }
    }

    /// The same walker with the parameter `key` at `value`, validated.
    pub fn with_parameter(&self, key: &str, value: f64) -> Result<Walker, ConfigError> {
        Ok(match self {
            Walker::Simplest(w) => Walker::Simplest(w.with_parameter(key, value)?),
            Walker::Compass(w) => Walker::Compass(w.with_parameter(key, value)?),
            Walker::Telescopic(w) => Walker::Telescopic(w.with_parameter(key, value)?),
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
    pub jacobian_check: Option<DerivativeCheck>,
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
    /// The error estimate of `DP` where it was taken by Richardson-extrapolated differences (the multipliers'
    /// accuracy is about as good); absent where `DP` is exact.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jacobian_error: Option<f64>,
    /// A walker with compliant legs: its heel strike's DLS indicators and branch, its double support, the
    /// impacts' losses, the dampers' work, the signed energy audit and the penetration; absent for rigid legs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub legged: Option<StepAccount>,
}

/// `dP/dp` of a walker's step map at its gait, by the section's coordinates.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkerParamDerivative {
    /// The parameter.
    pub parameter: String,
    /// `dP/dp`, one value per section coordinate.
    #[serde(serialize_with = "as_map")]
    pub values: Vec<(String, f64)>,
    /// How it was taken: exactly (as the gait's exact `derivative` says), or by Richardson-extrapolated central
    /// differences where the map has no derivative at the gait, and why.
    pub derivative: String,
    /// The differences' error estimate where they were taken; absent where exact.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<f64>,
}

/// Search the gait of `job.walker` and write `gait.json` (also without a gait, with the reason), after the
/// output directory is checked.
pub fn run_walker_gait(job: &WalkerGaitJob) -> Result<WalkerGaitSummary, AppError> {
    crate::output::manifest::check_out_dir(&job.out_dir, "gait", job.overwrite)?;
    let summary = compute_walker_gait(job)?;
    in_run_on(
        &job.out_dir,
        job.overwrite,
        ("gait", Some(job.walker.name())),
        |run| {
            output::write_json(&run.path("gait.json"), &summary)?;
            run.add("gait.json");
            Ok((summary, None))
        },
    )
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
        Walker::Telescopic(_) => compute_on_model(job)?,
        Walker::Described(w) if w.walks_compliant() => compute_on_model(job)?,
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
    let derivatives = match &result {
        Ok(g) => rigid_gait_derivatives(walker, &g.section, asked(job))?,
        Err(_) => GaitDerivatives::default(),
    };
    Ok(WalkerGaitSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        model: walker.name(),
        parameters: job.walker.clone(),
        initial: named(&names, &start),
        status: match &result {
            Ok(_) => SearchEnded::Found,
            Err(e) => SearchEnded::Failed(WalkerGaitError::from(e.clone()).kind()),
        },
        message: result.as_ref().err().map(ToString::to_string),
        gait: result.ok().map(|g| WalkerGait {
            dp_dparam: named_derivative(&names, job, derivatives.dp_dparam),
            ..gait_record(&found_rigid(walker, g), &names)
        }),
        jacobian_check: derivatives.jacobian_check,
    })
}

/// The search of [`run_walker_gait`] on the walker's [`WalkerModel`] (a walker with compliant legs, whose exact
/// `DP` is checked against Richardson-extrapolated differences at every gait), with the derivatives the job
/// asks for.
fn compute_on_model(job: &WalkerGaitJob) -> Result<WalkerGaitSummary, AppError> {
    let model = job.walker.model()?;
    let start = start_of(model.as_ref(), job.initial.as_deref())?;
    let result = model.gait(&start, job.transient_steps);
    super::check_phase_interrupted(None, "while searching the gait", super::NOTHING_WRITTEN)?;
    let derivatives = match &result {
        Ok(g) if job.parameter.is_some() || job.check_jacobian => {
            legged_derivatives(&job.walker, &g.section, asked(job))?
        }
        _ => GaitDerivatives::default(),
    };
    let names = model.section_names();
    Ok(WalkerGaitSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        model: job.walker.name(),
        parameters: job.walker.clone(),
        initial: named(&names, &start),
        status: match &result {
            Ok(_) => SearchEnded::Found,
            Err(e) => SearchEnded::Failed(e.kind()),
        },
        message: result.as_ref().err().map(ToString::to_string),
        gait: result.ok().map(|g| WalkerGait {
            dp_dparam: named_derivative(&names, job, derivatives.dp_dparam),
            ..gait_record(&g, &names)
        }),
        jacobian_check: derivatives.jacobian_check,
    })
}

/// What `job` asks of its gait's derivatives.
fn asked(job: &WalkerGaitJob) -> Asked<'_> {
    Asked {
        parameter: job.parameter.as_deref(),
        check: job.check_jacobian,
    }
}

/// The derivatives `asked` of `walker`, a walker with compliant legs, at its gait `section`.
fn legged_derivatives(
    walker: &Walker,
    section: &DVector<f64>,
    asked: Asked<'_>,
) -> Result<GaitDerivatives, AppError> {
    match walker {
        Walker::Telescopic(w) => legged_gait_derivatives::<_, 6, 13>(w, section, asked),
        Walker::Described(any) if any.walks_compliant() => crate::with_legged_described!(
            any, w, N, Y => legged_gait_derivatives::<_, N, Y>(w, section, asked),
            _ => unreachable_walk(any)
        ),
        _ => Err(AppError::InvalidOption {
            option: "model",
            reason: format!("`{}` has rigid legs", walker.name()),
        }),
    }
}

/// `dP/dp` of `job.parameter`, by the section's coordinate `names`.
fn named_derivative<S: AsRef<str>>(
    names: &[S],
    job: &WalkerGaitJob,
    d: Option<ParameterDerivative>,
) -> Option<WalkerParamDerivative> {
    let (key, d) = job.parameter.clone().zip(d)?;
    Some(WalkerParamDerivative {
        parameter: key,
        values: named(names, &d.values),
        derivative: d.derivative,
        error: d.error,
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

/// `gait.json`'s record of `g`, its section by `names`.
fn gait_record<S: AsRef<str>>(g: &FoundGait, names: &[S]) -> WalkerGait {
    let largest = g.largest_multiplier();
    WalkerGait {
        section: named(names, &g.section),
        residual: g.residual,
        newton_iterations: g.iterations,
        period: g.step.period,
        floquet_multipliers: g.multipliers.clone(),
        largest_multiplier: largest,
        stability: if largest < 1.0 { "stable" } else { "unstable" },
        derivative: g.derivative.clone(),
        lambda_i4: g.step.lambda_i4,
        impact_loss: g.step.impact_loss,
        energy_drift: g.step.energy_drift,
        scuffs: g.step.scuffs,
        dp_dparam: None,
        jacobian_error: g.jacobian_error,
        legged: g.step.legged,
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

/// Where a described walker's gait search starts (its `[gait]` table's `start`), or why it cannot walk: no
/// `[gait]` table, or joints that need the compliant walk ([`described::NotWalkable`]); and whether that start
/// (or `initial`, where given with the section's length) completes to a state after a heel strike.
pub(super) fn rigid_start(
    w: &AnyDescribed,
    initial: Option<&[f64]>,
) -> Result<DVector<f64>, AppError> {
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
pub(super) fn unreachable_walk<T>(w: &AnyDescribed) -> Result<T, AppError> {
    Err(AppError::InvalidOption {
        option: "model",
        reason: format!(
            "`{}` has {} coordinates: a biped with rigid legs needs at least 3",
            w.description().name,
            w.description().coordinates.len()
        ),
    })
}
