//! `vrw._vrw`: the Python binding of the vrw library (STYLE.md point 14).
//!
//! This crate only converts at the edge: keyword arguments become [`Config`] keys (typed as in a TOML file),
//! the library's jobs run with the GIL released, and their results come back as dicts of numpy arrays keyed
//! by the column names of the CSV files (taken from [`vrw::output`], the same functions the CSV writers use)
//! or as the JSON structures of `summary.json`, `gait.json` and `thresholds.json` (the same `Serialize`
//! impls, through `pythonize`). Each library error becomes one Python exception with the same message.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use numpy::{Complex64, IntoPyArray, PyArray2};
use pyo3::create_exception;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString};
use pythonize::pythonize;

mod animate;
mod parts;
mod progress;
mod walkers;

use progress::{interruptible_keeping, interruptible_with, keeping_partial, Progress};
use vrw::app::{
    compute_basin_part, compute_continuation, compute_gait, compute_map, compute_map_part,
    compute_orbit, compute_orbit_part, compute_simulation, compute_sweep, curve_rows, family_rows,
    monitored_header, monitored_rows, AppError, BasinJob, ContinueJob, GaitJob, MapJob, OrbitJob,
    OrbitJobPart, SimulateJob, SliceGrid, WalkerRange,
};
use vrw::dynamics::DIFFERENTIABLE_KEYS;
use vrw::fmt::short;
use vrw::gait::GaitOptions;
use vrw::output::{
    basin_header, basin_row, branch_header, branch_rows, curve_header, curve_row, family_header,
    family_row, friction_columns, map_header, map_rows, orbit_header, orbit_rows, steps_header,
    steps_row, sweep_header, sweep_row, trajectory_header, trajectory_row_under, Cell,
    StepsColumns,
};
use vrw::params::{Config, ConfigError as LibConfigError};
use vrw::study::basin::Coordinate;
use vrw::study::map::DEFAULT_CURVE_COLUMNS;
use vrw::study::orbit::OrbitSpec;
use vrw::study::MAX_SWEEP_POINTS;
use vrw::study::{MapSpec, SweepSpec};
use vrw::walk::SectionState;
use vrw::walk::WalkError as LibWalkError;
use walkers::WalkerParams;

create_exception!(
    vrw,
    ConfigError,
    PyValueError,
    "Invalid parameters: an unknown key, a value of the wrong type or one that breaks a rule, a malformed or \
     unreadable TOML file. The message is the command line's."
);
create_exception!(
    vrw,
    WalkError,
    PyRuntimeError,
    "A walk that cannot start (e.g. an invalid initial section state). The message is the command line's."
);

fn config_error(e: LibConfigError) -> PyErr {
    ConfigError::new_err(e.to_string())
}

fn walk_error(e: LibWalkError) -> PyErr {
    WalkError::new_err(e.to_string())
}

/// One Python exception per library error, with the library's message.
fn app_error(e: AppError) -> PyErr {
    match e {
        AppError::Config(e) => config_error(e),
        AppError::Walk(e) => walk_error(e),
        AppError::Output(e) => PyOSError::new_err(e.to_string()),
        e @ AppError::InvalidOption { .. } => ConfigError::new_err(e.to_string()),
        // Reading run directories and drawing figures are command-line jobs, not reached from Python.
        e @ (AppError::Read(_)
        | AppError::Animate(_)
        | AppError::Plot(_)
        | AppError::Manifest(_)
        | AppError::NotOneRun { .. }) => PyOSError::new_err(e.to_string()),
        // Only reached when the interrupt flag was set without a signal (the watcher raises the signal's
        // exception itself).
        e @ AppError::Interrupted { .. } => {
            pyo3::exceptions::PyKeyboardInterrupt::new_err(e.to_string())
        }
    }
}

/// A keyword argument as the TOML value a configuration file would hold.
fn toml_value(key: &str, value: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if let Ok(b) = value.downcast::<PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(value.extract()?));
    }
    if value.is_instance_of::<PyInt>() {
        return match value.extract::<i64>() {
            Ok(n) => Ok(toml::Value::Integer(n)),
            Err(_) => Err(config_error(LibConfigError::InvalidValue {
                key: key.to_string(),
                value: value.str()?.to_string(),
                reason: "is out of range".to_string(),
            })),
        };
    }
    if let Ok(s) = value.downcast::<PyString>() {
        return Ok(toml::Value::String(s.extract()?));
    }
    // numpy scalars (np.int64, np.bool_, np.float32, ...) and 0-d arrays: their Python value.
    if value.hasattr("dtype")? && value.getattr("ndim")?.extract::<usize>()? == 0 {
        return toml_value(key, &value.call_method0("item")?);
    }
    Err(PyTypeError::new_err(format!(
        "`{key}`: expected a number, a bool or a string, got {}",
        value.get_type().name()?
    )))
}

/// Apply `keys` (keyword arguments or a state dict) to `config`, then validate once, as the command line does.
fn apply_keys(config: Config, keys: Option<&Bound<'_, PyDict>>) -> PyResult<Config> {
    let mut values = Vec::new();
    for (key, value) in keys.into_iter().flat_map(|d| d.iter()) {
        let key: String = key.extract()?;
        let value = toml_value(&key, &value)?;
        values.push((key, value));
    }
    let config = config.with_values(values).map_err(config_error)?;
    // Legs stiff enough to make a run slow: a RuntimeWarning, as the command line warns on stderr.
    if let Some(warning) = config.params.leg_time_scale().and_then(|s| s.warning()) {
        let py = keys.map(|d| d.py());
        if let Some(py) = py {
            let category = py.get_type::<pyo3::exceptions::PyRuntimeWarning>();
            PyErr::warn(py, category.as_any(), &std::ffi::CString::new(warning)?, 1)?;
        }
    }
    Ok(config)
}

