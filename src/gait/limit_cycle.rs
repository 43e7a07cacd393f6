//! The passive gait: a fixed point `s* = P(s*)` of the step map, found by Newton's method, and its stability
//! from the eigenvalues of `DP(s*)` (the Floquet multipliers) (docs/model.md section 6).

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

use super::derivative::{gait_jacobian, GaitJacobian, ParamDerivative};
use super::step_map::{StepMap, StepOutcome};
use crate::params::{Params, RearExit};
use crate::walk::WalkError;
use crate::walk::{Branch, ContactAudit, SectionState, StepReport};

mod newton;

use newton::{Newton, Trial};

/// How a gait is searched for. Each setting has a valid range, checked by [`GaitOptions::validate`]
/// (`gait/options.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GaitOptions {
    /// Steps walked from the initial state before Newton's method starts (default 30).
    pub transient_steps: usize,
    /// Newton iterations allowed (default 20).
    pub max_iterations: usize,
    /// Convergence: `max |P(s) - s| <` this (default 1e-10; units of the section coordinates).
    pub tolerance: f64,
    /// Relative finite-difference step of the Jacobian where finite differences are used: Newton's matrix where
    /// the map is not differentiable, and the check of the exact `DP` (default 1e-4).
    pub fd_step: f64,
    /// Estimate the error of the final `DP` (default true): the exact `DP` computed again at tolerances
    /// [`super::derivative::DERIVATIVE_CHECK_TIGHTENING`] times tighter, the difference being the estimate that
    /// the stability verdict uses; otherwise no estimate (about half the cost, used inside continuation).
    pub refine_jacobian: bool,
    /// Also compute `dP/dp` of the gait for this parameter (one of
    /// [`DIFFERENTIABLE_KEYS`](crate::dynamics::DIFFERENTIABLE_KEYS); `gait.json`'s `dP_dparam`). Default none.
    pub parameter: Option<&'static str>,
    /// With `refine_jacobian`, estimate the error of `dP/dp` the same way (default true); otherwise the second
    /// computation carries `DP` alone (a direction less; a sweep's own `dP/dp`, which only predicts the next
    /// point, needs no estimate) and `dP_dparam`'s error is `NaN`.
    pub refine_dparam: bool,
}

impl Default for GaitOptions {
    fn default() -> Self {
        GaitOptions {
            transient_steps: 30,
            max_iterations: 20,
            tolerance: 1e-10,
            fd_step: 1e-4,
            refine_jacobian: true,
            parameter: None,
            refine_dparam: true,
        }
    }
}

impl GaitOptions {
    /// The settings of a sweep (`vrw sweep`): the defaults, with the refined `DP` whose error estimate gives
    /// each gait its stability verdict.
    pub fn for_sweeps() -> GaitOptions {
        GaitOptions::default()
    }

    /// Which error estimates the final `DP` gets: of `DP` (`refine_jacobian`), and of `dP/dp` with it
    /// (`refine_dparam`).
    fn estimates(&self) -> (bool, bool) {
        (
            self.refine_jacobian,
            self.refine_jacobian && self.refine_dparam,
        )
    }
}

