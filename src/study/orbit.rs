//! The orbit diagram (docs/model.md section 6): along one parameter, the section states and DLS indicators the walk
//! visits once its transient has died out.
//!
//! At each parameter value the wheel walks `transient` steps, then `steps` more whose section states and step
//! reports are kept (the points of the diagram). Each value starts from where the walk at the value it continues
//! ended, on the `grid` runner's schedule (every `COARSE_STRIDE`-th value in order,
//! then the values between in parallel), so that the diagram follows an attractor as the parameter changes
//! instead of jumping between coexisting ones. The first value, and a value after a walk that failed, start
//! from the job's initial state with `FRESH_TRANSIENT_FACTOR` times the transient.
//!
//! The period of the recorded returns ([`crate::gait::periodicity::least_period`]) is reported per value: a period-1
//! gait shows as one point, a period-k gait as `k`, anything else as a cloud.

use serde::Serialize;

use super::grid::{coarse_pass, fill, run_rows_measured, Cell, Evaluated, COARSE_STRIDE};
use super::parallelism::TaskGraph;
use super::sweep::{RangeNames, SweepSpec};
use crate::family::Parameter;
use crate::gait::periodicity::{least_period, MAX_PERIOD};
use crate::params::{Config, ConfigError};
use crate::walk::{SectionState, StepReport, Walker};

/// A value that does not continue another walks this many times the transient.
pub(crate) const FRESH_TRANSIENT_FACTOR: usize = 4;

/// The recorded returns repeat with period `k` to within this (largest coordinate difference) for a value to
/// be reported as period `k`.
pub(crate) const PERIOD_TOL: f64 = 1e-6;

/// The largest number of recorded steps per value.
pub const MAX_ORBIT_STEPS: usize = 100_000;

/// The most values an orbit diagram takes (`--points`).
pub const MAX_ORBIT_VALUES: usize = 10_000;

/// The most steps an orbit diagram walks in all, `points x (transient + steps)` (about a millisecond each):
/// the recorded returns are held in memory, and this is already hours of computing.
pub const MAX_ORBIT_WALKED_STEPS: usize = 10_000_000;

/// `vrw orbit`'s range: `--from`, `--to`, `--points` (at most [`MAX_ORBIT_VALUES`]).
pub const ORBIT_RANGE: RangeNames = RangeNames {
    command: "orbit",
    from: "from",
    to: "to",
    points: "points",
    max_points: MAX_ORBIT_VALUES,
};

/// What to compute.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrbitSpec {
    /// The parameter and its values (as for a sweep).
    pub range: SweepSpec,
    /// Steps walked at each value before recording (default 64).
    pub transient: usize,
    /// Steps recorded at each value (default 64).
    pub steps: usize,
}

impl OrbitSpec {
    /// Check the range against `config` (as a sweep's, with [`ORBIT_RANGE`]) and the step counts (each at
    /// most [`MAX_ORBIT_STEPS`], all values together at most [`MAX_ORBIT_WALKED_STEPS`]).
    pub fn validate(&self, config: &Config) -> Result<(), ConfigError> {
        self.range.validate_as(config, &ORBIT_RANGE)?;
        let walked = self
            .range
            .points
            .saturating_mul(self.transient.saturating_add(self.steps));
        if walked > MAX_ORBIT_WALKED_STEPS {
            return Err(ConfigError::InvalidValue {
                key: "points".to_string(),
                value: format!(
                    "{} (with `transient` {} `steps` {})",
                    self.range.points, self.transient, self.steps
                ),
                reason: format!(
                    "points x (transient + steps) = {walked} steps to walk; orbit walks at most \
                     {MAX_ORBIT_WALKED_STEPS}"
                ),
            });
        }
        if !(1..=MAX_ORBIT_STEPS).contains(&self.steps) {
            return Err(ConfigError::InvalidValue {
                key: "steps".to_string(),
                value: self.steps.to_string(),
                reason: format!("the recorded steps must be between 1 and {MAX_ORBIT_STEPS}"),
            });
        }
        if self.transient > MAX_ORBIT_STEPS {
            return Err(ConfigError::InvalidValue {
                key: "transient".to_string(),
                value: self.transient.to_string(),
                reason: format!("the transient must be at most {MAX_ORBIT_STEPS} steps"),
            });
        }
        Ok(())
    }
}

