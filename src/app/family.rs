//! The job of `vrw continue` (docs/model.md section 11): follow the gait family through a gait in one
//! parameter by pseudo-arclength continuation, locate its special points, follow the period-2 family of every
//! period doubling, say why each family ends, and write `branch.csv`, `special_points.json` and the
//! bifurcation diagram.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use serde::Serialize;

use super::family_curves::{self, two_param_curves, CurveRecord};
use super::family_records::{
    point_stability, special_record, EndRecord, FamilyRecord, SpecialRecord,
};
use super::family_switch::{same_as_followed, switched_families, Followed};
use super::{prepared, AppError};
use crate::continuation::Curve;
use crate::continuation::{
    continue_family, ContinuationError, ContinuationOptions, Family, FamilyEnd, FamilyMap,
};
use crate::family::natural::{EndCause, GaitPoint, NaturalContinuation};
use crate::family::{GaitFamily, GaitInfo};
use crate::gait::MAX_PERIOD;
use crate::gait::{find_gait_any_period, find_periodic_gait, GaitOptions, Stability, StepMap};
use crate::params::Config;
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

/// Most families one job follows (the start's and those switched to at period doublings).
pub const MAX_FAMILIES: usize = 8;

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
    /// Follow the period-2 family born at every located period doubling (up to [`MAX_FAMILIES`] families).
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
    /// Their special points, by family and arclength.
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
                format!("must be a positive number, got {}", self.max_step),
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
            family_curves::check_two_param(&self.param, &self.config, second)?;
        }
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
/// [`FamilyEnd::Interrupted`], no family is switched to and no curve is followed after it. Stopped before the
/// first gait is found, it is [`AppError::Interrupted`].
pub fn compute_continuation(job: &ContinueJob) -> Result<ContinueResult, AppError> {
    let clock = std::time::Instant::now();
    let start = job.validate()?;
    let config = job.config.with(&job.param, start)?;
    let (model, initial) = prepared(&config, job.initial)?;
    let flag = job.interrupt.as_deref();
    let gait = first_gait(job, &model, &config, &initial, start)?;
    // The step map P itself (every family's map is an iterate of it), and the first family's P^k.
    let base_map = GaitFamily::new(&config, &job.param, gait.section)
        .map_err(|e| AppError::InvalidOption {
            option: "param",
            reason: e.message,
        })?
        .with_interrupt(flag);
    let options = job.options();
    let followed = follow_families(job, &config, base_map, &gait, start, &options)?;
    let (mut families, mut warnings) = (followed.families, followed.warnings);
    let mut interrupted = followed.interrupted;
    if interrupted.is_some() {
        drop_unlocated(&mut families, &mut warnings);
    }
    let (records, special_points, stability) = family_records(job, &families, &mut warnings);
    if stopped(flag) {
        let note = "the stability verdicts within 1e-3 of the unit circle judged after it are `uncertain` \
                    (their DP's error estimate was not computed)";
        interrupted = Some(match interrupted {
            Some(words) => format!("{words}; {note}"),
            None => format!("while judging the families' stability: {note}"),
        });
    }
    let (curve_records, curves) = match (&job.two_param, &interrupted) {
        (Some(second), None) => {
            let followed = family_curves::FollowedParam {
                param: &job.param,
                from: job.from,
                to: job.to,
            };
            let maps: Vec<_> = families.iter().map(|f| (&f.family, f.map)).collect();
            let curves = two_param_curves(&followed, &config, second, &maps, &mut warnings)?;
            if stopped(flag) {
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
    })
}

/// Is the job's interrupt flag or the library's set?
fn stopped(flag: Option<&AtomicBool>) -> bool {
    flag.is_some_and(|f| f.load(std::sync::atomic::Ordering::SeqCst)) || crate::walk::interrupted()
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

/// The families [`follow_families`] followed, the warnings on the way, and where the interrupt flag stopped it
/// (in words; `None` if it did not).
struct FollowedFamilies<'a> {
    families: Vec<Followed<'a>>,
    warnings: Vec<String>,
    interrupted: Option<String>,
}

/// Follow the family of `gait` from `start`, then breadth first: each family's ends explained by a walk past
/// them, then (with `switch`) the period-2 family of each of its located period doublings and the family of
/// each gait a walk past an end settles on. Once the interrupt flag is set, what the step under way computed
/// is dropped (the causes of a family's ends, the families born from it) and nothing more is followed.
fn follow_families<'a>(
    job: &ContinueJob,
    config: &Config,
    base_map: GaitFamily<'a>,
    gait: &crate::gait::Gait,
    start: f64,
    options: &ContinuationOptions,
) -> Result<FollowedFamilies<'a>, AppError> {
    let flag = job.interrupt.as_deref();
    let family_map = base_map.iterated(gait.period_k);
    let first = continue_family(
        &family_map,
        &family_map.reduce(&gait.section),
        start,
        options,
    )
    .map_err(|e| continuation_error(e, &job.param))?;
    let mut followed = FollowedFamilies {
        families: vec![Followed {
            family: first,
            origin: "start".to_string(),
            map: family_map,
            ends: None,
        }],
        warnings: Vec::new(),
        interrupted: None,
    };
    let families = &mut followed.families;
    let mut next = 0;
    while next < families.len() && !stopped(flag) {
        let ends = families[next].family.ends.clone().map(|end| {
            let cause = end_cause(config, &job.param, &families[next], &end);
            EndRecord { end, cause }
        });
        if stopped(flag) {
            break;
        }
        families[next].ends = Some(ends.clone());
        let born = if job.switch {
            switched_families(&job.param, next, families, base_map, &ends, options)
        } else {
            Vec::new()
        };
        if stopped(flag) {
            break;
        }
        for outcome in born {
            match outcome {
                Ok(f) if same_as_followed(families, &f) => followed.warnings.push(format!(
                    "the family from {} is one already followed (same period and ends): left out",
                    f.origin
                )),
                Ok(f) if families.len() < MAX_FAMILIES => families.push(f),
                Ok(f) => followed.warnings.push(format!(
                    "more families than the {MAX_FAMILIES} one job follows: the one from {} not followed",
                    f.origin
                )),
                Err(w) => followed.warnings.push(w),
            }
        }
        next += 1;
    }
    if stopped(flag) {
        followed.interrupted = Some(format!(
            "while following family {} of {}: the points, ends and special points found before it are \
             kept; families not followed to their ends end as `interrupted`, and no family born after it \
             is followed",
            (next + 1).min(families.len()),
            families.len()
        ));
    }
    Ok(followed)
}

