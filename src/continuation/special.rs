//! Special points of a family (docs/model.md section 11): detected between two successive points by a sign
//! change of a test function, then located by solving for them.
//!
//! | label | what | test function `g` | located by |
//! |---|---|---|---|
//! | `LP` | fold (limit point): a multiplier `+1`, the family turns back in `p` | the tangent's `p` component (detection), `det(DP - I)` | Newton on `P(x) = x, g = 0` |
//! | `PD` | period doubling: a multiplier `-1` | `det(DP + I)` | Newton on `P(x) = x, g = 0` |
//! | `NS` | Neimark-Sacker: a complex pair on the unit circle | `prod_{i<j} (mu_i mu_j - 1)` (the bialternate product's determinant) | Newton on `P(x) = x, g = 0` |
//! | `BC` | border collision: a DLS indicator crosses zero | the indicator | Newton on `P(x) = x, g = 0` |
//! | `BC` | border collision: the event sequence changes without an indicator crossing | none smooth | bisection along the family |
//!
//! The extended systems have `n + 1` unknowns `z = (x, p / sigma)` and `n + 1` equations; the rows of
//! `P(x) - x` have the exact Jacobian `[DP - I, sigma dP/dp]`, the row of `g` central differences of `g` (step
//! [`LOCATE_FD_STEP`]), so the iteration converges to the zero of the exact residual even though its last row
//! is approximate. A point is located when the Newton step in `p` falls below the parameter tolerance with
//! `max |P(x) - x|` below ten times the corrector's tolerance; a point whose system does not converge within
//! [`MAX_LOCATE_ITERATIONS`], or converges outside its bracket, is reported as detected, with the bracket and
//! why, and not as located. A `NS` test that changes sign at a real pair with product one (a neutral saddle) is
//! not reported. At a border collision the multipliers on either side (`sides`) are those of `DP` at
//! [`SIDE_OFFSET`] along the family from the located point, or at the two ends of the final bisection bracket.

use nalgebra::{Complex, DMatrix, DVector};
use rayon::prelude::*;

use crate::meter::carried;
use serde::Serialize;

use super::corrector::{
    augmented, bordered, correct, multipliers, point_at, solve_on_hyperplane, split,
    ContinuationOptions, FamilyPoint,
};
use super::{Evaluation, FamilyMap};

/// Newton iterations allowed on an extended system.
pub const MAX_LOCATE_ITERATIONS: usize = 12;

/// Relative step of the central differences of a test function.
pub const LOCATE_FD_STEP: f64 = 1e-6;

/// Distance (in the scaled unknowns) from a border collision at which its one-sided multipliers are taken.
pub const SIDE_OFFSET: f64 = 1e-7;

/// Bisection steps allowed for an event-sequence change.
const MAX_BISECTIONS: usize = 80;

/// What kind of special point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum SpecialKind {
    /// Fold (`LP`).
    #[serde(rename = "LP")]
    Fold,
    /// Period doubling (`PD`).
    #[serde(rename = "PD")]
    PeriodDoubling,
    /// Neimark-Sacker (`NS`).
    #[serde(rename = "NS")]
    NeimarkSacker,
    /// Border collision (`BC`).
    #[serde(rename = "BC")]
    BorderCollision,
    /// Extremum of a monitored quantity (`EX`, [`super::monitor`]).
    #[serde(rename = "EX")]
    Extremum,
}

impl SpecialKind {
    /// The label: `LP`, `PD`, `NS`, `BC` or `EX`.
    pub fn label(&self) -> &'static str {
        match self {
            SpecialKind::Fold => "LP",
            SpecialKind::PeriodDoubling => "PD",
            SpecialKind::NeimarkSacker => "NS",
            SpecialKind::BorderCollision => "BC",
            SpecialKind::Extremum => "EX",
        }
    }
}

/// One side of a border collision.
#[derive(Debug, Clone, PartialEq)]
pub struct Side {
    /// The parameter where the side's multipliers were taken.
    pub param: f64,
    /// The piece of the map there (the VRW: the event sequence).
    pub piece: String,
    /// The multipliers there, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
}

