//! The parts of a job computed apart, for `vrw.grid` (a study spread over processes): how a part is named
//! from Python, and what it hands back besides the job's own result.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyStringMethods};

use vrw::app::OrbitJobPart;
use vrw::study::orbit::{OrbitColumn, OrbitPart};
use vrw::walk::SectionState;

use crate::{section, ConfigError};

/// `orbit`'s `part`: `"coarse"` (the diagram's coarse pass), `("fill", k, left)` (the values after the `k`-th
/// coarse value, from `left`, the `(L2, thetadot, L2dot)` its walk ended in, or `None`) or `"branch"`.
pub(crate) fn orbit_part_arg(value: &Bound<'_, PyAny>) -> PyResult<Option<OrbitJobPart>> {
    if value.is_none() {
        return Ok(None);
    }
    if let Ok(word) = value.downcast::<PyString>() {
        return match word.to_cow()?.as_ref() {
            "coarse" => Ok(Some(OrbitJobPart::Diagram(OrbitPart::Coarse))),
            "branch" => Ok(Some(OrbitJobPart::Branch)),
            other => Err(invalid(other)),
        };
    }
    let (name, k, left): (String, usize, Option<Vec<f64>>) =
        value.extract().map_err(|_| invalid(&value.to_string()))?;
    if name != "fill" {
        return Err(invalid(&name));
    }
    let left = section(left)?;
    Ok(Some(OrbitJobPart::Diagram(OrbitPart::Fill { k, left })))
}

fn invalid(part: &str) -> PyErr {
    ConfigError::new_err(format!(
        "invalid value {part:?} for `part`: \"coarse\", (\"fill\", k, left) or \"branch\""
    ))
}

/// What a part of the orbit diagram hands back besides `orbit.json`'s fields and its rows of `orbit.csv`:
/// `ends`, the state each column's walk ended in (`[L2, thetadot, L2dot]`, with `slip` after them where the
/// stance tip slips, `None` where it failed: what the
/// coarse pass hands to the fills), and `column_rows`, each column's number of rows in `orbit`.
pub(crate) fn orbit_part_extras(
    result: &Bound<'_, PyDict>,
    columns: &[OrbitColumn],
    ends: &[Option<SectionState>],
) -> PyResult<()> {
    let ends: Vec<Option<Vec<f64>>> = ends
        .iter()
        .map(|e| e.as_ref().map(SectionState::values))
        .collect();
    result.set_item("ends", ends)?;
    let rows: Vec<usize> = columns.iter().map(|c| c.returns.len().max(1)).collect();
    result.set_item("column_rows", rows)
}
