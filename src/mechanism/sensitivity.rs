//! Exact derivatives of a walked step of any hybrid walker on the mechanism interface (docs/model.md sections
//! 10 and 13): the step as the walk took it ([`Tape`]: the phases, the accepted integrator steps of each, the
//! events that ended them), replayed with the variational equations over the very same Runge-Kutta steps, and
//! each event crossed with its saltation.
//!
//! **Phases.** In a phase `q'' = a(q, q', p)` (a [`Hybrid::acceleration`]: a mechanism's constrained
//! accelerations with the phase's rows held, or a walker's reduced equations). The sensitivity
//! `S = d(q, q')/d(x, p)` along `D` directions (the step map's section coordinates and a parameter) obeys
//! `S' = F_y S + F_p`; both products come from one evaluation of `a` on dual numbers whose derivative parts are
//! the rows of `S` (and the parameter's unit direction in the constants), forward-mode automatic
//! differentiation through the very code the walk runs. The augmented state `[y, S]` is integrated with the
//! steps the walk accepted (`Integrator::fixed_step`: the same stages, the same dense output): internal
//! numerical differentiation (Bock 1981), so its state part is the walk's bit for bit (checked at every event:
//! [`NotDifferentiable::Diverged`]) and `S` is the exact derivative of that discretization.
//!
//! **Events.** An event with guard `g(q, q', p) = 0` ([`Hybrid::guard`]), reset `R` ([`Hybrid::reset`]: an
//! impact, a constrained impulse, and a relabeling of the coordinates) and vector fields `f-`, `f+` before and
//! after moves by `dt = -(g_y S + g_p) / (g_y f-)`; the sensitivity after it is
//! `S+ = R_y (S- + f- dt) + R_p - f+ dt` (the saltation matrix for `p = 0`), with no `f+ dt` after the event
//! that ends the step (the section is the event's instant). `g_y S` and `g_y f-` come from one evaluation of
//! the guard on duals carrying `S` and `f-`, `R_y` and `R_p` from the reset on duals. Where the map has no
//! derivative (a grazing event, two events at one instant) the replay says so ([`NotDifferentiable`]).
//!
//! The wheel has its own replay (`crate::variational`, on its reduced constrained solver and its event table);
//! this one knows only [`Hybrid`], so that any walker of the interface (the rigid walkers of
//! `super::rigid_derivative`, walkers with compliant legs and several phases) has its derivatives from it.

use std::fmt::Debug;

use nalgebra::{SMatrix, SVector};

use super::constrained::ConstrainedError;
use super::Real;
use crate::dynamics::Dual;
use crate::integrate::{Integrator, Method, OdeSystem};

/// A guard whose rate along the flow `g_y f-` is at most this times its largest derivative `|g_y S + g_p|`
/// (the event time would move by more than `1 / GRAZING_RATE` time units per unit of the section state or the
/// parameter) is grazing: the flow touches it tangentially and the event time is not a smooth function.
pub const GRAZING_RATE: f64 = 1e-7;

/// Two events less than this apart (in the walker's time unit) are coincident: the step map has a corner there.
pub const COINCIDENT_EVENTS: f64 = 1e-9;

/// A DLS indicator closer to zero than this puts an impact on the border between two branches of the impact
/// procedure (for a rigid walker: `lambda_I4` between the traditional impact and a stop in double support).
pub const BORDER_TOL: f64 = 1e-9;

/// A hybrid walker as its derivatives see it: the dynamics of each phase, the guard of each event and the reset
/// it applies, all over any [`Real`], with the constants over a [`Real`] too (one of them may carry `d/dp`).
/// The walk must run these very functions on `f64` (its vector field `(q', a(q, q'))`), so that the replay
/// reproduces it.
pub trait Hybrid<const N: usize> {
    /// The constants of the equations, over a [`Real`].
    type Constants<T: Real>: Copy;
    /// Which phase (e.g. the rows held: a stance foot, both feet, a stopper).
    type Phase: Copy + Debug + PartialEq;
    /// Which event.
    type Event: Copy + Debug + PartialEq;

