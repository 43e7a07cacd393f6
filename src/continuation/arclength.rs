//! Pseudo-arclength continuation of a family of fixed points `P(x; p) = x` (docs/model.md section 11; Keller
//! 1977, Allgower and Georg 1990 ch. 2, the predictor-corrector of AUTO, MatCont and BifurcationKit.jl).
//!
//! **Unknowns.** `z = (x, p / sigma)`: the state and the parameter divided by its scale `sigma`
//! ([`ContinuationOptions::param_scale`]), so that a step of length `h` in `z` moves the state and the parameter
//! by comparable amounts. `H(z) = P(x; p) - x` has the `n x (n + 1)` Jacobian `J = [DP - I, sigma dP/dp]`,
//! exact from the variational equations.
//!
//! **Predictor.** The tangent `t` is the unit null vector of `J`, oriented as the previous one
//! (`[J; t_prev^T] t = [0; 1]`); the prediction is `z + h t`.
//!
//! **Corrector.** Newton's method on `H(z) = 0` with the hyperplane `t . (z - z_pred) = 0`, the matrix
//! `[J; t^T]` of the last point held (a chord method: one evaluation of `P` per iteration, no derivatives),
//! until `max |H| <` [`ContinuationOptions::tolerance`]; it fails if the residual does not at least halve per
//! iteration. Because the hyperplane is transversal to the family, the corrector passes folds, where
//! natural-parameter continuation (fixed `p`) stops.
//!
//! **Step control.** A step is accepted only if its corrector converged, the corrected point is within
//! `h / 2` of the prediction and the new tangent turned by less than [`MAX_TURN`] (a step that jumps to
//! another family shows as a large turn or a large correction); otherwise it is halved. Accepted steps grow
//! by [`GROW`] after a corrector of at most [`EASY_CORRECTOR`] iterations and shrink by [`SHRINK`] after one of more than
//! [`HARD_CORRECTOR`]. The family ends where the step falls below [`ContinuationOptions::min_step`] (with the last
//! failure: the walk falls, rolls back, ...), where it leaves the parameter range (its last point placed
//! exactly on the bound), where it closes on itself, or after [`ContinuationOptions::max_points`] points.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::corrector::{
    augmented, bordered, correct, correct_to_point, corrector_failure, point_at, split,
    start_point, ContinuationOptions, FamilyPoint,
};
use super::special::{border_at_end, detect_between, SpecialPoint};
use super::{FamilyMap, MapFailure};

/// Largest angle between successive tangents of an accepted step (as its cosine).
pub const MAX_TURN: f64 = 0.9;

/// Below this step length (in the scaled unknowns) a large turn of the tangent is accepted: the family has a
/// corner there (a border of the map's pieces, where `DP` jumps; e.g. a nonsmooth fold), which no shorter
/// step smooths out.
pub const CORNER_STEP: f64 = 1e-5;

/// Growth of the step after an easy corrector (at most [`EASY_CORRECTOR`] iterations).
pub const GROW: f64 = 1.6;

/// Shrinkage of the step after a hard corrector (more than [`HARD_CORRECTOR`] iterations).
pub const SHRINK: f64 = 0.6;

/// A corrector of at most this many iterations lets the next step grow (the chord method from a good
/// prediction takes three to 1e-11).
pub const EASY_CORRECTOR: usize = 3;

/// A corrector of more than this many iterations makes the next step shrink.
pub const HARD_CORRECTOR: usize = 5;

/// Why following a family stopped in one direction.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FamilyEnd {
    /// The family reached the end of the parameter range (its last point lies on it).
    LeftRange {
        /// The bound.
        bound: f64,
    },
    /// The family came back to its start: a closed loop.
    Closed,
    /// [`ContinuationOptions::max_points`] points were followed.
    MaxPoints,
    /// Following was stopped from outside (the interrupt flag: a map failure
    /// [`MapFailure::interrupted`](super::MapFailure::interrupted)) after the point at `param`: the family goes
    /// on for all that is known, and nothing was searched past that point.
    Interrupted {
        /// The parameter at the last point followed.
        param: f64,
    },
    /// The step fell below [`ContinuationOptions::min_step`]: the family cannot be followed further. `failure`
    /// is the last failure of the map (the walk rolls back, falls, ...); where the map never failed, `border`
    /// if a border collision was found at the end (a special point), else the corrector's or the step
    /// control's (`corrector`, `step`). Where the map failed, the end is bracketed in the parameter to
    /// [`ContinuationOptions::param_tolerance`] times `max(1, |p|)` by bisection at fixed parameter from the
    /// last point (a border of the map's domain has no smooth test function to solve for).
    Ended {
        /// The parameter at the last point.
        param: f64,
        /// The nearest parameter beyond it where the map failed; just past the border at a `border` end;
        /// `NaN` otherwise.
        beyond: f64,
        /// The failure's kind (`corrector` where the corrector did not converge without a failure of the map).
        failure: String,
        /// The last failure in words.
        message: String,
    },
}

