//! Natural-parameter continuation of a gait family, verified from both sides, and the physical cause where a
//! family ends (docs/model.md section 6).
//!
//! A continuation step from the gait `s0` at `v0` to `v1` is accepted only if Newton's method from `s0` converges
//! at `v1` to some `s1` **and** Newton's method from `s1` back at `v0` returns to `s0` (within `SAME_GAIT_TOL`).
//! The second condition is what keeps a step from silently jumping to another gait family (two gaits coexist,
//! or the family folds between `v0` and `v1`): a jump is not reversible. The way back is answered after one
//! Newton step where that step lands within `EARLY_RETURN_TOL` of `s0` (`NaturalContinuation::first_newton_step`).
//! A step that fails is halved (and the step after a failure that works halves the next, which bisects toward
//! an end), so a family is followed in shrinking steps until it is reached or its end is bracketed to
//! `PARAM_TOL`; where the wheel is about to roll back at the end, or a DLS indicator vanishes there, the end is
//! extrapolated instead (`end_search.rs`). Where Newton's method fails at the finest step, or
//! `WALK_AFTER_FAILURES` times in a row (and every `WALK_AFTER_FAILURES` failures after that), steps are also
//! tried by walking instead (`NaturalContinuation::walk_step`), since the step map is only piecewise smooth. A family
//! of period-k gaits is followed the same way, as fixed points of `P^k` (`NaturalContinuation::with_period`).
//!
//! **Predictor.** Each step starts Newton's method from the gait carried along the family's tangent `ds*/dp`
//! (`Tangent`): given with the first point (`-(DP - I)^-1 dP/dp` from its exact derivatives), then the secant
//! of the last verified step. The start is then `O(dp^2)` from the gait instead of `O(dp)`, which saves Newton
//! iterations there and back; a step whose predicted start fails is tried again from the point itself: at the
//! finest step, whose failure ends the family, with Newton's method damped to the end as without a predictor;
//! on a longer step as a quick test (the step is halved if it fails). Period-1 families only (see
//! `NaturalContinuation::step_predicted`).
//!
//! Where a family ends, the cause is looked for just past the end: the wheel is walked from the last gait of the
//! family at the first parameter value it does not reach (`END_WALK_STEPS` steps). The walk fails (falls,
//! rolls back, stalls, the rear leg is not relocked, ...), settles on another gait of any period up to
//! [`MAX_PERIOD`] (a branch switch), or does neither, in which case the end is reported as unconfirmed. Newton's
//! method failing from a neighbour is never by itself taken for "no gait".

use nalgebra::DMatrix;
use serde::Serialize;

use super::end_search::{gauges, EndSearch, Gauges};
use super::Parameter;
use crate::gait::derivative::newton_jacobian;
use crate::gait::limit_cycle::{
    solve_fixed_point, solve_fixed_point_asking, FixedPoint, GaitError, GaitOptions,
};
pub(crate) use crate::gait::periodicity::SAME_GAIT_TOL;
use crate::gait::periodicity::{least_period, MAX_PERIOD, RETURN_TOL};
use crate::gait::step_map::StepMap;
use crate::params::ConfigError;
use crate::walk::{SectionState, Walker, SECTION_COORDINATES};

/// The way back of a continuation step ends early where the first step of Newton's method lands this close to
/// the gait the step came from (`NaturalContinuation::first_newton_step`): a tenth of [`SAME_GAIT_TOL`].
const EARLY_RETURN_TOL: f64 = 1e-7;

/// Tolerance of every threshold in the swept parameter.
pub(crate) const PARAM_TOL: f64 = 1e-6;

/// Newton iterations allowed in one continuation step (a step that needs more is halved instead).
pub(crate) const STEP_NEWTON_ITERATIONS: usize = 8;

/// Steps a walk may take to settle on a gait in a continuation step by walking.
pub(crate) const SETTLE_STEPS: usize = 200;

/// Most steps one [`NaturalContinuation::follow`] may try by walking (each walks up to twice [`SETTLE_STEPS`] steps):
/// where only walking carries the family on, it is given up after these, as after [`MAX_FOLLOW_STEPS`].
pub(crate) const MAX_FOLLOW_WALKS: usize = 60;

/// A walk has settled when two successive section states differ by less than this.
pub(crate) const SETTLE_TOL: f64 = 1e-11;
/// Most continuation steps (verified or failed) one [`NaturalContinuation::follow`] may try. Following a family to a
/// neighbouring value, or to its end bracketed to [`PARAM_TOL`], takes a few dozen; approaching an end where
/// the steps Newton's method takes shrink with the distance to it (the wheel about to roll back, e.g. at
/// `k = 761.311033 N/m` for `c = 50`) takes about four steps per halving, 100 to 150 from a grid interval of
/// 20; a family that only advances in ever tinier steps without end is given up rather than followed for
/// hours.
pub(crate) const MAX_FOLLOW_STEPS: usize = 200;

