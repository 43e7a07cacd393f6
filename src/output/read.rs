//! Reading a run directory back: what `vrw simulate` (or `vrw gait`) wrote, for the figures and the
//! animation.
//!
//! Columns are found by their header name, never by position, and extra columns are ignored, so files from a
//! newer vrw with more columns still read. Missing files or columns are errors that name the file and the
//! column.
//!
//! A last row without its line end (what a run killed while writing leaves) is left out, with a warning in
//! [`RunData::warnings`]. Values that cannot be (a non-finite or absurdly large number, `leg1` outside
//! `0..N`, a leg length outside `(0, L0 + LENGTH_SLACK]`) are refused with an error naming the file, the row
//! and the column.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer, Serialize};

use super::{step_row, trajectory_row, Cell, STEPS_HEADER, TRAJECTORY_HEADER};
use crate::params::Config;
use crate::walk::{Sample, StepReport};

/// A run directory could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The directory does not exist or is not a directory.
    #[error(
        "{path} is not a directory (give the output directory of `vrw simulate` or `vrw gait`)"
    )]
    NotADirectory {
        /// The path given.
        path: PathBuf,
    },
    /// A file the directory must hold is missing.
    #[error("{dir} has no {file} (is it an output directory of `vrw simulate` or `vrw gait`?)")]
    Missing {
        /// The directory.
        dir: PathBuf,
        /// The missing file name.
        file: &'static str,
    },
    /// The file could not be opened or read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A CSV file is malformed or lacks a column.
    #[error("cannot read {path}: {source}")]
    Csv {
        /// The file.
        path: PathBuf,
        /// Why (with the line and the column).
        source: csv::Error,
    },
    /// `summary.json` is not valid JSON.
    #[error("cannot read {path}: {source}")]
    Json {
        /// The file.
        path: PathBuf,
        /// Why.
        source: serde_json::Error,
    },
    /// `summary.json` lacks a parameter the figures need, or holds a value of the wrong kind.
    #[error("{path}: config.{key} is missing or not a {expected}")]
    Parameter {
        /// The file.
        path: PathBuf,
        /// The parameter key.
        key: &'static str,
        /// What kind of value was expected.
        expected: &'static str,
    },
    /// A table has no data rows.
    #[error("{path} has no data rows")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// A value that cannot be: not finite, absurdly large, or outside its range.
    #[error("{path}: data row {row} (line {line}), column {column}: {value} {reason}")]
    Implausible {
        /// The file.
        path: PathBuf,
        /// Data row, from 1.
        row: usize,
        /// Line of the file (the header is line 1).
        line: usize,
        /// The column.
        column: &'static str,
        /// The value as read.
        value: String,
        /// Why it cannot be.
        reason: String,
    },
    /// The samples of `trajectory.csv` are not in time order, or a time is not finite.
    #[error("{path}: time {time} on data row {row} is not finite or goes backwards")]
    Unordered {
        /// The file.
        path: PathBuf,
        /// Data row, from 1.
        row: usize,
        /// The offending time \[s\].
        time: f64,
    },
}

/// The largest magnitude a number of `trajectory.csv` or `steps.csv` may have: positions \[m\], angles
/// \[rad\], velocities, forces \[N\] and energies \[J\] of a walking wheel are far below it.
pub const MAX_MAGNITUDE: f64 = 1e9;

/// How far past the stopper length `L0` a leg length may read \[m\]: the largest `stopper_gap` accepted
/// (docs/model.md section 4, grazing guards), by which a free leg's stopper event may fire past `L0`.
pub const LENGTH_SLACK: f64 = 1e-6;

/// A 0/1 (or true/false) flag column.
fn flag<'de, D: Deserializer<'de>>(d: D) -> Result<bool, D::Error> {
    let s = String::deserialize(d)?;
    match s.trim() {
        "1" | "true" => Ok(true),
        "0" | "false" => Ok(false),
        other => Err(serde::de::Error::custom(format!(
            "expected a flag 0 or 1, found {other:?}"
        ))),
    }
}