/// A followed family: its points in order of arclength, its special points and how it ends either way.
#[derive(Debug, Clone, PartialEq)]
pub struct Family<I> {
    /// Points in order of arclength (the start among them).
    pub points: Vec<FamilyPoint<I>>,
    /// Index of the start in `points`.
    pub start: usize,
    /// Special points, in order of arclength.
    pub special: Vec<SpecialPoint<I>>,
    /// How the family ends at its first point (`[0]`) and at its last (`[1]`).
    pub ends: [FamilyEnd; 2],
    /// Steps of `P` per evaluation of the map followed.
    pub period: usize,
    /// The options it was followed with.
    pub options: ContinuationOptions,
}

/// Why a family could not be started.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ContinuationError {
    /// The options are invalid.
    #[error("invalid continuation options: {0}")]
    Options(String),
    /// The start is outside the range.
    #[error("the start value {value} is outside the range [{from}, {to}]")]
    StartOutsideRange {
        /// The start.
        value: f64,
        /// The range.
        from: f64,
        /// The range.
        to: f64,
    },
    /// No fixed point near the initial state at the start value.
    #[error("no fixed point at the start value {value}: {reason}")]
    NoStart {
        /// The start value.
        value: f64,
        /// Why.
        reason: String,
    },
}

/// Follow the family of fixed points of `map` through the state `x0` at the parameter `p0` (which need only
/// be near a fixed point: it is corrected at fixed `p0` first) in both directions (see the module
/// documentation).
pub fn continue_family<M: FamilyMap>(
    map: &M,
    x0: &DVector<f64>,
    p0: f64,
    options: &ContinuationOptions,
) -> Result<Family<M::Info>, ContinuationError> {
    options.validate().map_err(ContinuationError::Options)?;
    if !(options.from..=options.to).contains(&p0) {
        return Err(ContinuationError::StartOutsideRange {
            value: p0,
            from: options.from,
            to: options.to,
        });
    }
    let start = start_point(map, x0, p0, options).map_err(|e| ContinuationError::NoStart {
        value: p0,
        reason: e.message,
    })?;
    let forward = follow(map, start.clone(), options);
    let mut reversed = start.clone();
    reversed.tangent.neg_mut();
    let backward = follow(map, reversed, options);
    Ok(assemble(start, forward, backward, map.period(), *options))
}

/// What following one direction found.
pub(crate) struct Followed<I> {
    points: Vec<FamilyPoint<I>>,
    special: Vec<SpecialPoint<I>>,
    end: FamilyEnd,
}

/// Follow the family from `start` along its tangent (see the module documentation); the points after the
/// start, in order.
fn follow<M: FamilyMap>(
    map: &M,
    start: FamilyPoint<M::Info>,
    options: &ContinuationOptions,
) -> Followed<M::Info> {
    let mut follower = Follower::new(map, start, options);
    while follower.points.len() < options.max_points {
        if let Some(end) = follower.step() {
            return follower.finish(end);
        }
    }
    follower.finish(FamilyEnd::MaxPoints)
}