/// The model's parameters and the solver's settings: every key of a vrw TOML file, or another walker's
/// parameters.
///
/// `Params(viscosity=37, slope=0.05)` starts from the defaults (the paper's Table 1, c = 50 N s/m) and
/// applies each keyword as a TOML key, validated as `vrw --config FILE --set key=value` does: an unknown key or
/// a bad value raises `vrw.ConfigError` (a `ValueError`) with the command line's message.
/// `Params(model="compass", slope=0.05)` (`"simplest"`, `"compass"`, `"telescopic"` or the path of a walker's
/// description, `.toml`) holds another walker's parameters, validated as `vrw --model NAME --set key=value`
/// does; `model="vrw"` (the default) is the wheel.
#[pyclass(module = "vrw", name = "Params", frozen, eq)]
#[derive(Clone, PartialEq)]
struct Params {
    model: Model,
}

/// What a [`Params`] holds.
#[derive(Clone, PartialEq)]
enum Model {
    /// The wheel's configuration.
    Wheel(Config),
    /// Another walker's parameters.
    Walker(WalkerParams),
}

impl Params {
    /// The wheel's configuration, for the wheel's part of the job `vrw.{job}` (every job takes another walker
    /// before it: this error names the job and the model should one not).
    fn wheel(&self, job: &str) -> PyResult<&Config> {
        match &self.model {
            Model::Wheel(config) => Ok(config),
            Model::Walker(w) => Err(walkers::option_error(
                "model",
                format!(
                    "`vrw.{job}` took the model `{}` for the wheel's (docs/model.md section 13)",
                    w.name()
                ),
            )),
        }
    }

    /// The walker's parameters, if the model is not the wheel.
    fn walker(&self) -> Option<&WalkerParams> {
        match &self.model {
            Model::Wheel(_) => None,
            Model::Walker(w) => Some(w),
        }
    }

    /// The model `model` (`None` or `"vrw"`: the wheel) with its parameters from `file` and `keys`.
    fn load(
        model: Option<&str>,
        file: Option<&std::path::Path>,
        keys: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Params> {
        let model = match model {
            None | Some("vrw") => {
                let config = match file {
                    Some(path) => Config::from_file(path).map_err(config_error)?,
                    None => Config::default(),
                };
                Model::Wheel(apply_keys(config, keys)?)
            }
            Some(name) => {
                let overrides = walkers::overrides(keys)?;
                Model::Walker(WalkerParams::load(name, None, file, &overrides)?)
            }
        };
        Ok(Params { model })
    }
}

#[pymethods]
impl Params {
    #[new]
    #[pyo3(signature = (*, model = None, **keys))]
    fn new(model: Option<&str>, keys: Option<&Bound<'_, PyDict>>) -> PyResult<Params> {
        Params::load(model, None, keys)
    }

    /// Read a flat TOML file of parameters (as `vrw --config FILE`, with `--model model`).
    #[staticmethod]
    #[pyo3(signature = (path, model = None))]
    fn from_toml(path: PathBuf, model: Option<&str>) -> PyResult<Params> {
        Params::load(model, Some(&path), None)
    }

    /// The model: `"vrw"` (the wheel), a built-in walker's name, or a description's path as given.
    #[getter]
    fn model(&self) -> String {
        self.walker()
            .map_or_else(|| "vrw".to_string(), |w| w.model.clone())
    }

    /// Every key and its value, as a TOML file (or `summary.json`'s `config`) holds them (with the keys files
    /// leave out at their defaults too); a walker's parameters.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        match &self.model {
            Model::Wheel(config) => every_key(py, config),
            Model::Walker(w) => {
                let dict = PyDict::new(py);
                for (key, value) in w.parameters() {
                    dict.set_item(key, value)?;
                }
                Ok(dict.into_any())
            }
        }
    }

    /// A copy with the given keys changed (validated as in the constructor).
    #[pyo3(signature = (**keys))]
    fn replace(&self, keys: Option<&Bound<'_, PyDict>>) -> PyResult<Params> {
        let model = match &self.model {
            Model::Wheel(config) => Model::Wheel(apply_keys(config.clone(), keys)?),
            Model::Walker(w) => Model::Walker(w.replaced(&walkers::overrides(keys)?)?),
        };
        Ok(Params { model })
    }

    /// The value of one key.
    fn __getitem__<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        let all = self.to_dict(py)?;
        match all.get_item(key) {
            Ok(v) => Ok(v),
            Err(_) => Err(pyo3::exceptions::PyKeyError::new_err(key.to_string())),
        }
    }

    /// The wheel's keys holding a real number (the parameters a sweep or a grid can vary).
    #[staticmethod]
    fn numeric_keys() -> Vec<&'static str> {
        Config::numeric_keys().to_vec()
    }

    /// The keys this model's sweeps, continuations and orbit diagrams can vary: the wheel's `numeric_keys()`,
    /// or a walker's parameters.
    fn parameter_keys(&self) -> Vec<&'static str> {
        match &self.model {
            Model::Wheel(_) => Config::numeric_keys().to_vec(),
            Model::Walker(w) => w.parameters().into_iter().map(|(k, _)| k).collect(),
        }
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        // Pickle as `_params_from_dict(to_dict())`, for every protocol (`__getnewargs_ex__` served only
        // protocols 2 and up): the keys are re-read as the constructor reads them. A walker's as
        // `_walker_params(model, text, to_dict())`, a description with its text.
        let module = py.import("vrw._vrw")?;
        Ok(match &self.model {
            Model::Wheel(_) => (
                module.getattr("_params_from_dict")?,
                (self.to_dict(py)?,).into_pyobject(py)?.into_any(),
            ),
            Model::Walker(w) => (
                module.getattr("_walker_params")?,
                (w.model.clone(), w.text(), self.to_dict(py)?)
                    .into_pyobject(py)?
                    .into_any(),
            ),
        })
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let all = self.to_dict(py)?;
        let (defaults, mut changed) = match &self.model {
            Model::Wheel(_) => (every_key(py, &Config::default())?, Vec::new()),
            Model::Walker(w) => {
                let defaults = Params {
                    model: Model::Walker(w.defaults()?),
                };
                let model = PyString::new(py, &w.model).repr()?;
                (defaults.to_dict(py)?, vec![format!("model={model}")])
            }
        };
        for (key, value) in all.downcast::<PyDict>()?.iter() {
            if !value.eq(defaults.get_item(&key)?)? {
                changed.push(format!("{}={}", key.str()?, value.repr()?));
            }
        }
        Ok(format!("Params({})", changed.join(", ")))
    }
}

