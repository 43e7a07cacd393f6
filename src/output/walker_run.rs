//! A walker's run (`vrw simulate --model NAME`) as its files hold it: what its drawing shows ([`StickFigure`],
//! declared in `summary.json`), the columns of its `trajectory.csv` and `steps.csv`, and the run read back for
//! `vrw plot` and `vrw animate` ([`read_walker_run`]).
//!
//! `trajectory.csv` names everything by the model: `time`, `step`, `stance_x` (the stance foot's place along
//! the slope), the coordinates and their rates (`theta`, `theta_dot`, ...), `kinetic`, `potential`, `energy`,
//! and each point of the drawing in the slope frame (`hip_x`, `hip_z`, ...; `x` down the slope, `z` normal to
//! it), so that a drawing needs nothing of the model but the figure in `summary.json`.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::read::ReadError;
use crate::mechanism::legged::impact::Branch;
use crate::mechanism::legged::walk::StepAccount;

/// What a drawing of a walker shows: named points, the links between them (legs), which points are masses
/// (dots) and which are feet. The first link is the stance leg, the second the swing leg; they exchange roles
/// at every heel strike, so a drawing that colours a physical leg alternates with the step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StickFigure {
    /// The points' names (`stance_foot`, `hip`, ...), the columns `NAME_x`, `NAME_z` of `trajectory.csv`.
    pub points: Vec<String>,
    /// Links `[from, to]` between points (indices in `points`): the legs.
    pub links: Vec<[usize; 2]>,
    /// The points that carry mass, drawn as dots.
    pub masses: Vec<usize>,
    /// The feet.
    pub feet: Vec<usize>,
    /// Springs (with their dampers) `[from, to]` between points, drawn as coils; the first and every other one
    /// on the stance leg, as the links. None for rigid legs (and then not written).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub springs: Vec<[usize; 2]>,
}

impl StickFigure {
    /// Two legs from the hip: the points `stance_foot`, `hip`, `swing_foot`, then `leg_masses` (on the stance
    /// and swing leg); the hip and the leg masses are masses.
    pub fn legs_from_hip(leg_masses: &[&str]) -> StickFigure {
        let points: Vec<String> = ["stance_foot", "hip", "swing_foot"]
            .iter()
            .chain(leg_masses)
            .map(|p| p.to_string())
            .collect();
        StickFigure {
            links: vec![[1, 0], [1, 2]],
            masses: std::iter::once(1).chain(3..points.len()).collect(),
            feet: vec![0, 2],
            points,
            springs: Vec::new(),
        }
    }

    /// Two telescopic legs from the hip: the points `stance_foot`, `hip`, `swing_foot`, each leg's sleeve end
    /// (where its mass is: `stance_leg_mass`, `swing_leg_mass`) and the top of its sliding rod
    /// (`stance_rod_top`, `swing_rod_top`); the sleeves from the hip and the rods to the feet are links, the
    /// spring and damper of each leg joins its sleeve's end to its rod's top.
    pub fn telescopic_legs() -> StickFigure {
        let points = [
            "stance_foot",
            "hip",
            "swing_foot",
            "stance_leg_mass",
            "swing_leg_mass",
            "stance_rod_top",
            "swing_rod_top",
        ];
        StickFigure {
            points: points.iter().map(|p| p.to_string()).collect(),
            links: vec![[1, 3], [1, 4], [5, 0], [6, 2]],
            masses: vec![1, 3, 4],
            feet: vec![0, 2],
            springs: vec![[3, 5], [4, 6]],
        }
    }

    /// The columns of the points in `trajectory.csv`.
    pub fn point_columns(&self) -> Vec<String> {
        self.points
            .iter()
            .flat_map(|p| [format!("{p}_x"), format!("{p}_z")])
            .collect()
    }
}

/// The header of a walker's `trajectory.csv` for the coordinates `coordinates` and the drawing `figure`.
pub fn walker_trajectory_header(coordinates: &[String], figure: &StickFigure) -> Vec<String> {
    ["time", "step", "stance_x"]
        .iter()
        .map(|c| c.to_string())
        .chain(coordinates.iter().cloned())
        .chain(coordinates.iter().map(|c| format!("{c}_dot")))
        .chain(["kinetic", "potential", "energy"].map(String::from))
        .chain(figure.point_columns())
        .collect()
}