/// The state of the pseudo-arclength follower in one direction (see the module documentation): the points
/// accepted so far, the step and what the step control remembers of the steps rejected since the last accepted.
struct Follower<'a, M: FamilyMap> {
    map: &'a M,
    options: &'a ContinuationOptions,
    /// The parameter's scale ([`ContinuationOptions::param_scale`]).
    sigma: f64,
    /// The start's scaled unknowns (to find a closed family).
    z_start: DVector<f64>,
    /// The points accepted after the start, in order.
    points: Vec<FamilyPoint<M::Info>>,
    /// The special points found between them.
    special: Vec<SpecialPoint<M::Info>>,
    /// `J` of the last point that has derivatives: the corrector's matrix.
    held: DMatrix<f64>,
    /// The last accepted point (the start at first).
    current: FamilyPoint<M::Info>,
    /// The step length in the scaled unknowns.
    h: f64,
    /// The tangent at the point before `current` and the arclength between them (for the predictor's
    /// curvature).
    curvature: Option<(DVector<f64>, f64)>,
    /// The corrector's last contraction rate (to evaluate with derivatives where it expects to converge).
    rate_hint: f64,
    /// The last jump of the map a rejected step crossed (reported at the end if nothing else ends the family).
    pending_jump: Option<SpecialPoint<M::Info>>,
    /// The parameter of the last corrected point rejected for jumping or turning too far.
    rejected_at: f64,
    /// The last failure of a step.
    last_failure: Option<MapFailure>,
    /// The last failure of the map itself since the last accepted step, and the parameter it failed at.
    map_failure: Option<(MapFailure, f64)>,
    /// The arclength travelled from the start.
    travelled: f64,
}

impl<'a, M: FamilyMap> Follower<'a, M> {
    /// A follower at `start`, with the initial step.
    fn new(map: &'a M, start: FamilyPoint<M::Info>, options: &'a ContinuationOptions) -> Self {
        let sigma = options.param_scale;
        Follower {
            map,
            options,
            sigma,
            z_start: start.z(sigma),
            points: Vec::new(),
            special: Vec::new(),
            held: augmented(&start.jacobian, &start.dparam, sigma),
            current: start,
            h: options.initial_step,
            curvature: None,
            rate_hint: f64::NAN,
            pending_jump: None,
            rejected_at: f64::NAN,
            last_failure: None,
            map_failure: None,
            travelled: 0.0,
        }
    }

    /// What was followed, ending with `end`.
    fn finish(self, end: FamilyEnd) -> Followed<M::Info> {
        Followed {
            points: self.points,
            special: self.special,
            end,
        }
    }

    /// One predictor-corrector step from `current`: accepted, or rejected with a halved step; the end of the
    /// family where this step finds one.
    fn step(&mut self) -> Option<FamilyEnd> {
        let options = self.options;
        // An interrupted evaluation says nothing of the family: stop at once, without bracketing an end.
        if self
            .last_failure
            .as_ref()
            .is_some_and(MapFailure::interrupted)
            || self
                .map_failure
                .as_ref()
                .is_some_and(|(f, _)| f.interrupted())
        {
            return Some(FamilyEnd::Interrupted {
                param: self.current.param,
            });
        }
        if self.h < options.min_step {
            return Some(match self.map_failure.take() {
                Some((failure, at)) => self.end_where_map_failed(failure, at),
                None => self.end_where_map_worked(),
            });
        }
        let z = self.current.z(self.sigma);
        let z_pred = self.predict(&z);
        let mut next = match self.correct(&z_pred) {
            Ok(next) => next,
            Err(failure) => {
                if failure.kind != "corrector" {
                    self.map_failure = Some((failure.clone(), split(&z_pred, self.sigma).1));
                }
                self.last_failure = Some(failure);
                self.h *= 0.5;
                return None;
            }
        };
        let z_next = next.z(self.sigma);
        if self.reject_far(&next, &z_next, &z_pred) {
            return None;
        }
        let step = (&z_next - &z).norm();
        self.travelled += step;
        next.arclength = self.current.arclength + step;
        if let Some(end) = self.end_on_bound(&next) {
            return Some(end);
        }
        if options.detect && self.reject_jump(&next, step) {
            return None;
        }
        self.accept(next, step);
        // Back at the start after going round: a closed family.
        if self.travelled > 4.0 * self.h && (&z_next - &self.z_start).norm() < 0.5 * self.h {
            return Some(FamilyEnd::Closed);
        }
        let iterations = self.current.iterations;
        if iterations <= EASY_CORRECTOR {
            self.h = (self.h * GROW).min(options.max_step);
        } else if iterations > HARD_CORRECTOR {
            self.h = (self.h * SHRINK).max(options.min_step);
        }
        self.last_failure = None;
        self.map_failure = None;
        None
    }