/// How the walk at one value of an orbit diagram went. A value until it is written: its text (`walking`,
/// `rolled_back`, `invalid_parameter`, ...) is the `status` of `orbit.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WalkStatus {
    /// Every step was walked.
    Walking,
    /// The walk failed: its kind ([`crate::walk::WalkError::kind`]: `rolled_back`, `fell`, ...).
    Failed(&'static str),
    /// The value leaves the parameter's valid domain.
    InvalidParameter,
}

impl WalkStatus {
    /// Did the walk fail (or never start)?
    pub fn failed(self) -> bool {
        self != WalkStatus::Walking
    }
}

impl std::fmt::Display for WalkStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            WalkStatus::Walking => "walking",
            WalkStatus::Failed(kind) => kind,
            WalkStatus::InvalidParameter => "invalid_parameter",
        })
    }
}

/// The walk at one parameter value.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrbitColumn {
    /// The parameter value.
    pub value: f64,
    /// How the walk went.
    #[serde(serialize_with = "crate::fmt::as_text")]
    pub status: WalkStatus,
    /// The failure in words.
    pub message: Option<String>,
    /// The recorded steps (their section states, indicators and branches), in order; fewer than asked if the
    /// walk failed while recording.
    pub returns: Vec<StepReport>,
    /// The least period of the recorded returns (to `PERIOD_TOL`), up to [`MAX_PERIOD`]; `None` if they do
    /// not repeat (or the walk failed).
    pub period_k: Option<usize>,
    /// The value whose end state this walk started from (`None`: the initial state).
    pub continued_from: Option<f64>,
}

/// Walk at `value` from `start`: `transient` steps, then `steps` recorded. Returns the column and the state
/// the walk ended in (`None` if it failed).
fn walk_column(
    parameter: Parameter,
    value: f64,
    start: &SectionState,
    transient: usize,
    steps: usize,
) -> (OrbitColumn, Option<SectionState>) {
    let mut column = OrbitColumn {
        value,
        status: WalkStatus::Walking,
        message: None,
        returns: Vec::with_capacity(steps),
        period_k: None,
        continued_from: None,
    };
    let at = match parameter.at(value) {
        Ok(at) => at,
        Err(e) => {
            column.status = WalkStatus::InvalidParameter;
            column.message = Some(e.to_string());
            return (column, None);
        }
    };
    let walked = Walker::new(&at.model, &at.config.solver, start).and_then(|mut walker| {
        for _ in 0..transient {
            walker.step(None)?;
        }
        for _ in 0..steps {
            column.returns.push(walker.step(None)?);
        }
        // The next value continues from a touchdown on the section (one where the stance tip is at rest).
        for _ in 0..MAX_PERIOD {
            match walker.section() {
                Err(e) if e.leaves_section() => {
                    walker.step(None)?;
                }
                other => return other,
            }
        }
        walker.section()
    });
    match walked {
        Ok(end) => {
            let returns: Vec<SectionState> = column.returns.iter().map(|r| r.section).collect();
            column.period_k = least_period(&returns, MAX_PERIOD, PERIOD_TOL);
            (column, Some(end))
        }
        Err(e) => {
            column.status = WalkStatus::Failed(e.kind());
            column.message = Some(e.to_string());
            (column, None)
        }
    }
}

/// The orbit diagram of `config` along `spec` from `initial` (see the module documentation). Deterministic for
/// any number of threads.
pub fn orbit_diagram(
    config: &Config,
    spec: &OrbitSpec,
    initial: &SectionState,
    progress: &(dyn Fn(&OrbitColumn) + Sync),
) -> Result<Vec<OrbitColumn>, ConfigError> {
    orbit_diagram_measured(config, spec, initial, progress).map(|d| d.0)
}