/// A special point of a family.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecialPoint<I> {
    /// Its kind.
    pub kind: SpecialKind,
    /// The parameter (located, or interpolated in the bracket if not).
    pub param: f64,
    /// The state.
    pub x: DVector<f64>,
    /// Arclength along the family.
    pub arclength: f64,
    /// The parameters of the two family points it lies between.
    pub bracket: [f64; 2],
    /// Located by solving (false: only detected, see `note`).
    pub located: bool,
    /// How it was located.
    pub method: String,
    /// Newton iterations (or bisection steps).
    pub iterations: usize,
    /// `max |P(x) - x|` there.
    pub residual: f64,
    /// The test function there.
    pub test_value: f64,
    /// The multipliers there, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// For a border collision: the indicator that crosses zero, or `event sequence`.
    pub border: Option<String>,
    /// For a border collision: the two sides, in the order the family was followed.
    pub sides: Option<[Side; 2]>,
    /// What the map records of the point.
    pub info: Option<I>,
    /// Why it is not located, or what else is worth knowing.
    pub note: Option<String>,
    /// The direction the family was followed in at the point (unit, in the scaled unknowns).
    pub direction: DVector<f64>,
    /// The family ends here (a border collision past which no fixed point continues it).
    pub ends_family: bool,
    /// At a border collision where the family ends: how far the step map's images on the two sides of the
    /// border differ ([`JUMP_TOL`] and more: the map is discontinuous there); `NaN` otherwise.
    pub jump: f64,
}

impl std::fmt::Display for SpecialKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

/// The test function of `DP` whose zero is a special point of `kind` (`None` for a border collision or an
/// extremum).
pub fn test_function(kind: SpecialKind) -> Option<fn(&DMatrix<f64>) -> f64> {
    match kind {
        SpecialKind::Fold => Some(fold_test),
        SpecialKind::PeriodDoubling => Some(flip_test),
        SpecialKind::NeimarkSacker => Some(neimark_sacker_test),
        SpecialKind::BorderCollision | SpecialKind::Extremum => None,
    }
}

/// The name of [`test_function`]'s function, as `curves.csv`'s `border` column gives it.
pub fn test_name(kind: SpecialKind) -> &'static str {
    match kind {
        SpecialKind::Fold => "det(DP - I)",
        SpecialKind::PeriodDoubling => "det(DP + I)",
        SpecialKind::NeimarkSacker => "bialternate product",
        SpecialKind::BorderCollision => "border",
        SpecialKind::Extremum => "dq/ds",
    }
}

/// `det(DP - I)`.
fn fold_test(dp: &DMatrix<f64>) -> f64 {
    (dp - DMatrix::identity(dp.nrows(), dp.ncols())).determinant()
}

/// `det(DP + I)`.
fn flip_test(dp: &DMatrix<f64>) -> f64 {
    (dp + DMatrix::identity(dp.nrows(), dp.ncols())).determinant()
}

/// `prod_{i<j} (mu_i mu_j - 1)` over the eigenvalues of `DP` (real: complex pairs come conjugated); `NaN` for
/// a one-dimensional map.
fn neimark_sacker_test(dp: &DMatrix<f64>) -> f64 {
    let mu = multipliers(dp);
    if mu.len() < 2 {
        return f64::NAN;
    }
    let mut product = Complex::new(1.0, 0.0);
    for i in 0..mu.len() {
        for j in i + 1..mu.len() {
            product *= mu[i] * mu[j] - 1.0;
        }
    }
    product.re
}

/// Are `a` and `b` finite and of opposite signs?
fn crosses(a: f64, b: f64) -> bool {
    a.is_finite() && b.is_finite() && (a < 0.0) != (b < 0.0)
}

/// The special points between the successive family points `a` and `b` (see the module documentation).
pub(crate) fn detect_between<M: FamilyMap>(
    map: &M,
    a: &FamilyPoint<M::Info>,
    b: &FamilyPoint<M::Info>,
    options: &ContinuationOptions,
) -> Vec<SpecialPoint<M::Info>> {
    let mut found = smooth_points_between(map, a, b, options);
    let collisions = border_collisions_between(map, a, b, options);
    let border_crossed = !collisions.is_empty();
    found.extend(collisions);
    if !border_crossed && map.piece(&a.info) != map.piece(&b.info) {
        found.push(bisect_piece(map, a, b, options));
    }
    found.sort_by(|x, y| x.arclength.total_cmp(&y.arclength));
    found
}

