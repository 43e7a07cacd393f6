//! Curves of special points in two parameters (docs/model.md section 11, "Two-parameter curves"): the fixed
//! point together with its defining condition, `P(x; p1, p2) = x` and `g(x, p1, p2) = 0` (`g` a DLS
//! indicator for a border collision, `det(DP - I)` for a fold, `det(DP + I)` for a period doubling, the
//! bialternate product for a Neimark-Sacker point), followed by pseudo-arclength continuation in
//! `u = (x, p1 / sigma1, p2 / sigma2)`.
//!
//! The Jacobian `[DP - I, sigma1 dP/dp1, sigma2 dP/dp2; grad g]` has its first block exact (the variational
//! equations give `DP` and `dP/dp1`), `dP/dp2` by a central difference and the gradient of `g` by central
//! differences (all on both cores); the residual is exact, so the curve's points are zeros of the exact `g`
//! whatever the approximations of the matrix. The corrector holds the matrix of the last point (a chord
//! method) and stops when `max |P(x) - x|` is below the tolerance and the last Newton step below `1e-9` in
//! every unknown; steps grow by 1.5 after a corrector of at most 5 iterations and halve after a failure, down to
//! the smallest step of [`CurveOptions::steps`], where the curve ends with the last failure.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::meter::carried;
use serde::Serialize;

use super::corrector::tangent;
use super::{Evaluation, Family, FamilyMap, FamilyPoint, MapFailure};

/// Relative step of the central differences of the curve's Jacobian.
pub const CURVE_FD_STEP: f64 = 1e-6;

/// How a curve is followed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurveOptions {
    /// The first parameter's range.
    pub range1: (f64, f64),
    /// The second parameter's range.
    pub range2: (f64, f64),
    /// Scales of the two parameters (the power of two nearest a tenth of each range).
    pub sigma: (f64, f64),
    /// First, smallest and largest step (scaled unknowns).
    pub steps: (f64, f64, f64),
    /// Most points each way.
    pub max_points: usize,
    /// `max |P(x) - x|` at which the corrector stops.
    pub tolerance: f64,
}

impl CurveOptions {
    /// The defaults for the two ranges: steps from `1e-6` to `0.1` (first `0.01`), 200 points each way,
    /// tolerance `1e-10`.
    pub fn for_ranges(range1: (f64, f64), range2: (f64, f64)) -> CurveOptions {
        let scale = |(a, b): (f64, f64)| {
            let width = (b - a).abs();
            if width > 0.0 {
                (width / 10.0).log2().round().exp2()
            } else {
                1.0
            }
        };
        CurveOptions {
            range1: (range1.0.min(range1.1), range1.0.max(range1.1)),
            range2: (range2.0.min(range2.1), range2.0.max(range2.1)),
            sigma: (scale(range1), scale(range2)),
            steps: (0.01, 1e-6, 0.1),
            max_points: 200,
            tolerance: 1e-10,
        }
    }
}

/// A point of a curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvePoint<I> {
    /// The first parameter.
    pub p1: f64,
    /// The second parameter.
    pub p2: f64,
    /// The fixed point.
    pub x: DVector<f64>,
    /// `g - offset` there (zero to the corrector's accuracy).
    pub test_value: f64,
    /// `max |P(x) - x|`.
    pub residual: f64,
    /// Arclength from the curve's first point (scaled unknowns).
    pub arclength: f64,
    /// What the map records of the point.
    pub info: I,
}

/// How a curve ends at one side.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CurveEnd {
    /// It left the box of the two ranges.
    LeftRange,
    /// [`CurveOptions::max_points`] points.
    MaxPoints,
    /// The step fell below the smallest: the last failure.
    Ended {
        /// The failure in words.
        message: String,
    },
}

/// A followed curve: its points in order of arclength and how it ends either way.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve<I> {
    /// The points.
    pub points: Vec<CurvePoint<I>>,
    /// How it ends at its first point and at its last.
    pub ends: [CurveEnd; 2],
}