/// [`orbit_diagram`] with its task graph: one task per value, on the grid runner's schedule
/// ([`super::parallelism`]).
pub fn orbit_diagram_measured(
    config: &Config,
    spec: &OrbitSpec,
    initial: &SectionState,
    progress: &(dyn Fn(&OrbitColumn) + Sync),
) -> Result<(Vec<OrbitColumn>, TaskGraph), ConfigError> {
    spec.validate(config)?;
    let values = spec.range.values();
    let parameter = Parameter::named(config, &spec.range.param)?;
    let eval = column_eval(parameter, spec, initial, &values, progress);
    let mut run = run_rows_measured(0..1, 1, values.len(), eval);
    Ok((run.rows.pop().unwrap_or_default(), run.graph))
}

/// A part of an orbit diagram computed apart (a study spread over processes): the diagram's coarse pass, or
/// the values between two of its points (the grid runner's schedule, see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OrbitPart {
    /// Every `COARSE_STRIDE`-th value in order, each continuing the one before.
    Coarse,
    /// The values after the `k`-th coarse value up to the next, continuing from `left`, where the walk at
    /// the `k`-th coarse value ended (`None` if it failed).
    Fill {
        /// Which interval.
        k: usize,
        /// The end state of the coarse value's walk.
        left: Option<SectionState>,
    },
}

/// The columns of `part` of [`orbit_diagram`], each exactly as the whole diagram has it, with the state each
/// walk ended in (`None` if it failed: what the coarse pass hands to the fills). The diagram is the coarse
/// columns with every interval's fill after its coarse column.
pub fn orbit_part(
    config: &Config,
    spec: &OrbitSpec,
    initial: &SectionState,
    part: OrbitPart,
    progress: &(dyn Fn(&OrbitColumn) + Sync),
) -> Result<Vec<(OrbitColumn, Option<SectionState>)>, ConfigError> {
    spec.validate(config)?;
    let values = spec.range.values();
    let parameter = Parameter::named(config, &spec.range.param)?;
    let eval = column_eval(parameter, spec, initial, &values, progress);
    // The end state as the column's point too, so that a fill hands it back.
    let with_end = |cell, from: Option<(usize, &SectionState)>| {
        let e = eval(cell, from);
        Evaluated {
            point: (e.point, e.carry),
            carry: e.carry,
        }
    };
    match part {
        OrbitPart::Coarse => Ok(coarse_pass(0, values.len(), &with_end).0),
        OrbitPart::Fill { k, left } => {
            let intervals = values.len().div_ceil(COARSE_STRIDE);
            if k >= intervals {
                return Err(ConfigError::InvalidValue {
                    key: "orbit part".to_string(),
                    value: k.to_string(),
                    reason: format!(
                        "the diagram's {} values have {intervals} intervals",
                        values.len()
                    ),
                });
            }
            Ok(fill(0, values.len(), k, left.as_ref(), &with_end))
        }
    }
}

/// The walk at one value of the diagram, from where the value it continues ended (else from `initial` with the
/// longer transient): the grid runner's evaluation.
fn column_eval<'a>(
    parameter: Parameter<'a>,
    spec: &'a OrbitSpec,
    initial: &'a SectionState,
    values: &'a [f64],
    progress: &'a (dyn Fn(&OrbitColumn) + Sync),
) -> impl Fn(Cell, Option<(usize, &SectionState)>) -> Evaluated<OrbitColumn, SectionState> + Sync + 'a
{
    let fresh = spec.transient.saturating_mul(FRESH_TRANSIENT_FACTOR);
    move |cell, from| {
        let value = values[cell.col];
        let (start, transient, continued_from) = match from {
            Some((j, s)) => (*s, spec.transient, Some(values[j])),
            None => (*initial, fresh, None),
        };
        let (mut column, end) = walk_column(parameter, value, &start, transient, spec.steps);
        column.continued_from = continued_from;
        progress(&column);
        Evaluated {
            point: column,
            carry: end,
        }
    }
}
