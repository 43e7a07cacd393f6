//! Gaits of a rigid-legged walker (docs/model.md section 13): fixed points of its step map `P` on the section
//! ([`RigidWalker::section_of`]) by Newton's method, and their Floquet multipliers, the eigenvalues of `DP`.
//!
//! `DP` is exact ([`super::rigid_derivative`]: the variational equations over the walk's own integrator steps,
//! the heel strike's saltation). Where the map has no derivative (a grazing heel strike, `lambda_I4` at 0)
//! Newton's method takes central differences instead (relative step [`DIFFERENCE_STEP`]: a Newton matrix need
//! not be exact), and the gait's multipliers do so only where the caller asks
//! ([`RigidOptions::difference_fallback`]), saying so ([`JacobianRoute`]). The central differences also check
//! the exact `DP` ([`super::rigid_check::check_rigid_derivatives`], `vrw gait --model NAME --check-jacobian`).

use nalgebra::{DMatrix, DVector};

use super::rigid::{rigid_step, RigidError, RigidOptions, RigidStep, RigidWalker};
use super::rigid_derivative::DerivativeError;
use super::sensitivity::NotDifferentiable;

/// Relative step of the central differences of `DP`.
pub const DIFFERENCE_STEP: f64 = 1e-6;

/// Newton's method stops when `max |P(s) - s|` is below this.
pub const NEWTON_TOL: f64 = 1e-12;

/// Most Newton iterations.
const MAX_NEWTON_ITERATIONS: usize = 40;

/// A gait of a rigid-legged walker.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidGait<const N: usize> {
    /// The fixed point on the section.
    pub section: DVector<f64>,
    /// `max |P(s) - s|` there.
    pub residual: f64,
    /// Newton iterations taken.
    pub iterations: usize,
    /// `DP` at the fixed point.
    pub jacobian: DMatrix<f64>,
    /// How `DP` was taken.
    pub derivative: JacobianRoute,
    /// The Floquet multipliers `[re, im]`, largest modulus first.
    pub multipliers: Vec<[f64; 2]>,
    /// The step from the fixed point (its period, DLS indicator, impact loss, energy audit).
    pub step: RigidStep<N>,
}

impl<const N: usize> RigidGait<N> {
    /// The largest modulus of the multipliers: the gait is stable below 1.
    pub fn largest_multiplier(&self) -> f64 {
        self.multipliers
            .first()
            .map_or(f64::NAN, |[re, im]| re.hypot(*im))
    }
}

/// How a gait's `DP` was taken.
#[derive(Debug, Clone, PartialEq)]
pub enum JacobianRoute {
    /// Exactly (the variational equations and the heel strike's saltation).
    Exact,
    /// By central differences of relative step [`DIFFERENCE_STEP`], because the map is not differentiable at the
    /// gait (the caller asked for this fallback, [`RigidOptions::difference_fallback`]).
    CentralDifferences {
        /// Why not exactly.
        reason: NotDifferentiable,
    },
}

impl std::fmt::Display for JacobianRoute {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            JacobianRoute::Exact => f.write_str(EXACT_ROUTE),
            JacobianRoute::CentralDifferences { reason } => write!(
                f,
                "central differences, relative step {DIFFERENCE_STEP:e} (no exact derivative: {reason})"
            ),
        }
    }
}

/// How an exact `DP` is taken, in words (`gait.json`'s `derivative`).
pub const EXACT_ROUTE: &str =
    "exact: variational equations over the walk's steps, saltation at the heel strike";

/// Why no gait was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RigidGaitError {
    /// A step of the walk failed.
    #[error("step map failed in Newton iteration {iteration}: {source}")]
    Step {
        /// Iteration number (from 0: the start).
        iteration: usize,
        /// Why.
        source: RigidError,
    },
    /// The map is not differentiable at the gait, and no fallback to differences was asked for.
    #[error("no exact DP at the gait: {source}")]
    NotDifferentiable {
        /// Why.
        source: NotDifferentiable,
    },
    /// `DP - I` is singular.
    #[error("DP - I is singular (a multiplier at 1), residual {residual:e}")]
    Singular {
        /// The residual there.
        residual: f64,
    },
    /// Newton's method did not reach [`NEWTON_TOL`].
    #[error("no convergence: residual {residual:e} after {iterations} Newton iterations")]
    NoConvergence {
        /// Iterations taken.
        iterations: usize,
        /// The last `max |P(s) - s|`.
        residual: f64,
    },
}

/// `P(s)` and the step that gives it.
pub fn rigid_step_map<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    s: &DVector<f64>,
    options: &RigidOptions,
) -> Result<(DVector<f64>, RigidStep<N>), RigidError> {
    let (q, qd) = walker.state_at_section(s);
    let step = rigid_step(walker, &q, &qd, options)?;
    Ok((walker.section_of(&step.q, &step.qd), step))
}

/// The exact `DP` at `s` ([`RigidWalker::step_map_derivative`]).
pub fn rigid_jacobian<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    s: &DVector<f64>,
    options: &RigidOptions,
) -> Result<DMatrix<f64>, DerivativeError> {
    Ok(walker.step_map_derivative(s, None, 1, options)?.jacobian)
}

