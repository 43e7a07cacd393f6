//! The curves of a map followed by continuation (docs/model.md section 11, "Curves of a map"; `vrw map`): each
//! indicator curve `lambda = 0`, fold and loss of stability is traced across the map from a crossing that a row
//! (or column) found, as the solutions of `P(x; x_param, y_param) = x` together with its condition
//! ([`crate::continuation::curve`]), instead of joining the crossings of neighbouring grid lines. Every other crossing of the
//! same threshold within one grid cell of the curve is solved for on the curve at its line and compared with
//! the line's refined threshold: the lines are the curve's second route, and the crossings on it are covered
//! by it. Crossings that no continued curve covers (a period-k gait, a continuation that failed, another
//! border nearby) keep their curves through the crossings ([`crate::study::CurveMethod::Crossings`]).

use rayon::prelude::*;

use super::map::NearMiss;
use super::map::{Along, LineThreshold, RefinedOn};
use super::{
    ContinuedCurve, CurveMethod, GaitMap, MapCurves, SweepSpec, ThresholdCurve, LINE_CHECK_TOL,
};
use crate::continuation::curve::{
    border_curve_seed, continue_curve, curve_at, Curve, CurveEnd, CurveOptions, CurveProblem,
    CurveTest, BORDER_OFFSET, FOLLOW_OFFSET_FACTOR,
};
use crate::continuation::special::{test_function, test_name};
use crate::continuation::{
    continue_family, ContinuationOptions, Evaluation, MapFailure, SpecialKind,
};
use crate::family::{GaitFamily, GaitInfo};
use crate::params::Config;