/// `P(x; p1, p2)` with `DP` and `dP/dp1`.
pub type TwoParamEval<'f, I> =
    dyn Fn(&DVector<f64>, f64, f64) -> Result<Evaluation<I>, MapFailure> + Sync + 'f;

/// The two-parameter problem: `eval(x, p1, p2)` gives `P` with `DP` and `dP/dp1`; `test` the defining
/// condition `g`, whose zero is followed as `g = offset`.
///
/// **Borders.** A border collision's curve lies where `P` itself changes (and may jump): the curve is followed
/// at `g = offset`, a small value of the family's side (`1e-8`, above the `1e-9` within which the exact
/// derivatives refuse a border), and every difference of the Jacobian that would cross to the other side
/// (`g` of the opposite sign) is taken one-sided. The located curve then lies `offset / |grad g|` from the
/// border (`1e-8 N` of `lambda_2+` is about `5e-8 N/m` of stiffness). The steps themselves aim at
/// [`FOLLOW_OFFSET_FACTOR`] times the offset, and each point is then polished onto the offset.
pub struct CurveProblem<'f, I> {
    /// `P(x; p1, p2)` with its derivatives in `x` and `p1`.
    pub eval: &'f TwoParamEval<'f, I>,
    /// `P(x; p1, p2)` and what the map records, without derivatives (the evaluation's `jacobian` and `dparam`
    /// may be empty): the corrector's iterations and the differences use it, and `eval` is called once per
    /// point. `None` where `test` needs the derivatives (a fold's, period doubling's or Neimark-Sacker's `g`).
    pub observe: Option<&'f TwoParamEval<'f, I>>,
    /// `g` of an evaluation.
    pub test: &'f (dyn Fn(&Evaluation<I>) -> f64 + Sync),
    /// The value of `g` followed (0 for a fold, period doubling or Neimark-Sacker curve; the side's small value
    /// for a border).
    pub offset: f64,
}

/// What a curve of special points solves for together with the fixed point: a border function by name
/// (followed at a small offset on one side, [`BORDER_OFFSET`]) or a test function of `DP` (a fold's, period
/// doubling's or Neimark-Sacker point's, followed at zero).
#[derive(Debug, Clone, Copy)]
pub enum CurveTest<'a> {
    /// A border function of [`FamilyMap::borders`].
    Border(&'a str),
    /// A test function of `DP` ([`super::special::test_function`]).
    Jacobian(fn(&DMatrix<f64>) -> f64),
}

impl CurveTest<'_> {
    /// Its value at an evaluation of `map`.
    pub fn of<M: FamilyMap>(&self, map: &M, ev: &Evaluation<M::Info>) -> f64 {
        match self {
            CurveTest::Border(name) => map.border(&ev.info, name),
            CurveTest::Jacobian(test) => test(&ev.jacobian),
        }
    }

    /// A test function of `DP` needs every evaluation's derivatives (no [`CurveProblem::observe`]).
    pub fn needs_derivatives(&self) -> bool {
        matches!(self, CurveTest::Jacobian(_))
    }
}

/// The offset of a border curve from its border, on the side of `g`'s sign (see [`CurveProblem`]).
pub const BORDER_OFFSET: f64 = 1e-8;

/// A border curve's predictor-corrector steps aim at this many times its offset (`1e-4` for a border),
/// safely on the family's side, and each accepted point is then polished onto the offset itself: a step
/// whose corrector iterates cross the border evaluates the other piece, whose walk may fail or jump.
pub const FOLLOW_OFFSET_FACTOR: f64 = 1e4;

