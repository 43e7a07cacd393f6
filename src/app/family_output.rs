//! The files of `vrw continue` (docs/model.md section 11): `branch.csv`, `special_points.json` and the
//! bifurcation diagram `bifurcation.{svg,png}`.

use super::family::{compute_continuation, ContinueJob, ContinueResult};
use super::family_extrema::{monitored_header, monitored_rows};
use super::{axis_label, in_run, AppError};
use crate::continuation::{Family, FamilyEnd, SpecialPoint};
use crate::family::GaitInfo;
use crate::gait::Stability;
use crate::output::bifurcation_plot::{
    BifurcationFigure, DiagramFamily, DiagramSpecial, BIFURCATION_SIZE,
};
use crate::output::chart::write_svg_png;
use crate::output::manifest::RunDir;
use crate::output::{write_curves_csv, write_family_csv, write_json, CurveRow, FamilyRow};

/// Run `vrw continue`: [`compute_continuation`], then write `branch.csv`, `special_points.json` and the
/// diagram.
///
/// The options and the output directory are checked before anything is computed. Interrupted (Ctrl-C,
/// [`ContinueSummary::interrupted`](super::ContinueSummary::interrupted)), it writes
/// `branch.csv` and `special_points.json` with what was complete, no figure, and returns
/// [`AppError::Interrupted`] (the manifest says `interrupted`).
pub fn run_continuation(job: &ContinueJob) -> Result<ContinueResult, AppError> {
    job.validate()?;
    crate::output::manifest::check_out_dir(&job.out_dir, "continue", job.overwrite)?;
    let mut result = compute_continuation(job)?;
    in_run(&job.out_dir, job.overwrite, "continue", |run| {
        write_continuation(job, &mut result, run)?;
        match result.summary.interrupted.clone() {
            Some(during) => Err(AppError::Interrupted {
                during,
                kept: format!(
                    "{} hold what was complete",
                    result.summary.files.join(" and ")
                ),
            }),
            None => Ok((result, None)),
        }
    })
}

/// The rows of `branch.csv` of a computed continuation (also the Python binding's `branch` table).
pub fn family_rows(result: &ContinueResult) -> Vec<FamilyRow<'_>> {
    result
        .families
        .iter()
        .zip(&result.stability)
        .enumerate()
        .flat_map(|(k, (family, verdicts))| {
            family.points.iter().zip(verdicts).enumerate().map(
                move |(index, (point, &stability))| FamilyRow {
                    family: k + 1,
                    period_k: family.period,
                    index,
                    point,
                    stability,
                },
            )
        })
        .collect()
}

/// The rows of `curves.csv` of a computed continuation: every point of every two-parameter curve.
pub fn curve_rows(result: &ContinueResult) -> Vec<CurveRow<'_>> {
    result
        .curves
        .iter()
        .zip(&result.summary.curves)
        .flat_map(|(curve, record)| {
            curve.points.iter().map(move |point| CurveRow {
                curve: record.curve,
                condition: &record.condition,
                point,
            })
        })
        .collect()
}

/// Write the files of a computed continuation into `run`.
fn write_continuation(
    job: &ContinueJob,
    result: &mut ContinueResult,
    run: &mut RunDir,
) -> Result<(), AppError> {
    let param = &job.param;
    let rows = family_rows(result);
    let friction = crate::output::friction_columns(&job.config, &[param]);
    write_family_csv(&run.path("branch.csv"), param, friction, &rows)?;
    run.add("branch.csv");
    let mut files = vec!["branch.csv".to_string()];
    if result.summary.interrupted.is_some() {
        // No figure of an interrupted job: it would draw cut families as if they ended there.
        files.push("special_points.json".to_string());
        result.summary.files = files;
        write_json(&run.path("special_points.json"), &result.summary)?;
        run.add("special_points.json");
        return Ok(());
    }
    let figure = diagram(job, result);
    write_svg_png(
        &figure,
        &run.path("bifurcation.svg"),
        &run.path("bifurcation.png"),
        BIFURCATION_SIZE,
    )?;
    for name in ["bifurcation.svg", "bifurcation.png"] {
        run.add(name);
        files.push(name.to_string());
    }
    if !result.extrema.monitored.is_empty() {
        crate::output::write_table(
            &run.path("monitored.csv"),
            &monitored_header(param),
            monitored_rows(&result.families, &result.extrema.monitored),
        )?;
        run.add("monitored.csv");
        files.push("monitored.csv".to_string());
    }
    if !result.curves.is_empty() {
        let param2 = result.summary.curves[0].param2.clone();
        write_curves_csv(
            &run.path("curves.csv"),
            (param, &param2),
            &curve_rows(result),
        )?;
        let figure = curves_figure(job, result, &param2);
        write_svg_png(
            &figure,
            &run.path("curves.svg"),
            &run.path("curves.png"),
            BIFURCATION_SIZE,
        )?;
        for name in ["curves.csv", "curves.svg", "curves.png"] {
            run.add(name);
            files.push(name.to_string());
        }
    }
    files.insert(1, "special_points.json".to_string());
    result.summary.files = files;
    write_json(&run.path("special_points.json"), &result.summary)?;
    run.add("special_points.json");
    Ok(())
}

