//! `vrw orbit --model NAME --param KEY`: a walker's orbit diagram, as the wheel's (docs/model.md section 6): at
//! each value of the parameter the walker walks `transient` steps, then `steps` recorded ones, each value
//! starting from where its neighbour's walk ended (the shared grid runner's schedule), so that the diagram
//! follows an attractor and period doubling cascades show as branches splitting in two, four, ... The
//! period-1 gaits of [`super::walker_sweep`] are drawn beside it (solid where stable, dashed where not).
//! `orbit.csv` (a row per recorded step: the value, the status, the period of the returns, the section named
//! by the model, `lambda_I4`, the step's duration), `branch.csv`, `orbit.json` and `orbit.png`. Written once
//! for every walker, on [`super::WalkerModel`].

use std::collections::BTreeMap;
use std::path::PathBuf;

use nalgebra::DVector;
use serde::Serialize;

use super::walker_model::WalkerError;
use super::walker_model::WalkerStep;
use super::walker_output::{write_rows, WalkerOutput};
use super::walker_sweep::{walker_gaits, WalkerRange, WalkerSweepPoint};
use super::walkers::Walker;
use super::{check_interrupted, check_phase_interrupted, in_run_on, AppError, NOTHING_WRITTEN};
use crate::output;
use crate::output::orbit_plot::{write_orbit_figure, BranchPoint, OrbitFigure, OrbitPanel};
use crate::study::grid::{run_rows, Evaluated};
use crate::study::orbit::{
    FRESH_TRANSIENT_FACTOR, MAX_ORBIT_STEPS, MAX_ORBIT_VALUES, MAX_ORBIT_WALKED_STEPS, PERIOD_TOL,
};

/// The longest period the diagram names (as the wheel's).
pub const MAX_WALKER_PERIOD: usize = 16;

/// What `vrw orbit --model NAME` runs.
#[derive(Debug, Clone)]
pub struct WalkerOrbitJob {
    /// The walker (the parameter is set value by value).
    pub walker: Walker,
    /// The parameter and its values.
    pub range: WalkerRange,
    /// Steps walked at each value before recording (`FRESH_TRANSIENT_FACTOR` times as many where a walk
    /// starts afresh).
    pub transient: usize,
    /// Steps recorded at each value.
    pub steps: usize,
    /// Where the first walk starts (the section's coordinates); default the model's start.
    pub initial: Option<Vec<f64>>,
    /// Compute and draw the period-1 branch.
    pub branch: bool,
    /// Output directory.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir`.
    pub overwrite: bool,
}

impl WalkerOrbitJob {
    /// The values, after every option is checked as the wheel's orbit checks them.
    fn values(&self) -> Result<Vec<f64>, AppError> {
        let values = self.range.values(&self.walker, MAX_ORBIT_VALUES)?;
        let bad = |option, reason: String| Err(AppError::InvalidOption { option, reason });
        if !(1..=MAX_ORBIT_STEPS).contains(&self.steps) {
            return bad(
                "steps",
                format!("{} is not between 1 and {MAX_ORBIT_STEPS}", self.steps),
            );
        }
        if self.transient > MAX_ORBIT_STEPS {
            return bad(
                "transient",
                format!("{} is more than {MAX_ORBIT_STEPS}", self.transient),
            );
        }
        let walked = values
            .len()
            .saturating_mul(self.transient.saturating_add(self.steps));
        if walked > MAX_ORBIT_WALKED_STEPS {
            return bad(
                "points",
                format!("points x (transient + steps) = {walked} steps; orbit walks at most {MAX_ORBIT_WALKED_STEPS}"),
            );
        }
        Ok(values)
    }
}

/// The walk at one value.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkerOrbitColumn {
    /// The value.
    pub value: f64,
    /// `walking`, `invalid_parameter`, or the failure's kind.
    pub status: &'static str,
    /// The failure in words.
    pub message: Option<String>,
    /// The recorded steps: the section state at each step's start and the step.
    pub returns: Vec<(DVector<f64>, WalkerStep)>,
    /// The least period of the returns (to the wheel's tolerance), up to [`MAX_WALKER_PERIOD`].
    pub period_k: Option<usize>,
    /// The value whose end state this walk started from.
    pub continued_from: Option<f64>,
}

/// The least `k` with which `returns` repeat to `tol` (largest coordinate difference), up to `max`.
pub(super) fn least_period(returns: &[DVector<f64>], max: usize, tol: f64) -> Option<usize> {
    (1..=max.min(returns.len().saturating_sub(1))).find(|&k| {
        returns
            .iter()
            .zip(&returns[k..])
            .all(|(a, b)| (a - b).amax() < tol)
    })
}