impl<I: Clone + Send> CurveProblem<'_, I> {
    /// `x`, `p1`, `p2` of the scaled unknowns.
    fn split(&self, u: &DVector<f64>, o: &CurveOptions) -> (DVector<f64>, f64, f64) {
        let n = u.len() - 2;
        (
            u.rows(0, n).into_owned(),
            u[n] * o.sigma.0,
            u[n + 1] * o.sigma.1,
        )
    }

    /// The residual `[P(x) - x; g]` and the evaluation.
    fn residual(
        &self,
        u: &DVector<f64>,
        o: &CurveOptions,
    ) -> Result<(DVector<f64>, Evaluation<I>), MapFailure> {
        self.residual_at(u, o, self.offset, true)
    }

    /// The residual with `g` followed at `offset`; the evaluation with derivatives if `derivatives` (else
    /// perhaps without, see [`CurveProblem::observe`]).
    fn residual_at(
        &self,
        u: &DVector<f64>,
        o: &CurveOptions,
        offset: f64,
        derivatives: bool,
    ) -> Result<(DVector<f64>, Evaluation<I>), MapFailure> {
        let (x, p1, p2) = self.split(u, o);
        let ev = match self.observe {
            Some(observe) if !derivatives => observe(&x, p1, p2)?,
            _ => (self.eval)(&x, p1, p2)?,
        };
        let g = (self.test)(&ev) - offset;
        let n = x.len();
        let mut r = DVector::zeros(n + 1);
        r.rows_mut(0, n).copy_from(&(&ev.value - &x));
        r[n] = g;
        Ok((r, ev))
    }

    /// The `(n + 1) x (n + 2)` Jacobian at `u`, whose evaluation is `ev` (see the module documentation).
    fn jacobian(
        &self,
        u: &DVector<f64>,
        ev: &Evaluation<I>,
        o: &CurveOptions,
    ) -> Result<DMatrix<f64>, MapFailure> {
        let n = u.len() - 2;
        // Central differences: dP/dp2 (column n + 1) and the gradient of g (all columns).
        // Every difference is computed, a failure or not, and the first failure in order is the error: the same
        // work for any number of threads.
        let shifted: Vec<Result<(DVector<f64>, f64), MapFailure>> = (0..n + 2)
            .into_par_iter()
            .map(carried(
                |i: usize| -> Result<(DVector<f64>, f64), MapFailure> {
                    let step = CURVE_FD_STEP * u[i].abs().max(1.0);
                    let at = |sign: f64| {
                        let mut v = u.clone();
                        v[i] += sign * step;
                        self.residual_at(&v, o, self.offset, false).map(|(r, _)| r)
                    };
                    // A difference whose walk fails, or that lands on the other side of a border (g + offset of
                    // the opposite sign to offset), is replaced by the one-sided difference on the other side.
                    let usable = |r: &Result<DVector<f64>, MapFailure>| match r {
                        Ok(r) => self.offset == 0.0 || (r[n] + self.offset) * self.offset >= 0.0,
                        Err(_) => false,
                    };
                    let (plus, minus) = (at(1.0), at(-1.0));
                    let here = || self.residual_at(u, o, self.offset, false).map(|(r, _)| r);
                    let d = match (usable(&plus), usable(&minus), plus, minus) {
                        (true, true, Ok(p), Ok(m)) => (p - m) / (2.0 * step),
                        (false, true, _, Ok(m)) => (here()? - m) / step,
                        (true, false, Ok(p), _) => (p - here()?) / step,
                        (_, _, Err(e), _) | (_, _, _, Err(e)) => return Err(e),
                        _ => return Err(failure("both differences cross the border")),
                    };
                    Ok((d.rows(0, n).into_owned(), d[n]))
                },
            ))
            .collect();
        let shifted = shifted.into_iter().collect::<Result<Vec<_>, _>>()?;
        let mut j = DMatrix::zeros(n + 1, n + 2);
        for r in 0..n {
            for c in 0..n {
                j[(r, c)] = ev.jacobian[(r, c)] - if r == c { 1.0 } else { 0.0 };
            }
            j[(r, n)] = o.sigma.0 * ev.dparam[r];
            // sigma2 dP/dp2: the difference was taken in the scaled unknown itself.
            j[(r, n + 1)] = shifted[n + 1].0[r];
        }
        for (c, (_, dg)) in shifted.iter().enumerate() {
            j[(n, c)] = *dg;
        }
        Ok(j)
    }

    /// Newton's method (chord, matrix `j` held) from `u_pred` on the residual and `row . (u - u_pred) = 0`.
    fn correct(
        &self,
        u_pred: &DVector<f64>,
        row: &DVector<f64>,
        j: &DMatrix<f64>,
        o: &CurveOptions,
    ) -> Result<(DVector<f64>, Evaluation<I>, usize), MapFailure> {
        self.correct_at(u_pred, row, j, o, self.offset)
    }

    /// [`CurveProblem::correct`] with `g` followed at `offset`.
    fn correct_at(
        &self,
        u_pred: &DVector<f64>,
        row: &DVector<f64>,
        j: &DMatrix<f64>,
        o: &CurveOptions,
        offset: f64,
    ) -> Result<(DVector<f64>, Evaluation<I>, usize), MapFailure> {
        let n = u_pred.len() - 2;
        let mut m = j.clone().insert_row(n + 1, 0.0);
        m.row_mut(n + 1).copy_from(&row.transpose());
        let lu = m.lu();
        let mut u = u_pred.clone();
        let mut last_step = f64::INFINITY;
        for iteration in 0..MAX_CURVE_ITERATIONS {
            let (r, ev) = self.residual_at(&u, o, offset, false)?;
            let residual = r.rows(0, n).amax();
            if residual < o.tolerance && last_step < CURVE_STEP_TOL {
                // The point's derivatives for the next matrix (the same walk, its value agreeing to the
                // integrator's tolerance; the point's residual is recomputed from this evaluation).
                let ev = match self.observe {
                    Some(_) => self.residual_at(&u, o, offset, true)?.1,
                    None => ev,
                };
                return Ok((u, ev, iteration));
            }
            let mut rhs = r.insert_row(n + 1, row.dot(&(&u - u_pred)));
            rhs.neg_mut();
            let du = lu
                .solve(&rhs)
                .ok_or_else(|| failure("singular corrector matrix"))?;
            last_step = du.amax();
            if !last_step.is_finite() {
                return Err(failure("the corrector diverged"));
            }
            u += du;
        }
        Err(failure(&format!(
            "the corrector did not converge in {MAX_CURVE_ITERATIONS} iterations"
        )))
    }
}