/// The two-parameter curves in the plane of the two parameters.
fn curves_figure(job: &ContinueJob, result: &ContinueResult, param2: &str) -> BifurcationFigure {
    BifurcationFigure {
        title: format!(
            "Curves of special points in ({}, {param2}){}",
            job.param,
            super::settings_note(&job.config, &[&job.param, param2])
        ),
        param_label: axis_label(&job.param),
        y_label: axis_label(param2),
        // The curves' extent in the followed parameter, with a margin (a fold's curve may span a sliver of
        // the family's range).
        x: {
            let p1 = result
                .curves
                .iter()
                .flat_map(|c| c.points.iter().map(|p| p.p1));
            let (lo, hi) = p1.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
            let margin = 0.05 * (hi - lo).max(1e-9 * hi.abs().max(1.0));
            if lo <= hi {
                (lo - margin).max(job.from)..(hi + margin).min(job.to)
            } else {
                job.from..job.to
            }
        },
        families: result
            .curves
            .iter()
            .zip(&result.summary.curves)
            .map(|(curve, record)| DiagramFamily {
                label: format!("curve {}: {} = 0", record.curve, record.condition),
                phases: vec![curve
                    .points
                    .iter()
                    .map(|p| (p.p1, p.p2, Some(true)))
                    .collect()],
                ends: Vec::new(),
            })
            .collect(),
        // Each curve's start: the special point of the family it was continued from.
        special: result
            .summary
            .curves
            .iter()
            .enumerate()
            .filter_map(|(k, record)| {
                let sp = result.summary.special_points.get(record.special_point)?;
                Some(DiagramSpecial {
                    family: k,
                    param: sp.param,
                    value: result.summary.config.get_numeric(param2).ok()?,
                    label: record.kind.to_string(),
                })
            })
            .collect(),
        styles_in_legend: false,
    }
}

/// The bifurcation diagram of a computed continuation.
fn diagram(job: &ContinueJob, result: &ContinueResult) -> BifurcationFigure {
    let families: Vec<DiagramFamily> = result
        .families
        .iter()
        .zip(&result.stability)
        .enumerate()
        .map(|(k, (f, verdicts))| diagram_family(job, result, k, f, verdicts))
        .collect();
    BifurcationFigure {
        title: format!(
            "Gait families in {} (period of the start: {}){}",
            job.param,
            result.families.first().map_or(1, |f| f.period),
            super::settings_note(&job.config, &[&job.param])
        ),
        param_label: axis_label(&job.param),
        y_label: quantity_label(&job.plot),
        x: job.from..job.to,
        families,
        special: diagram_specials(job, result),
        styles_in_legend: true,
    }
}

