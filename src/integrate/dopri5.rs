//! The explicit Runge–Kutta pair DOPRI5 of Dormand & Prince (order 5 with an embedded 4th-order error
//! estimate): its tableau, Shampine's 4th-order continuous extension and Gustafsson's PI step-size control, as
//! in Hairer's `dopri5`.
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

use nalgebra::SVector;

use super::core::{all_finite, Core, Stats};
use super::tolerances::scaled_rms;
use super::{DenseStep, FixedStep, IntegrationError, OdeSystem, Tolerances};

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
/// Order of the starting-step heuristic: error constant ~ h^(p+1) with p = 4.
const HINIT_ORDER: i32 = 5;

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

    /// The state between steps (time, state, FSAL derivative, counters), read through [`super::Integrator`].
    pub(super) fn core(&self) -> &Core<N> {
        &self.core
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
            let Stages { k, y1 } = stages(sys, t, &y0, k1, h, t1);
            let [_, _, k3, k4, k5, k6, k7] = k;
            self.core.stats.rhs_evals += 6;

            let e = (k1 * E1 + k3 * E3 + k4 * E4 + k5 * E5 + k6 * E6 + k7 * E7) * h;
            let err = scaled_rms(&self.core.tol, &e, (&y0, &y1), sys.unmeasured());

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
                return Ok(dense_step((t, t1, h), &y0, y1, &k));
            }
            rejected_before = true;
            self.core.reject(h, FAC_SHRINK_MAX.min(fac11 / SAFE));
        }
    }
}

/// The seven stages `k1 .. k7` of a step of size `h` from `(t, y0)` to `t1` (`k1 = f(t, y0)` given, `k7 =
/// f(t1, y1)`), and the 5th-order solution `y1`.
struct Stages<const N: usize> {
    k: [SVector<f64, N>; 7],
    y1: SVector<f64, N>,
}

fn stages<const N: usize>(
    sys: &impl OdeSystem<N>,
    t: f64,
    y0: &SVector<f64, N>,
    k1: SVector<f64, N>,
    h: f64,
    t1: f64,
) -> Stages<N> {
    let y0 = *y0;
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
    Stages {
        k: [k1, k2, k3, k4, k5, k6, k7],
        y1,
    }
}

/// Shampine's 4th-order dense output of the step `(t, t1, h)` from `y0` to `y1` with stages `k`.
fn dense_step<const N: usize>(
    (t, t1, h): (f64, f64, f64),
    y0: &SVector<f64, N>,
    y1: SVector<f64, N>,
    k: &[SVector<f64, N>; 7],
) -> DenseStep<N> {
    let [k1, _, k3, k4, k5, k6, k7] = *k;
    let delta = y1 - y0;
    let bspl = k1 * h - delta;
    DenseStep::from_coefficients(
        (t, t1, h),
        y1,
        &[
            *y0,
            delta,
            bspl,
            delta - k7 * h - bspl,
            (k1 * D1 + k3 * D3 + k4 * D4 + k5 * D5 + k6 * D6 + k7 * D7) * h,
        ],
    )
}

/// One DOPRI5 step of the given size `h` from `(t, y0)` with `f0 = f(t, y0)` to `t1`, with no error control: the
/// step an adaptive run accepted, taken again on another system (see `super::dop853::fixed_step`).
pub(crate) fn fixed_step<const N: usize>(
    sys: &impl OdeSystem<N>,
    (t, y0, f0): (f64, &SVector<f64, N>, &SVector<f64, N>),
    h: f64,
    t1: f64,
    dense: bool,
) -> FixedStep<N> {
    let Stages { k, y1 } = stages(sys, t, y0, *f0, h, t1);
    FixedStep {
        y1,
        f1: k[6],
        dense: dense.then(|| dense_step((t, t1, h), y0, y1, &k)),
    }
}