/// A corrector of at most this many iterations lets the next step grow (the chord method with a matrix of
/// differences contracts more slowly than the family's).
const EASY_CURVE_CORRECTOR: usize = 5;

/// Corrector iterations allowed on a curve.
const MAX_CURVE_ITERATIONS: usize = 10;

/// The corrector's last step must be below this in every scaled unknown.
const CURVE_STEP_TOL: f64 = 1e-9;

/// Where a border collision's curve starts from: the family's point nearest the border (in arclength from
/// `arclength`, the collision's) whose border function `border` is clearly off it (ten times the offset the
/// curve's steps aim at), and the function's sign there (the family's side). The located collision, and the
/// family's last point before a border that ends it, lie on the border itself, perhaps a rounding error past
/// it: a side taken there could be the other piece's.
pub fn border_curve_seed<'p, M: FamilyMap>(
    map: &M,
    family: &'p Family<M::Info>,
    arclength: f64,
    border: &str,
) -> Option<(&'p FamilyPoint<M::Info>, f64)> {
    let clear = 10.0 * BORDER_OFFSET * FOLLOW_OFFSET_FACTOR;
    family
        .points
        .iter()
        .map(|p| (p, map.border(&p.info, border)))
        .filter(|(_, g)| g.abs() >= clear)
        .min_by(|a, b| {
            let d = |p: &FamilyPoint<M::Info>| (p.arclength - arclength).abs();
            d(a.0).total_cmp(&d(b.0))
        })
        .map(|(p, g)| (p, g.signum()))
}