/// Why no gait was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GaitError {
    /// The walk failed during the transient, at step `step`.
    #[error("walk failed during the transient at step {step}: {source}")]
    Transient {
        /// Transient step number (from 1).
        step: usize,
        /// Why.
        source: WalkError,
    },
    /// The step map could not be evaluated during Newton's method.
    #[error("step map failed in Newton iteration {iteration}: {source}")]
    Newton {
        /// Iteration number (from 1).
        iteration: usize,
        /// Why.
        source: WalkError,
    },
    /// Newton's method did not reach the tolerance.
    #[error("no convergence: residual {residual:e} after {iterations} Newton iterations")]
    NoConvergence {
        /// Iterations done.
        iterations: usize,
        /// Final `max |P(s) - s|`.
        residual: f64,
    },
    /// The walk keeps going but its returns repeat with no period up to `max_period` (period-k search).
    #[error(
        "the walk does not settle on a gait of period 1 to {max_period} within {steps} steps (closest \
         return {distance:e})"
    )]
    Unsettled {
        /// Longest period tried.
        max_period: usize,
        /// Steps walked.
        steps: usize,
        /// Smallest return distance over the periods tried.
        distance: f64,
    },
    /// Newton's method found a fixed point of `P^k`, but the walk from it does not repeat: the section state
    /// does not hold the whole state at touchdown (the stance tip slides then, docs/model.md section 6).
    #[error(
        "the walk settles with period {period_k}, but the section state does not hold its whole state (the \
         stance tip slides at touchdown): the walk from the fixed point of P^{period_k} misses it by \
         {distance:e} after two periods"
    )]
    SectionIncomplete {
        /// The walk's period.
        period_k: usize,
        /// Distance from the fixed point after `2 period_k` steps.
        distance: f64,
    },
    /// The search settings break a rule of [`GaitOptions::validate`] (the search does not start).
    #[error("invalid search settings: {message}")]
    InvalidOptions {
        /// The rule broken, naming the setting.
        message: String,
    },
    /// With Coulomb friction below the slope's tangent no gait exists (a necessary condition, checked before
    /// any walk; see docs/model.md section 12).
    #[error(
        "no gait can exist: friction = {friction} is below tan(slope) = {tan_slope:.6}. Over a period the \
         ground must push the wheel up the slope by its weight's component M g sin(slope) T, with at most \
         friction times the normal push M g cos(slope) T (docs/model.md section 12): the wheel slides away"
    )]
    FrictionBelowSlope {
        /// The friction coefficient.
        friction: f64,
        /// `tan(|slope|)`.
        tan_slope: f64,
    },
    /// `DP - I` is singular (a multiplier at 1: a fold of the gait).
    #[error("DP - I is singular (a Floquet multiplier at 1), residual {residual:e}")]
    SingularJacobian {
        /// Residual at that point.
        residual: f64,
    },
}

impl GaitError {
    /// Short machine-readable name (`fell`, `stalled`, `no_convergence`, ...).
    pub fn kind(&self) -> &'static str {
        match self {
            GaitError::Transient { source, .. } | GaitError::Newton { source, .. } => source.kind(),
            GaitError::NoConvergence { .. } => "no_convergence",
            GaitError::Unsettled { .. } => "unsettled",
            GaitError::SectionIncomplete { .. } => "section_incomplete",
            GaitError::SingularJacobian { .. } => "singular_jacobian",
            GaitError::InvalidOptions { .. } => "invalid_options",
            GaitError::FrictionBelowSlope { .. } => "friction_below_slope",
        }
    }

    /// Did the walk reach a touchdown that is not on the Poincare section ([`WalkError::leaves_section`])?
    pub(crate) fn leaves_section(&self) -> bool {
        matches!(
            self,
            GaitError::Transient { source, .. } | GaitError::Newton { source, .. }
                if source.leaves_section()
        )
    }
}