/// What a continued curve of a map solves for with the fixed point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Condition {
    /// A border function (a DLS indicator) at a small offset on the gaits' side.
    Border(&'static str),
    /// The test function of the special point of these kinds located nearest the crossing on the row's family
    /// (`det(DP - I)` for a fold, `det(DP + I)` for a period doubling, the bialternate product for a
    /// Neimark-Sacker point).
    Special(&'static [SpecialKind]),
}

/// The map's curves that are followed by continuation: the threshold's name and what is solved for.
pub const CONTINUED_CURVES: [(&str, Condition); 5] = [
    ("lambda_4_plus = 0", Condition::Border("lambda_4_plus")),
    ("lambda_2_plus = 0", Condition::Border("lambda_2_plus")),
    ("lambda_I4 = 0", Condition::Border("lambda_I4")),
    ("fold", Condition::Special(&[SpecialKind::Fold])),
    (
        "stability_lost",
        Condition::Special(&[
            SpecialKind::PeriodDoubling,
            SpecialKind::NeimarkSacker,
            SpecialKind::Fold,
        ]),
    ),
];

/// The thresholds that are ends of a row's family (a crossing at the same value is at the family's end).
const FAMILY_END_NAMES: [&str; 5] = [
    "gait_lost",
    "gait_found",
    "branch_switch",
    "fold",
    "unconfirmed",
];

/// Crossings of one curve from which continuation failed before its remaining crossings are left to the
/// curves through the crossings (each failure costs a continuation's start).
const MAX_FAILED_SEEDS: usize = 4;

/// Replace the curves of `curves` that can be followed ([`CONTINUED_CURVES`]) by curves continued from the
/// lines' crossings (see the module documentation). Returns the warnings: a continuation that failed
/// from a crossing inside a family.
pub fn continue_map_curves(config: &Config, map: &GaitMap, curves: &mut MapCurves) -> Vec<String> {
    let mut warnings = Vec::new();
    for (name, condition) in CONTINUED_CURVES {
        // A crossing where the row's family ends (the indicator vanishes with the family, at the same value as
        // the end's threshold): the curve may run along the end of existence, where a curve of
        // `lambda = offset` can often be followed but not always; where it cannot, the crossing silently stays
        // with the curves through the crossings.
        let at_family_end = |t: &LineThreshold| {
            curves.thresholds.iter().any(|o| {
                o.along == t.along
                    && o.line == t.line
                    && o.threshold.value == t.threshold.value
                    && FAMILY_END_NAMES.contains(&o.threshold.name.as_str())
            })
        };
        // The crossings of rows and columns (rows' first: the curves start from them where they can).
        let seeds: Vec<&LineThreshold> = curves
            .thresholds
            .iter()
            .filter(|t| t.threshold.name == name && t.threshold.value.is_finite())
            .collect();
        let mut covered = vec![false; seeds.len()];
        // Crossings within a grid cell of a continued curve but not on it: a different border nearby (e.g. a
        // period-2 family's where the curve is a period-1 family's). Continuing from one would most likely
        // follow the same curve again.
        let mut near = vec![false; seeds.len()];
        // Failures at family ends and elsewhere.
        let mut failures = [0, 0];
        let mut continued = Vec::new();
        for k in 0..seeds.len() {
            let end = usize::from(!at_family_end(seeds[k]));
            if covered[k] || near[k] || failures[end] >= MAX_FAILED_SEEDS {
                continue;
            }
            match follow_from_crossing(config, map, &seeds, k, condition) {
                Ok((curve, hits, misses)) => {
                    for h in hits {
                        covered[h] = true;
                    }
                    for m in misses {
                        near[m] = true;
                    }
                    continued.push(curve);
                }
                Err(_) if end == 0 => failures[0] += 1,
                Err(message) => {
                    failures[1] += 1;
                    let (line, param) = match seeds[k].along {
                        Along::X => ("row", &map.spec.x.param),
                        Along::Y => ("column", &map.spec.y.param),
                    };
                    warnings.push(format!(
                        "{name}: no curve continued from the crossing of {line} {} at {param} = {}: \
                         {message}; its curve is drawn through the crossings",
                        seeds[k].line, seeds[k].threshold.value
                    ));
                }
            }
        }
        // The crossings a continued curve covers leave the curves through the crossings, which split into the
        // runs of the crossings left.
        let covered_points: Vec<[f64; 2]> = seeds
            .iter()
            .zip(&covered)
            .filter(|(_, &c)| c)
            .map(|(t, _)| crossing_point(map, t))
            .collect();
        let (own, others): (Vec<ThresholdCurve>, Vec<ThresholdCurve>) =
            std::mem::take(&mut curves.curves)
                .into_iter()
                .partition(|c| c.name == name);
        curves.curves = others;
        for c in own {
            curves.curves.extend(uncovered_runs(c, &covered_points));
        }
        curves.curves.extend(continued);
    }
    warnings
}

/// The curve through the crossing `seeds[k]` (a row's or a column's), the indices of the crossings in `seeds` it covers, and
/// those of the crossings within a grid cell of it that it does not cover.
fn follow_from_crossing(
    config: &Config,
    map: &GaitMap,
    seeds: &[&LineThreshold],
    k: usize,
    condition: Condition,
) -> Result<(ThresholdCurve, Vec<usize>, Vec<usize>), String> {
    let seed = seeds[k];
    let spec = &map.spec;
    let (j, t) = (seed.line, &seed.threshold);
    // The line's parameter (x on a row, y on a column), the other one and its value on the line.
    let (line_spec, other_spec, values, fixed) = match seed.along {
        Along::X => (&spec.x, &spec.y, &map.xs, map.ys[j]),
        Along::Y => (&spec.y, &spec.x, &map.ys, map.xs[j]),
    };
    // The grid point of the crossing's bracket nearest it that has a period-1 gait: its fixed point starts
    // the line's family.
    let lo = t.grid_bracket[0].min(t.grid_bracket[1]);
    let i = values
        .iter()
        .position(|&v| v == lo)
        .ok_or("the crossing's bracket is not a grid cell")?;
    let (gait, v0) = [i, i + 1]
        .into_iter()
        .filter_map(|i| {
            let p = match seed.along {
                Along::X => map.rows[j].get(i)?,
                Along::Y => map.rows.get(i)?.get(j)?,
            };
            let g = p.gait.as_ref().filter(|g| g.period_k == 1)?;
            Some((g, values[i]))
        })
        .min_by(|a, b| (a.1 - t.value).abs().total_cmp(&(b.1 - t.value).abs()))
        .ok_or("no period-1 gait next to the crossing")?;
    let mut line_config = config.clone();
    line_config
        .set_numeric(&other_spec.param, fixed)
        .map_err(|e| e.to_string())?;
    let line_family =
        GaitFamily::new(&line_config, &line_spec.param, gait.section).map_err(|e| e.message)?;
    // The line's family followed across the crossing's cell and one more on either side (pseudo-arclength,
    // its special points located), and the curve started from it: for a border, from its point nearest the
    // collision that lies clearly on one side (near the end of a family's domain, lambda_2+ often reaches zero
    // just before the wheel rolls back, a Newton step from the grid gait straight to the border could leave
    // the domain); for a fold, period doubling or Neimark-Sacker point, from the located point.
    let cell = |s: &SweepSpec, n: usize| (s.to - s.from).abs() / (n.max(2) - 1) as f64;
    let x_cell = cell(&spec.x, map.xs.len());
    let y_cell = cell(&spec.y, map.ys.len());
    let line_cell = cell(line_spec, values.len());
    let (v_min, v_max) = (
        line_spec.from.min(line_spec.to),
        line_spec.from.max(line_spec.to),
    );
    let hi = t.grid_bracket[0].max(t.grid_bracket[1]);
    let row_options =
        ContinuationOptions::for_range((lo - line_cell).max(v_min), (hi + line_cell).min(v_max));
    let row_family = continue_family(
        &line_family,
        &line_family.reduce(&gait.section),
        v0,
        &row_options,
    )
    .map_err(|e| format!("the line's family: {e}"))?;
    // The curve's map: the family in x, whose evaluations set y.
    let family =
        GaitFamily::new(&line_config, &spec.x.param, gait.section).map_err(|e| e.message)?;
    let y_param = spec.y.param.as_str();
    let eval = |x: &nalgebra::DVector<f64>, p: f64, q: f64| family.eval_with(y_param, x, p, q);
    let observe =
        |x: &nalgebra::DVector<f64>, p: f64, q: f64| family.observe_with(y_param, x, p, q);
    let nearest = |a: f64, b: f64| (a - t.value).abs().total_cmp(&(b - t.value).abs());
    let (start, v_start, offset, condition, name): (_, _, _, CurveTest, String) = match condition {
        Condition::Border(border) => {
            let collision = row_family
                .special
                .iter()
                .filter(|s| {
                    s.kind == SpecialKind::BorderCollision
                        && s.located
                        && s.border.as_deref() == Some(border)
                })
                .min_by(|a, b| nearest(a.param, b.param))
                .map(|s| s.arclength)
                // Where the family ends with the indicator (no sign change on it), its point nearest the
                // crossing.
                .or_else(|| {
                    row_family
                        .points
                        .iter()
                        .min_by(|a, b| nearest(a.param, b.param))
                        .map(|p| p.arclength)
                })
                .ok_or("the row's family has no points")?;
            let (seed_point, side) =
                border_curve_seed(&line_family, &row_family, collision, border)
                    .ok_or("no point of the row's family lies clearly on one side of the border")?;
            (
                seed_point.x.clone(),
                seed_point.param,
                BORDER_OFFSET.copysign(side),
                CurveTest::Border(border),
                border.to_string(),
            )
        }
        Condition::Special(kinds) => {
            let sp = row_family
                .special
                .iter()
                .filter(|s| kinds.contains(&s.kind) && s.located)
                .min_by(|a, b| nearest(a.param, b.param))
                .ok_or_else(|| {
                    format!("the row's family has no located {kinds:?} point near the crossing")
                })?;
            let test = test_function(sp.kind).ok_or("not a special point with a test function")?;
            (
                sp.x.clone(),
                sp.param,
                0.0,
                CurveTest::Jacobian(test),
                test_name(sp.kind).to_string(),
            )
        }
    };
    let test = |ev: &Evaluation<GaitInfo>| condition.of(&family, ev);
    let problem = CurveProblem {
        eval: &eval,
        observe: (!condition.needs_derivatives()).then_some(&observe),
        test: &test,
        offset,
    };
    let options = CurveOptions::for_ranges((spec.x.from, spec.x.to), (spec.y.from, spec.y.to));
    let at = match seed.along {
        Along::X => (v_start, fixed),
        Along::Y => (fixed, v_start),
    };
    let curve =
        continue_curve(&problem, &start, at, &options).map_err(|e: MapFailure| e.message)?;
    // The crossings it may pass through: every one within one grid cell of the curve's polyline on its line.
    let candidates: Vec<usize> = (0..seeds.len())
        .filter(|&m| {
            let s = seeds[m];
            match s.along {
                Along::X => crossings_at(&curve, 1, map.ys[s.line])
                    .any(|x| (x - s.threshold.value).abs() <= x_cell),
                Along::Y => crossings_at(&curve, 0, map.xs[s.line])
                    .any(|y| (y - s.threshold.value).abs() <= y_cell),
            }
        })
        .collect();
    // Each solved for on the curve and compared with its line's threshold: those within LINE_CHECK_TOL are the
    // curve's, the others a different border nearby.
    let differences: Vec<f64> = candidates
        .par_iter()
        .map(|&m| {
            let s = seeds[m];
            let v = s.threshold.value;
            let on_curve = match s.along {
                Along::X => {
                    curve_at(&problem, &curve, (1, map.ys[s.line]), v, &options).map(|p| p.p1)
                }
                Along::Y => {
                    curve_at(&problem, &curve, (0, map.xs[s.line]), v, &options).map(|p| p.p2)
                }
            };
            on_curve.map_or(f64::NAN, |v| (v - s.threshold.value).abs())
        })
        .collect();
    type Checked = Vec<(usize, f64)>;
    let (hits, misses): (Checked, Checked) = candidates
        .into_iter()
        .zip(differences)
        .partition(|(_, d)| *d <= LINE_CHECK_TOL);
    let checked: Vec<f64> = hits.iter().map(|h| h.1).collect();
    let end_words = |e: &CurveEnd| match e {
        CurveEnd::LeftRange => "left_range".to_string(),
        CurveEnd::MaxPoints => "max_points".to_string(),
        CurveEnd::Ended { message } => format!("ended: {message}"),
    };
    let method = ContinuedCurve {
        seed: RefinedOn {
            along: seed.along,
            line: j,
            threshold: t.name.clone(),
        },
        condition: name.clone(),
        offset: problem.offset,
        ends: [end_words(&curve.ends[0]), end_words(&curve.ends[1])],
        max_residual: curve.points.iter().map(|p| p.residual).fold(0.0, f64::max),
        max_test_value: curve
            .points
            .iter()
            .map(|p| p.test_value.abs())
            .fold(0.0, f64::max),
        lines_checked: checked.len(),
        near_misses: misses
            .iter()
            .map(|&(m, difference)| NearMiss {
                along: seeds[m].along,
                line: seeds[m].line,
                value: seeds[m].threshold.value,
                difference,
            })
            .collect(),
        max_line_difference: checked.iter().copied().reduce(f64::max).unwrap_or(f64::NAN),
        description: format!(
            "pseudo-arclength continuation of P(x) = x and {name} = {:e} in ({}, {}), from the gait of {} \
             {j}'s family at {} = {}{}",
            problem.offset,
            spec.x.param,
            spec.y.param,
            if seed.along == Along::X { "row" } else { "column" },
            line_spec.param,
            v_start,
            if problem.offset == 0.0 {
                String::new()
            } else {
                format!(
                    "; steps aimed at {name} = {:e}, each point polished",
                    problem.offset * FOLLOW_OFFSET_FACTOR
                )
            }
        ),
    };
    let curve_out = ThresholdCurve {
        name: t.name.clone(),
        points: curve.points.iter().map(|p| [p.p1, p.p2]).collect(),
        refined_on: Vec::new(),
        closed: false,
        method: CurveMethod::Continuation(method),
    };
    Ok((
        curve_out,
        hits.into_iter().map(|h| h.0).collect(),
        misses.into_iter().map(|m| m.0).collect(),
    ))
}

/// Where the curve's polyline crosses the line where parameter `which` (0: `x`, 1: `y`) equals `value`: the
/// other parameter there (each segment that does).
fn crossings_at(
    curve: &Curve<GaitInfo>,
    which: usize,
    value: f64,
) -> impl Iterator<Item = f64> + '_ {
    let split = move |p: &crate::continuation::CurvePoint<GaitInfo>| {
        if which == 0 {
            (p.p1, p.p2)
        } else {
            (p.p2, p.p1)
        }
    };
    curve.points.windows(2).filter_map(move |w| {
        let ((a, a_other), (b, b_other)) = (split(&w[0]), split(&w[1]));
        ((a - value) * (b - value) <= 0.0 && a != b)
            .then(|| a_other + (value - a) / (b - a) * (b_other - a_other))
    })
}

/// The runs of a curve through crossings between its covered points (the whole curve if none is covered).
fn uncovered_runs(curve: ThresholdCurve, covered: &[[f64; 2]]) -> Vec<ThresholdCurve> {
    if !curve.points.iter().any(|p| covered.contains(p)) {
        return vec![curve];
    }
    let mut runs = Vec::new();
    let mut run = ThresholdCurve {
        points: Vec::new(),
        refined_on: Vec::new(),
        closed: false,
        ..curve.clone()
    };
    for (p, on) in curve.points.iter().zip(&curve.refined_on) {
        if covered.contains(p) {
            if !run.points.is_empty() {
                runs.push(run.clone());
                run.points.clear();
                run.refined_on.clear();
            }
        } else {
            run.points.push(*p);
            run.refined_on.push(on.clone());
        }
    }
    if !run.points.is_empty() {
        runs.push(run);
    }
    runs
}

/// The point `[x, y]` of a line's crossing (as the curves through the crossings have it).
fn crossing_point(map: &GaitMap, t: &LineThreshold) -> [f64; 2] {
    match t.along {
        Along::X => [t.threshold.value, map.ys[t.line]],
        Along::Y => [map.xs[t.line], t.threshold.value],
    }
}