    /// The tangent predictor from `z` (the current point's unknowns), with the curvature of the last step where
    /// there is one (the change of the tangent over it): quadratic extrapolation, which leaves the corrector a
    /// residual of order h^3.
    fn predict(&self, z: &DVector<f64>) -> DVector<f64> {
        let h = self.h;
        let mut z_pred = z + h * &self.current.tangent;
        if let Some((t_before, s_before)) = &self.curvature {
            z_pred += (0.5 * h * h / s_before) * (&self.current.tangent - t_before);
        }
        z_pred
    }

    /// The corrector from `z_pred` on the hyperplane of the current tangent, with the matrix of the current
    /// point where it has derivatives (else the one held).
    fn correct(&mut self, z_pred: &DVector<f64>) -> Result<FamilyPoint<M::Info>, MapFailure> {
        let current = &self.current;
        if current.has_derivatives() {
            self.held = augmented(&current.jacobian, &current.dparam, self.sigma);
        }
        let m = bordered(&self.held, &current.tangent);
        correct_to_point(
            self.map,
            z_pred,
            &current.tangent,
            &m,
            (&current.tangent, self.rate_hint),
            self.options,
        )
    }

    /// Reject (halving the step) a corrected point `next` (unknowns `z_next`) that jumped too far from the
    /// prediction `z_pred`, whose tangent turned too far, or that is another family's.
    fn reject_far(
        &mut self,
        next: &FamilyPoint<M::Info>,
        z_next: &DVector<f64>,
        z_pred: &DVector<f64>,
    ) -> bool {
        let h = self.h;
        let current = &self.current;
        let jumped = (z_next - z_pred).norm() > 0.5 * h;
        // A turn over a step this short is a corner of the family (it crosses a border where DP jumps), not
        // a jump to another family.
        let turned = next.tangent.dot(&current.tangent) < MAX_TURN && h > CORNER_STEP;
        // A step to a point that cannot be this family's (the VRW: another least period).
        let other = !self.map.same_family(&current.info, &next.info);
        if !((jumped || turned || other) && h > self.options.min_step) {
            return false;
        }
        self.last_failure = Some(MapFailure {
            kind: "step".to_string(),
            message: if other {
                format!(
                    "steps near p = {} reach another family (its least period differs)",
                    current.param
                )
            } else {
                format!(
                    "steps near p = {} turn or jump too far (the family turns sharply, or another is \
                     near)",
                    current.param
                )
            },
        });
        self.rejected_at = next.param;
        self.h *= 0.5;
        true
    }

    /// The end of the range, where `next` lies beyond it: the last point is placed on the bound.
    fn end_on_bound(&mut self, next: &FamilyPoint<M::Info>) -> Option<FamilyEnd> {
        let options = self.options;
        let bound = if next.param > options.to {
            Some(options.to)
        } else if next.param < options.from {
            Some(options.from)
        } else {
            None
        }?;
        let on_bound = point_on_bound(self.map, &self.current, next, bound, options).ok()?;
        if options.detect {
            let found = detect_between(self.map, &self.current, &on_bound, options);
            self.special.extend(found);
        }
        self.points.push(on_bound);
        Some(FamilyEnd::LeftRange { bound })
    }

    /// The special points between the current point and `next`, `step` from it; where a border between them
    /// has no fixed point at its middle, the step reached another family across a jump of the map: it is
    /// rejected (halving the step) and the jump kept for the end.
    fn reject_jump(&mut self, next: &FamilyPoint<M::Info>, step: f64) -> bool {
        let found = detect_between(self.map, &self.current, next, self.options);
        // A border between the two points with no fixed point at its middle: the step reached another
        // family across a jump of the map. The family ends at the last point before the border.
        if let Some(jump) = found.iter().find(|s| s.ends_family) {
            // The step reached past a jump of the map (another family's fixed point): rejected, like a
            // step that jumps, so that the steps shrink toward the family's own end; the jump is kept
            // for the end.
            self.last_failure = Some(MapFailure {
                kind: "border".to_string(),
                message: format!(
                    "a jump of the step map between {} and {}: {}",
                    self.current.param,
                    next.param,
                    jump.note
                        .as_deref()
                        .unwrap_or("no fixed point at its middle")
                ),
            });
            self.pending_jump = Some(jump.clone());
            self.travelled -= step;
            self.h *= 0.5;
            return true;
        }
        self.special.extend(found);
        false
    }