/// A test function of `DP` for one kind of smooth special point, and whether it changes sign between two
/// family points.
struct SmoothTest<I> {
    /// The kind of special point at its zero.
    kind: SpecialKind,
    /// It changes sign between the two points (the fold: the tangent's `p` component does).
    detected: bool,
    /// The test function of an evaluation.
    test: fn(&Evaluation<I>) -> f64,
    /// The condition solved for, in words.
    condition: &'static str,
}

/// The folds, period doublings and Neimark-Sacker points between `a` and `b`, each detected by a sign change
/// of its test function (the table of the module documentation) and located by [`locate`].
fn smooth_points_between<M: FamilyMap>(
    map: &M,
    a: &FamilyPoint<M::Info>,
    b: &FamilyPoint<M::Info>,
    options: &ContinuationOptions,
) -> Vec<SpecialPoint<M::Info>> {
    let n = a.x.len();
    let mut found = Vec::new();
    let smooth: [SmoothTest<M::Info>; 3] = [
        SmoothTest {
            kind: SpecialKind::Fold,
            detected: crosses(a.tangent[n], b.tangent[n]),
            test: |ev| fold_test(&ev.jacobian),
            condition: "det(DP - I) = 0",
        },
        SmoothTest {
            kind: SpecialKind::PeriodDoubling,
            detected: crosses(flip_test(&a.jacobian), flip_test(&b.jacobian)),
            test: |ev| flip_test(&ev.jacobian),
            condition: "det(DP + I) = 0",
        },
        SmoothTest {
            kind: SpecialKind::NeimarkSacker,
            detected: crosses(
                neimark_sacker_test(&a.jacobian),
                neimark_sacker_test(&b.jacobian),
            ),
            test: |ev| neimark_sacker_test(&ev.jacobian),
            condition: "prod (mu_i mu_j - 1) = 0",
        },
    ];
    for SmoothTest {
        kind,
        detected,
        test,
        condition,
    } in smooth
    {
        if !detected {
            continue;
        }
        let ga = test(&as_evaluation(a));
        let gb = test(&as_evaluation(b));
        let mut sp = locate(map, a, b, (ga, gb), &test, options);
        sp.kind = kind;
        sp.method = format!("Newton on P(x) = x, {condition}: {}", sp.method);
        if kind == SpecialKind::NeimarkSacker
            && sp.located
            && !sp
                .multipliers
                .iter()
                .any(|m| m.im.abs() > 1e-8 && (m.norm() - 1.0).abs() < 1e-6)
        {
            // A real pair with product one: a neutral saddle, not a bifurcation.
            continue;
        }
        found.push(sp);
    }
    found
}

/// The border collisions between `a` and `b`: each border function of the map that changes sign between them,
/// its zero located by [`locate`], with the one-sided multipliers ([`sides`]).
fn border_collisions_between<M: FamilyMap>(
    map: &M,
    a: &FamilyPoint<M::Info>,
    b: &FamilyPoint<M::Info>,
    options: &ContinuationOptions,
) -> Vec<SpecialPoint<M::Info>> {
    let mut found = Vec::new();
    let (ba, bb) = (map.borders(&a.info), map.borders(&b.info));
    for (name, ga) in &ba {
        let Some((_, gb)) = bb.iter().find(|(other, _)| other == name) else {
            continue;
        };
        if !crosses(*ga, *gb) {
            continue;
        }
        let name = *name;
        let test = |ev: &Evaluation<M::Info>| map.border(&ev.info, name);
        let mut sp = locate(map, a, b, (*ga, *gb), &test, options);
        sp.kind = SpecialKind::BorderCollision;
        // DP does not exist on the border: the one-sided multipliers are in `sides`.
        sp.multipliers = Vec::new();
        sp.method = format!("Newton on P(x) = x, {name} = 0: {}", sp.method);
        sp.border = Some(name.to_string());
        sp.sides = sides(
            map,
            &(b.z(options.param_scale) - a.z(options.param_scale)),
            &sp,
            options,
        );
        found.push(sp);
    }
    found
}

/// A family point as an evaluation (for the test functions).
fn as_evaluation<I: Clone>(p: &FamilyPoint<I>) -> Evaluation<I> {
    Evaluation {
        value: p.x.clone(),
        jacobian: p.jacobian.clone(),
        dparam: p.dparam.clone(),
        exact: p.exact,
        info: p.info.clone(),
    }
}

