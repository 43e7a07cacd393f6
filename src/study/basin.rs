//! The basin of attraction of a gait on a slice of the Poincare section (docs/model.md section 6).
//!
//! Two of the section coordinates `(L2, thetadot, L2dot)` span a grid; the third is held at the gait's value.
//! From every grid point the wheel walks until one of these happens, which is the point's outcome:
//!
//! - `gait`: a section state comes within `tolerance` of one of the gait's section states (largest coordinate
//!   difference; for a period-k gait any of its `k` states);
//! - `other`: the returns repeat with a period `k <= MAX_PERIOD` to `SETTLED_TOL` away from the gait: the
//!   walk settled on another attractor (its period is kept);
//! - the walk fails: the failure kind (`rolled_back`, `fell`, `stalled`, `chatter`, `rear_leg_in_contact`, ...);
//! - `invalid_start`: the point is not a section state (`L2` outside `(0, L0]`, `thetadot <= 0`, ...);
//! - `undecided`: none of these within `max_steps` steps.
//!
//! The grid runs on the `grid` runner, one row per value of the second coordinate (every start is
//! independent, so nothing is handed along a row).

use std::ops::Range;

use serde::Serialize;

use super::grid::run_independent;
use super::parallelism::TaskGraph;
use crate::dynamics::Model;
use crate::gait::limit_cycle::Gait;
use crate::gait::periodicity::{least_period, MAX_PERIOD};
use crate::params::SolverOptions;
use crate::walk::{SectionState, Walker};

/// Returns that repeat to within this (largest coordinate difference over the last returns) have settled.
pub(crate) const SETTLED_TOL: f64 = 1e-7;

/// A section coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Coordinate {
    /// `L2` \[m\].
    #[serde(rename = "L2")]
    L2,
    /// `dtheta/dt` \[rad/s\].
    #[serde(rename = "thetadot")]
    ThetaDot,
    /// `dL2/dt` \[m/s\].
    #[serde(rename = "L2dot")]
    L2Dot,
}

impl Coordinate {
    /// All three, in the section's order.
    pub(crate) const ALL: [Coordinate; 3] =
        [Coordinate::L2, Coordinate::ThetaDot, Coordinate::L2Dot];

    /// Index into `SectionState::coordinate` (`L2`, `thetadot`, `L2dot`).
    pub(crate) fn index(self) -> usize {
        match self {
            Coordinate::L2 => 0,
            Coordinate::ThetaDot => 1,
            Coordinate::L2Dot => 2,
        }
    }

    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Coordinate::L2 => "L2",
            Coordinate::ThetaDot => "thetadot",
            Coordinate::L2Dot => "L2dot",
        }
    }

    /// Axis label with its unit.
    pub(crate) fn label(self) -> &'static str {
        match self {
            Coordinate::L2 => "L2 [m]",
            Coordinate::ThetaDot => "dθ/dt [rad/s]",
            Coordinate::L2Dot => "dL2/dt [m/s]",
        }
    }
}

impl std::str::FromStr for Coordinate {
    type Err = String;
    fn from_str(s: &str) -> Result<Coordinate, String> {
        Coordinate::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| format!("unknown section coordinate '{s}' (use L2, thetadot or L2dot)"))
    }
}

/// One axis of the slice.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Axis {
    /// The coordinate.
    pub coordinate: Coordinate,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values, ends included (at least 2).
    pub points: usize,
}

impl Axis {
    /// The `i`-th value.
    pub(crate) fn value(&self, i: usize) -> f64 {
        self.from + (self.to - self.from) * (i as f64 / (self.points - 1) as f64)
    }
}

/// The slice and the walking rules.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BasinSpec {
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis (one grid row per value).
    pub y: Axis,
    /// The state the slice passes through: its third coordinate is held (the gait's fixed point).
    pub through: SectionState,
    /// Steps walked at most from each start.
    pub max_steps: usize,
    /// A return this close to a gait state (largest coordinate difference) has reached the gait.
    pub tolerance: f64,
}

/// Where the walk from one start went. A value until it is written: its text (`gait`, `other`, `undecided`,
/// `invalid_start` or the walk's failure kind) is the `outcome` of `basin.csv` and the figure's legend.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutcomeKind {
    /// It reached the gait.
    Gait,
    /// It settled on another attractor (its period in [`Outcome::period_k`]).
    Other,
    /// Neither within the steps walked.
    Undecided,
    /// The start is not a valid section state.
    InvalidStart,
    /// The walk failed: its kind ([`crate::walk::WalkError::kind`]: `rolled_back`, `fell`, ...).
    Failed(&'static str),
}