    /// Accept `next`, `step` from the current point, as the new current point.
    fn accept(&mut self, next: FamilyPoint<M::Info>, step: f64) {
        // A jump crossed before this accepted step is not where the family ends (steps toward an end fail
        // in a row after the last accepted one).
        self.pending_jump = None;
        self.rejected_at = f64::NAN;
        self.rate_hint = next.corrector_rate;
        self.curvature = (self.current.has_derivatives() && next.has_derivatives())
            .then(|| (self.current.tangent.clone(), step));
        self.points.push(next.clone());
        self.current = next;
    }

    /// The end where the step fell below the smallest after the map failed at the parameter `at`: bracketed
    /// by bisection ([`bracket_end`]), its nearest point added.
    fn end_where_map_failed(&mut self, failure: MapFailure, at: f64) -> FamilyEnd {
        let options = self.options;
        let (nearer, beyond, failure) =
            bracket_end(self.map, &self.current, &self.held, (at, failure), options);
        if let Some(nearer) = nearer {
            if options.detect {
                let found = detect_between(self.map, &self.current, &nearer, options);
                self.special.extend(found);
            }
            self.points.push(nearer.clone());
            self.current = nearer;
        }
        FamilyEnd::Ended {
            param: self.current.param,
            beyond,
            failure: failure.kind,
            message: failure.message,
        }
    }

    /// The end where the step fell below the smallest without a failure of the map: the family may end at a
    /// border of the map's pieces (a special point), or at a jump of the map found on the way.
    fn end_where_map_worked(&mut self) -> FamilyEnd {
        let options = self.options;
        let border = options
            .detect
            .then(|| {
                let previous = self.points.len().checked_sub(2).map(|i| &self.points[i]);
                border_at_end(self.map, previous, &self.current, options)
            })
            .flatten();
        let beyond = self.beyond_end(border.as_ref());
        let border = border.or(self.pending_jump.take());
        // The border is the end's cause where one was found; else the corrector's last failure.
        let failure = match &border {
            Some(b) => MapFailure {
                kind: "border".to_string(),
                message: format!(
                    "{} = 0 at {}: {}",
                    b.border.as_deref().unwrap_or("a border"),
                    b.param,
                    b.note.as_deref().unwrap_or("the family ends there")
                ),
            },
            None => self
                .last_failure
                .take()
                .unwrap_or_else(|| corrector_failure(0, f64::NAN)),
        };
        self.special.extend(border);
        FamilyEnd::Ended {
            param: self.current.param,
            beyond,
            failure: failure.kind,
            message: failure.message,
        }
    }

    /// Where the walk looks for what takes over past an end without a failure of the map: just past the
    /// `border` found at the end; past a jump of the map found on the way, its far side.
    fn beyond_end(&self, border: Option<&SpecialPoint<M::Info>>) -> f64 {
        let options = self.options;
        let current = &self.current;
        match (border, &self.pending_jump) {
            (Some(b), _) => {
                let step = options.param_tolerance.max(1e-7) * b.param.abs().max(1.0);
                b.param + step.copysign(b.param - current.param)
            }
            (None, Some(jump)) => jump.bracket[1],
            // Just past the last point in the direction of travel (the steps that jumped or turned too far
            // may have landed back inside the family): the walk from there says what takes over. Without a
            // direction, where the last rejected step landed.
            (None, None) => {
                let direction = current.tangent[current.tangent.len() - 1];
                let step = options.param_tolerance.max(1e-7) * current.param.abs().max(1.0);
                if direction != 0.0 {
                    current.param + step.copysign(direction)
                } else {
                    self.rejected_at
                }
            }
        }
    }
}

/// The point of the family between `a` and `b` at the parameter `bound` (corrected at fixed `p`).
fn point_on_bound<M: FamilyMap>(
    map: &M,
    a: &FamilyPoint<M::Info>,
    b: &FamilyPoint<M::Info>,
    bound: f64,
    options: &ContinuationOptions,
) -> Result<FamilyPoint<M::Info>, MapFailure> {
    let sigma = options.param_scale;
    let w = (bound - a.param) / (b.param - a.param);
    let (za, zb) = (a.z(sigma), b.z(sigma));
    let mut z_pred = &za + w * (&zb - &za);
    let n = a.x.len();
    z_pred[n] = bound / sigma;
    let mut e_p = DVector::zeros(n + 1);
    e_p[n] = 1.0;
    if !a.has_derivatives() {
        return Err(corrector_failure(0, f64::NAN));
    }
    let m = bordered(&augmented(&a.jacobian, &a.dparam, sigma), &e_p);
    let (z, it) = correct(map, &z_pred, &e_p, &m, options)?;
    let mut point = point_at(map, &z, &a.tangent, options)?;
    point.iterations = it;
    point.arclength = a.arclength + (&z - &za).norm();
    Ok(point)
}