/// After Newton's method fails this many continuation steps in a row (each half the one before), steps are
/// also tried by walking ([`NaturalContinuation::walk_step`]): near a border of the map's smooth pieces (a DLS
/// indicator near zero) the map's pieces differ across the border and Newton's method fails at every step
/// length, while the walk follows the stable gait.
///
/// While walking has not yet carried the family on, a walk that fails is tried again only after as many more
/// Newton failures (each halving the step): most ends (the wheel rolls back, a fold) cannot be walked past
/// either, and a walk per bisection step was a fifth of a map's evaluations.
pub(crate) const WALK_AFTER_FAILURES: usize = 3;

/// A real Floquet multiplier this close to +1 at the last gait of a family marks a fold.
pub(crate) const FOLD_TOL: f64 = 0.05;

/// Steps walked from the last gait of a family just past its end, looking for the physical cause.
pub(crate) const END_WALK_STEPS: usize = 300;

/// Largest coordinate difference between two section states: [`SectionState::distance`], kept under this
/// name for callers outside the crate.
pub fn section_distance(a: &SectionState, b: &SectionState) -> f64 {
    a.distance(b)
}

/// Follows gait families of one configuration along one parameter: fixed points of the step map `P`, or of
/// `P^k` for a family of period-k gaits ([`NaturalContinuation::with_period`]).
#[derive(Debug, Clone)]
pub(crate) struct NaturalContinuation<'a> {
    parameter: Parameter<'a>,
    options: GaitOptions,
    /// Steps per period of the family followed (1: fixed points of `P`).
    period: usize,
}

/// The gait `from` of a family in `parameter` as a start at `value` (see `NaturalContinuation::start_from`):
/// its section state, or, where the parameter is `min_length` and Leg 2 is held at its compression stop there,
/// the state held at the stop of `value`.
pub(crate) fn carried_start(parameter: &Parameter, from: &GaitPoint, value: f64) -> SectionState {
    if parameter.key() != "min_length" {
        return from.section;
    }
    match parameter.at(from.value) {
        Ok(at) if from.section.rear_held_under(&at.config.params) => SectionState {
            l2: value,
            l2_dot: 0.0,
            ..from.section
        },
        _ => from.section,
    }
}

/// Why Newton's method found no gait of a family at a parameter value.
#[derive(Debug, thiserror::Error)]
pub(crate) enum PointError {
    /// The value leaves the parameter's valid domain.
    #[error(transparent)]
    InvalidParameter(#[from] ConfigError),
    /// The search failed.
    #[error(transparent)]
    Gait(#[from] GaitError),
}

/// A point of a family: the parameter value and the gait's section state there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaitPoint {
    /// The parameter value.
    pub value: f64,
    /// The fixed point of the step map.
    pub section: SectionState,
}

/// The tangent `ds*/dp` of a family at the parameter value `at`, over the section coordinates `[L2,
/// dtheta/dt, dL2/dt, slip]` ([`crate::walk::SECTION_COORDINATES`]): the predictor of the next step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Tangent {
    /// Where it holds.
    pub(crate) at: f64,
    /// `ds*/dp` per coordinate.
    pub(crate) rates: [f64; SECTION_COORDINATES.len()],
}

impl Tangent {
    /// The secant of a verified step from `a` to `b`, or `None` where the two sections differ in kind (one
    /// slips and the other does not: the coordinates do not carry over).
    fn secant(a: &GaitPoint, b: &GaitPoint) -> Option<Tangent> {
        let dp = b.value - a.value;
        (a.section.slips() == b.section.slips() && dp != 0.0).then(|| Tangent {
            at: b.value,
            rates: std::array::from_fn(|i| {
                (b.section.coordinate(i) - a.section.coordinate(i)) / dp
            }),
        })
    }

    /// The start at `value` predicted from `from` (where the tangent holds, and the state stays of its kind:
    /// a tip at rest is not set slipping); `None` elsewhere.
    fn predict(&self, from: &GaitPoint, value: f64) -> Option<SectionState> {
        if self.at != from.value {
            return None;
        }
        let dp = value - from.value;
        let moved = (0..4).fold(from.section, |s, i| {
            let rate = if i == 3 && !from.section.slips() {
                0.0
            } else {
                self.rates[i]
            };
            s.with_coordinate(i, s.coordinate(i) + rate * dp)
        });
        // A slip that would change its sign (a border of the map) is not predicted.
        let kept = moved.slip.signum() == from.section.slip.signum();
        (kept && self.rates.iter().all(|r| r.is_finite())).then_some(moved)
    }
}

/// Where following a family led.
#[derive(Debug, Clone, PartialEq)]
pub enum FollowOutcome {
    /// The family reaches the target value.
    Reached(GaitPoint),
    /// The family ends between `last.value` and `beyond` (`|beyond - last.value| <= PARAM_TOL`, or the
    /// tolerance the coarse pass of a sweep gives, one grid interval).
    Ended {
        /// The last point of the family.
        last: GaitPoint,
        /// The first value it does not reach.
        beyond: f64,
    },
    /// Neither within `MAX_FOLLOW_STEPS` steps (or `MAX_FOLLOW_WALKS` walking steps): the family was
    /// followed to `last` and given up there.
    GaveUp {
        /// The last point of the family reached.
        last: GaitPoint,
        /// The value being followed to.
        target: f64,
    },
}

