//! The job of `vrw orbit`: the orbit diagram along one parameter (the states the walk visits after a
//! transient), the period-1 branch beside it, `orbit.csv`, `branch.csv`, `orbit.json` and `orbit.png`.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::PathBuf;

use serde::Serialize;

use super::sweep::swept_row;
use crate::fmt::short;
use crate::gait::{Gait, GaitOptions, Stability};
use crate::output;
use crate::output::orbit_plot::{write_orbit_figure, BranchPoint, OrbitFigure, OrbitPanel};
use crate::params::Config;
use crate::study::orbit::{
    orbit_diagram_measured, orbit_part, OrbitColumn, OrbitPart, OrbitSpec, WalkStatus,
};
use crate::study::parallelism::{PhaseWork, TaskGraph, WithParallelism};
use crate::walk::{SectionState, StepReport};

use super::{axis_label, check_interrupted, in_run, prepared, AppError};
use crate::output::manifest::RunDir;
use crate::output::{write_branch_csv, write_orbit_csv};

/// What `vrw orbit` runs.
#[derive(Debug, Clone)]
pub struct OrbitJob {
    /// Parameters and solver options (the swept key is overridden value by value).
    pub config: Config,
    /// The parameter, its values, the transient and the recorded steps.
    pub spec: OrbitSpec,
    /// Where the first walk starts (`None`: [`crate::reference::default_initial`]).
    pub initial: Option<SectionState>,
    /// Draw the period-1 branch (a sweep with continuation over the same values).
    pub branch: bool,
    /// The DLS indicator the diagram's second panel draws (one of [`ORBIT_QUANTITIES`]).
    pub plot: String,
    /// Where `orbit.csv`, `branch.csv`, `orbit.json` and `orbit.png` go.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir` (its files are removed and listed in the manifest);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    pub overwrite: bool,
}

/// The DLS indicators the orbit diagram's second panel can draw (`vrw orbit --plot`).
pub const ORBIT_QUANTITIES: [&str; 3] = ["lambda_I4", "lambda_2_plus", "lambda_4_plus"];

/// The kinds of walk failure that are no failure of the walk: it goes on, but its touchdown is not on the
/// Poincare section the diagram records (`WalkError::leaves_section`).
const LEAVES_SECTION: [&str; 2] = ["off_section", "leg_swings_at_section"];

impl OrbitJob {
    /// Checks the settings that are not model parameters or the spec's (`plot`).
    fn validate(&self) -> Result<(), AppError> {
        if ORBIT_QUANTITIES.contains(&self.plot.as_str()) {
            return Ok(());
        }
        Err(AppError::InvalidOption {
            option: "plot",
            reason: format!(
                "unknown quantity {:?}: expected one of {}",
                crate::fmt::clip(&self.plot),
                ORBIT_QUANTITIES.join(", ")
            ),
        })
    }
}

/// `orbit.json`.
#[derive(Debug, Clone, Serialize)]
pub struct OrbitSummary {
    /// Version of vrw that produced the file.
    pub vrw_version: &'static str,
    /// Parameters and solver options.
    pub config: Config,
    /// What was computed.
    pub spec: OrbitSpec,
    /// Number of values whose walk settled on a period `k` (key `k`), did not settle (`none`) or failed
    /// (the failure kind).
    pub outcomes: BTreeMap<String, usize>,
    /// Values with a period-1 gait on the branch, and how many of them are stable.
    pub branch_gaits: [usize; 2],
    /// The files written.
    pub files: Vec<String>,
    /// Wall-clock seconds of the diagram and of the branch (printed, not written).
    #[serde(skip)]
    pub seconds: [f64; 2],
    /// The work and span of the diagram's walks and of the branch's gaits ([`crate::study::parallelism`]);
    /// written to `orbit.json` (after these fields) by [`run_orbit`], in steps walked.
    #[serde(skip)]
    pub parallelism: Vec<PhaseWork>,
}

impl OrbitSummary {
    /// `orbit.json`: the summary with its phases' work and span.
    pub fn with_parallelism(&self) -> WithParallelism<'_, OrbitSummary> {
        WithParallelism {
            summary: self,
            parallelism: &self.parallelism,
        }
    }
}

