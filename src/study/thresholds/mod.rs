//! Parameter values where something changes along a sweep, found by root finding in the parameter (never read
//! off the grid): the DLS indicators crossing zero (the paper's `c = 220` for `lambda_4+` and `c = 4.0` for
//! `lambda_2+`), the changes of stability (`max |multiplier| = 1`: `stability_lost` or `stability_regained` in
//! the direction of increasing parameter, `period_doubling` where a multiplier crosses -1), and the ends of gait
//! families.
//!
//! Sign changes between neighbouring sweep points of one gait family are refined by Brent's method (the `roots`
//! crate) on the indicator of the gait continued from the left neighbour, to [`PARAM_TOL`] in the parameter.
//! Ends of families are followed in verified continuation steps to [`PARAM_TOL`] and their physical cause is
//! looked for just past the end ([`crate::family::natural`]):
//!
//! | threshold | where |
//! |---|---|
//! | `gait_lost` | the family ends going up the parameter, and a walk from its last gait just past the end fails |
//! | `gait_found` | the same going down: a family begins after a stretch without a gait |
//! | `branch_switch` | the family ends and the walk settles on another gait family (or the neighbour is one) |
//! | `fold` | the family ends at a multiplier of +1 (saddle-node) |
//! | `unconfirmed` | the family ends, but nothing physical was found just past the end (the reason is given) |
//!
//! The refinements are independent and run in parallel (rayon); each is deterministic, so the results do not
//! depend on the number of threads.

use std::cell::{Cell, RefCell};

use rayon::prelude::*;

use crate::meter::carried;
use crate::study::parallelism::{measured, Cost};
use roots::{find_root_brent, Convergency};
use serde::Serialize;

use nalgebra::DMatrix;

use super::sweep::SweepPoint;
mod ends;

pub(crate) use crate::family::natural::PARAM_TOL;
use crate::family::natural::{carried_start, GaitPoint};
use crate::family::Parameter;
use crate::gait::limit_cycle::{find_gait, solve_fixed_point, Gait, GaitOptions};
use crate::walk::DlsIndicators;
use ends::refine_end;

/// Brent iterations allowed.
const MAX_BRENT_ITERATIONS: usize = 100;

/// A located threshold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Threshold {
    /// What crosses: `lambda_4_plus = 0`, `lambda_2_plus = 0`, `lambda_I4 = 0`, a change of stability (the
    /// largest Floquet multiplier's modulus crosses 1: `stability_lost` where the gaits below are stable,
    /// `stability_regained` where those above are, `period_doubling` where a multiplier crosses -1, the
    /// stable side then in `detail`), or an end of a gait family: `gait_lost`, `gait_found`, `branch_switch`,
    /// `fold` or `unconfirmed` (see the module documentation).
    pub name: String,
    /// The parameter value \[unit of the parameter\]; `NaN` if the search failed.
    pub value: f64,
    /// Final bracket `[a, b]` (for the grid bracket it was started from, see `grid_bracket`).
    pub bracket: [f64; 2],
    /// The sweep points it was started between.
    pub grid_bracket: [f64; 2],
    /// The function at `value` (the indicator \[N s or N\], or `max |multiplier| - 1`); `NaN` for the ends of
    /// families.
    pub residual: f64,
    /// What happens past a family's end (its physical cause) or why the search failed.
    pub detail: Option<String>,
    /// The same threshold searched again by a second route (`vrw sweep --second-route`), if it was.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub second_route: Option<SecondRoute>,
}

/// Two routes agree on a threshold when their values differ by at most this: each value is the middle of a
/// bracket at most `PARAM_TOL` wide.
pub const SECOND_ROUTE_TOL: f64 = 2.0 * PARAM_TOL;

