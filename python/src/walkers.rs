//! The walkers other than the wheel from Python (`vrw.Params(model=...)`, docs/model.md section 13): their
//! parameters, loaded and validated by the library as `--model NAME --config FILE --set key=value` loads them,
//! and the library's walker jobs (`vrw::app::compute_walker_*`, the jobs of `vrw gait`, `simulate`, `sweep`,
//! `continue`, `orbit`, `map` and `basin --model NAME` without their files) with their results converted at
//! the edge: the fields of their JSON files, and their CSV files' rows as tables keyed by the same header.

use std::path::{Path, PathBuf};

use numpy::{Complex64, IntoPyArray};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt};
use pythonize::pythonize;

use vrw::app::{
    compute_walker_basin, compute_walker_continuation, compute_walker_gait, compute_walker_map,
    compute_walker_orbit, compute_walker_simulate, compute_walker_sweep, AppError, SliceGrid,
    Walker, WalkerBasinJob, WalkerContinueJob, WalkerGaitJob, WalkerMapJob, WalkerOrbitJob,
    WalkerOutput, WalkerRange, WalkerSimulateJob, WalkerSweepJob, MAX_WALKER_SWEEP_POINTS,
};
use vrw::gait::GaitOptions;
use vrw::mechanism::described;
use vrw::output::Cell;
use vrw::params::ConfigError as LibConfigError;
use vrw::study::{MapSpec, SweepSpec};

use crate::progress::{interruptible_keeping, interruptible_with, keeping_partial, Progress};
use crate::{app_error, config_error, count, interruptible, table};

/// What `vrw.Params(model=...)` holds for a walker other than the wheel.
#[derive(Debug, Clone)]
pub(crate) struct WalkerParams {
    /// `model=` as given: a built-in model's name or a description file's path.
    pub(crate) model: String,
    /// A described walker's description, as read from its file: what a pickled `Params` carries to another
    /// process, which reads it again from this text, not from the file.
    text: Option<String>,
    /// The walker with its parameters.
    pub(crate) walker: Walker,
}

impl PartialEq for WalkerParams {
    /// The same walker with the same parameters (a description read from two paths is the same walker).
    fn eq(&self, other: &Self) -> bool {
        self.walker == other.walker
    }
}

impl WalkerParams {
    /// The walker `model` (a built-in name or a description's path; `text`: the description already read)
    /// with its parameters from the flat TOML `file` and the `key=value` `overrides`, validated by the library
    /// as the command line's `--model`, `--config` and `--set` are.
    pub(crate) fn load(
        model: &str,
        text: Option<&str>,
        file: Option<&Path>,
        overrides: &[String],
    ) -> PyResult<WalkerParams> {
        let walker = match text {
            Some(text) => {
                let described = described::parse(model, text)
                    .map_err(|e| model_error(e.to_string()))?
                    .with_parameters(file, overrides)
                    .map_err(config_error)?;
                Walker::Described(described)
            }
            None => match Walker::load(model, file, overrides).map_err(app_error)? {
                Some(w) => w,
                None => return Err(model_error("the wheel (`vrw`) is not a walker".to_string())),
            },
        };
        // A description travels with its text (read once more: Walker::load checked the file's size and kind).
        let text = match (&walker, text) {
            (_, Some(text)) => Some(text.to_string()),
            (Walker::Described(_), None) => Some(
                std::fs::read_to_string(model)
                    .map_err(|e| model_error(format!("cannot read {model:?}: {e}")))?,
            ),
            _ => None,
        };
        Ok(WalkerParams {
            model: model.to_string(),
            text,
            walker,
        })
    }

    /// The description's text, for a described walker (pickling).
    pub(crate) fn text(&self) -> Option<&str> {
        self.text.as_deref()
    }

    /// The model's name (a description's `name`).
    pub(crate) fn name(&self) -> &'static str {
        self.walker.name()
    }

    /// The parameters' keys and values, in the model's order.
    pub(crate) fn parameters(&self) -> Vec<(&'static str, f64)> {
        let w = &self.walker;
        w.parameter_keys()
            .into_iter()
            .map(|k| (k, w.parameter(k).unwrap_or(f64::NAN)))
            .collect()
    }

    /// The same model with the keys `changes` changed (`key=value` overrides after the current values),
    /// validated as the constructor validates.
    pub(crate) fn replaced(&self, changes: &[String]) -> PyResult<WalkerParams> {
        let mut overrides: Vec<String> = self
            .parameters()
            .iter()
            .map(|(k, v)| format!("{k}={v:?}"))
            .collect();
        overrides.extend(changes.iter().cloned());
        WalkerParams::load(&self.model, self.text(), None, &overrides)
    }

    /// The same model at its defaults.
    pub(crate) fn defaults(&self) -> PyResult<WalkerParams> {
        WalkerParams::load(&self.model, self.text(), None, &[])
    }
}