/// The walk at `value` from `start` (`from`: the value it continues), and where it ended.
fn walk_column(
    job: &WalkerOrbitJob,
    value: f64,
    (start, from): (&DVector<f64>, Option<f64>),
) -> (WalkerOrbitColumn, Option<DVector<f64>>) {
    let mut column = WalkerOrbitColumn {
        value,
        status: "walking",
        message: None,
        returns: Vec::with_capacity(job.steps),
        period_k: None,
        continued_from: from,
    };
    let walker = match job.walker.with_parameter(&job.range.param, value) {
        Ok(w) => w,
        Err(e) => {
            column.status = "invalid_parameter";
            column.message = Some(e.to_string());
            return (column, None);
        }
    };
    let model = match walker.model() {
        Ok(model) => model,
        Err(e) => {
            column.status = "invalid_model";
            column.message = Some(e.to_string());
            return (column, None);
        }
    };
    let transient = match from {
        Some(_) => job.transient,
        None => FRESH_TRANSIENT_FACTOR * job.transient,
    };
    let mut s = start.clone();
    let walked: Result<(), WalkerError> = (|| {
        for _ in 0..transient {
            s = model.step(&s, None)?.section;
        }
        for _ in 0..job.steps {
            let step = model.step(&s, None)?;
            let next = step.section.clone();
            column.returns.push((std::mem::replace(&mut s, next), step));
        }
        Ok(())
    })();
    match walked {
        Ok(()) => {
            let sections: Vec<DVector<f64>> = column.returns.iter().map(|r| r.0.clone()).collect();
            column.period_k = least_period(&sections, MAX_WALKER_PERIOD, PERIOD_TOL);
            (column, Some(s))
        }
        Err(e) => {
            column.status = e.kind();
            column.message = Some(e.to_string());
            (column, None)
        }
    }
}

/// `orbit.json` of a walker.
#[derive(Debug, Clone, Serialize)]
pub struct WalkerOrbitSummary {
    /// vrw's version.
    pub vrw_version: &'static str,
    /// The model's name.
    pub model: String,
    /// Its parameters.
    pub parameters: Walker,
    /// The range.
    pub range: WalkerRange,
    /// Steps walked before recording.
    pub transient: usize,
    /// Steps recorded.
    pub steps: usize,
    /// Values whose walk settled on a period `k` (`period_k`), did not settle (`not_settled`) or failed.
    pub outcomes: BTreeMap<String, usize>,
    /// Values with a period-1 gait on the branch, and how many of them are stable.
    pub branch_gaits: [usize; 2],
    /// The files written.
    pub files: Vec<String>,
}

/// Draw `job.walker`'s orbit diagram and write its files, after the options and the output directory are
/// checked.
pub fn run_walker_orbit(job: &WalkerOrbitJob) -> Result<WalkerOrbitSummary, AppError> {
    let values = job.values()?;
    let model = job.walker.model()?;
    let start = super::walkers::start_of(model.as_ref(), job.initial.as_deref())?;
    let names = model.section_names();
    output::manifest::check_out_dir(&job.out_dir, "orbit", job.overwrite)?;
    in_run_on(
        &job.out_dir,
        job.overwrite,
        ("orbit", Some(job.walker.name())),
        |run| {
            let columns = diagram(job, &values, &start);
            write_rows(
                &run.path("orbit.csv"),
                &orbit_rows(&job.range.param, &names, &columns),
            )?;
            run.add("orbit.csv");
            check_interrupted(columns.len(), values.len(), "orbit.csv")?;
            let mut files = vec!["orbit.csv".to_string()];
            let branch = match job.branch {
                true => walker_gaits(&job.walker, &job.range.param, &values, &start),
                false => Vec::new(),
            };
            if job.branch {
                write_rows(
                    &run.path("branch.csv"),
                    &branch_rows(&job.range.param, &names, &branch),
                )?;
                run.add("branch.csv");
                files.push("branch.csv".to_string());
                check_interrupted(
                    branch.len(),
                    values.len(),
                    "branch.csv (and orbit.csv, complete)",
                )?;
            }
            let figure = orbit_figure(job, (&names[0], model.name()), &columns, &branch);
            match write_orbit_figure(&figure, &run.path("orbit.png")) {
                Ok(()) => {
                    run.add("orbit.png");
                    files.push("orbit.png".to_string());
                }
                Err(crate::output::style::PlotError::Empty(_)) => {}
                Err(e) => return Err(e.into()),
            }
            files.push("orbit.json".to_string());
            let summary = summary(job, model.name(), &columns, &branch, files);
            output::write_json(&run.path("orbit.json"), &summary)?;
            run.add("orbit.json");
            Ok((summary, None))
        },
    )
}

