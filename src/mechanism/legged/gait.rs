//! Gaits of a legged walker (docs/model.md section 13): fixed points of its step map on the section
//! ([`Legged::section_of`]) by Newton's method, and their Floquet multipliers, the eigenvalues of `DP` at the
//! fixed point. A walker with exact derivatives ([`LeggedDerivatives`], the replay of `super::derivative`) has
//! them in Newton's method and for its multipliers, Richardson-extrapolated central differences
//! ([`crate::mechanism::derivative_check::richardson_jacobian`]) their second route ([`legged_gait_exact`]); another
//! has its `DP` by central differences in Newton's method
//! ([`crate::mechanism::rigid_gait::central_jacobian`]) and by Richardson's at the fixed point with their error
//! estimate ([`legged_gait`]).

use nalgebra::{DMatrix, DVector};

use super::derivative::LeggedDerivatives;
use super::walk::{legged_step, LeggedOptions, LeggedStep};
use super::{Legged, LeggedError};
use crate::mechanism::derivative_check::richardson_jacobian;
use crate::mechanism::rigid_gait::{central_jacobian, damped_newton, multipliers, FixedPointError};

/// [`LeggedGait::derivative`] of exact derivatives (the replay of the walk's step).
pub const EXACT_ROUTE: &str = "exact_replay";

/// [`LeggedGait::derivative`] of Richardson-extrapolated central differences.
pub const DIFFERENCES_ROUTE: &str = "richardson_differences";

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
    /// `DP` at the fixed point.
    pub jacobian: DMatrix<f64>,
    /// How it was taken: [`EXACT_ROUTE`] or [`DIFFERENCES_ROUTE`].
    pub derivative: &'static str,
    /// Its error estimate: with exact derivatives, the largest difference from Richardson-extrapolated
    /// central differences (their second route); with differences, their own estimate (the largest over the
    /// columns, [`richardson_jacobian`]).
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

/// `DP` at `section` by Richardson-extrapolated central differences, with their error estimate.
fn differences<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    section: &DVector<f64>,
    iteration: usize,
    options: &LeggedOptions,
) -> Result<(DMatrix<f64>, f64), LeggedGaitError> {
    let sizes: Vec<f64> = section.iter().copied().collect();
    richardson_jacobian(section.len(), &sizes, |k, t| {
        let mut x = section.clone();
        x[k] += t;
        legged_step_map::<W, N, Y>(walker, &x, options)
            .map(|(image, _)| image)
            .map_err(|source| LeggedGaitError::Step { iteration, source })
    })
}

/// The gait near `start` by Newton's method on `P(s) = s` ([`damped_newton`], `DP` by central differences),
/// its multipliers from `DP` at the fixed point by Richardson-extrapolated differences.
pub fn legged_gait<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    start: &DVector<f64>,
    options: &LeggedOptions,
) -> Result<LeggedGait<N>, LeggedGaitError> {
    gait_with::<W, N, Y>(walker, start, options, |_| None)
}

/// The gait near `start` of a walker with exact derivatives: Newton's method with the exact `DP` (central
/// differences at an iterate where the map has none), its multipliers from the exact `DP` at the fixed point,
/// checked against Richardson-extrapolated differences (their largest difference is the error stated). Where
/// the map has no derivative at the fixed point (a DLS indicator at zero, a grazing event), Richardson's
/// differences give `DP`, said in [`LeggedGait::derivative`].
pub fn legged_gait_exact<W: LeggedDerivatives<N>, const N: usize, const Y: usize>(
    walker: &W,
    start: &DVector<f64>,
    options: &LeggedOptions,
) -> Result<LeggedGait<N>, LeggedGaitError> {
    gait_with::<W, N, Y>(walker, start, options, |s| {
        walker
            .exact_step_map(s, None, options)
            .ok()
            .map(|d| d.jacobian)
    })
}

/// The gait near `start` with `exact(s)`, the exact `DP` at `s` where there is one: Newton's method with it (or
/// central differences), and at the fixed point its multipliers checked against Richardson-extrapolated
/// differences (or those differences' `DP` with their own error estimate).
fn gait_with<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    start: &DVector<f64>,
    options: &LeggedOptions,
    exact: impl Fn(&DVector<f64>) -> Option<DMatrix<f64>>,
) -> Result<LeggedGait<N>, LeggedGaitError> {
    let map = |s: &DVector<f64>, iteration: usize| {
        legged_step_map::<W, N, Y>(walker, s, options)
            .map_err(|source| LeggedGaitError::Step { iteration, source })
    };
    let (section, residual, iterations, step) =
        damped_newton(start, NEWTON_TOL, map, |s, i| match exact(s) {
            Some(jacobian) => Ok(jacobian),
            None => central_jacobian(s, |x| Ok(map(x, i)?.0)),
        })?;
    let (second, spread) = differences::<W, N, Y>(walker, &section, iterations + 1, options)?;
    let (jacobian, derivative, jacobian_error) = match exact(&section) {
        Some(jacobian) => {
            let error = (&jacobian - &second).amax();
            (jacobian, EXACT_ROUTE, error)
        }
        None => (second, DIFFERENCES_ROUTE, spread),
    };
    Ok(LeggedGait {
        multipliers: multipliers(&jacobian),
        section,
        residual,
        iterations,
        jacobian,
        derivative,
        jacobian_error,
        step,
    })
}
