//! The exact derivatives of a legged walker's step map (docs/model.md sections 10 and 13): `DP` and `dP/dp`
//! in one of its parameters, from the walk's record of the step ([`LeggedTape`]) replayed by
//! [`crate::mechanism::sensitivity`].
//!
//! The section's coordinates `x` (and the parameter) are seeded as dual numbers into the state on the section
//! ([`LeggedDerivatives::state_at_section_with`]); the heel strike's impulse at the step's start is taken on
//! them with the units the walk chose ([`LeggedTape::strike`]); each phase is replayed with the variational
//! equations of its active constraints over its very integrator steps, each event crossed with the sensitivity
//! of its guard (a tip's normal force or a stopper's holding force reaching zero, a leg reaching its stopper, a
//! tip reaching the ground) and its reset differentiated (the impulses the walk applied there, in order, and
//! after the heel strike that ends the step the legs' exchange); the section of the state at the end on dual
//! numbers gives `DP` and `dP/dp`. The choices the walk made (which units take an impulse, which constraints a
//! phase holds) are those of the step walked: the derivatives are those of the smooth piece of the map the
//! step lies on, and a step on the border between two pieces (a DLS indicator at zero, a grazing event, two
//! events at one instant) has none ([`NotDifferentiable`]). They are the exact derivatives of the walk's
//! discretization (not of the exact flow, from which they differ by the integration error).

use nalgebra::{DMatrix, DVector, SVector};

use super::walk::{legged_step_taped, Crossing, Event, LeggedOptions, LeggedStep, LeggedTape};
use super::{Legged, LeggedError, Modes};
use crate::dynamics::Dual;
use crate::mechanism::constrained::{accelerations_with, impulse_with, ConstrainedError, Row};
use crate::mechanism::sensitivity::{
    self, replay, seeded, sensitivity_of, state_duals, Hybrid, NotDifferentiable, Segment,
    SegmentEnd, Sensitivity, Tape, BORDER_TOL,
};
use crate::mechanism::Real;

/// What the exact derivatives need of a legged walker beyond its walk: its stoppers, the legs' exchange and
/// its section over any [`Real`] (its [`Legged`] methods are these on `f64`).
pub trait LeggedDerivatives<const N: usize>: Legged<N> {
    /// The stopper's length of leg `leg` (0 the fore, 1 the rear) with the constants `c` (a parameter may
    /// carry `d/dp`).
    fn stopper_with<T: Real>(&self, c: &Self::Constants<T>, leg: usize) -> T;

    /// [`Legged::relabel`] over any [`Real`], with the constants `c`.
    fn relabel_with<T: Real>(
        &self,
        c: &Self::Constants<T>,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
    ) -> (SVector<T, N>, SVector<T, N>);

    /// [`Legged::section_of`] over any [`Real`].
    fn section_with<T: Real>(&self, q: &SVector<T, N>, qd: &SVector<T, N>) -> Vec<T>;

    /// [`Legged::state_at_section`] over any [`Real`], with the constants `c`.
    fn state_at_section_with<T: Real>(
        &self,
        c: &Self::Constants<T>,
        s: &[T],
    ) -> Option<(SVector<T, N>, SVector<T, N>)>;

    /// `P(x)` with its exact `DP` and, for `param`, `dP/dp` ([`replayed_step_map`] with the walker's sizes).
    fn exact_step_map(
        &self,
        x: &DVector<f64>,
        param: Option<&str>,
        options: &LeggedOptions,
    ) -> Result<LeggedDerivative<N>, LeggedDerivativeError>;
}

/// `P(x)` with its exact derivatives.
#[derive(Debug, Clone, PartialEq)]
pub struct LeggedDerivative<const N: usize> {
    /// `P(x)`.
    pub value: DVector<f64>,
    /// `DP(x)`.
    pub jacobian: DMatrix<f64>,
    /// `dP/dp` for the parameter asked for.
    pub dparam: Option<DVector<f64>>,
    /// The step walked.
    pub step: LeggedStep<N>,
}

/// Why a step map has no exact derivative.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LeggedDerivativeError {
    /// The walk failed.
    #[error(transparent)]
    Walk(#[from] LeggedError),
    /// The walk went, but the map has no derivative there (or the replay could not give it).
    #[error(transparent)]
    NotDifferentiable(#[from] NotDifferentiable),
    /// A section state of another size than the walker's section.
    #[error("a section state of {given} values; the walker's section has {expected}")]
    SectionSize {
        /// The section's size.
        expected: usize,
        /// The state's.
        given: usize,
    },
    /// The parameter asked for is not one of the walker's constants.
    #[error("`{key}` is not a parameter of this walker")]
    UnknownParameter {
        /// The key asked for.
        key: String,
    },
}

/// A legged walker as the replay sees it: a phase is its active constraints, an event its guard and the
/// impulses (and, at the heel strike, the exchange of the legs) its reset applied.
struct Replay<'w, W, const N: usize>(&'w W);

