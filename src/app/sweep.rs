//! The job of `vrw sweep`: one parameter swept with continuation, its thresholds, `sweep.csv`,
//! `thresholds.json`, and Fig. 2 with the intervals without a gait.

use std::path::PathBuf;

use serde::Serialize;

use crate::family::Parameter;
use crate::fmt::short;
use crate::gait::GaitOptions;
use crate::output;
use crate::output::plot::{
    write_fig2 as write_fig2_files, Fig2Spec, IndicatorPoint, ThresholdMark,
};
use crate::params::{Config, ConfigError};
use crate::study::parallelism::{PhaseWork, TaskGraph, WithParallelism};
use crate::study::sweep::{checked_row, gait_rows_measured};
use crate::study::thresholds::find_thresholds_costed;
use crate::study::{SecondRoute, SweepPoint, SweepSpec, Threshold};
use crate::walk::SectionState;

use super::{
    axis_label, check_interrupted, check_phase_interrupted, in_run, prepared, second_route_config,
    short_name, AppError,
};
use crate::output::manifest::RunDir;

/// What `vrw sweep` runs.
#[derive(Debug, Clone)]
pub struct SweepJob {
    /// Parameters and solver options (the swept key is overridden point by point).
    pub config: Config,
    /// The parameter and its range.
    pub spec: SweepSpec,
    /// Where the search at the first point starts (`None`:
    /// [`default_initial`](crate::reference::default_initial)).
    pub initial: Option<SectionState>,
    /// Search settings.
    pub options: GaitOptions,
    /// Search every threshold again by a second route (the whole sweep with the other integrator) and record
    /// in each whether it is confirmed ([`SecondRoute`]).
    pub second_route: bool,
    /// Where `sweep.csv`, `thresholds.json`, `fig2.svg` and `fig2.png` go.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir` (its files are removed and listed in the manifest);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    pub overwrite: bool,
}

/// `thresholds.json`.
#[derive(Debug, Clone, Serialize)]
pub struct SweepSummary {
    /// Version of vrw that produced the file.
    pub vrw_version: &'static str,
    /// Parameters and solver options (the swept key at its configured value).
    pub config: Config,
    /// The sweep.
    pub spec: SweepSpec,
    /// Points with a gait / all points.
    pub gaits_found: usize,
    /// Number of sweep points.
    pub points: usize,
    /// Every located threshold, in parameter order.
    pub thresholds: Vec<Threshold>,
    /// Wall-clock seconds spent on the sweep and on the thresholds (printed, not written: files are
    /// reproducible).
    #[serde(skip)]
    pub seconds: [f64; 2],
    /// Wall-clock seconds spent on the second route (0 without it; printed, not written).
    #[serde(skip)]
    pub second_route_seconds: f64,
    /// The work and span of the gaits and of the thresholds ([`crate::study::parallelism`]); written to
    /// `thresholds.json` (after these fields) by [`run_sweep`], in steps walked.
    #[serde(skip)]
    pub parallelism: Vec<PhaseWork>,
    /// The files this run wrote into the output directory (Fig. 2 only if some point has a gait; an earlier
    /// run's figure is removed rather than left beside this run's tables).
    pub files: Vec<String>,
    /// Every audit value above its tolerance in the steps of the gaits found (empty when every law holds).
    pub warnings: Vec<String>,
}

impl SweepSummary {
    /// `thresholds.json`: the summary with its phases' work and span.
    pub fn with_parallelism(&self) -> WithParallelism<'_, SweepSummary> {
        WithParallelism {
            summary: self,
            parallelism: &self.parallelism,
        }
    }
}

