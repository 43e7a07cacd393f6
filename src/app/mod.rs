//! The jobs the command line runs, as library functions (STYLE.md point 2: all science lives in the library).
//!
//! One file per job: [`simulate`](run_simulate) (`simulate.rs`), [`gait`](run_gait) (`gait.rs`),
//! [`sweep`](run_sweep) with its Fig. 2 (`sweep.rs`), [`map`](run_map) (`map.rs`), [`orbit`](run_orbit)
//! (`orbit.rs`), [`basin`](run_basin) (`basin.rs`), [`continue`](run_continuation)
//! (`family.rs`, its records `family_records.rs`, its files `family_output.rs`), and [`plot`](run_plot) / [`animate`](run_animate) of a run
//! directory (`figures.rs`); the tables they write are declared in `output::tables`. This file holds what they
//! share: the error type, the start of every walk, and the names of parameters on figures.

mod basin;
mod family;
mod family_extrema;
mod family_output;
mod family_records;
mod figures;
mod gait;
mod legged;
mod map;
mod orbit;
mod simulate;
mod sweep;
mod walker_basin;
mod walker_continue;
mod walker_derivatives;
mod walker_described;
mod walker_figures;
mod walker_map;
mod walker_model;
mod walker_orbit;
mod walker_output;
mod walker_simulate;
mod walker_sweep;
mod walkers;

pub use crate::family::curves::CurveRecord;
pub use crate::family::diagram::{EndRecord, KNOWN_GAIT_TOL, MAX_FAMILIES, SAME_END_TOL};
pub use basin::{
    compute_basin, compute_basin_part, default_basin_range, run_basin, BasinJob, BasinSummary,
    SliceGrid, MAX_BASIN_POINTS, MAX_BASIN_STEPS,
};
pub use family::{
    compute_continuation, ContinueJob, ContinueResult, ContinueSummary, DIAGRAM_QUANTITIES,
    MAX_FAMILY_POINTS,
};
pub use family_extrema::{monitored_header, monitored_rows, FamilyExtrema};
pub use family_output::{curve_rows, family_rows, run_continuation};
pub use family_records::{
    ExtremumRecord, FamilyRecord, SectionRecord, SideRecord, SpecialRecord, STABILITY_BAND,
};
pub use figures::{
    checked_run, run_animate, run_plot, run_still, AnimateJob, AnimateOutcome, PlotReport,
    MAX_ANIMATION_FRAMES,
};
pub use gait::{
    compute_gait, run_gait, write_gait_period, GaitJob, GaitSummary, SearchEnded,
    MIN_GAIT_TOLERANCE,
};
pub use legged::{Compliant, LeggedModel};
pub use map::{compute_map, compute_map_part, run_map, MapJob, MapSummary};
pub use orbit::{
    compute_orbit, compute_orbit_part, run_orbit, OrbitJob, OrbitJobPart, OrbitPartResult,
    OrbitSummary, ORBIT_QUANTITIES,
};
pub use simulate::{
    compute_simulation, run_simulate, SimulateEvent, SimulateJob, SimulateSummary, WalkEnded,
    DEFAULT_SAMPLE_DT, MAX_SIMULATE_STEPS, MIN_SAMPLE_DT, SAMPLE_DT_RANGE,
};
pub use sweep::{compute_sweep, run_sweep, SweepJob, SweepResult, SweepSummary};
pub use walker_basin::{
    compute_walker_basin, run_walker_basin, WalkerBasinAxis, WalkerBasinGait, WalkerBasinJob,
    WalkerBasinPoint, WalkerBasinSummary, WalkerOutcome,
};
pub use walker_continue::{
    compute_walker_continuation, run_walker_continuation, WalkerContinueJob, WalkerContinueSummary,
    WalkerSpecialPoint,
};
pub use walker_map::{
    compute_walker_map, run_walker_map, WalkerMap, WalkerMapJob, WalkerMapSummary,
    WalkerMapThreshold,
};
pub use walker_model::{
    Body, FoundGait, Rigid, RigidModel, Sampling, Walk, WalkerError, WalkerGaitError, WalkerModel,
    WalkerSample, WalkerStep, Walking,
};
pub use walker_orbit::{
    compute_walker_orbit, run_walker_orbit, WalkerOrbitColumn, WalkerOrbitJob, WalkerOrbitSummary,
    MAX_WALKER_PERIOD,
};
pub use walker_output::WalkerOutput;
pub use walker_simulate::{
    compute_walker_simulate, run_walker_simulate, WalkerSimulateJob, WalkerSimulateSummary,
    WalkerStepRecord,
};
pub use walker_sweep::{
    compute_walker_sweep, run_walker_sweep, WalkerRange, WalkerSweepJob, WalkerSweepPoint,
    WalkerSweepSummary, WalkerThreshold, MAX_WALKER_SWEEP_POINTS,
};
pub use walkers::{
    compute_walker_gait, run_walker_gait, Walker, WalkerGait, WalkerGaitJob, WalkerGaitSummary,
    WalkerParamDerivative, MODELS, TELESCOPIC,
};