    /// The constants, each made a `T` by `value(key, value)` (the key as in a configuration file).
    fn hybrid_constants<T: Real>(
        &self,
        value: &dyn Fn(&'static str, f64) -> T,
    ) -> Self::Constants<T>;

    /// `q''` in `phase` at `(q, q')`.
    fn acceleration<T: Real>(
        &self,
        c: &Self::Constants<T>,
        phase: Self::Phase,
        state: (&SVector<T, N>, &SVector<T, N>),
    ) -> Result<SVector<T, N>, ConstrainedError>;

    /// The guard of `event` ending `phase`: the function of the state whose zero is the event.
    fn guard<T: Real>(
        &self,
        c: &Self::Constants<T>,
        crossing: (Self::Phase, Self::Event),
        state: (&SVector<T, N>, &SVector<T, N>),
    ) -> Result<T, ConstrainedError>;

    /// The reset of `event` at `(q, q'-)`: the state after its impacts and relabeling.
    #[allow(clippy::type_complexity)]
    fn reset<T: Real>(
        &self,
        c: &Self::Constants<T>,
        event: Self::Event,
        state: (&SVector<T, N>, &SVector<T, N>),
    ) -> Result<(SVector<T, N>, SVector<T, N>), ConstrainedError>;
}

/// Why a step has no derivative (or the replay could not give it).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NotDifferentiable {
    /// An event met the flow tangentially ([`GRAZING_RATE`]): the step map is not differentiable there.
    #[error("grazing {event} at t = {time}: the step map is not differentiable there")]
    Grazing {
        /// Time of the event.
        time: f64,
        /// Which event.
        event: String,
    },
    /// Two events within [`COINCIDENT_EVENTS`] of each other: the step map has a corner there.
    #[error("two events at t = {time}: the step map has a corner there and no derivative")]
    CoincidentEvents {
        /// Time of the second event.
        time: f64,
    },
    /// An impact's branch is decided by a DLS indicator within [`BORDER_TOL`] of zero: on the border between
    /// two smooth pieces of the step map, it has only one-sided derivatives.
    #[error("{indicator} = {value:e} at t = {time}: on the border between two impact branches, the step map is not differentiable there")]
    Border {
        /// Time of the impact.
        time: f64,
        /// The indicator.
        indicator: &'static str,
        /// Its value.
        value: f64,
    },
    /// A constrained solve of the replay failed.
    #[error("singular constraint solve at t = {time} in the derivative replay")]
    Singular {
        /// Time.
        time: f64,
    },
    /// The replay's state left the walk's (an internal error: it takes the walk's steps bit for bit).
    #[error("the derivative replay diverged from the walk at t = {time}")]
    Diverged {
        /// Time.
        time: f64,
    },
    /// The recorded step is incomplete (it did not reach its event).
    #[error("the step was not recorded to its end")]
    Incomplete,
}

/// A walked step as the replay needs it: its phases in order, each with its accepted integrator steps and the
/// event that ended it.
#[derive(Debug, Clone, PartialEq)]
pub struct Tape<P, E, const Y: usize> {
    /// The integrator the walk took the steps with.
    pub method: Method,
    /// The phases; the last one's event ends the step.
    pub segments: Vec<Segment<P, E, Y>>,
}

/// One phase of a walked step.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment<P, E, const Y: usize> {
    /// Which phase.
    pub phase: P,
    /// Its start time.
    pub t0: f64,
    /// The state `(q, q')` at its start (after the reset of the event before).
    pub y0: SVector<f64, Y>,
    /// The accepted integrator steps, `(h, t1)` each, every one starting where the one before ended.
    pub steps: Vec<(f64, f64)>,
    /// The event that ended it (inside its last step).
    pub end: Option<SegmentEnd<E, Y>>,
}

/// The event that ended a phase.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentEnd<E, const Y: usize> {
    /// When.
    pub time: f64,
    /// Which event.
    pub event: E,
    /// The state then, on the last step's dense output, before the reset.
    pub y: SVector<f64, Y>,
}

impl<P, E, const Y: usize> Tape<P, E, Y> {
    /// An empty record of a walk with `method`.
    pub fn new(method: Method) -> Tape<P, E, Y> {
        Tape {
            method,
            segments: Vec::new(),
        }
    }

    /// A phase starts at `(t0, y0)`.
    pub fn begin(&mut self, phase: P, t0: f64, y0: SVector<f64, Y>) {
        self.segments.push(Segment {
            phase,
            t0,
            y0,
            steps: Vec::new(),
            end: None,
        });
    }