/// The columns a walker with compliant legs adds to `steps.csv` (named as the wheel's), in the order of
/// [`legged_step_values`].
pub const LEGGED_STEP_COLUMNS: [&str; 11] = [
    "lambda_2_plus",
    "lambda_4_plus",
    "branch",
    "dls_duration",
    "rear_contact_duration",
    "stopper_loss",
    "landing_loss",
    "damper_loss",
    "energy_residual",
    "penetration",
    "events",
];

/// A heel strike's branch as the outputs write it (`DLS`, `SLS`, `SLS_B3`, `BOUNCE`: its serialization).
pub fn branch_text(branch: Branch) -> String {
    serde_json::to_value(branch)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// The values of [`LEGGED_STEP_COLUMNS`] of a step's account (an indicator not defined on its branch empty).
pub fn legged_step_values(a: &StepAccount) -> [String; 11] {
    let maybe = |v: Option<f64>| v.map_or(String::new(), super::num);
    [
        maybe(a.lambda_2_plus),
        maybe(a.lambda_4_plus),
        branch_text(a.branch),
        super::num(a.dls_duration),
        super::num(a.rear_contact_duration),
        super::num(a.losses.stoppers),
        super::num(a.losses.landings),
        super::num(a.damper_work),
        super::num(a.energy_residual),
        super::num(a.penetration),
        a.events.to_string(),
    ]
}

/// The header of a walker's `steps.csv` for the section's coordinates `section` (the state at the step's
/// start), with [`LEGGED_STEP_COLUMNS`] for a walker with compliant legs (`legged`).
pub fn walker_steps_header(section: &[String], legged: bool) -> Vec<String> {
    ["step", "time"]
        .iter()
        .map(|c| c.to_string())
        .chain(section.iter().cloned())
        .chain(
            [
                "period",
                "stride",
                "speed",
                "lambda_I4",
                "impact_loss",
                "energy_start",
                "energy_drift",
                "scuffs",
            ]
            .map(String::from),
        )
        .chain(
            LEGGED_STEP_COLUMNS
                .iter()
                .filter(|_| legged)
                .map(|c| c.to_string()),
        )
        .collect()
}

/// What the drawings read of a walker run's `summary.json`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct WalkerRunInfo {
    /// The model's name.
    pub model: String,
    /// The slope \[rad\].
    pub slope: f64,
    /// The model's coordinates.
    pub coordinates: Vec<String>,
    /// What the drawing shows.
    pub figure: StickFigure,
    /// How the walk ended.
    pub status: String,
}

/// A walker's run read back.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkerRun {
    /// The directory.
    pub dir: PathBuf,
    /// Its `summary.json`.
    pub info: WalkerRunInfo,
    /// `trajectory.csv`'s header.
    pub columns: Vec<String>,
    /// Its complete rows.
    pub rows: Vec<Vec<f64>>,
    /// What was left out (an incomplete last row).
    pub warnings: Vec<String>,
}

impl WalkerRun {
    /// The column `name` of the trajectory, if it has it.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r[k]).collect())
    }

    /// The time span of the trajectory.
    pub fn time_span(&self) -> (f64, f64) {
        let t = |r: Option<&Vec<f64>>| r.map_or(0.0, |r| r[0]);
        (t(self.rows.first()), t(self.rows.last()))
    }

    /// The drawing's points at row `k`: `(x, z)` in the slope frame.
    pub fn points_at(&self, k: usize) -> Vec<[f64; 2]> {
        let first = self.columns.len() - 2 * self.info.figure.points.len();
        self.rows[k][first..]
            .chunks(2)
            .map(|p| [p[0], p[1]])
            .collect()
    }

    /// The step number at row `k`.
    pub fn step_at(&self, k: usize) -> usize {
        self.rows[k][1] as usize
    }
}

/// Does `dir` hold a walker's run (its `summary.json` or `gait.json` names a model other than the wheel)? The
/// model's name if so.
pub fn walker_model_of(dir: &Path) -> Option<String> {
    ["summary.json", "gait.json"].iter().find_map(|f| {
        let text = std::fs::read_to_string(dir.join(f)).ok()?;
        let value: serde_json::Value = serde_json::from_str(&text).ok()?;
        Some(value.get("model")?.as_str()?.to_string()).filter(|m| m != "vrw")
    })
}

