//! The job of `vrw map`: the gait over a grid of two parameters, the threshold curves across it, `map.csv`,
//! `curves.json` and the heat maps.

use std::ops::Range;
use std::path::PathBuf;

use serde::Serialize;

use crate::dynamics::Model;
use crate::fmt::short;
use crate::gait::GaitOptions;
use crate::output::map_plot::{write_map_figure, MapFigure, MapMark};
use crate::output::signature_plot::write_signature_figure;
use crate::output::{self, write_map_csv};
use crate::params::Config;
use crate::study::map::{map_curves_measured, map_gaits_measured};
use crate::study::map::{LineThreshold, ThresholdCurve};
use crate::study::map_curves::continue_map_curves_measured;
use crate::study::parallelism::{PhaseWork, TaskGraph, WithParallelism};
use crate::study::{map_curves, map_gaits, GaitMap, MapSpec, SecondRoute, SweepPoint};
use crate::walk::SectionState;

use super::{
    axis_label, check_interrupted, check_phase_interrupted, in_run, second_route_config,
    short_name, AppError,
};
use crate::output::manifest::RunDir;
use crate::reference::default_initial;

/// What `vrw map` runs.
#[derive(Debug, Clone)]
pub struct MapJob {
    /// Parameters and solver options (the two mapped keys are overridden point by point).
    pub config: Config,
    /// The two parameters and their ranges.
    pub spec: MapSpec,
    /// Where the search at the first point of every row starts (`None`: [`default_initial`]).
    pub initial: Option<SectionState>,
    /// Search settings.
    pub options: GaitOptions,
    /// Trace the threshold curves (`curves.json`, lines on the heat maps).
    pub curves: bool,
    /// The most columns the curves are refined on ([`crate::study::map::curve_columns`]; every row is).
    pub curve_columns: usize,
    /// Follow the indicator, fold and stability curves by continuation from the lines' crossings
    /// ([`mod@crate::study::map_curves`]); false: every curve through the refined crossings.
    pub continue_curves: bool,
    /// Search every threshold again by a second route (the whole map with the other integrator) and record in
    /// each whether it is confirmed ([`SecondRoute`]); only with `curves`.
    pub second_route: bool,
    /// Points to mark on the heat maps (e.g. the paper's thresholds).
    pub marks: Vec<MapMark>,
    /// Where `map.csv`, `curves.json`, `map.svg` and `map.png` go.
    pub out_dir: PathBuf,
    /// Replace a run of another command in `out_dir` (its files are removed and listed in the manifest);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    pub overwrite: bool,
}

/// `curves.json`: the map's parameters, its curves and the 1-D thresholds they pass through.
#[derive(Debug, Clone, Serialize)]
pub struct MapSummary {
    /// Version of vrw that produced the file.
    pub vrw_version: &'static str,
    /// Parameters and solver options (the mapped keys at their configured values).
    pub config: Config,
    /// The two axes.
    pub spec: MapSpec,
    /// Points with a gait / all points.
    pub gaits_found: usize,
    /// Number of map points.
    pub points: usize,
    /// The threshold curves (empty when they were not traced).
    pub curves: Vec<ThresholdCurve>,
    /// Every 1-D threshold of the rows (`along = "x"`) and columns (`along = "y"`).
    pub thresholds: Vec<LineThreshold>,
    /// Wall-clock seconds spent on the gaits and on the curves (printed, not written: files are
    /// reproducible).
    #[serde(skip)]
    pub seconds: [f64; 2],
    /// Of the curves' seconds, those spent on the continued curves and their checks (printed, not written).
    #[serde(skip)]
    pub continuation_seconds: f64,
    /// Wall-clock seconds spent on the second route (0 without it; printed, not written).
    #[serde(skip)]
    pub second_route_seconds: f64,
    /// The work and span of the gaits, the crossings of the rows and columns and the continued curves
    /// ([`crate::study::parallelism`]); written to `curves.json` (beside these fields) by [`run_map`], in
    /// steps walked.
    #[serde(skip)]
    pub parallelism: Vec<PhaseWork>,
    /// Where the interrupt flag stopped the job and what is kept ([`compute_map`]: the gaits without curves);
    /// `None` (and not written) when it did not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interrupted: Option<String>,
    /// Every audit value above its tolerance in the steps of the gaits found (empty when every law holds).
    pub warnings: Vec<String>,
}