/// A verified continuation step: the gait reached, and its [`Gauges`] where the family is of period 1 (what
/// its end is extrapolated from: [`EndSearch`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Verified {
    point: GaitPoint,
    gauges: Option<Gauges>,
}

/// Why a continuation step failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum StepFailure {
    /// The walk from the start fails at the new value: no Newton matrix would help.
    Start,
    /// Newton's method failed (there or back), or came back to another gait.
    Newton,
}

/// What happens just past the end of a family.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum EndCause {
    /// The walk from the family's last gait fails: `failure` is its kind (`rolled_back`, `fell`, ...).
    WalkFails {
        /// Failure kind.
        failure: String,
        /// The failure in words, with the step it happened in.
        message: String,
    },
    /// The walk settles on another gait (a branch switch), possibly of another period.
    OtherGait {
        /// Steps walked before the search that found it.
        steps: usize,
        /// The other gait's section state.
        section: SectionState,
        /// Its `lambda_I4` \[N s\].
        lambda_i4: f64,
        /// Its period in steps (1 for a fixed point of `P`).
        period_k: usize,
    },
    /// The family folds: the largest Floquet multiplier of its last gait is within `FOLD_TOL` (0.05) of +1 (a
    /// saddle-node, where the gait meets an unstable one and both vanish), and the walk drifts slowly.
    Fold {
        /// The multiplier closest to +1.
        multiplier: f64,
    },
    /// The walk neither fails nor settles on a period-1 gait: nothing physical was found.
    Unconfirmed {
        /// Why.
        reason: String,
    },
}

impl<'a> NaturalContinuation<'a> {
    /// NaturalContinuation in `parameter`, with Newton settings from `options`.
    pub(crate) fn new(parameter: Parameter<'a>, options: &GaitOptions) -> NaturalContinuation<'a> {
        NaturalContinuation {
            parameter,
            options: GaitOptions {
                transient_steps: 0,
                refine_jacobian: false,
                max_iterations: STEP_NEWTON_ITERATIONS.min(options.max_iterations),
                ..*options
            },
            period: 1,
        }
    }

    /// The same continuation for a family of period-`k` gaits: fixed points of `P^k` (`k = 0` is taken as 1).
    pub(crate) fn with_period(self, k: usize) -> NaturalContinuation<'a> {
        NaturalContinuation {
            period: k.max(1),
            ..self
        }
    }

    /// The gait `from` of the family as a start at `value`: its section state, except that where the followed
    /// parameter is `min_length` and Leg 2 is held at its compression stop there, it is held at the stop of
    /// `value` (`L2 = value`, `dL2/dt = 0`): the stop moves with the parameter and the held leg with it (the
    /// section state at the old stop would be below the new one, or off it).
    fn start_from(&self, from: &GaitPoint, value: f64) -> SectionState {
        carried_start(&self.parameter, from, value)
    }

    /// The fixed point at `value` by Newton's method from `start` (no transient), the Newton matrix's guess
    /// asked of `guess` once the map is evaluated at the start ([`solve_fixed_point_asking`]).
    pub(crate) fn solve(
        &self,
        value: f64,
        start: &SectionState,
        guess: &mut dyn FnMut() -> Option<DMatrix<f64>>,
        undamped: bool,
    ) -> Result<FixedPoint, PointError> {
        let at = self.parameter.at(value)?;
        let map = at.step_map().iterated(self.period);
        Ok(solve_fixed_point_asking(
            &map,
            start,
            &self.options,
            guess,
            undamped,
        )?)
    }

    /// One verified continuation step from `from` to `value` by Newton's method, there and back (see the module
    /// documentation).
    pub(crate) fn step(
        &self,
        from: &GaitPoint,
        value: f64,
        guess: Option<&DMatrix<f64>>,
    ) -> Option<GaitPoint> {
        self.step_asking(from, value, guess, false)
            .ok()
            .map(|v| v.point)
    }