/// A `lock1` / `lock2` column: 0 free, 1 held on the stopper, 2 held on the compression stop.
fn stop_flag<'de, D: Deserializer<'de>>(d: D) -> Result<u8, D::Error> {
    let s = String::deserialize(d)?;
    match s.trim() {
        "0" => Ok(0),
        "1" => Ok(1),
        "2" => Ok(2),
        other => Err(serde::de::Error::custom(format!(
            "expected 0, 1 (stopper) or 2 (compression stop), found {other:?}"
        ))),
    }
}

/// One row of `trajectory.csv` (docs/model.md section 1: `q = [x, z, theta, L1, L2]`, slope frame; and `L3`
/// under `rear_exit = "continue"`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
pub struct TrajectoryRow {
    /// Time \[s\].
    pub time: f64,
    /// Slope coordinate of Leg 1's tip, from the start of the walk \[m\].
    pub x: f64,
    /// Height of Leg 1's tip above the slope \[m\].
    pub z: f64,
    /// Angle of Leg 1 from the slope normal \[rad\].
    pub theta: f64,
    /// Length of Leg 1 \[m\].
    #[serde(rename = "L1")]
    pub l1: f64,
    /// Length of Leg 2 \[m\].
    #[serde(rename = "L2")]
    pub l2: f64,
    /// `dtheta/dt` \[rad/s\].
    #[serde(rename = "thetadot")]
    pub theta_dot: f64,
    /// `dL1/dt` \[m/s\].
    #[serde(rename = "L1dot")]
    pub l1_dot: f64,
    /// `dL2/dt` \[m/s\].
    #[serde(rename = "L2dot")]
    pub l2_dot: f64,
    /// Leg 1's tip is on the ground.
    #[serde(deserialize_with = "flag")]
    pub contact1: bool,
    /// Leg 2's tip is on the ground.
    #[serde(deserialize_with = "flag")]
    pub contact2: bool,
    /// Leg 1's contact slides.
    #[serde(deserialize_with = "flag")]
    pub slide1: bool,
    /// Leg 2's contact slides.
    #[serde(deserialize_with = "flag")]
    pub slide2: bool,
    /// Which stop holds Leg 1: 0 none, 1 its stopper, 2 its compression stop.
    #[serde(deserialize_with = "stop_flag")]
    pub lock1: u8,
    /// Which stop holds Leg 2: 0 none, 1 its stopper, 2 its compression stop.
    #[serde(deserialize_with = "stop_flag")]
    pub lock2: u8,
    /// Tangential force on Leg 1's tip \[N\].
    pub lambda_1: f64,
    /// Normal force on Leg 1's tip \[N\].
    pub lambda_2: f64,
    /// Tangential force on Leg 2's tip \[N\].
    pub lambda_3: f64,
    /// Normal force on Leg 2's tip \[N\].
    pub lambda_4: f64,
    /// Which physical leg (0 to N-1) is Leg 1.
    pub leg1: usize,
    /// Length of the swinging leg (the old rear leg under `rear_exit = "continue"`, one leg behind Leg 2) while
    /// it swings, 0 when none does or the file has no such column \[m\].
    #[serde(rename = "L3", default)]
    pub l3: f64,
}

/// The contact state of a leg's tip.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TipState {
    /// On the ground, not slipping.
    Stuck,
    /// On the ground, sliding.
    Sliding,
    /// In the air.
    Air,
}

impl TipState {
    fn of(contact: bool, slide: bool) -> TipState {
        match (contact, slide) {
            (true, false) => TipState::Stuck,
            (true, true) => TipState::Sliding,
            (false, _) => TipState::Air,
        }
    }
}

impl TrajectoryRow {
    /// Contact state of Leg 1's and Leg 2's tips.
    pub(crate) fn tips(&self) -> [TipState; 2] {
        [
            TipState::of(self.contact1, self.slide1),
            TipState::of(self.contact2, self.slide2),
        ]
    }

