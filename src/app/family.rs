//! The job of `vrw continue` (docs/model.md section 11): follow the gait family through a gait in one
//! parameter by pseudo-arclength continuation, locate its special points, follow the period-2 family of every
//! period doubling, say why each family ends, and write `branch.csv`, `special_points.json` and the
//! bifurcation diagram.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use serde::Serialize;

use super::family_extrema::{check_extremum_names, family_extrema, FamilyExtrema};
use super::family_records::{point_stability, special_record, FamilyRecord, SpecialRecord};
use super::{prepared, AppError};
use crate::continuation::{ContinuationError, ContinuationOptions, Curve, Family};
use crate::family::curves::{two_param_curves, CurveRecord, FollowedParam};
use crate::family::diagram::{
    drop_unlocated, follow_families, DiagramSettings, EndRecord, FollowedFamily,
};
use crate::family::{GaitFamily, GaitInfo, Parameter};
use crate::gait::MAX_PERIOD;
use crate::gait::{find_gait_any_period, find_periodic_gait, GaitOptions, Stability, StepMap};
use crate::params::Config;
use crate::walk::interrupt::stop_requested;
use crate::walk::SectionState;

/// The quantities the bifurcation diagram can draw against the parameter (`--plot`).
pub const DIAGRAM_QUANTITIES: [&str; 10] = [
    "thetadot",
    "L2",
    "L2dot",
    "lambda_I4",
    "lambda_2_plus",
    "lambda_4_plus",
    "max_floquet",
    "period",
    "speed",
    "dls_duration",
];

/// Most points one family may have in each direction (`max_points`).
pub const MAX_FAMILY_POINTS: usize = 10_000;
/// What `vrw continue` runs.
#[derive(Debug, Clone)]
pub struct ContinueJob {
    /// Parameters and solver options (the parameter's own value is replaced by `start`).
    pub config: Config,
    /// The parameter followed (one of [`Config::numeric_keys`]).
    pub param: String,
    /// The parameter value of the first gait (`None`: the configuration's value).
    pub start: Option<f64>,
    /// The range the families are followed in.
    pub from: f64,
    /// See `from`.
    pub to: f64,
    /// Where the search for the first gait starts (`None`: the default start); with `period` it is taken as a
    /// point of the gait itself.
    pub initial: Option<SectionState>,
    /// The largest period of the first gait (`None`: any up to 8, period 1 first); the family is that of the
    /// least period the search finds.
    pub period: Option<usize>,
    /// Most points of a family in each direction.
    pub max_points: usize,
    /// Largest continuation step (scaled unknowns).
    pub max_step: f64,
    /// Follow the period-2 family born at every located period doubling (up to
    /// [`MAX_FAMILIES`](crate::family::diagram::MAX_FAMILIES) families).
    pub switch: bool,
    /// The quantity the diagram draws (one of [`DIAGRAM_QUANTITIES`]).
    pub plot: String,
    /// Where `branch.csv`, `special_points.json` and `bifurcation.{svg,png}` go.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir` (its files are removed and listed in the manifest);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    pub overwrite: bool,
    /// Stops the walks when set.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// Follow the curve of every located special point (indicator border collisions, folds, period doublings,
    /// Neimark-Sacker points) in a second parameter over its range (`name`, from, to): `curves.csv`,
    /// `curves.png`.
    pub two_param: Option<(String, f64, f64)>,
    /// Locate the extrema of these monitored quantities
    /// ([`MONITORED_QUANTITIES`](crate::family::monitor::MONITORED_QUANTITIES)) along every family: special
    /// points `EX` after the others, and `monitored.csv`, every monitored quantity at every point with its
    /// derivative along the family. Empty: neither.
    pub extremum: Vec<String>,
}

