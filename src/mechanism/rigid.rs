//! The walk of a walker with rigid legs and point feet (docs/model.md section 13): single support on the
//! stance foot between heel strikes, the heel strike decided by the DLS indicator `lambda_I4` and followed by the
//! legs' exchange of roles, and the step map on the section just after a heel strike.
//!
//! A step integrates the single-support dynamics (DOP853, [`crate::integrate`]) until the swing foot's height
//! crosses zero from above while the foot is ahead of the stance foot (heel strike); the crossing near
//! mid-swing, where the foot comes up through the ground, is not from above, and the start (the foot leaving
//! the ground behind the stance foot) is not ahead: both are foot scuffing, ignored as the papers do and
//! counted. The event is located on the dense output (`crate::integrate::locate_root`); the integration
//! fails where the stance foot's normal force turns negative (the walker would leave the ground) or the hip
//! falls below the ground.

use nalgebra::{DMatrix, DVector, SVector};

use super::constrained::ConstrainedError;
use super::sensitivity::{NotDifferentiable, Tape};
use super::Real;
use crate::integrate::{locate_root, Dop853, IntegrationError, Method, OdeSystem, Tolerances};

/// What a rigid-legged walker gives the walk (the assembled compass gait and the simplest walking model, whose
/// massless legs leave it only reduced equations, implement it alike). `N` coordinates, `Y = 2 N` integrated
/// states `(q, q')`.
///
/// The dynamics, the guard, the heel strike and the section's maps are written over any [`Real`] with the
/// walker's constants as [`RigidWalker::Constants`] (as [`super::Mechanism::constants`] makes them): the walk
/// runs them on `f64`, and its exact derivatives (`super::rigid_derivative`) on dual numbers, one of the
/// constants carrying `d/dp`.
pub trait RigidWalker<const N: usize, const Y: usize> {
    /// The constants of the walker's equations, over a [`Real`].
    type Constants<T: Real>: Copy;

    /// The walker's name.
    fn name(&self) -> &'static str;

    /// The names of the coordinates of the section ([`RigidWalker::section_of`]).
    fn section_names(&self) -> Vec<&'static str>;