/// `DP` at `s` by central differences ([`central_jacobian`]).
pub fn difference_jacobian<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    s: &DVector<f64>,
    options: &RigidOptions,
) -> Result<DMatrix<f64>, RigidError> {
    central_jacobian(s, |x| Ok(rigid_step_map(walker, x, options)?.0))
}

/// Newton's matrix `DP` at `s`: exact, or central differences where the map has no derivative.
fn newton_jacobian<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    s: &DVector<f64>,
    options: &RigidOptions,
) -> Result<DMatrix<f64>, RigidError> {
    match rigid_jacobian(walker, s, options) {
        Ok(jacobian) => Ok(jacobian),
        Err(DerivativeError::Walk(e)) => Err(e),
        // Not differentiable here (no parameter was asked for, so no other reason).
        Err(_) => difference_jacobian(walker, s, options),
    }
}

/// The gait's `DP` at `s` and how it was taken: exact, or (where the map has no derivative and `options` ask
/// for it) central differences.
fn gait_jacobian<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    s: &DVector<f64>,
    options: &RigidOptions,
    iteration: usize,
) -> Result<(DMatrix<f64>, JacobianRoute), RigidGaitError> {
    let step = |source| RigidGaitError::Step { iteration, source };
    match rigid_jacobian(walker, s, options) {
        Ok(jacobian) => Ok((jacobian, JacobianRoute::Exact)),
        Err(DerivativeError::Walk(e)) => Err(step(e)),
        Err(DerivativeError::NotDifferentiable(reason)) if options.difference_fallback => Ok((
            difference_jacobian(walker, s, options).map_err(step)?,
            JacobianRoute::CentralDifferences { reason },
        )),
        Err(DerivativeError::NotDifferentiable(source)) => {
            Err(RigidGaitError::NotDifferentiable { source })
        }
        Err(DerivativeError::UnknownParameter { .. }) => unreachable!("no parameter asked for"),
    }
}

/// The Jacobian of `f` at `x` by central differences, each coordinate stepped by [`DIFFERENCE_STEP`] times its
/// size (at least 1).
pub fn central_jacobian<E>(
    x: &DVector<f64>,
    f: impl Fn(&DVector<f64>) -> Result<DVector<f64>, E>,
) -> Result<DMatrix<f64>, E> {
    let n = x.len();
    let mut jacobian = DMatrix::zeros(n, n);
    for k in 0..n {
        let h = DIFFERENCE_STEP * x[k].abs().max(1.0);
        let (mut plus, mut minus) = (x.clone(), x.clone());
        plus[k] += h;
        minus[k] -= h;
        jacobian.set_column(k, &((f(&plus)? - f(&minus)?) / (2.0 * h)));
    }
    Ok(jacobian)
}

/// The gait near `start` (a section state) by Newton's method on `P(s) = s`, each step damped until the
/// residual falls.
pub fn rigid_gait<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    start: &DVector<f64>,
    options: &RigidOptions,
) -> Result<RigidGait<N>, RigidGaitError> {
    let map = |s: &DVector<f64>, iteration: usize| {
        rigid_step_map(walker, s, options)
            .map_err(|source| RigidGaitError::Step { iteration, source })
    };
    let mut s = start.clone();
    let (mut image, mut step) = map(&s, 0)?;
    for iteration in 1..=MAX_NEWTON_ITERATIONS {
        let r = &image - &s;
        let residual = r.amax();
        if residual < NEWTON_TOL {
            let (jacobian, derivative) = gait_jacobian(walker, &s, options, iteration)?;
            return Ok(RigidGait {
                multipliers: multipliers(&jacobian),
                section: s,
                residual,
                iterations: iteration - 1,
                jacobian,
                derivative,
                step,
            });
        }
        let jacobian = newton_jacobian(walker, &s, options)
            .map_err(|source| RigidGaitError::Step { iteration, source })?;
        let n = s.len();
        let delta = (jacobian - DMatrix::identity(n, n))
            .lu()
            .solve(&(-r))
            .ok_or(RigidGaitError::Singular { residual })?;
        // Damped: the full step, or halves of it, until the residual falls (or the walk works at all).
        let mut scale = 1.0;
        loop {
            let trial = &s + scale * &delta;
            match map(&trial, iteration) {
                Ok((next, next_step)) if (&next - &trial).amax() < residual || scale < 1e-3 => {
                    (s, image, step) = (trial, next, next_step);
                    break;
                }
                Err(e) if scale < 1e-3 => return Err(e),
                _ => scale *= 0.5,
            }
        }
    }
    Err(RigidGaitError::NoConvergence {
        iterations: MAX_NEWTON_ITERATIONS,
        residual: (&image - &s).amax(),
    })
}

/// The eigenvalues of `jacobian` as `[re, im]`, largest modulus first.
pub fn multipliers(jacobian: &DMatrix<f64>) -> Vec<[f64; 2]> {
    let mut m: Vec<[f64; 2]> = jacobian
        .complex_eigenvalues()
        .iter()
        .map(|z| [z.re, z.im])
        .collect();
    m.sort_by(|a, b| b[0].hypot(b[1]).total_cmp(&a[0].hypot(a[1])));
    m
}
