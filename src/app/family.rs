//! The job of `vrw continue` (docs/model.md section 11): follow the gait family through a gait in one
//! parameter by pseudo-arclength continuation, locate its special points, follow the period-2 family of every
//! period doubling, say why each family ends, and write `branch.csv`, `special_points.json` and the
//! bifurcation diagram.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use serde::Serialize;

use super::family_curves::{self, two_param_curves, CurveRecord};
use super::family_records::{special_record, EndRecord, FamilyRecord, SpecialRecord};
use super::{prepared, AppError};
use crate::bifurcation::corrector::solve_on_hyperplane;
use crate::bifurcation::special::JUMP_TOL;
use crate::bifurcation::Curve;
use crate::bifurcation::{
    continue_family, switch_at_border, switch_at_period_doubling, ContinuationError,
    ContinuationOptions, Family, FamilyEnd, FamilyMap, GaitFamily, GaitInfo, SpecialKind,
};
use crate::gait::continuation::{Continuation, EndCause, FamilyPoint as GaitPoint};
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

/// Within this of the unit circle, a point's stability verdict uses the error estimate of its `DP` (a second
/// `DP` at tighter tolerances); farther out the exact `DP`'s error (below `1e-6` wherever it was estimated)
/// cannot change it.
pub const STABILITY_BAND: f64 = 1e-3;

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
    /// The files written.
    pub files: Vec<String>,
    /// Wall time \[s\].
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
    fn validate(&self) -> Result<f64, AppError> {
        let invalid =
            |option: &'static str, reason: String| AppError::InvalidOption { option, reason };
        if !Config::numeric_keys().contains(&self.param.as_str()) {
            return Err(invalid(
                "param",
                format!(
                    "unknown parameter {:?}: expected one of {}",
                    self.param,
                    Config::numeric_keys().join(", ")
                ),
            ));
        }
        if !DIAGRAM_QUANTITIES.contains(&self.plot.as_str()) {
            return Err(invalid(
                "plot",
                format!(
                    "unknown quantity {:?}: expected one of {}",
                    self.plot,
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
pub fn compute_continuation(job: &ContinueJob) -> Result<ContinueResult, AppError> {
    let clock = std::time::Instant::now();
    let start = job.validate()?;
    let config = job.config.with(&job.param, start)?;
    let (model, initial) = prepared(&config, job.initial)?;
    let flag = job.interrupt.as_deref();
    let map = StepMap::new(&model, &config.solver).with_interrupt(flag);
    let gait_options = GaitOptions {
        refine_jacobian: false,
        ..GaitOptions::default()
    };
    let gait = match job.period {
        None => find_gait_any_period(&map, &initial, &gait_options, MAX_PERIOD),
        Some(k) => find_periodic_gait(&map, &initial, &gait_options, k),
    }
    .map_err(|e| AppError::InvalidOption {
        option: "start",
        reason: format!("no gait at {} = {start} to start from: {e}", job.param),
    })?;
    // The step map P itself (every family's map is an iterate of it), and the first family's P^k.
    let base_map = GaitFamily::new(&config, &job.param, gait.section)
        .map_err(|e| AppError::InvalidOption {
            option: "param",
            reason: e.message,
        })?
        .with_interrupt(flag);
    let family_map = base_map.iterated(gait.period_k);
    let options = job.options();
    let first = continue_family(
        &family_map,
        &family_map.reduce(&gait.section),
        start,
        &options,
    )
    .map_err(|e| continuation_error(e, &job.param))?;
    let mut families = vec![Followed {
        family: first,
        origin: "start".to_string(),
        map: family_map,
        ends: None,
    }];
    let mut warnings = Vec::new();
    // Breadth first: each family's ends explained by a walk past them, then (with `switch`) the period-2
    // family of each of its located period doublings and the family of each gait a walk past an end settles
    // on.
    let mut next = 0;
    while next < families.len() {
        let ends = families[next].family.ends.clone().map(|end| {
            let cause = end_cause(&config, &job.param, &families[next], &end);
            EndRecord { end, cause }
        });
        families[next].ends = Some(ends.clone());
        if job.switch {
            let born = switched_families(job, next, &families, base_map, &ends, &options);
            for outcome in born {
                match outcome {
                    Ok(f) if same_as_followed(&families, &f) => warnings.push(format!(
                        "the family from {} is one already followed (same period and ends): left out",
                        f.origin
                    )),
                    Ok(f) if families.len() < MAX_FAMILIES => families.push(f),
                    Ok(f) => warnings.push(format!(
                        "more families than the {MAX_FAMILIES} one job follows: the one from {} not followed",
                        f.origin
                    )),
                    Err(w) => warnings.push(w),
                }
            }
        }
        next += 1;
    }
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
            ends: f
                .ends
                .clone()
                .expect("every family's ends are explained above"),
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
    let (curve_records, curves) = match &job.two_param {
        Some(second) => {
            let followed = family_curves::FollowedParam {
                param: &job.param,
                from: job.from,
                to: job.to,
            };
            let maps: Vec<_> = families.iter().map(|f| (&f.family, f.map)).collect();
            two_param_curves(&followed, &config, second, &maps, &mut warnings)?
        }
        None => (Vec::new(), Vec::new()),
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

/// A family being followed: where it came from, its map and its ends with their causes.
struct Followed<'a> {
    family: Family<GaitInfo>,
    origin: String,
    map: GaitFamily<'a>,
    ends: Option<[EndRecord; 2]>,
}

/// The families born from family `k` (branch switching): the period-2 family of each of its located period
/// doublings, the other piece's family at each border collision where it ends, and the family of each gait that a walk past one of its `ends` settles on (unless a family
/// already followed passes through that gait). A family that cannot be started is a warning.
fn switched_families<'a>(
    job: &ContinueJob,
    k: usize,
    families: &[Followed<'a>],
    base_map: GaitFamily<'a>,
    ends: &[EndRecord; 2],
    options: &ContinuationOptions,
) -> Vec<Result<Followed<'a>, String>> {
    let parent = &families[k];
    let mut born = Vec::new();
    for (i, pd) in parent.family.special.iter().enumerate() {
        if pd.kind != SpecialKind::PeriodDoubling || !pd.located {
            continue;
        }
        born.push(
            switch_at_period_doubling(&parent.map, pd, options)
                .map(|family| Followed {
                    family,
                    origin: format!("family {} special point {i} (PD)", k + 1),
                    map: parent.map.iterated(2),
                    ends: None,
                })
                .map_err(|e| {
                    format!(
                        "family {} PD at {} = {}: no period-2 family followed: {e}",
                        k + 1,
                        job.param,
                        pd.param
                    )
                }),
        );
    }
    for (i, bc) in parent.family.special.iter().enumerate() {
        // Where the map jumps across the border, no fixed point of the other piece is near: the walk past
        // the end (below) looks for what takes over.
        if bc.kind != SpecialKind::BorderCollision
            || !bc.ends_family
            || !bc.located
            || bc.jump.is_nan()
            || bc.jump > JUMP_TOL
        {
            continue;
        }
        born.push(
            switch_at_border(&parent.map, bc, options)
                .map(|family| Followed {
                    family,
                    origin: format!(
                        "family {} special point {i} (BC: the other piece's fixed points)",
                        k + 1
                    ),
                    map: parent.map,
                    ends: None,
                })
                .map_err(|e| {
                    format!(
                        "family {} BC at {} = {}: no family of the other piece followed: {e}",
                        k + 1,
                        job.param,
                        bc.param
                    )
                }),
        );
    }
    for end in ends {
        let (
            Some(EndCause::OtherGait {
                section, period_k, ..
            }),
            FamilyEnd::Ended { beyond, .. },
        ) = (&end.cause, &end.end)
        else {
            continue;
        };
        // The walk's period may be a multiple of the gait's least period (its detection compares states
        // within the walk's tolerance): the family is followed as P^j for the least period j of its fixed
        // point at the walk's parameter.
        let walked = base_map.iterated(*period_k);
        let x = walked.reduce(section);
        let least = solve_on_parameter(&walked, &x, *beyond, options)
            .and_then(|fixed| walked.value_with_info(&fixed, *beyond).ok())
            .map_or(*period_k, |info| info.least_period());
        let period_k = &least;
        let map = base_map.iterated(*period_k);
        if known_gait(families, base_map, *period_k, &x, *beyond) {
            continue;
        }
        if !(options.from..=options.to).contains(beyond) {
            continue;
        }
        born.push(
            continue_family(&map, &x, *beyond, options)
                .map(|family| Followed {
                    family,
                    origin: format!(
                        "family {} end at {} = {} (the gait a walk past it settles on)",
                        k + 1,
                        job.param,
                        beyond
                    ),
                    map,
                    ends: None,
                })
                .map_err(|e| {
                    format!(
                        "family {} end at {} = {}: the period-{period_k} gait past it could not be followed: {e}",
                        k + 1,
                        job.param,
                        beyond
                    )
                }),
        );
    }
    born
}

/// The fixed point of `map` at `p` by Newton's method from `x` (`None` if it does not converge).
fn solve_on_parameter(
    map: &GaitFamily,
    x: &nalgebra::DVector<f64>,
    p: f64,
    options: &ContinuationOptions,
) -> Option<nalgebra::DVector<f64>> {
    let sigma = options.param_scale;
    let n = x.len();
    let mut z = x.clone().insert_row(n, p / sigma);
    let mut row = nalgebra::DVector::zeros(n + 1);
    row[n] = 1.0;
    z = solve_on_hyperplane(map, &z, &row, options).ok()?;
    Some(z.rows(0, n).into_owned())
}

/// Does a family already followed pass through the period-`k` gait `x` at `p` (any of its `k` phases)? Each
/// family of period `k` is interpolated linearly at `p` between its successive points that bracket `p`, and
/// compared with the phases within [`KNOWN_GAIT_TOL`] (the interpolation's error over a continuation step).
fn known_gait(
    families: &[Followed],
    base_map: GaitFamily,
    k: usize,
    x: &nalgebra::DVector<f64>,
    p: f64,
) -> bool {
    let mut phases = vec![x.clone()];
    for _ in 1..k {
        match phases.last().map(|y| base_map.value(y, p)) {
            Some(Ok(y)) => phases.push(y),
            _ => break,
        }
    }
    families
        .iter()
        .filter(|f| f.map.period() == k)
        .flat_map(|f| f.family.points.windows(2))
        .filter(|w| (w[0].param - p) * (w[1].param - p) <= 0.0 && w[0].param != w[1].param)
        .any(|w| {
            let t = (p - w[0].param) / (w[1].param - w[0].param);
            let at = &w[0].x + t * (&w[1].x - &w[0].x);
            phases.iter().any(|y| (&at - y).amax() < KNOWN_GAIT_TOL)
        })
}

/// Is `new` a family already followed: the same period, and both its ends within [`SAME_END_TOL`] times
/// `max(1, |p|)` in the parameter of that family's ends (a walk past an end can settle on another phase of a
/// known orbit, where [`known_gait`]'s interpolation misses it)?
fn same_as_followed(families: &[Followed], new: &Followed) -> bool {
    let ends = |f: &Family<GaitInfo>| -> Option<[f64; 2]> {
        Some([f.points.first()?.param, f.points.last()?.param])
    };
    let Some(mut a) = ends(&new.family) else {
        return false;
    };
    a.sort_by(f64::total_cmp);
    families.iter().any(|f| {
        f.family.period == new.family.period
            && ends(&f.family).is_some_and(|mut b| {
                b.sort_by(f64::total_cmp);
                a.iter()
                    .zip(b)
                    .all(|(x, y)| (x - y).abs() <= SAME_END_TOL * y.abs().max(1.0))
            })
    })
}

/// Two families whose ends lie this close (relative to the parameter) are taken as one: ends are bracketed to
/// far less.
pub const SAME_END_TOL: f64 = 1e-6;

/// Two gaits closer than this on the section (interpolated) are taken as one ([`known_gait`]).
pub const KNOWN_GAIT_TOL: f64 = 1e-3;

/// A continuation error as the job's error.
fn continuation_error(e: ContinuationError, param: &str) -> AppError {
    AppError::InvalidOption {
        option: "start",
        reason: format!("the family in {param} could not be started: {e}"),
    }
}

/// The stability verdict of a family point: from its multipliers, with the error estimate of its `DP`
/// within [`STABILITY_BAND`] of the unit circle; uncertain without derivatives.
fn point_stability(map: &GaitFamily, p: &crate::bifurcation::FamilyPoint<GaitInfo>) -> Stability {
    let max = p.max_multiplier();
    if !p.has_derivatives() || !max.is_finite() {
        return Stability::Uncertain;
    }
    if (max - 1.0).abs() > STABILITY_BAND {
        return Stability::judge(max, 0.0);
    }
    Stability::judge(max, map.jacobian_error(&p.x, p.param, &p.jacobian))
}

/// What the walk from the last gait does just past an end where the map failed ([`Continuation::end_cause`]).
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
        Continuation::new(config, param, &GaitOptions::default()).with_period(map.period());
    Some(continuation.end_cause(
        &GaitPoint {
            value: last.param,
            section: map.section_at(&last.x, last.param),
        },
        *beyond,
    ))
}