    /// The phase in words: which tips are on the ground, which slide, which stoppers hold.
    pub fn phase_name(&self) -> String {
        let [t1, t2] = self.tips();
        let on = |t: TipState| t != TipState::Air;
        let mut name = match (on(t1), on(t2)) {
            (true, true) => "DLS".to_string(),
            (true, false) => "SLS".to_string(),
            (false, true) => "rear support".to_string(),
            (false, false) => "flight".to_string(),
        };
        for (leg, t) in [(1, t1), (2, t2)] {
            if t == TipState::Sliding {
                name.push_str(&format!(", Leg {leg} slides"));
            }
        }
        name
    }

    /// The discrete state (contacts, slides, stoppers, re-indexing) that changes only at events.
    pub fn mode(&self) -> (bool, bool, bool, bool, u8, u8, usize) {
        (
            self.contact1,
            self.contact2,
            self.slide1,
            self.slide2,
            self.lock1,
            self.lock2,
            self.leg1,
        )
    }
}

/// One row of `steps.csv` (the columns the figures use).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub struct StepRow {
    /// Step number, from 1.
    pub step: usize,
    /// Time of the touchdown that starts the step \[s\].
    pub time: f64,
    /// DLS indicator `lambda_I4` \[N s\].
    #[serde(rename = "lambda_I4", alias = "lambda_i4")]
    pub lambda_i4: f64,
    /// DLS indicator `lambda_2+` \[N\].
    pub lambda_2_plus: f64,
    /// DLS indicator `lambda_4+` \[N\].
    pub lambda_4_plus: f64,
    /// Branch of the impact procedure.
    pub branch: String,
    /// Time in double support \[s\].
    pub dls_duration: f64,
    /// Time to the next touchdown \[s\].
    pub period: f64,
    /// Loss of `T + V` over the step \[J\].
    pub energy_loss: f64,
    /// Damper dissipation \[J\].
    pub damper_loss: f64,
    /// Impact losses \[J\].
    pub impact_loss: f64,
    /// Stopper losses \[J\].
    pub stopper_loss: f64,
    /// Residual of the energy audit \[J\].
    pub energy_residual: f64,
}

/// The parameters the figures need, from `summary.json`'s `config`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    /// Number of legs `N`.
    pub legs: usize,
    /// Stopper length `L0` \[m\].
    pub stopper_length: f64,
    /// Spring natural length `Lstar` \[m\].
    pub spring_natural_length: f64,
    /// Distance `a` of the leg mass from the tip \[m\].
    pub leg_mass_offset: f64,
    /// Slope angle `phi` \[rad\].
    pub slope: f64,
    /// Leg viscosity `c` \[N s/m\].
    pub viscosity: f64,
    /// Whether Leg 2 has its stopper (`rear_stopper`, true when the key is absent, as it is at its default).
    pub rear_stopper: bool,
    /// Length of the compression stop \[m\] (`min_length`; 0, none, when the key is absent, as at its default).
    pub min_length: f64,
    /// Length of the legs other than Legs 1 and 2 \[m\]: `touchdown_length`, or `L0` when the key is absent (as
    /// at its default, 0).
    pub spoke_length: f64,
}

impl Geometry {
    /// Inter-leg angle `alpha = 2 pi / N` \[rad\].
    pub(crate) fn alpha(&self) -> f64 {
        std::f64::consts::TAU / self.legs as f64
    }
}

/// A run directory read back.
#[derive(Debug, Clone)]
pub struct RunData {
    /// The directory.
    pub dir: PathBuf,
    /// Parameters.
    pub geometry: Geometry,
    /// How the run ended (`completed`, `fell`, ...), from `summary.json`.
    pub status: String,
    /// The samples of `trajectory.csv`, in time order.
    pub samples: Vec<TrajectoryRow>,
    /// The rows of `steps.csv`, in step order.
    pub steps: Vec<StepRow>,
    /// What was left out while reading (an incomplete last row), for the user.
    pub warnings: Vec<String>,
}