/// In an interrupted job: drop the special points that were not located (their location may have been cut
/// short), with a warning.
fn drop_unlocated(families: &mut [Followed], warnings: &mut Vec<String>) {
    for (k, f) in families.iter_mut().enumerate() {
        let before = f.family.special.len();
        f.family.special.retain(|sp| sp.located);
        let dropped = before - f.family.special.len();
        if dropped > 0 {
            warnings.push(format!(
                "family {}: {dropped} special points detected but not located are left out (the job was \
                 interrupted)",
                k + 1
            ));
        }
    }
}

/// The families' records, their special points and their points' stability verdicts; the audit warnings of
/// their gaits go to `warnings`. A family whose ends were not explained (the job was interrupted first) has
/// its ends without causes.
fn family_records(
    job: &ContinueJob,
    families: &[Followed],
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

/// What the walk from the last gait does just past an end where the map failed (`NaturalContinuation::end_cause`).
fn end_cause(
    config: &Config,
    param: &str,
    followed: &Followed,
    end: &FamilyEnd,
) -> Option<EndCause> {
    let (family, map) = (&followed.family, &followed.map);
    let FamilyEnd::Ended {
        param: at, beyond, ..
    } = end
    else {
        return None;
    };
    if !beyond.is_finite() {
        return None;
    }
    let last = family
        .points
        .iter()
        .find(|p| p.param == *at)
        .or(family.points.last())?;
    let continuation =
        NaturalContinuation::new(config, param, &GaitOptions::default()).with_period(map.period());
    Some(continuation.end_cause(
        &GaitPoint {
            value: last.param,
            section: map.section_at(&last.x, last.param),
        },
        *beyond,
    ))
}
