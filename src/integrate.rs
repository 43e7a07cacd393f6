//! Adaptive Dormand–Prince integration with dense output and event-root location.
//!
//! Two explicit Runge–Kutta pairs, chosen by [`Method`] (the `integrator` key of a configuration) and driven
//! through [`Integrator`]: [`Dop853`] (order 8, the default, in its own module) and [`Dopri5`] (order 5, below).
//! Both hand out each accepted step as a [`DenseStep`], on which the caller locates events ([`locate_root`]).
//!
//! [`Dopri5`] is the explicit Runge–Kutta pair of Dormand & Prince (1980) used in
//! local extrapolation mode (the 5th-order solution is propagated, the embedded 4th-order one
//! only estimates the error), with FSAL (the last stage is f at the new point), the PI
//! ("Lund-stabilised") step-size controller of Gustafsson (1991) as in Hairer's `dopri5`, the
//! starting-step heuristic of Hairer, Nørsett & Wanner (1993, Sec. II.4), and Shampine's (1986)
//! 4th-order continuous extension (the `contd5` dense output of `dopri5`, HNW Sec. II.6).
//!
//! # Why hand-written
//! The hybrid walk needs (i) fixed-size stack state (`SVector<f64, N>`, N = 11 and larger for
//! augmented systems) with no heap allocation per right-hand-side call or step; (ii) events with a
//! crossing direction and arming guards decided by the caller; and (iii) restarts with a new state
//! and possibly a new vector field after every event. diffsol's root finder reports any sign
//! change (no direction filter), re-reports a root right after a reset, and its problem must be
//! rebuilt per phase. So this module only integrates one accepted step at a time
//! ([`Dopri5::step`] returns a [`DenseStep`]); the caller evaluates its event functions on the
//! dense output and refines a bracketed root with [`locate_root`], which uses Brent's method from
//! the `roots` crate.
//!
//! # References
//! - J. R. Dormand, P. J. Prince, "A family of embedded Runge–Kutta formulae",
//!   J. Comput. Appl. Math. 6(1):19–26, 1980.
//! - L. F. Shampine, "Some practical Runge–Kutta formulas", Math. Comp. 46(173):135–150, 1986.
//! - K. Gustafsson, "Control theoretic techniques for stepsize selection in explicit Runge–Kutta
//!   methods", ACM Trans. Math. Softw. 17(4):533–554, 1991.
//! - E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed.,
//!   Springer, 1993: Sec. II.4 (error estimate, step control, starting step), Sec. II.5 (DOPRI5),
//!   Sec. II.6 (dense output).
//! - R. P. Brent, *Algorithms for Minimization without Derivatives*, Prentice-Hall, 1973, Ch. 4.

use nalgebra::SVector;

mod dop853;
pub use dop853::Dop853;

/// A first-order system y' = f(t, y).
pub trait OdeSystem<const N: usize> {
    /// The right-hand side f(t, y).
    fn rhs(&self, t: f64, y: &SVector<f64, N>) -> SVector<f64, N>;
}

/// Error tolerances and step-size bounds of [`Dopri5`].
///
/// The local error estimate `e` of a step from `y0` to `y1` is accepted when
/// `sqrt(mean_i (e_i / (atol + rtol * max(|y0_i|, |y1_i|)))^2) <= 1` (HNW I, Eq. II.4.11).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Relative tolerance \[-\], default 1e-10.
    pub rtol: f64,
    /// Absolute tolerance \[state units\], default 1e-12.
    pub atol: f64,
    /// Largest step \[s\], default 0.02 (a step may be stretched by up to 1% to land exactly
    /// on `t_stop`, see [`Dopri5::step`]).
    pub h_max: f64,
    /// Smallest step \[s\]: a controller proposal below it ends the integration with
    /// [`IntegrationError::StepSizeTooSmall`] (or [`IntegrationError::NonFinite`] if the last
    /// trial produced non-finite values), default 1e-14. Steps shortened to land on `t_stop`
    /// are not subject to it.
    pub h_min: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            rtol: 1e-10,
            atol: 1e-12,
            h_max: 0.02,
            h_min: 1e-14,
        }
    }
}

/// Why [`Dopri5::step`] could not take a step.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum IntegrationError {
    /// The step-size controller asked for a step shorter than [`Tolerances::h_min`]
    /// (or one that no longer advances t in floating point): typically a finite-time blow-up or
    /// a discontinuity of the vector field that is not handled as an event.
    #[error("step size fell below {h_min:e} s at t = {time} s")]
    StepSizeTooSmall {
        /// Time of the last accepted point \[s\].
        time: f64,
        /// The smallest allowed step \[s\].
        h_min: f64,
    },
    /// The state or its derivative is NaN or infinite at the current point, or every trial step
    /// down to [`Tolerances::h_min`] produced non-finite values.
    #[error("non-finite state at t = {time} s")]
    NonFinite {
        /// Time of the last accepted (finite) point \[s\].
        time: f64,
    },
}

/// Work counters of a [`Dopri5`] solver, for benchmarks and snapshot tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Stats {
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected trial steps (error too large or non-finite values).
    pub rejected: usize,
    /// Evaluations of [`OdeSystem::rhs`], including those for starting-step estimates.
    pub rhs_evals: usize,
}

// Dormand–Prince 5(4) tableau (HNW I, Table II.5.2).
const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
// 5th-order weights b_i (= a_7i, which gives FSAL).
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
// Error weights e_i = b_i - b̂_i.
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Shampine's dense-output weights (dopri5 `contd5`).
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

// Step-size controller of dopri5 (HNW I, Sec. II.4 and IV.2).
/// Safety factor on the optimal step.
const SAFE: f64 = 0.9;
/// PI (Lund stabilisation) exponent on the previous error.
const BETA: f64 = 0.04;
/// Exponent on the current error: 1/5 - 0.75 * BETA.
const EXPO1: f64 = 0.2 - BETA * 0.75;
/// Largest divisor h_old/h_new (step shrinks at most 5x per trial).
const FAC_SHRINK_MAX: f64 = 5.0;
/// Smallest divisor h_old/h_new (step grows at most 10x per step).
const FAC_GROW_MAX: f64 = 0.1;
/// Floor on the stored previous error of the PI controller (also its value after a (re)start).
const ERR_OLD_MIN: f64 = 1e-4;
/// A step within this factor of `t_stop` is stretched to land on it (avoids a sliver step).
const LAND_STRETCH: f64 = 1.01;
/// Order of the starting-step heuristic: error constant ~ h^(p+1) with p = 4.
const HINIT_ORDER: i32 = 5;