impl RunData {
    /// Path of `name` inside the run directory.
    pub(crate) fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Time span `[first, last]` of the samples \[s\].
    pub fn time_span(&self) -> (f64, f64) {
        match (self.samples.first(), self.samples.last()) {
            (Some(a), Some(b)) => (a.time, b.time),
            _ => (0.0, 0.0),
        }
    }

    /// The step running at time `t` (the last touchdown at or before `t`), if any.
    pub(crate) fn step_at(&self, t: f64) -> Option<&StepRow> {
        let k = self.steps.partition_point(|s| s.time <= t);
        k.checked_sub(1).map(|k| &self.steps[k])
    }
}

/// Read the rows of a CSV file by header name (an empty table is an error unless `allow_empty`).
pub fn read_csv<T: DeserializeOwned>(path: &Path, allow_empty: bool) -> Result<Vec<T>, ReadError> {
    read_complete_rows(path, allow_empty).map(|(rows, _)| rows)
}

/// [`read_csv`], leaving out a last row without its line end (a run killed while writing it); the warning
/// says so.
pub fn read_complete_rows<T: DeserializeOwned>(
    path: &Path,
    allow_empty: bool,
) -> Result<(Vec<T>, Option<String>), ReadError> {
    let bytes = std::fs::read(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_rows(path, bytes, allow_empty)
}

/// [`read_complete_rows`] of the text `bytes` of the file `path`.
fn parse_rows<T: DeserializeOwned>(
    path: &Path,
    mut bytes: Vec<u8>,
    allow_empty: bool,
) -> Result<(Vec<T>, Option<String>), ReadError> {
    let csv_err = |source| ReadError::Csv {
        path: path.to_path_buf(),
        source,
    };
    let mut warning = None;
    if bytes.last().is_some_and(|&b| b != b'\n') {
        let end = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |k| k + 1);
        // Only a data row can be left out; a header without its line end is read as it is.
        if end > 0 {
            let line = bytes[..end].iter().filter(|&&b| b == b'\n').count() + 1;
            bytes.truncate(end);
            warning = Some(format!(
                "{}: the last row (line {line}) is incomplete (the run was killed while writing it?); it \
                 is left out",
                path.display()
            ));
        }
    }
    let mut reader = csv::Reader::from_reader(bytes.as_slice());
    let rows = reader
        .deserialize()
        .collect::<Result<Vec<T>, _>>()
        .map_err(csv_err)?;
    if rows.is_empty() && !allow_empty {
        return Err(ReadError::Empty {
            path: path.to_path_buf(),
        });
    }
    Ok((rows, warning))
}

fn parameter<T>(
    config: &serde_json::Value,
    path: &Path,
    key: &'static str,
    expected: &'static str,
    get: impl Fn(&serde_json::Value) -> Option<T>,
) -> Result<T, ReadError> {
    config
        .get(key)
        .and_then(get)
        .ok_or_else(|| ReadError::Parameter {
            path: path.to_path_buf(),
            key,
            expected,
        })
}

