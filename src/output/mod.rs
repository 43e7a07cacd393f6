//! Output: tables a script can read (CSV, JSON) and figures a person can look at (STYLE.md point 12).
//!
//! Numbers are written with Rust's shortest round-trip formatting, so a value read back is bit-identical;
//! undefined values (e.g. `lambda_2+` after an (A3) exchange) are written as `NaN` in CSV and `null` in JSON.

pub mod animate;
pub mod chart;
pub mod map_plot;
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

/// Header of `steps.csv`.
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

/// One row of `steps.csv` (columns of [`STEPS_HEADER`]).
fn step_row(s: &StepReport) -> [String; STEPS_HEADER.len()] {
    let e = &s.energy;
    [
        s.step.to_string(),
        num(s.time),
        num(s.section.l2),
        num(s.section.theta_dot),
        num(s.section.l2_dot),
        num(s.theta),
        num(s.indicators.lambda_i4),
        num(s.indicators.lambda_2_plus),
        num(s.indicators.lambda_4_plus),
        s.branch.to_string(),
        num(s.dls_duration),
        num(s.period),
        num(s.step_length),
        num(s.speed),
        s.scuffing.to_string(),
        s.bounce.to_string(),
        s.events.to_string(),
        num(e.start),
        num(e.end),
        num(e.loss),
        num(e.damper),
        num(e.impact),
        num(e.stopper),
        num(e.residual),
        num(s.rear_contact_duration),
        num(s.contact.pull_force),
        num(s.contact.pull_impulse),
        num(s.contact.penetration),
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
        self.0.write(step_row(step))
    }
}

/// Write the per-step table `steps.csv`: one row per touchdown (section state before it, DLS indicators,
/// branch, step measures, flags, the energy audit, and the contact audit).
pub fn write_steps_csv(path: &Path, steps: &[StepReport]) -> Result<(), OutputError> {
    let mut w = StepsCsv::create(path)?;
    steps.iter().try_for_each(|s| w.write(s))
}

/// Header of `trajectory.csv`.
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

/// One row of `trajectory.csv` (columns of [`TRAJECTORY_HEADER`]).
fn sample_row(s: &Sample) -> Vec<String> {
    let flag = |b: bool| if b { "1" } else { "0" }.to_string();
    let mut row: Vec<String> = Vec::with_capacity(TRAJECTORY_HEADER.len());
    row.push(num(s.time));
    row.extend(s.q.iter().chain(s.qd.iter()).map(|v| num(*v)));
    let a = &s.active;
    row.extend([a.contact1, a.contact2, a.slide1, a.slide2, a.lock1, a.lock2].map(flag));
    let m = &s.multipliers;
    row.extend([m[0], m[1], m[2], m[3], -m[4], -m[5]].map(num));
    row.push(s.leg1.to_string());
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
        self.0.row(sample_row(sample)).map_err(std::io::Error::from)
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
pub const SWEEP_COLUMNS: [&str; 23] = [
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
    "message",
];

/// Write `sweep.csv`: one row per sweep point (the parameter value, the status and the gait's scalars; empty
/// gait fields where no gait was found).
pub fn write_sweep_csv(path: &Path, param: &str, points: &[SweepPoint]) -> Result<(), OutputError> {
    let mut w = csv_writer(path)?;
    let header: Vec<&str> = std::iter::once(param).chain(SWEEP_COLUMNS).collect();
    write_record(&mut w, path, &header)?;
    for p in points {
        let mut row = vec![num(p.value), p.status.clone()];
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
                    .map(num),
                );
                row.push(g.branch.to_string());
                row.extend(
                    [
                        g.period,
                        g.step_length,
                        g.speed,
                        g.dls_duration,
                        g.rear_contact_duration,
                    ]
                    .map(num),
                );
                row.extend([g.scuffing, g.bounce].map(|b| b.to_string()));
                row.push(g.stability.to_string());
                row.extend([
                    num(g.max_floquet),
                    num(g.jacobian_error),
                    num(g.residual),
                    g.iterations.to_string(),
                    p.family.map_or_else(String::new, |f| f.to_string()),
                ]);
            }
            None => row.extend(std::iter::repeat_n(String::new(), SWEEP_COLUMNS.len() - 2)),
        }
        row.push(p.message.clone().unwrap_or_default());
        write_record(&mut w, path, &row)?;
    }
    finish_csv(w, path)
}

/// Columns of `map.csv` after the two parameter columns.
pub const MAP_COLUMNS: [&str; 12] = [
    "status",
    "branch",
    "family",
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
/// row), the three DLS indicators, period, speed, the largest Floquet multiplier modulus and the stability
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