/// `special_points.json`: what was followed, the families and their special points.
#[derive(Debug, Clone, Serialize)]
pub struct ContinueSummary {
    /// Version of vrw that produced the file.
    pub vrw_version: &'static str,
    /// Parameters and solver options, with the parameter at the start value.
    pub config: Config,
    /// The parameter followed.
    pub param: String,
    /// The start value.
    pub start: f64,
    /// The section state of the first gait.
    pub initial: SectionState,
    /// The continuation settings.
    pub options: ContinuationOptions,
    /// The families.
    pub families: Vec<FamilyRecord>,
    /// Their special points, by family and arclength (then the extrema of `extremum`, by family and quantity).
    pub special_points: Vec<SpecialRecord>,
    /// The two-parameter curves followed (`two_param`), in `curves.csv`'s order.
    pub curves: Vec<CurveRecord>,
    /// Audit warnings of the families' gaits, and families that could not be followed.
    pub warnings: Vec<String>,
    /// Where the interrupt flag (Ctrl-C) stopped the job and what is kept, in words (`None`: it did not).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interrupted: Option<String>,
    /// The files written.
    pub files: Vec<String>,
    /// Wall time \[s\] (printed, not written: `special_points.json` is reproducible).
    #[serde(skip)]
    pub seconds: f64,
}

/// What [`compute_continuation`] gives: the summary and the families themselves.
#[derive(Debug, Clone)]
pub struct ContinueResult {
    /// What `special_points.json` holds.
    pub summary: ContinueSummary,
    /// The families, in the summary's order.
    pub families: Vec<Family<GaitInfo>>,
    /// Each family's points' stability verdicts.
    pub stability: Vec<Vec<Stability>>,
    /// The two-parameter curves, as the summary's `curves`.
    pub curves: Vec<Curve<GaitInfo>>,
    /// With `extremum`: the monitored quantities along the families and their extrema (empty without).
    pub extrema: FamilyExtrema,
}

impl ContinueJob {
    /// Checks the settings that are not model parameters.
    pub(super) fn validate(&self) -> Result<f64, AppError> {
        let invalid =
            |option: &'static str, reason: String| AppError::InvalidOption { option, reason };
        if !Config::numeric_keys().contains(&self.param.as_str()) {
            return Err(invalid(
                "param",
                format!(
                    "unknown parameter {:?}: expected one of {}",
                    crate::fmt::clip(&self.param),
                    Config::numeric_keys().join(", ")
                ),
            ));
        }
        if !DIAGRAM_QUANTITIES.contains(&self.plot.as_str()) {
            return Err(invalid(
                "plot",
                format!(
                    "unknown quantity {:?}: expected one of {}",
                    crate::fmt::clip(&self.plot),
                    DIAGRAM_QUANTITIES.join(", ")
                ),
            ));
        }
        if !(self.from.is_finite() && self.to.is_finite() && self.from < self.to) {
            return Err(invalid(
                "from",
                format!(
                    "the range must be finite with from < to, got [{}, {}]",
                    self.from, self.to
                ),
            ));
        }
        if !(1..=MAX_FAMILY_POINTS).contains(&self.max_points) {
            return Err(invalid(
                "max_points",
                format!(
                    "must be from 1 to {MAX_FAMILY_POINTS}, got {}",
                    self.max_points
                ),
            ));
        }
        if !(self.max_step.is_finite() && self.max_step > 0.0) {
            return Err(invalid(
                "max_step",
                format!(
                    "the longest continuation step must be a positive number, got {}",
                    self.max_step
                ),
            ));
        }
        if let Some(k) = self.period {
            if !(1..=MAX_PERIOD).contains(&k) {
                return Err(invalid(
                    "period",
                    format!("must be from 1 to {MAX_PERIOD}, got {k}"),
                ));
            }
        }
        if let Some(second) = &self.two_param {
            check_two_param(&self.param, &self.config, second)?;
        }
        check_extremum_names(&self.extremum)?;
        let start = match self.start {
            Some(v) => v,
            None => self.config.get_numeric(&self.param)?,
        };
        if !(self.from..=self.to).contains(&start) {
            return Err(invalid(
                "start",
                format!("{start} is outside the range [{}, {}]", self.from, self.to),
            ));
        }
        Ok(start)
    }