/// Run `vrw orbit`. `progress` is called after every value of the diagram.
pub fn run_orbit(
    job: &OrbitJob,
    progress: &(dyn Fn(&OrbitColumn) + Sync),
) -> Result<OrbitSummary, AppError> {
    let (_, initial) = prepared(&job.config, job.initial)?;
    job.spec.validate(&job.config)?;
    job.validate()?;
    in_run(&job.out_dir, job.overwrite, "orbit", |run| {
        orbit_into(job, &initial, run, progress).map(|s| (s, None))
    })
}

/// The period-1 branch beside the diagram: each value and its period-1 gait, if there is one.
pub type Branch = Vec<(f64, Option<Gait>)>;

/// The work of [`run_orbit`] without writing anything: the summary (`orbit.json`'s fields, no files), the
/// diagram's columns (`orbit.csv`'s rows) and the period-1 branch (`branch.csv`'s; empty without
/// `job.branch`). The Python front's `vrw.orbit`.
pub fn compute_orbit(
    job: &OrbitJob,
    progress: &(dyn Fn(&OrbitColumn) + Sync),
) -> Result<(OrbitSummary, Vec<OrbitColumn>, Branch), AppError> {
    let (_, initial) = prepared(&job.config, job.initial)?;
    job.spec.validate(&job.config)?;
    job.validate()?;
    let clock = std::time::Instant::now();
    let (columns, walks) = orbit_diagram_measured(&job.config, &job.spec, &initial, progress)?;
    let orbit_seconds = clock.elapsed().as_secs_f64();
    let total = job.spec.range.points;
    check_interrupted(columns.len(), total, "the orbit diagram")?;
    let clock = std::time::Instant::now();
    let (branch, gaits) = period_one_branch(job, &initial)?;
    if job.branch {
        check_interrupted(branch.len(), total, "the branch")?;
    }
    let seconds = [orbit_seconds, clock.elapsed().as_secs_f64()];
    let mut summary = orbit_summary(job, &columns, &branch, Vec::new(), seconds);
    summary.parallelism = orbit_parallelism(job, &walks, &gaits);
    Ok((summary, columns, branch))
}

/// A part of `vrw orbit` computed apart (a study spread over processes: `vrw.grid.orbit_grid`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OrbitJobPart {
    /// A part of the diagram ([`OrbitPart`]).
    Diagram(OrbitPart),
    /// The period-1 branch beside it (empty without `job.branch`).
    Branch,
}

/// A part's summary, its columns, the states their walks ended in, and the branch (see
/// [`compute_orbit_part`]).
pub type OrbitPartResult = (
    OrbitSummary,
    Vec<OrbitColumn>,
    Vec<Option<SectionState>>,
    Branch,
);

/// The columns of one part of [`compute_orbit`]'s diagram and the states their walks ended in (`None` where a
/// walk failed), or its branch: each exactly as the whole job computes it, with the summary of that part
/// (`outcomes` counting its columns, `branch_gaits` its branch).
pub fn compute_orbit_part(
    job: &OrbitJob,
    part: OrbitJobPart,
    progress: &(dyn Fn(&OrbitColumn) + Sync),
) -> Result<OrbitPartResult, AppError> {
    let (_, initial) = prepared(&job.config, job.initial)?;
    job.spec.validate(&job.config)?;
    job.validate()?;
    let total = job.spec.range.points;
    let (columns, ends, branch) = match part {
        OrbitJobPart::Diagram(p) => {
            let walked = orbit_part(&job.config, &job.spec, &initial, p, progress)?;
            check_interrupted(walked.len(), total, "the orbit diagram")?;
            let (columns, ends) = walked.into_iter().unzip();
            (columns, ends, Vec::new())
        }
        OrbitJobPart::Branch => {
            let (branch, _) = period_one_branch(job, &initial)?;
            check_interrupted(branch.len(), total, "the branch")?;
            (Vec::new(), Vec::new(), branch)
        }
    };
    let summary = orbit_summary(job, &columns, &branch, Vec::new(), [0.0; 2]);
    Ok((summary, columns, ends, branch))
}

/// The period-1 branch over the diagram's values (a sweep with continuation), with `job.branch`; else empty.
/// With the task graph of its gaits.
fn period_one_branch(
    job: &OrbitJob,
    initial: &SectionState,
) -> Result<(Branch, TaskGraph), AppError> {
    if !job.branch {
        return Ok((Vec::new(), TaskGraph::new()));
    }
    let range = &job.spec.range;
    range.validate(&job.config)?;
    let options = GaitOptions::default();
    let (points, graph) = swept_row(
        &job.config,
        &range.param,
        &range.values(),
        (initial, &options),
        &|_| {},
    )?;
    let branch = points
        .into_iter()
        .map(|p| (p.value, p.gait.filter(|g| g.period_k == 1)))
        .collect();
    Ok((branch, graph))
}