/// A walking gait (limit cycle) and what it does. A period-k gait ([`super::period_k`]) is a fixed point of
/// `P^k`: its scalar fields are those of its first step, `cycle` has every step, and the Jacobian and
/// multipliers are those of `P^k`. Serialized with `theta` inside `section`
/// (`{"section": {"L2", "thetadot", "L2dot", "theta"}, ...}`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(into = "GaitRecord")]
pub struct Gait {
    /// Steps per period of the gait: 1 for an ordinary gait (a fixed point of `P`), `k` for a fixed point of
    /// `P^k` that is not one of any `P^j` with `j < k`.
    pub period_k: usize,
    /// The fixed point on the section (for a period-k gait, the first of its `k` section states).
    pub section: SectionState,
    /// `theta` at the section \[rad\].
    pub theta: f64,
    /// `max |P(s*) - s*|`.
    pub residual: f64,
    /// Newton iterations used.
    pub iterations: usize,
    /// DLS indicator `lambda_I4` \[N s\].
    pub lambda_i4: f64,
    /// DLS indicator `lambda_2+` \[N\].
    pub lambda_2_plus: f64,
    /// DLS indicator `lambda_4+` \[N\].
    pub lambda_4_plus: f64,
    /// Branch of the impact procedure.
    pub branch: Branch,
    /// Step period \[s\].
    pub period: f64,
    /// Step length \[m\].
    pub step_length: f64,
    /// Mean speed \[m/s\].
    pub speed: f64,
    /// Double-limb support per step: both tips on the ground without slipping \[s\].
    pub dls_duration: f64,
    /// Time Leg 2's tip touches the ground per step, sticking or sliding \[s\].
    pub rear_contact_duration: f64,
    /// Leg 2 scuffs (re-contacts or slides after its lift-off).
    pub scuffing: bool,
    /// Leg 1 bounces.
    pub bounce: bool,
    /// Energy-audit residual of the gait's step \[J\].
    pub energy_residual: f64,
    /// Contact audit of the gait's step.
    pub contact: ContactAudit,
    /// Every step of one period, in order (`period_k` records; each carries its section state, DLS
    /// indicators and branch).
    pub cycle: Vec<StepReport>,
    /// `DP(s*)` (`D(P^k)(s*)` for a period-k gait) on the free coordinates, row-major: exact derivatives
    /// (variational equations and saltation matrices, docs/model.md section 10).
    pub jacobian: Vec<Vec<f64>>,
    /// Estimated error of the Jacobian entries: the largest difference to the exact `DP` at tolerances
    /// [`super::derivative::DERIVATIVE_CHECK_TIGHTENING`] times tighter, or `NaN` if not estimated.
    pub jacobian_error: f64,
    /// With Coulomb friction, the event sequence of the gait's step (as `branch.csv`'s `signature`, with
    /// `SLIP1`/`SLIP2` for a tip that slips through the touchdown and `SLIDE`/`STICK` for each slip start and
    /// stop): where the tips stick and slip. Absent without friction.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub signature: Option<String>,
    /// `dP/dp` for the parameter of [`GaitOptions::parameter`], if one was chosen (`dP_dparam` in JSON).
    pub dp_dparam: Option<ParamDerivative>,
    /// Eigenvalues of `DP(s*)` (of `D(P^k)(s*)` for a period-k gait) as `[re, im]`, largest modulus first.
    pub floquet_multipliers: Vec<[f64; 2]>,
    /// Largest modulus of the multipliers.
    pub max_floquet: f64,
    /// What the multipliers and their error estimate show (see [`Stability`]).
    pub stability: Stability,
    /// Why `DP` could not be computed (the map is not differentiable at the gait, e.g. a grazing event or two
    /// events at one instant, or the walk failed); `None` when it was. Then the multipliers are unknown and the
    /// stability uncertain.
    pub jacobian_failure: Option<String>,
    /// `stability == Stability::Stable`: all multipliers inside the unit circle by more than the error
    /// estimate.
    pub stable: bool,
    /// Leg 2 is held at its compression stop at the section (`min_length`, docs/model.md section 6): the map,
    /// its Jacobian and the multipliers are over `dtheta/dt` alone (the other two coordinates are fixed after
    /// one step: their multipliers are 0).
    pub rear_held: bool,
    /// With Coulomb friction, the coordinates of the section the map acts on, which are the rows and columns
    /// of `jacobian`: `["L2", "thetadot", "L2dot"]` where Leg 2's tip is at rest at the section, with `"slip"`
    /// after them where it slips there (docs/model.md section 12; `["thetadot"]` / `["thetadot", "slip"]`
    /// with `rear_held` or rigid legs). Absent without friction.
    pub section_coordinates: Option<Vec<&'static str>>,
}

/// The stability verdict of a gait, honest about the Jacobian's error estimate `e`: `Stable` only when the
/// largest `|multiplier| + e < 1`, `Unstable` when `|multiplier| - e > 1`, `Uncertain` otherwise (also when no
/// error estimate was made).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stability {
    /// Every multiplier inside the unit circle, by more than the error estimate.
    Stable,
    /// A multiplier outside the unit circle, by more than the error estimate.
    Unstable,
    /// The error estimate straddles the unit circle (or is unknown).
    Uncertain,
}

impl Stability {
    /// The verdict for the largest multiplier modulus `max_floquet` and the error estimate `error`.
    pub fn judge(max_floquet: f64, error: f64) -> Stability {
        if !(max_floquet.is_finite() && error.is_finite()) {
            Stability::Uncertain
        } else if max_floquet + error < 1.0 {
            Stability::Stable
        } else if max_floquet - error > 1.0 {
            Stability::Unstable
        } else {
            Stability::Uncertain
        }
    }
}