/// The scale of parameter `k` (0 or 1).
fn o_sigma(o: &CurveOptions, k: usize) -> f64 {
    if k == 0 {
        o.sigma.0
    } else {
        o.sigma.1
    }
}

/// A corrector failure.
fn failure(message: &str) -> MapFailure {
    MapFailure {
        kind: "corrector".to_string(),
        message: message.to_string(),
    }
}

/// Follow the curve of `problem` through the special point `x0` at `(p1, p2)` in both directions.
pub fn continue_curve<I: Clone + Send>(
    problem: &CurveProblem<'_, I>,
    x0: &DVector<f64>,
    (p1, p2): (f64, f64),
    options: &CurveOptions,
) -> Result<Curve<I>, MapFailure> {
    let n = x0.len();
    let mut u0 = DVector::zeros(n + 2);
    u0.rows_mut(0, n).copy_from(x0);
    u0[n] = p1 / options.sigma.0;
    u0[n + 1] = p2 / options.sigma.1;
    // The start corrected at its own p2, as the steps are: to the safe offset (from a special point located
    // on the border itself, which may lie a rounding error on its other side), then polished.
    let (_, ev0) =
        problem.residual_at(&u0, options, problem.offset * FOLLOW_OFFSET_FACTOR, true)?;
    let j0 = problem.jacobian(&u0, &ev0, options)?;
    let mut e2 = DVector::zeros(n + 2);
    e2[n + 1] = 1.0;
    let follow_offset = problem.offset * FOLLOW_OFFSET_FACTOR;
    let (u0, ev0, _) = problem.correct_at(&u0, &e2, &j0, options, follow_offset)?;
    let j0 = problem.jacobian(&u0, &ev0, options)?;
    let (u0, ev0, _) = problem.correct(&u0, &e2, &j0, options)?;
    let j0 = problem.jacobian(&u0, &ev0, options)?;
    let t0 =
        tangent(&j0, &e2).ok_or_else(|| failure("the curve has no unique tangent at its start"))?;
    let start = point(problem, &u0, &ev0, options, 0.0);
    let forward = follow(problem, (&u0, &j0, &t0), options);
    let backward = follow(problem, (&u0, &j0, &(-&t0)), options);
    // Backward points count their arclength from the start too: negative, then all shifted to start at 0.
    let mut points: Vec<CurvePoint<I>> = backward
        .0
        .into_iter()
        .rev()
        .map(|mut p| {
            p.arclength = -p.arclength;
            p
        })
        .collect();
    points.push(start);
    points.extend(forward.0);
    let first = points.first().map_or(0.0, |p| p.arclength);
    for p in &mut points {
        p.arclength -= first;
    }
    Ok(Curve {
        points,
        ends: [backward.1, forward.1],
    })
}

/// A curve point at `u`.
fn point<I: Clone + Send>(
    problem: &CurveProblem<'_, I>,
    u: &DVector<f64>,
    ev: &Evaluation<I>,
    options: &CurveOptions,
    arclength: f64,
) -> CurvePoint<I> {
    let (x, p1, p2) = problem.split(u, options);
    CurvePoint {
        p1,
        p2,
        residual: (&ev.value - &x).amax(),
        test_value: (problem.test)(ev) - problem.offset,
        x,
        arclength,
        info: ev.info.clone(),
    }
}

