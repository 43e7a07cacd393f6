//! `vrw continue --extremum NAME` (docs/model.md section 11): the gait quantities monitored along every family
//! followed, with their derivatives along the family (`monitored.csv`), and the extrema of the named ones as
//! special points (`EX` in `special_points.json`, after the others).

use std::sync::atomic::AtomicBool;

use super::family_records::{special_record, ExtremumRecord, SpecialRecord};
use super::AppError;
use crate::continuation::monitor::{
    extrema, monitor_family, Extremum, Monitor, Monitored, EXTREMUM_TOL, MONITOR_STEP,
};
use crate::family::diagram::FollowedFamily;
use crate::family::monitor::{GaitQuantity, MONITORED_QUANTITIES};
use crate::family::GaitInfo;
use crate::output::Cell;
use crate::walk::interrupt::stop_requested;

/// How `dq/ds` is computed, as `special_points.json` says it.
pub const DERIVATIVE_METHOD: &str = "dq/ds = grad q . t along the arclength s in the scaled unknowns \
    (x, p / sigma): the unit tangent t from the exact DP and dP/dp, grad q . t by central differences of q \
    along t (no exact derivative of the quantities themselves)";

/// The monitored quantities of every family and the extrema of the named ones.
#[derive(Debug, Clone, Default)]
pub struct FamilyExtrema {
    /// `[family][point][quantity]`, the quantities in [`MONITORED_QUANTITIES`]' order.
    pub monitored: Vec<Vec<Vec<Monitored>>>,
    /// The extrema, each with the index of its family.
    pub extrema: Vec<(usize, Extremum<GaitInfo>)>,
}

/// Checks the names of `--extremum`.
pub(super) fn check_extremum_names(names: &[String]) -> Result<(), AppError> {
    match names.iter().find(|n| GaitQuantity::named(n).is_none()) {
        Some(unknown) => Err(AppError::InvalidOption {
            option: "extremum",
            reason: format!(
                "unknown quantity {:?}: expected one of {}",
                crate::fmt::clip(unknown),
                MONITORED_QUANTITIES.join(", ")
            ),
        }),
        None => Ok(()),
    }
}

impl FamilyExtrema {
    /// The extrema as special points of `special_points.json`.
    pub(super) fn records(&self) -> Vec<SpecialRecord> {
        self.extrema
            .iter()
            .map(|(k, e)| extremum_record(k + 1, e))
            .collect()
    }
}

/// Every quantity of [`MONITORED_QUANTITIES`] along every family, and the extrema of those of `names`
/// (a name given twice counts once); nothing without names or when `skip` (an interrupt came before: the
/// families may be cut short), and nothing kept if the interrupt `flag` is set while they are located (an
/// interrupted probe leaves its extremum out).
pub(super) fn family_extrema(
    names: &[String],
    families: &[FollowedFamily],
    skip: bool,
    flag: Option<&AtomicBool>,
) -> FamilyExtrema {
    if names.is_empty() || skip {
        return FamilyExtrema::default();
    }
    let quantities = GaitQuantity::all();
    let monitors: Vec<&dyn Monitor<GaitInfo>> = quantities
        .iter()
        .map(|q| q as &dyn Monitor<GaitInfo>)
        .collect();
    let mut out = FamilyExtrema::default();
    for (k, f) in families.iter().enumerate() {
        let monitored = monitor_family(&f.map, &f.family, &monitors);
        for (j, q) in quantities.iter().enumerate() {
            if !names.iter().any(|n| n == q.name()) {
                continue;
            }
            let column: Vec<Monitored> = monitored.iter().map(|m| m[j]).collect();
            out.extrema.extend(
                extrema(&f.map, &f.family, q, &column)
                    .into_iter()
                    .map(|e| (k, e)),
            );
        }
        out.monitored.push(monitored);
    }
    if stop_requested(flag) {
        return FamilyExtrema::default();
    }
    out
}

/// An extremum as a special point of `special_points.json`.
fn extremum_record(family: usize, e: &Extremum<GaitInfo>) -> SpecialRecord {
    let mut record = special_record(family, &e.special);
    record.extremum = Some(ExtremumRecord {
        quantity: e.quantity.clone(),
        extremum: e.kind,
        shape: if e.corner.is_some() {
            "corner"
        } else {
            "smooth"
        },
        corner: e.corner.clone(),
        value: e.value,
        located_bracket: e.located_bracket,
        speed: e.special.info.as_ref().map_or(f64::NAN, |i| i.report.speed),
        derivative: format!(
            "{DERIVATIVE_METHOD}, step {MONITOR_STEP:e}; located to {EXTREMUM_TOL:e}"
        ),
    });
    record
}

/// The header of `monitored.csv`: which point, then each quantity and its derivative along the family.
pub fn monitored_header(param: &str) -> Vec<String> {
    let mut header: Vec<String> = ["family", "point", "arclength", param]
        .iter()
        .map(|s| s.to_string())
        .collect();
    for q in MONITORED_QUANTITIES {
        header.push(q.to_string());
        header.push(format!("d{q}_ds"));
    }
    header
}

/// The rows of `monitored.csv`: one per point of every family.
pub fn monitored_rows(
    families: &[crate::continuation::Family<GaitInfo>],
    monitored: &[Vec<Vec<Monitored>>],
) -> Vec<Vec<Cell>> {
    let mut rows = Vec::new();
    for (k, (family, values)) in families.iter().zip(monitored).enumerate() {
        for (i, (point, row)) in family.points.iter().zip(values).enumerate() {
            let mut cells = vec![
                Cell::Count(k + 1),
                Cell::Count(i),
                Cell::Real(point.arclength),
                Cell::Real(point.param),
            ];
            for m in row {
                cells.push(Cell::Real(m.value));
                cells.push(Cell::Real(m.derivative));
            }
            rows.push(cells);
        }
    }
    rows
}