/// The orbit diagram of [`run_walker_orbit`] without its files and figure (the Python binding): `orbit.json`'s
/// fields (`files` the tables') and the rows of `orbit.csv` and, with `job.branch`, `branch.csv` (`job.out_dir`
/// and `job.overwrite` are not read). Ctrl-C: an error, nothing kept.
pub fn compute_walker_orbit(
    job: &WalkerOrbitJob,
) -> Result<WalkerOutput<WalkerOrbitSummary>, AppError> {
    let values = job.values()?;
    let model = job.walker.model()?;
    let start = super::walkers::start_of(model.as_ref(), job.initial.as_deref())?;
    let names = model.section_names();
    let columns = diagram(job, &values, &start);
    check_phase_interrupted(None, "while walking the diagram", NOTHING_WRITTEN)?;
    let mut tables = vec![("orbit.csv", orbit_rows(&job.range.param, &names, &columns))];
    let branch = match job.branch {
        true => walker_gaits(&job.walker, &job.range.param, &values, &start),
        false => Vec::new(),
    };
    check_phase_interrupted(None, "while searching the branch", NOTHING_WRITTEN)?;
    if job.branch {
        tables.push(("branch.csv", branch_rows(&job.range.param, &names, &branch)));
    }
    let files = tables.iter().map(|(name, _)| name.to_string()).collect();
    let summary = summary(job, model.name(), &columns, &branch, files);
    Ok(WalkerOutput { summary, tables })
}

/// The walks of the diagram at `values`, each from where its neighbour's ended (the first from `start`);
/// cut to their complete prefix by Ctrl-C.
fn diagram(job: &WalkerOrbitJob, values: &[f64], start: &DVector<f64>) -> Vec<WalkerOrbitColumn> {
    run_rows(1, values.len(), |cell, from| {
        let (start, from) = match from {
            Some((col, end)) => (end, Some(values[col])),
            None => (start, None),
        };
        let (point, carry) = walk_column(job, values[cell.col], (start, from));
        Evaluated { point, carry }
    })
    .into_iter()
    .next()
    .unwrap_or_default()
}

/// `orbit.json`'s fields.
fn summary(
    job: &WalkerOrbitJob,
    model: &str,
    columns: &[WalkerOrbitColumn],
    branch: &[WalkerSweepPoint],
    files: Vec<String>,
) -> WalkerOrbitSummary {
    let mut outcomes = BTreeMap::new();
    for c in columns {
        let key = match (c.status, c.period_k) {
            ("walking", Some(k)) => format!("period_{k}"),
            ("walking", None) => "not_settled".to_string(),
            (failed, _) => failed.to_string(),
        };
        *outcomes.entry(key).or_insert(0) += 1;
    }
    WalkerOrbitSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        model: model.to_string(),
        parameters: job.walker.clone(),
        range: job.range.clone(),
        transient: job.transient,
        steps: job.steps,
        outcomes,
        branch_gaits: [
            branch.iter().filter(|p| p.gait.is_ok()).count(),
            branch.iter().filter(|p| p.status() == "stable").count(),
        ],
        files,
    }
}

/// The rows of a walker's `orbit.csv`, its header first.
fn orbit_rows(param: &str, names: &[String], columns: &[WalkerOrbitColumn]) -> Vec<Vec<String>> {
    let mut header = vec![
        param.to_string(),
        "status".into(),
        "period_k".into(),
        "step".into(),
    ];
    header.extend(names.iter().cloned());
    header.extend(["lambda_I4", "period", "continued_from", "message"].map(String::from));
    let mut rows = vec![header];
    for c in columns {
        let head = |step: String| {
            vec![
                output::num(c.value),
                c.status.to_string(),
                c.period_k.map_or(String::new(), |k| k.to_string()),
                step,
            ]
        };
        let from = c.continued_from.map_or(String::new(), output::num);
        for (k, (s, step)) in c.returns.iter().enumerate() {
            let mut row = head((k + 1).to_string());
            row.extend(s.iter().map(|v| output::num(*v)));
            row.extend([
                output::num(step.lambda_i4),
                output::num(step.period),
                from.clone(),
                String::new(),
            ]);
            rows.push(row);
        }
        if c.returns.is_empty() {
            let mut row = head(String::new());
            row.extend(std::iter::repeat_n(String::new(), names.len() + 2));
            row.extend([from, c.message.clone().unwrap_or_default()]);
            rows.push(row);
        }
    }
    rows
}

