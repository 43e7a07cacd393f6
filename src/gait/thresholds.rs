//! Parameter values where something changes along a sweep, found by root finding in the parameter (never read
//! off the grid): the DLS indicators crossing zero (the paper's `c = 220` for `lambda_4+` and `c = 4.0` for
//! `lambda_2+`), the loss of stability (`max |multiplier| = 1`) and the ends of the range where a gait exists.
//!
//! Sign changes between neighbouring sweep points are refined by Brent's method (the `roots` crate) on the
//! indicator of the gait continued from the left neighbour, to [`PARAM_TOL`] in the parameter; the existence
//! boundary by bisection on "a gait is found". The refinements are independent and run in parallel (rayon);
//! each is deterministic, so the results do not depend on the number of threads.

use std::cell::Cell;

use rayon::prelude::*;
use roots::{find_root_brent, Convergency};
use serde::Serialize;

use super::limit_cycle::{find_gait, solve_fixed_point, Gait, GaitOptions};
use super::step_map::StepMap;
use super::sweep::{configured, SweepPoint, SweepSpec};
use crate::params::Config;
use crate::walk::DlsIndicators;

/// Tolerance of every threshold in the swept parameter.
pub const PARAM_TOL: f64 = 1e-6;

/// Newton iterations allowed at each bisection point of a gait-existence boundary.
const BISECTION_NEWTON_ITERATIONS: usize = 8;

/// Brent iterations allowed.
const MAX_BRENT_ITERATIONS: usize = 100;

/// A located threshold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Threshold {
    /// What crosses: `lambda_4_plus = 0`, `lambda_2_plus = 0`, `lambda_I4 = 0`, `stability_lost` (largest
    /// Floquet multiplier modulus = 1) or `gait_lost`.
    pub name: String,
    /// The parameter value \[unit of the parameter\]; `NaN` if the search failed.
    pub value: f64,
    /// Final bracket `[a, b]` (for the grid bracket it was started from, see `grid_bracket`).
    pub bracket: [f64; 2],
    /// The sweep points it was started between.
    pub grid_bracket: [f64; 2],
    /// The function at `value` (the indicator \[N s or N\], or `max |multiplier| - 1`); `NaN` for `gait_lost`.
    pub residual: f64,
    /// How the gait is lost (failure kind beyond the boundary) or why the search failed.
    pub detail: Option<String>,
}

/// What a threshold measures on a gait.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Quantity {
    Lambda4Plus,
    Lambda2Plus,
    LambdaI4,
    Stability,
}

impl Quantity {
    const ALL: [Quantity; 4] = [
        Quantity::Lambda4Plus,
        Quantity::Lambda2Plus,
        Quantity::LambdaI4,
        Quantity::Stability,
    ];

    fn name(self) -> &'static str {
        match self {
            Quantity::Lambda4Plus => "lambda_4_plus = 0",
            Quantity::Lambda2Plus => "lambda_2_plus = 0",
            Quantity::LambdaI4 => "lambda_I4 = 0",
            Quantity::Stability => "stability_lost",
        }
    }

    fn of(self, g: &Gait) -> f64 {
        match self {
            Quantity::Stability => g.max_floquet - 1.0,
            _ => self.of_indicators(&DlsIndicators {
                lambda_i4: g.lambda_i4,
                lambda_2_plus: g.lambda_2_plus,
                lambda_4_plus: g.lambda_4_plus,
            }),
        }
    }

    /// The quantity from the DLS indicators of a step (`NaN` for `Stability`, which needs `DP`).
    fn of_indicators(self, i: &DlsIndicators) -> f64 {
        match self {
            Quantity::Lambda4Plus => i.lambda_4_plus,
            Quantity::Lambda2Plus => i.lambda_2_plus,
            Quantity::LambdaI4 => i.lambda_i4,
            Quantity::Stability => f64::NAN,
        }
    }

    /// Does the quantity change sign (both values defined) between the gaits `a` and `b`?
    fn changes_sign(self, a: &Gait, b: &Gait) -> bool {
        let (fa, fb) = (self.of(a), self.of(b));
        fa.is_finite() && fb.is_finite() && (fa < 0.0) != (fb < 0.0)
    }
}

