//! Dense output: one accepted step with its continuous extension ([`DenseStep`]), evaluated anywhere inside the
//! step by Horner's scheme in the nested form of Hairer's codes (HNW I, Sec. II.6).

use nalgebra::SVector;

/// One accepted step with its continuous extension (dense output), in the nested form of Hairer's codes.
///
/// With `θ = (t - t0)/(t1 - t0)` the interpolant is
/// `y(t) = c0 + θ (c1 + (1-θ) (c2 + θ (c3 + (1-θ) (c4 + θ (c5 + (1-θ) (c6 + θ c7))))))`, truncated after the
/// last coefficient the method has: five for [`Dopri5`](super::Dopri5) (`c0 = y0`, `c1 = Δ = y1 - y0`, `c2 = h k1 - Δ`,
/// `c3 = Δ - h k7 - c2`, `c4 = h Σ d_i k_i`: Shampine's 4th-order extension, `contd5` of `dopri5`), eight for
/// `Dop853` (its 7th-order extension, `contd8` of `dop853`). It matches y0, y1, f0 and f1.
#[derive(Debug, Clone)]
pub struct DenseStep<const N: usize> {
    t0: f64,
    t1: f64,
    /// The step size the method used (`t1 - t0` up to rounding; exactly the `h` of its stages).
    h: f64,
    y1: SVector<f64, N>,
    /// `c0 .. c7`; only the first `terms` are used.
    cont: [SVector<f64, N>; MAX_DENSE_TERMS],
    terms: usize,
}

/// Most coefficients of a continuous extension ([`Dop853`](super::Dop853) has eight).
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

    /// The step size the method used: `t1 - t0` up to rounding, exactly the `h` of its stages (what a fixed
    /// step needs to take the same step again, `Integrator::fixed_step`).
    pub(crate) fn h(&self) -> f64 {
        self.h
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
    pub(crate) fn eval(&self, t: f64) -> SVector<f64, N> {
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
    pub(super) fn eval_inside(&self, t: f64) -> SVector<f64, N> {
        assert!(
            self.t0 <= t && t <= self.t1,
            "rewind time {t} outside the step [{}, {}]",
            self.t0,
            self.t1
        );
        self.eval(t)
    }

    /// A dense step from its coefficients `c0 ..` (see the type's documentation).
    pub(super) fn from_coefficients(
        (t0, t1, h): (f64, f64, f64),
        y1: SVector<f64, N>,
        coefficients: &[SVector<f64, N>],
    ) -> Self {
        let mut cont = [SVector::zeros(); MAX_DENSE_TERMS];
        cont[..coefficients.len()].copy_from_slice(coefficients);
        DenseStep {
            t0,
            t1,
            h,
            y1,
            cont,
            terms: coefficients.len(),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::integrate::testing::{oscillator_flow, steps_of, tight, METHODS, TIME_ROUNDOFF};
    use crate::integrate::{Integrator, Method};
    use crate::reference::HarmonicOscillator;

    /// A 4th-order continuous extension has local error O(h^5): halving h divides it by ~32.
    /// Requiring >= 16 (= 2^4) fails for an interpolant of order 3 or less.
    const MIN_DENSE_ERROR_RATIO: f64 = 16.0;
    /// The same for DOP853's 7th-order extension (local error O(h^8), ~256 per halving): >= 2^7.
    const MIN_DENSE853_ERROR_RATIO: f64 = 128.0;

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
}
