//! Adaptive Dormand–Prince integration with dense output and event-root location.
//!
//! Two explicit Runge–Kutta pairs, chosen by [`Method`] (the `integrator` key of a configuration) and driven
//! through `Integrator`: `Dop853` (order 8, the default) and [`Dopri5`] (order 5). Both hand out each
//! accepted step as a [`DenseStep`], on which the caller locates events (`locate_root`).
//!
//! [`Dopri5`] is the explicit Runge–Kutta pair of Dormand & Prince (1980) used in
//! local extrapolation mode (the 5th-order solution is propagated, the embedded 4th-order one
//! only estimates the error), with FSAL (the last stage is f at the new point), the PI
//! ("Lund-stabilised") step-size controller of Gustafsson (1991) as in Hairer's `dopri5`, the
//! starting-step heuristic of Hairer, Nørsett & Wanner (1993, Sec. II.4), and Shampine's (1986)
//! 4th-order continuous extension (the `contd5` dense output of `dopri5`, HNW Sec. II.6).
//!
//! # Layout
//! - this file: the [`OdeSystem`] trait, [`IntegrationError`], the [`Method`] choice and the `Integrator`
//!   front over both pairs;
//! - `tolerances`: [`Tolerances`] and the scaled error norm;
//! - `core`: the stepping state and step-size control both pairs share (trial step, rejection,
//!   acceptance, restart, starting step) and the work counters [`Stats`];
//! - `dopri5`, `dop853`: each pair's tableau and step;
//! - `dense`: the dense output [`DenseStep`] and its interpolation;
//! - `roots`: `locate_root`, root location on the dense output.
//!
//! # Why hand-written
//! The hybrid walk needs (i) fixed-size stack state (`SVector<f64, N>`, N = 11 and larger for
//! augmented systems) with no heap allocation per right-hand-side call or step; (ii) events with a
//! crossing direction and arming guards decided by the caller; and (iii) restarts with a new state
//! and possibly a new vector field after every event. diffsol's root finder reports any sign
//! change (no direction filter), re-reports a root right after a reset, and its problem must be
//! rebuilt per phase. So this module only integrates one accepted step at a time
//! ([`Dopri5::step`] returns a [`DenseStep`]); the caller evaluates its event functions on the
//! dense output and refines a bracketed root with `locate_root`, which uses Brent's method from
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

mod core;
mod dense;
mod dop853;
mod dopri5;
mod roots;
#[cfg(test)]
mod testing;
mod tolerances;

use self::core::Core;
pub use self::core::Stats;
pub use self::dense::DenseStep;
pub(crate) use self::dop853::Dop853;
pub use self::dopri5::Dopri5;
pub(crate) use self::roots::locate_root;
pub use self::tolerances::Tolerances;

/// A first-order system y' = f(t, y).
pub trait OdeSystem<const N: usize> {
    /// The right-hand side f(t, y).
    fn rhs(&self, t: f64, y: &SVector<f64, N>) -> SVector<f64, N>;

    /// Components of `y` the error norm leaves out (none by default): components that are constant in this
    /// system (a coordinate that is absent from it, as the walk's swinging-leg length when no leg swings), so
    /// that the norm, and every step size, is that of the system without them, bit for bit.
    fn unmeasured(&self) -> &[usize] {
        &[]
    }
}

/// A step of given size without error control (`Integrator::fixed_step`): its end, the vector field there, and
/// its dense output if asked for.
#[derive(Debug, Clone)]
pub(crate) struct FixedStep<const N: usize> {
    /// The state at the end.
    pub(crate) y1: SVector<f64, N>,
    /// `f(t1, y1)` (the next step's first stage).
    pub(crate) f1: SVector<f64, N>,
    /// The dense output over the step.
    pub(crate) dense: Option<DenseStep<N>>,
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

/// Which Runge-Kutta pair integrates (the `integrator` key of a configuration).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// `Dop853`: order 8 with a 7th-order dense output. Default.
    Dop853,
    /// [`Dopri5`]: order 5 with a 4th-order dense output.
    Dopri5,
}

impl Method {
    /// The other method: the second route for a result computed with this one.
    pub(crate) fn other(self) -> Method {
        match self {
            Method::Dop853 => Method::Dopri5,
            Method::Dopri5 => Method::Dop853,
        }
    }

    /// The name of the method (`"dop853"` or `"dopri5"`), as in configurations.
    pub(crate) fn name(self) -> &'static str {
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
pub(crate) enum Integrator<const N: usize> {
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
            Integrator::Dopri5(s) => s.core(),
        }
    }

    /// Start `method` at (t0, y0) (see [`Dopri5::new`]).
    pub(crate) fn new(
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
    pub(crate) fn step(
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
    pub(crate) fn restart(&mut self, sys: &impl OdeSystem<N>, t: f64, y: SVector<f64, N>) {
        match self {
            Integrator::Dop853(s) => s.restart(sys, t, y),
            Integrator::Dopri5(s) => s.restart(sys, t, y),
        }
    }

    /// One step of `method` of the given size `h` from `(t, y0)` (with `f0 = f(t, y0)`) to `t1`, with no error
    /// control: an accepted step of an adaptive run taken again on another system whose first components are
    /// the original one's (the variational equations of `crate::variational`, which thereby see the original
    /// run's steps, states and dense output bit for bit). The dense output only if `dense`.
    pub(crate) fn fixed_step(
        method: Method,
        sys: &impl OdeSystem<N>,
        start: (f64, &SVector<f64, N>, &SVector<f64, N>),
        (h, t1): (f64, f64),
        dense: bool,
    ) -> FixedStep<N> {
        match method {
            Method::Dop853 => dop853::fixed_step(sys, start, h, t1, dense),
            Method::Dopri5 => dopri5::fixed_step(sys, start, h, t1, dense),
        }
    }

    /// Work counters.
    pub(crate) fn stats(&self) -> Stats {
        self.core().stats
    }

    /// Current time \[s\].
    #[cfg(test)]
    pub(crate) fn t(&self) -> f64 {
        self.core().t
    }

    /// Current state.
    #[cfg(test)]
    pub(crate) fn y(&self) -> &SVector<f64, N> {
        &self.core().y
    }

    /// Derivative f(t, y) at the current point (FSAL value).
    #[cfg(test)]
    pub(crate) fn dy(&self) -> &SVector<f64, N> {
        &self.core().dy
    }

    /// Move back to time `t` inside the last step, possibly with a new vector field (see [`Dopri5::rewind`]).
    ///
    /// # Panics
    /// If `t` is outside `[step.t0(), step.t1()]`.
    #[cfg(test)]
    pub(crate) fn rewind(&mut self, sys: &impl OdeSystem<N>, step: &DenseStep<N>, t: f64) {
        self.restart(sys, t, step.eval_inside(t));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::testing::{
        first_downward_crossing, oscillator_flow, tight, CROSSING_TIME_TOL, FINAL_STATE_TOL,
        IMPACT_TIME_TOL, METHODS, ROOT_T_TOL,
    };
    use crate::reference::{FallingPoint, HarmonicOscillator};
    use approx::assert_abs_diff_eq;
    use std::f64::consts::PI;

    /// Allowed relative energy drift of the oscillator over 10 periods (~2000 steps at
    /// rtol 1e-10; same size as the state tolerance).
    const ENERGY_DRIFT_TOL: f64 = 1e-8;

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
}
