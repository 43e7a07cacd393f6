//! `trajectory.csv`: the sampled trajectory of a walk (time, the ten states, the active contacts and stoppers,
//! the multipliers and which physical leg is Leg 1), and its writers.

use std::path::Path;

use super::{fixed_names, row, Cell, Column};
use crate::contact::{ActiveSet, Role, Stop};
use crate::dynamics::L3;
use crate::output::{CsvStream, OutputError};
use crate::params::RearExit;
use crate::walk::{Sample, SampleSink};

use Cell::{Count, Real};

/// `0`/`1` for a flag of `trajectory.csv`.
fn bit(b: bool) -> Cell {
    Count(usize::from(b))
}

/// Which stop holds `leg`: 1 the stopper, 2 the compression stop, 0 none.
fn stop_state(active: &ActiveSet, leg: Role) -> Cell {
    Count(if active.held(leg, Stop::Compression) {
        2
    } else {
        usize::from(active.lock(leg))
    })
}

/// The columns of `trajectory.csv` (docs/model.md section 1: `q = [x, z, theta, L1, L2]`, slope frame; the
/// swinging leg's `L3` under `rear_exit = "continue"` is in `SWING_COLUMNS`).
pub(crate) const TRAJECTORY: [Column<Sample>; 24] = [
    Column::new("time", "Time [s].", |s| Real(s.time)),
    Column::new(
        "x",
        "Slope coordinate of Leg 1's tip, from the start of the walk [m].",
        |s| Real(s.q[0]),
    ),
    Column::new("z", "Height of Leg 1's tip above the slope [m].", |s| {
        Real(s.q[1])
    }),
    Column::new(
        "theta",
        "Angle of Leg 1 from the slope normal [rad].",
        |s| Real(s.q[2]),
    ),
    Column::new("L1", "Length of Leg 1 [m].", |s| Real(s.q[3])),
    Column::new("L2", "Length of Leg 2 [m].", |s| Real(s.q[4])),
    Column::new("xdot", "dx/dt [m/s].", |s| Real(s.qd[0])),
    Column::new("zdot", "dz/dt [m/s].", |s| Real(s.qd[1])),
    Column::new("thetadot", "dtheta/dt [rad/s].", |s| Real(s.qd[2])),
    Column::new("L1dot", "dL1/dt [m/s].", |s| Real(s.qd[3])),
    Column::new("L2dot", "dL2/dt [m/s].", |s| Real(s.qd[4])),
    Column::new("contact1", "1 if Leg 1's tip is on the ground.", |s| {
        bit(s.active.contact1)
    }),
    Column::new("contact2", "1 if Leg 2's tip is on the ground.", |s| {
        bit(s.active.contact2)
    }),
    Column::new("slide1", "1 if Leg 1's contact slides.", |s| {
        bit(s.active.slide1)
    }),
    Column::new("slide2", "1 if Leg 2's contact slides.", |s| {
        bit(s.active.slide2)
    }),
    Column::new(
        "lock1",
        "1 if Leg 1 is held on its stopper, 2 if on its compression stop (min_length), else 0.",
        |s| stop_state(&s.active, Role::Fore),
    ),
    Column::new(
        "lock2",
        "1 if Leg 2 is held on its stopper, 2 if on its compression stop (min_length), else 0.",
        |s| stop_state(&s.active, Role::Rear),
    ),
    Column::new("lambda_1", "Tangential force on Leg 1's tip [N].", |s| {
        Real(s.multipliers[0])
    }),
    Column::new("lambda_2", "Normal force on Leg 1's tip [N].", |s| {
        Real(s.multipliers[1])
    }),
    Column::new("lambda_3", "Tangential force on Leg 2's tip [N].", |s| {
        Real(s.multipliers[2])
    }),
    Column::new("lambda_4", "Normal force on Leg 2's tip [N].", |s| {
        Real(s.multipliers[3])
    }),
    Column::new(
        "stopper_1",
        "Stopper reaction on Leg 1, positive inward (-mu_1; a compression stop's, negative, pushes outward) [N].",
        |s| Real(-s.multipliers[4]),
    ),
    Column::new(
        "stopper_2",
        "Stopper reaction on Leg 2, positive inward (-mu_2; a compression stop's, negative, pushes outward) [N].",
        |s| Real(-s.multipliers[5]),
    ),
    Column::new("leg1", "Which physical leg (0 to N-1) is Leg 1.", |s| {
        Count(s.leg1)
    }),
];