impl std::fmt::Display for OutcomeKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            OutcomeKind::Gait => "gait",
            OutcomeKind::Other => "other",
            OutcomeKind::Undecided => "undecided",
            OutcomeKind::InvalidStart => "invalid_start",
            OutcomeKind::Failed(kind) => kind,
        })
    }
}

/// What the walk from one start did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Outcome {
    /// Where it went.
    #[serde(serialize_with = "crate::fmt::as_text")]
    pub kind: OutcomeKind,
    /// Steps walked until the outcome was known.
    pub steps: usize,
    /// For `other`, the period of the attractor reached.
    pub period_k: Option<usize>,
    /// The last section state reached (`None` if none was).
    pub end: Option<SectionState>,
}

impl Outcome {
    fn new(
        kind: OutcomeKind,
        steps: usize,
        period_k: Option<usize>,
        end: Option<SectionState>,
    ) -> Outcome {
        Outcome {
            kind,
            steps,
            period_k,
            end,
        }
    }
}

/// One grid point of the basin.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BasinPoint {
    /// Grid column (x index).
    pub ix: usize,
    /// Grid row (y index).
    pub iy: usize,
    /// The start.
    pub start: SectionState,
    /// What the walk from it did.
    pub outcome: Outcome,
}

/// Walk from `start` until its outcome is known (see the module documentation).
pub(crate) fn classify(
    model: &Model,
    opts: &SolverOptions,
    gait: &Gait,
    start: &SectionState,
    max_steps: usize,
    tolerance: f64,
) -> Outcome {
    let near_gait = |s: &SectionState| {
        gait.cycle
            .iter()
            .map(|r| &r.section)
            .chain(std::iter::once(&gait.section))
            .any(|g| g.distance(s) < tolerance)
    };
    if start.validate(model).is_err() {
        return Outcome::new(OutcomeKind::InvalidStart, 0, None, None);
    }
    if near_gait(start) {
        return Outcome::new(OutcomeKind::Gait, 0, None, Some(*start));
    }
    let mut walker = match Walker::new(model, opts, start) {
        Ok(w) => w,
        Err(e) => return Outcome::new(OutcomeKind::Failed(e.kind()), 0, None, None),
    };
    let mut returns: Vec<SectionState> = Vec::with_capacity(max_steps);
    for step in 1..=max_steps {
        // The touchdown's coordinates (a touchdown may be off the section inside another attractor's cycle).
        let s = match walker.step(None).map(|_| walker.touchdown_coordinates()) {
            Ok(s) => s,
            Err(e) => {
                return Outcome::new(
                    OutcomeKind::Failed(e.kind()),
                    step,
                    None,
                    returns.last().copied(),
                )
            }
        };
        returns.push(s);
        if near_gait(&s) {
            return Outcome::new(OutcomeKind::Gait, step, None, Some(s));
        }
        if let Some(k) = least_period(&returns, MAX_PERIOD, SETTLED_TOL) {
            return Outcome::new(OutcomeKind::Other, step, Some(k), Some(s));
        }
    }
    Outcome::new(
        OutcomeKind::Undecided,
        max_steps,
        None,
        returns.last().copied(),
    )
}

/// The basin on the slice `spec` of `gait`: one [`BasinPoint`] per grid point, row by row (rows are `y`
/// values). Deterministic for any number of threads.
pub fn basin(
    model: &Model,
    opts: &SolverOptions,
    gait: &Gait,
    spec: &BasinSpec,
    progress: &(dyn Fn(&BasinPoint) + Sync),
) -> Vec<Vec<BasinPoint>> {
    basin_measured(model, opts, gait, spec, 0..spec.y.points, progress).0
}

/// The rows `part` (indices of `y` values, within `0..spec.y.points`) of [`basin`], each point exactly as the
/// whole basin has it (a basin computed in parts, a study spread over processes, is the basin), with the task
/// graph ([`super::parallelism`]): every start is a task of its own, and all of them run in parallel (none
/// continues another).
pub fn basin_measured(
    model: &Model,
    opts: &SolverOptions,
    gait: &Gait,
    spec: &BasinSpec,
    part: Range<usize>,
    progress: &(dyn Fn(&BasinPoint) + Sync),
) -> (Vec<Vec<BasinPoint>>, TaskGraph) {
    let run = run_independent(part, spec.x.points, |cell| {
        // The other coordinates (and a slipping tip's `slip`) are the gait's.
        let start = spec
            .through
            .with_coordinate(spec.x.coordinate.index(), spec.x.value(cell.col))
            .with_coordinate(spec.y.coordinate.index(), spec.y.value(cell.row));
        let point = BasinPoint {
            ix: cell.col,
            iy: cell.row,
            start,
            outcome: classify(model, opts, gait, &start, spec.max_steps, spec.tolerance),
        };
        progress(&point);
        point
    });
    (run.rows, run.graph)
}