/// The zero of `test` between `a` and `b` (values `g`) by Newton's method on the extended system (see the
/// module documentation).
fn locate<M: FamilyMap>(
    map: &M,
    a: &FamilyPoint<M::Info>,
    b: &FamilyPoint<M::Info>,
    g: (f64, f64),
    test: &(dyn Fn(&Evaluation<M::Info>) -> f64 + Sync),
    options: &ContinuationOptions,
) -> SpecialPoint<M::Info> {
    let sigma = options.param_scale;
    let (za, zb) = (a.z(sigma), b.z(sigma));
    let w = (g.0 / (g.0 - g.1)).clamp(0.0, 1.0);
    let z0 = &za + w * (&zb - &za);
    let (x0, p0) = split(&z0, sigma);
    let mut sp = SpecialPoint {
        kind: SpecialKind::Fold,
        param: p0,
        x: x0,
        arclength: a.arclength + w * (b.arclength - a.arclength),
        bracket: [a.param, b.param],
        located: false,
        method: String::new(),
        iterations: 0,
        residual: f64::NAN,
        test_value: f64::NAN,
        multipliers: Vec::new(),
        border: None,
        sides: None,
        info: None,
        note: None,
        direction: (&zb - &za).normalize(),
        ends_family: false,
        jump: f64::NAN,
    };
    match newton_extended(map, &z0, test, options) {
        Ok((z, ev, iterations)) => {
            let (x, p) = split(&z, sigma);
            // Converged, but to a zero outside the bracket (widened by its own length): not this one.
            let span = (&zb - &za).norm();
            if (&z - &za).norm() > 2.0 * span + 1e-9 || (&z - &zb).norm() > 2.0 * span + 1e-9 {
                sp.note = Some(format!(
                    "the extended system converged outside the bracket (p = {p}); detected only"
                ));
                sp.method = "not located".to_string();
                return sp;
            }
            sp.param = p;
            sp.residual = (&ev.value - &x).amax();
            sp.x = x;
            sp.test_value = test(&ev);
            sp.multipliers = multipliers(&ev.jacobian);
            sp.iterations = iterations;
            sp.located = true;
            sp.method = format!("{iterations} iterations");
            let wa = (&z - &za).norm() / span.max(f64::MIN_POSITIVE);
            sp.arclength = a.arclength + wa.min(1.0) * (b.arclength - a.arclength);
            sp.info = Some(ev.info);
        }
        Err(why) => {
            sp.note = Some(format!("not located: {why}"));
            sp.method = "not located".to_string();
        }
    }
    sp
}

/// A located zero: the unknowns, the evaluation there and the iterations.
type Located<I> = (DVector<f64>, Evaluation<I>, usize);

/// Newton's method on `P(x) = x, test = 0` from `z0`: the root, the evaluation there and the iterations.
fn newton_extended<M: FamilyMap>(
    map: &M,
    z0: &DVector<f64>,
    test: &(dyn Fn(&Evaluation<M::Info>) -> f64 + Sync),
    options: &ContinuationOptions,
) -> Result<Located<M::Info>, String> {
    let sigma = options.param_scale;
    let n = z0.len() - 1;
    let mut z = z0.clone();
    for iteration in 1..=MAX_LOCATE_ITERATIONS {
        let (x, p) = split(&z, sigma);
        let ev = map.eval(&x, p).map_err(|e| e.message)?;
        let h = &ev.value - &x;
        let g = test(&ev);
        if !g.is_finite() {
            return Err(format!("the test function is not defined at p = {p}"));
        }
        // Central differences of the test function in each unknown, on both cores (every one computed, the first
        // failure in order the error: the same work for any number of threads).
        let gradient: Vec<Result<f64, String>> = (0..=n)
            .into_par_iter()
            .map(carried(|i: usize| {
                let step = LOCATE_FD_STEP * z[i].abs().max(1.0);
                let at = |sign: f64| -> Result<f64, String> {
                    let mut zs = z.clone();
                    zs[i] += sign * step;
                    let (xs, ps) = split(&zs, sigma);
                    Ok(test(&map.eval(&xs, ps).map_err(|e| e.message)?))
                };
                Ok((at(1.0)? - at(-1.0)?) / (2.0 * step))
            }))
            .collect();
        let gradient = gradient.into_iter().collect::<Result<Vec<f64>, String>>()?;
        let m = bordered(
            &augmented(&ev.jacobian, &ev.dparam, sigma),
            &DVector::from_vec(gradient),
        );
        let residual = h.amax();
        let mut r = h.insert_row(n, g);
        r.neg_mut();
        let dz = m
            .lu()
            .solve(&r)
            .ok_or_else(|| format!("singular extended system at p = {p}"))?;
        z += &dz;
        if (dz[n] * sigma).abs() < options.param_tolerance * p.abs().max(1.0)
            && residual < 10.0 * options.tolerance
        {
            let (x, p) = split(&z, sigma);
            let ev = map.eval(&x, p).map_err(|e| e.message)?;
            return Ok((z, ev, iteration));
        }
    }
    Err(format!(
        "the extended system did not converge in {MAX_LOCATE_ITERATIONS} iterations"
    ))
}