/// Weighted RMS norm of `v` with scale `atol + rtol * max(|a_i|, |b_i|)` (HNW I, Eq. II.4.11).
fn scaled_rms<const N: usize>(
    tol: &Tolerances,
    v: &SVector<f64, N>,
    a: &SVector<f64, N>,
    b: &SVector<f64, N>,
) -> f64 {
    let sum: f64 = v
        .iter()
        .zip(a.iter().zip(b.iter()))
        .map(|(vi, (ai, bi))| {
            let r = vi / (tol.atol + tol.rtol * ai.abs().max(bi.abs()));
            r * r
        })
        .sum();
    (sum / N as f64).sqrt()
}

/// One accepted step with its continuous extension (dense output), in the nested form of Hairer's codes.
///
/// With `θ = (t - t0)/(t1 - t0)` the interpolant is
/// `y(t) = c0 + θ (c1 + (1-θ) (c2 + θ (c3 + (1-θ) (c4 + θ (c5 + (1-θ) (c6 + θ c7))))))`, truncated after the
/// last coefficient the method has: five for [`Dopri5`] (`c0 = y0`, `c1 = Δ = y1 - y0`, `c2 = h k1 - Δ`,
/// `c3 = Δ - h k7 - c2`, `c4 = h Σ d_i k_i`: Shampine's 4th-order extension, `contd5` of `dopri5`), eight for
/// [`Dop853`] (its 7th-order extension, `contd8` of `dop853`). It matches y0, y1, f0 and f1.
#[derive(Debug, Clone)]
pub struct DenseStep<const N: usize> {
    t0: f64,
    t1: f64,
    y1: SVector<f64, N>,
    /// `c0 .. c7`; only the first `terms` are used.
    cont: [SVector<f64, N>; MAX_DENSE_TERMS],
    terms: usize,
}

/// Most coefficients of a continuous extension ([`Dop853`] has eight).
const MAX_DENSE_TERMS: usize = 8;

impl<const N: usize> DenseStep<N> {
    /// Start time of the step \[s\].
    pub fn t0(&self) -> f64 {
        self.t0
    }

    /// End time of the step \[s\].
    pub fn t1(&self) -> f64 {
        self.t1
    }

    /// State at [`t0`](Self::t0).
    pub fn y0(&self) -> &SVector<f64, N> {
        &self.cont[0]
    }

    /// State at [`t1`](Self::t1).
    pub fn y1(&self) -> &SVector<f64, N> {
        &self.y1
    }

    /// Dense output at t in [t0, t1].
    ///
    /// Returns `y0` exactly at `t0` and `y1` exactly at `t1`. Outside the step the polynomial is
    /// extrapolated, which is not accurate.
    pub fn eval(&self, t: f64) -> SVector<f64, N> {
        if t == self.t1 {
            return self.y1;
        }
        let theta = (t - self.t0) / (self.t1 - self.t0);
        let theta1 = 1.0 - theta;
        // Innermost first: c_{n-1}, then c_k + (θ or 1-θ) * (...) down to c0 + θ (...).
        let mut acc = self.cont[self.terms - 1];
        for k in (0..self.terms - 1).rev() {
            let factor = if k % 2 == 0 { theta } else { theta1 };
            acc = self.cont[k] + acc * factor;
        }
        acc
    }

    /// Dense output at `t`, which must lie inside the step (a rewind to an event).
    ///
    /// # Panics
    /// If `t` is outside `[t0, t1]`.
    fn eval_inside(&self, t: f64) -> SVector<f64, N> {
        assert!(
            self.t0 <= t && t <= self.t1,
            "rewind time {t} outside the step [{}, {}]",
            self.t0,
            self.t1
        );
        self.eval(t)
    }

    /// A dense step from its coefficients `c0 ..` (see the type's documentation).
    fn from_coefficients(
        t0: f64,
        t1: f64,
        y1: SVector<f64, N>,
        coefficients: &[SVector<f64, N>],
    ) -> Self {
        let mut cont = [SVector::zeros(); MAX_DENSE_TERMS];
        cont[..coefficients.len()].copy_from_slice(coefficients);
        DenseStep {
            t0,
            t1,
            y1,
            cont,
            terms: coefficients.len(),
        }
    }
}

/// What both Runge-Kutta pairs keep between steps, and the parts of a step they share: the checks before a
/// step, the trial step size, a rejection and an acceptance.
#[derive(Debug, Clone)]
struct Core<const N: usize> {
    tol: Tolerances,
    t: f64,
    y: SVector<f64, N>,
    /// FSAL value f(t, y).
    dy: SVector<f64, N>,
    /// Step size the controller proposes for the next trial \[s\].
    h: f64,
    /// Size of the last accepted step \[s\], if any.
    h_accepted: Option<f64>,
    stats: Stats,
}

impl<const N: usize> Core<N> {
    /// At (t0, y0), for a method whose local error is `~ h^order`: f(t0, y0) and a starting step (two
    /// evaluations).
    fn new(
        sys: &impl OdeSystem<N>,
        t0: f64,
        y0: SVector<f64, N>,
        tol: Tolerances,
        order: i32,
    ) -> Self {
        let mut core = Core {
            tol,
            t: t0,
            y: y0,
            dy: SVector::zeros(),
            h: 0.0,
            h_accepted: None,
            stats: Stats::default(),
        };
        core.reset_point(sys, t0, y0, order);
        core
    }

    /// Set the current point, recompute the FSAL derivative and a fresh starting step (HNW I, Sec. II.4,
    /// "Starting step size").
    fn reset_point(&mut self, sys: &impl OdeSystem<N>, t: f64, y: SVector<f64, N>, order: i32) {
        self.t = t;
        self.y = y;
        self.dy = sys.rhs(t, &y);
        self.stats.rhs_evals += 2;
        self.h = initial_step(sys, &self.tol, t, &self.y, &self.dy, order);
    }