/// Every key of `config` and its value: its serialization, with the keys it leaves out at their defaults
/// ([`vrw::params::Params::keys_left_out_at_defaults`]) added.
fn every_key<'py>(py: Python<'py>, config: &Config) -> PyResult<Bound<'py, PyAny>> {
    let dict = pythonize(py, config)?.downcast_into::<PyDict>()?;
    for (key, value) in config.params.keys_left_out_at_defaults() {
        if !dict.contains(key)? {
            dict.set_item(key, pythonize(py, &value)?)?;
        }
    }
    Ok(dict.into_any())
}

/// A table (CSV header and typed rows) as a dict of numpy arrays keyed by the header: real columns as
/// float64 (`NaN` for empty cells), counts as int64 (as float64 with `NaN` where a cell is empty, as pandas
/// reads the CSV: a count of 0 would be a value), flags as bool (False for empty cells), words as numpy
/// string arrays.
fn table<'py, H: AsRef<str>>(
    py: Python<'py>,
    header: &[H],
    rows: &[Vec<Cell>],
) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    let numpy = py.import("numpy")?;
    for (j, name) in header.iter().enumerate() {
        let column = rows.iter().map(|r| r.get(j).unwrap_or(&Cell::Empty));
        let kind = column.clone().find(|c| !matches!(c, Cell::Empty));
        let array: Bound<'py, PyAny> = match kind {
            None | Some(Cell::Real(_)) | Some(Cell::Empty) => column
                .map(|c| match c {
                    Cell::Real(v) => *v,
                    _ => f64::NAN,
                })
                .collect::<Vec<f64>>()
                .into_pyarray(py)
                .into_any(),
            Some(Cell::Count(_)) if column.clone().any(|c| matches!(c, Cell::Empty)) => column
                .map(|c| match c {
                    Cell::Count(n) => *n as f64,
                    _ => f64::NAN,
                })
                .collect::<Vec<f64>>()
                .into_pyarray(py)
                .into_any(),
            Some(Cell::Count(_)) => column
                .map(|c| match c {
                    Cell::Count(n) => *n as i64,
                    _ => 0,
                })
                .collect::<Vec<i64>>()
                .into_pyarray(py)
                .into_any(),
            Some(Cell::Flag(_)) => column
                .map(|c| matches!(c, Cell::Flag(true)))
                .collect::<Vec<bool>>()
                .into_pyarray(py)
                .into_any(),
            Some(Cell::Text(_)) => {
                let words: Vec<String> = column.map(Cell::to_csv).collect();
                numpy.call_method1("array", (PyList::new(py, words)?, "U"))?
            }
        };
        dict.set_item(name.as_ref(), array)?;
    }
    Ok(dict)
}

/// The `initial` keyword: `None`, or the section state `[L2, thetadot, L2dot]` or, with Coulomb friction and a
/// slipping stance tip, `[L2, thetadot, L2dot, slip]` (checked against the model where the job starts).
pub(crate) fn section(initial: Option<Vec<f64>>) -> PyResult<Option<SectionState>> {
    initial
        .map(|values| {
            SectionState::from_values(&values).ok_or_else(|| {
                WalkError::new_err(format!(
                    "invalid initial state {values:?}: {} values given (expected [L2, thetadot, L2dot], or \
                     [L2, thetadot, L2dot, slip] with a slipping stance tip)",
                    values.len()
                ))
            })
        })
        .transpose()
}

/// The `parameter` keyword: `None`, or a key `dP/dp` can be taken for (the command line's `--parameter` rule
/// and message).
fn differentiable_key(value: &Bound<'_, PyAny>) -> PyResult<Option<&'static str>> {
    if value.is_none() {
        return Ok(None);
    }
    let key: String = value.extract()?;
    DIFFERENTIABLE_KEYS
        .iter()
        .find(|k| **k == key)
        .map(|k| Some(*k))
        .ok_or_else(|| {
            ConfigError::new_err(format!(
                "invalid value {key:?} for `parameter`: no derivative with respect to it; the parameter must be one of {}",
                DIFFERENTIABLE_KEYS.join(", ")
            ))
        })
}

/// The search settings: `defaults` with the keyword arguments `options` (the fields of the library's
/// `GaitOptions`, as `gait.json` lists them under `options`).
fn gait_options(
    defaults: GaitOptions,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<GaitOptions> {
    let mut o = defaults;
    for (key, value) in options.into_iter().flat_map(|d| d.iter()) {
        let key: String = key.extract()?;
        match key.as_str() {
            "transient_steps" => o.transient_steps = count(&key, &value)?,
            "max_iterations" => o.max_iterations = count(&key, &value)?,
            "tolerance" => o.tolerance = real(&key, &value)?,
            "fd_step" => o.fd_step = real(&key, &value)?,
            "refine_jacobian" => o.refine_jacobian = value.extract()?,
            "parameter" => o.parameter = differentiable_key(&value)?,
            _ => {
                return Err(PyTypeError::new_err(format!(
                    "unexpected keyword argument `{key}` (search options: transient_steps, \
                     max_iterations, tolerance, fd_step, refine_jacobian, parameter)"
                )))
            }
        }
    }
    // The library's ranges, with its message naming the keyword.
    o.validate().map_err(config_error)?;
    Ok(o)
}

/// The keyword argument `name` as a count: a non-negative integer that fits the platform's `usize`
/// (never a bare `OverflowError`: the error names the argument).
fn count(name: &str, value: &Bound<'_, PyAny>) -> PyResult<usize> {
    if value.is_instance_of::<PyBool>() || !value.is_instance_of::<PyInt>() {
        // numpy integers: their Python value.
        if value.hasattr("dtype")? && value.getattr("ndim")?.extract::<usize>()? == 0 {
            return count(name, &value.call_method0("item")?);
        }
        return Err(PyTypeError::new_err(format!(
            "`{name}`: expected a non-negative integer, got {}",
            value.get_type().name()?
        )));
    }
    value.extract::<usize>().map_err(|_| {
        let shown = value
            .str()
            .map_or_else(|_| "?".to_string(), |s| s.to_string());
        config_error(LibConfigError::InvalidValue {
            key: name.to_string(),
            value: shown,
            reason: "must be a non-negative integer of at most 64 bits".to_string(),
        })
    })
}

/// The keyword argument `name` as a real number (an int or a float; ranges are checked by the library).
fn real(name: &str, value: &Bound<'_, PyAny>) -> PyResult<f64> {
    if value.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!(
            "`{name}`: expected a number, got bool"
        )));
    }
    value.extract::<f64>().map_err(|_| {
        let kind = value
            .get_type()
            .name()
            .map_or_else(|_| "?".to_string(), |n| n.to_string());
        PyTypeError::new_err(format!("`{name}`: expected a number, got {kind}"))
    })
}

