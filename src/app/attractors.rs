//! The jobs of `vrw orbit` (the orbit diagram along one parameter) and `vrw basin` (the basin of the gait on a
//! slice of the Poincare section): compute, write the tables and draw the figures.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Serialize;

use crate::fmt::short;
use crate::gait::basin::{basin, Axis, BasinPoint, BasinSpec, Coordinate};
use crate::gait::orbit::{orbit_diagram, OrbitColumn, OrbitSpec};
use crate::gait::{find_gait_any_period, sweep, Gait, GaitOptions, Stability, StepMap, MAX_PERIOD};
use crate::output;
use crate::output::basin_plot::{write_basin_figure, BasinFigure};
use crate::output::orbit_plot::{write_orbit_figure, BranchPoint, OrbitFigure, OrbitPanel};
use crate::params::Config;
use crate::walk::{SectionState, StepReport};

use super::{axis_label, prepared, AppError};

/// What `vrw orbit` runs.
#[derive(Debug, Clone)]
pub struct OrbitJob {
    /// Parameters and solver options (the swept key is overridden value by value).
    pub config: Config,
    /// The parameter, its values, the transient and the recorded steps.
    pub spec: OrbitSpec,
    /// Where the first walk starts (`None`: [`crate::reference::default_initial`]).
    pub initial: Option<SectionState>,
    /// Draw the period-1 branch (a sweep with continuation over the same values).
    pub branch: bool,
    /// Where `orbit.csv`, `branch.csv`, `orbit.json` and `orbit.png` go.
    pub out_dir: PathBuf,
}

/// `orbit.json`.
#[derive(Debug, Clone, Serialize)]
pub struct OrbitSummary {
    /// Version of vrw that produced the file.
    pub vrw_version: &'static str,
    /// Parameters and solver options.
    pub config: Config,
    /// What was computed.
    pub spec: OrbitSpec,
    /// Number of values whose walk settled on a period `k` (key `k`), did not settle (`none`) or failed
    /// (the failure kind).
    pub outcomes: BTreeMap<String, usize>,
    /// Values with a period-1 gait on the branch, and how many of them are stable.
    pub branch_gaits: [usize; 2],
    /// The files written.
    pub files: Vec<String>,
    /// Wall-clock seconds of the diagram and of the branch (printed, not written).
    #[serde(skip)]
    pub seconds: [f64; 2],
}

/// Run `vrw orbit`. `progress` is called after every value of the diagram.
pub fn run_orbit(
    job: &OrbitJob,
    progress: &(dyn Fn(&OrbitColumn) + Sync),
) -> Result<OrbitSummary, AppError> {
    let (_, initial) = prepared(&job.config, job.initial)?;
    job.spec.validate(&job.config)?;
    output::ensure_dir(&job.out_dir)?;
    let clock = std::time::Instant::now();
    let columns = orbit_diagram(&job.config, &job.spec, &initial, progress)?;
    let orbit_seconds = clock.elapsed().as_secs_f64();
    let param = &job.spec.range.param;
    let mut files = vec!["orbit.csv".to_string()];
    write_orbit_csv(&job.out_dir.join("orbit.csv"), param, &columns)?;
    let clock = std::time::Instant::now();
    let branch: Vec<(f64, Option<Gait>)> = if job.branch {
        sweep(
            &job.config,
            &job.spec.range,
            &initial,
            &GaitOptions::default(),
            &|_| {},
        )?
        .into_iter()
        .map(|p| (p.value, p.gait.filter(|g| g.period_k == 1)))
        .collect()
    } else {
        Vec::new()
    };
    let branch_seconds = clock.elapsed().as_secs_f64();
    if job.branch {
        write_branch_csv(&job.out_dir.join("branch.csv"), param, &branch)?;
        files.push("branch.csv".to_string());
    }
    let mut outcomes = BTreeMap::new();
    for c in &columns {
        let key = match (c.status.as_str(), c.period_k) {
            ("walking", Some(k)) => format!("period_{k}"),
            ("walking", None) => "not_settled".to_string(),
            (kind, _) => kind.to_string(),
        };
        *outcomes.entry(key).or_insert(0) += 1;
    }
    let gaits = branch.iter().filter_map(|(_, g)| g.as_ref());
    let branch_gaits = [
        gaits.clone().count(),
        gaits.filter(|g| g.stability == Stability::Stable).count(),
    ];
    let figure = orbit_figure(job, &columns, &branch);
    match write_orbit_figure(&figure, &job.out_dir.join("orbit.png")) {
        Ok(()) => files.push("orbit.png".to_string()),
        Err(crate::output::style::PlotError::Empty(_)) => {}
        Err(e) => return Err(e.into()),
    }
    files.push("orbit.json".to_string());
    let summary = OrbitSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: job.config.clone(),
        spec: job.spec.clone(),
        outcomes,
        branch_gaits,
        files,
        seconds: [orbit_seconds, branch_seconds],
    };
    output::write_json(&job.out_dir.join("orbit.json"), &summary)?;
    Ok(summary)
}