/// A threshold searched again by a second route: the whole computation (gaits, continuation, thresholds) run
/// once more with the other integrator, so that a value that depends on the integration (or on the path the
/// continuation took with it) shows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SecondRoute {
    /// The route, e.g. `integrator = dopri5`.
    pub route: String,
    /// The threshold the second route found between the same grid points, closest in value: its name, or
    /// `None` if it found none there.
    pub name: Option<String>,
    /// Its value (`NaN` if none, or if its search failed).
    pub value: f64,
    /// `|value - first value|` (`NaN` if either is unknown).
    pub difference: f64,
    /// The same name, and values within [`SECOND_ROUTE_TOL`].
    pub confirmed: bool,
}

impl SecondRoute {
    /// `threshold` checked against `found`, the thresholds the second route `route` found along the same line:
    /// the one between the same grid points closest in value (by name first) is its counterpart.
    pub(crate) fn check<'a>(
        threshold: &Threshold,
        found: impl IntoIterator<Item = &'a Threshold>,
        route: &str,
    ) -> SecondRoute {
        let distance = |t: &Threshold| {
            let d = (t.value - threshold.value).abs();
            (
                t.name != threshold.name,
                if d.is_nan() { f64::INFINITY } else { d },
            )
        };
        let counterpart = found
            .into_iter()
            .filter(|t| t.grid_bracket == threshold.grid_bracket)
            .min_by(|a, b| {
                let (da, db) = (distance(a), distance(b));
                da.0.cmp(&db.0).then(da.1.total_cmp(&db.1))
            });
        let value = counterpart.map_or(f64::NAN, |t| t.value);
        let difference = (value - threshold.value).abs();
        SecondRoute {
            route: route.to_string(),
            name: counterpart.map(|t| t.name.clone()),
            value,
            difference,
            confirmed: counterpart.is_some_and(|t| t.name == threshold.name)
                && difference <= SECOND_ROUTE_TOL,
        }
    }
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
    /// A family ends between a point with a gait (first) and its neighbour (second), which has no gait or a
    /// gait of another family.
    End(&'a SweepPoint, &'a SweepPoint),
}

/// Locate every threshold in the sweep `points` of `spec` (see the module documentation).
pub fn find_thresholds(
    parameter: Parameter,
    points: &[SweepPoint],
    options: &GaitOptions,
) -> Vec<Threshold> {
    find_thresholds_costed(parameter, points, options).0
}

/// [`find_thresholds`], with the cost of each of its refinements (independent tasks, run in parallel).
pub(crate) fn find_thresholds_costed(
    parameter: Parameter,
    points: &[SweepPoint],
    options: &GaitOptions,
) -> (Vec<Threshold>, Vec<Cost>) {
    let mut tasks = Vec::new();
    for pair in points.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        match (&a.gait, &b.gait) {
            (Some(ga), Some(gb)) if a.family == b.family => {
                for q in Quantity::ALL {
                    if q.changes_sign(ga, gb) {
                        tasks.push(Task::Root(q, a, b));
                    }
                }
            }
            // A change of family: where the left one ends and where the right one begins (they may coexist,
            // or meet at one point, e.g. a border collision).
            (Some(_), Some(_)) => {
                tasks.push(Task::End(a, b));
                tasks.push(Task::End(b, a));
            }
            (Some(_), None) => tasks.push(Task::End(a, b)),
            (None, Some(_)) => tasks.push(Task::End(b, a)),
            (None, None) => {}
        }
    }
    let gait_before = |v: f64| points.iter().any(|p| p.gait.is_some() && p.value < v);
    let found: Vec<(Vec<Threshold>, Cost)> = tasks
        .par_iter()
        .map(carried(|task: &Task| {
            measured(|| match task {
                Task::Root(q, a, b) => vec![refine_root(parameter, *q, a, b, options)],
                Task::End(from, toward) => {
                    refine_end(parameter, from, toward, options, gait_before(from.value))
                }
            })
        }))
        .collect();
    let costs = found.iter().map(|f| f.1).collect();
    let found = found.into_iter().flat_map(|f| f.0).collect();
    let thresholds = every_family_change_named(parameter.key(), points, without_repeats(found));
    (thresholds, costs)
}