use crate::dynamics::Model;
use crate::output::manifest::{RunDir, RunStatus};
use crate::output::OutputError;
use crate::params::{Config, ConfigError};
use crate::reference::default_initial;
use crate::walk::{SectionState, WalkError};

/// A job could not run or could not write its results.
#[derive(Debug, thiserror::Error)]
pub enum AppError {
    /// Bad parameters.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A bad initial state or a walk that could not start.
    #[error(transparent)]
    Walk(#[from] WalkError),
    /// Results could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// A run directory could not be read back.
    #[error(transparent)]
    Read(#[from] crate::output::read::ReadError),
    /// The animation could not be made.
    #[error(transparent)]
    Animate(#[from] crate::output::animate::AnimateError),
    /// A figure could not be drawn.
    #[error(transparent)]
    Plot(#[from] crate::output::style::PlotError),
    /// The directory's manifest is missing or unreadable (`plot`, `animate`).
    #[error(transparent)]
    Manifest(#[from] crate::output::manifest::ManifestError),
    /// The files of a directory do not all belong to one finished run of `simulate` or `gait`.
    #[error("{dir}: {reason}")]
    NotOneRun {
        /// The directory.
        dir: std::path::PathBuf,
        /// What is wrong, and what to do.
        reason: String,
    },
    /// The interrupt flag (Ctrl-C) stopped the job; what was complete is written (and named in `kept`).
    #[error("interrupted (Ctrl-C) {during}; {kept}{}", recorded(kept))]
    Interrupted {
        /// Where the job was: `after 12 of 300 points`, `while locating the thresholds`.
        during: String,
        /// What the output directory holds, in words: `sweep.csv holds the complete points`.
        kept: String,
    },
    /// A bad job setting that is not a model parameter.
    #[error("invalid `{option}`: {reason}")]
    InvalidOption {
        /// The setting: the job's field, which is the Python keyword (`sample_dt`); the command line shows
        /// its flag instead (`--sample-dt`).
        option: &'static str,
        /// Why.
        reason: String,
    },
}

/// What an interrupted job that writes nothing keeps ([`AppError::Interrupted`]'s `kept`).
pub(crate) const NOTHING_WRITTEN: &str = "nothing is written";

/// Where an interrupted job's record is: its manifest, unless it wrote nothing.
fn recorded(kept: &str) -> &'static str {
    if kept == NOTHING_WRITTEN {
        ""
    } else {
        " (manifest.json: interrupted)"
    }
}

/// The validated configuration's model and the start on the section (`initial`, or [`default_initial`]),
/// checked against the model: what every job that walks needs first.
fn prepared(
    config: &Config,
    initial: Option<SectionState>,
) -> Result<(Model, SectionState), AppError> {
    config.validate()?;
    let model = Model::new(&config.params)?;
    let initial = initial.unwrap_or_else(|| default_initial(config));
    initial.validate(&model)?;
    Ok((model, initial))
}

/// Run `body` as a job `command` writing into `dir` ([`RunDir::start`]: the directory is checked and the
/// earlier run it holds removed, with `overwrite` also another command's; the manifest says `running`), then write the manifest's final status: `completed`, `interrupted`
/// (when `body` returns an interruption reason, or [`AppError::Interrupted`]) or `failed` with the error.
fn in_run<T>(
    dir: &std::path::Path,
    overwrite: bool,
    command: &str,
    body: impl FnOnce(&mut RunDir) -> Result<(T, Option<String>), AppError>,
) -> Result<T, AppError> {
    in_run_on(dir, overwrite, (command, None), body)
}

/// [`in_run`] of a job on the walker `model` (`None`: the wheel), which the manifest names.
fn in_run_on<T>(
    dir: &std::path::Path,
    overwrite: bool,
    (command, model): (&str, Option<&str>),
    body: impl FnOnce(&mut RunDir) -> Result<(T, Option<String>), AppError>,
) -> Result<T, AppError> {
    let mut run = RunDir::start_on(dir, command, model, overwrite)?;
    match body(&mut run) {
        Ok((value, None)) => {
            run.finish(RunStatus::Completed, None)?;
            Ok(value)
        }
        Ok((value, Some(reason))) => {
            run.finish(RunStatus::Interrupted, Some(reason))?;
            Ok(value)
        }
        Err(e) => {
            let status = match e {
                AppError::Interrupted { .. } => RunStatus::Interrupted,
                _ => RunStatus::Failed,
            };
            // The job's own error says more than a failure to record it.
            let _ = run.finish(status, Some(e.to_string()));
            Err(e)
        }
    }
}

/// The error of a grid job cut short by the interrupt flag, once its complete points are in `kept`; `Ok` if it
/// was not.
fn check_interrupted(done: usize, total: usize, kept: &'static str) -> Result<(), AppError> {
    if crate::walk::interrupted() {
        Err(AppError::Interrupted {
            during: format!("after {done} of {total} points"),
            kept: format!("{kept} holds the complete ones"),
        })
    } else {
        Ok(())
    }
}

/// The error of a job whose phase `during` (`while locating the thresholds`) was cut short by the interrupt
/// flag (the library's, or the job's own `flag`), its earlier phases' files being complete (`kept`); `Ok` if it
/// was not. What the phase computed is discarded by the caller.
fn check_phase_interrupted(
    flag: Option<&std::sync::atomic::AtomicBool>,
    during: &str,
    kept: &str,
) -> Result<(), AppError> {
    if crate::walk::interrupt::stop_requested(flag) {
        Err(AppError::Interrupted {
            during: during.to_string(),
            kept: kept.to_string(),
        })
    } else {
        Ok(())
    }
}

/// The configuration of the second route for a result computed with `config`: the other integrator, and the
/// route's name.
pub(crate) fn second_route_config(config: &Config) -> (Config, String) {
    let mut second = config.clone();
    second.solver.integrator = config.solver.integrator.other();
    let route = format!("integrator = {}", second.solver.integrator);
    (second, route)
}

/// The most non-default keys a figure's title names ([`settings_note`]); the rest are counted.
const TITLE_KEYS: usize = 5;

/// The keys a figure's title names besides those it shows already (`shown`: the varied parameters, and those
/// the title names itself): every key of `config` whose value differs from the default (a reading's rules,
/// `friction`, `impact`, `legs`, ...), as ` [friction = 0.105, impact traditional]`; empty when there is
/// none. So a figure always says what it was made with.
pub(crate) fn settings_note(config: &Config, shown: &[&str]) -> String {
    let (Ok(serde_json::Value::Object(now)), Ok(serde_json::Value::Object(default))) = (
        serde_json::to_value(config),
        serde_json::to_value(Config::default()),
    ) else {
        return String::new();
    };
    let changed: Vec<String> = now
        .iter()
        .filter(|(key, value)| !shown.contains(&key.as_str()) && default.get(*key) != Some(*value))
        .map(|(key, value)| match value {
            serde_json::Value::Number(n) => match n.as_f64() {
                Some(v) => format!("{} = {}", short_name(key), crate::fmt::short(v)),
                None => format!("{key} = {n}"),
            },
            serde_json::Value::String(text) => format!("{key} {text}"),
            other => format!("{key} = {other}"),
        })
        .collect();
    if changed.is_empty() {
        return String::new();
    }
    format!(
        " [{}]",
        crate::fmt::first_of(&changed, TITLE_KEYS, " non-default keys")
    )
}

/// Short symbol of a parameter for labels (`c` for viscosity, ...).
fn short_name(param: &str) -> &str {
    match param {
        "viscosity" => "c",
        "stiffness" => "k",
        "slope" => "φ",
        "hub_mass" => "mH",
        "leg_mass" => "m",
        "friction" => "μ",
        other => other,
    }
}

/// Axis label with unit.
fn axis_label(param: &str) -> String {
    let unit = match param {
        "viscosity" => "N s/m",
        "stiffness" => "N/m",
        "slope" => "rad",
        "hub_mass" | "leg_mass" => "kg",
        "hub_inertia" => "kg m²",
        "gravity" => "m/s²",
        "leg_mass_offset" | "stopper_length" | "spring_natural_length" => "m",
        _ => "",
    };
    if unit.is_empty() {
        short_name(param).to_string()
    } else {
        format!("{} [{unit}]", short_name(param))
    }
}

/// Audit warnings of the gaits of a sweep or a map ([`crate::walk::StepReport::audit_warnings`] of every
/// step of every gait), each prefixed with where the gait is (`where_` names a point, e.g. `viscosity = 50`).
/// A gait whose step breaks a law of the model is not to be trusted, so its numbers never go out unsaid.
pub(crate) fn gait_warnings<'a>(
    points: impl IntoIterator<Item = (String, &'a crate::study::SweepPoint)>,
) -> Vec<String> {
    points
        .into_iter()
        .flat_map(|(at, point)| {
            let steps = point.gait.iter().flat_map(|g| g.cycle.iter());
            steps
                .flat_map(|s| s.audit_warnings())
                .map(move |w| format!("gait at {at}: {w}"))
                .collect::<Vec<_>>()
        })
        .collect()
}