impl<W: LeggedDerivatives<N>, const N: usize> Replay<'_, W, N> {
    /// The multiplier of `row` among `rows` in the solve of `rows` at `(q, q')`.
    fn multiplier<T: Real>(
        &self,
        c: &W::Constants<T>,
        rows: &[Row],
        row: Row,
        state: (&SVector<T, N>, &SVector<T, N>),
    ) -> Result<T, ConstrainedError> {
        let solved = accelerations_with(self.0, c, state, rows)?;
        let index = rows.iter().position(|r| *r == row);
        // A row that is not active has no multiplier: the walk never watches it (a NaN guard is grazing).
        Ok(index.map_or(T::lit(f64::NAN), |k| solved.multipliers[k]))
    }

    /// The coordinate of leg `leg`'s stroke.
    fn stroke(&self, leg: usize) -> Option<usize> {
        self.0.strokes()[leg].map(|s| s.coordinate)
    }
}

impl<W: LeggedDerivatives<N>, const N: usize> Hybrid<N> for Replay<'_, W, N> {
    type Constants<T: Real> = W::Constants<T>;
    type Phase = Modes;
    type Event = Crossing;

    fn hybrid_constants<T: Real>(&self, value: &dyn Fn(&'static str, f64) -> T) -> W::Constants<T> {
        self.0.constants(value)
    }

    fn acceleration<T: Real>(
        &self,
        c: &W::Constants<T>,
        modes: Modes,
        state: (&SVector<T, N>, &SVector<T, N>),
    ) -> Result<SVector<T, N>, ConstrainedError> {
        Ok(accelerations_with(self.0, c, state, &modes.rows(&self.0.strokes()))?.qdd)
    }

    /// The walk's event functions less their constant margins and guards' offsets, which do not move with the
    /// state: a tip's normal force, a held stopper's holding force (the negative of its row's multiplier), a
    /// free leg's distance to its stopper, a tip's height. A fall or a roll-back ends no step that is replayed.
    fn guard<T: Real>(
        &self,
        c: &W::Constants<T>,
        (modes, crossing): (Modes, Crossing),
        (q, qd): (&SVector<T, N>, &SVector<T, N>),
    ) -> Result<T, ConstrainedError> {
        let rows = modes.rows(&self.0.strokes());
        let nan = T::lit(f64::NAN);
        Ok(match crossing.event {
            Event::LiftOff(i) => self.multiplier(c, &rows, Row::Normal(i), (q, qd))?,
            Event::Unlock(i) => match self.stroke(i) {
                Some(k) => -self.multiplier(c, &rows, Row::Held(k), (q, qd))?,
                None => nan,
            },
            Event::Stopper(i) => match self.stroke(i) {
                Some(k) => self.0.stopper_with(c, i) - q[k],
                None => nan,
            },
            Event::Landing => self.0.contact(c, q, qd, 0).position.y,
            Event::Strike => self.0.contact(c, q, qd, 1).position.y,
            Event::Fall | Event::RollBack => nan,
        })
    }

    fn reset<T: Real>(
        &self,
        c: &W::Constants<T>,
        crossing: Crossing,
        (q, qd): (&SVector<T, N>, &SVector<T, N>),
    ) -> Result<(SVector<T, N>, SVector<T, N>), ConstrainedError> {
        if crossing.event == Event::Strike {
            return Ok(self.0.relabel_with(c, q, qd));
        }
        let strokes = self.0.strokes();
        let mut qd = *qd;
        for took in crossing.impulses.iter().flatten() {
            qd = impulse_with(self.0, c, (q, &qd), &took.rows(&strokes))?.qd_plus;
        }
        Ok((*q, qd))
    }
}

/// The walk's record on its state `(q, q', W)` (`Y = 2 N + 1`) as the replay's on `(q, q')` (`Z = 2 N`): the
/// dampers' work is a quadrature that nothing else reads, and the Runge-Kutta steps treat each component on its
/// own, so dropping it leaves the other components' steps as they were.
fn without_work<const Y: usize, const Z: usize>(
    tape: &Tape<Modes, Crossing, Y>,
) -> Tape<Modes, Crossing, Z> {
    const { assert!(Y == Z + 1) };
    let cut = |y: &SVector<f64, Y>| y.fixed_rows::<Z>(0).into_owned();
    Tape {
        method: tape.method,
        segments: tape
            .segments
            .iter()
            .map(|s| Segment {
                phase: s.phase,
                t0: s.t0,
                y0: cut(&s.y0),
                steps: s.steps.clone(),
                end: s.end.as_ref().map(|e| SegmentEnd {
                    time: e.time,
                    event: e.event,
                    y: cut(&e.y),
                }),
            })
            .collect(),
    }
}

