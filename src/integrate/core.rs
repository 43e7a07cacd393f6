//! The stepping state and step-size control that DOPRI5 and DOP853 share ([`Core`]): the current point and its
//! FSAL derivative, the checks before a step, the trial step (bounded by `h_max`, landing on `t_stop`), rejection
//! and acceptance, restarts, Hairer's starting-step heuristic (HNW I, Sec. II.4), and the work counters
//! ([`Stats`]).

use nalgebra::SVector;

use super::tolerances::scaled_rms;
use super::{IntegrationError, OdeSystem, Tolerances};

/// Work counters of a [`Dopri5`](super::Dopri5) or `Dop853` solver, for benchmarks and snapshot tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Stats {
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected trial steps (error too large or non-finite values).
    pub rejected: usize,
    /// Evaluations of [`OdeSystem::rhs`], including those for starting-step estimates.
    pub rhs_evals: usize,
}

/// A step within this factor of `t_stop` is stretched to land on it (avoids a sliver step).
const LAND_STRETCH: f64 = 1.01;

/// What both Runge-Kutta pairs keep between steps, and the parts of a step they share: the checks before a
/// step, the trial step size, a rejection and an acceptance.
#[derive(Debug, Clone)]
pub(super) struct Core<const N: usize> {
    /// Tolerances and step bounds.
    pub(super) tol: Tolerances,
    /// Current time \[s\].
    pub(super) t: f64,
    /// Current state.
    pub(super) y: SVector<f64, N>,
    /// FSAL value f(t, y).
    pub(super) dy: SVector<f64, N>,
    /// Step size the controller proposes for the next trial \[s\].
    h: f64,
    /// Size of the last accepted step \[s\], if any.
    h_accepted: Option<f64>,
    /// Work counters.
    pub(super) stats: Stats,
}

impl<const N: usize> Core<N> {
    /// At (t0, y0), for a method whose local error is `~ h^order`: f(t0, y0) and a starting step (two
    /// evaluations).
    pub(super) fn new(
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
    pub(super) fn restart(
        &mut self,
        sys: &impl OdeSystem<N>,
        t: f64,
        y: SVector<f64, N>,
        order: i32,
    ) {
        self.reset_point(sys, t, y, order);
        if let Some(h_acc) = self.h_accepted {
            self.h = self.h.min(h_acc);
        }
    }

    /// The checks before a step: `t_stop` after the current time (else a panic), a finite current point.
    pub(super) fn begin(&self, t_stop: f64) -> Result<(), IntegrationError> {
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
    pub(super) fn trial(
        &self,
        t_stop: f64,
        last_non_finite: bool,
    ) -> Result<(f64, f64), IntegrationError> {
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
    pub(super) fn reject(&mut self, h: f64, divisor: f64) {
        self.stats.rejected += 1;
        self.h = h / divisor;
    }

    /// Accept a trial of size `h` ending at `(t1, y1)` with `f1 = f(t1, y1)`; the next trial is `h_new`, not
    /// grown right after a rejection, and at most `h_max`.
    pub(super) fn accept(
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
    let skip = sys.unmeasured();
    let d0 = scaled_rms(tol, y0, (y0, y0), skip);
    let d1 = scaled_rms(tol, f0, (y0, y0), skip);
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    }
    .min(tol.h_max);
    let f1 = sys.rhs(t + h0, &(y0 + f0 * h0));
    let d2 = scaled_rms(tol, &(f1 - f0), (y0, y0), skip) / h0;
    let d12 = d1.max(d2);
    let h1 = if d12 <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d12).powf(1.0 / f64::from(order))
    };
    (100.0 * h0).min(h1).min(tol.h_max)
}

/// Whether every component of `v` is finite.
pub(super) fn all_finite<const N: usize>(v: &SVector<f64, N>) -> bool {
    v.iter().all(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::testing::{tight, FINAL_STATE_TOL, MAX_STEPS, METHODS};
    use crate::integrate::{Integrator, Method};
    use crate::reference::HarmonicOscillator;
    use approx::{assert_abs_diff_eq, assert_relative_eq};

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

    /// The harmonic oscillator with two constant components inserted (at 1 and 3) that the error norm leaves
    /// out ([`OdeSystem::unmeasured`]): it must take the oscillator's steps, bit for bit.
    struct Padded(HarmonicOscillator);
    impl OdeSystem<4> for Padded {
        fn rhs(&self, t: f64, y: &SVector<f64, 4>) -> SVector<f64, 4> {
            let f = self.0.rhs(t, &SVector::<f64, 2>::new(y[0], y[2]));
            SVector::<f64, 4>::new(f[0], 0.0, f[1], 0.0)
        }
        fn unmeasured(&self) -> &[usize] {
            &[1, 3]
        }
    }

    #[test]
    fn unmeasured_components_leave_the_steps_unchanged() {
        for method in METHODS {
            let sys = HarmonicOscillator {
                omega: 3.0,
                amplitude: 0.7,
                phase: 0.3,
            };
            let y0 = sys.exact(0.0);
            let padded = Padded(sys);
            let tol = tight();
            let mut plain = Integrator::new(method, &sys, 0.0, y0, tol);
            let start = SVector::<f64, 4>::new(y0[0], 5.0, y0[1], -2.0);
            let mut with = Integrator::new(method, &padded, 0.0, start, tol);
            for _ in 0..50 {
                let (a, b) = (
                    plain.step(&sys, 10.0).unwrap(),
                    with.step(&padded, 10.0).unwrap(),
                );
                assert_eq!(a.t1().to_bits(), b.t1().to_bits());
                let (ya, yb) = (plain.y(), with.y());
                assert_eq!(
                    (ya[0].to_bits(), ya[1].to_bits()),
                    (yb[0].to_bits(), yb[2].to_bits())
                );
                assert_eq!((yb[1], yb[3]), (5.0, -2.0));
            }
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