/// `simulate`'s and `orbit`'s `steps`, named in their errors.
fn steps_arg(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    count("steps", value)
}

/// `simulate`'s `sample_dt`, named in its errors.
fn sample_dt_arg(value: &Bound<'_, PyAny>) -> PyResult<f64> {
    real("sample_dt", value)
}

/// Walk `steps` steps from `initial` (`vrw simulate`).
///
/// `initial` is the Poincare-section state `(L2, thetadot, L2dot)` (default: the command line's). Returns the
/// fields of `summary.json`, with `steps` a dict of numpy arrays keyed like `steps.csv` and `trajectory` one
/// keyed like `trajectory.csv` (`None` without `trajectory`). A walk that stops early is a `status`; an
/// invalid initial state raises `vrw.WalkError`. Another walker's (`Params(model=...)`): `vrw simulate
/// --model`'s files, the tables named by the model's coordinates, `initial` its section's coordinates.
#[pyfunction]
#[pyo3(signature = (params, steps = 20, initial = None, trajectory = true, sample_dt = 0.005))]
fn simulate<'py>(
    py: Python<'py>,
    params: &Params,
    #[pyo3(from_py_with = steps_arg)] steps: usize,
    initial: Option<Vec<f64>>,
    trajectory: bool,
    #[pyo3(from_py_with = sample_dt_arg)] sample_dt: f64,
) -> PyResult<Bound<'py, PyDict>> {
    if let Some(w) = params.walker() {
        return walkers::simulate(py, w, (steps, initial), (trajectory, sample_dt));
    }
    let config = params.wheel("simulate")?;
    let job = SimulateJob {
        config: config.clone(),
        initial: section(initial)?,
        steps,
        sample_dt,
        trajectory,
        out_dir: PathBuf::new(),
        overwrite: false,
        interrupt: Some(Arc::new(AtomicBool::new(false))),
    };
    let flag = job.interrupt.clone().unwrap_or_default();
    let (summary, samples) =
        interruptible(py, &flag, || compute_simulation(&job, trajectory))?.map_err(app_error)?;
    let result = pythonize(py, &summary)?.downcast_into::<PyDict>()?;
    let columns = StepsColumns::of(&config.params);
    let rear_exit = config.params.rear_exit;
    let rows: Vec<Vec<Cell>> = summary
        .steps
        .iter()
        .map(|s| steps_row(s, columns))
        .collect();
    result.set_item("steps", table(py, &steps_header(columns), &rows)?)?;
    match samples {
        Some(t) => {
            let rows: Vec<Vec<Cell>> = t
                .samples
                .iter()
                .map(|s| trajectory_row_under(s, rear_exit))
                .collect();
            let header = trajectory_header(rear_exit);
            result.set_item("trajectory", table(py, &header, &rows)?)?
        }
        None => result.set_item("trajectory", py.None())?,
    }
    Ok(result)
}

/// Find the gait (`vrw gait`): the fields of `gait.json`.
///
/// `status` is `found` or why no gait was found (with `message`, as the command line reports it); a found
/// gait adds its fields, `floquet_multipliers` as a complex numpy array and `jacobian` as a 2-D array.
/// Keyword options: `transient_steps`, `max_iterations`, `tolerance`, `fd_step`, `refine_jacobian`,
/// `parameter` (`dP/dp` of the gait for that key, as `dP_dparam`). Another walker's (`Params(model=...)`):
/// `vrw gait --model`'s `gait.json` with its gait's fields at the top (`section` by the model's coordinates,
/// `period`, `lambda_I4`, `impact_loss`, `energy_drift`, `stable`, ...); options `transient_steps` and
/// `parameter` only.
#[pyfunction]
#[pyo3(signature = (params, initial = None, **options))]
fn find_gait<'py>(
    py: Python<'py>,
    params: &Params,
    initial: Option<Vec<f64>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    if let Some(w) = params.walker() {
        return walkers::find_gait(py, w, initial, options);
    }
    let job = GaitJob {
        config: params.wheel("find_gait")?.clone(),
        initial: section(initial)?,
        options: gait_options(GaitOptions::default(), options)?,
        out_dir: PathBuf::new(),
        overwrite: false,
        check_jacobian: false,
        interrupt: Some(Arc::new(AtomicBool::new(false))),
    };
    let flag = job.interrupt.clone().unwrap_or_default();
    let summary = interruptible(py, &flag, || compute_gait(&job))?.map_err(app_error)?;
    let result = pythonize(py, &summary)?.downcast_into::<PyDict>()?;
    if let Some(g) = &summary.gait {
        let multipliers: Vec<Complex64> = g
            .floquet_multipliers
            .iter()
            .map(|[re, im]| Complex64::new(*re, *im))
            .collect();
        result.set_item("floquet_multipliers", multipliers.into_pyarray(py))?;
        result.set_item("jacobian", PyArray2::from_vec2(py, &g.jacobian)?)?;
    }
    Ok(result)
}