    /// [`NaturalContinuation::step_asking`] from the start `tangent` predicts (see the module documentation), and
    /// from the plain start where that fails or no prediction is made. `undamped` as for
    /// [`NaturalContinuation::step_asking`]; `finest`: the step is the shortest [`NaturalContinuation::follow_to`] takes (its
    /// failure would end the family).
    fn step_predicted(
        &self,
        from: &GaitPoint,
        value: f64,
        (guess, tangent): (Option<&DMatrix<f64>>, Option<&Tangent>),
        (undamped, finest): (bool, bool),
    ) -> Result<Verified, StepFailure> {
        // `min_length` moves a held state with the parameter itself (`carried_start`): no predictor there. Nor
        // for a period-k family: its fixed points of `P^k` include the period-1 gait where the period-k orbit
        // collapses onto it (a bounce that vanishes at `lambda_2+ = 0`), and a predicted start carries the
        // family through that border, so that the change of period would go unreported.
        let tangent = tangent.filter(|_| self.parameter.key() != "min_length" && self.period == 1);
        let predicted = tangent.and_then(|t| {
            let start = t.predict(from, value)?;
            let back = Tangent { at: value, ..*t };
            Some((start, back))
        });
        let mut plain_undamped = undamped;
        if let Some((start, back)) = predicted {
            let step = self.step_from(from, value, (guess, undamped), (start, Some(&back)));
            if step.is_ok() {
                return step;
            }
            // Where a longer step's prediction fails, its plain start is a quick test (`undamped`): the step
            // is halved anyway if it fails, and the halves start closer to the family. Damped to the end, the
            // plain starts after a failed prediction cost 9.8 evaluations each and worked for none of 175 on
            // ten rows of the 100 x 100 map (a quarter of their evaluations). Skipping them would lose steps:
            // on the default map's row `k = 1500` only a plain start 15 N s/m long carries the family across
            // `lambda_2+ = 0` to two more grid points, which shorter steps cannot reach. The quick test keeps
            // that crossing, and every gait of the default and the 100 x 100 maps, but a crossing that needs
            // damping would be lost. At the finest step, whose failure ends the family, the plain start is
            // damped as before.
            plain_undamped = undamped || !finest;
        }
        self.step_asking(from, value, guess, plain_undamped)
    }

    /// [`NaturalContinuation::step`], failing with [`StepFailure::Start`] where the walk from `from`'s gait at `value`
    /// fails (whatever the Newton matrix), else with [`StepFailure::Newton`]; `undamped`: Newton's method fails
    /// as soon as it must damp a step taken with `DP` at its iterate ([`solve_fixed_point_asking`]).
    fn step_asking(
        &self,
        from: &GaitPoint,
        value: f64,
        guess: Option<&DMatrix<f64>>,
        undamped: bool,
    ) -> Result<Verified, StepFailure> {
        let start = self.start_from(from, value);
        self.step_from(from, value, (guess, undamped), (start, None))
    }

    /// One verified step from `from` to `value` with Newton's method started at `start`, and on the way back at
    /// the start `back` predicts from the point reached (else that point itself).
    fn step_from(
        &self,
        from: &GaitPoint,
        value: f64,
        (guess, undamped): (Option<&DMatrix<f64>>, bool),
        (start, back): (SectionState, Option<&Tangent>),
    ) -> Result<Verified, StepFailure> {
        // Newton's method asks for its matrix once the map is evaluated at the start.
        let mut started = false;
        let forward = self.solve(
            value,
            &start,
            &mut || {
                started = true;
                guess.cloned()
            },
            undamped,
        );
        let forward = forward.map_err(|_| {
            if started {
                StepFailure::Newton
            } else {
                StepFailure::Start
            }
        })?;
        let reached = GaitPoint {
            value,
            section: forward.section,
        };
        let verified = Verified {
            point: reached,
            gauges: (self.period == 1).then(|| gauges(&forward.outcome.report)),
        };
        let back_start = back
            .and_then(|t| t.predict(&reached, from.value))
            .unwrap_or_else(|| self.start_from(&reached, from.value));
        if self
            .first_newton_step(from.value, &back_start, guess)
            .is_some_and(|landing| landing.distance(&from.section) <= EARLY_RETURN_TOL)
        {
            return Ok(verified);
        }
        let back = self
            .solve(from.value, &back_start, &mut || guess.cloned(), undamped)
            .map_err(|_| StepFailure::Newton)?;
        if back.section.distance(&from.section) <= SAME_GAIT_TOL {
            Ok(verified)
        } else {
            Err(StepFailure::Newton)
        }
    }

    /// Where the first step of Newton's method from `start` at `value` lands with the Newton matrix `guess - I`
    /// (`start` itself where its residual is already below the tolerance), for the way back of a continuation
    /// step: landing within [`EARLY_RETURN_TOL`] of the gait the step came from, Newton's method is on its way
    /// to that gait (a known fixed point there, and the landing far closer to it than the distance between two
    /// gaits the check tells apart, [`SAME_GAIT_TOL`]), so the rest of its iterations (one evaluation of the map
    /// each, to confirm a convergence already shown) are not taken. `None` without a matrix of the map's size or
    /// where the walk fails (the full solve then decides).
    fn first_newton_step(
        &self,
        value: f64,
        start: &SectionState,
        guess: Option<&DMatrix<f64>>,
    ) -> Option<SectionState> {
        let at = self.parameter.at(value).ok()?;
        let map = at.step_map().iterated(self.period).on_section_of(start);
        let n = map.free_coordinates().len();
        let guess = guess.filter(|g| g.nrows() == n && g.ncols() == n)?;
        let x = map.reduce(start);
        let r = map.reduce(&map.eval(start).ok()?.next) - &x;
        if r.amax() < self.options.tolerance {
            return Some(*start);
        }
        let delta = (guess - DMatrix::identity(n, n)).lu().solve(&(-r))?;
        Some(map.expand(start, &(x + delta)))
    }