    /// [`Core::reset_point`], keeping the last accepted step size as a bound on the first trial step.
    fn restart(&mut self, sys: &impl OdeSystem<N>, t: f64, y: SVector<f64, N>, order: i32) {
        self.reset_point(sys, t, y, order);
        if let Some(h_acc) = self.h_accepted {
            self.h = self.h.min(h_acc);
        }
    }

    /// The checks before a step: `t_stop` after the current time (else a panic), a finite current point.
    fn begin(&self, t_stop: f64) -> Result<(), IntegrationError> {
        assert!(
            t_stop > self.t,
            "t_stop = {t_stop} is not after the current time {}",
            self.t
        );
        if all_finite(&self.y) && all_finite(&self.dy) {
            Ok(())
        } else {
            Err(IntegrationError::NonFinite { time: self.t })
        }
    }

    /// The next trial step `(h, t1)`: the controller's proposal, at most `h_max`, stretched or shortened to land
    /// on `t_stop`; an error if the proposal fell below `h_min` (`NonFinite` if the last trial was).
    fn trial(&self, t_stop: f64, last_non_finite: bool) -> Result<(f64, f64), IntegrationError> {
        let t = self.t;
        let h_ctrl = self.h.min(self.tol.h_max);
        if !(h_ctrl >= self.tol.h_min && t + h_ctrl > t) {
            return Err(if last_non_finite {
                IntegrationError::NonFinite { time: t }
            } else {
                IntegrationError::StepSizeTooSmall {
                    time: t,
                    h_min: self.tol.h_min,
                }
            });
        }
        Ok(if t + LAND_STRETCH * h_ctrl >= t_stop {
            (t_stop - t, t_stop)
        } else {
            (h_ctrl, t + h_ctrl)
        })
    }

    /// Reject a trial of size `h`: the next one is `h / divisor`.
    fn reject(&mut self, h: f64, divisor: f64) {
        self.stats.rejected += 1;
        self.h = h / divisor;
    }

    /// Accept a trial of size `h` ending at `(t1, y1)` with `f1 = f(t1, y1)`; the next trial is `h_new`, not
    /// grown right after a rejection, and at most `h_max`.
    fn accept(
        &mut self,
        h: f64,
        (t1, y1, f1): (f64, SVector<f64, N>, SVector<f64, N>),
        h_new: f64,
        rejected_before: bool,
    ) {
        let h_new = if rejected_before { h_new.min(h) } else { h_new };
        self.h = h_new.min(self.tol.h_max);
        self.h_accepted = Some(h);
        self.stats.accepted += 1;
        self.t = t1;
        self.y = y1;
        self.dy = f1;
    }
}

/// Adaptive Dormand-Prince 5(4) with FSAL, PI step-size control, dense output.
///
/// Drive it one accepted step at a time with [`step`](Self::step); after an event, continue
/// with [`restart`](Self::restart) (new state or vector field) or [`rewind`](Self::rewind)
/// (back to a time inside the last step). No heap allocation: all stages live on the stack.
#[derive(Debug, Clone)]
pub struct Dopri5<const N: usize> {
    core: Core<N>,
    /// Previous accepted error norm, for the PI controller.
    err_old: f64,
}

impl<const N: usize> Dopri5<N> {
    /// Start at (t0, y0); computes f(t0,y0) and an initial step (Hairer's initial step heuristic).
    ///
    /// Costs two right-hand-side evaluations. A non-finite f(t0, y0) is reported by the first
    /// [`step`](Self::step) as [`IntegrationError::NonFinite`].
    pub fn new(sys: &impl OdeSystem<N>, t0: f64, y0: SVector<f64, N>, tol: Tolerances) -> Self {
        Self {
            core: Core::new(sys, t0, y0, tol, HINIT_ORDER),
            err_old: ERR_OLD_MIN,
        }
    }

    /// Restart at (t, y) after a reset (new state, possibly new vector field): recomputes f, keeps the
    /// last accepted step size as the first trial step (bounded by a fresh initial-step estimate).
    ///
    /// Costs two right-hand-side evaluations; the PI controller memory is reset.
    pub fn restart(&mut self, sys: &impl OdeSystem<N>, t: f64, y: SVector<f64, N>) {
        self.core.restart(sys, t, y, HINIT_ORDER);
        self.err_old = ERR_OLD_MIN;
    }

    /// Move the solver back to time t inside the last step (t0 <= t <= t1) using the dense output:
    /// used when an event is located inside the last step and the walk continues from there.
    ///
    /// Equivalent to `restart(sys, t, step.eval(t))`; pass a different `sys` to continue with a
    /// new vector field.
    ///
    /// # Panics
    /// If `t` is outside `[step.t0(), step.t1()]`.
    pub fn rewind(&mut self, sys: &impl OdeSystem<N>, step: &DenseStep<N>, t: f64) {
        self.restart(sys, t, step.eval_inside(t));
    }

    /// Current time \[s\].
    pub fn t(&self) -> f64 {
        self.core.t
    }

    /// Current state.
    pub fn y(&self) -> &SVector<f64, N> {
        &self.core.y
    }

    /// Derivative f(t, y) at the current point (FSAL value).
    pub fn dy(&self) -> &SVector<f64, N> {
        &self.core.dy
    }

    /// Counters for benchmarks/snapshots.
    pub fn stats(&self) -> Stats {
        self.core.stats
    }

