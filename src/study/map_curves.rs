//! The curves of a map followed by continuation (docs/model.md section 11, "Curves of a map"; `vrw map`): each
//! indicator curve `lambda = 0`, fold and loss of stability is traced across the map from a crossing that a row
//! (or column) found, as the solutions of `P(x; x_param, y_param) = x` together with its condition
//! ([`crate::continuation::curve`]), instead of joining the crossings of neighbouring grid lines. Every other crossing of the
//! same threshold within one grid cell of the curve is solved for on the curve at its line and compared with
//! the line's refined threshold: the lines are the curve's second route, and the crossings on it are covered
//! by it. Crossings that no continued curve covers (a period-k gait, a continuation that failed, another
//! border nearby) keep their curves through the crossings ([`crate::study::CurveMethod::Crossings`]).

use rayon::prelude::*;

use super::parallelism::{measured, Cost, TaskGraph};
use crate::meter::carried;

use super::map::NearMiss;
use super::map::{Along, LineThreshold, RefinedOn};
use super::{
    ContinuedCurve, CurveMethod, GaitMap, MapCurves, SweepSpec, ThresholdCurve, LINE_CHECK_TOL,
};
use crate::continuation::curve::{
    curve_at, Curve, CurveEnd, CurveOptions, CurveProblem, FOLLOW_OFFSET_FACTOR,
};
use crate::continuation::{continue_family, ContinuationOptions, Family, SpecialKind};
use crate::family::curves::CurveSeed;
use crate::family::{GaitFamily, GaitInfo, Parameter};
use crate::gait::Gait;
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
    continue_map_curves_measured(config, map, curves).0
}

/// [`continue_map_curves`] with its task graph ([`super::parallelism`]): the curves of the five conditions are
/// followed at the same time (each reads only the lines' thresholds); within one, every continuation from a
/// crossing is a task after the one before (which crossings are left to start from depends on the curves
/// already followed).
pub fn continue_map_curves_measured(
    config: &Config,
    map: &GaitMap,
    curves: &mut MapCurves,
) -> (Vec<String>, TaskGraph) {
    let thresholds = &curves.thresholds;
    let followed: Vec<Followed> = CONTINUED_CURVES
        .par_iter()
        .with_max_len(1)
        .map(carried(|&(name, condition): &(&str, Condition)| {
            follow_condition(config, map, thresholds, name, condition)
        }))
        .collect();
    let mut warnings = Vec::new();
    let mut graph = TaskGraph::new();
    for ((name, _), f) in CONTINUED_CURVES.iter().zip(followed) {
        let mut last: Option<usize> = None;
        for &cost in &f.costs {
            last = Some(graph.task(cost, last.as_slice()));
        }
        warnings.extend(f.warnings);
        // The crossings a continued curve covers leave the curves through the crossings, which split into the
        // runs of the crossings left.
        let (own, others): (Vec<ThresholdCurve>, Vec<ThresholdCurve>) =
            std::mem::take(&mut curves.curves)
                .into_iter()
                .partition(|c| c.name == *name);
        curves.curves = others;
        for c in own {
            curves.curves.extend(uncovered_runs(c, &f.covered_points));
        }
        curves.curves.extend(f.continued);
    }
    (warnings, graph)
}

/// The curves of one condition continued from the lines' crossings, and what they cover.
struct Followed {
    /// The continued curves, in the order their seeds come.
    continued: Vec<ThresholdCurve>,
    /// The points of the crossings they cover.
    covered_points: Vec<[f64; 2]>,
    /// The continuations that failed from a crossing inside a family.
    warnings: Vec<String>,
    /// The cost of each continuation tried, in order.
    costs: Vec<Cost>,
}