    /// The phase in progress took an accepted step of size `h` to `t1`.
    pub fn step(&mut self, h: f64, t1: f64) {
        if let Some(segment) = self.segments.last_mut() {
            segment.steps.push((h, t1));
        }
    }

    /// The phase in progress ended with `event` at `(time, y)`.
    pub fn end(&mut self, time: f64, event: E, y: SVector<f64, Y>) {
        if let Some(segment) = self.segments.last_mut() {
            segment.end = Some(SegmentEnd { time, event, y });
        }
    }
}

/// A sensitivity `d(q, q')/d(x, p)`: `Y = 2 N` rows, `D` directions.
pub type Sensitivity<const Y: usize, const D: usize> = SMatrix<f64, Y, D>;

/// The derivatives of a replayed step.
#[derive(Debug, Clone, PartialEq)]
pub struct Replayed<const Y: usize, const D: usize> {
    /// `d(q, q')/d(x, p)` just after the reset of the event that ends the step.
    pub sensitivity: Sensitivity<Y, D>,
    /// The derivative of the step's duration (the last event's time).
    pub duration: SVector<f64, D>,
}

/// The constants of `model` over `Dual<D>`, the parameter `param` (if any) carrying the unit derivative in
/// direction `index`.
pub(crate) fn seeded<H: Hybrid<N>, const N: usize, const D: usize>(
    model: &H,
    param: Option<&str>,
    index: usize,
) -> H::Constants<Dual<D>> {
    model.hybrid_constants(&|key, value| {
        let mut e = SVector::<f64, D>::zeros();
        if param == Some(key) {
            e[index] = 1.0;
        }
        Dual::new(value, e)
    })
}

/// The value of `model`'s constant `key` (as its constants read it), `None` for no such key: the parameters
/// [`seeded`] can carry `d/dp`.
pub(crate) fn constant_value<H: Hybrid<N>, const N: usize>(model: &H, key: &str) -> Option<f64> {
    let found = std::cell::Cell::new(None);
    model.hybrid_constants::<f64>(&|k, v| {
        if k == key {
            found.set(Some(v));
        }
        v
    });
    found.get()
}

/// `(q, q')` as duals: the values `y`, the derivative parts the rows of `s`.
pub(crate) fn state_duals<const N: usize, const Y: usize, const D: usize>(
    y: &SVector<f64, Y>,
    s: &Sensitivity<Y, D>,
) -> (SVector<Dual<D>, N>, SVector<Dual<D>, N>) {
    let at = |i: usize| Dual::new(y[i], s.row(i).transpose());
    (
        SVector::from_fn(|i, _| at(i)),
        SVector::from_fn(|i, _| at(N + i)),
    )
}

/// The derivative parts of `(q, q')` as a sensitivity.
pub(crate) fn sensitivity_of<const N: usize, const Y: usize, const D: usize>(
    q: &SVector<Dual<D>, N>,
    qd: &SVector<Dual<D>, N>,
) -> Sensitivity<Y, D> {
    Sensitivity::from_fn(|i, c| if i < N { q[i].eps[c] } else { qd[i - N].eps[c] })
}

/// `(q, q')` as one state `y` (`Y = 2 N`).
fn join_state<T: Real, const N: usize, const Y: usize>(
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> SVector<T, Y> {
    const { assert!(Y == 2 * N) };
    SVector::from_fn(|i, _| if i < N { q[i] } else { qd[i - N] })
}

/// The vector field `(q', q'')` of `phase` on `f64` (the walk's own), `None` where the phase's solve fails.
fn field<H: Hybrid<N>, const N: usize, const Y: usize>(
    model: &H,
    c: &H::Constants<f64>,
    phase: H::Phase,
    y: &SVector<f64, Y>,
) -> Option<SVector<f64, Y>> {
    let q = SVector::<f64, N>::from_fn(|i, _| y[i]);
    let qd = SVector::<f64, N>::from_fn(|i, _| y[N + i]);
    let qdd = model.acceleration(c, phase, (&q, &qd)).ok()?;
    Some(join_state(&qd, &qdd))
}

/// A phase's vector field with its variational equation, on the augmented state `[y, S]` (`A = Y + Y D`).
struct Variational<'a, H: Hybrid<N>, const N: usize, const Y: usize, const D: usize> {
    model: &'a H,
    c: H::Constants<f64>,
    duals: H::Constants<Dual<D>>,
    phase: H::Phase,
}

