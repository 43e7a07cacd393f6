//! Gaits of a rigid-legged walker (docs/model.md section 13): fixed points of its step map `P` on the section
//! ([`RigidWalker::section_of`]) by Newton's method, and their Floquet multipliers, the eigenvalues of `DP`.
//!
//! `DP` is exact ([`super::rigid_derivative`]: the variational equations over the walk's own integrator steps,
//! the heel strike's saltation). Where the map has no derivative (a grazing heel strike, `lambda_I4` at 0)
//! Newton's method takes central differences instead (relative step [`DIFFERENCE_STEP`]: a Newton matrix need
//! not be exact), and the gait's multipliers do so only where the caller asks
//! ([`RigidOptions::difference_fallback`]), saying so ([`JacobianRoute`]). The central differences also check
//! the exact `DP` ([`super::derivative_check::check_rigid_derivatives`], `vrw gait --model NAME --check-jacobian`).

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

/// What a fixed-point search needs to say why it failed, besides the map's own failures.
pub trait FixedPointError {
    /// `DP - I` is singular at a point of residual `residual`.
    fn singular(residual: f64) -> Self;
    /// No convergence after `iterations` iterations, the last residual `residual`.
    fn no_convergence(iterations: usize, residual: f64) -> Self;
}

impl FixedPointError for RigidGaitError {
    fn singular(residual: f64) -> Self {
        RigidGaitError::Singular { residual }
    }
    fn no_convergence(iterations: usize, residual: f64) -> Self {
        RigidGaitError::NoConvergence {
            iterations,
            residual,
        }
    }
}

/// A fixed point of `map` found by [`damped_newton`]: the point, `max |P(s) - s|` there, the Newton iterations
/// taken, and what the map gave with its image there.
pub type FixedPoint<S> = (DVector<f64>, f64, usize, S);

/// The fixed point of `map` (a section state to its image and what the step gave, in Newton iteration `i`)
/// near `start` by Newton's method on `P(s) = s` to `max |P(s) - s| < tol`, with `DP` from `jacobian`, each
/// step damped until the residual falls: the full step, or halves of it, down to 1e-3 of it. The one Newton
/// loop of the rigid and the legged walkers.
pub fn damped_newton<S, E: FixedPointError>(
    start: &DVector<f64>,
    tol: f64,
    map: impl Fn(&DVector<f64>, usize) -> Result<(DVector<f64>, S), E>,
    jacobian: impl Fn(&DVector<f64>, usize) -> Result<DMatrix<f64>, E>,
) -> Result<FixedPoint<S>, E> {
    let mut s = start.clone();
    let (mut image, mut step) = map(&s, 0)?;
    for iteration in 1..=MAX_NEWTON_ITERATIONS {
        let r = &image - &s;
        let residual = r.amax();
        if residual < tol {
            return Ok((s, residual, iteration - 1, step));
        }
        let n = s.len();
        let delta = (jacobian(&s, iteration)? - DMatrix::identity(n, n))
            .lu()
            .solve(&(-r))
            .ok_or_else(|| E::singular(residual))?;
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
    Err(E::no_convergence(
        MAX_NEWTON_ITERATIONS,
        (&image - &s).amax(),
    ))
}

/// The gait near `start` (a section state) by Newton's method on `P(s) = s` ([`damped_newton`]).
pub fn rigid_gait<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    start: &DVector<f64>,
    options: &RigidOptions,
) -> Result<RigidGait<N>, RigidGaitError> {
    let (section, residual, iterations, step) = damped_newton(
        start,
        NEWTON_TOL,
        |s, iteration| {
            rigid_step_map(walker, s, options)
                .map_err(|source| RigidGaitError::Step { iteration, source })
        },
        |s, iteration| {
            newton_jacobian(walker, s, options)
                .map_err(|source| RigidGaitError::Step { iteration, source })
        },
    )?;
    let (jacobian, derivative) = gait_jacobian(walker, &section, options, iterations + 1)?;
    Ok(RigidGait {
        multipliers: multipliers(&jacobian),
        section,
        residual,
        iterations,
        jacobian,
        derivative,
        step,
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