/// Run `vrw sweep`: the sweep, its thresholds, `sweep.csv`, `thresholds.json` and Fig. 2. `progress` is called
/// after every sweep point. `sweep.csv` is written before the thresholds are searched, so a later failure loses
/// nothing already computed.
pub fn run_sweep(
    job: &SweepJob,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<SweepSummary, AppError> {
    let (_, initial) = prepared(&job.config, job.initial)?;
    job.spec.validate(&job.config)?;
    in_run(&job.out_dir, job.overwrite, "sweep", |run| {
        sweep_into(job, initial, run, progress).map(|s| (s, None))
    })
}

/// The work of [`run_sweep`] in its run directory.
fn sweep_into(
    job: &SweepJob,
    initial: SectionState,
    run: &mut RunDir,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<SweepSummary, AppError> {
    let csv = run.path("sweep.csv");
    let friction = output::friction_columns(&job.config, &[&job.spec.param]);
    let result = compute_sweep(
        &job.config,
        &job.spec.param,
        &job.spec.values(),
        Some(initial),
        &job.options,
        progress,
        &mut |points| {
            output::write_sweep_csv(&csv, &job.spec.param, friction, points)?;
            run.add("sweep.csv");
            Ok(())
        },
    )?;
    let gaits_found = result.points.iter().filter(|p| p.gait.is_some()).count();
    let figures = ["fig2.svg", "fig2.png"];
    let mut files = vec!["sweep.csv".to_string(), "thresholds.json".to_string()];
    if gaits_found > 0 {
        files.extend(figures.map(String::from));
    }
    let mut summary = SweepSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: job.config.clone(),
        spec: job.spec.clone(),
        gaits_found,
        points: result.points.len(),
        thresholds: result.thresholds,
        seconds: result.seconds,
        second_route_seconds: 0.0,
        parallelism: result.parallelism,
        files,
        warnings: super::gait_warnings(
            result
                .points
                .iter()
                .map(|p| (format!("{} = {}", job.spec.param, short(p.value)), p)),
        ),
    };
    let thresholds_json = run.path("thresholds.json");
    output::write_json(&thresholds_json, &summary.with_parallelism())?;
    run.add("thresholds.json");
    if gaits_found > 0 {
        write_fig2(job, &result.points, &summary.thresholds)?;
        for f in figures {
            run.add(f);
        }
    }
    if job.second_route {
        // Everything of the first route is written: nothing is lost if this fails.
        second_route(job, initial, progress, &mut summary)?;
        output::write_json(&thresholds_json, &summary.with_parallelism())?;
    }
    Ok(summary)
}

/// Sweep again with the other integrator and record in each of `summary`'s thresholds whether the second
/// route confirms it, and the seconds it took.
fn second_route(
    job: &SweepJob,
    initial: SectionState,
    progress: &(dyn Fn(&SweepPoint) + Sync),
    summary: &mut SweepSummary,
) -> Result<(), AppError> {
    let clock = std::time::Instant::now();
    let (second_config, route) = second_route_config(&job.config);
    let second = compute_sweep(
        &second_config,
        &job.spec.param,
        &job.spec.values(),
        Some(initial),
        &job.options,
        progress,
        &mut |_| Ok(()),
    )
    .map_err(|e| match e {
        AppError::Interrupted { .. } => AppError::Interrupted {
            during: format!("during the second route ({route})"),
            kept: format!(
                "{} are complete; the thresholds are not confirmed by a second route",
                summary.files.join(", ")
            ),
        },
        other => other,
    })?;
    for t in &mut summary.thresholds {
        t.second_route = Some(SecondRoute::check(t, &second.thresholds, &route));
    }
    summary.second_route_seconds = clock.elapsed().as_secs_f64();
    Ok(())
}

/// A sweep and its thresholds, as [`compute_sweep`] returns them.
#[derive(Debug, Clone)]
pub struct SweepResult {
    /// One point per parameter value, in the order given.
    pub points: Vec<SweepPoint>,
    /// Every located threshold, in parameter order.
    pub thresholds: Vec<Threshold>,
    /// Wall-clock seconds spent on the sweep and on the thresholds.
    pub seconds: [f64; 2],
    /// The work and span of the gaits and of the thresholds' refinements ([`crate::study::parallelism`]).
    pub parallelism: Vec<PhaseWork>,
}

/// The computation of [`run_sweep`] without writing anything: sweep `param` over `values` with continuation
/// (starting at `initial`, `None`: [`default_initial`](crate::reference::default_initial)), then locate the
/// thresholds between the points. `progress` is called after every point; `swept` receives the points before
/// the thresholds are searched (where `vrw sweep` writes `sweep.csv`). When the library's interrupt flag
/// stops the sweep, `swept` receives the complete points and the result is [`AppError::Interrupted`].
pub fn compute_sweep(
    config: &Config,
    param: &str,
    values: &[f64],
    initial: Option<SectionState>,
    options: &GaitOptions,
    progress: &(dyn Fn(&SweepPoint) + Sync),
    swept: &mut dyn FnMut(&[SweepPoint]) -> Result<(), AppError>,
) -> Result<SweepResult, AppError> {
    let (_, initial) = prepared(config, initial)?;
    let clock = std::time::Instant::now();
    let (points, gaits) = swept_row(config, param, values, (&initial, options), progress)?;
    let sweep_seconds = clock.elapsed().as_secs_f64();
    swept(&points)?;
    check_interrupted(points.len(), values.len(), "sweep.csv")?;
    let clock = std::time::Instant::now();
    let (mut thresholds, refinements) =
        find_thresholds_costed(Parameter::named(config, param)?, &points, options);
    // Thresholds searched while the flag was set are not results (their walks were cut short).
    check_phase_interrupted(
        None,
        "while locating the thresholds",
        "sweep.csv holds every point; no threshold is kept",
    )?;
    let threshold_seconds = clock.elapsed().as_secs_f64();
    thresholds.sort_by(|a, b| a.value.total_cmp(&b.value));
    let mut refined = TaskGraph::new();
    for cost in refinements {
        refined.task(cost, &[]);
    }
    Ok(SweepResult {
        points,
        thresholds,
        seconds: [sweep_seconds, threshold_seconds],
        parallelism: vec![
            PhaseWork::of("gaits", &gaits),
            PhaseWork::of("thresholds", &refined),
        ],
    })
}

/// The sweep of `param` over `values` from `initial` with `options` (as [`crate::study::sweep_values`]), with
/// its task graph.
pub(crate) fn swept_row(
    config: &Config,
    param: &str,
    values: &[f64],
    (initial, options): (&SectionState, &GaitOptions),
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<(Vec<SweepPoint>, TaskGraph), ConfigError> {
    let row = checked_row(config, param, values, options)?;
    let (mut rows, graph) = gait_rows_measured(&[row], 0..1, initial, options, progress);
    Ok((rows.pop().unwrap_or_default(), graph))
}

/// Write Fig. 2 (`fig2.svg`, `fig2.png`) of the sweep's `points` and `thresholds` into the job's directory.
fn write_fig2(
    job: &SweepJob,
    points: &[SweepPoint],
    thresholds: &[Threshold],
) -> Result<(), AppError> {
    let indicator_points = indicator_points(points);
    let marks: Vec<ThresholdMark> = thresholds
        .iter()
        .filter(|t| t.value.is_finite())
        .map(|t| ThresholdMark {
            label: format!(
                "{}: {} = {:.2}",
                threshold_symbol(t),
                short_name(&job.spec.param),
                t.value
            ),
            value: t.value,
        })
        .collect();
    let no_gait = no_gait_spans(points, thresholds);
    let title = fig2_title(job);
    let label = axis_label(&job.spec.param);
    let (lo, hi) = (
        job.spec.from.min(job.spec.to),
        job.spec.from.max(job.spec.to),
    );
    let spec = Fig2Spec {
        points: &indicator_points,
        thresholds: &marks,
        param_label: &label,
        title: &title,
        x_range: Some(lo..hi),
        no_gait: &no_gait,
    };
    write_fig2_files(
        &spec,
        &job.out_dir.join("fig2.svg"),
        &job.out_dir.join("fig2.png"),
    )
    .map_err(|e| AppError::InvalidOption {
        option: "figure",
        reason: e.to_string(),
    })
}

/// The sweep points as Fig. 2 draws them.
fn indicator_points(points: &[SweepPoint]) -> Vec<IndicatorPoint> {
    // Points without a gait are NaN, so the curves break there instead of bridging the gap; a change of
    // family breaks them too.
    points
        .iter()
        .map(|p| match &p.gait {
            Some(g) => IndicatorPoint {
                param: p.value,
                lambda_i4: g.lambda_i4,
                lambda_2_plus: g.lambda_2_plus,
                lambda_4_plus: g.lambda_4_plus,
                scuffing: g.scuffing,
                family: p.family,
                period: g.period,
                period_k: g.period_k,
                max_floquet: g.max_floquet,
            },
            None => IndicatorPoint {
                param: p.value,
                lambda_i4: f64::NAN,
                lambda_2_plus: f64::NAN,
                lambda_4_plus: f64::NAN,
                scuffing: false,
                family: None,
                period: f64::NAN,
                period_k: 1,
                max_floquet: f64::NAN,
            },
        })
        .collect()
}

/// The words of a threshold on Fig. 2 (`λ₄⁺ = 0`, `gait lost`, ...).
fn threshold_symbol(t: &Threshold) -> &'static str {
    match t.name.as_str() {
        "lambda_4_plus = 0" => "λ₄⁺ = 0",
        "lambda_2_plus = 0" => "λ₂⁺ = 0",
        "lambda_I4 = 0" => "λI4 = 0",
        "stability_lost" => "unstable above",
        "stability_regained" => "stable above",
        "period_doubling" => "period doubling",
        "gait_lost" => "gait lost",
        "gait_found"
            if t.detail
                .as_deref()
                .is_some_and(|d| d.contains("found again")) =>
        {
            "gait found again"
        }
        "gait_found" => "gait found",
        "branch_switch" => "branch switch",
        "fold" => "fold",
        _ => "unconfirmed end",
    }
}

/// Fig. 2's title: the swept parameter, the fixed ones and the settings that differ from the defaults.
fn fig2_title(job: &SweepJob) -> String {
    format!(
        "Gaits along {}: {}{} (hollow: scuffing of Leg 2; grey: no gait)",
        short_name(&job.spec.param),
        fixed_parameters(&job.config, &job.spec.param),
        super::settings_note(
            &job.config,
            &[
                &job.spec.param,
                "viscosity",
                "stiffness",
                "slope",
                "impact",
                "rigid_legs"
            ]
        )
    )
}

/// The parameter intervals without a gait: each maximal run of sweep points without one, from the end of the
/// family on its left (the located threshold in that grid interval, else the midpoint) to the start of the
/// family on its right (likewise), or to the end of the sweep.
fn no_gait_spans(points: &[SweepPoint], thresholds: &[Threshold]) -> Vec<std::ops::Range<f64>> {
    let edge = |a: &SweepPoint, b: &SweepPoint| {
        let (lo, hi) = (a.value.min(b.value), a.value.max(b.value));
        thresholds
            .iter()
            .map(|t| t.value)
            .find(|v| v.is_finite() && lo <= *v && *v <= hi)
            .unwrap_or(0.5 * (a.value + b.value))
    };
    let mut spans = Vec::new();
    let mut i = 0;
    while i < points.len() {
        if points[i].gait.is_some() {
            i += 1;
            continue;
        }
        let start = i;
        while i < points.len() && points[i].gait.is_none() {
            i += 1;
        }
        let a = if start == 0 {
            points[0].value
        } else {
            edge(&points[start - 1], &points[start])
        };
        let b = if i == points.len() {
            points[i - 1].value
        } else {
            edge(&points[i - 1], &points[i])
        };
        spans.push(a.min(b)..a.max(b));
    }
    spans
}

/// The main parameters other than the swept one, for titles: `c = 50 N s/m, k = 500 N/m, φ = 0.1 rad, ...`.
fn fixed_parameters(config: &Config, swept: &str) -> String {
    let p = &config.params;
    let mut parts: Vec<String> = [
        ("viscosity", p.viscosity),
        ("stiffness", p.stiffness),
        ("slope", p.slope),
    ]
    .iter()
    .filter(|(key, _)| *key != swept)
    .map(|(key, v)| {
        let unit = axis_label(key);
        let unit = unit
            .split_once('[')
            .map_or("", |(_, u)| u.trim_end_matches(']'));
        format!("{} = {} {unit}", short_name(key), short(*v))
    })
    .collect();
    parts.push(format!("impact {}", p.impact));
    if p.rigid_legs {
        parts.push("rigid legs".to_string());
    }
    parts.join(", ")
}