impl<H: Hybrid<N>, const N: usize, const Y: usize, const D: usize> Variational<'_, H, N, Y, D> {
    fn split<const A: usize>(a: &SVector<f64, A>) -> (SVector<f64, Y>, Sensitivity<Y, D>) {
        const { assert!(A == Y + Y * D) };
        (
            a.fixed_rows::<Y>(0).into_owned(),
            Sensitivity::from_column_slice(&a.as_slice()[Y..]),
        )
    }

    fn join<const A: usize>(y: &SVector<f64, Y>, s: &Sensitivity<Y, D>) -> SVector<f64, A> {
        const { assert!(A == Y + Y * D) };
        let mut a = SVector::<f64, A>::zeros();
        a.fixed_rows_mut::<Y>(0).copy_from(y);
        a.as_mut_slice()[Y..].copy_from_slice(s.as_slice());
        a
    }
}

impl<H: Hybrid<N>, const N: usize, const Y: usize, const D: usize, const A: usize> OdeSystem<A>
    for Variational<'_, H, N, Y, D>
{
    fn rhs(&self, _t: f64, a: &SVector<f64, A>) -> SVector<f64, A> {
        let (y, s) = Self::split::<A>(a);
        // The state's rate by the walk's own arithmetic, so that the state part is the walk's bit for bit.
        let Some(f) = field(self.model, &self.c, self.phase, &y) else {
            return SVector::repeat(f64::NAN);
        };
        let (q, qd) = state_duals::<N, Y, D>(&y, &s);
        let Ok(qdd) = self.model.acceleration(&self.duals, self.phase, (&q, &qd)) else {
            return SVector::repeat(f64::NAN);
        };
        let ds = Sensitivity::<Y, D>::from_fn(|i, c| {
            if i < N {
                s[(N + i, c)]
            } else {
                qdd[i - N].eps[c]
            }
        });
        Self::join(&f, &ds)
    }
}

/// Replays `tape`, a step of `model` walked with the constants' values of `model` and started with the
/// sensitivity `s0`: the sensitivity just after the reset of its last event, and the derivative of its
/// duration. `D` directions (the parameter `param`'s, if any, the last), `E = D + 1` (the guard's rate rides
/// along), `A = Y + Y D`.
pub fn replay<H, const N: usize, const Y: usize, const D: usize, const E: usize, const A: usize>(
    model: &H,
    param: Option<&str>,
    tape: &Tape<H::Phase, H::Event, Y>,
    s0: &Sensitivity<Y, D>,
) -> Result<Replayed<Y, D>, NotDifferentiable>
where
    H: Hybrid<N>,
{
    const { assert!(E == D + 1 && A == Y + Y * D && Y == 2 * N) };
    let c = model.hybrid_constants(&|_, v| v);
    // The parameter is the last of the `D` directions; with the guard's rate, the last but one of `E`.
    let duals = seeded::<H, N, D>(model, param, D - 1);
    let duals_rate = seeded::<H, N, E>(model, param, D - 1);
    let mut s = *s0;
    let mut last_event: Option<f64> = None;
    for (k, segment) in tape.segments.iter().enumerate() {
        let end = segment.end.as_ref().ok_or(NotDifferentiable::Incomplete)?;
        let system = Variational::<H, N, Y, D> {
            model,
            c,
            duals,
            phase: segment.phase,
        };
        let (y_minus, s_minus) =
            integrate_segment::<H, N, Y, D, A>(&system, tape.method, segment, &s)?;
        if last_event.is_some_and(|t| (end.time - t).abs() < COINCIDENT_EVENTS) {
            return Err(NotDifferentiable::CoincidentEvents { time: end.time });
        }
        last_event = Some(end.time);
        let f_minus = field(model, &c, segment.phase, &y_minus)
            .ok_or(NotDifferentiable::Singular { time: end.time })?;
        let crossing = (segment.phase, end.event, end.time);
        let dt = event_time::<H, N, Y, D, E>(
            model,
            &duals_rate,
            crossing,
            (&y_minus, &s_minus, &f_minus),
        )?;
        let s_event = s_minus + f_minus * dt.transpose();
        let (q, qd) = state_duals::<N, Y, D>(&y_minus, &s_event);
        let (q_plus, qd_plus) = model
            .reset(&duals, end.event, (&q, &qd))
            .map_err(|_| NotDifferentiable::Singular { time: end.time })?;
        let s_plus = sensitivity_of::<N, Y, D>(&q_plus, &qd_plus);
        let Some(next) = tape.segments.get(k + 1) else {
            return Ok(Replayed {
                sensitivity: s_plus,
                duration: dt,
            });
        };
        let f_plus = field(model, &c, next.phase, &next.y0)
            .ok_or(NotDifferentiable::Singular { time: end.time })?;
        s = s_plus - f_plus * dt.transpose();
    }
    Err(NotDifferentiable::Incomplete)
}