/// `thresholds` without the repeats of one end found from both sides (the same name within [`PARAM_TOL`] in
/// the same grid interval), the first kept.
fn without_repeats(thresholds: Vec<Threshold>) -> Vec<Threshold> {
    let mut kept: Vec<Threshold> = Vec::with_capacity(thresholds.len());
    for t in thresholds {
        let repeat = kept.iter().any(|k| {
            k.name == t.name
                && k.grid_bracket == t.grid_bracket
                && (k.value - t.value).abs() <= PARAM_TOL
        });
        if !repeat {
            kept.push(t);
        }
    }
    kept
}

/// `thresholds` with an entry for every pair of neighbouring points where the family number changes and no
/// threshold lies: the family change was seen but neither family's end could be bracketed between them (the
/// reason in `detail`, the grid interval as the bracket, no value).
fn every_family_change_named(
    param: &str,
    points: &[SweepPoint],
    mut thresholds: Vec<Threshold>,
) -> Vec<Threshold> {
    for pair in points.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        let (Some(ga), Some(gb)) = (&a.gait, &b.gait) else {
            continue;
        };
        let interval = sorted([a.value, b.value]);
        let named = thresholds
            .iter()
            .any(|t| sorted(t.grid_bracket) == interval);
        if a.family == b.family || named {
            continue;
        }
        let mut entry = unconfirmed(
            interval,
            format!(
                "the family changes between {p} = {} (period {}) and {p} = {} (period {}), but neither \
                 family's end is bracketed between them: each family, followed toward the other point, reaches \
                 it as the other's gait (a change of least period, e.g. period doublings, within one family of \
                 fixed points of P^k)",
                a.value,
                ga.period_k,
                b.value,
                gb.period_k,
                p = param
            ),
        );
        entry.name = "family_change".to_string();
        thresholds.push(entry);
    }
    thresholds
}

/// A family end that could not be located, reported over its grid interval with the reason.
fn unconfirmed(grid_bracket: [f64; 2], detail: String) -> Threshold {
    Threshold {
        name: "unconfirmed".to_string(),
        value: f64::NAN,
        bracket: grid_bracket,
        grid_bracket,
        residual: f64::NAN,
        detail: Some(detail),
        second_route: None,
    }
}

fn sorted(mut pair: [f64; 2]) -> [f64; 2] {
    pair.sort_by(f64::total_cmp);
    pair
}

/// Brent on `q(gait(v))` between the sweep points `a` and `b`, continuing from `a`'s gait: Newton's method at
/// each `v` starts from the gait found at the value nearest to `v` so far (`a`'s at first), carried to `v`, so
/// that as Brent's brackets shrink its starts come closer to the gait.
fn refine_root(
    parameter: Parameter,
    q: Quantity,
    a: &SweepPoint,
    b: &SweepPoint,
    options: &GaitOptions,
) -> Threshold {
    let start = a
        .gait
        .as_ref()
        .expect("root tasks have gaits on both sides");
    let search = RootSearch {
        parameter,
        q,
        start,
        options: GaitOptions {
            transient_steps: 0,
            refine_jacobian: false,
            ..*options
        },
        guess: start.jacobian_guess(),
        found: RefCell::new(vec![GaitPoint {
            value: a.value,
            section: start.section,
        }]),
        last_gait: RefCell::new(None),
        failure: Cell::new(None),
        bracket: [Cell::new(a.value), Cell::new(b.value)],
        f_a: q.of(start),
    };
    let f = |v: f64| search.f(v);
    let result = find_root_brent(a.value, b.value, &f, &mut ParamTolerance);
    let mut detail = search
        .failure
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
    let (name, detail) = if q == Quantity::Stability {
        let root_gait = search.last_gait.borrow();
        let at_root = root_gait.as_ref().filter(|_| value.is_finite());
        let change = stability_change(a.value, b.value, search.f_a);
        stability_named(change, at_root, value, detail)
    } else {
        (q.name().to_string(), detail)
    };
    Threshold {
        name,
        value,
        bracket: sorted(search.bracket.each_ref().map(Cell::get)),
        grid_bracket: [a.value, b.value],
        residual,
        detail,
        second_route: None,
    }
}

