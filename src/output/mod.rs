//! Output: tables a script can read (CSV, JSON) and figures a person can look at (STYLE.md point 12).
//!
//! Numbers are written with Rust's shortest round-trip formatting, so a value read back is bit-identical;
//! undefined values (e.g. `lambda_2+` after an (A3) exchange) are written as `NaN` in CSV and `null` in JSON.

pub mod plot;

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::gait::SweepPoint;
use crate::walk::{Sample, StepReport};

/// Writing a result file failed.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The file or directory could not be created or written.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The path.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// CSV encoding failed.
    #[error("cannot write CSV {path}: {source}")]
    Csv {
        /// The path.
        path: PathBuf,
        /// Why.
        source: csv::Error,
    },
    /// JSON encoding failed.
    #[error("cannot write JSON {path}: {source}")]
    Json {
        /// The path.
        path: PathBuf,
        /// Why.
        source: serde_json::Error,
    },
}

/// A number as written in CSV: the shortest text that reads back to the same `f64`, in scientific notation
/// when very small or very large; `NaN` for undefined values.
pub fn num(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".to_string()
    } else if (1e-4..1e15).contains(&a) {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

/// Create `dir` (and its parents) if needed.
pub fn ensure_dir(dir: &Path) -> Result<(), OutputError> {
    std::fs::create_dir_all(dir).map_err(|source| OutputError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

/// Open a CSV writer on `path`.
pub fn csv_writer(path: &Path) -> Result<csv::Writer<File>, OutputError> {
    csv::Writer::from_path(path).map_err(|source| OutputError::Csv {
        path: path.to_path_buf(),
        source,
    })
}

/// Write one CSV record, mapping errors to [`OutputError`].
pub fn write_record<I, T>(
    w: &mut csv::Writer<File>,
    path: &Path,
    record: I,
) -> Result<(), OutputError>
where
    I: IntoIterator<Item = T>,
    T: AsRef<[u8]>,
{
    w.write_record(record).map_err(|source| OutputError::Csv {
        path: path.to_path_buf(),
        source,
    })
}

/// Flush a CSV writer.
pub fn finish_csv(mut w: csv::Writer<File>, path: &Path) -> Result<(), OutputError> {
    w.flush().map_err(|source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Write `value` as pretty JSON to `path`.
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), OutputError> {
    let io = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut w = BufWriter::new(File::create(path).map_err(io)?);
    serde_json::to_writer_pretty(&mut w, value).map_err(|source| OutputError::Json {
        path: path.to_path_buf(),
        source,
    })?;
    writeln!(w).map_err(io)?;
    w.flush().map_err(io)
}

/// One cell of a result table, typed so that a table can be written as CSV or handed to another front (the
/// Python binding turns each column into an array of its type).
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// A real number, written with [`num`].
    Real(f64),
    /// A count or an index (also the `0`/`1` flags of `trajectory.csv`).
    Count(usize),
    /// A flag, written `true` or `false`.
    Flag(bool),
    /// A word (a branch, a status, a message).
    Text(String),
    /// No value (e.g. the gait columns of a sweep point without a gait), written as an empty field.
    Empty,
}

impl Cell {
    /// The cell as a CSV field.
    pub fn to_csv(&self) -> String {
        match self {
            Cell::Real(v) => num(*v),
            Cell::Count(n) => n.to_string(),
            Cell::Flag(b) => b.to_string(),
            Cell::Text(t) => t.clone(),
            Cell::Empty => String::new(),
        }
    }
}

/// Write a CSV table: the header, then one record per row.
pub fn write_table<H, R>(path: &Path, header: &[H], rows: R) -> Result<(), OutputError>
where
    H: AsRef<[u8]>,
    R: IntoIterator<Item = Vec<Cell>>,
{
    let mut w = csv_writer(path)?;
    write_record(&mut w, path, header)?;
    for row in rows {
        write_record(&mut w, path, row.iter().map(Cell::to_csv))?;
    }
    finish_csv(w, path)
}

/// Header of `steps.csv` (the names of [`step_row`]'s cells).
pub const STEPS_HEADER: [&str; 24] = [
    "step",
    "time",
    "L2",
    "thetadot",
    "L2dot",
    "theta",
    "lambda_I4",
    "lambda_2_plus",
    "lambda_4_plus",
    "branch",
    "dls_duration",
    "period",
    "step_length",
    "speed",
    "scuffing",
    "bounce",
    "events",
    "energy_start",
    "energy_end",
    "energy_loss",
    "damper_loss",
    "impact_loss",
    "stopper_loss",
    "energy_residual",
];

/// One row of `steps.csv`, in the order of [`STEPS_HEADER`].
pub fn step_row(s: &StepReport) -> Vec<Cell> {
    use Cell::{Count, Flag, Real, Text};
    let e = &s.energy;
    vec![
        Count(s.step),
        Real(s.time),
        Real(s.section.l2),
        Real(s.section.theta_dot),
        Real(s.section.l2_dot),
        Real(s.theta),
        Real(s.indicators.lambda_i4),
        Real(s.indicators.lambda_2_plus),
        Real(s.indicators.lambda_4_plus),
        Text(s.branch.to_string()),
        Real(s.dls_duration),
        Real(s.period),
        Real(s.step_length),
        Real(s.speed),
        Flag(s.scuffing),
        Flag(s.bounce),
        Count(s.events),
        Real(e.start),
        Real(e.end),
        Real(e.loss),
        Real(e.damper),
        Real(e.impact),
        Real(e.stopper),
        Real(e.residual),
    ]
}

/// Write the per-step table `steps.csv`: one row per touchdown (section state before it, DLS indicators,
/// branch, step measures, flags and the energy audit).
pub fn write_steps_csv(path: &Path, steps: &[StepReport]) -> Result<(), OutputError> {
    write_table(path, &STEPS_HEADER, steps.iter().map(step_row))
}

/// Header of `trajectory.csv` (the names of [`trajectory_row`]'s cells).
pub const TRAJECTORY_HEADER: [&str; 24] = [
    "time",
    "x",
    "z",
    "theta",
    "L1",
    "L2",
    "xdot",
    "zdot",
    "thetadot",
    "L1dot",
    "L2dot",
    "contact1",
    "contact2",
    "slide1",
    "slide2",
    "lock1",
    "lock2",
    "lambda_1",
    "lambda_2",
    "lambda_3",
    "lambda_4",
    "stopper_1",
    "stopper_2",
    "leg1",
];

/// One row of `trajectory.csv`, in the order of [`TRAJECTORY_HEADER`]: time, the ten states (`x` from the
/// start of the walk), the active contacts and stoppers as `0`/`1`, the multipliers (stopper reactions
/// positive inward) and which physical leg is Leg 1.
pub fn trajectory_row(s: &Sample) -> Vec<Cell> {
    let mut row = Vec::with_capacity(TRAJECTORY_HEADER.len());
    row.push(Cell::Real(s.time));
    row.extend(s.q.iter().chain(s.qd.iter()).map(|v| Cell::Real(*v)));
    let a = &s.active;
    row.extend(
        [a.contact1, a.contact2, a.slide1, a.slide2, a.lock1, a.lock2]
            .map(|b| Cell::Count(usize::from(b))),
    );
    let m = &s.multipliers;
    row.extend([m[0], m[1], m[2], m[3], -m[4], -m[5]].map(Cell::Real));
    row.push(Cell::Count(s.leg1));
    row
}

/// Write the sampled trajectory `trajectory.csv` (see [`trajectory_row`]).
pub fn write_trajectory_csv(path: &Path, samples: &[Sample]) -> Result<(), OutputError> {
    write_table(path, &TRAJECTORY_HEADER, samples.iter().map(trajectory_row))
}

/// Columns of `sweep.csv` after the parameter column.
pub const SWEEP_COLUMNS: [&str; 20] = [
    "status",
    "L2",
    "thetadot",
    "L2dot",
    "theta",
    "lambda_I4",
    "lambda_2_plus",
    "lambda_4_plus",
    "branch",
    "period",
    "step_length",
    "speed",
    "dls_duration",
    "scuffing",
    "bounce",
    "stable",
    "max_floquet",
    "residual",
    "iterations",
    "message",
];

/// The header of `sweep.csv` for a sweep of `param`: the parameter, then [`SWEEP_COLUMNS`].
pub fn sweep_header(param: &str) -> Vec<&str> {
    std::iter::once(param).chain(SWEEP_COLUMNS).collect()
}

/// One row of `sweep.csv`, in the order of [`sweep_header`]: the parameter value, the status and the gait's
/// scalars ([`Cell::Empty`] where no gait was found).
pub fn sweep_row(p: &SweepPoint) -> Vec<Cell> {
    use Cell::{Count, Flag, Real, Text};
    let mut row = vec![Real(p.value), Text(p.status.clone())];
    match &p.gait {
        Some(g) => {
            row.extend(
                [
                    g.section.l2,
                    g.section.theta_dot,
                    g.section.l2_dot,
                    g.theta,
                    g.lambda_i4,
                    g.lambda_2_plus,
                    g.lambda_4_plus,
                ]
                .map(Real),
            );
            row.push(Text(g.branch.to_string()));
            row.extend([g.period, g.step_length, g.speed, g.dls_duration].map(Real));
            row.extend([g.scuffing, g.bounce, g.stable].map(Flag));
            row.extend([Real(g.max_floquet), Real(g.residual), Count(g.iterations)]);
        }
        None => row.extend(std::iter::repeat_n(Cell::Empty, SWEEP_COLUMNS.len() - 2)),
    }
    row.push(Text(p.message.clone().unwrap_or_default()));
    row
}

/// Write `sweep.csv`: one row per sweep point (see [`sweep_row`]).
pub fn write_sweep_csv(path: &Path, param: &str, points: &[SweepPoint]) -> Result<(), OutputError> {
    write_table(path, &sweep_header(param), points.iter().map(sweep_row))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::default_initial;
    use crate::dynamics::Model;
    use crate::params::Config;
    use crate::walk::{simulate, Trajectory};

    /// Every row function gives one cell per header name (the CSV writers and the Python binding rely on it).
    #[test]
    fn rows_match_their_headers() {
        let config = Config::default();
        let model = Model::new(&config.params).unwrap();
        let mut trajectory = Trajectory::new(0.1);
        let start = default_initial(&config);
        let run = simulate(&model, &config.solver, &start, 1, Some(&mut trajectory)).unwrap();
        assert_eq!(step_row(&run.steps[0]).len(), STEPS_HEADER.len());
        assert_eq!(
            trajectory_row(&trajectory.samples[0]).len(),
            TRAJECTORY_HEADER.len()
        );
        let no_gait = SweepPoint {
            value: 1.0,
            status: "fell".to_string(),
            message: Some("fell".to_string()),
            gait: None,
        };
        assert_eq!(sweep_row(&no_gait).len(), sweep_header("c").len());
        assert_eq!(Cell::Empty.to_csv(), "");
        assert_eq!(Cell::Real(f64::NAN).to_csv(), "NaN");
    }
}