/// `orbit.csv`: one row per recorded step (its number from 1 after the transient); a value whose walk failed
/// before recording anything has one row with empty step fields.
fn write_orbit_csv(
    path: &std::path::Path,
    param: &str,
    columns: &[OrbitColumn],
) -> Result<(), AppError> {
    Ok(output::write_orbit_csv(path, param, columns)?)
}

/// `branch.csv`: the period-1 gait at each value (empty where there is none).
fn write_branch_csv(
    path: &std::path::Path,
    param: &str,
    branch: &[(f64, Option<Gait>)],
) -> Result<(), AppError> {
    Ok(output::write_branch_csv(path, param, branch)?)
}

/// The two panels of the orbit diagram: `dtheta/dt` on the section and `lambda_I4`.
fn orbit_figure(
    job: &OrbitJob,
    columns: &[OrbitColumn],
    branch: &[(f64, Option<Gait>)],
) -> OrbitFigure {
    type Pick = fn(&StepReport) -> f64;
    type OfGait = fn(&Gait) -> f64;
    let panels: [(&str, Pick, OfGait); 2] = [
        (
            "dθ/dt before touchdown [rad/s]",
            |r| r.section.theta_dot,
            |g| g.section.theta_dot,
        ),
        ("λI4 [N s]", |r| r.indicators.lambda_i4, |g| g.lambda_i4),
    ];
    let p = &job.config.params;
    let range = &job.spec.range;
    // Each failed value shades half a spacing on either side; a label per failure kind.
    let half = 0.5 * (range.to - range.from).abs() / (range.points.max(2) - 1) as f64;
    let failed = columns
        .iter()
        .filter(|c| c.status != "walking")
        .map(|c| {
            (
                (c.value - half)..(c.value + half),
                format!("walk fails: {}", c.status.replace('_', " ")),
            )
        })
        .collect();
    OrbitFigure {
        failed,
        title: format!(
            "Orbit diagram: {} steps after a transient of {}, {}impact {}",
            job.spec.steps,
            job.spec.transient,
            [
                ("viscosity", format!("c = {} N s/m, ", short(p.viscosity))),
                ("stiffness", format!("k = {} N/m, ", short(p.stiffness))),
                ("slope", format!("slope φ = {} rad, ", p.slope)),
            ]
            .into_iter()
            .filter(|(key, _)| *key != range.param)
            .map(|(_, fixed)| fixed)
            .collect::<String>(),
            p.impact
        ),
        param_label: axis_label(&range.param),
        x: range.from.min(range.to)..range.from.max(range.to),
        panels: panels
            .iter()
            .map(|(label, pick, of_gait)| OrbitPanel {
                y_label: label.to_string(),
                points: columns
                    .iter()
                    .flat_map(|c| c.returns.iter().map(move |r| (c.value, pick(r))))
                    .collect(),
                branch: branch
                    .iter()
                    .map(|(v, g)| BranchPoint {
                        param: *v,
                        value: g.as_ref().map_or(f64::NAN, of_gait),
                        stable: g.as_ref().and_then(|g| match g.stability {
                            Stability::Stable => Some(true),
                            Stability::Unstable => Some(false),
                            Stability::Uncertain => None,
                        }),
                    })
                    .collect(),
            })
            .collect(),
    }
}