impl std::fmt::Display for Stability {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Stability::Stable => "stable",
            Stability::Unstable => "unstable",
            Stability::Uncertain => "uncertain",
        })
    }
}

/// Newton stops after this many consecutive iterations with a freshly computed `DP` that fail to halve the
/// residual.
pub(crate) const MAX_POOR_ITERATIONS: usize = 3;

/// Largest entry of `|v|`.
fn norm(v: &DVector<f64>) -> f64 {
    v.amax()
}

/// A fixed point of the step map, without its stability.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FixedPoint {
    /// `s*`.
    pub section: SectionState,
    /// The step from `s*` (its report carries the DLS indicators).
    pub outcome: StepOutcome,
    /// `max |P(s*) - s*|`.
    pub residual: f64,
    /// Newton iterations used.
    pub iterations: usize,
    /// Leg 2 is held at its compression stop at `s*`: the map acted on `dtheta/dt` alone.
    pub rear_held: bool,
}

/// Find the gait from `initial`: `transient_steps` steps of the map, then Newton's method on `P(s) - s`,
/// then `DP(s*)` and its eigenvalues.
///
/// `jacobian_guess`, if given (e.g. the neighbour's `DP` in a continuation), is used as the Newton matrix as
/// long as the residual falls at least tenfold per iteration; otherwise `DP` is recomputed.
pub fn find_gait(
    map: &StepMap,
    initial: &SectionState,
    options: &GaitOptions,
    jacobian_guess: Option<&DMatrix<f64>>,
) -> Result<Gait, GaitError> {
    let fp = solve_fixed_point(map, initial, options, jacobian_guess)?;
    Ok(gait_with_jacobian(map, &fp, options))
}

/// [`find_gait`] from a section state `s` at which Newton's method on this map has just converged (a
/// continuation step's), without evaluating the map there once more: the walk of the exact derivatives is
/// that evaluation (the same walk, bit for bit), and the gait is the one [`find_gait`] gives (`iterations` 0)
/// once its residual is checked. Where that check or the derivatives fail, or the first step of
/// [`solve_fixed_point`] could move `s` (onto the held set, or onto the slipping section with Coulomb
/// friction), [`find_gait`] itself.
pub(crate) fn gait_at_converged(
    map: &StepMap,
    s: &SectionState,
    options: &GaitOptions,
    jacobian_guess: Option<&DMatrix<f64>>,
) -> Result<Gait, GaitError> {
    let params = map.model().params();
    let may_move = first_step_may_move(map, s) != (false, false);
    let on = map.on_section_of(s);
    let checked = options.validate().is_ok() && friction_admits_gaits(params).is_ok();
    let converged = (!may_move && checked)
        .then(|| gait_jacobian(map, s, options.parameter, options.estimates()).ok())
        .flatten()
        .and_then(|j| {
            let residual = norm(&(on.reduce(&j.outcome.next) - on.reduce(s)));
            let fp = FixedPoint {
                section: s.pinned(map.model()),
                outcome: j.outcome,
                residual,
                iterations: 0,
                rear_held: on.rear_held(),
            };
            (residual < options.tolerance).then_some((fp, j))
        });
    match converged {
        Some((fp, j)) => {
            let gait = gait_from(&fp, Ok(j), params.has_friction());
            Ok(with_section_coordinates(map, &on, gait))
        }
        None => find_gait(map, s, options, jacobian_guess),
    }
}

/// The gait at the fixed point `fp` of `map` with its exact `DP` (and `dP/dp` if asked for) and the error
/// estimate of [`super::derivative::gait_jacobian`]; where the map is not differentiable at `fp` (or a
/// perturbed walk fails), the gait without multipliers and the reason in [`Gait::jacobian_failure`].
pub(crate) fn gait_with_jacobian(map: &StepMap, fp: &FixedPoint, options: &GaitOptions) -> Gait {
    let on = map.on_section_of(&fp.section);
    let jacobian = gait_jacobian(map, &fp.section, options.parameter, options.estimates());
    let jacobian = jacobian.map_err(|e| (on.free_coordinates().len(), e.to_string()));
    let friction = map.model().params().has_friction();
    with_section_coordinates(map, &on, gait_from(fp, jacobian, friction))
}

