//! Reading a run directory back: what `vrw simulate` (or `vrw gait`) wrote, for the figures and the
//! animation.
//!
//! Columns are found by their header name, never by position, and extra columns are ignored, so files from a
//! newer vrw with more columns still read. Missing files or columns are errors that name the file and the
//! column.

use std::fs::File;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer, Serialize};

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

/// One row of `trajectory.csv` (docs/model.md section 1: `q = [x, z, theta, L1, L2]`, slope frame).
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
    /// Leg 1 is held on its stopper.
    #[serde(deserialize_with = "flag")]
    pub lock1: bool,
    /// Leg 2 is held on its stopper.
    #[serde(deserialize_with = "flag")]
    pub lock2: bool,
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
    pub fn mode(&self) -> (bool, bool, bool, bool, bool, bool, usize) {
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
pub(crate) fn read_csv<T: DeserializeOwned>(
    path: &Path,
    allow_empty: bool,
) -> Result<Vec<T>, ReadError> {
    let csv_err = |source| ReadError::Csv {
        path: path.to_path_buf(),
        source,
    };
    let file = File::open(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut reader = csv::Reader::from_reader(std::io::BufReader::new(file));
    let rows = reader
        .deserialize()
        .collect::<Result<Vec<T>, _>>()
        .map_err(csv_err)?;
    if rows.is_empty() && !allow_empty {
        return Err(ReadError::Empty {
            path: path.to_path_buf(),
        });
    }
    Ok(rows)
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
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|source| ReadError::Json {
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
    let geometry = Geometry {
        legs,
        stopper_length: number("stopper_length")?,
        spring_natural_length: number("spring_natural_length")?,
        leg_mass_offset: number("leg_mass_offset")?,
        slope: number("slope")?,
        viscosity: number("viscosity")?,
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
    let samples: Vec<TrajectoryRow> = read_csv(&trajectory_path, false)?;
    let mut last = f64::NEG_INFINITY;
    for (k, s) in samples.iter().enumerate() {
        if !(s.time.is_finite() && s.time >= last) {
            return Err(ReadError::Unordered {
                path: trajectory_path,
                row: k + 1,
                time: s.time,
            });
        }
        last = s.time;
    }
    // A walk that stopped during its first step has no step rows, but its trajectory can still be shown.
    let steps: Vec<StepRow> = read_csv(&steps_path, true)?;
    Ok(RunData {
        dir: dir.to_path_buf(),
        geometry,
        status,
        samples,
        steps,
    })
}