/// Default range of a coordinate on the basin slice around the gait's value `at`: `L2` from `L0 / 2` to `L0`,
/// `dtheta/dt` from a twentieth of the gait's to three times it, `dL2/dt` the gait's plus and minus 1.5 m/s.
pub fn default_basin_range(config: &Config, coordinate: Coordinate, at: f64) -> (f64, f64) {
    let l0 = config.params.stopper_length;
    match coordinate {
        Coordinate::L2 => (0.5 * l0, l0),
        Coordinate::ThetaDot => (0.05 * at, 3.0 * at),
        Coordinate::L2Dot => (at - 1.5, at + 1.5),
    }
}

/// The most grid points along one axis of a basin.
pub const MAX_BASIN_POINTS: usize = 2000;

/// What `vrw basin` runs.
#[derive(Debug, Clone)]
pub struct BasinJob {
    /// Parameters and solver options.
    pub config: Config,
    /// Where the gait search starts (`None`: [`crate::reference::default_initial`]).
    pub initial: Option<SectionState>,
    /// Horizontal and vertical coordinates of the slice.
    pub coordinates: [Coordinate; 2],
    /// Their ranges (`None`: [`default_basin_range`]).
    pub ranges: [Option<(f64, f64)>; 2],
    /// Grid points along x and y.
    pub points: [usize; 2],
    /// Steps walked at most from each start.
    pub max_steps: usize,
    /// Distance to a gait state that counts as reaching it.
    pub tolerance: f64,
    /// Where `basin.csv`, `basin.json` and `basin.png` go.
    pub out_dir: PathBuf,
}

/// `basin.json`.
#[derive(Debug, Clone, Serialize)]
pub struct BasinSummary {
    /// Version of vrw that produced the file.
    pub vrw_version: &'static str,
    /// Parameters and solver options.
    pub config: Config,
    /// The slice and the rules.
    pub spec: BasinSpec,
    /// The gait whose basin it is.
    pub gait: Gait,
    /// Number of grid points per outcome.
    pub outcomes: BTreeMap<String, usize>,
    /// The files written.
    pub files: Vec<String>,
    /// Wall-clock seconds of the grid (printed, not written).
    #[serde(skip)]
    pub seconds: f64,
}

impl BasinJob {
    fn invalid(option: &'static str, reason: String) -> AppError {
        AppError::InvalidOption { option, reason }
    }

    /// Check the options that do not depend on the gait.
    fn validate(&self) -> Result<(), AppError> {
        if self.coordinates[0] == self.coordinates[1] {
            return Err(Self::invalid(
                "--x/--y",
                format!(
                    "the two axes must be different coordinates (both are {})",
                    self.coordinates[0].name()
                ),
            ));
        }
        for (option, n) in [("--nx", self.points[0]), ("--ny", self.points[1])] {
            if !(2..=MAX_BASIN_POINTS).contains(&n) {
                return Err(Self::invalid(
                    option,
                    format!("{n} grid points; use 2 to {MAX_BASIN_POINTS}"),
                ));
            }
        }
        for (option, range) in [("--x-range", self.ranges[0]), ("--y-range", self.ranges[1])] {
            if let Some((a, b)) = range {
                if !(a.is_finite() && b.is_finite() && a != b) {
                    return Err(Self::invalid(
                        option,
                        format!(
                            "{},{} is not a range with two different finite ends",
                            short(a),
                            short(b)
                        ),
                    ));
                }
            }
        }
        if !(1..=100_000).contains(&self.max_steps) {
            return Err(Self::invalid(
                "--max-steps",
                format!("{} steps; use 1 to 100000", self.max_steps),
            ));
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(Self::invalid(
                "--tolerance",
                format!("{} is not a positive distance", short(self.tolerance)),
            ));
        }
        Ok(())
    }
}