/// Sweep `param` over `values` with continuation and locate the thresholds (`vrw sweep`, without the
/// figure).
///
/// Returns `param`, `sweep` (the columns of `sweep.csv` as numpy arrays), `thresholds` (the entries of
/// `thresholds.json`), `gaits_found` and `seconds`. `progress`: a callable `progress(done, total)`, called on
/// this thread as points finish. Keyword options as for `find_gait`, defaulting to the
/// command line's sweep settings. `vrw.linspace` gives the command line's values. Another walker's
/// (`Params(model=...)`): `vrw sweep --model`'s `thresholds.json` fields and `sweep`, at these values; no
/// options, no `progress` yet.
#[pyfunction]
#[pyo3(signature = (params, param, values, *, initial = None, progress = None, **options))]
fn sweep<'py>(
    py: Python<'py>,
    params: &Params,
    param: &str,
    values: Vec<f64>,
    initial: Option<Vec<f64>>,
    progress: Option<Py<PyAny>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    if let Some(w) = params.walker() {
        return walkers::sweep(py, w, (param, values, initial), progress, options);
    }
    let options = gait_options(GaitOptions::for_sweeps(), options)?;
    let config = params.wheel("sweep")?;
    let progress = Progress::new(progress, values.len());
    let initial = section(initial)?;
    let result = interruptible_with(py, vrw::gait::interrupt_flag(), Some(&progress), || {
        compute_sweep(
            config,
            param,
            &values,
            initial,
            &options,
            &|_| progress.tick(),
            &mut |_| Ok(()),
        )
    })?
    .map_err(app_error)?;
    let out = PyDict::new(py);
    out.set_item("param", param)?;
    let friction = friction_columns(config, &[param]);
    let rows: Vec<Vec<Cell>> = result
        .points
        .iter()
        .map(|p| sweep_row(p, friction))
        .collect();
    out.set_item("sweep", table(py, &sweep_header(param, friction), &rows)?)?;
    out.set_item("thresholds", pythonize(py, &result.thresholds)?)?;
    out.set_item(
        "gaits_found",
        result.points.iter().filter(|p| p.gait.is_some()).count(),
    )?;
    out.set_item("seconds", result.seconds.to_vec())?;
    Ok(out)
}

/// The basin of the gait on a slice of the section (`vrw basin`, without the figure).
///
/// Returns the fields of `basin.json` (`spec`, `gait`, `outcomes`, ...) and `points`, the columns of
/// `basin.csv` as numpy arrays (one row per grid point, row by row). Keyword arguments as the command line's
/// options: `x`, `y` (`"L2"`, `"thetadot"`, `"L2dot"`; default `"L2"` and `"thetadot"`), `x_range`, `y_range`
/// (`(from, to)`, default the command line's), `nx`, `ny`, `max_steps`, `tolerance`, `initial` (where the gait
/// search starts); and `rows` (`(start, end)`: only the grid rows `start..end`, each point as the whole basin
/// has it, `outcomes` counting them: a part of a study spread over processes, see `vrw.grid`) and `progress` (a
/// callable `progress(done, total)`, called on this thread as grid points finish). Another walker's
/// (`Params(model=...)`): `vrw basin --model`'s `basin.json` fields and `points`, `x` and `y` two of its
/// section's coordinates (default its first and second), `initial` its section's coordinates; no `rows` yet.
#[pyfunction]
#[pyo3(signature = (params, *, x = None, y = None, x_range = None, y_range = None, nx = 61, ny = 61, max_steps = 100, tolerance = 1e-3, initial = None, rows = None, progress = None))]
#[allow(clippy::too_many_arguments)]
fn basin<'py>(
    py: Python<'py>,
    params: &Params,
    x: Option<&str>,
    y: Option<&str>,
    x_range: Option<(f64, f64)>,
    y_range: Option<(f64, f64)>,
    #[pyo3(from_py_with = nx_arg)] nx: usize,
    #[pyo3(from_py_with = ny_arg)] ny: usize,
    #[pyo3(from_py_with = max_steps_arg)] max_steps: usize,
    #[pyo3(from_py_with = tolerance_arg)] tolerance: f64,
    initial: Option<Vec<f64>>,
    rows: Option<(usize, usize)>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let grid = SliceGrid {
        ranges: [x_range, y_range],
        points: [nx, ny],
        max_steps,
        tolerance,
    };
    if let Some(w) = params.walker() {
        if rows.is_some() {
            return Err(walkers::whole_only(w, "rows", "basin"));
        }
        let options = walkers::BasinOptions {
            coordinates: [x, y],
            grid,
            initial,
        };
        return walkers::basin(py, w, options, progress);
    }
    let coordinate = |name: &str, value: &str| {
        value
            .parse::<Coordinate>()
            .map_err(|e| ConfigError::new_err(format!("invalid value {value:?} for `{name}`: {e}")))
    };
    let job = BasinJob {
        config: params.wheel("basin")?.clone(),
        initial: section(initial)?,
        coordinates: [
            coordinate("x", x.unwrap_or("L2"))?,
            coordinate("y", y.unwrap_or("thetadot"))?,
        ],
        grid,
        out_dir: PathBuf::new(),
        overwrite: false,
    };
    let part = rows.map(|(start, end)| start..end);
    let progress = Progress::new(progress, nx * part.as_ref().map_or(ny, |p| p.len()));
    let (summary, grid) =
        interruptible_with(py, vrw::gait::interrupt_flag(), Some(&progress), || {
            compute_basin_part(&job, part, &|_| progress.tick())
        })?
        .map_err(app_error)?;
    let result = pythonize(py, &summary)?.downcast_into::<PyDict>()?;
    let friction = friction_columns(&job.config, &[]);
    let rows: Vec<Vec<Cell>> = grid
        .iter()
        .flatten()
        .map(|p| basin_row(p, friction))
        .collect();
    result.set_item("points", table(py, &basin_header(friction), &rows)?)?;
    Ok(result)
}