fn read_summary(path: &Path) -> Result<(Geometry, String), ReadError> {
    let text = std::fs::read_to_string(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    summary_fields(path, &text)
}

/// The geometry and the status of the text `text` of `summary.json` (the file `path`).
fn summary_fields(path: &Path, text: &str) -> Result<(Geometry, String), ReadError> {
    let json: serde_json::Value = serde_json::from_str(text).map_err(|source| ReadError::Json {
        path: path.to_path_buf(),
        source,
    })?;
    let config = json.get("config").unwrap_or(&serde_json::Value::Null);
    let number = |key| {
        parameter(config, path, key, "finite number", |v| {
            v.as_f64().filter(|x| x.is_finite())
        })
    };
    let legs = parameter(config, path, "legs", "whole number of at least 3", |v| {
        v.as_u64().filter(|&n| n >= 3).map(|n| n as usize)
    })?;
    // A key files leave out at its default, 0.
    let optional_length = |key| match config.get(key) {
        None => Ok(0.0),
        Some(_) => parameter(config, path, key, "non-negative number", |v| {
            v.as_f64().filter(|x| x.is_finite() && *x >= 0.0)
        }),
    };
    let stopper_length = number("stopper_length")?;
    let geometry = Geometry {
        legs,
        stopper_length,
        spring_natural_length: number("spring_natural_length")?,
        leg_mass_offset: number("leg_mass_offset")?,
        slope: number("slope")?,
        viscosity: number("viscosity")?,
        rear_stopper: match config.get("rear_stopper") {
            None => true,
            Some(_) => parameter(config, path, "rear_stopper", "true or false", |v| {
                v.as_bool()
            })?,
        },
        min_length: optional_length("min_length")?,
        spoke_length: match optional_length("touchdown_length")? {
            0.0 => stopper_length,
            length => length,
        },
    };
    let status = json
        .get("status")
        .and_then(|s| s.as_str())
        .unwrap_or("unknown")
        .to_string();
    Ok((geometry, status))
}

/// Read `steps.csv`, `trajectory.csv` and `summary.json` from `dir` (the output of `vrw simulate`, or of
/// `vrw gait`, which writes the same three files for one period of its gait).
///
/// # Errors
/// [`ReadError`] naming the directory, the file and, for CSV, the line and column at fault.
pub fn read_run(dir: &Path) -> Result<RunData, ReadError> {
    if !dir.is_dir() {
        return Err(ReadError::NotADirectory {
            path: dir.to_path_buf(),
        });
    }
    let file = |name: &'static str| {
        let path = dir.join(name);
        if path.is_file() {
            Ok(path)
        } else {
            Err(ReadError::Missing {
                dir: dir.to_path_buf(),
                file: name,
            })
        }
    };
    let trajectory_path = file("trajectory.csv")?;
    let steps_path = file("steps.csv")?;
    let summary_path = file("summary.json")?;
    let (geometry, status) = read_summary(&summary_path)?;
    let (samples, warning) = read_complete_rows(&trajectory_path, false)?;
    let mut warnings: Vec<String> = warning.into_iter().collect();
    check_samples(&trajectory_path, &samples, &geometry)?;
    // A walk that stopped during its first step has no step rows, but its trajectory can still be shown.
    let (steps, warning): (Vec<StepRow>, _) = read_complete_rows(&steps_path, true)?;
    warnings.extend(warning);
    check_steps(&steps_path, &steps)?;
    Ok(RunData {
        dir: dir.to_path_buf(),
        geometry,
        status,
        samples,
        steps,
        warnings,
    })
}

/// A walk held in memory as the [`RunData`] that [`read_run`] reads from the files `vrw simulate` writes for
/// it, without files (for a front that draws a walk it has just computed, such as the Python binding): the
/// parameters go through the JSON text of `summary.json` and the tables through the CSV text of
/// `steps.csv` and `trajectory.csv`, written as their writers write them and read back as [`read_run`] reads
/// them, so a figure drawn from it is the one drawn from the directory, bit for bit (its numbers are those
/// the files give back, not the walk's own: a cell is the shortest text that reads back to the same number
/// but writes `-0` as `0`, and serde_json may read a JSON number one unit in the last place off). `status`
/// is `summary.json`'s; the paths named in errors are the bare file names.
///
/// # Errors
/// [`ReadError`] as [`read_run`]'s checks raise it (a walk computed by vrw passes them).
pub fn run_from_walk(
    config: &Config,
    status: &str,
    steps: &[StepReport],
    samples: &[Sample],
) -> Result<RunData, ReadError> {
    #[derive(Serialize)]
    struct Summary<'a> {
        config: &'a Config,
        status: &'a str,
    }
    let summary_path = Path::new("summary.json");
    let text =
        serde_json::to_string(&Summary { config, status }).map_err(|source| ReadError::Json {
            path: summary_path.to_path_buf(),
            source,
        })?;
    let (geometry, status) = summary_fields(summary_path, &text)?;
    let trajectory_path = Path::new("trajectory.csv");
    let text = csv_text(
        trajectory_path,
        &TRAJECTORY_HEADER,
        samples.iter().map(trajectory_row),
    )?;
    let (samples, _) = parse_rows(trajectory_path, text, false)?;
    check_samples(trajectory_path, &samples, &geometry)?;
    let steps_path = Path::new("steps.csv");
    let text = csv_text(steps_path, &STEPS_HEADER, steps.iter().map(step_row))?;
    let (steps, _) = parse_rows(steps_path, text, true)?;
    check_steps(steps_path, &steps)?;
    Ok(RunData {
        dir: PathBuf::new(),
        geometry,
        status,
        samples,
        steps,
        warnings: Vec::new(),
    })
}