    /// The constants, each made a `T` by `value(key, value)` (the key as in a configuration file).
    fn rigid_constants<T: Real>(
        &self,
        value: &dyn Fn(&'static str, f64) -> T,
    ) -> Self::Constants<T>;

    /// `q''` in single support, and the stance foot's normal force (in the walker's force unit), with the
    /// constants `c`.
    fn single_support_with<T: Real>(
        &self,
        c: &Self::Constants<T>,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
    ) -> Result<(SVector<T, N>, T), ConstrainedError>;

    /// The swing foot's height above the ground (the heel strike's guard) and its distance ahead of the stance
    /// foot along the slope, with the constants `c`.
    fn swing_foot_with<T: Real>(&self, c: &Self::Constants<T>, q: &SVector<T, N>) -> (T, T);

    /// The hip's height above the ground.
    fn hip_height(&self, q: &SVector<f64, N>) -> f64;

    /// The heel strike at `(q, q'-)` with the constants `c`: `lambda_I4`, the rear foot's normal impulse with
    /// both feet held (the paper's (A1)), and the traditional impact (the new foot held, the rear one released)
    /// followed by the legs' exchange of roles, whatever the sign of `lambda_I4`.
    fn transition_with<T: Real>(
        &self,
        c: &Self::Constants<T>,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
    ) -> Result<Transition<N, T>, ConstrainedError>;

    /// The heel strike at `(q, q'-)` ([`RigidWalker::transition_with`] on `f64`), the walker stopping in double
    /// support where `lambda_I4 >= 0`, and the energy it takes.
    fn heel_strike(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Result<HeelStrike<N>, ConstrainedError>;

    /// The mechanical energy `T + V`.
    fn mechanical_energy(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64;

    /// The free coordinates of a state just after a heel strike (the section; the others follow from the
    /// stance foot on the ground and both feet on it), with the constants `c`.
    fn section_with<T: Real>(
        &self,
        c: &Self::Constants<T>,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
    ) -> Vec<T>;

    /// The state just after a heel strike with the free coordinates `s`, with the constants `c`.
    fn state_at_section_with<T: Real>(
        &self,
        c: &Self::Constants<T>,
        s: &[T],
    ) -> (SVector<T, N>, SVector<T, N>);

    /// `P^period(x)` with its exact `DP` (and `dP/dp` in the parameter `param`, one of the walker's keys):
    /// [`super::rigid_derivative::step_map_derivative`] with the sizes of this walker's dual numbers (a const
    /// generic cannot be computed from `N` on stable Rust, so each walker names them).
    fn step_map_derivative(
        &self,
        x: &DVector<f64>,
        param: Option<&str>,
        period: usize,
        options: &RigidOptions,
    ) -> Result<StepMapDerivative<N>, DerivativeError>;

    /// The constants as `f64`.
    fn rigid_constants_f64(&self) -> Self::Constants<f64> {
        self.rigid_constants(&|_, v| v)
    }

    /// `q''` in single support and the stance foot's normal force ([`RigidWalker::single_support_with`]).
    fn single_support(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> Result<(SVector<f64, N>, f64), ConstrainedError> {
        self.single_support_with(&self.rigid_constants_f64(), q, qd)
    }

    /// The swing foot's height and its distance ahead ([`RigidWalker::swing_foot_with`]).
    fn swing_foot(&self, q: &SVector<f64, N>) -> (f64, f64) {
        self.swing_foot_with(&self.rigid_constants_f64(), q)
    }

    /// The section's coordinates of a state just after a heel strike ([`RigidWalker::section_with`]).
    fn section_of(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> DVector<f64> {
        DVector::from_vec(self.section_with(&self.rigid_constants_f64(), q, qd))
    }

    /// The state just after a heel strike with the section's coordinates `s`
    /// ([`RigidWalker::state_at_section_with`]).
    fn state_at_section(&self, s: &DVector<f64>) -> (SVector<f64, N>, SVector<f64, N>) {
        self.state_at_section_with(&self.rigid_constants_f64(), s.as_slice())
    }
}

/// The heel strike's transition over a [`Real`] ([`RigidWalker::transition_with`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition<const N: usize, T: Real = f64> {
    /// `lambda_I4`: the rear foot's normal impulse with both feet held (DLS indicator 1).
    pub lambda_i4: T,
    /// Coordinates after the legs exchange roles.
    pub q: SVector<T, N>,
    /// Velocities after the traditional impact, in the new roles.
    pub qd: SVector<T, N>,
}

/// A heel strike's outcome.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeelStrike<const N: usize> {
    /// `lambda_I4`: the rear foot's normal impulse with both feet held (DLS indicator 1).
    pub lambda_i4: f64,
    /// Coordinates after the legs exchange roles (the new stance foot at `x = 0` where the walker has one).
    pub q: SVector<f64, N>,
    /// Velocities after the impact, in the new roles; `None` where `lambda_i4 >= 0`: the walker stops in
    /// double support.
    pub qd: Option<SVector<f64, N>>,
    /// The energy the impact took (`T + V` before less after, at the same place).
    pub loss: f64,
}

/// How a step of a rigid-legged walker is integrated.
#[derive(Debug, Clone, Copy)]
pub struct RigidOptions {
    /// The integrator's tolerances.
    pub tolerances: Tolerances,
    /// The longest a step may last (in the walker's time unit).
    pub max_step_time: f64,
    /// Events are located to this time.
    pub event_time_tol: f64,
    /// Asked every [`STOP_CHECK_STEPS`] integrator steps whether to stop (the caller's interrupt: Ctrl-C);
    /// `None`: never.
    pub stop: Option<fn() -> bool>,
    /// Where the step map has no exact derivative (a grazing heel strike, `lambda_I4` at 0), take `DP` and
    /// `dP/dp` by central differences and say so (`true`), or fail (`false`, the default).
    pub difference_fallback: bool,
}

/// Integrator steps between two questions of [`RigidOptions::stop`].
pub const STOP_CHECK_STEPS: usize = 1000;

/// A swing foot that meets the ground less than this far ahead of the stance foot, relative to the hip's
/// height, is passing it (the legs of equal length coincide there: foot scuffing near mid-swing), not striking
/// the ground ahead: a heel strike is at least a step's length ahead.
pub const MIN_STRIDE: f64 = 1e-6;

impl Default for RigidOptions {
    fn default() -> RigidOptions {
        RigidOptions {
            tolerances: Tolerances {
                rtol: 1e-12,
                atol: 1e-13,
                h_max: 0.05,
                h_min: 1e-14,
            },
            max_step_time: 20.0,
            event_time_tol: 1e-14,
            stop: None,
            difference_fallback: false,
        }
    }
}

/// Why a step of a rigid-legged walker failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RigidError {
    /// The integration failed.
    #[error("integration failed: {0}")]
    Integration(#[from] IntegrationError),
    /// A constrained solve failed.
    #[error("{0}")]
    Constrained(#[from] ConstrainedError),
    /// No heel strike within the longest step.
    #[error("no heel strike within {time} time units")]
    Stalled {
        /// The time walked.
        time: f64,
    },
    /// The stance foot's normal force turned negative: the walker would leave the ground.
    #[error("the stance foot would leave the ground at t = {time} (normal force {force:e})")]
    StanceLiftsOff {
        /// When.
        time: f64,
        /// The normal force there.
        force: f64,
    },
    /// The hip reached the ground.
    #[error("the walker fell (hip on the ground) at t = {time}")]
    Fell {
        /// When.
        time: f64,
    },
    /// The caller asked the walk to stop ([`RigidOptions::stop`]).
    #[error("interrupted")]
    Interrupted,
    /// `lambda_I4 >= 0` at heel strike: with rigid legs, double support holds the walker still.
    #[error("the walker stops in double support (lambda_I4 = {lambda_i4:e} >= 0)")]
    StopsInDoubleSupport {
        /// The DLS indicator.
        lambda_i4: f64,
    },
}

impl RigidError {
    /// Short machine-readable name.
    pub fn kind(&self) -> &'static str {
        match self {
            RigidError::Integration(_) => "integration_failed",
            RigidError::Constrained(_) => "constrained_solve_failed",
            RigidError::Stalled { .. } => "stalled",
            RigidError::StanceLiftsOff { .. } => "stance_lifts_off",
            RigidError::Fell { .. } => "fell",
            RigidError::StopsInDoubleSupport { .. } => "stops_in_double_support",
            RigidError::Interrupted => "interrupted",
        }
    }
}

/// One step from just after a heel strike to just after the next.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidStep<const N: usize> {
    /// Coordinates just after the next heel strike (roles exchanged).
    pub q: SVector<f64, N>,
    /// Velocities just after it.
    pub qd: SVector<f64, N>,
    /// The step's duration.
    pub period: f64,
    /// The heel strike's DLS indicator.
    pub lambda_i4: f64,
    /// The energy the heel strike took (`T + V` before less after).
    pub impact_loss: f64,
    /// The largest `|T + V - (T + V)_0|` over the step's integrator steps (energy is conserved in single
    /// support): the step's energy audit.
    pub energy_drift: f64,
    /// Crossings of the ground by the swing foot that were not heel strikes (scuffing).
    pub scuffs: usize,
}

/// The single-support vector field of `walker` (with `N` coordinates), as the integrator sees it.
struct SingleSupport<'w, W, const N: usize>(&'w W);

impl<W: RigidWalker<N, Y>, const N: usize, const Y: usize> OdeSystem<Y>
    for SingleSupport<'_, W, N>
{
    fn rhs(&self, _t: f64, y: &SVector<f64, Y>) -> SVector<f64, Y> {
        let (q, qd) = unpack::<N, Y>(y);
        match self.0.single_support(&q, &qd) {
            Ok((qdd, _)) => pack(&qd, &qdd),
            Err(_) => SVector::repeat(f64::NAN),
        }
    }
}

/// `(q, q')` as one state.
pub(crate) fn pack<const N: usize, const Y: usize>(
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
) -> SVector<f64, Y> {
    assert_eq!(Y, 2 * N, "a rigid walker integrates (q, q')");
    let mut y = SVector::<f64, Y>::zeros();
    y.rows_mut(0, N).copy_from(q);
    y.rows_mut(N, N).copy_from(qd);
    y
}

/// `(q, q')` of a state.
pub(crate) fn unpack<const N: usize, const Y: usize>(
    y: &SVector<f64, Y>,
) -> (SVector<f64, N>, SVector<f64, N>) {
    (
        SVector::from_iterator(y.rows(0, N).iter().copied()),
        SVector::from_iterator(y.rows(N, N).iter().copied()),
    )
}

/// The heel-strike event function: the swing foot's height where it is ahead of the stance foot (by more than
/// [`MIN_STRIDE`] of the hip's height), `None` where it is not (behind the stance foot or beside it). A heel
/// strike is a crossing of zero from above between two samples that are both ahead: a foot that comes ahead
/// while under the ground (passing the stance foot from above, the legs' coincidence) is scuffing, not
/// striking (as `super::legged`'s `Event::Strike` does).
fn strike_height<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    y: &SVector<f64, Y>,
) -> Option<f64> {
    let (q, _) = unpack::<N, Y>(y);
    let (height, ahead) = walker.swing_foot(&q);
    (ahead > MIN_STRIDE * walker.hip_height(&q).abs()).then_some(height)
}