/// The phases of an orbit diagram: its walks, and the branch's gaits with `job.branch`.
fn orbit_parallelism(job: &OrbitJob, walks: &TaskGraph, gaits: &TaskGraph) -> Vec<PhaseWork> {
    let mut phases = vec![PhaseWork::of("walks", walks)];
    if job.branch {
        phases.push(PhaseWork::of("branch", gaits));
    }
    phases
}

/// `orbit.json`'s fields: how each value's walk ended, and the branch's gaits.
fn orbit_summary(
    job: &OrbitJob,
    columns: &[OrbitColumn],
    branch: &[(f64, Option<Gait>)],
    files: Vec<String>,
    seconds: [f64; 2],
) -> OrbitSummary {
    let mut outcomes = BTreeMap::new();
    for c in columns {
        let key = match (c.status, c.period_k) {
            (WalkStatus::Walking, Some(k)) => format!("period_{k}"),
            (WalkStatus::Walking, None) => "not_settled".to_string(),
            (failed, _) => failed.to_string(),
        };
        *outcomes.entry(key).or_insert(0) += 1;
    }
    let gaits = branch.iter().filter_map(|(_, g)| g.as_ref());
    let branch_gaits = [
        gaits.clone().count(),
        gaits.filter(|g| g.stability == Stability::Stable).count(),
    ];
    OrbitSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: job.config.clone(),
        spec: job.spec.clone(),
        outcomes,
        branch_gaits,
        files,
        seconds,
        parallelism: Vec::new(),
    }
}

/// The work of [`run_orbit`] in its run directory.
fn orbit_into(
    job: &OrbitJob,
    initial: &SectionState,
    run: &mut RunDir,
    progress: &(dyn Fn(&OrbitColumn) + Sync),
) -> Result<OrbitSummary, AppError> {
    let clock = std::time::Instant::now();
    let (columns, walks) = orbit_diagram_measured(&job.config, &job.spec, initial, progress)?;
    let orbit_seconds = clock.elapsed().as_secs_f64();
    let param = &job.spec.range.param;
    let mut files = vec!["orbit.csv".to_string()];
    let friction = crate::output::friction_columns(&job.config, &[param]);
    write_orbit_csv(&run.path("orbit.csv"), param, friction, &columns)?;
    run.add("orbit.csv");
    let total = job.spec.range.points;
    check_interrupted(columns.len(), total, "orbit.csv")?;
    let clock = std::time::Instant::now();
    let (branch, gaits) = period_one_branch(job, initial)?;
    let branch_seconds = clock.elapsed().as_secs_f64();
    if job.branch {
        write_branch_csv(&run.path("branch.csv"), param, friction, &branch)?;
        files.push("branch.csv".to_string());
        run.add("branch.csv");
        check_interrupted(branch.len(), total, "branch.csv (and orbit.csv, complete)")?;
    }
    let figure = orbit_figure(job, &columns, &branch);
    match write_orbit_figure(&figure, &run.path("orbit.png")) {
        Ok(()) => {
            files.push("orbit.png".to_string());
            run.add("orbit.png");
        }
        Err(crate::output::style::PlotError::Empty(_)) => {}
        Err(e) => return Err(e.into()),
    }
    files.push("orbit.json".to_string());
    let mut summary = orbit_summary(
        job,
        &columns,
        &branch,
        files,
        [orbit_seconds, branch_seconds],
    );
    summary.parallelism = orbit_parallelism(job, &walks, &gaits);
    output::write_json(&run.path("orbit.json"), &summary.with_parallelism())?;
    run.add("orbit.json");
    Ok(summary)
}

/// The orbit diagram's figure: its two panels (`dtheta/dt` on the section and the DLS indicator `job.plot`,
/// `lambda_I4` by default) with the branch, the shaded failures and the title.
fn orbit_figure(
    job: &OrbitJob,
    columns: &[OrbitColumn],
    branch: &[(f64, Option<Gait>)],
) -> OrbitFigure {
    let range = &job.spec.range;
    OrbitFigure {
        failed: failed_stretches(job, columns),
        title: orbit_title(job),
        param_label: axis_label(&range.param),
        x: range.from.min(range.to)..range.from.max(range.to),
        panels: panel_quantities(&job.plot)
            .iter()
            .map(|q| orbit_panel(q, columns, branch))
            .collect(),
    }
}

