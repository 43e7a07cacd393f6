//! Output: tables a script can read (CSV, JSON) and figures a person can look at (STYLE.md point 12).
//!
//! Numbers are written with Rust's shortest round-trip formatting, so a value read back is bit-identical;
//! undefined values (e.g. `lambda_2+` after an (A3) exchange) are written as `NaN` in CSV and `null` in JSON.

pub mod animate;
pub mod basin_plot;
pub mod chart;
pub mod map_plot;
pub mod orbit_plot;
pub mod plot;
pub mod read;
pub mod run_plot;
pub mod steps_plot;
pub mod style;

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::gait::SweepPoint;
use crate::walk::{Sample, SampleSink, StepReport};

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
    /// The output directory names an existing file.
    #[error("output directory {path} is an existing file, not a directory: choose another --out")]
    NotADirectory {
        /// The path.
        path: PathBuf,
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

/// Create `dir` (and its parents) if needed; a `dir` that is an existing file is refused.
pub fn ensure_dir(dir: &Path) -> Result<(), OutputError> {
    if dir.exists() && !dir.is_dir() {
        return Err(OutputError::NotADirectory {
            path: dir.to_path_buf(),
        });
    }
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
pub const STEPS_HEADER: [&str; 28] = [
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
    "rear_contact_duration",
    "pull_force",
    "pull_impulse",
    "penetration",
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
        Real(s.rear_contact_duration),
        Real(s.contact.pull_force),
        Real(s.contact.pull_impulse),
        Real(s.contact.penetration),
    ]
}

/// A CSV file written row by row: each row is flushed to the file as soon as it is written, so an
/// interrupted or crashed run keeps every row it produced and memory does not grow with the rows.
pub struct CsvStream {
    w: csv::Writer<File>,
    path: PathBuf,
}

impl CsvStream {
    /// Create (truncate) `path` and write `header`.
    pub fn create<I, T>(path: &Path, header: I) -> Result<CsvStream, OutputError>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        let mut w = csv_writer(path)?;
        write_record(&mut w, path, header)?;
        Ok(CsvStream {
            w,
            path: path.to_path_buf(),
        })
    }

    /// Write one row, without flushing.
    fn row<I, T>(&mut self, record: I) -> Result<(), csv::Error>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        self.w.write_record(record)
    }

    /// Write one row and flush it to the file.
    pub fn write<I, T>(&mut self, record: I) -> Result<(), OutputError>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        write_record(&mut self.w, &self.path, record)?;
        self.flush()
    }

    /// Flush the rows written so far to the file.
    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.w.flush().map_err(|source| OutputError::Io {
            path: self.path.clone(),
            source,
        })
    }

    /// The file written.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// `steps.csv` written step by step ([`CsvStream`]).
pub struct StepsCsv(CsvStream);

impl StepsCsv {
    /// Create `path` with the header [`STEPS_HEADER`].
    pub fn create(path: &Path) -> Result<StepsCsv, OutputError> {
        CsvStream::create(path, STEPS_HEADER).map(StepsCsv)
    }

    /// Write the row of one step and flush it.
    pub fn write(&mut self, step: &StepReport) -> Result<(), OutputError> {
        self.0.write(step_row(step).iter().map(Cell::to_csv))
    }
}