/// The end of a family whose map failed at the parameter `fail_at` just beyond the point `from`, bracketed by
/// bisection in the parameter: each trial value is corrected at fixed parameter from the nearest point that
/// worked (along its tangent), with the matrix of that point or, if that fails, of the trial itself. The
/// point nearest the end (if nearer than `from`), the first parameter found to fail, and the last failure
/// of the map.
fn bracket_end<M: FamilyMap>(
    map: &M,
    from: &FamilyPoint<M::Info>,
    held: &DMatrix<f64>,
    (fail_at, failure): (f64, MapFailure),
    options: &ContinuationOptions,
) -> (Option<FamilyPoint<M::Info>>, f64, MapFailure) {
    let sigma = options.param_scale;
    let n = from.x.len();
    let mut e_p = DVector::zeros(n + 1);
    e_p[n] = 1.0;
    let mut failure = failure;
    let mut nearer: Option<FamilyPoint<M::Info>> = None;
    let mut hi = fail_at;
    let tol = options.param_tolerance * from.param.abs().max(1.0);
    for _ in 0..MAX_END_BISECTIONS {
        let base = nearer.as_ref().unwrap_or(from);
        let t_p = base.tangent[n];
        if (hi - base.param).abs() <= tol || t_p.abs() < 1e-12 {
            break;
        }
        let mid = 0.5 * (base.param + hi);
        let z_base = base.z(sigma);
        let mut z_pred = &z_base + ((mid - base.param) / sigma / t_p) * &base.tangent;
        z_pred[n] = mid / sigma;
        let j = if base.has_derivatives() {
            augmented(&base.jacobian, &base.dparam, sigma)
        } else {
            held.clone()
        };
        let trial = correct(map, &z_pred, &e_p, &bordered(&j, &e_p), options).or_else(|_| {
            let (x, p) = split(&z_pred, sigma);
            let ev = map.eval(&x, p)?;
            let fresh = bordered(&augmented(&ev.jacobian, &ev.dparam, sigma), &e_p);
            correct(map, &z_pred, &e_p, &fresh, options)
        });
        match trial.and_then(|(z, it)| {
            let mut point = point_at(map, &z, &base.tangent, options)?;
            point.iterations = it;
            point.arclength = base.arclength + (&z - &z_base).norm();
            Ok(point)
        }) {
            Ok(point) => nearer = Some(point),
            Err(f) => {
                hi = mid;
                if f.kind != "corrector" {
                    failure = f;
                }
            }
        }
    }
    (nearer, hi, failure)
}

/// Bisections allowed to bracket the end of a family.
const MAX_END_BISECTIONS: usize = 60;

/// One family from the start and the two directions followed from it, in order of arclength.
fn assemble<I: Clone>(
    start: FamilyPoint<I>,
    forward: Followed<I>,
    backward: Followed<I>,
    period: usize,
    options: ContinuationOptions,
) -> Family<I> {
    let mut points: Vec<FamilyPoint<I>> = backward.points.into_iter().rev().collect();
    let start_index = points.len();
    points.push(start);
    points.extend(forward.points);
    // Arclength from the first point, and every tangent along the order of the points.
    let total_back = points[start_index].arclength;
    let back_lengths: Vec<f64> = points[..start_index].iter().map(|p| p.arclength).collect();
    for (point, len) in points[..start_index].iter_mut().zip(back_lengths) {
        point.arclength = -len;
        point.tangent.neg_mut();
    }
    let offset = points.first().map_or(total_back, |p| p.arclength);
    for point in &mut points {
        point.arclength -= offset;
    }
    let mut special: Vec<SpecialPoint<I>> = backward.special;
    for sp in &mut special {
        sp.arclength = -sp.arclength;
    }
    special.extend(forward.special);
    for sp in &mut special {
        sp.arclength -= offset;
    }
    special.sort_by(|a, b| a.arclength.total_cmp(&b.arclength));
    Family {
        points,
        start: start_index,
        special,
        ends: [backward.end, forward.end],
        period,
        options,
    }
}