/// Run `vrw map`: the gaits (written to `map.csv` at once), the curves (`curves.json`) and the heat maps
/// (`map.svg`, `map.png`). `progress` is called after every map point.
pub fn run_map(
    job: &MapJob,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<MapSummary, AppError> {
    let initial = checked_initial(job)?;
    in_run(&job.out_dir, job.overwrite, "map", |run| {
        map_into(job, &initial, run, progress).map(|s| (s, None))
    })
}

/// The work of [`run_map`] without writing anything: the summary (`curves.json`'s fields) and the map's
/// gaits (`map.csv`'s rows). The Python front's `vrw.map`.
///
/// Interrupted while the curves are traced (the gaits being complete), it returns the gaits with no curve and
/// says so in [`MapSummary::interrupted`] (the Python front hands them on with its `KeyboardInterrupt`);
/// interrupted among the gaits, it is [`AppError::Interrupted`].
pub fn compute_map(
    job: &MapJob,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<(MapSummary, GaitMap), AppError> {
    let initial = checked_initial(job)?;
    let (mut summary, map) = summarized_rows(job, &initial, 0..job.spec.y.points, progress)?;
    if let Err(AppError::Interrupted { during, kept }) =
        check_curves_interrupted("the map's gaits are complete")
    {
        // The summary of the gaits alone (no curve, none of the curves' warnings).
        let gaits_only = MapJob {
            curves: false,
            ..job.clone()
        };
        let mut gaits = map_summary(&gaits_only, &map, (summary.seconds[0], &TaskGraph::new()))?;
        // The gaits' work and span, as measured.
        gaits.parallelism = summary.parallelism[..1].to_vec();
        gaits.interrupted = Some(format!("{during}; {kept}"));
        return Ok((gaits, map));
    }
    second_route(job, &initial, progress, &mut summary)?;
    Ok((summary, map))
}

/// The rows `part` (indices of `y` values) of [`compute_map`]'s gaits, each exactly as the whole map has them,
/// with the summary of those rows (a map computed in parts, a study spread over processes). A part has no
/// curves (they need every row): `job.curves` is refused.
pub fn compute_map_part(
    job: &MapJob,
    part: Range<usize>,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<(MapSummary, GaitMap), AppError> {
    if job.curves {
        return Err(AppError::InvalidOption {
            option: "rows",
            reason:
                "a part of the map's rows has no curves (they need every row): compute the part \
                     without curves"
                    .to_string(),
        });
    }
    let initial = checked_initial(job)?;
    summarized_rows(job, &initial, part, progress)
}

/// The gaits of the rows `part` from `initial` (an error if interrupted) and their summary, with the curves
/// when `job.curves`.
fn summarized_rows(
    job: &MapJob,
    initial: &SectionState,
    part: Range<usize>,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<(MapSummary, GaitMap), AppError> {
    let clock = std::time::Instant::now();
    let (map, gaits) = map_gaits_measured(
        &job.config,
        &job.spec,
        part,
        initial,
        &job.options,
        progress,
    )?;
    let points = map.xs.len() * map.ys.len();
    check_interrupted(map.rows.iter().map(Vec::len).sum(), points, "the map")?;
    let summary = map_summary(job, &map, (clock.elapsed().as_secs_f64(), &gaits))?;
    Ok((summary, map))
}

/// The job checked before anything is computed, and the state every row's first search starts from.
fn checked_initial(job: &MapJob) -> Result<SectionState, AppError> {
    job.config.validate()?;
    job.spec.validate(&job.config)?;
    let model = Model::new(&job.config.params)?;
    let initial = job.initial.unwrap_or_else(|| default_initial(&job.config));
    initial.validate(&model)?;
    for m in &job.marks {
        if !(m.x.is_finite() && m.y.is_finite()) {
            return Err(AppError::InvalidOption {
                option: "mark",
                reason: format!("{} is not a point of two finite numbers", m.label),
            });
        }
    }
    Ok(initial)
}

/// The work of [`run_map`] in its run directory.
fn map_into(
    job: &MapJob,
    initial: &SectionState,
    run: &mut RunDir,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<MapSummary, AppError> {
    let clock = std::time::Instant::now();
    let all_rows = 0..job.spec.y.points;
    let (map, gaits) = map_gaits_measured(
        &job.config,
        &job.spec,
        all_rows,
        initial,
        &job.options,
        progress,
    )?;
    let gait_seconds = clock.elapsed().as_secs_f64();
    let friction = output::friction_columns(&job.config, &[&job.spec.x.param, &job.spec.y.param]);
    write_map_csv(&run.path("map.csv"), &map, friction)?;
    run.add("map.csv");
    let points = map.xs.len() * map.ys.len();
    check_interrupted(map.rows.iter().map(Vec::len).sum(), points, "map.csv")?;
    let mut summary = map_summary(job, &map, (gait_seconds, &gaits))?;
    check_curves_interrupted("map.csv holds every point of the map")?;
    let curves_json = run.path("curves.json");
    output::write_json(&curves_json, &summary.with_parallelism())?;
    run.add("curves.json");
    write_figure(job, &map, &summary.curves, friction)?;
    run.add("map.svg");
    run.add("map.png");
    if friction {
        run.add("signatures.svg");
        run.add("signatures.png");
    }
    if job.second_route && job.curves {
        // Everything of the first route is written: nothing is lost if this fails.
        second_route(job, initial, progress, &mut summary)?;
        output::write_json(&curves_json, &summary.with_parallelism())?;
    }
    Ok(summary)
}

/// The error of a map whose curves (or the summary's searches) the interrupt flag cut short: none of them is
/// kept, the gaits are (`kept`).
fn check_curves_interrupted(kept: &str) -> Result<(), AppError> {
    check_phase_interrupted(
        None,
        "while tracing the threshold curves",
        &format!("{kept}; no curve is kept"),
    )
}

impl MapSummary {
    /// `curves.json`: the summary with its phases' work and span.
    pub fn with_parallelism(&self) -> WithParallelism<'_, MapSummary> {
        WithParallelism {
            summary: self,
            parallelism: &self.parallelism,
        }
    }
}

/// The curves of `map` (with `job.curves`) and the summary of the map and its curves; `gaits` the seconds
/// and the task graph of the map's gaits.
fn map_summary(
    job: &MapJob,
    map: &GaitMap,
    gaits: (f64, &TaskGraph),
) -> Result<MapSummary, AppError> {
    let (gait_seconds, gait_graph) = gaits;
    let clock = std::time::Instant::now();
    let mut curve_warnings = Vec::new();
    let mut continuation_seconds = 0.0;
    let mut parallelism = vec![PhaseWork::of("gaits", gait_graph)];
    let (curves, thresholds) = if job.curves {
        let (mut c, crossings) =
            map_curves_measured(&job.config, map, &job.options, job.curve_columns)?;
        parallelism.push(PhaseWork::of("crossings", &crossings));
        if job.continue_curves {
            let clock = std::time::Instant::now();
            let (warnings, continued) = continue_map_curves_measured(&job.config, map, &mut c);
            curve_warnings = warnings;
            continuation_seconds = clock.elapsed().as_secs_f64();
            parallelism.push(PhaseWork::of("continued_curves", &continued));
        }
        (c.curves, c.thresholds)
    } else {
        (Vec::new(), Vec::new())
    };
    let curve_seconds = clock.elapsed().as_secs_f64();
    let mut summary = MapSummary {
        vrw_version: env!("CARGO_PKG_VERSION"),
        config: job.config.clone(),
        spec: job.spec.clone(),
        gaits_found: map
            .rows
            .iter()
            .flatten()
            .filter(|p| p.gait.is_some())
            .count(),
        points: map.xs.len() * map.ys.len(),
        curves,
        thresholds,
        seconds: [gait_seconds, curve_seconds],
        continuation_seconds,
        second_route_seconds: 0.0,
        parallelism,
        interrupted: None,
        warnings: super::gait_warnings(map.ys.iter().zip(&map.rows).flat_map(|(y, row)| {
            row.iter().map(move |p| {
                let at = format!(
                    "{} = {}, {} = {}",
                    job.spec.x.param,
                    short(p.value),
                    job.spec.y.param,
                    short(*y)
                );
                (at, p)
            })
        })),
    };
    summary.warnings.extend(curve_warnings);
    Ok(summary)
}

/// With `job.second_route` (and curves): the whole map again with the other integrator, each threshold of
/// `summary` checked against the second route's on the same line.
fn second_route(
    job: &MapJob,
    initial: &SectionState,
    progress: &(dyn Fn(&SweepPoint) + Sync),
    summary: &mut MapSummary,
) -> Result<(), AppError> {
    if !(job.second_route && job.curves) {
        return Ok(());
    }
    let clock = std::time::Instant::now();
    let (second_config, route) = second_route_config(&job.config);
    let second_map = map_gaits(&second_config, &job.spec, initial, &job.options, progress)?;
    let kept =
        "map.csv, curves.json and the heat maps of the first route are complete; no threshold is \
                confirmed by a second route";
    check_phase_interrupted(None, &format!("during the second route ({route})"), kept)?;
    let second = map_curves(&second_config, &second_map, &job.options, job.curve_columns)?;
    check_phase_interrupted(None, &format!("during the second route ({route})"), kept)?;
    for t in &mut summary.thresholds {
        let same_line = second
            .thresholds
            .iter()
            .filter(|o| o.along == t.along && o.line == t.line)
            .map(|o| &o.threshold);
        t.threshold.second_route = Some(SecondRoute::check(&t.threshold, same_line, &route));
    }
    summary.second_route_seconds = clock.elapsed().as_secs_f64();
    Ok(())
}

/// The map figure, and with Coulomb friction (`friction`) the stick/slip figure.
fn write_figure(
    job: &MapJob,
    map: &GaitMap,
    curves: &[ThresholdCurve],
    friction: bool,
) -> Result<(), AppError> {
    let p = &job.config.params;
    let preload = p.stiffness * (p.spring_natural_length - p.stopper_length);
    let fixed = |key: &str| key == job.spec.x.param || key == job.spec.y.param;
    let mut context = vec![format!("slope φ = {} rad", p.slope)];
    if !fixed("stiffness") && !fixed("spring_natural_length") && !fixed("stopper_length") {
        context.push(format!("preload {} N", crate::fmt::short(preload)));
    } else if !fixed("spring_natural_length") && !fixed("stopper_length") {
        context.push(format!(
            "L* − L0 = {} m",
            crate::fmt::short(p.spring_natural_length - p.stopper_length)
        ));
    }
    context.push(format!("impact {}", p.impact));
    let title = format!(
        "Gaits over ({}, {}), {}{}",
        short_name(&job.spec.x.param),
        short_name(&job.spec.y.param),
        context.join(", "),
        super::settings_note(
            &job.config,
            &[
                &job.spec.x.param,
                &job.spec.y.param,
                "slope",
                "impact",
                "stiffness",
                "spring_natural_length",
                "stopper_length",
            ]
        )
    );
    let figure = MapFigure {
        map,
        curves,
        marks: &job.marks,
        x_label: axis_label(&job.spec.x.param),
        y_label: axis_label(&job.spec.y.param),
        title,
    };
    write_map_figure(
        &figure,
        &job.out_dir.join("map.svg"),
        &job.out_dir.join("map.png"),
    )?;
    if friction {
        write_signature_figure(
            &figure,
            &job.out_dir.join("signatures.svg"),
            &job.out_dir.join("signatures.png"),
        )?;
    }
    Ok(())
}