/// One step of `walker` from `(q, q')` just after a heel strike (see the module documentation).
pub fn rigid_step<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
    options: &RigidOptions,
) -> Result<RigidStep<N>, RigidError> {
    walk_step(walker, (q, qd), options, None)
}

/// The single support of a rigid walker: its one phase (the stance foot held).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SingleSupportPhase;

/// The heel strike: the event that ends a rigid walker's step (the swing foot's height reaching 0 ahead).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeelStrikeEvent;

/// The record of a rigid walker's step ([`rigid_step_taped`]): its accepted integrator steps and its heel
/// strike.
pub type RigidTape<const Y: usize> = Tape<SingleSupportPhase, HeelStrikeEvent, Y>;

/// [`rigid_step`], recording on `tape` what its exact derivatives replay (`super::rigid_derivative`): the
/// start, every accepted integrator step and the heel strike (its time and the state then, before the
/// impact).
pub fn rigid_step_taped<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    options: &RigidOptions,
    tape: &mut RigidTape<Y>,
) -> Result<RigidStep<N>, RigidError> {
    walk_step(walker, (q, qd), options, Some(tape))
}

/// The step of [`rigid_step`], recorded on `tape` if given.
fn walk_step<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    options: &RigidOptions,
    mut tape: Option<&mut RigidTape<Y>>,
) -> Result<RigidStep<N>, RigidError> {
    let system = SingleSupport::<W, N>(walker);
    let y0 = pack::<N, Y>(q, qd);
    let e0 = walker.mechanical_energy(q, qd);
    let mut integrator = Dop853::new(&system, 0.0, y0, options.tolerances);
    if let Some(tape) = tape.as_deref_mut() {
        *tape = Tape::new(Method::Dop853);
        tape.begin(SingleSupportPhase, 0.0, y0);
    }
    let (mut scuffs, mut energy_drift) = (0, 0.0f64);
    let mut below = walker.swing_foot(q).0 < 0.0;
    let mut taken = 0usize;
    loop {
        taken += 1;
        if taken.is_multiple_of(STOP_CHECK_STEPS) && options.stop.is_some_and(|stop| stop()) {
            return Err(RigidError::Interrupted);
        }
        let step = integrator.step(&system, options.max_step_time)?;
        let (t0, t1) = (step.t0(), step.t1());
        if let Some(tape) = tape.as_deref_mut() {
            tape.step(step.h(), t1);
        }
        let (g0, g1) = (
            strike_height(walker, step.y0()),
            strike_height(walker, step.y1()),
        );
        let (q1, qd1) = unpack::<N, Y>(step.y1());
        energy_drift = energy_drift.max((walker.mechanical_energy(&q1, &qd1) - e0).abs());
        // A heel strike: the height crossing zero from above, the foot ahead at both ends of the step.
        let strike = match (g0, g1) {
            (Some(g0), Some(g1)) if g0 > 0.0 && g1 <= 0.0 => Some((g0, g1)),
            _ => None,
        };
        if let Some((g0, g1)) = strike {
            let t = locate_root(
                &step,
                |_, y| walker.swing_foot(&unpack::<N, Y>(y).0).0,
                t0,
                g0,
                t1,
                g1,
                options.event_time_tol,
            );
            let y_minus = step.eval(t);
            if let Some(tape) = tape.as_deref_mut() {
                tape.end(t, HeelStrikeEvent, y_minus);
            }
            let (q_minus, qd_minus) = unpack::<N, Y>(&y_minus);
            return finish_step(walker, (&q_minus, &qd_minus), t, (scuffs, energy_drift));
        }
        // A crossing of the ground that is no heel strike: the swing foot comes up through it (scuffing).
        let now_below = walker.swing_foot(&q1).0 < 0.0;
        if below && !now_below {
            scuffs += 1;
        }
        below = now_below;
        check_support(walker, (&q1, &qd1), t1)?;
        if t1 >= options.max_step_time {
            return Err(RigidError::Stalled { time: t1 });
        }
    }
}