    /// The continuation settings.
    fn options(&self) -> ContinuationOptions {
        let mut options = ContinuationOptions::for_range(self.from, self.to);
        options.max_points = self.max_points;
        options.max_step = self.max_step;
        options.initial_step = options.initial_step.min(self.max_step);
        options
    }
}

/// The work of [`run_continuation`](super::run_continuation) without writing anything.
///
/// When the interrupt flag (the job's or the library's) stops the work, the result keeps what was complete
/// and says so in [`ContinueSummary::interrupted`]: the points followed before it (verified gaits), the ends
/// reached before it, the special points located before it; a family cut short ends with
/// [`FamilyEnd::Interrupted`](crate::continuation::FamilyEnd::Interrupted), no family is switched to and no
/// curve is followed after it. Stopped before the first gait is found, it is [`AppError::Interrupted`].
pub fn compute_continuation(job: &ContinueJob) -> Result<ContinueResult, AppError> {
    let clock = std::time::Instant::now();
    let start = job.validate()?;
    let config = job.config.with(&job.param, start)?;
    let (model, initial) = prepared(&config, job.initial)?;
    let flag = job.interrupt.as_deref();
    let gait = first_gait(job, &model, &config, &initial, start)?;
    // The step map P itself (every family's map is an iterate of it), and the first family's P^k.
    let parameter = Parameter::named(&config, &job.param).map_err(|e| AppError::InvalidOption {
        option: "param",
        reason: e.to_string(),
    })?;
    let base_map = GaitFamily::new(parameter, gait.section).with_interrupt(flag);
    let options = job.options();
    let settings = DiagramSettings {
        switch: job.switch,
        interrupt: flag,
    };
    let followed = follow_families(&settings, base_map, &gait, start, &options)
        .map_err(|e| continuation_error(e, &job.param))?;
    let (mut families, mut warnings) = (followed.families, followed.warnings);
    let mut interrupted = followed.interrupted;
    if interrupted.is_some() {
        drop_unlocated(&mut families, &mut warnings);
    }
    let (records, mut special_points, stability) = family_records(job, &families, &mut warnings);
    let extrema = family_extrema(&job.extremum, &families, interrupted.is_some(), flag);
    special_points.extend(extrema.records());
    if stop_requested(flag) {
        interrupted = Some(stopped_after_following(job, interrupted));
    }
    let (curve_records, curves) = match (&job.two_param, &interrupted) {
        (Some(second), None) => {
            let followed = FollowedParam {
                param: &job.param,
                from: job.from,
                to: job.to,
            };
            let q0 = check_two_param(&job.param, &config, second)?;
            let maps: Vec<_> = families.iter().map(|f| (&f.family, f.map)).collect();
            let curves = two_param_curves(&followed, second, q0, &maps, &mut warnings);
            if stop_requested(flag) {
                interrupted =
                    Some("while following the two-parameter curves: none is kept".to_string());
                (Vec::new(), Vec::new())
            } else {
                curves
            }
        }
        _ => (Vec::new(), Vec::new()),
    };
    let summary = ContinueSummary {
        curves: curve_records,
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: config.clone(),
        param: job.param.clone(),
        start,
        initial: gait.section,
        options,
        families: records,
        special_points,
        warnings,
        interrupted,
        files: Vec::new(),
        seconds: clock.elapsed().as_secs_f64(),
    };
    Ok(ContinueResult {
        summary,
        families: families.into_iter().map(|f| f.family).collect(),
        stability,
        curves,
        extrema,
    })
}

/// What an interrupt that came after the families were followed (while their stability was judged or their
/// extrema located) leaves, after what an earlier one (`interrupted`) left.
fn stopped_after_following(job: &ContinueJob, interrupted: Option<String>) -> String {
    let mut note =
        "the stability verdicts within 1e-3 of the unit circle judged after it are `uncertain` \
                    (their DP's error estimate was not computed)"
            .to_string();
    if !job.extremum.is_empty() {
        note.push_str("; no extremum is kept");
    }
    match interrupted {
        Some(words) => format!("{words}; {note}"),
        None => format!("while judging the families' stability: {note}"),
    }
}