/// Write the per-step table `steps.csv`: one row per touchdown (section state before it, DLS indicators,
/// branch, step measures, flags, the energy audit, and the contact audit).
pub fn write_steps_csv(path: &Path, steps: &[StepReport]) -> Result<(), OutputError> {
    let mut w = StepsCsv::create(path)?;
    steps.iter().try_for_each(|s| w.write(s))
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

/// `trajectory.csv` written sample by sample: the [`SampleSink`] of a streaming
/// [`Trajectory`](crate::walk::Trajectory). Rows are buffered and flushed when the walk flushes the trajectory
/// (after every step).
pub struct TrajectoryCsv(CsvStream);

impl TrajectoryCsv {
    /// Create `path` with the header [`TRAJECTORY_HEADER`].
    pub fn create(path: &Path) -> Result<TrajectoryCsv, OutputError> {
        CsvStream::create(path, TRAJECTORY_HEADER).map(TrajectoryCsv)
    }

    /// The file written.
    pub fn path(&self) -> &Path {
        self.0.path()
    }
}

impl SampleSink for TrajectoryCsv {
    fn write(&mut self, sample: &Sample) -> std::io::Result<()> {
        self.0
            .row(trajectory_row(sample).iter().map(Cell::to_csv))
            .map_err(std::io::Error::from)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.w.flush()
    }
}

/// Write the sampled trajectory `trajectory.csv`: time, the ten states (`x` from the start of the walk), the
/// active contacts and stoppers, the multipliers (stopper reactions positive inward) and which physical leg is
/// Leg 1.
pub fn write_trajectory_csv(path: &Path, samples: &[Sample]) -> Result<(), OutputError> {
    let mut w = TrajectoryCsv::create(path)?;
    samples
        .iter()
        .try_for_each(|s| w.write(s))
        .and_then(|()| SampleSink::flush(&mut w))
        .map_err(|source| OutputError::Io {
            path: path.to_path_buf(),
            source,
        })
}

/// Columns of `sweep.csv` after the parameter column.
pub const SWEEP_COLUMNS: [&str; 24] = [
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
    "rear_contact_duration",
    "scuffing",
    "bounce",
    "stability",
    "max_floquet",
    "jacobian_error",
    "residual",
    "iterations",
    "family",
    "period_k",
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
            row.extend(
                [
                    g.period,
                    g.step_length,
                    g.speed,
                    g.dls_duration,
                    g.rear_contact_duration,
                ]
                .map(Real),
            );
            row.extend([g.scuffing, g.bounce].map(Flag));
            row.push(Text(g.stability.to_string()));
            row.extend([
                Real(g.max_floquet),
                Real(g.jacobian_error),
                Real(g.residual),
                Count(g.iterations),
                p.family.map_or(Cell::Empty, Count),
                Count(g.period_k),
            ]);
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

/// Columns of `map.csv` after the two parameter columns.
pub const MAP_COLUMNS: [&str; 13] = [
    "status",
    "branch",
    "family",
    "period_k",
    "lambda_I4",
    "lambda_2_plus",
    "lambda_4_plus",
    "period",
    "speed",
    "max_floquet",
    "stability",
    "scuffing",
    "message",
];

/// Write `map.csv`: one row per map point, row by row (`y` outer, `x` inner): both parameter values, the status
/// (the stability verdict, or why no gait was found), the impact branch, the gait family (numbered within the
/// row), `period_k`, the three DLS indicators, period, speed, the largest Floquet multiplier modulus and the stability
/// verdict; empty gait fields where no gait was found.
pub fn write_map_csv(path: &Path, map: &crate::gait::GaitMap) -> Result<(), OutputError> {
    let mut w = csv_writer(path)?;
    let header: Vec<&str> = [map.spec.x.param.as_str(), map.spec.y.param.as_str()]
        .into_iter()
        .chain(MAP_COLUMNS)
        .collect();
    write_record(&mut w, path, &header)?;
    for (row, &y) in map.rows.iter().zip(&map.ys) {
        for p in row {
            let mut record = vec![num(p.value), num(y), p.status.clone()];
            match &p.gait {
                Some(g) => {
                    record.push(g.branch.to_string());
                    record.push(p.family.map_or_else(String::new, |f| f.to_string()));
                    record.push(g.period_k.to_string());
                    record.extend(
                        [
                            g.lambda_i4,
                            g.lambda_2_plus,
                            g.lambda_4_plus,
                            g.period,
                            g.speed,
                            g.max_floquet,
                        ]
                        .map(num),
                    );
                    record.push(g.stability.to_string());
                    record.push(g.scuffing.to_string());
                }
                None => record.extend(std::iter::repeat_n(String::new(), MAP_COLUMNS.len() - 2)),
            }
            record.push(p.message.clone().unwrap_or_default());
            write_record(&mut w, path, &record)?;
        }
    }
    finish_csv(w, path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::Model;
    use crate::params::Config;
    use crate::reference::default_initial;
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
            continued_from: None,
            family: None,
            attempts: Vec::new(),
        };
        assert_eq!(sweep_row(&no_gait).len(), sweep_header("c").len());
        assert_eq!(Cell::Empty.to_csv(), "");
        assert_eq!(Cell::Real(f64::NAN).to_csv(), "NaN");
    }
}