/// The value of `walker`'s constant `key` (as its constants read it), `None` for no such key.
pub fn constant_value<W: LeggedDerivatives<N>, const N: usize>(
    walker: &W,
    key: &str,
) -> Option<f64> {
    sensitivity::constant_value(&Replay::<W, N>(walker), key)
}

/// The DLS indicators of a step's heel strike within [`BORDER_TOL`] of zero put it on the border between two
/// branches of the impact procedure, where the map has only one-sided derivatives.
fn check_border<const N: usize>(step: &LeggedStep<N>) -> Result<(), NotDifferentiable> {
    let a = &step.account;
    let indicators = [
        ("lambda_I4", Some(a.lambda_i4)),
        ("lambda_2+", a.lambda_2_plus),
        ("lambda_4+", a.lambda_4_plus),
    ];
    for (indicator, value) in indicators {
        if let Some(value) = value.filter(|v| v.abs() < BORDER_TOL) {
            return Err(NotDifferentiable::Border {
                time: 0.0,
                indicator,
                value,
            });
        }
    }
    Ok(())
}

/// `P(x)` of `walker` with its exact `DP` and, if `param` names one of its constants, `dP/dp` (see the module
/// documentation). The sizes: `Y = 2 N + 1` the walk's state, `Z = 2 N`, `D = x.len() + 1` directions (the
/// section's coordinates and the parameter), `E = D + 1`, `A = Z + Z D` (each walker names them,
/// [`LeggedDerivatives::exact_step_map`]).
pub fn replayed_step_map<
    W,
    const N: usize,
    const Y: usize,
    const Z: usize,
    const D: usize,
    const E: usize,
    const A: usize,
>(
    walker: &W,
    x: &DVector<f64>,
    param: Option<&str>,
    options: &LeggedOptions,
) -> Result<LeggedDerivative<N>, LeggedDerivativeError>
where
    W: LeggedDerivatives<N>,
{
    assert_eq!(
        x.len() + 1,
        D,
        "a direction per section coordinate and the parameter's"
    );
    if let Some(key) = param.filter(|key| constant_value(walker, key).is_none()) {
        return Err(LeggedDerivativeError::UnknownParameter {
            key: key.to_string(),
        });
    }
    let model = Replay::<W, N>(walker);
    let duals = seeded::<_, N, D>(&model, param, D - 1);
    let seeds: Vec<Dual<D>> = x
        .iter()
        .enumerate()
        .map(|(k, &v)| Dual::new(v, SVector::<f64, D>::from_fn(|i, _| f64::from(i == k))))
        .collect();
    let (q0, qd0) = walker
        .state_at_section_with(&duals, &seeds)
        .ok_or(LeggedError::OffSection)?;
    let (q, qd) = walker.state_at_section(x).ok_or(LeggedError::OffSection)?;
    let mut tape = LeggedTape::<Y>::new();
    let step = legged_step_taped::<W, N, Y>(walker, (&q, &qd), options, &mut tape)?;
    check_border(&step)?;
    let singular = |_| NotDifferentiable::Singular { time: 0.0 };
    let rows = tape.strike.rows(&walker.strokes());
    let qd0_plus = impulse_with(walker, &duals, (&q0, &qd0), &rows)
        .map_err(singular)?
        .qd_plus;
    let s0: Sensitivity<Z, D> = sensitivity_of(&q0, &qd0_plus);
    let phases = without_work::<Y, Z>(&tape.phases);
    let s = replay::<_, N, Z, D, E, A>(&model, param, &phases, &s0)?.sensitivity;
    let y_end = SVector::<f64, Z>::from_fn(|i, _| if i < N { step.q[i] } else { step.qd[i - N] });
    let (q_end, qd_end) = state_duals::<N, Z, D>(&y_end, &s);
    let section = walker.section_with(&q_end, &qd_end);
    let n = x.len();
    Ok(LeggedDerivative {
        value: walker.section_of(&step.q, &step.qd),
        jacobian: DMatrix::from_fn(n, n, |i, k| section[i].eps[k]),
        dparam: param.map(|_| DVector::from_fn(n, |i, _| section[i].eps[D - 1])),
        step,
    })
}