/// Brent's stopping rule: the bracket is narrower than [`PARAM_TOL`] or the function is exactly zero.
struct ParamTolerance;

impl Convergency<f64> for ParamTolerance {
    fn is_root_found(&mut self, y: f64) -> bool {
        y == 0.0
    }
    fn is_converged(&mut self, x1: f64, x2: f64) -> bool {
        (x1 - x2).abs() < PARAM_TOL
    }
    fn is_iteration_limit_reached(&mut self, iter: usize) -> bool {
        iter >= MAX_BRENT_ITERATIONS
    }
}

enum Task<'a> {
    Root(Quantity, &'a SweepPoint, &'a SweepPoint),
    Boundary(&'a SweepPoint, &'a SweepPoint),
}

/// Locate every threshold in the sweep `points` of `spec` (see the module documentation).
pub fn find_thresholds(
    config: &Config,
    spec: &SweepSpec,
    points: &[SweepPoint],
    options: &GaitOptions,
) -> Vec<Threshold> {
    let mut tasks = Vec::new();
    for pair in points.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        match (&a.gait, &b.gait) {
            (Some(ga), Some(gb)) => {
                for q in Quantity::ALL {
                    if q.changes_sign(ga, gb) {
                        tasks.push(Task::Root(q, a, b));
                    }
                }
            }
            (Some(_), None) | (None, Some(_)) => tasks.push(Task::Boundary(a, b)),
            (None, None) => {}
        }
    }
    let mut found: Vec<Threshold> = tasks
        .par_iter()
        .map(|task| match task {
            Task::Root(q, a, b) => refine_root(config, spec, *q, a, b, options),
            Task::Boundary(a, b) => refine_boundary(config, spec, a, b, options),
        })
        .collect();
    found.extend(sign_changes_across_gaps(points));
    found
}

/// Sign changes of a quantity between two gaits separated by points without a gait: the crossing cannot be
/// refined (the gait does not exist continuously across it), so it is reported with its grid bracket and no
/// value. This happens where the crossing switches the impact branch and the step map jumps.
fn sign_changes_across_gaps(points: &[SweepPoint]) -> Vec<Threshold> {
    let with_gait: Vec<(usize, &SweepPoint, &Gait)> = points
        .iter()
        .enumerate()
        .filter_map(|(i, p)| p.gait.as_ref().map(|g| (i, p, g)))
        .collect();
    let mut out = Vec::new();
    for pair in with_gait.windows(2) {
        let ((ia, a, ga), (ib, b, gb)) = (pair[0], pair[1]);
        if ib == ia + 1 {
            continue;
        }
        for q in Quantity::ALL {
            if q.changes_sign(ga, gb) {
                let (fa, fb) = (q.of(ga), q.of(gb));
                out.push(Threshold {
                    name: q.name().to_string(),
                    value: f64::NAN,
                    bracket: [a.value, b.value],
                    grid_bracket: [a.value, b.value],
                    residual: f64::NAN,
                    detail: Some(format!(
                        "sign change from {fa} to {fb} across points without a gait: not refinable"
                    )),
                });
            }
        }
    }
    out
}