/// `gait` with the names of its section coordinates where the model has Coulomb friction (`on` is `map` on
/// the gait's section).
fn with_section_coordinates(map: &StepMap, on: &StepMap, gait: Gait) -> Gait {
    let coordinates = map
        .model()
        .params()
        .has_friction()
        .then(|| on.free_coordinate_names());
    Gait {
        section_coordinates: coordinates,
        ..gait
    }
}

/// The gait at `fp` with its exact derivatives (and the event sequence of its step where the model has
/// `friction`), or without multipliers and with the reason the derivatives failed (`(n, reason)`, `n` the
/// number of free coordinates).
fn gait_from(
    fp: &FixedPoint,
    jacobian: Result<GaitJacobian, (usize, String)>,
    friction: bool,
) -> Gait {
    match jacobian {
        Ok(j) => {
            let mut gait = gait_at(fp, j.jacobian, j.error);
            gait.dp_dparam = j.dparam;
            gait.signature = friction.then_some(j.signature);
            gait
        }
        Err((n, failure)) => {
            let mut gait = gait_at(fp, DMatrix::from_element(n, n, f64::NAN), f64::NAN);
            gait.jacobian_failure = Some(failure);
            gait
        }
    }
}

/// Can the parameters have a gait at all, as far as Coulomb friction goes? Over one period of any gait (of any
/// period `k`) the wheel's momentum returns, so the ground's tangential forces and impulses add up to
/// `-M g sin(slope) T` and its normal ones to `M g cos(slope) T` (`M` the whole wheel's mass, `T` the period;
/// stopper impulses are internal). Each force and impulse lies in the friction cone, `|lambda_t| <= mu
/// lambda_n`, so `tan|slope| <= mu`: below that no gait exists, and the search says so at once
/// ([`GaitError::FrictionBelowSlope`]) instead of walking a wheel that slides away. Not with `rear_exit =
/// "reset"`, whose reset of a leaving leg changes the momentum without a force.
pub(crate) fn friction_admits_gaits(params: &Params) -> Result<(), GaitError> {
    let tan_slope = params.slope.abs().tan();
    if params.has_friction() && params.rear_exit != RearExit::Reset && params.friction < tan_slope {
        return Err(GaitError::FrictionBelowSlope {
            friction: params.friction,
            tan_slope,
        });
    }
    Ok(())
}

/// May the first step of Newton's method from `s` move it, onto the held set (`s` not held where the model has
/// a compression stop) or onto the slipping section (`s` at rest where the model has Coulomb friction)? See
/// [`solve_fixed_point_asking`].
fn first_step_may_move(map: &StepMap, s: &SectionState) -> (bool, bool) {
    let params = map.model().params();
    (
        params.min_length > 0.0 && !s.rear_held(map.model()),
        params.has_friction() && !s.slips(),
    )
}

/// The fixed point alone (no Jacobian at the end): what threshold searches need.
pub(crate) fn solve_fixed_point(
    map: &StepMap,
    initial: &SectionState,
    options: &GaitOptions,
    jacobian_guess: Option<&DMatrix<f64>>,
) -> Result<FixedPoint, GaitError> {
    solve_fixed_point_asking(
        map,
        initial,
        options,
        &mut || jacobian_guess.cloned(),
        false,
    )
}