/// The variational equations over the recorded steps of `segment` from its start with the sensitivity `s0`: the
/// state and sensitivity at the event that ends it. The state must be the walk's, bit for bit.
fn integrate_segment<H, const N: usize, const Y: usize, const D: usize, const A: usize>(
    system: &Variational<'_, H, N, Y, D>,
    method: Method,
    segment: &Segment<H::Phase, H::Event, Y>,
    s0: &Sensitivity<Y, D>,
) -> Result<(SVector<f64, Y>, Sensitivity<Y, D>), NotDifferentiable>
where
    H: Hybrid<N>,
{
    let end = segment.end.as_ref().ok_or(NotDifferentiable::Incomplete)?;
    let mut t = segment.t0;
    let mut a = Variational::<H, N, Y, D>::join::<A>(&segment.y0, s0);
    let mut f = system.rhs(t, &a);
    let mut at_event = None;
    for &(h, t1) in &segment.steps {
        let last = end.time <= t1;
        let step = Integrator::fixed_step(method, system, (t, &a, &f), (h, t1), last);
        if let Some(dense) = step.dense {
            at_event = Some(dense.eval(end.time));
            break;
        }
        (a, f, t) = (step.y1, step.f1, t1);
    }
    let (y, s) =
        Variational::<H, N, Y, D>::split::<A>(&at_event.ok_or(NotDifferentiable::Incomplete)?);
    if y != end.y || !s.iter().all(|v| v.is_finite()) {
        return Err(NotDifferentiable::Diverged { time: end.time });
    }
    Ok((y, s))
}

/// The derivative of the time of the event that ends a phase, `dt = -(g_y S + g_p) / (g_y f-)`, from one
/// evaluation of the guard on duals whose first `D` directions are the rows of `s` and whose last is the rate
/// `f` (`E = D + 1`); a grazing event has none.
fn event_time<H, const N: usize, const Y: usize, const D: usize, const E: usize>(
    model: &H,
    duals: &H::Constants<Dual<E>>,
    (phase, event, time): (H::Phase, H::Event, f64),
    (y, s, f): (&SVector<f64, Y>, &Sensitivity<Y, D>, &SVector<f64, Y>),
) -> Result<SVector<f64, D>, NotDifferentiable>
where
    H: Hybrid<N>,
{
    let at = |i: usize| {
        let mut e = SVector::<f64, E>::zeros();
        e.fixed_rows_mut::<D>(0).copy_from(&s.row(i).transpose());
        e[D] = f[i];
        Dual::new(y[i], e)
    };
    let q = SVector::<Dual<E>, N>::from_fn(|i, _| at(i));
    let qd = SVector::<Dual<E>, N>::from_fn(|i, _| at(N + i));
    let g = model
        .guard(duals, (phase, event), (&q, &qd))
        .map_err(|_| NotDifferentiable::Singular { time })?;
    let d = g.derivative();
    let rate = d[D];
    let spread = d.fixed_rows::<D>(0).amax();
    if !rate.is_finite() || rate == 0.0 || rate.abs() <= GRAZING_RATE * spread {
        return Err(NotDifferentiable::Grazing {
            time,
            event: format!("{event:?}"),
        });
    }
    Ok(-d.fixed_rows::<D>(0) / rate)
}