    /// The same step by walking, where Newton's method fails (the step map is only piecewise smooth): the wheel
    /// walked from the gait at `value` settles on a gait, and walked from that one at `from.value` comes back to
    /// `from` (a stable family followed the way an experiment would).
    pub(crate) fn walk_step(&self, from: &GaitPoint, value: f64) -> Option<GaitPoint> {
        let forward = self.settle(value, &self.start_from(from, value))?;
        let reached = GaitPoint {
            value,
            section: forward,
        };
        let back = self.settle(from.value, &self.start_from(&reached, from.value))?;
        (back.distance(&from.section) <= SAME_GAIT_TOL).then_some(GaitPoint {
            value,
            section: forward,
        })
    }

    /// The section state a walk at `value` from `start` settles on: successive returns (every `k` steps for a
    /// period-k family) closer than [`SETTLE_TOL`] within [`SETTLE_STEPS`] steps; `None` if the walk fails or
    /// does not settle.
    fn settle(&self, value: f64, start: &SectionState) -> Option<SectionState> {
        let at = self.parameter.at(value).ok()?;
        let mut walker = Walker::new(&at.model, &at.config.solver, start).ok()?;
        let mut previous = *start;
        for _ in 0..SETTLE_STEPS.div_ceil(self.period) {
            for _ in 0..self.period {
                walker.step(None).ok()?;
            }
            let next = walker.section().ok()?;
            if next.distance(&previous) < SETTLE_TOL {
                return Some(next);
            }
            previous = next;
        }
        None
    }

    /// `DP` (`D(P^k)` for a period-k family; exact, or a central difference where the map is not
    /// differentiable) of the gait `at`.
    fn jacobian(&self, at: &GaitPoint) -> Option<DMatrix<f64>> {
        let point = self.parameter.at(at.value).ok()?;
        // On the section of `at` where its stance tip slips (Coulomb friction): the slip is a coordinate there.
        let map = point
            .step_map()
            .iterated(self.period)
            .with_slip(at.section.slips());
        newton_jacobian(&map, &at.section, self.options.fd_step).ok()
    }

    /// Follow the family of `from` to `target` in verified steps, until the target is reached or the family's
    /// end is bracketed to [`PARAM_TOL`]. `known` is what is known at `from`: `DP` and the family's [`Tangent`]
    /// (the predictor of the first step). A step whose Newton's method fails
    /// is retried once with `DP` recomputed at the current point (if the Newton matrix was computed elsewhere;
    /// not a step whose walk fails at its start, where no matrix helps), a retry that fails as soon as it must
    /// damp a Newton step taken with `DP` at its iterate, then halved; a
    /// step that works lets the next one double, or halve right after a failure (bisecting toward the end),
    /// unless the end is extrapolated from the gaits' smallest `dtheta/dt` or DLS indicators ([`EndSearch`]).
    /// At most [`MAX_FOLLOW_STEPS`] steps, [`MAX_FOLLOW_WALKS`] of them by walking, are tried
    /// ([`FollowOutcome::GaveUp`]).
    pub(crate) fn follow(
        &self,
        from: GaitPoint,
        target: f64,
        known: (Option<&DMatrix<f64>>, Option<Tangent>),
    ) -> FollowOutcome {
        self.follow_to(from, target, known, PARAM_TOL)
    }