/// The walker still stands on its stance foot at `(q, q')` at time `t`: a pushing normal force and the hip
/// above the ground.
fn check_support<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    time: f64,
) -> Result<(), RigidError> {
    if walker.hip_height(q) <= 0.0 {
        return Err(RigidError::Fell { time });
    }
    let (_, force) = walker.single_support(q, qd)?;
    if force < 0.0 {
        return Err(RigidError::StanceLiftsOff { time, force });
    }
    Ok(())
}

/// The step's end: the heel strike at `(q, q'-)` at time `t`.
fn finish_step<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    t: f64,
    (scuffs, energy_drift): (usize, f64),
) -> Result<RigidStep<N>, RigidError> {
    let strike = walker.heel_strike(q, qd)?;
    let Some(qd_plus) = strike.qd else {
        return Err(RigidError::StopsInDoubleSupport {
            lambda_i4: strike.lambda_i4,
        });
    };
    Ok(RigidStep {
        q: strike.q,
        qd: qd_plus,
        period: t,
        lambda_i4: strike.lambda_i4,
        impact_loss: strike.loss,
        energy_drift,
        scuffs,
    })
}

/// `P^k(x)` with its exact derivatives ([`RigidWalker::step_map_derivative`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StepMapDerivative<const N: usize> {
    /// `P^k(x)`.
    pub value: DVector<f64>,
    /// `DP^k` at `x`.
    pub jacobian: DMatrix<f64>,
    /// `dP^k/dp` in the parameter asked for.
    pub dparam: Option<DVector<f64>>,
    /// The first step (its duration, DLS indicator, audit).
    pub step: RigidStep<N>,
}

/// Why a step map has no exact derivative here.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DerivativeError {
    /// The walk failed.
    #[error(transparent)]
    Walk(#[from] RigidError),
    /// The walk went, but the map has no derivative there (or the replay could not give it).
    #[error(transparent)]
    NotDifferentiable(#[from] NotDifferentiable),
    /// The parameter asked for is not one of the walker's constants.
    #[error("`{key}` is not a parameter of this walker")]
    UnknownParameter {
        /// The key asked for.
        key: String,
    },
}