/// The `k`-th family `f` of the diagram, with the stability `verdicts` of its points: a line per step of
/// its period (one for the multipliers) and its ends where it failed.
fn diagram_family(
    job: &ContinueJob,
    result: &ContinueResult,
    k: usize,
    f: &Family<GaitInfo>,
    verdicts: &[Stability],
) -> DiagramFamily {
    // One line per step of the period (the multipliers are the orbit's: one line).
    let phases = if job.plot == "max_floquet" {
        1
    } else {
        f.period
    };
    let ends = result.summary.families[k]
        .ends
        .iter()
        .zip([f.points.first(), f.points.last()])
        .filter_map(|(end, point)| match (&end.end, point) {
            (FamilyEnd::Ended { failure, .. }, Some(p)) => {
                let value = match job.plot.as_str() {
                    "max_floquet" => p.max_multiplier(),
                    q => quantity_of_report(&p.info.report, q),
                };
                Some((p.param, value, failure.clone()))
            }
            _ => None,
        })
        .collect();
    DiagramFamily {
        ends,
        label: format!("family {} (period {})", k + 1, f.period),
        phases: (0..phases)
            .map(|j| {
                f.points
                    .iter()
                    .zip(verdicts)
                    .map(|(p, s)| {
                        let stable = match s {
                            Stability::Stable => Some(true),
                            Stability::Unstable => Some(false),
                            Stability::Uncertain => None,
                        };
                        let value = match job.plot.as_str() {
                            "max_floquet" => p.max_multiplier(),
                            q => p
                                .info
                                .cycle
                                .get(j)
                                .map_or(f64::NAN, |r| quantity_of_report(r, q)),
                        };
                        (p.param, value, stable)
                    })
                    .collect()
            })
            .collect(),
    }
}

/// The special points of every family, at the value the diagram draws; then the located extrema of
/// `--extremum`, labelled `max` or `min` (`corner min` at a corner) and the quantity.
fn diagram_specials(job: &ContinueJob, result: &ContinueResult) -> Vec<DiagramSpecial> {
    let drawn = |k: usize, s: &SpecialPoint<GaitInfo>, label: String| DiagramSpecial {
        family: k,
        param: s.param,
        value: match job.plot.as_str() {
            "max_floquet" => s.multipliers.first().map_or(f64::NAN, |m| m.norm()),
            q => s
                .info
                .as_ref()
                .map_or(f64::NAN, |i| quantity_of_report(&i.report, q)),
        },
        label,
    };
    let mut special: Vec<DiagramSpecial> = result
        .families
        .iter()
        .enumerate()
        .flat_map(|(k, f)| {
            f.special
                .iter()
                .map(move |s| drawn(k, s, s.kind.label().to_string()))
        })
        .collect();
    special.extend(
        result
            .extrema
            .extrema
            .iter()
            .filter(|(_, e)| e.special.located)
            .map(|(k, e)| {
                let corner = if e.corner.is_some() { "corner " } else { "" };
                drawn(*k, &e.special, format!("{corner}{} {}", e.kind, e.quantity))
            }),
    );
    special
}

/// The axis label of a quantity of [`super::DIAGRAM_QUANTITIES`], with its unit.
fn quantity_label(quantity: &str) -> String {
    match quantity {
        "L2" => "L2 before touchdown [m]",
        "thetadot" => "dθ/dt before touchdown [rad/s]",
        "L2dot" => "dL2/dt before touchdown [m/s]",
        "lambda_I4" => "λI4 [N s]",
        "lambda_2_plus" => "λ2+ [N]",
        "lambda_4_plus" => "λ4+ [N]",
        "max_floquet" => "largest |Floquet multiplier|",
        "period" => "step period [s]",
        "speed" => "speed [m/s]",
        "dls_duration" => "DLS duration [s]",
        other => other,
    }
    .to_string()
}

/// The value of a report quantity (those of [`super::DIAGRAM_QUANTITIES`] other than `max_floquet`).
fn quantity_of_report(r: &crate::walk::StepReport, quantity: &str) -> f64 {
    match quantity {
        "L2" => r.section.l2,
        "thetadot" => r.section.theta_dot,
        "L2dot" => r.section.l2_dot,
        "lambda_I4" => r.indicators.lambda_i4,
        "lambda_2_plus" => r.indicators.lambda_2_plus,
        "lambda_4_plus" => r.indicators.lambda_4_plus,
        "period" => r.period,
        "speed" => r.speed,
        "dls_duration" => r.dls_duration,
        _ => f64::NAN,
    }
}