/// The gait the first family is followed from (period at most `job.period`, or any up to [`MAX_PERIOD`]); an
/// interrupted search is [`AppError::Interrupted`], a failed one a bad `start`.
fn first_gait(
    job: &ContinueJob,
    model: &crate::dynamics::Model,
    config: &Config,
    initial: &SectionState,
    start: f64,
) -> Result<crate::gait::Gait, AppError> {
    let map = StepMap::new(model, &config.solver).with_interrupt(job.interrupt.as_deref());
    let gait_options = GaitOptions {
        refine_jacobian: false,
        ..GaitOptions::default()
    };
    let gait = match job.period {
        None => find_gait_any_period(&map, initial, &gait_options, MAX_PERIOD),
        Some(k) => find_periodic_gait(&map, initial, &gait_options, k),
    };
    super::check_phase_interrupted(
        job.interrupt.as_deref(),
        "while searching the first gait",
        "nothing is kept",
    )?;
    gait.map_err(|e| AppError::InvalidOption {
        option: "start",
        reason: format!("no gait at {} = {start} to start from: {e}", job.param),
    })
}

/// The families' records, their special points and their points' stability verdicts; the audit warnings of
/// their gaits go to `warnings`. A family whose ends were not explained (the job was interrupted first) has
/// its ends without causes.
fn family_records(
    job: &ContinueJob,
    families: &[FollowedFamily],
    warnings: &mut Vec<String>,
) -> (Vec<FamilyRecord>, Vec<SpecialRecord>, Vec<Vec<Stability>>) {
    let mut records = Vec::new();
    let mut special_points = Vec::new();
    let mut stability = Vec::new();
    for (k, f) in families.iter().enumerate() {
        let family = &f.family;
        records.push(FamilyRecord {
            family: k + 1,
            period_k: family.period,
            points: family.points.len(),
            origin: f.origin.clone(),
            ends: f.ends.clone().unwrap_or_else(|| {
                family
                    .ends
                    .clone()
                    .map(|end| EndRecord { end, cause: None })
            }),
        });
        special_points.extend(family.special.iter().map(|s| special_record(k + 1, s)));
        stability.push(
            family
                .points
                .iter()
                .map(|p| point_stability(&f.map, p))
                .collect(),
        );
        for p in &family.points {
            warnings.extend(
                p.info
                    .report
                    .audit_warnings()
                    .into_iter()
                    .map(|w| format!("family {} at {} = {}: {w}", k + 1, job.param, p.param)),
            );
        }
    }
    (records, special_points, stability)
}

/// A continuation error as the job's error.
fn continuation_error(e: ContinuationError, param: &str) -> AppError {
    AppError::InvalidOption {
        option: "start",
        reason: format!("the family in {param} could not be started: {e}"),
    }
}

/// Checks `--two-param` before anything is computed: a real-valued key other than the followed `param`, and a
/// finite range `from < to` that holds its configured value (returned).
fn check_two_param(
    param: &str,
    config: &Config,
    (name, from, to): &(String, f64, f64),
) -> Result<f64, AppError> {
    let invalid = |reason: String| AppError::InvalidOption {
        option: "two_param",
        reason,
    };
    if !Config::numeric_keys().contains(&name.as_str()) || name == param {
        return Err(invalid(format!(
            "{name:?} must be a real-valued key other than the followed parameter {param:?}"
        )));
    }
    let q0 = config.get_numeric(name)?;
    if !(from.is_finite() && to.is_finite() && from < to && (*from..=*to).contains(&q0)) {
        return Err(invalid(format!(
            "the range [{from}, {to}] must hold {name} = {q0} with from < to"
        )));
    }
    Ok(q0)
}