/// One direction of a curve from `(u, j, t)`: its points (arclength from the start) and its end.
fn follow<I: Clone + Send>(
    problem: &CurveProblem<'_, I>,
    (u0, j0, t0): (&DVector<f64>, &DMatrix<f64>, &DVector<f64>),
    o: &CurveOptions,
) -> (Vec<CurvePoint<I>>, CurveEnd) {
    let (mut u, mut j, mut t) = (u0.clone(), j0.clone(), t0.clone());
    let mut h = o.steps.0;
    let mut s = 0.0;
    let mut points = Vec::new();
    let mut last_failure = String::new();
    let inside = |p1: f64, p2: f64| {
        (o.range1.0..=o.range1.1).contains(&p1) && (o.range2.0..=o.range2.1).contains(&p2)
    };
    while points.len() < o.max_points {
        if h < o.steps.1 {
            return (
                points,
                CurveEnd::Ended {
                    message: last_failure,
                },
            );
        }
        let u_pred = &u + h * &t;
        // Followed at the safe offset, then polished onto the precise one (the same hyperplane).
        let follow_offset = problem.offset * FOLLOW_OFFSET_FACTOR;
        let next = problem
            .correct_at(&u_pred, &t, &j, o, follow_offset)
            .and_then(|(un, ev, it)| {
                // The polish uses the new point's own matrix: the last point's could step across the border.
                let jn = problem.jacobian(&un, &ev, o)?;
                let (up, ev, _) = if follow_offset == problem.offset {
                    (un, ev, 0)
                } else {
                    problem.correct(&un, &t, &jn, o)?
                };
                let tn = tangent(&jn, &t).ok_or_else(|| failure("no unique tangent"))?;
                Ok((up, ev, jn, tn, it))
            });
        match next {
            Ok((un, ev, jn, tn, it)) if (&un - &u_pred).norm() <= 0.5 * h && tn.dot(&t) >= 0.9 => {
                s += (&un - &u).norm();
                let p = point(problem, &un, &ev, o, s);
                if !inside(p.p1, p.p2) {
                    points.push(last_in_range(problem, (&u, &j, &t), &un, p, o));
                    return (points, CurveEnd::LeftRange);
                }
                points.push(p);
                (u, j, t) = (un, jn, tn);
                if it <= EASY_CURVE_CORRECTOR {
                    h = (1.5 * h).min(o.steps.2);
                }
            }
            Ok(_) => {
                last_failure = "steps turn or jump too far".to_string();
                h *= 0.5;
            }
            Err(e) => {
                last_failure = e.message;
                h *= 0.5;
            }
        }
    }
    (points, CurveEnd::MaxPoints)
}

/// The last point of a curve whose step from `(u, j, t)` to `un` (the point `p`) left the box of the ranges:
/// on the bound the step crossed first, where one can be solved for ([`on_hyperplane`]); else `p` itself.
fn last_in_range<I: Clone + Send>(
    problem: &CurveProblem<'_, I>,
    (u, j, t): (&DVector<f64>, &DMatrix<f64>, &DVector<f64>),
    un: &DVector<f64>,
    p: CurvePoint<I>,
    o: &CurveOptions,
) -> CurvePoint<I> {
    let n = un.len() - 2;
    let crossed = |k: usize, v: f64, (lo, hi): (f64, f64)| {
        let bound = if v > hi { hi } else { lo };
        let fraction = (bound / o_sigma(o, k) - u[n + k]) / (un[n + k] - u[n + k]);
        (v < lo || v > hi).then_some((fraction, n + k, bound / o_sigma(o, k)))
    };
    let first = [crossed(0, p.p1, o.range1), crossed(1, p.p2, o.range2)]
        .into_iter()
        .flatten()
        .min_by(|a, b| a.0.total_cmp(&b.0));
    let on_bound =
        first.and_then(|(_, index, value)| on_hyperplane(problem, (u, j, t), index, value, o));
    match on_bound {
        Some((ub, evb)) => {
            let sb = p.arclength - (un - u).norm() + (&ub - u).norm();
            point(problem, &ub, &evb, o, sb)
        }
        None => p,
    }
}

