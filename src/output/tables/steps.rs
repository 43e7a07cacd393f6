//! `steps.csv`: one row per step of a walk, from a touchdown to the next (section state before it, DLS
//! indicators, branch, step measures, flags, the energy audit and the contact audit), and its writers.

use std::path::Path;

use super::{fixed_names, row, Cell, Column};
use crate::output::{CsvStream, OutputError};
use crate::params::{Params, RearExit};
use crate::walk::StepReport;

use Cell::{Count, Flag, Real, Text};

/// The columns of `steps.csv` (docs/model.md sections 4-5 for the section state and the indicators).
pub const STEPS: [Column<StepReport>; 30] = [
    Column::new("step", "Step number, from 1.", |s| Count(s.step)),
    Column::new(
        "time",
        "Time of the touchdown that starts the step [s].",
        |s| Real(s.time),
    ),
    Column::new(
        "L2",
        "Length of Leg 2 just before the touchdown (section state) [m].",
        |s| Real(s.section.l2),
    ),
    Column::new(
        "thetadot",
        "Angular velocity of the wheel just before the touchdown (section state) [rad/s].",
        |s| Real(s.section.theta_dot),
    ),
    Column::new(
        "L2dot",
        "Rate of change of Leg 2's length just before the touchdown (section state) [m/s].",
        |s| Real(s.section.l2_dot),
    ),
    Column::new(
        "theta",
        "theta at the touchdown, after re-indexing [rad].",
        |s| Real(s.theta),
    ),
    Column::new(
        "lambda_I4",
        "DLS indicator: normal impulse on Leg 2 of the DLS collision [N s].",
        |s| Real(s.indicators.lambda_i4),
    ),
    Column::new(
        "lambda_2_plus",
        "DLS indicator: normal force on Leg 1 just after impact [N] (NaN where undefined).",
        |s| Real(s.indicators.lambda_2_plus),
    ),
    Column::new(
        "lambda_4_plus",
        "DLS indicator: normal force on Leg 2 just after impact [N] (NaN where undefined).",
        |s| Real(s.indicators.lambda_4_plus),
    ),
    Column::new(
        "branch",
        "Branch of the impact procedure taken.",
        |s| Text(s.branch.to_string()),
    ),
    Column::new(
        "dls_duration",
        "Double-limb support: time both tips are on the ground without slipping [s].",
        |s| Real(s.dls_duration),
    ),
    Column::new("period", "Time to the next touchdown [s].", |s| {
        Real(s.period)
    }),
    Column::new(
        "step_length",
        "Distance along the slope between this touchdown's tip and the next one's [m].",
        |s| Real(s.step_length),
    ),
    Column::new("speed", "step_length / period [m/s].", |s| Real(s.speed)),
    Column::new(
        "scuffing",
        "Leg 2's tip came back to the ground during the step.",
        |s| Flag(s.scuffing),
    ),
    Column::new(
        "bounce",
        "Leg 1 left the ground during the step (or at the touchdown itself).",
        |s| Flag(s.bounce),
    ),
    Column::new(
        "events",
        "Number of events (lift-offs, contacts, stopper locks/unlocks) in the step.",
        |s| Count(s.events),
    ),
    Column::new(
        "energy_start",
        "T + V just before the touchdown that starts the step [J].",
        |s| Real(s.energy.start),
    ),
    Column::new(
        "energy_end",
        "T + V just before the next touchdown [J].",
        |s| Real(s.energy.end),
    ),
    Column::new(
        "energy_loss",
        "energy_start - energy_end [J].",
        |s| Real(s.energy.loss),
    ),
    Column::new(
        "damper_loss",
        "Damper dissipation, integral of c (dL1^2 + dL2^2) dt [J].",
        |s| Real(s.energy.damper),
    ),
    Column::new(
        "impact_loss",
        "Kinetic energy lost in the touchdown collision and in ground re-contacts [J].",
        |s| Real(s.energy.impact),
    ),
    Column::new(
        "stopper_loss",
        "Kinetic energy lost when a sliding leg hits its stopper [J].",
        |s| Real(s.energy.stopper),
    ),
    Column::new(
        "energy_residual",
        "energy_loss - (damper_loss + impact_loss + stopper_loss), zero up to the integration error [J].",
        |s| Real(s.energy.residual),
    ),
    Column::new(
        "rear_contact_duration",
        "Time Leg 2's tip touches the ground during the step, sticking or sliding [s].",
        |s| Real(s.rear_contact_duration),
    ),
    Column::new(
        "pull_force",
        "Largest pulling normal force or outward stopper reaction in the step, 0 if none [N].",
        |s| Real(s.contact.pull_force),
    ),
    Column::new(
        "pull_impulse",
        "Largest pulling impulse at any of the step's impacts, 0 if none [N s].",
        |s| Real(s.contact.pull_impulse),
    ),
    Column::new(
        "penetration",
        "Deepest any tip went below the ground during the step, 0 if none [m].",
        |s| Real(s.contact.penetration),
    ),
    Column::new(
        "stopper_overrun",
        "Farthest Leg 1 or Leg 2 went past its stopper during the step, max(L - L0), 0 if none [m].",
        |s| Real(s.contact.stopper_overrun),
    ),
    Column::new(
        "zeno_impulse",
        "Largest outward impulse of a stopper locked at the end of a Zeno sequence of stopper impacts, 0 if none [N s].",
        |s| Real(s.contact.zeno_impulse),
    ),
];