/// The CSV text of a table with `header` and `rows`, as the streaming writers write the file `path`.
fn csv_text(
    path: &Path,
    header: &[&str],
    rows: impl Iterator<Item = Vec<Cell>>,
) -> Result<Vec<u8>, ReadError> {
    let csv_err = |source| ReadError::Csv {
        path: path.to_path_buf(),
        source,
    };
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(header).map_err(csv_err)?;
    for row in rows {
        w.write_record(row.iter().map(Cell::to_csv))
            .map_err(csv_err)?;
    }
    w.into_inner().map_err(|e| ReadError::Io {
        path: path.to_path_buf(),
        source: e.into_error(),
    })
}

/// Check the samples of `trajectory.csv` (the file `path`): in time order, each a state of the wheel
/// `geometry` ([`check_sample`]).
fn check_samples(
    path: &Path,
    samples: &[TrajectoryRow],
    geometry: &Geometry,
) -> Result<(), ReadError> {
    let mut last = f64::NEG_INFINITY;
    for (k, s) in samples.iter().enumerate() {
        if !(s.time.is_finite() && s.time >= last) {
            return Err(ReadError::Unordered {
                path: path.to_path_buf(),
                row: k + 1,
                time: s.time,
            });
        }
        last = s.time;
        check_sample(path, k + 1, s, geometry)?;
    }
    Ok(())
}

/// Check the rows of `steps.csv` (the file `path`) with [`check_step`].
fn check_steps(path: &Path, steps: &[StepRow]) -> Result<(), ReadError> {
    for (k, s) in steps.iter().enumerate() {
        check_step(path, k + 1, s)?;
    }
    Ok(())
}

/// The error for `value` in `column` of data row `row` of `path`.
fn implausible(
    path: &Path,
    row: usize,
    column: &'static str,
    value: String,
    reason: String,
) -> ReadError {
    ReadError::Implausible {
        path: path.to_path_buf(),
        row,
        line: row + 1,
        column,
        value,
        reason,
    }
}

/// A number that must be finite and at most [`MAX_MAGNITUDE`] in size.
fn check_number(path: &Path, row: usize, column: &'static str, v: f64) -> Result<(), ReadError> {
    if v.is_finite() && v.abs() <= MAX_MAGNITUDE {
        Ok(())
    } else {
        Err(implausible(
            path,
            row,
            column,
            v.to_string(),
            format!("is not a finite number of at most {MAX_MAGNITUDE:e} in size"),
        ))
    }
}