/// The multipliers of `DP` at [`SIDE_OFFSET`] before and after the located border collision `sp`, along the
/// direction `d` in the scaled unknowns.
fn sides<M: FamilyMap>(
    map: &M,
    d: &DVector<f64>,
    sp: &SpecialPoint<M::Info>,
    options: &ContinuationOptions,
) -> Option<[Side; 2]> {
    if !sp.located {
        return None;
    }
    let sigma = options.param_scale;
    let n = sp.x.len();
    let z = DVector::from_fn(n + 1, |i, _| if i < n { sp.x[i] } else { sp.param / sigma });
    let d = d.normalize();
    let side = |sign: f64| -> Option<Side> {
        let (x, p) = split(&(&z + sign * SIDE_OFFSET * &d), sigma);
        let ev = map.eval(&x, p).ok()?;
        Some(Side {
            param: p,
            piece: map.piece(&ev.info),
            multipliers: multipliers(&ev.jacobian),
        })
    };
    Some([side(-1.0)?, side(1.0)?])
}

/// Images of the two sides of a border (at [`SIDE_OFFSET`]) that differ by more than this show a jump of the
/// step map.
pub const JUMP_TOL: f64 = 1e-5;

/// How far (in the scaled unknowns) from a family's last point a border at which the family ends may lie.
pub const END_BORDER_REACH: f64 = 1e-3;

/// Where a family ends without a failure of its map (the corrector fails at every step length just past its
/// last point `last`, after `previous`): a border collision at which no fixed point continues the family on
/// the other side. Each border function whose zero, extrapolated linearly from `previous` and `last`, lies
/// ahead within [`END_BORDER_REACH`] is solved for along the family ([`approach_border`]); the nearest zero
/// is the end, with the one-sided multipliers along the family's tangent.
pub(crate) fn border_at_end<M: FamilyMap>(
    map: &M,
    previous: Option<&FamilyPoint<M::Info>>,
    last: &FamilyPoint<M::Info>,
    options: &ContinuationOptions,
) -> Option<SpecialPoint<M::Info>> {
    let sigma = options.param_scale;
    let z_last = last.z(sigma);
    let mut best: Option<(f64, SpecialPoint<M::Info>)> = None;
    let before = previous.map(|p| map.borders(&p.info)).unwrap_or_default();
    for (name, g) in map.borders(&last.info) {
        if !g.is_finite() {
            continue;
        }
        // Only a border the family is heading for.
        if let (Some(prev), Some((_, g_prev))) =
            (previous, before.iter().find(|(other, _)| *other == name))
        {
            let ds = (&z_last - prev.z(sigma)).norm();
            let ahead = g * ds / (g_prev - g);
            if !(ahead.is_finite() && ahead >= 0.0 && ahead <= END_BORDER_REACH.max(2.0 * ds)) {
                continue;
            }
        }
        let Some((point, iterations)) = approach_border(map, previous, last, name, options) else {
            continue;
        };
        let z = point.z(sigma);
        let distance = (&z - &z_last).norm();
        if distance > END_BORDER_REACH || best.as_ref().is_some_and(|(d, _)| *d <= distance) {
            continue;
        }
        let (x, p) = split(&z, sigma);
        let mut sp = SpecialPoint {
            kind: SpecialKind::BorderCollision,
            param: p,
            residual: point.residual,
            x,
            arclength: last.arclength + distance,
            bracket: [last.param, p],
            located: true,
            method: format!(
                "secant along the family on {name} from its last point: {iterations} iterations"
            ),
            iterations,
            test_value: map.border(&point.info, name),
            // DP does not exist on the border: the one-sided multipliers are in `sides`.
            multipliers: Vec::new(),
            border: Some(name.to_string()),
            sides: None,
            info: Some(point.info),
            note: None,
            direction: last.tangent.normalize(),
            ends_family: true,
            jump: f64::NAN,
        };
        sp.sides = sides(map, &last.tangent, &sp, options);
        let jump = jump_across(map, &z, &last.tangent, sigma);
        sp.jump = jump;
        sp.note = Some(end_note(jump));
        best = Some((distance, sp));
    }
    best.map(|(_, sp)| sp)
}