/// [`solve_fixed_point`] with the guess of `DP` asked of `jacobian_guess` once the map is evaluated at the
/// start (not if that evaluation fails, where no matrix could help: a continuation step tells the two
/// failures apart by it). `undamped`: fail as soon as a Newton step taken with `DP` at its iterate must be
/// damped (its full length does not reduce the residual; a matrix from elsewhere is first replaced by `DP`
/// there, as always), a quick test that Newton's method converges from `initial` as it is.
pub(crate) fn solve_fixed_point_asking(
    map: &StepMap,
    initial: &SectionState,
    options: &GaitOptions,
    jacobian_guess: &mut dyn FnMut() -> Option<DMatrix<f64>>,
    undamped: bool,
) -> Result<FixedPoint, GaitError> {
    options.validate().map_err(|e| GaitError::InvalidOptions {
        message: e.to_string(),
    })?;
    friction_admits_gaits(map.model().params())?;
    let NewtonStart {
        section,
        first_step,
    } = newton_start(map, initial, options)?;
    let map = &map.on_section_of(&section);
    let n = map.free_coordinates().len();
    let trial = match first_step {
        // The same map (`s` is not held) at the same point.
        Some(out) => {
            let r = map.reduce(&out.next) - map.reduce(&section);
            Trial {
                section,
                outcome: out,
                r,
            }
        }
        None => Trial::at(map, section, 1)?,
    };
    // A guess for the other coordinates (a neighbour held where this one is not) is no guess.
    let newton_matrix: Option<DMatrix<f64>> = jacobian_guess()
        .filter(|j| j.nrows() == n)
        .map(|j| j - DMatrix::identity(n, n));
    let mut newton = Newton::new(map, options, undamped, trial, newton_matrix);
    while newton.residual() >= options.tolerance {
        newton.iterate()?;
    }
    Ok(newton.fixed_point())
}

/// Where Newton's method starts: the section state and, where it was walked already, the step from it.
struct NewtonStart {
    section: SectionState,
    first_step: Option<StepOutcome>,
}

/// The start of Newton's method from `initial`: the end of the transient, moved by one more step onto the
/// held set or onto the slipping section where that step lands there (see [`solve_fixed_point_asking`]).
fn newton_start(
    map: &StepMap,
    initial: &SectionState,
    options: &GaitOptions,
) -> Result<NewtonStart, GaitError> {
    // The transient is one continuous walk (touchdowns on the way may be off the section, see
    // `WalkError::OffSection`); only where it ends must be on the section.
    let mut s = *initial;
    if options.transient_steps > 0 {
        let transient = |step: usize| move |source| GaitError::Transient { step, source };
        let mut walker = map.walker(initial).map_err(transient(1))?;
        for step in 1..=options.transient_steps {
            walker.step(None).map_err(transient(step))?;
        }
        s = walker
            .section()
            .map_err(transient(options.transient_steps))?;
    }
    // A walk whose stance leg is held at its compression stop at touchdown starts every step with Leg 2 held
    // there (`L2 = min_length`, `dL2/dt = 0`): one more step takes a start that is not onto that set, and the
    // map then acts on `dtheta/dt` alone (`StepMap::on_section_of`).
    // A step that stays off the held set is the first one Newton's method needs: kept, not walked again.
    // With Coulomb friction, the same for a start whose stance tip is at rest while the next touchdown's
    // slips: the map then has the slip velocity as a coordinate (the first step is walked on the map that
    // has it, which accepts either).
    let mut first_step = None;
    let (held_may_start, slip_may_start) = first_step_may_move(map, &s);
    if held_may_start || slip_may_start {
        if let Ok(first) = map.clone().with_slip(true).eval(&s) {
            let held = held_may_start && first.next.rear_held(map.model());
            let slips = slip_may_start && first.next.slips();
            if held || slips {
                s = first.next;
            } else {
                first_step = Some(first);
            }
        }
    }
    Ok(NewtonStart {
        section: s,
        first_step,
    })
}

/// The period-1 gait at the fixed point `fp` with Jacobian `dp` and its error estimate (`dp` not finite: no
/// multipliers, stability uncertain).
pub(crate) fn gait_at(fp: &FixedPoint, dp: DMatrix<f64>, jacobian_error: f64) -> Gait {
    let mut multipliers: Vec<Complex<f64>> = if dp.iter().all(|v| v.is_finite()) {
        dp.complex_eigenvalues().iter().copied().collect()
    } else {
        Vec::new()
    };
    multipliers.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
    let max_floquet = multipliers.first().map_or(f64::NAN, |z| z.norm());
    let report = &fp.outcome.report;
    Gait {
        period_k: 1,
        section: fp.section,
        theta: report.theta,
        residual: fp.residual,
        iterations: fp.iterations,
        lambda_i4: report.indicators.lambda_i4,
        lambda_2_plus: report.indicators.lambda_2_plus,
        lambda_4_plus: report.indicators.lambda_4_plus,
        branch: report.branch,
        period: report.period,
        step_length: report.step_length,
        speed: report.speed,
        dls_duration: report.dls_duration,
        rear_contact_duration: report.rear_contact_duration,
        scuffing: report.scuffing,
        bounce: report.bounce,
        energy_residual: report.energy.residual,
        contact: report.contact,
        cycle: vec![*report],
        jacobian: dp
            .row_iter()
            .map(|row| row.iter().copied().collect())
            .collect(),
        jacobian_error,
        dp_dparam: None,
        floquet_multipliers: multipliers.iter().map(|z| [z.re, z.im]).collect(),
        max_floquet,
        stability: Stability::judge(max_floquet, jacobian_error),
        jacobian_failure: None,
        signature: None,
        stable: Stability::judge(max_floquet, jacobian_error) == Stability::Stable,
        rear_held: fp.rear_held,
        section_coordinates: None,
    }
}