/// A bad `model`, in the command line's words.
fn model_error(reason: String) -> PyErr {
    option_error("model", reason)
}

/// A bad value of the option `option`, in the command line's words (the library's
/// [`AppError::InvalidOption`], raised as `vrw.ConfigError`).
pub(crate) fn option_error(option: &'static str, reason: String) -> PyErr {
    app_error(AppError::InvalidOption { option, reason })
}

/// Keyword arguments as `key=value` overrides (`--set`): each value a number (an int, a float, a numpy scalar),
/// written so that it reads back to the same float.
pub(crate) fn overrides(keys: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<String>> {
    let mut out = Vec::new();
    for (key, value) in keys.into_iter().flat_map(|d| d.iter()) {
        let key: String = key.extract()?;
        out.push(format!("{key}={:?}", number(&key, &value)?));
    }
    Ok(out)
}

/// A walker's parameter value: a number, or the library's error naming the key.
fn number(key: &str, value: &Bound<'_, PyAny>) -> PyResult<f64> {
    if value.hasattr("dtype")? && value.getattr("ndim")?.extract::<usize>()? == 0 {
        return number(key, &value.call_method0("item")?);
    }
    let is_number = value.is_instance_of::<PyFloat>() || value.is_instance_of::<PyInt>();
    if !is_number || value.is_instance_of::<PyBool>() {
        return Err(config_error(LibConfigError::WrongType {
            key: key.to_string(),
            expected: "a number".to_string(),
            found: value.repr()?.to_string(),
        }));
    }
    value.extract()
}

/// The rows of a CSV file (its header first) as a table of numpy arrays keyed by the header: the columns of
/// words (`status`, `stability`, `message`, `outcome`) as strings, of counts (`step`, `iterations`, `scuffs`,
/// `period_k`, `steps`, and a basin's grid indices `ix`, `iy`) as integers, every other one as floats (the files
/// write the shortest text that reads back to the same float, so the values are the job's).
fn rows_table<'py>(py: Python<'py>, rows: &[Vec<String>]) -> PyResult<Bound<'py, PyDict>> {
    const WORDS: [&str; 4] = ["status", "stability", "message", "outcome"];
    const COUNTS: [&str; 7] = [
        "step",
        "iterations",
        "scuffs",
        "period_k",
        "steps",
        "ix",
        "iy",
    ];
    let Some((header, rows)) = rows.split_first() else {
        return Ok(PyDict::new(py));
    };
    let kinds: Vec<fn(&str) -> Option<Cell>> = header
        .iter()
        .enumerate()
        .map(|(j, name)| {
            let cells = || {
                rows.iter()
                    .filter_map(|r| r.get(j))
                    .filter(|c| !c.is_empty())
            };
            let counts =
                COUNTS.contains(&name.as_str()) && cells().all(|c| c.parse::<usize>().is_ok());
            let reals = cells().all(|c| c.parse::<f64>().is_ok());
            match () {
                _ if WORDS.contains(&name.as_str()) || !reals => {
                    |c: &str| Some(Cell::Text(c.to_string()))
                }
                _ if counts => |c: &str| c.parse().ok().map(Cell::Count),
                _ => |c: &str| c.parse().ok().map(Cell::Real),
            }
        })
        .collect();
    let cells: Vec<Vec<Cell>> = rows
        .iter()
        .map(|r| {
            r.iter()
                .zip(&kinds)
                .map(|(c, kind)| match c.is_empty() {
                    true => Cell::Empty,
                    false => kind(c).unwrap_or(Cell::Empty),
                })
                .collect()
        })
        .collect();
    table(py, header, &cells)
}

/// A walker job's result: its JSON file's fields (`summary`, pythonized; without `files`: nothing is written)
/// and each CSV file's table under `names` (in the job's order).
fn output<'py, S>(
    summary: Bound<'py, PyAny>,
    out: &WalkerOutput<S>,
    names: &[&str],
) -> PyResult<Bound<'py, PyDict>> {
    let py = summary.py();
    let result = summary.downcast_into::<PyDict>()?;
    if result.contains("files")? {
        result.del_item("files")?;
    }
    for ((_, rows), name) in out.tables.iter().zip(names) {
        result.set_item(*name, rows_table(py, rows)?)?;
    }
    Ok(result)
}

