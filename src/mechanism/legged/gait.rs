//! Gaits of a legged walker (docs/model.md section 13): fixed points of its step map on the section
//! ([`Legged::section_of`]) by Newton's method (its `DP` by central differences,
//! [`crate::mechanism::rigid_gait::central_jacobian`]), and their Floquet multipliers, the eigenvalues of `DP`
//! at the fixed point by Richardson-extrapolated central differences with their error estimate
//! ([`crate::mechanism::rigid_check::richardson_jacobian`]): the exact derivatives of the replay are to come.

use nalgebra::{DMatrix, DVector};

use super::walk::{legged_step, LeggedOptions, LeggedStep};
use super::{Legged, LeggedError};
use crate::mechanism::rigid_check::richardson_jacobian;
use crate::mechanism::rigid_gait::{central_jacobian, damped_newton, multipliers, FixedPointError};

/// Newton's method stops when `max |P(s) - s|` is below this.
pub const NEWTON_TOL: f64 = 1e-11;

/// `P(s)` and the step that gives it.
pub fn legged_step_map<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    s: &DVector<f64>,
    options: &LeggedOptions,
) -> Result<(DVector<f64>, LeggedStep<N>), LeggedError> {
    let (q, qd) = walker.state_at_section(s).ok_or(LeggedError::OffSection)?;
    let step = legged_step::<W, N, Y>(walker, (&q, &qd), options)?;
    Ok((walker.section_of(&step.q, &step.qd), step))
}

/// A gait of a legged walker.
#[derive(Debug, Clone, PartialEq)]
pub struct LeggedGait<const N: usize> {
    /// The fixed point on the section.
    pub section: DVector<f64>,
    /// `max |P(s) - s|` there.
    pub residual: f64,
    /// Newton iterations taken.
    pub iterations: usize,
    /// `DP` at the fixed point (Richardson-extrapolated central differences).
    pub jacobian: DMatrix<f64>,
    /// Its error estimate (the largest over its columns, [`richardson_jacobian`]).
    pub jacobian_error: f64,
    /// The Floquet multipliers `[re, im]`, largest modulus first.
    pub multipliers: Vec<[f64; 2]>,
    /// The step from the fixed point.
    pub step: LeggedStep<N>,
}

/// Why no gait was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LeggedGaitError {
    /// A step of the walk failed.
    #[error("step map failed in Newton iteration {iteration}: {source}")]
    Step {
        /// Iteration number (from 0: the start).
        iteration: usize,
        /// Why.
        source: LeggedError,
    },
    /// `DP - I` is singular.
    #[error("DP - I is singular (a multiplier at 1), residual {residual:e}")]
    Singular {
        /// The residual there.
        residual: f64,
    },
    /// Newton's method did not converge.
    #[error("no convergence: residual {residual:e} after {iterations} Newton iterations")]
    NoConvergence {
        /// Iterations taken.
        iterations: usize,
        /// The last residual.
        residual: f64,
    },
}

impl FixedPointError for LeggedGaitError {
    fn singular(residual: f64) -> Self {
        LeggedGaitError::Singular { residual }
    }
    fn no_convergence(iterations: usize, residual: f64) -> Self {
        LeggedGaitError::NoConvergence {
            iterations,
            residual,
        }
    }
}

/// The gait near `start` by Newton's method on `P(s) = s` ([`damped_newton`]), its multipliers from `DP` at
/// the fixed point by Richardson-extrapolated differences.
pub fn legged_gait<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    start: &DVector<f64>,
    options: &LeggedOptions,
) -> Result<LeggedGait<N>, LeggedGaitError> {
    let map = |s: &DVector<f64>, iteration: usize| {
        legged_step_map::<W, N, Y>(walker, s, options)
            .map_err(|source| LeggedGaitError::Step { iteration, source })
    };
    let (section, residual, iterations, step) = damped_newton(start, NEWTON_TOL, map, |s, i| {
        central_jacobian(s, |x| Ok(map(x, i)?.0))
    })?;
    let sizes: Vec<f64> = section.iter().copied().collect();
    let (jacobian, jacobian_error) = richardson_jacobian(section.len(), &sizes, |k, t| {
        let mut x = section.clone();
        x[k] += t;
        Ok(map(&x, iterations + 1)?.0)
    })?;
    Ok(LeggedGait {
        multipliers: multipliers(&jacobian),
        section,
        residual,
        iterations,
        jacobian,
        jacobian_error,
        step,
    })
}