/// The curves of the threshold `name` continued from the crossings of `thresholds` (rows' first), each from the
/// first crossing no curve followed before covers (see [`continue_map_curves`]).
fn follow_condition(
    config: &Config,
    map: &GaitMap,
    thresholds: &[LineThreshold],
    name: &str,
    condition: Condition,
) -> Followed {
    // A crossing where the row's family ends (the indicator vanishes with the family, at the same value as
    // the end's threshold): the curve may run along the end of existence, where a curve of
    // `lambda = offset` can often be followed but not always; where it cannot, the crossing silently stays
    // with the curves through the crossings.
    let at_family_end = |t: &LineThreshold| {
        thresholds.iter().any(|o| {
            o.along == t.along
                && o.line == t.line
                && o.threshold.value == t.threshold.value
                && FAMILY_END_NAMES.contains(&o.threshold.name.as_str())
        })
    };
    // The crossings of rows and columns (rows' first: the curves start from them where they can).
    let seeds: Vec<&LineThreshold> = thresholds
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
    let mut out = Followed {
        continued: Vec::new(),
        covered_points: Vec::new(),
        warnings: Vec::new(),
        costs: Vec::new(),
    };
    for k in 0..seeds.len() {
        let end = usize::from(!at_family_end(seeds[k]));
        if covered[k] || near[k] || failures[end] >= MAX_FAILED_SEEDS {
            continue;
        }
        let (result, cost) = measured(|| follow_from_crossing(config, map, &seeds, k, condition));
        out.costs.push(cost);
        match result {
            Ok((curve, hits, misses)) => {
                for h in hits {
                    covered[h] = true;
                }
                for m in misses {
                    near[m] = true;
                }
                out.continued.push(curve);
            }
            Err(_) if end == 0 => failures[0] += 1,
            Err(message) => {
                failures[1] += 1;
                let (line, param) = match seeds[k].along {
                    Along::X => ("row", &map.spec.x.param),
                    Along::Y => ("column", &map.spec.y.param),
                };
                out.warnings.push(format!(
                    "{name}: no curve continued from the crossing of {line} {} at {param} = {}: \
                     {message}; its curve is drawn through the crossings",
                    seeds[k].line, seeds[k].threshold.value
                ));
            }
        }
    }
    out.covered_points = seeds
        .iter()
        .zip(&covered)
        .filter(|(_, &c)| c)
        .map(|(t, _)| crossing_point(map, t))
        .collect();
    out
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
    let line = CrossingLine::of(map, seeds[k])?;
    let spec = &map.spec;
    let mut line_config = config.clone();
    line_config
        .set_numeric(&line.other.param, line.fixed)
        .map_err(|e| e.to_string())?;
    let parameter = |key: &str| Parameter::named(&line_config, key).map_err(|e| e.to_string());
    let line_family = GaitFamily::new(parameter(&line.spec.param)?, line.gait.section);
    let row_family = line.family(&line_family)?;
    let seed = curve_seed(condition, &line_family, &row_family, line.threshold.value)?;
    // The curve's map: the family in x, whose evaluations set y.
    let family = GaitFamily::new(parameter(&spec.x.param)?, line.gait.section);
    let options = CurveOptions::for_ranges((spec.x.from, spec.x.to), (spec.y.from, spec.y.to));
    let at = match line.along {
        Along::X => (seed.p, line.fixed),
        Along::Y => (line.fixed, seed.p),
    };
    let (curve, (hits, misses)) = seed.with_problem(family, &spec.y.param, |problem| {
        let curve = seed.follow(problem, at, &options).map_err(|e| e.message)?;
        let checked = check_crossings(problem, &curve, map, seeds, &options);
        Ok::<_, String>((curve, checked))
    })?;
    let method = ContinuedCurve {
        seed: RefinedOn {
            along: line.along,
            line: line.index,
            threshold: line.threshold.name.clone(),
        },
        condition: seed.condition.clone(),
        offset: seed.offset,
        ends: [end_words(&curve.ends[0]), end_words(&curve.ends[1])],
        max_residual: curve.points.iter().map(|p| p.residual).fold(0.0, f64::max),
        max_test_value: curve
            .points
            .iter()
            .map(|p| p.test_value.abs())
            .fold(0.0, f64::max),
        lines_checked: hits.len(),
        near_misses: misses
            .iter()
            .map(|&(m, difference)| NearMiss {
                along: seeds[m].along,
                line: seeds[m].line,
                value: seeds[m].threshold.value,
                difference,
            })
            .collect(),
        max_line_difference: hits
            .iter()
            .map(|h| h.1)
            .reduce(f64::max)
            .unwrap_or(f64::NAN),
        description: line.description(spec, &seed),
    };
    let curve_out = ThresholdCurve {
        name: line.threshold.name.clone(),
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

/// A crossing's line of the map and the gait its family starts from.
struct CrossingLine<'m> {
    /// Along `x` (a row) or `y` (a column).
    along: Along,
    /// The line's index.
    index: usize,
    /// The crossing.
    threshold: &'m crate::study::Threshold,
    /// The line's parameter (x on a row, y on a column).
    spec: &'m SweepSpec,
    /// The other parameter.
    other: &'m SweepSpec,
    /// The other parameter's value on the line.
    fixed: f64,
    /// The line's grid values.
    values: &'m [f64],
    /// The period-1 gait of the crossing's grid bracket nearest it.
    gait: &'m Gait,
    /// Its value of the line's parameter.
    v0: f64,
}

impl<'m> CrossingLine<'m> {
    /// The line of the crossing `seed` and the grid point of its bracket nearest it that has a period-1 gait.
    fn of(map: &'m GaitMap, seed: &'m LineThreshold) -> Result<CrossingLine<'m>, String> {
        let spec = &map.spec;
        let (j, t) = (seed.line, &seed.threshold);
        let (line_spec, other, values, fixed) = match seed.along {
            Along::X => (&spec.x, &spec.y, &map.xs, map.ys[j]),
            Along::Y => (&spec.y, &spec.x, &map.ys, map.xs[j]),
        };
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
        Ok(CrossingLine {
            along: seed.along,
            index: j,
            threshold: t,
            spec: line_spec,
            other,
            fixed,
            values,
            gait,
            v0,
        })
    }

    /// The line's family (of `line_family`) followed across the crossing's cell and one more on either side
    /// (pseudo-arclength, its special points located).
    fn family(&self, line_family: &GaitFamily) -> Result<Family<GaitInfo>, String> {
        let s = self.spec;
        let line_cell = (s.to - s.from).abs() / (self.values.len().max(2) - 1) as f64;
        let (v_min, v_max) = (s.from.min(s.to), s.from.max(s.to));
        let bracket = self.threshold.grid_bracket;
        let (lo, hi) = (bracket[0].min(bracket[1]), bracket[0].max(bracket[1]));
        let options = ContinuationOptions::for_range(
            (lo - line_cell).max(v_min),
            (hi + line_cell).min(v_max),
        );
        let x0 = line_family.reduce(&self.gait.section);
        continue_family(line_family, &x0, self.v0, &options)
            .map_err(|e| format!("the line's family: {e}"))
    }

    /// How the curve from `seed` on this line is computed, in words ([`ContinuedCurve::description`]).
    fn description(&self, spec: &super::MapSpec, seed: &CurveSeed) -> String {
        let (name, offset) = (&seed.condition, seed.offset);
        format!(
            "pseudo-arclength continuation of P(x) = x and {name} = {offset:e} in ({}, {}), from the gait of {} \
             {}'s family at {} = {}{}",
            spec.x.param,
            spec.y.param,
            if self.along == Along::X { "row" } else { "column" },
            self.index,
            self.spec.param,
            seed.p,
            if offset == 0.0 {
                String::new()
            } else {
                format!(
                    "; steps aimed at {name} = {:e}, each point polished",
                    offset * FOLLOW_OFFSET_FACTOR
                )
            }
        )
    }
}