/// `gait.json`'s gait fields at the top level, as the wheel's `gait.json` has them, the multipliers as a
/// complex numpy array, and `stable` (every multiplier inside the unit circle).
fn flatten_gait(py: Python<'_>, result: &Bound<'_, PyDict>) -> PyResult<()> {
    let Some(gait) = result.get_item("gait")? else {
        return Ok(());
    };
    result.del_item("gait")?;
    let Ok(gait) = gait.downcast_into::<PyDict>() else {
        return Ok(());
    };
    for (key, value) in gait.iter() {
        result.set_item(key, value)?;
    }
    let pairs: Vec<[f64; 2]> = gait
        .get_item("floquet_multipliers")?
        .map(|m| m.extract())
        .transpose()?
        .unwrap_or_default();
    let multipliers: Vec<Complex64> = pairs
        .iter()
        .map(|[re, im]| Complex64::new(*re, *im))
        .collect();
    result.set_item("stable", multipliers.iter().all(|z| z.norm() < 1.0))?;
    result.set_item("floquet_multipliers", multipliers.into_pyarray(py))?;
    Ok(())
}

/// A walker's gait-search settings: `find_gait`'s keywords.
struct Search {
    /// Steps walked before Newton's method (the command line's `--transient`).
    transient_steps: usize,
    /// `dP/dp` for this parameter too (`--parameter`).
    parameter: Option<String>,
}

impl Search {
    /// The keywords `options` (`transient_steps`, `parameter`), the transient checked by the library's rule.
    fn new(params: &WalkerParams, options: Option<&Bound<'_, PyDict>>) -> PyResult<Search> {
        let mut search = Search {
            transient_steps: GaitOptions::default().transient_steps,
            parameter: None,
        };
        for (key, value) in options.into_iter().flat_map(|d| d.iter()) {
            let key: String = key.extract()?;
            match key.as_str() {
                "transient_steps" => search.transient_steps = count(&key, &value)?,
                "parameter" => search.parameter = value.extract()?,
                _ => return Err(unexpected(&key, params)),
            }
        }
        let checked = GaitOptions {
            transient_steps: search.transient_steps,
            ..GaitOptions::default()
        };
        checked.validate().map_err(config_error)?;
        Ok(search)
    }
}

/// The error of a keyword `find_gait` does not take for a walker.
fn unexpected(key: &str, params: &WalkerParams) -> PyErr {
    PyTypeError::new_err(format!(
        "unexpected keyword argument `{key}` for the model `{}` (its search options: transient_steps, \
         parameter)",
        params.name()
    ))
}

/// `vrw.find_gait` of a walker: `vrw gait --model NAME` without its file. Options: `transient_steps` (the
/// command line's `--transient`) and `parameter` (`dP/dp` as `dP_dparam`).
pub(crate) fn find_gait<'py>(
    py: Python<'py>,
    params: &WalkerParams,
    initial: Option<Vec<f64>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let Search {
        transient_steps,
        parameter,
    } = Search::new(params, options)?;
    let flag = vrw::gait::interrupt_flag();
    let job = WalkerGaitJob {
        walker: params.walker.clone(),
        initial,
        transient_steps,
        parameter,
        check_jacobian: false,
        out_dir: PathBuf::new(),
        overwrite: false,
    };
    let summary = interruptible(py, flag, || compute_walker_gait(&job))?.map_err(app_error)?;
    let result = pythonize(py, &summary)?.downcast_into::<PyDict>()?;
    flatten_gait(py, &result)?;
    Ok(result)
}

/// `vrw.simulate` of a walker: `vrw simulate --model NAME` without its files.
pub(crate) fn simulate<'py>(
    py: Python<'py>,
    params: &WalkerParams,
    (steps, initial): (usize, Option<Vec<f64>>),
    (trajectory, sample_dt): (bool, f64),
) -> PyResult<Bound<'py, PyDict>> {
    let job = WalkerSimulateJob {
        walker: params.walker.clone(),
        initial,
        steps,
        sample_dt,
        trajectory,
        out_dir: PathBuf::new(),
        overwrite: false,
    };
    let flag = vrw::gait::interrupt_flag();
    let out = interruptible(py, flag, || compute_walker_simulate(&job))?.map_err(app_error)?;
    let result = output(pythonize(py, &out.summary)?, &out, &["steps", "trajectory"])?;
    if !trajectory {
        result.set_item("trajectory", py.None())?;
    }
    Ok(result)
}