    /// [`NaturalContinuation::follow`] with the family's end bracketed to `end_tol` instead of [`PARAM_TOL`] (the
    /// coarse pass of a split row needs it only to a grid interval), and the family's tangent at `from` if
    /// known (the predictor of the first step; the secant of the last verified step after that).
    pub(crate) fn follow_to(
        &self,
        from: GaitPoint,
        target: f64,
        (guess, tangent): (Option<&DMatrix<f64>>, Option<Tangent>),
        end_tol: f64,
    ) -> FollowOutcome {
        let mut tangent = tangent;
        let mut current = from;
        let mut steps = 0;
        // The Newton matrix and the parameter value where it was computed.
        let mut jac: Option<(f64, DMatrix<f64>)> = guess.map(|j| (from.value, j.clone()));
        let mut h = target - current.value;
        let mut walking = false;
        let mut failed_before = false;
        // Newton's method failed this many steps in a row.
        let mut failures = 0;
        // Steps tried by walking.
        let mut walks = 0;
        let mut end = EndSearch::default();
        end.verified(from.value, None);
        loop {
            let remaining = target - current.value;
            if remaining == 0.0 {
                return FollowOutcome::Reached(current);
            }
            if steps == MAX_FOLLOW_STEPS || walks == MAX_FOLLOW_WALKS {
                return FollowOutcome::GaveUp {
                    last: current,
                    target,
                };
            }
            steps += 1;
            let next_value = match end.aim(end_tol) {
                Some(v) => v,
                None if h.abs() >= remaining.abs() => target,
                None => current.value + h,
            };
            let at_end = (next_value - current.value).abs() <= end_tol;
            let next = self.newton_step(&current, next_value, &mut jac, tangent.as_ref(), at_end);
            let mut next = next.map(|v| {
                end.verified(v.point.value, v.gauges);
                v.point
            });
            // Where Newton's method fails at the finest step, or at WALK_AFTER_FAILURES halvings in a row (and at
            // every WALK_AFTER_FAILURES-th one after that; once a walk works, through every halving of a walking
            // step that fails, until Newton's method works again), a step is also tried by walking, before an
            // end is declared.
            failures = if next.is_some() { 0 } else { failures + 1 };
            let walk_due = failures >= WALK_AFTER_FAILURES && failures % WALK_AFTER_FAILURES == 0;
            if next.is_none() && (walking || at_end || walk_due) {
                next = self.walk_step(&current, next_value);
                if let Some(p) = &next {
                    end.verified(p.value, None);
                }
                walks += 1;
                walking = walking || next.is_some();
            } else if next.is_some() {
                walking = false;
            }
            if let Some(next) = &next {
                tangent = Tangent::secant(&current, next);
            }
            match next {
                Some(next) => {
                    // A step that works doubles the next one, unless the step before (twice as long) failed:
                    // then the next one is half as long, which bisects toward the family's end.
                    let grow = if failed_before { 0.5 } else { 2.0 };
                    h = grow * (next.value - current.value);
                    current = next;
                    failed_before = false;
                }
                None if at_end => {
                    return FollowOutcome::Ended {
                        last: current,
                        beyond: next_value,
                    }
                }
                None => {
                    end.failed(next_value);
                    h = 0.5 * (next_value - current.value);
                    failed_before = true;
                }
            }
        }
    }

    /// The verified step from `current` to `next_value` by Newton's method ([`NaturalContinuation::step_predicted`])
    /// with the Newton matrix `jac` (and the parameter value where it was computed), updated where the step is
    /// retried; `at_end`: the step is the finest [`NaturalContinuation::follow_to`] takes.
    fn newton_step(
        &self,
        current: &GaitPoint,
        next_value: f64,
        jac: &mut Option<(f64, DMatrix<f64>)>,
        tangent: Option<&Tangent>,
        at_end: bool,
    ) -> Option<Verified> {
        let matrix = jac.as_ref().map(|(_, j)| j);
        match self.step_predicted(current, next_value, (matrix, tangent), (false, at_end)) {
            Ok(p) => Some(p),
            // A step that fails in Newton's method with a matrix computed elsewhere is retried with DP at
            // `current`, as a quick test: Newton's method must not have to damp a step taken with DP at its
            // iterate (`undamped`). Of the 1 338 retries of a 100 x 100 map, 1 336 failed, after up to 8 damped
            // iterations each with a new DP; the two that worked (and the default map's one) damp none. Not a
            // step whose walk fails at the start, where no matrix would help (near an end where the wheel rolls
            // back, most steps of the bisection).
            Err(StepFailure::Newton) if jac.as_ref().is_none_or(|(v, _)| *v != current.value) => {
                self.jacobian(current).and_then(|j| {
                    let predicted = (Some(&j), tangent);
                    let next = self
                        .step_predicted(current, next_value, predicted, (true, at_end))
                        .ok();
                    *jac = Some((current.value, j));
                    next
                })
            }
            Err(_) => None,
        }
    }

    /// The longest step of the gait `at` \[s\] (of the `k` steps of a period-k gait); `None` where the walk
    /// fails.
    pub(crate) fn longest_step(&self, at: &GaitPoint) -> Option<f64> {
        let point = self.parameter.at(at.value).ok()?;
        let map = point.step_map().iterated(self.period);
        let walked = map.eval_signature(&at.section).ok()?;
        walked.cycle.iter().map(|r| r.period).reduce(f64::max)
    }

    /// The real Floquet multiplier closest to +1 of the gait `at`.
    fn near_fold(&self, at: &GaitPoint) -> Option<f64> {
        self.jacobian(at)?
            .complex_eigenvalues()
            .iter()
            .filter(|z| z.im.abs() < 1e-9)
            .map(|z| z.re)
            .min_by(|a, b| (a - 1.0).abs().total_cmp(&(b - 1.0).abs()))
    }

    /// The largest modulus of the Floquet multipliers of the gait `at` (`None` where `DP` cannot be had).
    pub(crate) fn largest_multiplier(&self, at: &GaitPoint) -> Option<f64> {
        let moduli = self.jacobian(at)?.complex_eigenvalues().map(|z| z.norm());
        Some(moduli.iter().copied().fold(0.0, f64::max))
    }