/// Where the curve of `condition` starts on the line's family `row_family` (of `line_family`), nearest the
/// crossing at `value`: for a border, from the family's point nearest the collision that lies clearly on one
/// side (near the end of a family's domain, lambda_2+ often reaches zero just before the wheel rolls back, and a
/// Newton step from the grid gait straight to the border could leave the domain); for a fold, period doubling
/// or Neimark-Sacker point, from the located point.
fn curve_seed(
    condition: Condition,
    line_family: &GaitFamily,
    row_family: &Family<GaitInfo>,
    value: f64,
) -> Result<CurveSeed, String> {
    let nearest = |a: f64, b: f64| (a - value).abs().total_cmp(&(b - value).abs());
    match condition {
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
            CurveSeed::at_border(line_family, row_family, collision, border).ok_or_else(|| {
                "no point of the row's family lies clearly on one side of the border".into()
            })
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
            CurveSeed::at_special(sp)
                .ok_or_else(|| "not a special point with a test function".into())
        }
    }
}

/// The crossings of `seeds` the continued `curve` of `problem` passes through: every one within one grid cell of
/// the curve's polyline on its line, solved for on the curve and compared with its line's threshold. Those
/// within [`LINE_CHECK_TOL`] are the curve's (hits), the others a different border nearby (misses); each with
/// its difference.
fn check_crossings(
    problem: &CurveProblem<'_, GaitInfo>,
    curve: &Curve<GaitInfo>,
    map: &GaitMap,
    seeds: &[&LineThreshold],
    options: &CurveOptions,
) -> (Checked, Checked) {
    let cell = |s: &SweepSpec, n: usize| (s.to - s.from).abs() / (n.max(2) - 1) as f64;
    let x_cell = cell(&map.spec.x, map.xs.len());
    let y_cell = cell(&map.spec.y, map.ys.len());
    let candidates: Vec<usize> = (0..seeds.len())
        .filter(|&m| {
            let s = seeds[m];
            match s.along {
                Along::X => crossings_at(curve, 1, map.ys[s.line])
                    .any(|x| (x - s.threshold.value).abs() <= x_cell),
                Along::Y => crossings_at(curve, 0, map.xs[s.line])
                    .any(|y| (y - s.threshold.value).abs() <= y_cell),
            }
        })
        .collect();
    let differences: Vec<f64> = candidates
        .par_iter()
        .map(carried(|&m: &usize| {
            let s = seeds[m];
            let v = s.threshold.value;
            let on_curve = match s.along {
                Along::X => curve_at(problem, curve, (1, map.ys[s.line]), v, options).map(|p| p.p1),
                Along::Y => curve_at(problem, curve, (0, map.xs[s.line]), v, options).map(|p| p.p2),
            };
            on_curve.map_or(f64::NAN, |v| (v - s.threshold.value).abs())
        }))
        .collect();
    candidates
        .into_iter()
        .zip(differences)
        .partition(|(_, d)| *d <= LINE_CHECK_TOL)
}

/// Crossings (their indices in the seeds), each with the difference between the curve and its line's threshold.
type Checked = Vec<(usize, f64)>;

/// How a continued curve ends, in words ([`ContinuedCurve::ends`]).
fn end_words(e: &CurveEnd) -> String {
    match e {
        CurveEnd::LeftRange => "left_range".to_string(),
        CurveEnd::MaxPoints => "max_points".to_string(),
        CurveEnd::Ended { message } => format!("ended: {message}"),
    }
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