/// No `progress` for a walker's job (its grid reports none yet), no option of the wheel's.
fn wheel_options(
    params: &WalkerParams,
    job: &str,
    progress: &Option<Py<PyAny>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<()> {
    if progress.is_some() {
        let reason = format!(
            "`progress` is reported by the wheel's jobs only so far; `vrw.{job}` of the model `{}` runs \
             without it",
            params.name()
        );
        return Err(option_error("progress", reason));
    }
    if let Some(key) = options.and_then(|d| d.keys().iter().next()) {
        return Err(PyTypeError::new_err(format!(
            "unexpected keyword argument `{key}` for the model `{}`: the search options are the wheel's",
            params.name()
        )));
    }
    Ok(())
}

/// `vrw.sweep` of a walker: `vrw sweep --model NAME --param KEY` without its files, at the given values (each
/// checked against the walker's domain, as the command line checks its range's ends).
pub(crate) fn sweep<'py>(
    py: Python<'py>,
    params: &WalkerParams,
    (param, values, initial): (&str, Vec<f64>, Option<Vec<f64>>),
    progress: Option<Py<PyAny>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    wheel_options(params, "sweep", &progress, options)?;
    let walker = &params.walker;
    walker
        .checked_parameter("param", param)
        .map_err(app_error)?;
    if !(2..=MAX_WALKER_SWEEP_POINTS).contains(&values.len()) {
        return Err(option_error(
            "values",
            format!(
                "{} values; a sweep takes between 2 and {MAX_WALKER_SWEEP_POINTS}",
                values.len()
            ),
        ));
    }
    for v in &values {
        walker.with_parameter(param, *v).map_err(config_error)?;
    }
    let job = WalkerSweepJob {
        walker: walker.clone(),
        range: WalkerRange {
            param: param.to_string(),
            from: values[0],
            to: values[values.len() - 1],
            points: values.len(),
        },
        initial,
        out_dir: PathBuf::new(),
        overwrite: false,
    };
    let flag = vrw::gait::interrupt_flag();
    let out =
        interruptible(py, flag, || compute_walker_sweep(&job, &values))?.map_err(app_error)?;
    let result = output(pythonize(py, &out.summary)?, &out, &["sweep"])?;
    result.set_item("param", param)?;
    Ok(result)
}

/// What `vrw.continue_family` of a walker takes besides its walker and parameter.
pub(crate) struct FamilyOptions {
    /// Where the first gait is searched.
    pub(crate) start: Option<f64>,
    /// The range followed.
    pub(crate) range: (f64, f64),
    /// Most points in each direction.
    pub(crate) max_points: usize,
    /// Largest continuation step.
    pub(crate) max_step: f64,
    /// The first of the wheel's options a walker's continuation does not take (`initial`, `period`,
    /// `two_param`, `extremum`) given: an error that names it.
    pub(crate) wheel_only: Option<&'static str>,
}

/// `vrw.continue_family` of a walker: `vrw continue --model NAME --param KEY` without its files.
pub(crate) fn continue_family<'py>(
    py: Python<'py>,
    params: &WalkerParams,
    param: &str,
    options: FamilyOptions,
) -> PyResult<Bound<'py, PyDict>> {
    let walker = &params.walker;
    if let Some(option) = options.wheel_only {
        let reason = format!(
            "is an option of the wheel's continuation; the model `{}` follows its start's family only so far \
             (docs/model.md section 13)",
            params.name()
        );
        return Err(option_error(option, reason));
    }
    let job = WalkerContinueJob {
        walker: walker.clone(),
        param: param.to_string(),
        start: options.start,
        range: options.range,
        max_points: options.max_points,
        max_step: options.max_step,
        out_dir: PathBuf::new(),
        overwrite: false,
    };
    let flag = vrw::gait::interrupt_flag();
    let out = interruptible(py, flag, || compute_walker_continuation(&job))?.map_err(app_error)?;
    output(pythonize(py, &out.summary)?, &out, &["branch"])
}

/// `vrw.orbit` of a walker: `vrw orbit --model NAME --param KEY` without its files and figure.
#[allow(clippy::too_many_arguments)]
pub(crate) fn orbit<'py>(
    py: Python<'py>,
    params: &WalkerParams,
    range: WalkerRange,
    (transient, steps): (usize, usize),
    initial: Option<Vec<f64>>,
    branch: bool,
    progress: Option<Py<PyAny>>,
    part: bool,
) -> PyResult<Bound<'py, PyDict>> {
    wheel_options(params, "orbit", &progress, None)?;
    if part {
        return Err(whole_only(params, "part", "orbit diagram"));
    }
    let job = WalkerOrbitJob {
        walker: params.walker.clone(),
        range,
        transient,
        steps,
        initial,
        branch,
        out_dir: PathBuf::new(),
        overwrite: false,
    };
    let flag = vrw::gait::interrupt_flag();
    let out = interruptible(py, flag, || compute_walker_orbit(&job))?.map_err(app_error)?;
    let names: &[&str] = if branch {
        &["orbit", "branch"]
    } else {
        &["orbit"]
    };
    output(pythonize(py, &out.summary)?, &out, names)
}