/// Brent on `q(gait(v))` between the sweep points `a` and `b`, continuing from `a`'s gait.
fn refine_root(
    config: &Config,
    spec: &SweepSpec,
    q: Quantity,
    a: &SweepPoint,
    b: &SweepPoint,
    options: &GaitOptions,
) -> Threshold {
    let start = a
        .gait
        .as_ref()
        .expect("root tasks have gaits on both sides");
    let continued = GaitOptions {
        transient_steps: 0,
        refine_jacobian: false,
        ..*options
    };
    let guess = start.jacobian_matrix();
    let failure: Cell<Option<String>> = Cell::new(None);
    let (lo, hi) = (Cell::new(a.value), Cell::new(b.value));
    let f_a = q.of(start);
    let f = |v: f64| -> f64 {
        // After a failure the search is abandoned: keep the first reason, evaluate nothing more.
        let failed = failure.take();
        if failed.is_some() {
            failure.set(failed);
            return f64::NAN;
        }
        let value = (|| {
            let (c, model) = configured(config, &spec.param, v).map_err(|e| e.to_string())?;
            let map = StepMap::new(&model, &c.solver);
            let y = if q == Quantity::Stability {
                q.of(&find_gait(&map, &start.section, &continued, Some(&guess))
                    .map_err(|e| e.to_string())?)
            } else {
                let fp = solve_fixed_point(&map, &start.section, &continued, Some(&guess))
                    .map_err(|e| e.to_string())?;
                q.of_indicators(&fp.outcome.report.indicators)
            };
            Ok::<f64, String>(y)
        })();
        match value {
            Ok(y) => {
                // Track the bracket for the report.
                if (y < 0.0) == (f_a < 0.0) {
                    lo.set(v);
                } else {
                    hi.set(v);
                }
                y
            }
            Err(message) => {
                failure.set(Some(message));
                f64::NAN
            }
        }
    };
    let result = find_root_brent(a.value, b.value, &f, &mut ParamTolerance);
    let mut detail = failure
        .take()
        .map(|m| format!("gait search failed inside the bracket: {m}"));
    let value = match result {
        Ok(v) if detail.is_none() => v,
        Ok(_) => f64::NAN,
        Err(e) => {
            detail.get_or_insert_with(|| format!("root search failed: {e}"));
            f64::NAN
        }
    };
    let residual = if value.is_finite() {
        f(value)
    } else {
        f64::NAN
    };
    let mut bracket = [lo.get(), hi.get()];
    bracket.sort_by(f64::total_cmp);
    Threshold {
        name: q.name().to_string(),
        value,
        bracket,
        grid_bracket: [a.value, b.value],
        residual,
        detail,
    }
}

/// Bisection on "a gait is found" between a point with a gait and one without.
fn refine_boundary(
    config: &Config,
    spec: &SweepSpec,
    a: &SweepPoint,
    b: &SweepPoint,
    options: &GaitOptions,
) -> Threshold {
    let (found, lost) = if a.gait.is_some() { (a, b) } else { (b, a) };
    let start = found.gait.as_ref().expect("one side has a gait");
    let guess = start.jacobian_matrix();
    let mut section = start.section;
    // Each bisection point is at most half the previous interval from a converged neighbour: a few Newton
    // iterations suffice, and failing fast matters because half the attempts fail.
    let continued = GaitOptions {
        transient_steps: 0,
        refine_jacobian: false,
        max_iterations: BISECTION_NEWTON_ITERATIONS.min(options.max_iterations),
        ..*options
    };
    let (mut inside, mut outside) = (found.value, lost.value);
    let mut how = lost.status.clone();
    while (outside - inside).abs() > PARAM_TOL {
        let mid = 0.5 * (inside + outside);
        let attempt = configured(config, &spec.param, mid)
            .map_err(|e| e.to_string())
            .and_then(|(c, model)| {
                let map = StepMap::new(&model, &c.solver);
                solve_fixed_point(&map, &section, &continued, Some(&guess))
                    .map_err(|e| e.kind().to_string())
            });
        match attempt {
            Ok(fp) => {
                inside = mid;
                section = fp.section;
            }
            Err(kind) => {
                outside = mid;
                how = kind;
            }
        }
    }
    let mut bracket = [inside, outside];
    bracket.sort_by(f64::total_cmp);
    Threshold {
        name: "gait_lost".to_string(),
        value: 0.5 * (inside + outside),
        bracket,
        grid_bracket: [a.value, b.value],
        residual: f64::NAN,
        detail: Some(format!(
            "gait exists at {} = {inside} and not at {outside}: {how}",
            spec.param
        )),
    }
}