    /// Take one accepted step, never passing `t_stop` (it lands exactly on t_stop if it would pass it).
    /// Rejected trial steps are retried internally. Returns the dense step.
    ///
    /// A step is accepted when its error norm is <= 1 (see [`Tolerances`]); the next step is
    /// `h / clamp(err^(0.2-0.75β) / err_old^β / 0.9, 1/10, 5)` with β = 0.04 (Gustafsson's PI
    /// control as in `dopri5`), not grown right after a rejection, and at most `h_max`. A trial
    /// with non-finite values is rejected and the step divided by 5. A step that would end within
    /// 1% of the step size before `t_stop` is stretched to end exactly on it.
    ///
    /// # Errors
    /// [`IntegrationError::NonFinite`] if f(t, y) at the current point is not finite, or if trials
    /// keep producing non-finite values until the step falls below `h_min`;
    /// [`IntegrationError::StepSizeTooSmall`] if the controller's step falls below `h_min`.
    /// The solver is left at its last accepted point.
    ///
    /// # Panics
    /// If `t_stop` is not after the current time.
    pub fn step(
        &mut self,
        sys: &impl OdeSystem<N>,
        t_stop: f64,
    ) -> Result<DenseStep<N>, IntegrationError> {
        self.core.begin(t_stop)?;
        let t = self.core.t;
        let y0 = self.core.y;
        let k1 = self.core.dy;
        let mut rejected_before = false;
        let mut last_non_finite = false;
        loop {
            let (h, t1) = self.core.trial(t_stop, last_non_finite)?;
            let k2 = sys.rhs(t + C2 * h, &(y0 + k1 * (h * A21)));
            let k3 = sys.rhs(t + C3 * h, &(y0 + (k1 * A31 + k2 * A32) * h));
            let k4 = sys.rhs(t + C4 * h, &(y0 + (k1 * A41 + k2 * A42 + k3 * A43) * h));
            let k5 = sys.rhs(
                t + C5 * h,
                &(y0 + (k1 * A51 + k2 * A52 + k3 * A53 + k4 * A54) * h),
            );
            let k6 = sys.rhs(
                t1,
                &(y0 + (k1 * A61 + k2 * A62 + k3 * A63 + k4 * A64 + k5 * A65) * h),
            );
            let y1 = y0 + (k1 * A71 + k3 * A73 + k4 * A74 + k5 * A75 + k6 * A76) * h;
            let k7 = sys.rhs(t1, &y1);
            self.core.stats.rhs_evals += 6;

            let e = (k1 * E1 + k3 * E3 + k4 * E4 + k5 * E5 + k6 * E6 + k7 * E7) * h;
            let err = scaled_rms(&self.core.tol, &e, &y0, &y1);

            if !(err.is_finite() && all_finite(&y1) && all_finite(&k7)) {
                rejected_before = true;
                last_non_finite = true;
                self.core.reject(h, FAC_SHRINK_MAX);
                continue;
            }
            last_non_finite = false;

            let fac11 = err.powf(EXPO1);
            if err <= 1.0 {
                let fac =
                    (fac11 / self.err_old.powf(BETA) / SAFE).clamp(FAC_GROW_MAX, FAC_SHRINK_MAX);
                self.err_old = err.max(ERR_OLD_MIN);
                self.core.accept(h, (t1, y1, k7), h / fac, rejected_before);
                let delta = y1 - y0;
                let bspl = k1 * h - delta;
                return Ok(DenseStep::from_coefficients(
                    t,
                    t1,
                    y1,
                    &[
                        y0,
                        delta,
                        bspl,
                        delta - k7 * h - bspl,
                        (k1 * D1 + k3 * D3 + k4 * D4 + k5 * D5 + k6 * D6 + k7 * D7) * h,
                    ],
                ));
            }
            rejected_before = true;
            self.core.reject(h, FAC_SHRINK_MAX.min(fac11 / SAFE));
        }
    }
}

/// Hairer's starting-step heuristic for a method whose local error is `~ h^order`: h0 = 0.01 ||y0|| / ||f0||,
/// one explicit Euler step to estimate ||y''||, then h = min(100 h0, (0.01 / max(||f0||, ||y''||))^(1/order),
/// h_max). Costs one right-hand-side evaluation (the caller counts it with the one of `f0`).
fn initial_step<const N: usize>(
    sys: &impl OdeSystem<N>,
    tol: &Tolerances,
    t: f64,
    y0: &SVector<f64, N>,
    f0: &SVector<f64, N>,
    order: i32,
) -> f64 {
    let d0 = scaled_rms(tol, y0, y0, y0);
    let d1 = scaled_rms(tol, f0, y0, y0);
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    }
    .min(tol.h_max);
    let f1 = sys.rhs(t + h0, &(y0 + f0 * h0));
    let d2 = scaled_rms(tol, &(f1 - f0), y0, y0) / h0;
    let d12 = d1.max(d2);
    let h1 = if d12 <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d12).powf(1.0 / f64::from(order))
    };
    (100.0 * h0).min(h1).min(tol.h_max)
}

fn all_finite<const N: usize>(v: &SVector<f64, N>) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Largest number of Brent iterations in [`locate_root`] before falling back to bisection.
const BRENT_MAX_ITER: usize = 100;

/// Brent stopping rule in time only: bracket narrower than `t_tol`, or g exactly zero.
struct BracketWidth {
    t_tol: f64,
}

impl roots::Convergency<f64> for BracketWidth {
    fn is_root_found(&mut self, g: f64) -> bool {
        g == 0.0
    }

    fn is_converged(&mut self, t1: f64, t2: f64) -> bool {
        (t1 - t2).abs() <= self.t_tol
    }

    fn is_iteration_limit_reached(&mut self, iter: usize) -> bool {
        iter >= BRENT_MAX_ITER
    }
}