/// The gait over a grid of two parameters and the threshold curves across it (`vrw map`, without the
/// figure).
///
/// Returns the fields of `curves.json` (`spec`, `gaits_found`, `curves` with each one's `method`, `thresholds`,
/// `warnings`, ...) and `map`, the columns of `map.csv` as numpy arrays (row by row in `y`, each row along
/// `x`). Keyword arguments as the command line's options: `x`, `y` (parameter names), `x_range`, `y_range`
/// (`(from, to)`, default the command line's `(1, 300)` and `(300, 1500)`), `nx`, `ny`, `curves` (`False`: the
/// command line's `--no-curves`), `curve_columns`, `curve_method` (`"continuation"` or `"crossings"`),
/// `second_route`, `initial` (where every row's first search starts); and `rows` (`(start, end)`: only the
/// gaits of the rows `start..end` of `y`, each point as the whole map has it, with `curves=False`: a part of a
/// study spread over processes, see `vrw.grid`) and `progress` (a callable `progress(done, total)`, called on
/// this thread as grid points finish; the curves, after the gaits, are not counted). Another walker's
/// (`Params(model=...)`): `vrw map --model`'s `map.json` fields and `map`, `x` and `y` two of its parameters,
/// `curves` its changes of stability bisected along the rows (`thresholds`), `initial` its section's
/// coordinates; no `curve_columns`, `curve_method`, `second_route` or `rows`.
#[pyfunction]
#[pyo3(name = "map", signature = (params, *, x = "viscosity", y = "stiffness", x_range = None, y_range = None, nx = 21, ny = 21, curves = true, curve_columns = 25, curve_method = "continuation", second_route = false, initial = None, rows = None, progress = None))]
#[allow(clippy::too_many_arguments)]
fn gait_map<'py>(
    py: Python<'py>,
    params: &Params,
    x: &str,
    y: &str,
    x_range: Option<(f64, f64)>,
    y_range: Option<(f64, f64)>,
    #[pyo3(from_py_with = nx_arg)] nx: usize,
    #[pyo3(from_py_with = ny_arg)] ny: usize,
    curves: bool,
    #[pyo3(from_py_with = curve_columns_arg)] curve_columns: usize,
    curve_method: &str,
    second_route: bool,
    initial: Option<Vec<f64>>,
    rows: Option<(usize, usize)>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (x_range, y_range) = (
        x_range.unwrap_or((1.0, 300.0)),
        y_range.unwrap_or((300.0, 1500.0)),
    );
    let axis = |param: &str, (from, to): (f64, f64), points: usize| SweepSpec {
        param: param.to_string(),
        from,
        to,
        points,
    };
    let spec = MapSpec {
        x: axis(x, x_range, nx),
        y: axis(y, y_range, ny),
    };
    if let Some(w) = params.walker() {
        if rows.is_some() {
            return Err(walkers::whole_only(w, "rows", "map"));
        }
        let wheel_only = [
            ("curve_columns", curve_columns != DEFAULT_CURVE_COLUMNS),
            ("curve_method", curve_method != "continuation"),
            ("second_route", second_route),
        ];
        let options = walkers::MapOptions {
            axes: spec,
            thresholds: curves,
            initial,
            wheel_only: wheel_only.iter().find(|(_, given)| *given).map(|(o, _)| *o),
        };
        return walkers::map(py, w, options, progress);
    }
    let continue_curves = match curve_method {
        "continuation" => true,
        "crossings" => false,
        other => {
            return Err(ConfigError::new_err(format!(
                "invalid value {other:?} for `curve_method`: expected \"continuation\" or \"crossings\""
            )))
        }
    };
    if curve_columns < 2 {
        return Err(ConfigError::new_err(format!(
            "invalid value {curve_columns} for `curve_columns`: at least 2 (both ends of the map)"
        )));
    }
    if second_route && !curves {
        return Err(ConfigError::new_err(
            "`second_route` searches the curves' thresholds again: it needs `curves=True`",
        ));
    }
    let job = MapJob {
        config: params.wheel("map")?.clone(),
        spec,
        initial: section(initial)?,
        options: GaitOptions::default(),
        curves,
        curve_columns,
        continue_curves,
        second_route,
        marks: Vec::new(),
        out_dir: PathBuf::new(),
        overwrite: false,
    };
    let part = rows.map(|(start, end)| start..end);
    let points = nx * part.as_ref().map_or(ny, |p| p.len());
    let progress = Progress::new(progress, points * if second_route { 2 } else { 1 });
    let done = interruptible_keeping(py, vrw::gait::interrupt_flag(), Some(&progress), || {
        let tick = |_: &_| progress.tick();
        match part {
            Some(part) => compute_map_part(&job, part, &tick),
            None => compute_map(&job, &tick),
        }
    });
    keeping_partial(
        py,
        done,
        |(summary, _)| summary.interrupted.clone(),
        |(summary, map)| map_result(py, summary, map, &job.config, (x, y)),
    )
}

/// What `vrw.map` returns: the fields of `curves.json` and the columns of `map.csv` as `map`.
fn map_result<'py>(
    py: Python<'py>,
    summary: &vrw::app::MapSummary,
    map: &vrw::study::GaitMap,
    config: &Config,
    (x, y): (&str, &str),
) -> PyResult<Bound<'py, PyDict>> {
    let result = pythonize(py, summary)?.downcast_into::<PyDict>()?;
    let friction = friction_columns(config, &[x, y]);
    let map_table = table(py, &map_header(x, y, friction), &map_rows(map, friction))?;
    result.set_item("map", map_table)?;
    Ok(result)
}