/// Header of `steps.csv` (the names of `STEPS`).
pub const STEPS_HEADER: [&str; 30] = fixed_names(&STEPS, 0);

/// The last column of `steps.csv` of a walk with `rear_exit = "reset"` (only there, so that every other walk's
/// file is as it was before the option existed).
pub(crate) const RESET_COLUMN: Column<StepReport> = Column::new(
    "reset_energy",
    "Energy removed (negative: added) at the touchdown that ends the step by discarding the old rear leg's \
     length and rate, rear_exit = \"reset\": not part of energy_loss [J].",
    |s| Real(s.energy.reset),
);

/// The columns of `steps.csv` of a walk with Coulomb friction (a finite `friction`, docs/model.md section 12),
/// after [`STEPS_HEADER`] (only there, so that every other walk's file is as it was before the option
/// existed).
const FRICTION_COLUMNS: [Column<StepReport>; 5] = [
    Column::new(
        "slip",
        "Slip velocity of Leg 2's tip along the slope (+x, down it) just before the touchdown (the section \
         state's fourth coordinate), 0 where the tip is at rest [m/s].",
        |s| Real(s.section.slip),
    ),
    Column::new(
        "friction_loss",
        "Energy the Coulomb friction force dissipated while tips slipped between impacts [J]; energy_residual \
         subtracts it too.",
        |s| Real(s.energy.friction.unwrap_or(f64::NAN)),
    ),
    Column::new(
        "cone_violation",
        "Largest distance of a sticking contact's force outside the friction cone, (|lambda_t| - mu lambda_n) \
         / sqrt(1 + mu^2), 0 if none [N].",
        |s| Real(s.contact.friction.map_or(f64::NAN, |f| f.cone_violation)),
    ),
    Column::new(
        "cone_violation_impulse",
        "The same for an impulse that stuck through an impact, 0 if none [N s].",
        |s| Real(s.contact.friction.map_or(f64::NAN, |f| f.cone_violation_impulse)),
    ),
    Column::new(
        "slip_power",
        "Largest power lambda_t v_t of the friction force on a slipping tip, 0 if it never did positive work \
         [W].",
        |s| Real(s.contact.friction.map_or(f64::NAN, |f| f.slip_power)),
    ),
];

/// One row of `steps.csv`, in the order of [`STEPS_HEADER`].
pub fn step_row(s: &StepReport) -> Vec<Cell> {
    row(&STEPS, s)
}

/// Which optional columns a walk's `steps.csv` has: the friction audit and work (after [`STEPS_HEADER`]) with
/// a finite `friction`, and `reset_energy` (last) under `rear_exit = "reset"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepsColumns {
    friction: bool,
    reset: bool,
}

impl StepsColumns {
    /// The columns of a walk with `params`.
    pub fn of(params: &Params) -> StepsColumns {
        StepsColumns {
            friction: params.has_friction(),
            reset: params.rear_exit == RearExit::Reset,
        }
    }

    fn optional(self) -> impl Iterator<Item = &'static Column<StepReport>> {
        let friction = FRICTION_COLUMNS.iter().filter(move |_| self.friction);
        friction.chain(std::iter::once(&RESET_COLUMN).filter(move |_| self.reset))
    }
}

/// The header of `steps.csv` with `columns`: [`STEPS_HEADER`], then the optional columns.
pub fn steps_header(columns: StepsColumns) -> Vec<&'static str> {
    let mut header = STEPS_HEADER.to_vec();
    header.extend(columns.optional().map(|c| c.header_name(&[])));
    header
}

/// One row of `steps.csv` with `columns`, in the order of [`steps_header`].
pub fn steps_row(s: &StepReport, columns: StepsColumns) -> Vec<Cell> {
    let mut cells = step_row(s);
    cells.extend(columns.optional().map(|c| (c.get)(s)));
    cells
}

/// `steps.csv` written step by step (`CsvStream`).
pub struct StepsCsv(CsvStream, StepsColumns);

impl StepsCsv {
    /// Create `path` with the header [`steps_header`] of `columns`.
    pub(crate) fn create(path: &Path, columns: StepsColumns) -> Result<StepsCsv, OutputError> {
        CsvStream::create(path, steps_header(columns)).map(|w| StepsCsv(w, columns))
    }

    /// Write the row of one step and flush it.
    pub(crate) fn write(&mut self, step: &StepReport) -> Result<(), OutputError> {
        self.0
            .write(steps_row(step, self.1).iter().map(Cell::to_csv))
    }
}

/// Write the per-step table `steps.csv` of a walk with `columns`: one row per touchdown (section state before
/// it, DLS indicators, branch, step measures, flags, the energy audit, and the contact audit).
pub fn write_steps_csv(
    path: &Path,
    steps: &[StepReport],
    columns: StepsColumns,
) -> Result<(), OutputError> {
    let mut w = StepsCsv::create(path, columns)?;
    steps.iter().try_for_each(|s| w.write(s))
}
