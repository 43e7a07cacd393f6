//! Output: tables a script can read (CSV, JSON) and figures a person can look at (STYLE.md point 12).
//!
//! Numbers are written with Rust's shortest round-trip formatting, so a value read back is bit-identical;
//! undefined values (e.g. `lambda_2+` after an (A3) exchange) are written as `NaN` in CSV and `null` in JSON.

pub mod animate;
pub mod chart;
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

/// Header of `steps.csv`.
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

/// Write the per-step table `steps.csv`: one row per touchdown (section state before it, DLS indicators,
/// branch, step measures, flags and the energy audit).
pub fn write_steps_csv(path: &Path, steps: &[StepReport]) -> Result<(), OutputError> {
    let mut w = csv_writer(path)?;
    write_record(&mut w, path, STEPS_HEADER)?;
    for s in steps {
        let e = &s.energy;
        let row = [
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
        ];
        write_record(&mut w, path, row)?;
    }
    finish_csv(w, path)
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

/// Write the sampled trajectory `trajectory.csv`: time, the ten states (`x` from the start of the walk), the
/// active contacts and stoppers, the multipliers (stopper reactions positive inward) and which physical leg is
/// Leg 1.
pub fn write_trajectory_csv(path: &Path, samples: &[Sample]) -> Result<(), OutputError> {
    let mut w = csv_writer(path)?;
    write_record(&mut w, path, TRAJECTORY_HEADER)?;
    let flag = |b: bool| if b { "1" } else { "0" }.to_string();
    for s in samples {
        let mut row: Vec<String> = Vec::with_capacity(TRAJECTORY_HEADER.len());
        row.push(num(s.time));
        row.extend(s.q.iter().chain(s.qd.iter()).map(|v| num(*v)));
        let a = &s.active;
        row.extend([a.contact1, a.contact2, a.slide1, a.slide2, a.lock1, a.lock2].map(flag));
        let m = &s.multipliers;
        row.extend([m[0], m[1], m[2], m[3], -m[4], -m[5]].map(num));
        row.push(s.leg1.to_string());
        write_record(&mut w, path, row)?;
    }
    finish_csv(w, path)
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
                row.extend([g.period, g.step_length, g.speed, g.dls_duration].map(num));
                row.extend([g.scuffing, g.bounce, g.stable].map(|b| b.to_string()));
                row.extend([
                    num(g.max_floquet),
                    num(g.residual),
                    g.iterations.to_string(),
                ]);
            }
            None => row.extend(std::iter::repeat_n(String::new(), SWEEP_COLUMNS.len() - 2)),
        }
        row.push(p.message.clone().unwrap_or_default());
        write_record(&mut w, path, &row)?;
    }
    finish_csv(w, path)
}