/// The orbit diagram along one parameter: the states the walk visits after a transient at each value, and the
/// period-1 branch beside it (`vrw orbit`, without the figure).
///
/// Returns the fields of `orbit.json` (`spec`, `outcomes`, `branch_gaits`, ...), `orbit`, the columns of
/// `orbit.csv` (one row per recorded step of every value), and with `branch` (default) `branch`, the columns of
/// `branch.csv`. Keyword arguments as the command line's options: `range` (`(from, to)`, default the command
/// line's `(1, 150)`), `points` (300), `transient` (32), `steps` (64), `initial`, `branch`; and `progress` (a
/// callable `progress(done, total)`, called on this thread as the values' walks finish). `part` computes one
/// part of the job apart (a study spread over processes, see `vrw.grid.orbit_grid`): `"coarse"`, `("fill",
/// k, left)` or `"branch"`; the result then also has `ends` and `column_rows` (see `parts`). Another walker's
/// (`Params(model=...)`): `vrw orbit --model`'s, without `progress` and `part` yet.
#[pyfunction]
#[pyo3(signature = (params, param = "viscosity", *, range = None, points = 300, transient = 32, steps = 64, initial = None, branch = true, progress = None, part = None))]
#[allow(clippy::too_many_arguments)]
fn orbit<'py>(
    py: Python<'py>,
    params: &Params,
    param: &str,
    range: Option<(f64, f64)>,
    #[pyo3(from_py_with = points_arg)] points: usize,
    #[pyo3(from_py_with = transient_arg)] transient: usize,
    #[pyo3(from_py_with = steps_arg)] steps: usize,
    initial: Option<Vec<f64>>,
    branch: bool,
    progress: Option<Py<PyAny>>,
    #[pyo3(from_py_with = parts::orbit_part_arg)] part: Option<OrbitJobPart>,
) -> PyResult<Bound<'py, PyDict>> {
    let (from, to) = range.unwrap_or((1.0, 150.0));
    if let Some(w) = params.walker() {
        let range = WalkerRange {
            param: param.to_string(),
            from,
            to,
            points,
        };
        let walk = (transient, steps);
        return walkers::orbit(
            py,
            w,
            range,
            walk,
            initial,
            branch,
            progress,
            part.is_some(),
        );
    }
    let job = OrbitJob {
        config: params.wheel("orbit")?.clone(),
        spec: OrbitSpec {
            range: SweepSpec {
                param: param.to_string(),
                from,
                to,
                points,
            },
            transient,
            steps,
        },
        initial: section(initial)?,
        branch,
        plot: "lambda_I4".to_string(),
        out_dir: PathBuf::new(),
        overwrite: false,
    };
    let progress = Progress::new(progress, points);
    let (summary, columns, ends, gaits) =
        interruptible_with(py, vrw::gait::interrupt_flag(), Some(&progress), || {
            let tick = |_: &_| progress.tick();
            match part {
                Some(part) => compute_orbit_part(&job, part, &tick),
                None => compute_orbit(&job, &tick).map(|(s, c, g)| (s, c, Vec::new(), g)),
            }
        })?
        .map_err(app_error)?;
    let result = pythonize(py, &summary)?.downcast_into::<PyDict>()?;
    if part.is_some() {
        parts::orbit_part_extras(&result, &columns, &ends)?;
    }
    let friction = friction_columns(&job.config, &[param]);
    result.set_item(
        "orbit",
        table(
            py,
            &orbit_header(param, friction),
            &orbit_rows(&columns, friction),
        )?,
    )?;
    if branch {
        result.set_item(
            "branch",
            table(
                py,
                &branch_header(param, friction),
                &branch_rows(&gaits, friction),
            )?,
        )?;
    }
    Ok(result)
}

/// `orbit`'s `points`, named in its errors.
fn points_arg(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    count("points", value)
}

/// `orbit`'s `transient`, named in its errors.
fn transient_arg(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    count("transient", value)
}

/// `map`'s `curve_columns`, named in its errors.
fn curve_columns_arg(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    count("curve_columns", value)
}