/// What one panel of the orbit diagram draws: its axis label and the quantity of a step and of a gait.
struct PanelQuantity {
    /// The y axis description with unit.
    y_label: &'static str,
    /// The quantity of a recorded step.
    of_step: fn(&StepReport) -> f64,
    /// The same quantity of a gait of the branch.
    of_gait: fn(&Gait) -> f64,
}

/// The quantities of the two panels: `dtheta/dt` before touchdown, then the DLS indicator `plot`.
fn panel_quantities(plot: &str) -> [PanelQuantity; 2] {
    let indicator = match plot {
        "lambda_2_plus" => PanelQuantity {
            y_label: "λ₂⁺ [N]",
            of_step: |r| r.indicators.lambda_2_plus,
            of_gait: |g| g.lambda_2_plus,
        },
        "lambda_4_plus" => PanelQuantity {
            y_label: "λ₄⁺ [N]",
            of_step: |r| r.indicators.lambda_4_plus,
            of_gait: |g| g.lambda_4_plus,
        },
        _ => PanelQuantity {
            y_label: "λI4 [N s]",
            of_step: |r| r.indicators.lambda_i4,
            of_gait: |g| g.lambda_i4,
        },
    };
    [
        PanelQuantity {
            y_label: "dθ/dt before touchdown [rad/s]",
            of_step: |r| r.section.theta_dot,
            of_gait: |g| g.section.theta_dot,
        },
        indicator,
    ]
}

/// The stretches of the parameter where the walk fails: half a spacing on either side of each failed value,
/// with a label per failure kind.
fn failed_stretches(job: &OrbitJob, columns: &[OrbitColumn]) -> Vec<(Range<f64>, String)> {
    let range = &job.spec.range;
    let half = 0.5 * (range.to - range.from).abs() / (range.points.max(2) - 1) as f64;
    columns
        .iter()
        .filter(|c| c.status.failed())
        .map(|c| {
            let words = c.status.to_string().replace('_', " ");
            let label = match c.status {
                WalkStatus::Failed(kind) if LEAVES_SECTION.contains(&kind) => {
                    format!("walk leaves the section: {words}")
                }
                _ => format!("walk fails: {words}"),
            };
            ((c.value - half)..(c.value + half), label)
        })
        .collect()
}

/// The orbit diagram's title: the steps, the transient, the fixed parameters and the settings that differ
/// from the defaults.
fn orbit_title(job: &OrbitJob) -> String {
    let p = &job.config.params;
    let range = &job.spec.range;
    format!(
        "Orbit diagram: {} steps after a transient of {}, {}impact {}",
        job.spec.steps,
        job.spec.transient,
        [
            ("viscosity", format!("c = {} N s/m, ", short(p.viscosity))),
            ("stiffness", format!("k = {} N/m, ", short(p.stiffness))),
            ("slope", format!("slope φ = {} rad, ", p.slope)),
        ]
        .into_iter()
        .filter(|(key, _)| *key != range.param)
        .map(|(_, fixed)| fixed)
        .collect::<String>(),
        p.impact
    ) + &super::settings_note(
        &job.config,
        &[&range.param, "viscosity", "stiffness", "slope", "impact"],
    )
}

/// One panel of the orbit diagram: the quantity `q` of every recorded step, and of the branch's gaits with
/// their stability.
fn orbit_panel(
    q: &PanelQuantity,
    columns: &[OrbitColumn],
    branch: &[(f64, Option<Gait>)],
) -> OrbitPanel {
    let (pick, of_gait) = (q.of_step, q.of_gait);
    OrbitPanel {
        y_label: q.y_label.to_string(),
        points: columns
            .iter()
            .flat_map(|c| c.returns.iter().map(move |r| (c.value, pick(r))))
            .collect(),
        branch: branch
            .iter()
            .map(|(v, g)| BranchPoint {
                param: *v,
                value: g.as_ref().map_or(f64::NAN, of_gait),
                stable: g.as_ref().and_then(|g| match g.stability {
                    Stability::Stable => Some(true),
                    Stability::Unstable => Some(false),
                    Stability::Uncertain => None,
                }),
            })
            .collect(),
    }
}