/// Brent's function of [`refine_root`]: the quantity `q` of the gait of `start`'s family at a parameter value.
struct RootSearch<'a> {
    parameter: Parameter<'a>,
    q: Quantity,
    /// The gait the family is followed from.
    start: &'a Gait,
    /// Newton's method's settings (no transient).
    options: GaitOptions,
    /// Its Newton matrix.
    guess: Option<DMatrix<f64>>,
    /// The gaits found so far (the family's points in the bracket).
    found: RefCell<Vec<GaitPoint>>,
    /// The gait of the last evaluation (stability only): at the root, its critical multiplier names the change.
    last_gait: RefCell<Option<Gait>>,
    /// Why an evaluation failed (the first reason: the search evaluates nothing after it).
    failure: Cell<Option<String>>,
    /// The bracket Brent's method has reached, for the report: the last values with the sign of `f_a` and
    /// without it.
    bracket: [Cell<f64>; 2],
    /// The quantity at the start.
    f_a: f64,
}

impl RootSearch<'_> {
    /// Brent's function: [`RootSearch::evaluate`], `NaN` after a failure (its reason kept in `failure`).
    fn f(&self, v: f64) -> f64 {
        // After a failure the search is abandoned: keep the first reason, evaluate nothing more.
        let failed = self.failure.take();
        if failed.is_some() {
            self.failure.set(failed);
            return f64::NAN;
        }
        match self.evaluate(v) {
            Ok(y) => {
                // Track the bracket for the report.
                let side = usize::from((y < 0.0) != (self.f_a < 0.0));
                self.bracket[side].set(v);
                y
            }
            Err(message) => {
                self.failure.set(Some(message));
                f64::NAN
            }
        }
    }

    /// `q` of the family's gait at `v`, by Newton's method from the gait found nearest `v` so far, carried to
    /// `v`; why not, in words.
    fn evaluate(&self, v: f64) -> Result<f64, String> {
        let at = self.parameter.at(v).map_err(|e| e.to_string())?;
        // A period-k family's gaits are fixed points of P^k; the indicators are those of its first step.
        let map = at.step_map().iterated(self.start.period_k);
        let from = *self
            .found
            .borrow()
            .iter()
            .min_by(|x, y| (x.value - v).abs().total_cmp(&(y.value - v).abs()))
            .expect("a's gait is found");
        let s = carried_start(&self.parameter, &from, v);
        let guess = self.guess.as_ref();
        let (y, section) = if self.q == Quantity::Stability {
            let g = find_gait(&map, &s, &self.options, guess).map_err(|e| e.to_string())?;
            let y = self.q.of(&g);
            let section = g.section;
            *self.last_gait.borrow_mut() = Some(g);
            (y, section)
        } else {
            let fp =
                solve_fixed_point(&map, &s, &self.options, guess).map_err(|e| e.to_string())?;
            (
                self.q.of_indicators(&fp.outcome.report.indicators),
                fp.section,
            )
        };
        self.found
            .borrow_mut()
            .push(GaitPoint { value: v, section });
        Ok(y)
    }
}

