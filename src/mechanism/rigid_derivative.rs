//! The exact derivatives of a rigid-legged walker's step map (docs/model.md section 13): `DP` and `dP/dp` in
//! one of its parameters, from the walk's record of each step replayed by [`super::sensitivity`].
//!
//! The section's coordinates `x` (and the parameter) are seeded as dual numbers into the state just after a
//! heel strike ([`RigidWalker::state_at_section_with`]); each step is walked on `f64` and recorded
//! ([`rigid_step_taped`]), then replayed with the variational equations of single support over its very
//! integrator steps, crossed at the heel strike with the guard's sensitivity (the swing foot's height,
//! [`RigidWalker::swing_foot_with`]) and the heel strike's transition differentiated
//! ([`RigidWalker::transition_with`]: the constrained impulse and the legs' exchange); the section of the state
//! at the end ([`RigidWalker::section_with`]) on dual numbers gives `DP` and `dP/dp`. They are the exact
//! derivatives of the walk's discretization (not of the exact flow, from which they differ by the integration
//! error).

use std::marker::PhantomData;

use nalgebra::{DMatrix, DVector, SVector};

use super::constrained::ConstrainedError;
use super::rigid::{
    pack, rigid_step_taped, HeelStrikeEvent, RigidOptions, RigidTape, RigidWalker,
    SingleSupportPhase,
};
pub use super::rigid::{DerivativeError, StepMapDerivative};
use super::sensitivity::{
    constant_value, replay, seeded, sensitivity_of, state_duals, Hybrid, NotDifferentiable,
    Sensitivity, BORDER_TOL,
};
use super::Real;
use crate::dynamics::Dual;
use crate::integrate::Method;

/// A rigid walker as the replay sees it: one phase (single support), one event (the heel strike), whose reset
/// is the impact and the legs' exchange.
struct Rigid<'w, W, const Y: usize>(&'w W, PhantomData<[(); Y]>);

impl<W: RigidWalker<N, Y>, const N: usize, const Y: usize> Hybrid<N> for Rigid<'_, W, Y> {
    type Constants<T: Real> = W::Constants<T>;
    type Phase = SingleSupportPhase;
    type Event = HeelStrikeEvent;

    fn hybrid_constants<T: Real>(&self, value: &dyn Fn(&'static str, f64) -> T) -> W::Constants<T> {
        self.0.rigid_constants(value)
    }

    fn acceleration<T: Real>(
        &self,
        c: &W::Constants<T>,
        _: SingleSupportPhase,
        (q, qd): (&SVector<T, N>, &SVector<T, N>),
    ) -> Result<SVector<T, N>, ConstrainedError> {
        Ok(self.0.single_support_with(c, q, qd)?.0)
    }

    fn guard<T: Real>(
        &self,
        c: &W::Constants<T>,
        _: (SingleSupportPhase, HeelStrikeEvent),
        (q, _): (&SVector<T, N>, &SVector<T, N>),
    ) -> Result<T, ConstrainedError> {
        Ok(self.0.swing_foot_with(c, q).0)
    }

    fn reset<T: Real>(
        &self,
        c: &W::Constants<T>,
        _: HeelStrikeEvent,
        (q, qd): (&SVector<T, N>, &SVector<T, N>),
    ) -> Result<(SVector<T, N>, SVector<T, N>), ConstrainedError> {
        let t = self.0.transition_with(c, q, qd)?;
        Ok((t.q, t.qd))
    }
}

/// The value of `walker`'s constant `key` (as its constants read it), `None` for no such key.
pub fn parameter_value<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    key: &str,
) -> Option<f64> {
    constant_value(&Rigid::<W, Y>(walker, PhantomData), key)
}

/// `P^period(x)` of `walker` with its exact `DP` and, if `param` names one of the walker's constants, `dP/dp`
/// (see the module documentation). `D = x.len() + 1` directions (the section's coordinates and the parameter),
/// `E = D + 1`, `A = Y + Y D`: the sizes of the dual numbers and of the augmented state, which each walker
/// names ([`RigidWalker::step_map_derivative`]).
pub fn step_map_derivative<
    W,
    const N: usize,
    const Y: usize,
    const D: usize,
    const E: usize,
    const A: usize,
>(
    walker: &W,
    x: &DVector<f64>,
    param: Option<&str>,
    period: usize,
    options: &RigidOptions,
) -> Result<StepMapDerivative<N>, DerivativeError>
where
    W: RigidWalker<N, Y>,
{
    assert_eq!(
        x.len() + 1,
        D,
        "a direction per section coordinate and the parameter's"
    );
    if let Some(key) = param.filter(|key| parameter_value(walker, key).is_none()) {
        return Err(DerivativeError::UnknownParameter {
            key: key.to_string(),
        });
    }
    let rigid = Rigid::<W, Y>(walker, PhantomData);
    let duals = seeded::<_, N, D>(&rigid, param, D - 1);
    let seeds: Vec<Dual<D>> = x
        .iter()
        .enumerate()
        .map(|(k, &v)| Dual::new(v, SVector::<f64, D>::from_fn(|i, _| f64::from(i == k))))
        .collect();
    let (q0, qd0) = walker.state_at_section_with(&duals, &seeds);
    let mut sensitivity: Sensitivity<Y, D> = sensitivity_of(&q0, &qd0);
    let (mut q, mut qd) = walker.state_at_section(x);
    let mut first = None;
    let mut tape = RigidTape::<Y>::new(Method::Dop853);
    for _ in 0..period.max(1) {
        let step = rigid_step_taped(walker, (&q, &qd), options, &mut tape)?;
        if step.lambda_i4.abs() < BORDER_TOL {
            return Err(NotDifferentiable::Border {
                time: step.period,
                indicator: "lambda_I4",
                value: step.lambda_i4,
            }
            .into());
        }
        sensitivity = replay::<_, N, Y, D, E, A>(&rigid, param, &tape, &sensitivity)?.sensitivity;
        (q, qd) = (step.q, step.qd);
        first.get_or_insert(step);
    }
    let (q_end, qd_end) = state_duals::<N, Y, D>(&pack::<N, Y>(&q, &qd), &sensitivity);
    let section = walker.section_with(&duals, &q_end, &qd_end);
    let n = x.len();
    Ok(StepMapDerivative {
        value: walker.section_of(&q, &qd),
        jacobian: DMatrix::from_fn(n, n, |i, k| section[i].eps[k]),
        dparam: param.map(|_| DVector::from_fn(n, |i, _| section[i].eps[D - 1])),
        step: first.expect("at least one step"),
    })
}