/// Follow the gait family through the gait at `start` in `param` by pseudo-arclength continuation (`vrw
/// continue`, without the figure).
///
/// Returns the fields of `special_points.json` (`families` with how each ends and why, `special_points`,
/// `warnings`, ...) and `branch`, the columns of `branch.csv` as numpy arrays. Keyword arguments as the command
/// line's options: `start` (default the parameter's value in `params`), `range` (`(from, to)`, `None`: the
/// command line's `(1, 300)`), `initial`, `period`, `max_points`, `max_step`, `switch` (follow the families born at period
/// doublings, border collisions and ends; the command line's `--no-switch` is `switch=False`), `two_param`
/// (`(name, from, to)`: the command line's `--two-param name --two-range from,to`; the curves' points are then
/// `curve_points`, the columns of `curves.csv`), `extremum` (a list of monitored quantities: the command line's
/// `--extremum`, each located extremum a special point `EX` with its `extremum` record, and `monitored`, the
/// columns of `monitored.csv`). Another walker's (`Params(model=...)`): `vrw continue
/// --model`'s, its start's family only (no `initial`, `period`, `two_param`).
#[pyfunction]
#[pyo3(signature = (params, param = "viscosity", *, start = None, range = None, initial = None, period = None, max_points = 300, max_step = 0.1, switch = true, two_param = None, extremum = None))]
#[allow(clippy::too_many_arguments)]
fn continue_family<'py>(
    py: Python<'py>,
    params: &Params,
    param: &str,
    start: Option<f64>,
    range: Option<(f64, f64)>,
    initial: Option<Vec<f64>>,
    period: Option<usize>,
    #[pyo3(from_py_with = max_points_arg)] max_points: usize,
    max_step: f64,
    switch: bool,
    two_param: Option<(String, f64, f64)>,
    extremum: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyDict>> {
    let flag = Arc::new(AtomicBool::new(false));
    let range = range.unwrap_or((1.0, 300.0));
    let extremum = extremum.unwrap_or_default();
    if let Some(w) = params.walker() {
        let options = walkers::FamilyOptions {
            start,
            range,
            max_points,
            max_step,
            wheel_only: [
                ("initial", initial.is_some()),
                ("period", period.is_some()),
                ("two_param", two_param.is_some()),
                ("extremum", !extremum.is_empty()),
            ]
            .iter()
            .find(|(_, given)| *given)
            .map(|(o, _)| *o),
        };
        return walkers::continue_family(py, w, param, options);
    }
    let job = ContinueJob {
        config: params.wheel("continue_family")?.clone(),
        param: param.to_string(),
        start,
        from: range.0,
        to: range.1,
        initial: section(initial)?,
        period,
        max_points,
        max_step,
        switch,
        plot: "thetadot".to_string(),
        out_dir: PathBuf::new(),
        overwrite: false,
        interrupt: Some(Arc::clone(&flag)),
        two_param,
        extremum,
    };
    let result = interruptible(py, &flag, || compute_continuation(&job))?.map_err(app_error)?;
    let out = pythonize(py, &result.summary)?.downcast_into::<PyDict>()?;
    // Wall time: not in special_points.json (reproducible files), but the result says it.
    out.set_item("seconds", result.summary.seconds)?;
    let friction = friction_columns(&job.config, &[param]);
    let rows: Vec<Vec<Cell>> = family_rows(&result)
        .iter()
        .map(|r| family_row(r, friction))
        .collect();
    out.set_item("branch", table(py, &family_header(param, friction), &rows)?)?;
    if !result.extrema.monitored.is_empty() {
        let rows = monitored_rows(&result.families, &result.extrema.monitored);
        out.set_item("monitored", table(py, &monitored_header(param), &rows)?)?;
    }
    if let Some(first) = result.summary.curves.first() {
        let rows: Vec<Vec<Cell>> = curve_rows(&result).iter().map(curve_row).collect();
        let header = curve_header((param, &first.param2));
        out.set_item("curve_points", table(py, &header, &rows)?)?;
    }
    Ok(out)
}

/// `continue_family`'s `max_points`, named in its errors.
fn max_points_arg(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    count("max_points", value)
}

/// `basin`'s `nx`, named in its errors.
fn nx_arg(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    count("nx", value)
}

/// `basin`'s `ny`, named in its errors.
fn ny_arg(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    count("ny", value)
}

/// `basin`'s `max_steps`, named in its errors.
fn max_steps_arg(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    count("max_steps", value)
}

/// `basin`'s `tolerance`, named in its errors.
fn tolerance_arg(value: &Bound<'_, PyAny>) -> PyResult<f64> {
    real("tolerance", value)
}

/// `Params(**keys)`: how a pickled `Params` is rebuilt (`Params.__reduce__`).
#[pyfunction]
fn _params_from_dict(keys: &Bound<'_, PyDict>) -> PyResult<Params> {
    Params::new(None, Some(keys))
}

/// `Params(model=model, **keys)`, a description read from its `text`: how a pickled walker's `Params` is
/// rebuilt (`Params.__reduce__`).
#[pyfunction]
#[pyo3(signature = (model, text, keys))]
fn _walker_params(model: &str, text: Option<&str>, keys: &Bound<'_, PyDict>) -> PyResult<Params> {
    let overrides = walkers::overrides(Some(keys))?;
    Ok(Params {
        model: Model::Walker(WalkerParams::load(model, text, None, &overrides)?),
    })
}

/// Run `work` with the GIL released, Ctrl-C stopping it ([`progress::interruptible_with`] without a progress
/// report).
fn interruptible<T: Send>(
    py: Python<'_>,
    flag: &AtomicBool,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    interruptible_with(py, flag, None, work)
}

/// The values `vrw sweep --from START --to STOP --points POINTS` visits (evenly spaced, ends included), checked
/// as the command line checks them (2 to `MAX_SWEEP_POINTS` points) before any is made.
#[pyfunction]
fn linspace(start: f64, stop: f64, points: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let points = count("points", points)?;
    let invalid = |value: String, reason: String| {
        config_error(LibConfigError::InvalidValue {
            key: "linspace".to_string(),
            value,
            reason,
        })
    };
    if !(start.is_finite() && stop.is_finite()) || start == stop {
        return Err(invalid(
            format!("start {} stop {}", short(start), short(stop)),
            "needs two different finite ends".to_string(),
        ));
    }
    if !(2..=MAX_SWEEP_POINTS).contains(&points) {
        return Err(invalid(
            format!("points {points}"),
            format!("a sweep takes between 2 and {MAX_SWEEP_POINTS} values"),
        ));
    }
    let spec = SweepSpec {
        param: String::new(),
        from: start,
        to: stop,
        points,
    };
    Ok(spec.values())
}

#[pymodule]
fn _vrw(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<Params>()?;
    m.add_function(wrap_pyfunction!(_params_from_dict, m)?)?;
    m.add_function(wrap_pyfunction!(_walker_params, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(find_gait, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(basin, m)?)?;
    m.add_function(wrap_pyfunction!(continue_family, m)?)?;
    m.add_function(wrap_pyfunction!(gait_map, m)?)?;
    m.add_function(wrap_pyfunction!(orbit, m)?)?;
    m.add_function(wrap_pyfunction!(linspace, m)?)?;
    m.add_function(wrap_pyfunction!(animate::animate, m)?)?;
    m.add("ConfigError", py.get_type::<ConfigError>())?;
    m.add("WalkError", py.get_type::<WalkError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