/// Run `vrw basin`: find the gait (any period up to 8), walk from every grid point of the slice through it,
/// write `basin.csv`, `basin.json` and `basin.png`. `progress` is called after every grid point.
pub fn run_basin(
    job: &BasinJob,
    progress: &(dyn Fn(&BasinPoint) + Sync),
) -> Result<BasinSummary, AppError> {
    job.validate()?;
    let (model, initial) = prepared(&job.config, job.initial)?;
    let map = StepMap::new(&model, &job.config.solver);
    let gait =
        find_gait_any_period(&map, &initial, &GaitOptions::default(), MAX_PERIOD).map_err(|e| {
            AppError::InvalidOption {
                option: "basin",
                reason: format!("no gait to draw the basin of: {e}"),
            }
        })?;
    let through = gait.section.to_array();
    let axis = |k: usize| {
        let c = job.coordinates[k];
        let (from, to) = job.ranges[k]
            .unwrap_or_else(|| default_basin_range(&job.config, c, through[c.index()]));
        Axis {
            coordinate: c,
            from,
            to,
            points: job.points[k],
        }
    };
    let spec = BasinSpec {
        x: axis(0),
        y: axis(1),
        through: gait.section,
        max_steps: job.max_steps,
        tolerance: job.tolerance,
    };
    output::ensure_dir(&job.out_dir)?;
    let clock = std::time::Instant::now();
    let grid = basin(&model, &job.config.solver, &gait, &spec, progress);
    let seconds = clock.elapsed().as_secs_f64();
    let mut outcomes = BTreeMap::new();
    for p in grid.iter().flatten() {
        *outcomes.entry(p.outcome.kind.clone()).or_insert(0) += 1;
    }
    write_basin_csv(&job.out_dir.join("basin.csv"), &grid)?;
    let (cx, cy) = (spec.x.coordinate.index(), spec.y.coordinate.index());
    let figure = BasinFigure {
        title: format!(
            "Basin of the {}gait on the slice {} = {:.4} (c = {} N s/m, slope φ = {} rad, impact {})",
            if gait.period_k > 1 {
                format!("period-{} ", gait.period_k)
            } else {
                String::new()
            },
            Coordinate::ALL[3 - cx - cy].name(),
            through[3 - cx - cy],
            job.config.params.viscosity,
            job.config.params.slope,
            job.config.params.impact
        ),
        x_label: spec.x.coordinate.label().to_string(),
        y_label: spec.y.coordinate.label().to_string(),
        xs: (0..spec.x.points).map(|i| spec.x.value(i)).collect(),
        ys: (0..spec.y.points).map(|i| spec.y.value(i)).collect(),
        outcomes: grid
            .iter()
            .map(|row| row.iter().map(|p| p.outcome.kind.clone()).collect())
            .collect(),
        gait: gait
            .cycle
            .iter()
            .map(|r| {
                let a = r.section.to_array();
                (a[cx], a[cy])
            })
            .collect(),
    };
    write_basin_figure(&figure, &job.out_dir.join("basin.png"))?;
    let summary = BasinSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: job.config.clone(),
        spec,
        gait,
        outcomes,
        files: ["basin.csv", "basin.png", "basin.json"]
            .map(String::from)
            .to_vec(),
        seconds,
    };
    output::write_json(&job.out_dir.join("basin.json"), &summary)?;
    Ok(summary)
}

/// `basin.csv`: one row per grid point.
fn write_basin_csv(path: &std::path::Path, grid: &[Vec<BasinPoint>]) -> Result<(), AppError> {
    Ok(output::write_basin_csv(path, grid)?)
}