/// A part of a study spread over processes (`rows`, `part`) is the wheel's only so far: the error naming the
/// option and the model.
pub(crate) fn whole_only(params: &WalkerParams, option: &'static str, job: &str) -> PyErr {
    let reason = format!(
        "`{option}` splits the wheel's {job}; the model `{}` computes its {job} whole so far",
        params.name()
    );
    option_error(option, reason)
}

/// What `vrw.map` of a walker takes besides its walker.
pub(crate) struct MapOptions {
    /// The parameters along the rows (`x`) and the columns (`y`) and their values.
    pub(crate) axes: MapSpec,
    /// Bisect every change of stability along the rows (`curves`; the command line's `--no-curves`).
    pub(crate) thresholds: bool,
    /// Where the search at the first point starts.
    pub(crate) initial: Option<Vec<f64>>,
    /// The first of the wheel's options for its curves given (`curve_columns`, `curve_method`,
    /// `second_route`), which a walker's map refuses.
    pub(crate) wheel_only: Option<&'static str>,
}

/// `vrw.map` of a walker: `vrw map --model NAME` without its files and figure (`map.json`'s fields and `map`, the
/// columns of `map.csv`). `progress` counts the points; Ctrl-C while the thresholds are bisected hands the
/// complete gaits on with the `KeyboardInterrupt` (as `partial`), as the wheel's map does.
pub(crate) fn map<'py>(
    py: Python<'py>,
    params: &WalkerParams,
    options: MapOptions,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    if let Some(option) = options.wheel_only {
        let reason = format!(
            "is an option of the wheel's map; the model `{}` has no threshold curves (its changes of \
             stability are bisected along the rows: `curves=False` skips them)",
            params.name()
        );
        return Err(option_error(option, reason));
    }
    let range = |s: SweepSpec| WalkerRange {
        param: s.param,
        from: s.from,
        to: s.to,
        points: s.points,
    };
    let job = WalkerMapJob {
        walker: params.walker.clone(),
        x: range(options.axes.x),
        y: range(options.axes.y),
        initial: options.initial,
        thresholds: options.thresholds,
        out_dir: PathBuf::new(),
        overwrite: false,
    };
    let progress = Progress::new(progress, job.x.points.saturating_mul(job.y.points));
    let flag = vrw::gait::interrupt_flag();
    let done = interruptible_keeping(py, flag, Some(&progress), || {
        compute_walker_map(&job, &|_| progress.tick())
    });
    keeping_partial(
        py,
        done,
        |out| out.summary.interrupted.clone(),
        |out| output(pythonize(py, &out.summary)?, out, &["map"]),
    )
}

/// What `vrw.basin` of a walker takes besides its walker.
pub(crate) struct BasinOptions<'a> {
    /// The slice's coordinates (`None`: the section's first and second).
    pub(crate) coordinates: [Option<&'a str>; 2],
    /// Their ranges (`None`: from 0 to twice the gait's value, or -1 to 1 where that is 0), the grid, and when a
    /// walk ends.
    pub(crate) grid: SliceGrid,
    /// Where the gait search starts.
    pub(crate) initial: Option<Vec<f64>>,
}

/// `vrw.basin` of a walker: `vrw basin --model NAME` without its files and figure (`basin.json`'s fields and
/// `points`, the columns of `basin.csv`). `progress` counts the starts; Ctrl-C: `KeyboardInterrupt`, nothing
/// kept, as the wheel's basin.
pub(crate) fn basin<'py>(
    py: Python<'py>,
    params: &WalkerParams,
    options: BasinOptions<'_>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let coordinates = WalkerBasinJob::slice_coordinates(&params.walker, options.coordinates)
        .map_err(app_error)?;
    let job = WalkerBasinJob {
        walker: params.walker.clone(),
        initial: options.initial,
        coordinates,
        grid: options.grid,
        out_dir: PathBuf::new(),
        overwrite: false,
    };
    let [nx, ny] = job.grid.points;
    let progress = Progress::new(progress, nx.saturating_mul(ny));
    let flag = vrw::gait::interrupt_flag();
    let out = interruptible_with(py, flag, Some(&progress), || {
        compute_walker_basin(&job, &|_| progress.tick())
    })?
    .map_err(app_error)?;
    output(pythonize(py, &out.summary)?, &out, &["points"])
}