/// Header of `trajectory.csv` (the names of `TRAJECTORY`).
pub const TRAJECTORY_HEADER: [&str; 24] = fixed_names(&TRAJECTORY, 0);

/// The columns `trajectory.csv` adds last under `rear_exit = "continue"`: the swinging leg (docs/model.md
/// section 5), 0 when no leg swings.
pub(crate) const SWING_COLUMNS: [Column<Sample>; 2] = [
    Column::new(
        "L3",
        "Length of the swinging leg (the old rear leg until its stopper locks it; rear_exit = continue), 0 when \
         none swings [m].",
        |s| Real(s.q[L3]),
    ),
    Column::new("L3dot", "dL3/dt [m/s] (0 when no leg swings).", |s| {
        Real(s.qd[L3])
    }),
];

/// The header of `trajectory.csv` of a walk under `rear_exit`: [`TRAJECTORY_HEADER`], and `L3`, `L3dot` last
/// under [`RearExit::Continue`].
pub fn trajectory_header(rear_exit: RearExit) -> Vec<&'static str> {
    let mut header = TRAJECTORY_HEADER.to_vec();
    if rear_exit == RearExit::Continue {
        header.extend(SWING_COLUMNS.iter().map(|c| c.header_name(&[])));
    }
    header
}

/// One row of `trajectory.csv` under `rear_exit`, in the order of [`trajectory_header`].
pub fn trajectory_row_under(s: &Sample, rear_exit: RearExit) -> Vec<Cell> {
    let mut cells = trajectory_row(s);
    if rear_exit == RearExit::Continue {
        cells.extend(SWING_COLUMNS.iter().map(|c| (c.get)(s)));
    }
    cells
}

/// One row of `trajectory.csv`, in the order of [`TRAJECTORY_HEADER`]: time, the ten states (`x` from the
/// start of the walk), the active contacts and stoppers as `0`/`1`, the multipliers (stopper reactions
/// positive inward) and which physical leg is Leg 1.
pub fn trajectory_row(s: &Sample) -> Vec<Cell> {
    row(&TRAJECTORY, s)
}

/// `trajectory.csv` written sample by sample: the [`SampleSink`] of a streaming
/// [`Trajectory`](crate::walk::Trajectory). Rows are buffered and flushed when the walk flushes the trajectory
/// (after every step).
pub struct TrajectoryCsv(CsvStream, RearExit);

impl TrajectoryCsv {
    /// Create `path` with the header [`trajectory_header`] of `rear_exit`.
    pub(crate) fn create(path: &Path, rear_exit: RearExit) -> Result<TrajectoryCsv, OutputError> {
        CsvStream::create(path, trajectory_header(rear_exit)).map(|w| TrajectoryCsv(w, rear_exit))
    }

    /// The file written.
    pub fn path(&self) -> &Path {
        self.0.path()
    }
}

impl SampleSink for TrajectoryCsv {
    fn write(&mut self, sample: &Sample) -> std::io::Result<()> {
        self.0
            .row(
                trajectory_row_under(sample, self.1)
                    .iter()
                    .map(Cell::to_csv),
            )
            .map_err(std::io::Error::from)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.w.flush()
    }
}

/// Write the sampled trajectory `trajectory.csv` of a walk under `rear_exit` ([`trajectory_header`]): time, the
/// ten states (`x` from the start of the walk), the active contacts and stoppers, the multipliers (stopper
/// reactions positive inward) and which physical leg is Leg 1.
pub fn write_trajectory_csv(
    path: &Path,
    samples: &[Sample],
    rear_exit: RearExit,
) -> Result<(), OutputError> {
    let mut w = TrajectoryCsv::create(path, rear_exit)?;
    samples
        .iter()
        .try_for_each(|s| w.write(s))
        .and_then(|()| SampleSink::flush(&mut w))
        .map_err(|source| OutputError::Io {
            path: path.to_path_buf(),
            source,
        })
}