/// Locate a root of g on the dense output inside `step`, given g(t_a) and g(t_b) of opposite sign (or g(t_b)==0)
/// for t_a < t_b inside the step. Brent's method from the `roots` crate, to |dt| <= t_tol (default use 1e-13 s).
/// Returns the root time (the end of the final bracket on the "after crossing" side, i.e. the returned t has
/// g(t) on the same side as g(t_b) or is exactly 0), so that a caller that resets there is past the crossing.
///
/// Method: Brent (1973) on `s(t) = sign(g_b) g(t, step.eval(t))`, stopped when its bracket is
/// narrower than `t_tol`. Brent returns a point near the root that may still be on the
/// pre-crossing side (`s < 0`); in that case the bracket `[t, t_post]` is closed by bisection,
/// with `t_post` the earliest post-crossing time evaluated during the search (or `t_b`), until it
/// is narrower than `t_tol` (or cannot be split in floating point), and its post-crossing end is
/// returned. So the result is within about `t_tol` after the crossing and never before it.
/// If `g_b == 0`, `t_b` is returned. If `g_a == 0` (not allowed by the precondition) `t_a`, an
/// exact root, is returned.
pub fn locate_root<const N: usize>(
    step: &DenseStep<N>,
    g: impl Fn(f64, &SVector<f64, N>) -> f64,
    t_a: f64,
    g_a: f64,
    t_b: f64,
    g_b: f64,
    t_tol: f64,
) -> f64 {
    debug_assert!(t_a < t_b, "empty bracket [{t_a}, {t_b}]");
    debug_assert!(
        g_a * g_b <= 0.0,
        "g({t_a}) = {g_a} and g({t_b}) = {g_b} do not bracket a root"
    );
    if g_b == 0.0 {
        return t_b;
    }
    let side = g_b.signum();
    let s = |t: f64| side * g(t, &step.eval(t));

    let mut t_post = t_b;
    let brent = roots::find_root_brent(
        t_a,
        t_b,
        |t: f64| {
            let v = s(t);
            if v >= 0.0 && t < t_post {
                t_post = t;
            }
            v
        },
        &mut BracketWidth { t_tol },
    );
    // On NoConvergency (or a caller that broke the precondition) start from t_a.
    let t_r = brent.unwrap_or(t_a);
    if s(t_r) >= 0.0 {
        return t_r;
    }
    let mut lo = t_r;
    let mut hi = if t_post > t_r { t_post } else { t_b };
    while hi - lo > t_tol {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if s(mid) >= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// Which Runge-Kutta pair integrates (the `integrator` key of a configuration).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// [`Dop853`]: order 8 with a 7th-order dense output. Default.
    Dop853,
    /// [`Dopri5`]: order 5 with a 4th-order dense output.
    Dopri5,
}

impl Method {
    /// The other method: the second route for a result computed with this one.
    pub fn other(self) -> Method {
        match self {
            Method::Dop853 => Method::Dopri5,
            Method::Dopri5 => Method::Dop853,
        }
    }

    /// The name of the method (`"dop853"` or `"dopri5"`), as in configurations.
    pub fn name(self) -> &'static str {
        match self {
            Method::Dop853 => "dop853",
            Method::Dopri5 => "dopri5",
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// An adaptive integrator of either [`Method`], driven one accepted step at a time.
#[derive(Debug, Clone)]
pub enum Integrator<const N: usize> {
    /// DOP853.
    Dop853(Dop853<N>),
    /// DOPRI5.
    Dopri5(Dopri5<N>),
}

impl<const N: usize> Integrator<N> {
    /// The state between steps.
    fn core(&self) -> &Core<N> {
        match self {
            Integrator::Dop853(s) => s.core(),
            Integrator::Dopri5(s) => &s.core,
        }
    }

    /// Start `method` at (t0, y0) (see [`Dopri5::new`]).
    pub fn new(
        method: Method,
        sys: &impl OdeSystem<N>,
        t0: f64,
        y0: SVector<f64, N>,
        tol: Tolerances,
    ) -> Self {
        match method {
            Method::Dop853 => Integrator::Dop853(Dop853::new(sys, t0, y0, tol)),
            Method::Dopri5 => Integrator::Dopri5(Dopri5::new(sys, t0, y0, tol)),
        }
    }

    /// One accepted step, never passing `t_stop` (see [`Dopri5::step`]).
    ///
    /// # Errors
    /// As [`Dopri5::step`].
    pub fn step(
        &mut self,
        sys: &impl OdeSystem<N>,
        t_stop: f64,
    ) -> Result<DenseStep<N>, IntegrationError> {
        match self {
            Integrator::Dop853(s) => s.step(sys, t_stop),
            Integrator::Dopri5(s) => s.step(sys, t_stop),
        }
    }

    /// Restart at (t, y), possibly with a new vector field (see [`Dopri5::restart`]).
    pub fn restart(&mut self, sys: &impl OdeSystem<N>, t: f64, y: SVector<f64, N>) {
        match self {
            Integrator::Dop853(s) => s.restart(sys, t, y),
            Integrator::Dopri5(s) => s.restart(sys, t, y),
        }
    }

    /// Work counters.
    pub fn stats(&self) -> Stats {
        self.core().stats
    }

    /// Current time \[s\].
    pub fn t(&self) -> f64 {
        self.core().t
    }

    /// Current state.
    pub fn y(&self) -> &SVector<f64, N> {
        &self.core().y
    }

    /// Derivative f(t, y) at the current point (FSAL value).
    pub fn dy(&self) -> &SVector<f64, N> {
        &self.core().dy
    }

    /// Move back to time `t` inside the last step, possibly with a new vector field (see [`Dopri5::rewind`]).
    ///
    /// # Panics
    /// If `t` is outside `[step.t0(), step.t1()]`.
    pub fn rewind(&mut self, sys: &impl OdeSystem<N>, step: &DenseStep<N>, t: f64) {
        self.restart(sys, t, step.eval_inside(t));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::{FallingPoint, HarmonicOscillator};
    use approx::{assert_abs_diff_eq, assert_relative_eq};
    use std::f64::consts::PI;

    /// Time tolerance handed to `locate_root` \[s\] (the contract's default).
    const ROOT_T_TOL: f64 = 1e-13;
    /// Required accuracy of the falling point's impact time at rtol 1e-10 \[s\].
    const IMPACT_TIME_TOL: f64 = 1e-12;
    /// Required accuracy of the oscillator's zero crossings at rtol 1e-10, atol 1e-12 \[s\].
    const CROSSING_TIME_TOL: f64 = 1e-9;
    /// Required accuracy of the oscillator state after 10 periods \[m, m/s\].
    const FINAL_STATE_TOL: f64 = 1e-8;
    /// Allowed relative energy drift of the oscillator over 10 periods (~2000 steps at
    /// rtol 1e-10; same size as the state tolerance).
    const ENERGY_DRIFT_TOL: f64 = 1e-8;
    /// A 4th-order continuous extension has local error O(h^5): halving h divides it by ~32.
    /// Requiring >= 16 (= 2^4) fails for an interpolant of order 3 or less.
    const MIN_DENSE_ERROR_RATIO: f64 = 16.0;
    /// The same for DOP853's 7th-order extension (local error O(h^8), ~256 per halving): >= 2^7.
    const MIN_DENSE853_ERROR_RATIO: f64 = 128.0;
    /// Largest distance of the observed convergence order from the method's order.
    const ORDER_TOL: f64 = 0.5;
    /// Both methods, for the tests that hold for each.
    const METHODS: [Method; 2] = [Method::Dop853, Method::Dopri5];
    /// Roundoff allowance for times built from sums of floating-point steps \[s\].
    const TIME_ROUNDOFF: f64 = 1e-14;
    /// Safety cap on steps in test loops, so a broken solver fails instead of hanging.
    const MAX_STEPS: usize = 1_000_000;

    fn tight() -> Tolerances {
        Tolerances::default()
    }

    /// Step until `g` goes from > 0 to <= 0; returns the located time and the step holding it.
    fn first_downward_crossing<const N: usize>(
        solver: &mut Integrator<N>,
        sys: &impl OdeSystem<N>,
        t_end: f64,
        g: impl Fn(f64, &SVector<f64, N>) -> f64,
        t_tol: f64,
    ) -> (f64, DenseStep<N>) {
        let mut g_a = g(solver.t(), solver.y());
        for _ in 0..MAX_STEPS {
            let step = solver.step(sys, t_end).expect("integration failed");
            let g_b = g(step.t1(), step.y1());
            if g_a > 0.0 && g_b <= 0.0 {
                let t = locate_root(&step, &g, step.t0(), g_a, step.t1(), g_b, t_tol);
                return (t, step);
            }
            assert!(step.t1() < t_end, "no crossing before t_end");
            g_a = g_b;
        }
        panic!("too many steps");
    }

    /// Exact flow of x'' = -w^2 x over time s from state y.
    fn oscillator_flow(omega: f64, y: &SVector<f64, 2>, s: f64) -> SVector<f64, 2> {
        let (sn, cs) = (omega * s).sin_cos();
        SVector::<f64, 2>::new(
            y[0] * cs + y[1] / omega * sn,
            -y[0] * omega * sn + y[1] * cs,
        )
    }

    #[test]
    fn falling_point_impact_time_is_exact() {
        for method in METHODS {
            for v0 in [0.5, 0.0, -0.3] {
                let sys = FallingPoint {
                    h0: 1.0,
                    v0,
                    g: 9.81,
                };
                let mut solver = Integrator::new(method, &sys, 0.0, sys.exact(0.0), tight());
                let (t, step) =
                    first_downward_crossing(&mut solver, &sys, 10.0, |_, y| y[0], ROOT_T_TOL);
                let err = t - sys.exact_impact_time();
                eprintln!("falling point v0 = {v0}: impact time error {err:e} s");
                assert_abs_diff_eq!(t, sys.exact_impact_time(), epsilon = IMPACT_TIME_TOL);
                assert!(
                    step.eval(t)[0] <= 0.0,
                    "located time is before the crossing"
                );
            }
        }
    }

    #[test]
    fn locate_root_is_after_crossing_within_t_tol() {
        for method in METHODS {
            let sys = FallingPoint {
                h0: 1.0,
                v0: 0.5,
                g: 9.81,
            };
            let t_exact = sys.exact_impact_time();
            for t_tol in [1e-3, 1e-5, 1e-7, 1e-9, 1e-11, 1e-13] {
                let mut solver = Integrator::new(method, &sys, 0.0, sys.exact(0.0), tight());
                let (t, step) =
                    first_downward_crossing(&mut solver, &sys, 10.0, |_, y| y[0], t_tol);
                assert!(
                    step.eval(t)[0] <= 0.0,
                    "t_tol {t_tol:e}: located time before the crossing"
                );
                assert!(
                    t >= t_exact - TIME_ROUNDOFF,
                    "t_tol {t_tol:e}: {t} before {t_exact}"
                );
                assert!(
                    t <= t_exact + t_tol + TIME_ROUNDOFF,
                    "t_tol {t_tol:e}: {t} too late"
                );
            }
        }
    }

    #[test]
    fn oscillator_crossings_final_state_and_energy() {
        for method in METHODS {
            let sys = HarmonicOscillator {
                omega: 3.0,
                amplitude: 0.7,
                phase: 0.3,
            };
            let tol = Tolerances {
                rtol: 1e-10,
                atol: 1e-12,
                ..Tolerances::default()
            };
            let t_end = 10.0 * 2.0 * PI / sys.omega;
            let energy =
                |y: &SVector<f64, 2>| 0.5 * (y[1] * y[1] + sys.omega * sys.omega * y[0] * y[0]);
            let e0 = energy(&sys.exact(0.0));
            let mut solver = Integrator::new(method, &sys, 0.0, sys.exact(0.0), tol);
            let mut crossings = Vec::new();
            let mut max_drift: f64 = 0.0;
            while solver.t() < t_end {
                let step = solver.step(&sys, t_end).expect("integration failed");
                max_drift = max_drift.max(((energy(step.y1()) - e0) / e0).abs());
                let (g_a, g_b) = (step.y0()[0], step.y1()[0]);
                if g_a != 0.0 && g_a * g_b <= 0.0 {
                    let t = locate_root(
                        &step,
                        |_, y| y[0],
                        step.t0(),
                        g_a,
                        step.t1(),
                        g_b,
                        ROOT_T_TOL,
                    );
                    let x = step.eval(t)[0];
                    assert!(
                        x == 0.0 || x.signum() == g_b.signum(),
                        "crossing at {t} not past the root"
                    );
                    crossings.push(t);
                }
            }
            assert_eq!(solver.t(), t_end);
            assert!(crossings.len() >= 10);
            let max_crossing_err = crossings
                .iter()
                .take(10)
                .enumerate()
                .map(|(k, t)| (t - sys.zero_crossing(k)).abs())
                .fold(0.0, f64::max);
            let final_err = (solver.y() - sys.exact(t_end)).amax();
            eprintln!(
            "oscillator: max crossing error {max_crossing_err:e} s, final state error {final_err:e}, \
             max relative energy drift {max_drift:e}, {:?}",
            solver.stats()
        );
            for (k, t) in crossings.iter().take(10).enumerate() {
                assert_abs_diff_eq!(*t, sys.zero_crossing(k), epsilon = CROSSING_TIME_TOL);
            }
            assert_abs_diff_eq!(*solver.y(), sys.exact(t_end), epsilon = FINAL_STATE_TOL);
            assert!(max_drift < ENERGY_DRIFT_TOL, "energy drift {max_drift:e}");
        }
    }

    /// The oscillator x'' = -4 x from x = 1 and `method` on it with largest step `h_max` and tolerances `tol`
    /// (loose, so that `h_max` sets the step).
    fn steps_of(method: Method, h_max: f64, tol: f64) -> (HarmonicOscillator, Integrator<2>) {
        let sys = HarmonicOscillator {
            omega: 2.0,
            amplitude: 1.0,
            phase: 0.0,
        };
        let tol = Tolerances {
            rtol: tol,
            atol: tol,
            h_max,
            ..Tolerances::default()
        };
        let solver = Integrator::new(method, &sys, 0.0, sys.exact(0.0), tol);
        (sys, solver)
    }

    /// Largest dense-output error inside steps of size exactly `h_max`, against the exact flow
    /// from each step's start (so only the interpolation error is measured).
    fn max_dense_error(method: Method, h_max: f64) -> f64 {
        // So loose that h_max, not the error control, sets the step.
        let (sys, mut solver) = steps_of(method, h_max, 1e-3);
        let (mut max_err, mut full_steps) = (0.0_f64, 0);
        while solver.t() < 4.0 {
            let step = solver.step(&sys, 4.0).expect("integration failed");
            let h = step.t1() - step.t0();
            if (h - h_max).abs() > TIME_ROUNDOFF {
                continue;
            }
            full_steps += 1;
            for i in 1..10 {
                let s = h * f64::from(i) / 10.0;
                let exact = oscillator_flow(sys.omega, step.y0(), s);
                max_err = max_err.max((step.eval(step.t0() + s) - exact).amax());
            }
        }
        assert!(full_steps > 10, "h_max did not bind");
        max_err
    }

    #[test]
    fn dense_output_has_the_methods_order() {
        // DOPRI5's continuous extension is of order 4, DOP853's of order 7.
        for (method, min_ratio) in [
            (Method::Dopri5, MIN_DENSE_ERROR_RATIO),
            (Method::Dop853, MIN_DENSE853_ERROR_RATIO),
        ] {
            let (coarse, fine) = (max_dense_error(method, 0.1), max_dense_error(method, 0.05));
            let ratio = coarse / fine;
            eprintln!(
                "{method} dense output error: h=0.1 {coarse:e}, h=0.05 {fine:e}, ratio {ratio:.1}"
            );
            assert!(ratio >= min_ratio, "{method}: ratio {ratio}");
        }
    }

    /// Error at t = 4 of the oscillator integrated in steps of exactly `h` (the tolerance so loose that `h`
    /// binds).
    fn global_error(method: Method, h: f64) -> f64 {
        let (sys, mut solver) = steps_of(method, h, 1.0);
        while solver.t() < 4.0 {
            solver.step(&sys, 4.0).expect("integration failed");
        }
        (solver.y() - sys.exact(4.0)).amax()
    }

    /// The tableau taken from `differential-equations` gives a method of order 8 (and DOPRI5 one of order 5):
    /// halving the step divides the global error by about 2^8 (2^5).
    #[test]
    fn methods_converge_with_their_order() {
        for (method, order) in [(Method::Dopri5, 5), (Method::Dop853, 8)] {
            let (coarse, fine) = (global_error(method, 0.2), global_error(method, 0.1));
            let observed = (coarse / fine).log2();
            eprintln!(
                "{method}: global error {coarse:e} -> {fine:e}, observed order {observed:.2}"
            );
            assert!(
                (observed - f64::from(order)).abs() < ORDER_TOL,
                "{method}: observed order {observed}"
            );
        }
    }

    #[test]
    fn dense_output_matches_step_ends() {
        for method in METHODS {
            let sys = HarmonicOscillator {
                omega: 3.0,
                amplitude: 0.7,
                phase: 0.3,
            };
            let mut solver = Integrator::new(method, &sys, 0.0, sys.exact(0.0), tight());
            let y_start = *solver.y();
            let step = solver.step(&sys, 1.0).unwrap();
            assert_eq!(step.eval(step.t0()), y_start);
            assert_eq!(step.eval(step.t1()), *solver.y());
            assert_eq!(step.y1(), solver.y());
            assert_eq!(step.t1(), solver.t());
        }
    }

    #[test]
    fn step_lands_exactly_on_t_stop() {
        for method in METHODS {
            let sys = HarmonicOscillator {
                omega: 3.0,
                amplitude: 0.7,
                phase: 0.3,
            };
            let mut solver = Integrator::new(method, &sys, 0.0, sys.exact(0.0), tight());
            let t_stop = 0.123_456_789;
            while solver.t() < t_stop {
                let step = solver.step(&sys, t_stop).unwrap();
                assert!(step.t1() <= t_stop);
            }
            assert_eq!(solver.t(), t_stop);
            // A sliver far below h_min still lands exactly (h_min limits the controller only).
            let t_sliver = t_stop + 1e-16;
            assert!(t_sliver > t_stop);
            let step = solver.step(&sys, t_sliver).unwrap();
            assert_eq!(step.t1(), t_sliver);
            assert_eq!(solver.t(), t_sliver);
            assert_abs_diff_eq!(*solver.y(), sys.exact(t_sliver), epsilon = FINAL_STATE_TOL);
        }
    }

    #[test]
    fn restart_with_reset_state_and_new_vector_field() {
        for method in METHODS {
            // A ball bounces with restitution e on a floor and lands on a planet with other gravity.
            let (e, g2) = (0.8, 3.7);
            let fall = FallingPoint {
                h0: 1.0,
                v0: 0.5,
                g: 9.81,
            };
            let mut solver = Integrator::new(method, &fall, 0.0, fall.exact(0.0), tight());
            let (t1, step) =
                first_downward_crossing(&mut solver, &fall, 10.0, |_, y| y[0], ROOT_T_TOL);
            let y1 = step.eval(t1);
            let rise = FallingPoint {
                h0: 0.0,
                v0: -e * y1[1],
                g: g2,
            };
            solver.restart(&rise, t1, SVector::<f64, 2>::new(y1[0], -e * y1[1]));
            assert_eq!(solver.t(), t1);
            assert_eq!(*solver.dy(), rise.rhs(t1, solver.y()));
            // z starts at <= 0 (post-crossing side) and rises: no spurious re-detection of t1.
            let (t2, _) =
                first_downward_crossing(&mut solver, &rise, 10.0, |_, y| y[0], ROOT_T_TOL);
            let t1_exact = fall.exact_impact_time();
            let t2_exact = t1_exact + 2.0 * e * (fall.g * t1_exact - fall.v0) / g2;
            eprintln!("bounce: second impact error {:e} s", t2 - t2_exact);
            assert!(t2 - t1 > 0.1, "reset re-reported the old root");
            assert_abs_diff_eq!(t2, t2_exact, epsilon = IMPACT_TIME_TOL);
        }
    }

    #[test]
    fn rewind_to_event_inside_step_with_new_vector_field() {
        for method in METHODS {
            // At the first zero of x the frequency changes from w1 to w2 (same state, new field).
            let osc1 = HarmonicOscillator {
                omega: 3.0,
                amplitude: 0.7,
                phase: 0.3,
            };
            let osc2 = HarmonicOscillator { omega: 5.0, ..osc1 };
            let mut solver = Integrator::new(method, &osc1, 0.0, osc1.exact(0.0), tight());
            let (t_c, step) =
                first_downward_crossing(&mut solver, &osc1, 10.0, |_, y| y[0], ROOT_T_TOL);
            assert!(t_c < step.t1(), "event should be inside the step");
            solver.rewind(&osc2, &step, t_c);
            assert_eq!(solver.t(), t_c);
            assert_eq!(*solver.y(), step.eval(t_c));
            let y_c = *solver.y();
            // x now goes negative then comes back up; its next zero is half a period of w2 later.
            let (t_next, _) =
                first_downward_crossing(&mut solver, &osc2, 10.0, |_, y| -y[0], ROOT_T_TOL);
            let t_exact = osc1.zero_crossing(0) + PI / osc2.omega;
            eprintln!("rewind: next crossing error {:e} s", t_next - t_exact);
            assert_abs_diff_eq!(t_next, t_exact, epsilon = CROSSING_TIME_TOL);
            let at_next = oscillator_flow(osc2.omega, &y_c, t_next - t_c);
            assert_abs_diff_eq!(at_next[0], 0.0, epsilon = FINAL_STATE_TOL);
        }
    }

    /// y' = y², y(0) = 1: y = 1/(1 - t) blows up at t = 1.
    struct Riccati;
    impl OdeSystem<1> for Riccati {
        fn rhs(&self, _t: f64, y: &SVector<f64, 1>) -> SVector<f64, 1> {
            y.component_mul(y)
        }
    }

    /// Returns NaN from t = 0.5 on (x' = 1 before).
    struct NanAfterHalf;
    impl OdeSystem<1> for NanAfterHalf {
        fn rhs(&self, t: f64, _y: &SVector<f64, 1>) -> SVector<f64, 1> {
            SVector::<f64, 1>::new(if t < 0.5 { 1.0 } else { f64::NAN })
        }
    }

    /// Run until the first error (the test systems never reach `t_end`).
    fn run_until_error<const N: usize>(
        solver: &mut Integrator<N>,
        sys: &impl OdeSystem<N>,
        t_end: f64,
    ) -> IntegrationError {
        for _ in 0..MAX_STEPS {
            if let Err(err) = solver.step(sys, t_end) {
                return err;
            }
            assert!(solver.t() < t_end, "reached t_end without error");
        }
        panic!("too many steps");
    }

    #[test]
    fn blow_up_returns_step_size_too_small() {
        for method in METHODS {
            let tol = tight();
            let mut solver =
                Integrator::new(method, &Riccati, 0.0, SVector::<f64, 1>::new(1.0), tol);
            let err = run_until_error(&mut solver, &Riccati, 2.0);
            eprintln!(
                "blow-up: {err} after {:?}, y = {:e}",
                solver.stats(),
                solver.y()[0]
            );
            match err {
                IntegrationError::StepSizeTooSmall { time, h_min } => {
                    assert_eq!(h_min, tol.h_min);
                    assert_eq!(time, solver.t());
                    // Within rounding of the singularity (DOP853 may step a hair past it).
                    assert!((time - 1.0).abs() < 1e-6, "stopped at {time}");
                }
                other => panic!("expected StepSizeTooSmall, got {other:?}"),
            }
        }
    }

    #[test]
    fn nan_system_returns_non_finite() {
        for method in METHODS {
            let nan_everywhere = |_: f64| SVector::<f64, 1>::new(f64::NAN);
            struct AlwaysNan<F>(F);
            impl<F: Fn(f64) -> SVector<f64, 1>> OdeSystem<1> for AlwaysNan<F> {
                fn rhs(&self, t: f64, _y: &SVector<f64, 1>) -> SVector<f64, 1> {
                    (self.0)(t)
                }
            }
            let sys = AlwaysNan(nan_everywhere);
            let mut solver =
                Integrator::new(method, &sys, 0.0, SVector::<f64, 1>::new(1.0), tight());
            assert_eq!(
                solver.step(&sys, 1.0).unwrap_err(),
                IntegrationError::NonFinite { time: 0.0 }
            );

            let mut solver = Integrator::new(
                method,
                &NanAfterHalf,
                0.0,
                SVector::<f64, 1>::new(0.0),
                tight(),
            );
            let err = run_until_error(&mut solver, &NanAfterHalf, 1.0);
            eprintln!("NaN after 0.5: {err} after {:?}", solver.stats());
            match err {
                IntegrationError::NonFinite { time } => {
                    assert!(time < 0.5 && time > 0.5 - 1e-12, "stopped at {time}");
                    assert_relative_eq!(solver.y()[0], time, max_relative = 1e-12);
                }
                other => panic!("expected NonFinite, got {other:?}"),
            }
        }
    }

    #[test]
    fn stats_count_every_rhs_evaluation() {
        let sys = HarmonicOscillator {
            omega: 3.0,
            amplitude: 0.7,
            phase: 0.3,
        };
        // Per trial step, and per accepted step on top (DOP853: f(t1, y1) and three dense-output stages).
        for (method, per_trial, per_accepted) in [(Method::Dopri5, 6, 0), (Method::Dop853, 11, 4)] {
            let mut solver = Integrator::new(method, &sys, 0.0, sys.exact(0.0), tight());
            assert_eq!(solver.stats().rhs_evals, 2);
            for _ in 0..20 {
                solver.step(&sys, 10.0).unwrap();
            }
            let y = *solver.y();
            solver.restart(&sys, solver.t(), y);
            let s = solver.stats();
            assert_eq!(s.accepted, 20);
            assert_eq!(
                s.rhs_evals,
                2 + per_trial * (s.accepted + s.rejected) + per_accepted * s.accepted + 2,
                "{method}"
            );
        }
    }
}