/// The rows of a walker's `branch.csv` (the period-1 gait at each value), its header first.
fn branch_rows(param: &str, names: &[String], branch: &[WalkerSweepPoint]) -> Vec<Vec<String>> {
    let mut header = vec![param.to_string()];
    header.extend(names.iter().cloned());
    header.extend(["lambda_I4", "period", "max_floquet", "stability"].map(String::from));
    let rows = branch.iter().filter_map(|p| {
        let g = p.gait.as_ref().ok()?;
        let mut row = vec![output::num(p.value)];
        row.extend(g.section.iter().map(|v| output::num(*v)));
        row.extend([g.step.lambda_i4, g.step.period, g.largest_multiplier()].map(output::num));
        row.push(p.status().to_string());
        Some(row)
    });
    std::iter::once(header).chain(rows).collect()
}

/// The diagram: the section's first coordinate (`first`: its name) and `lambda_I4` of every recorded step
/// against the parameter, with the branch and the failed values shaded.
fn orbit_figure(
    job: &WalkerOrbitJob,
    (first, model): (&str, &str),
    columns: &[WalkerOrbitColumn],
    branch: &[WalkerSweepPoint],
) -> OrbitFigure {
    let r = &job.range;
    let half = 0.5 * (r.to - r.from).abs() / (r.points.max(2) - 1) as f64;
    let panel = |label: String, pick: fn(&DVector<f64>, &WalkerStep) -> f64| OrbitPanel {
        y_label: label,
        points: columns
            .iter()
            .flat_map(|c| {
                c.returns
                    .iter()
                    .map(move |(s, step)| (c.value, pick(s, step)))
            })
            .collect(),
        branch: branch
            .iter()
            .map(|p| BranchPoint {
                param: p.value,
                value: p
                    .gait
                    .as_ref()
                    .map_or(f64::NAN, |g| pick(&g.section, &g.step)),
                stable: p.gait.as_ref().ok().map(|g| g.largest_multiplier() < 1.0),
            })
            .collect(),
    };
    let others: Vec<String> = non_default_parameters(&job.walker)
        .into_iter()
        .filter(|(k, _)| *k != r.param)
        .map(|(k, v)| format!("{k} = {v}"))
        .collect();
    OrbitFigure {
        title: format!(
            "Orbit diagram of the {model} walker: {} steps after a transient of {}{}",
            job.steps,
            job.transient,
            if others.is_empty() {
                String::new()
            } else {
                format!(" [{}]", others.join(", "))
            }
        ),
        param_label: super::axis_label(&r.param),
        x: r.from.min(r.to)..r.from.max(r.to),
        panels: vec![
            panel(format!("{first} after heel strike"), |s, _| s[0]),
            panel("λI4 at heel strike".to_string(), |_, step| step.lambda_i4),
        ],
        failed: columns
            .iter()
            .filter(|c| c.status != "walking")
            .map(|c| {
                (
                    (c.value - half)..(c.value + half),
                    format!("walk fails: {}", c.status.replace('_', " ")),
                )
            })
            .collect(),
    }
}

/// The parameters of `walker` that differ from its model's defaults (a figure's title names them).
pub(super) fn non_default_parameters(walker: &Walker) -> Vec<(String, f64)> {
    let defaults: Vec<(String, f64)> = match walker {
        Walker::Simplest(_) => serde_pairs(&Walker::Simplest(Default::default())),
        Walker::Compass(_) => serde_pairs(&Walker::Compass(Default::default())),
        Walker::Telescopic(_) => serde_pairs(&Walker::Telescopic(Default::default())),
        Walker::Described(w) => w
            .description()
            .parameters
            .iter()
            .map(|p| (p.name.to_string(), p.default))
            .collect(),
    };
    let now = match walker {
        Walker::Described(w) => w
            .parameters()
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
        _ => serde_pairs(walker),
    };
    now.into_iter()
        .filter(|(k, v)| !defaults.iter().any(|(dk, dv)| dk == k && dv == v))
        .collect()
}

/// A built-in walker's parameters as `(key, value)` pairs, from its serialization.
fn serde_pairs(walker: &Walker) -> Vec<(String, f64)> {
    serde_json::to_value(walker)
        .ok()
        .and_then(|v| v.as_object().cloned())
        .into_iter()
        .flatten()
        .filter_map(|(k, v)| v.as_f64().map(|v| (k, v)))
        .collect()
}
