//! The tables of `vrw orbit` (`orbit.csv`, `branch.csv`) and `vrw basin` (`basin.csv`): their headers and
//! rows.

use crate::gait::basin::BasinPoint;
use crate::gait::orbit::OrbitColumn;
use crate::gait::Gait;
use crate::output::{self, finish_csv, num, write_record};
use crate::walk::StepReport;

use super::AppError;

/// The section state and the three DLS indicators, as columns of `orbit.csv` and `branch.csv`.
const STATE_COLUMNS: [&str; 6] = [
    "L2",
    "thetadot",
    "L2dot",
    "lambda_I4",
    "lambda_2_plus",
    "lambda_4_plus",
];

/// The section state and indicators of a step as CSV fields.
fn step_fields(r: &StepReport) -> [String; 7] {
    let i = &r.indicators;
    [
        num(r.section.l2),
        num(r.section.theta_dot),
        num(r.section.l2_dot),
        num(i.lambda_i4),
        num(i.lambda_2_plus),
        num(i.lambda_4_plus),
        r.branch.to_string(),
    ]
}

/// `orbit.csv`: one row per recorded step (its number from 1 after the transient); a value whose walk failed
/// before recording anything has one row with empty step fields.
pub(super) fn write_orbit_csv(
    path: &std::path::Path,
    param: &str,
    columns: &[OrbitColumn],
) -> Result<(), AppError> {
    let mut w = output::csv_writer(path)?;
    let header: Vec<&str> = [param, "status", "period_k", "step"]
        .into_iter()
        .chain(STATE_COLUMNS)
        .chain(["branch", "continued_from"])
        .collect();
    write_record(&mut w, path, &header)?;
    for c in columns {
        let head = [
            num(c.value),
            c.status.clone(),
            c.period_k.map_or_else(String::new, |k| k.to_string()),
        ];
        let from = c.continued_from.map_or_else(String::new, num);
        if c.returns.is_empty() {
            let mut row = head.to_vec();
            row.extend(std::iter::repeat_n(String::new(), 8));
            row.push(from.clone());
            write_record(&mut w, path, &row)?;
        }
        for (n, r) in c.returns.iter().enumerate() {
            let mut row = head.to_vec();
            row.push((n + 1).to_string());
            row.extend(step_fields(r));
            row.push(from.clone());
            write_record(&mut w, path, &row)?;
        }
    }
    Ok(finish_csv(w, path)?)
}

/// `branch.csv`: the period-1 gait at each value (empty where there is none).
pub(super) fn write_branch_csv(
    path: &std::path::Path,
    param: &str,
    branch: &[(f64, Option<Gait>)],
) -> Result<(), AppError> {
    let mut w = output::csv_writer(path)?;
    let header: Vec<&str> = std::iter::once(param)
        .chain(STATE_COLUMNS)
        .chain(["max_floquet", "stability"])
        .collect();
    write_record(&mut w, path, &header)?;
    for (value, gait) in branch {
        let mut row = vec![num(*value)];
        match gait {
            Some(g) => {
                row.extend(
                    [
                        g.section.l2,
                        g.section.theta_dot,
                        g.section.l2_dot,
                        g.lambda_i4,
                        g.lambda_2_plus,
                        g.lambda_4_plus,
                        g.max_floquet,
                    ]
                    .map(num),
                );
                row.push(g.stability.to_string());
            }
            None => row.extend(std::iter::repeat_n(String::new(), 8)),
        }
        write_record(&mut w, path, &row)?;
    }
    Ok(finish_csv(w, path)?)
}

/// `basin.csv`: one row per grid point.
pub(super) fn write_basin_csv(
    path: &std::path::Path,
    grid: &[Vec<BasinPoint>],
) -> Result<(), AppError> {
    let mut w = output::csv_writer(path)?;
    write_record(
        &mut w,
        path,
        [
            "ix",
            "iy",
            "L2",
            "thetadot",
            "L2dot",
            "outcome",
            "steps",
            "period_k",
            "end_L2",
            "end_thetadot",
            "end_L2dot",
        ],
    )?;
    for p in grid.iter().flatten() {
        let o = &p.outcome;
        let mut row = vec![
            p.ix.to_string(),
            p.iy.to_string(),
            num(p.start.l2),
            num(p.start.theta_dot),
            num(p.start.l2_dot),
            o.kind.clone(),
            o.steps.to_string(),
            o.period_k.map_or_else(String::new, |k| k.to_string()),
        ];
        match &o.end {
            Some(e) => row.extend([e.l2, e.theta_dot, e.l2_dot].map(num)),
            None => row.extend(std::iter::repeat_n(String::new(), 3)),
        }
        write_record(&mut w, path, &row)?;
    }
    Ok(finish_csv(w, path)?)
}