    /// What happens at `beyond`, just past the end of the family whose last gait is `last`: walk from it (see
    /// [`EndCause`]).
    pub(crate) fn end_cause(&self, last: &GaitPoint, beyond: f64) -> EndCause {
        let at = match self.parameter.at(beyond) {
            Ok(at) => at,
            Err(e) => {
                return EndCause::WalkFails {
                    failure: "invalid_parameter".to_string(),
                    message: e.to_string(),
                }
            }
        };
        let mut walker =
            match Walker::new(&at.model, &at.config.solver, &self.start_from(last, beyond)) {
                Ok(w) => w,
                Err(e) => {
                    return EndCause::WalkFails {
                        failure: e.kind().to_string(),
                        message: e.to_string(),
                    }
                }
            };
        // The touchdowns of the walk, for its period.
        let mut returns = Vec::with_capacity(END_WALK_STEPS);
        for step in 1..=END_WALK_STEPS {
            if let Err(e) = walker.step(None) {
                return EndCause::WalkFails {
                    failure: e.kind().to_string(),
                    message: format!("walking from the last gait, step {step}: {e}"),
                };
            }
            returns.push(walker.touchdown_coordinates());
        }
        let walked = match walker.section() {
            Ok(s) => s,
            Err(e) => {
                return EndCause::WalkFails {
                    failure: e.kind().to_string(),
                    message: e.to_string(),
                }
            }
        };
        // The period the walk shows (up to MAX_PERIOD), else the family's own: a period-1 family may end where
        // a period-2 gait takes over, for instance.
        let k = least_period(&returns, MAX_PERIOD, RETURN_TOL).unwrap_or(self.period);
        let single = at.step_map();
        match solve_fixed_point(&single.iterated(k), &walked, &self.options, None) {
            Ok(fp) if k != self.period || !on_orbit(&single, &fp.section, k, &last.section) => {
                EndCause::OtherGait {
                    steps: END_WALK_STEPS,
                    section: fp.section,
                    lambda_i4: fp.outcome.report.indicators.lambda_i4,
                    period_k: k,
                }
            }
            Ok(_) => EndCause::Unconfirmed {
                reason: "the walk from the last gait returns to it: the end of the family is numerical"
                    .to_string(),
            },
            Err(e) => match self.near_fold(last) {
                Some(multiplier) if (multiplier - 1.0).abs() < FOLD_TOL => {
                    EndCause::Fold { multiplier }
                }
                _ => EndCause::Unconfirmed {
                    reason: format!(
                        "the walk from the last gait neither fails nor settles on a gait of period 1 to \
                         {MAX_PERIOD} within {END_WALK_STEPS} steps ({e})"
                    ),
                },
            },
        }
    }
}