/// The section state with its `theta`, as written in `gait.json`.
#[derive(Debug, Clone, Serialize)]
struct SectionRecord {
    #[serde(flatten)]
    state: SectionState,
    theta: f64,
}

/// The serialized shape of a [`Gait`].
#[derive(Debug, Clone, Serialize)]
struct GaitRecord {
    period_k: usize,
    section: SectionRecord,
    residual: f64,
    iterations: usize,
    #[serde(rename = "lambda_I4")]
    lambda_i4: f64,
    lambda_2_plus: f64,
    lambda_4_plus: f64,
    branch: Branch,
    period: f64,
    step_length: f64,
    speed: f64,
    dls_duration: f64,
    rear_contact_duration: f64,
    scuffing: bool,
    bounce: bool,
    energy_residual: f64,
    #[serde(flatten)]
    contact: ContactAudit,
    cycle: Vec<StepReport>,
    jacobian: Vec<Vec<f64>>,
    jacobian_error: f64,
    #[serde(rename = "dP_dparam", skip_serializing_if = "Option::is_none")]
    dp_dparam: Option<ParamDerivative>,
    floquet_multipliers: Vec<[f64; 2]>,
    max_floquet: f64,
    stability: Stability,
    #[serde(skip_serializing_if = "Option::is_none")]
    jacobian_failure: Option<String>,
    stable: bool,
    /// Written only when true (a compression stop holds Leg 2 at the section), so other gaits' files are as
    /// before.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    rear_held: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    section_coordinates: Option<Vec<&'static str>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    signature: Option<String>,
}

impl From<Gait> for GaitRecord {
    fn from(g: Gait) -> GaitRecord {
        GaitRecord {
            period_k: g.period_k,
            section: SectionRecord {
                state: g.section,
                theta: g.theta,
            },
            residual: g.residual,
            iterations: g.iterations,
            lambda_i4: g.lambda_i4,
            lambda_2_plus: g.lambda_2_plus,
            lambda_4_plus: g.lambda_4_plus,
            branch: g.branch,
            period: g.period,
            step_length: g.step_length,
            speed: g.speed,
            dls_duration: g.dls_duration,
            rear_contact_duration: g.rear_contact_duration,
            scuffing: g.scuffing,
            bounce: g.bounce,
            energy_residual: g.energy_residual,
            contact: g.contact,
            cycle: g.cycle,
            jacobian: g.jacobian,
            jacobian_error: g.jacobian_error,
            dp_dparam: g.dp_dparam,
            floquet_multipliers: g.floquet_multipliers,
            max_floquet: g.max_floquet,
            stability: g.stability,
            jacobian_failure: g.jacobian_failure,
            stable: g.stable,
            rear_held: g.rear_held,
            section_coordinates: g.section_coordinates,
            signature: g.signature,
        }
    }
}

impl Gait {
    /// `DP(s*)` as a matrix (`NaN` entries if it could not be computed, see [`Gait::jacobian_failure`]).
    pub fn jacobian_matrix(&self) -> DMatrix<f64> {
        let n = self.jacobian.len();
        DMatrix::from_fn(n, n, |i, j| self.jacobian[i][j])
    }

    /// `DP(s*)` as a Newton matrix for a neighbouring search, if it was computed.
    pub fn jacobian_guess(&self) -> Option<DMatrix<f64>> {
        let dp = self.jacobian_matrix();
        (dp.nrows() > 0 && dp.iter().all(|v| v.is_finite())).then_some(dp)
    }
}