/// Read the walker run in `dir`: `summary.json` and the complete rows of `trajectory.csv` (a last row cut
/// short by a killed run is left out, with a warning).
pub fn read_walker_run(dir: &Path) -> Result<WalkerRun, ReadError> {
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
    let summary = file("summary.json")?;
    let text = std::fs::read_to_string(&summary).map_err(|source| ReadError::Io {
        path: summary.clone(),
        source,
    })?;
    let info: WalkerRunInfo = serde_json::from_str(&text).map_err(|source| ReadError::Json {
        path: summary.clone(),
        source,
    })?;
    let trajectory = file("trajectory.csv")?;
    let table = read_numbers(&trajectory)?;
    walker_run(dir, info, table, trajectory)
}

/// The walker run of `info` (its `summary.json`) with the trajectory `table` (read from `trajectory`, named in
/// errors), checked: the header is the one the model writes, and it has rows.
fn walker_run(
    dir: &Path,
    info: WalkerRunInfo,
    (columns, rows, warnings): NumericTable,
    trajectory: PathBuf,
) -> Result<WalkerRun, ReadError> {
    let expected = walker_trajectory_header(&info.coordinates, &info.figure);
    if columns != expected {
        return Err(ReadError::Csv {
            path: trajectory,
            source: csv::Error::from(std::io::Error::other(format!(
                "its header is not the one summary.json's model `{}` writes ({})",
                info.model,
                expected.join(",")
            ))),
        });
    }
    if rows.is_empty() {
        return Err(ReadError::Empty { path: trajectory });
    }
    Ok(WalkerRun {
        dir: dir.to_path_buf(),
        info,
        columns,
        rows,
        warnings,
    })
}

/// A walker's run computed in memory, as [`read_walker_run`] reads it from the files `vrw simulate --model`
/// writes for it, without files (a front that draws a walk it has just computed, such as the Python binding):
/// `summary` (the fields of `summary.json`) goes through its JSON text, `trajectory` (the rows of
/// `trajectory.csv`, its header first, each cell the text the file holds) is read as the file's cells are, so
/// a drawing of it is the one of the directory, bit for bit. The paths named in errors are the bare file
/// names.
pub fn walker_run_from_walk<S: Serialize>(
    summary: &S,
    trajectory: &[Vec<String>],
) -> Result<WalkerRun, ReadError> {
    let path = PathBuf::from("summary.json");
    let json = |source| ReadError::Json {
        path: path.clone(),
        source,
    };
    let text = serde_json::to_string(summary).map_err(json)?;
    let info: WalkerRunInfo = serde_json::from_str(&text).map_err(json)?;
    let empty = Vec::new();
    let (header, cells) = trajectory.split_first().unwrap_or((&empty, &[]));
    // The rows as the file's reader takes them: complete rows of numbers (a walk computed in memory has no
    // other).
    let rows = cells
        .iter()
        .map_while(|r| {
            let values: Option<Vec<f64>> = r.iter().map(|v| v.parse::<f64>().ok()).collect();
            values.filter(|v| v.len() == header.len())
        })
        .collect();
    let table = (header.to_vec(), rows, Vec::new());
    walker_run(Path::new(""), info, table, PathBuf::from("trajectory.csv"))
}

/// A CSV file's header, complete numeric rows, and warnings about the rows left out.
type NumericTable = (Vec<String>, Vec<Vec<f64>>, Vec<String>);

/// The header and the complete numeric rows of the CSV file `path`; a last row with too few fields or a
/// value that is no number (a killed run's) is left out with a warning.
fn read_numbers(path: &Path) -> Result<NumericTable, ReadError> {
    let csv_error = |source| ReadError::Csv {
        path: path.to_path_buf(),
        source,
    };
    let mut reader = csv::ReaderBuilder::new()
        .flexible(true)
        .from_path(path)
        .map_err(csv_error)?;
    let columns: Vec<String> = reader
        .headers()
        .map_err(csv_error)?
        .iter()
        .map(String::from)
        .collect();
    let mut rows = Vec::new();
    let mut warnings = Vec::new();
    for (k, record) in reader.records().enumerate() {
        let record = record.map_err(csv_error)?;
        let values: Option<Vec<f64>> = record.iter().map(|v| v.parse::<f64>().ok()).collect();
        match values.filter(|v| v.len() == columns.len()) {
            Some(v) => rows.push(v),
            None => {
                warnings.push(format!(
                    "{}: data row {} is incomplete and left out",
                    path.display(),
                    k + 1
                ));
                break;
            }
        }
    }
    Ok((columns, rows, warnings))
}