/// The map at the border point `z`: continuous (a nonsmooth fold: no fixed point of the other piece nearby) or
/// not (the other piece's image jumps away); how far its images at [`SIDE_OFFSET`] on either side along
/// `tangent` differ (`NaN` where either fails).
fn jump_across<M: FamilyMap>(map: &M, z: &DVector<f64>, tangent: &DVector<f64>, sigma: f64) -> f64 {
    let d = tangent.normalize();
    let at = |sign: f64| {
        let (xs, ps) = split(&(z + sign * SIDE_OFFSET * &d), sigma);
        map.value(&xs, ps).ok()
    };
    match (at(-1.0), at(1.0)) {
        (Some(a), Some(b)) => (a - b).amax(),
        _ => f64::NAN,
    }
}

/// The note of a family's end at a border across which the step map jumps by `jump` ([`JUMP_TOL`] and more: a
/// discontinuity).
fn end_note(jump: f64) -> String {
    if jump > JUMP_TOL {
        format!(
            "the family ends here: the step map jumps by {jump:.3e} across the border, and no fixed point \
             continues the family on the other side"
        )
    } else {
        format!(
            "the family ends here: the step map is continuous across the border (jump {jump:.1e}) but no \
             fixed point continues the family on the other side"
        )
    }
}

/// The zero of the border function `name` ahead of the family's last point `last`, approached along the
/// family from its side: secant steps in the arclength `s` along `last`'s tangent, each trial corrected onto
/// the family (on the hyperplane normal to the tangent, with `last`'s matrix held); a trial whose corrector
/// fails lies past the border (the family does not continue there) and is halved back toward the last point
/// that worked. Stops when successive points differ by less than the parameter tolerance in `p` and
/// `1e-9` in the state; the point nearest the border and the iterations.
fn approach_border<M: FamilyMap>(
    map: &M,
    previous: Option<&FamilyPoint<M::Info>>,
    last: &FamilyPoint<M::Info>,
    name: &str,
    options: &ContinuationOptions,
) -> Option<(FamilyPoint<M::Info>, usize)> {
    let sigma = options.param_scale;
    let z0 = last.z(sigma);
    let t = &last.tangent;
    let g = |p: &FamilyPoint<M::Info>| map.border(&p.info, name);
    let m = bordered(&augmented(&last.jacobian, &last.dparam, sigma), t);
    let at = |s: f64| -> Option<FamilyPoint<M::Info>> {
        let (z, _) = correct(map, &(&z0 + s * t), t, &m, options).ok()?;
        point_at(map, &z, t, options).ok()
    };
    // Two points on this side: the last, and the previous (or one just behind the last).
    let behind = match previous {
        Some(p) => (t.dot(&(p.z(sigma) - &z0)), g(p)),
        None => {
            let s = -SIDE_OFFSET * 10.0;
            (s, g(&at(s)?))
        }
    };
    let (mut s_a, mut g_a, mut best) = (0.0, g(last), last.clone());
    let (mut s_b, mut g_b) = behind;
    let tol = options.param_tolerance * last.param.abs().max(1.0);
    for iteration in 1..=MAX_APPROACH_ITERATIONS {
        if !(g_a.is_finite() && g_b.is_finite()) || g_a == g_b {
            return None;
        }
        let mut s_new = s_a - g_a * (s_a - s_b) / (g_a - g_b);
        if !(s_new.is_finite() && s_new >= s_b.min(0.0) && s_new <= END_BORDER_REACH) {
            return None;
        }
        let mut point = None;
        for _ in 0..MAX_APPROACH_HALVINGS {
            if let Some(p) = at(s_new) {
                point = Some(p);
                break;
            }
            s_new = 0.5 * (s_a + s_new);
        }
        let point = point?;
        let converged =
            (point.param - best.param).abs() < tol && (&point.x - &best.x).amax() < 1e-9;
        (s_b, g_b) = (s_a, g_a);
        (s_a, g_a) = (s_new, g(&point));
        best = point;
        if converged {
            return Some((best, iteration));
        }
    }
    None
}