/// The point of `curve` at the second parameter `p2`, if the curve crosses `p2`: a step from the curve point
/// before the crossing along its tangent to `p2`, corrected on the hyperplane `p2 = const` as the curve's own
/// steps are (to the safe offset with that point's matrix, then polished with the new point's).
pub fn curve_at_p2<I: Clone + Send>(
    problem: &CurveProblem<'_, I>,
    curve: &Curve<I>,
    p2: f64,
    options: &CurveOptions,
) -> Option<CurvePoint<I>> {
    curve_at(problem, curve, (1, p2), f64::NAN, options)
}

/// The point of `curve` where parameter `which` (0: `p1`, 1: `p2`) equals `value`, as [`curve_at_p2`]; where the
/// curve crosses that line more than once, the crossing whose other parameter is nearest `near` (the first if
/// `near` is `NaN`).
pub fn curve_at<I: Clone + Send>(
    problem: &CurveProblem<'_, I>,
    curve: &Curve<I>,
    (which, value): (usize, f64),
    near: f64,
    options: &CurveOptions,
) -> Option<CurvePoint<I>> {
    let split = |p: &CurvePoint<I>| {
        if which == 0 {
            (p.p1, p.p2)
        } else {
            (p.p2, p.p1)
        }
    };
    let crossing = |w: &[CurvePoint<I>]| {
        let ((a, a_other), (b, b_other)) = (split(&w[0]), split(&w[1]));
        ((a - value) * (b - value) <= 0.0 && a != b)
            .then(|| a_other + (value - a) / (b - a) * (b_other - a_other))
    };
    let distance = |w: &[CurvePoint<I>]| crossing(w).map_or(f64::INFINITY, |o| (o - near).abs());
    let w = if near.is_nan() {
        curve.points.windows(2).find(|w| crossing(w).is_some())?
    } else {
        curve
            .points
            .windows(2)
            .filter(|w| crossing(w).is_some())
            .min_by(|a, b| distance(a).total_cmp(&distance(b)))?
    };
    let n = w[0].x.len();
    let scaled = |p: &CurvePoint<I>| {
        let mut u = DVector::zeros(n + 2);
        u.rows_mut(0, n).copy_from(&p.x);
        u[n] = p.p1 / options.sigma.0;
        u[n + 1] = p.p2 / options.sigma.1;
        u
    };
    let (u0, u1) = (scaled(&w[0]), scaled(&w[1]));
    let (_, ev0) = problem.residual(&u0, options).ok()?;
    let j0 = problem.jacobian(&u0, &ev0, options).ok()?;
    let t0 = tangent(&j0, &(&u1 - &u0))?;
    let scaled_value = value / o_sigma(options, which);
    let (u, ev) = on_hyperplane(problem, (&u0, &j0, &t0), n + which, scaled_value, options)?;
    Some(point(problem, &u, &ev, options, f64::NAN))
}

/// The curve's point where the scaled unknown `index` equals `value`: a step from `u0` along its tangent `t0`
/// to the hyperplane, corrected on it as the curve's own steps are (to the safe offset with `u0`'s matrix
/// `j0`, then polished with the new point's).
fn on_hyperplane<I: Clone + Send>(
    problem: &CurveProblem<'_, I>,
    (u0, j0, t0): (&DVector<f64>, &DMatrix<f64>, &DVector<f64>),
    index: usize,
    value: f64,
    options: &CurveOptions,
) -> Option<(DVector<f64>, Evaluation<I>)> {
    let s = (value - u0[index]) / t0[index];
    if !s.is_finite() {
        return None;
    }
    let mut u_pred = u0 + s * t0;
    u_pred[index] = value;
    let mut e = DVector::zeros(u0.len());
    e[index] = 1.0;
    let follow_offset = problem.offset * FOLLOW_OFFSET_FACTOR;
    let (u, ev, _) = problem
        .correct_at(&u_pred, &e, j0, options, follow_offset)
        .ok()?;
    let j = problem.jacobian(&u, &ev, options).ok()?;
    let (u, ev, _) = problem.correct(&u, &e, &j, options).ok()?;
    (u[index] == value).then_some((u, ev))
}