/// Check one row of `trajectory.csv` against what a state of the wheel `geometry` can be.
fn check_sample(
    path: &Path,
    row: usize,
    s: &TrajectoryRow,
    geometry: &Geometry,
) -> Result<(), ReadError> {
    let numbers = [
        ("x", s.x),
        ("z", s.z),
        ("theta", s.theta),
        ("L1", s.l1),
        ("L2", s.l2),
        ("thetadot", s.theta_dot),
        ("L1dot", s.l1_dot),
        ("L2dot", s.l2_dot),
        ("lambda_1", s.lambda_1),
        ("lambda_2", s.lambda_2),
        ("lambda_3", s.lambda_3),
        ("lambda_4", s.lambda_4),
        ("L3", s.l3),
    ];
    for (column, v) in numbers {
        check_number(path, row, column, v)?;
    }
    let stopped = geometry.stopper_length + LENGTH_SLACK;
    // Without its stopper Leg 2 extends past `L0`, though not (with a sound spring) to twice its natural length.
    let free = 2.0 * geometry.spring_natural_length.max(geometry.stopper_length);
    for (column, l, stopper) in [("L1", s.l1, true), ("L2", s.l2, geometry.rear_stopper)] {
        let (longest, which) = if stopper {
            (stopped, format!("L0 + {LENGTH_SLACK:e}"))
        } else {
            (free, "2 max(L0, Lstar), no rear stopper".to_string())
        };
        if !(l > 0.0 && l <= longest) {
            return Err(implausible(
                path,
                row,
                column,
                l.to_string(),
                format!("is not a leg length in (0, {which}] = (0, {longest}] m"),
            ));
        }
        if geometry.min_length > 0.0 && l < geometry.min_length - LENGTH_SLACK {
            return Err(implausible(
                path,
                row,
                column,
                l.to_string(),
                format!(
                    "is below the compression stop: a leg length is at least min_length - {LENGTH_SLACK:e} = {} m",
                    geometry.min_length - LENGTH_SLACK
                ),
            ));
        }
    }
    // The swinging leg (rear_exit = continue): 0 when none swings, else a length up to its stopper.
    if !(s.l3 == 0.0 || (s.l3 > 0.0 && s.l3 <= stopped)) {
        return Err(implausible(
            path,
            row,
            "L3",
            s.l3.to_string(),
            format!(
                "is neither 0 (no swinging leg) nor a leg length in (0, L0 + {LENGTH_SLACK:e}] m"
            ),
        ));
    }
    if s.leg1 >= geometry.legs {
        return Err(implausible(
            path,
            row,
            "leg1",
            s.leg1.to_string(),
            format!(
                "is not a leg of the {}-leg wheel (0 to {})",
                geometry.legs,
                geometry.legs - 1
            ),
        ));
    }
    Ok(())
}

/// Check one row of `steps.csv`: the time is finite, every defined number (undefined ones are `NaN`) is at
/// most [`MAX_MAGNITUDE`] in size.
fn check_step(path: &Path, row: usize, s: &StepRow) -> Result<(), ReadError> {
    check_number(path, row, "time", s.time)?;
    let numbers = [
        ("lambda_I4", s.lambda_i4),
        ("lambda_2_plus", s.lambda_2_plus),
        ("lambda_4_plus", s.lambda_4_plus),
        ("dls_duration", s.dls_duration),
        ("period", s.period),
        ("energy_loss", s.energy_loss),
        ("damper_loss", s.damper_loss),
        ("impact_loss", s.impact_loss),
        ("stopper_loss", s.stopper_loss),
        ("energy_residual", s.energy_residual),
    ];
    for (column, v) in numbers {
        if !v.is_nan() {
            check_number(path, row, column, v)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::{compute_simulation, run_simulate, SimulateJob};

    /// A walk held in memory reads as its run directory reads: the same samples, steps and parameters.
    #[test]
    fn walk_in_memory_reads_as_its_directory() {
        let dir = tempfile::tempdir().unwrap();
        let job = SimulateJob {
            config: Config::default(),
            initial: None,
            steps: 2,
            sample_dt: 0.01,
            trajectory: true,
            out_dir: dir.path().to_path_buf(),
            overwrite: false,
            interrupt: None,
        };
        run_simulate(&job, &mut |_| {}).unwrap();
        let files = read_run(dir.path()).unwrap();
        let (summary, trajectory) = compute_simulation(&job, true).unwrap();
        let samples = trajectory.unwrap().samples;
        let memory = run_from_walk(
            &job.config,
            &summary.status.to_string(),
            &summary.steps,
            &samples,
        )
        .unwrap();
        assert_eq!(memory.geometry, files.geometry);
        assert_eq!(memory.status, files.status);
        assert_eq!(memory.samples, files.samples);
        // Debug text, where NaN (an undefined indicator) equals NaN.
        assert_eq!(format!("{:?}", memory.steps), format!("{:?}", files.steps));
        assert!(memory.warnings.is_empty());
    }
}
