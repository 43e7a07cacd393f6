//! The job of `vrw gait`: search the gait (period 1, or period k), write `gait.json` and one period of the
//! walk in the files of `vrw simulate`.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use serde::Serialize;

use crate::dynamics::Model;
use crate::gait::{
    check_jacobian, find_gait_any_period, Gait, GaitOptions, JacobianCheck, StepMap, MAX_PERIOD,
    TOLERANCE_RANGE,
};
use crate::output;
use crate::params::Config;
use crate::reference::default_initial;
use crate::walk::SectionState;

use super::simulate::{simulate_into, SimulateJob, SimulateSummary, DEFAULT_SAMPLE_DT};
use super::{in_run, AppError};
use crate::output::manifest::RunDir;

/// What `vrw gait` runs.
#[derive(Debug, Clone)]
pub struct GaitJob {
    /// Parameters and solver options.
    pub config: Config,
    /// Where the search starts (`None`: [`default_initial`]).
    pub initial: Option<SectionState>,
    /// Search settings (checked by [`GaitOptions::validate`]).
    pub options: GaitOptions,
    /// Where `gait.json` goes, and one period of the gait in the files of `vrw simulate`.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir` (its files are removed and listed in the manifest);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    pub overwrite: bool,
    /// Check the exact `DP` of the gait found against finite differences ([`check_jacobian`]).
    pub check_jacobian: bool,
    /// Stops the search inside a step when set (e.g. by Ctrl-C from Python); the search then ends with the
    /// interruption as its failure.
    pub interrupt: Option<Arc<AtomicBool>>,
}

/// `gait.json`: the parameters, and the gait or why none was found.
#[derive(Debug, Clone, Serialize)]
pub struct GaitSummary {
    /// Version of vrw that produced the file.
    pub vrw_version: &'static str,
    /// Parameters and solver options used.
    pub config: Config,
    /// Search settings.
    pub options: GaitOptions,
    /// Initial section state of the search.
    pub initial: SectionState,
    /// Whether the search found a gait (written `found`), or the failure's kind.
    #[serde(serialize_with = "crate::fmt::as_text")]
    pub status: SearchEnded,
    /// The failure, in words, if any.
    pub message: Option<String>,
    /// The gait, if found (its fields are also flattened into the top level of the JSON).
    #[serde(flatten)]
    pub gait: Option<Gait>,
    /// The exact `DP` against finite differences, if asked for ([`GaitJob::check_jacobian`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jacobian_check: Option<JacobianCheck>,
    /// What makes the gait untrustworthy: every audit value of its steps above its tolerance
    /// ([`StepReport::audit_warnings`](crate::walk::StepReport::audit_warnings)); empty when every law holds.
    pub warnings: Vec<String>,
}

/// How the gait search of `vrw gait` ended. A value until it is written: `gait.json`'s `status` is `found` or
/// the failure's kind (`rolled_back`, `no_convergence`, ...).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchEnded {
    /// A gait was found.
    Found,
    /// No gait: the kind of the failure ([`crate::gait::GaitError::kind`]).
    Failed(&'static str),
}

impl std::fmt::Display for SearchEnded {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SearchEnded::Found => "found",
            SearchEnded::Failed(kind) => kind,
        })
    }
}

/// The smallest Newton tolerance `vrw gait` accepts: the lower end of [`TOLERANCE_RANGE`], which says why.
pub const MIN_GAIT_TOLERANCE: f64 = TOLERANCE_RANGE[0];

/// Run `vrw gait`: search the gait (period 1, or if Newton's method fails there and the walk settles, period
/// `k <= MAX_PERIOD`) and write `gait.json` (also when no gait is found, with the reason), and
/// for a gait found, one period of it as `steps.csv`, `trajectory.csv` and `summary.json`
/// (`write_gait_period`).
///
/// The options and the output directory are checked before the search; an interrupted search
/// ([`AppError::Interrupted`]) writes nothing.
pub fn run_gait(job: &GaitJob) -> Result<GaitSummary, AppError> {
    job.options.validate()?;
    job.config.validate()?;
    crate::output::manifest::check_out_dir(&job.out_dir, "gait", job.overwrite)?;
    let summary = compute_gait(job)?;
    in_run(&job.out_dir, job.overwrite, "gait", |run| {
        output::write_json(&run.path("gait.json"), &summary)?;
        run.add("gait.json");
        if let Some(gait) = &summary.gait {
            let period = write_gait_period(job, gait, run)?;
            if period.status == super::WalkEnded::Interrupted {
                return Err(AppError::Interrupted {
                    during: "while walking the gait's period".to_string(),
                    kept: "gait.json holds the gait (complete); the period's tables hold its complete \
                           steps"
                        .to_string(),
                });
            }
        }
        Ok((summary, None))
    })
}

/// The search of [`run_gait`] without writing anything (`job.out_dir` is not used). A search that finds no
/// gait is a summary with its status and message, not an error.
pub fn compute_gait(job: &GaitJob) -> Result<GaitSummary, AppError> {
    job.options.validate()?;
    job.config.validate()?;
    let model = Model::new(&job.config.params)?;
    let initial = job.initial.unwrap_or_else(|| default_initial(&job.config));
    initial.validate(&model)?;
    let map = StepMap::new(&model, &job.config.solver).with_interrupt(job.interrupt.as_deref());
    let result = find_gait_any_period(&map, &initial, &job.options, MAX_PERIOD);
    let flag = job.interrupt.as_deref();
    let nothing = super::NOTHING_WRITTEN;
    super::check_phase_interrupted(flag, "while searching the gait", nothing)?;
    let jacobian_check = match (&result, job.check_jacobian) {
        (Ok(gait), true) => Some(
            check_jacobian(
                &map.iterated(gait.period_k),
                &gait.section,
                job.options.fd_step,
            )
            .unwrap_or_else(|e| JacobianCheck::failed(e.to_string())),
        ),
        _ => None,
    };
    super::check_phase_interrupted(flag, "while checking the Jacobian", nothing)?;
    let summary = GaitSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: job.config.clone(),
        options: job.options,
        initial,
        status: result
            .as_ref()
            .map_or_else(|e| SearchEnded::Failed(e.kind()), |_| SearchEnded::Found),
        message: result.as_ref().err().map(ToString::to_string),
        warnings: result.as_ref().map_or_else(
            |_| Vec::new(),
            |g| g.cycle.iter().flat_map(|s| s.audit_warnings()).collect(),
        ),
        gait: result.ok(),
        jacobian_check,
    };
    Ok(summary)
}

/// Walk one period (`period_k` steps) from the gait's fixed point, sampled every [`DEFAULT_SAMPLE_DT`], and write it beside
/// `gait.json` in the format of `vrw simulate` (`steps.csv`, `trajectory.csv`, `summary.json`), so that
/// `vrw plot` and `vrw animate` work on a gait directly; the files are added to `run`'s manifest.
pub fn write_gait_period(
    job: &GaitJob,
    gait: &Gait,
    run: &mut RunDir,
) -> Result<SimulateSummary, AppError> {
    let period = SimulateJob {
        config: job.config.clone(),
        initial: Some(gait.section),
        steps: gait.period_k,
        sample_dt: DEFAULT_SAMPLE_DT,
        trajectory: true,
        out_dir: job.out_dir.clone(),
        overwrite: job.overwrite,
        interrupt: None,
    };
    let model = Model::new(&job.config.params)?;
    simulate_into(&period, &model, gait.section, run, &mut |_| {})
}