/// Is `s` within [`SAME_GAIT_TOL`] of a state of the period-`k` orbit through `orbit` (the orbit walked `k`
/// steps with `map`)? The phases of a period-k gait are all fixed points of `P^k`.
fn on_orbit(map: &StepMap, orbit: &SectionState, k: usize, s: &SectionState) -> bool {
    if orbit.distance(s) <= SAME_GAIT_TOL {
        return true;
    }
    let Ok(mut walker) = map.walker(orbit) else {
        return false;
    };
    for _ in 1..k {
        if walker.step(None).is_err() {
            return false;
        }
        if walker.touchdown_coordinates().distance(s) <= SAME_GAIT_TOL {
            return true;
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::Model;
    use crate::gait::limit_cycle::find_gait;
    use crate::params::Config;
    use crate::reference::default_initial;

    /// The default family in `viscosity` (it ends where the wheel rolls back, near `c = 135.489237`) and a
    /// continuation of it.
    fn family_at(config: &Config, c: f64) -> (GaitPoint, Option<DMatrix<f64>>) {
        let at = config.with("viscosity", c).unwrap();
        let model = Model::new(&at.params).unwrap();
        let map = StepMap::new(&model, &at.solver);
        let g = find_gait(&map, &default_initial(&at), &GaitOptions::default(), None).unwrap();
        let point = GaitPoint {
            value: c,
            section: g.section,
        };
        (point, g.jacobian_guess())
    }

    /// A coarse step's end tolerance brackets the same end as `PARAM_TOL` does from a neighbouring point, only
    /// more loosely: the sweep's coarse pass and its fill agree on where the family ends.
    #[test]
    fn a_coarse_end_tolerance_brackets_the_same_end() {
        let config = Config::default();
        let cont = NaturalContinuation::new(
            Parameter::named(&config, "viscosity").unwrap(),
            &GaitOptions::default(),
        );
        let (from, guess) = family_at(&config, 131.0);
        let FollowOutcome::Ended { last, beyond } =
            cont.follow_to(from, 141.0, (guess.as_ref(), None), 1.0)
        else {
            panic!("the family ends before 141");
        };
        assert!(
            (beyond - last.value).abs() <= 1.0 && beyond > last.value,
            "{last:?} {beyond}"
        );
        let (near, guess) = family_at(&config, 135.0);
        let FollowOutcome::Ended {
            last: fine,
            beyond: fine_beyond,
        } = cont.follow(near, 136.0, (guess.as_ref(), None))
        else {
            panic!("the family ends before 136");
        };
        assert!(fine_beyond - fine.value <= PARAM_TOL);
        assert!(last.value <= fine.value && fine_beyond <= beyond);
        assert!((fine.value - 135.489237).abs() < 1e-6, "{}", fine.value);
    }

    /// A step whose walk fails at its start says so (`Start`: `follow` then computes no `DP` to retry it). A
    /// step Newton's method takes without damping succeeds undamped as damped, to the same gait.
    #[test]
    fn steps_tell_a_failing_start_from_a_failing_newton() {
        let config = Config::default();
        let cont = NaturalContinuation::new(
            Parameter::named(&config, "viscosity").unwrap(),
            &GaitOptions::default(),
        );
        let (from, guess) = family_at(&config, 135.0);
        let beyond = cont.step_asking(&from, 137.0, guess.as_ref(), false);
        assert_eq!(beyond, Err(StepFailure::Start));
        let damped = cont
            .step_asking(&from, 135.2, guess.as_ref(), false)
            .unwrap();
        let undamped = cont
            .step_asking(&from, 135.2, guess.as_ref(), true)
            .unwrap();
        assert_eq!(damped, undamped);
    }

    /// The gait at a point where Newton's method converged, taken from the walk of its derivatives, is the one
    /// `find_gait` gives there, bit for bit (sweeps use it at every continued point); a start that is not a
    /// fixed point falls back to `find_gait` itself.
    #[test]
    fn a_gait_at_a_converged_point_is_find_gaits() {
        use crate::gait::limit_cycle::gait_at_converged;
        let config = Config::default();
        let (from, guess) = family_at(&config, 50.0);
        let model = Model::new(&config.params).unwrap();
        let map = StepMap::new(&model, &config.solver);
        let options = GaitOptions {
            transient_steps: 0,
            parameter: Some("viscosity"),
            ..GaitOptions::default()
        };
        let direct = find_gait(&map, &from.section, &options, guess.as_ref()).unwrap();
        let converged = gait_at_converged(&map, &from.section, &options, guess.as_ref()).unwrap();
        assert_eq!(direct, converged);
        assert_eq!(converged.iterations, 0);
        let mut off = from.section;
        off.theta_dot += 1e-4;
        let direct = find_gait(&map, &off, &options, guess.as_ref()).unwrap();
        let converged = gait_at_converged(&map, &off, &options, guess.as_ref()).unwrap();
        assert_eq!(direct, converged);
        assert!(converged.iterations > 0);
    }

    /// The way back of a step ends after one Newton step where that step lands on the gait the step came from
    /// (the step's result is the one the full solve back accepts), and not where it lands elsewhere: from a
    /// start on another gait (the default family's gait at `c = 60`, taken as a start at `c = 50`) the first
    /// step heads for that gait's neighbourhood, not for the one at `c = 50`.
    #[test]
    fn the_way_back_ends_early_only_on_the_gait_it_came_from() {
        let config = Config::default();
        let cont = NaturalContinuation::new(
            Parameter::named(&config, "viscosity").unwrap(),
            &GaitOptions::default(),
        );
        let (from, guess) = family_at(&config, 50.0);
        let reached = cont
            .step(&from, 51.0, guess.as_ref())
            .expect("a verified step");
        let back_start = cont.start_from(&reached, 50.0);
        let landing = cont
            .first_newton_step(50.0, &back_start, guess.as_ref())
            .unwrap();
        assert!(
            landing.distance(&from.section) <= EARLY_RETURN_TOL,
            "{landing:?}"
        );
        // The full solve back confirms it.
        let back = cont
            .solve(50.0, &back_start, &mut || guess.clone(), false)
            .unwrap();
        assert!(back.section.distance(&from.section) <= SAME_GAIT_TOL);
        let (far, _) = family_at(&config, 60.0);
        let landing = cont
            .first_newton_step(50.0, &far.section, guess.as_ref())
            .unwrap();
        assert!(
            landing.distance(&from.section) > EARLY_RETURN_TOL,
            "{landing:?}"
        );
        // Without a Newton matrix of the map's size there is no early answer.
        let wrong = DMatrix::<f64>::zeros(2, 2);
        assert!(cont
            .first_newton_step(50.0, &back_start, Some(&wrong))
            .is_none());
    }

    /// A family whose stance tip slips at the section has the slip as a coordinate of its Newton matrix too
    /// (regression: `DP` was asked of the map at rest, which refused the slipping touchdown, so continuation
    /// stepped without it and stopped early).
    #[test]
    fn a_slipping_family_has_its_newton_matrix() {
        let mut config = Config::default();
        config.apply_override("friction=0.105").unwrap();
        let (from, guess) = family_at(&config, 50.0);
        assert!(from.section.slips() && guess.is_some());
        let cont = NaturalContinuation::new(
            Parameter::named(&config, "viscosity").unwrap(),
            &GaitOptions::for_sweeps(),
        );
        let j = cont.jacobian(&from).expect("DP at a slipping gait");
        assert_eq!((j.nrows(), j.ncols()), (4, 4));
        assert!(cont
            .step(&from, 51.0, Some(&j))
            .is_some_and(|p| p.section.slips()));
    }
}