/// A stability change's name and detail: `period_doubling` where the critical multiplier of the gait at the
/// root is real and negative, else the name of [`stability_change`]; the stable side noted before `detail`.
fn stability_named(
    (stable_side, words): (&'static str, &'static str),
    at_root: Option<&Gait>,
    value: f64,
    detail: Option<String>,
) -> (String, Option<String>) {
    let critical = at_root.and_then(|g| critical_multiplier(&g.floquet_multipliers));
    let noted = |note: String| {
        Some(
            detail
                .clone()
                .map_or(note.clone(), |d| format!("{note}; {d}")),
        )
    };
    if let Some([re, im]) = critical.filter(|[re, im]| *re < 0.0 && im.abs() <= REAL_MULTIPLIER_TOL)
    {
        let note = format!(
            "a multiplier crosses -1 ({re:.6}{im:+.1e}i at the root): a period doubling, stable {stable_side}"
        );
        ("period_doubling".to_string(), noted(note))
    } else if value.is_finite() {
        (words.to_string(), noted(format!("stable {stable_side}")))
    } else {
        (words.to_string(), detail)
    }
}

/// A multiplier whose imaginary part is at most this is real (the eigenvalue solver's rounding).
const REAL_MULTIPLIER_TOL: f64 = 1e-9;

/// Which side of a stability change between the grid points at `a` and `b` (with `max |multiplier| - 1` equal
/// to `f_a` at `a`) is stable, in words (`below` or `above` the threshold), and the threshold's name in the
/// direction of increasing parameter: `stability_lost` when the gaits below are stable, `stability_regained`
/// when those above are.
fn stability_change(a: f64, b: f64, f_a: f64) -> (&'static str, &'static str) {
    let stable_below = (f_a < 0.0) == (a < b);
    if stable_below {
        ("below", "stability_lost")
    } else {
        ("above", "stability_regained")
    }
}

/// The multiplier of largest modulus, `[re, im]` (`None` without multipliers).
fn critical_multiplier(multipliers: &[[f64; 2]]) -> Option<[f64; 2]> {
    multipliers
        .iter()
        .copied()
        .max_by(|x, y| x[0].hypot(x[1]).total_cmp(&y[0].hypot(y[1])))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn threshold(name: &str, value: f64, grid_bracket: [f64; 2]) -> Threshold {
        Threshold {
            name: name.to_string(),
            value,
            bracket: [value, value],
            grid_bracket,
            residual: f64::NAN,
            detail: None,
            second_route: None,
        }
    }

    /// The counterpart is the one between the same grid points, of the same kind first, closest in value; a
    /// threshold is confirmed only by one of its kind within SECOND_ROUTE_TOL.
    #[test]
    fn second_route_confirms_only_the_same_threshold() {
        let first = threshold("gait_lost", 135.489237, [120.0, 140.0]);
        let found = [
            threshold("gait_lost", 135.4892375, [100.0, 120.0]),
            threshold("lambda_2_plus = 0", 135.489237, [120.0, 140.0]),
            threshold("gait_lost", 135.4892381, [120.0, 140.0]),
        ];
        let r = SecondRoute::check(&first, &found, "integrator = dopri5");
        assert_eq!(r.name.as_deref(), Some("gait_lost"));
        assert_eq!(r.value, 135.4892381);
        assert!(r.confirmed, "{r:?}");
        assert_eq!(r.route, "integrator = dopri5");

        // Too far apart, another kind, nothing there, or not located at all: not confirmed.
        let far = [threshold("gait_lost", 135.48925, [120.0, 140.0])];
        assert!(!SecondRoute::check(&first, &far, "r").confirmed);
        let other_kind = [threshold("branch_switch", 135.489237, [120.0, 140.0])];
        let r = SecondRoute::check(&first, &other_kind, "r");
        assert!(!r.confirmed);
        assert_eq!(r.name.as_deref(), Some("branch_switch"));
        let r = SecondRoute::check(&first, &[], "r");
        assert!(!r.confirmed && r.name.is_none() && r.value.is_nan());
        let lost = threshold("unconfirmed", f64::NAN, [120.0, 140.0]);
        let again = [threshold("unconfirmed", f64::NAN, [120.0, 140.0])];
        assert!(!SecondRoute::check(&lost, &again, "r").confirmed);
    }
}