/// Secant steps allowed to approach a border at a family's end.
const MAX_APPROACH_ITERATIONS: usize = 60;

/// Halvings of a secant step that lands past the border.
const MAX_APPROACH_HALVINGS: usize = 40;

/// The change of piece between `a` and `b` bracketed by bisection along the family: each midpoint of the
/// bracket corrected onto the family on the hyperplane through it normal to the bracket (the chord method with
/// the matrix of the bracket's end on the old piece, else Newton's method with `DP` at every iterate), until the bracket's
/// parameter width is below the parameter tolerance and its state width below `1e-9`.
fn bisect_piece<M: FamilyMap>(
    map: &M,
    a: &FamilyPoint<M::Info>,
    b: &FamilyPoint<M::Info>,
    options: &ContinuationOptions,
) -> SpecialPoint<M::Info> {
    let sigma = options.param_scale;
    let piece_a = map.piece(&a.info);
    let (mut lo, mut hi) = (a.clone(), b.clone());
    let mut steps = 0;
    let mut note = None;
    while steps < MAX_BISECTIONS {
        let (zl, zh) = (lo.z(sigma), hi.z(sigma));
        let width_p = (hi.param - lo.param).abs();
        if width_p < options.param_tolerance && (&zh - &zl).amax() < 1e-9 {
            break;
        }
        steps += 1;
        let mid = (&zl + &zh) * 0.5;
        let d = (&zh - &zl).normalize();
        let m = bordered(&augmented(&lo.jacobian, &lo.dparam, sigma), &d);
        // With the matrix of the bracket's end on the old piece, or (where `DP` jumps across the border and
        // that fails) with the midpoint's own.
        let point = correct(map, &mid, &d, &m, options)
            .map(|(z, _)| z)
            .or_else(|_| solve_on_hyperplane(map, &mid, &d, options))
            .and_then(|z| point_at(map, &z, &lo.tangent, options));
        match point {
            Ok(point) if map.piece(&point.info) == piece_a => lo = point,
            Ok(point) => hi = point,
            Err(e) => {
                note = Some(format!(
                    "the bisection stopped after {steps} steps, the bracket [{}, {}] holding no fixed point \
                     at its middle ({}): the family may jump across this border (a discontinuity of the step \
                     map)",
                    lo.param, hi.param, e.message
                ));
                break;
            }
        }
    }
    let located = note.is_none() && steps < MAX_BISECTIONS;
    // No fixed point at a midpoint: the family does not pass this border continuously.
    let ends_family = note.is_some();
    let side = |p: &FamilyPoint<M::Info>| Side {
        param: p.param,
        piece: map.piece(&p.info),
        multipliers: p.multipliers.clone(),
    };
    SpecialPoint {
        kind: SpecialKind::BorderCollision,
        param: 0.5 * (lo.param + hi.param),
        x: (&lo.x + &hi.x) * 0.5,
        arclength: a.arclength
            + (lo.z(sigma) - a.z(sigma))
                .norm()
                .min(b.arclength - a.arclength),
        bracket: [a.param, b.param],
        located,
        method: format!("bisection along the family: {steps} steps"),
        iterations: steps,
        residual: lo.residual.max(hi.residual),
        test_value: f64::NAN,
        multipliers: lo.multipliers.clone(),
        border: Some("event sequence".to_string()),
        sides: Some([side(&lo), side(&hi)]),
        info: Some(lo.info.clone()),
        note,
        direction: (hi.z(sigma) - lo.z(sigma)).normalize(),
        ends_family,
        jump: f64::NAN,
    }
}
