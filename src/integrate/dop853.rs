//! The explicit Runge–Kutta pair DOP853 of Dormand & Prince (order 8, with error estimators of orders 5 and 3)
//! and its 7th-order continuous extension, driven one accepted step at a time like [`super::Dopri5`].
//!
//! At the tight tolerances of the walk (rtol 1e-10) it takes steps several times longer than DOPRI5 for the
//! same accuracy, which more than pays for its 12 stages per step (plus 3 for the dense output).
//!
//! The coefficients are those of Hairer's `dop853` (HNW I, Sec. II.10), taken from the `differential-equations`
//! crate's Butcher tableau (`ButcherTableau::dop853`) rather than typed in again; the tests check them through
//! the method's convergence order. The stepping itself is hand-written for the same
//! reasons as `Dopri5` (stack state, caller-located events, restarts; see the parent module): error norm and
//! step-size control as in `dop853` (HNW I, Sec. II.10, Eq. (10.17); no PI term, `fac1 = 0.333`, `fac2 = 6`).
//!
//! # References
//! - E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., Springer, 1993,
//!   Sec. II.10 (DOP853, its error estimate and dense output).
//! - P. J. Prince, J. R. Dormand, "High order embedded Runge-Kutta formulae", J. Comput. Appl. Math.
//!   7(1):67–75, 1981.

use std::sync::OnceLock;

use differential_equations::tableau::ButcherTableau;
use nalgebra::SVector;

use super::core::{all_finite, Core};
use super::tolerances::{measured, scaled_rms};
use super::{DenseStep, FixedStep, IntegrationError, OdeSystem, Tolerances};

/// Stages of one step.
const STAGES: usize = 12;
/// Stages including the three extra ones of the dense output and `f(t1, y1)`.
const DENSE_STAGES: usize = 16;
/// Safety factor on the optimal step.
const SAFE: f64 = 0.9;
/// Exponent of the error: 1/8.
const EXPO: f64 = 1.0 / 8.0;
/// Largest divisor h_old/h_new (a step shrinks at most ~3x per trial; `dop853`'s `1/fac1`).
const FAC_SHRINK_MAX: f64 = 1.0 / 0.333;
/// Smallest divisor h_old/h_new (a step grows at most 6x; `dop853`'s `1/fac2`).
const FAC_GROW_MAX: f64 = 1.0 / 6.0;
/// Weight of the 3rd-order estimate in the error norm (`dop853`: `deno = err5 + 0.01 err3`).
const ERR3_WEIGHT: f64 = 0.01;
/// Order used by the starting-step heuristic.
const HINIT_ORDER: i32 = 8;

/// The coefficients of DOP853, with the zero entries of `a` skipped.
struct Tableau {
    c: [f64; DENSE_STAGES],
    /// `a[i]`: the nonzero `(j, a_ij)` of stage `i`.
    a: Vec<Vec<(usize, f64)>>,
    b: [f64; STAGES],
    /// 3rd-order weights (`bhh` of `dop853`).
    bh: [f64; STAGES],
    /// 5th-order error weights.
    er: [f64; STAGES],
    /// Dense-output rows `d4 .. d7` over the 16 stages.
    d: [[f64; DENSE_STAGES]; 4],
}

fn tableau() -> &'static Tableau {
    static TABLEAU: OnceLock<Tableau> = OnceLock::new();
    TABLEAU.get_or_init(|| {
        let t = ButcherTableau::<f64, STAGES, DENSE_STAGES>::dop853();
        let a =
            t.a.iter()
                .map(|row| {
                    row.iter()
                        .enumerate()
                        .filter(|(_, &v)| v != 0.0)
                        .map(|(j, &v)| (j, v))
                        .collect()
                })
                .collect();
        let bi = t.bi.expect("DOP853 has a dense output");
        Tableau {
            c: t.c,
            a,
            b: t.b,
            bh: t.bh.expect("DOP853 has a 3rd-order estimate"),
            er: t.er.expect("DOP853 has a 5th-order estimate"),
            d: [bi[4], bi[5], bi[6], bi[7]],
        }
    })
}

/// Adaptive DOP853 with FSAL, the step-size control of `dop853` and its 7th-order dense output.
///
/// Driven like [`super::Dopri5`]: [`step`](Self::step) returns a [`DenseStep`]; after an event,
/// [`restart`](Self::restart). Its time, state and counters are read through [`super::Integrator`].
#[derive(Debug, Clone)]
pub(crate) struct Dop853<const N: usize> {
    core: Core<N>,
}

impl<const N: usize> Dop853<N> {
    /// Start at (t0, y0); computes f(t0, y0) and an initial step. Costs two right-hand-side evaluations.
    pub(crate) fn new(
        sys: &impl OdeSystem<N>,
        t0: f64,
        y0: SVector<f64, N>,
        tol: Tolerances,
    ) -> Self {
        Self {
            core: Core::new(sys, t0, y0, tol, HINIT_ORDER),
        }
    }

    /// Restart at (t, y) with a possibly new vector field: recomputes f and keeps the last accepted step
    /// size as the first trial step (bounded by a fresh initial-step estimate). Two evaluations.
    pub(crate) fn restart(&mut self, sys: &impl OdeSystem<N>, t: f64, y: SVector<f64, N>) {
        self.core.restart(sys, t, y, HINIT_ORDER);
    }

    /// The state between steps (time, state, FSAL derivative, counters), read through [`super::Integrator`].
    pub(super) fn core(&self) -> &Core<N> {
        &self.core
    }

    /// Take one accepted step, never passing `t_stop` (the same contract as [`super::Dopri5::step`]).
    ///
    /// # Errors
    /// As [`super::Dopri5::step`].
    ///
    /// # Panics
    /// If `t_stop` is not after the current time.
    pub(crate) fn step(
        &mut self,
        sys: &impl OdeSystem<N>,
        t_stop: f64,
    ) -> Result<DenseStep<N>, IntegrationError> {
        self.core.begin(t_stop)?;
        let tab = tableau();
        let t = self.core.t;
        let y0 = self.core.y;
        let mut k = [SVector::<f64, N>::zeros(); DENSE_STAGES];
        k[0] = self.core.dy;
        let mut rejected_before = false;
        let mut last_non_finite = false;
        loop {
            let (h, t1) = self.core.trial(t_stop, last_non_finite)?;
            trial_stages(sys, t, &y0, &mut k, h);
            self.core.stats.rhs_evals += STAGES - 1;
            let mut yseg = SVector::<f64, N>::zeros();
            let mut e5 = SVector::<f64, N>::zeros();
            let mut e3 = SVector::<f64, N>::zeros();
            for (i, ki) in k.iter().take(STAGES).enumerate() {
                yseg += ki * tab.b[i];
                e5 += ki * tab.er[i];
                e3 += ki * tab.bh[i];
            }
            e3 = yseg - e3;
            let y1 = y0 + yseg * h;
            // HNW I, Eq. (10.17): err = |h| err5^2 / sqrt(n (err5^2 + 0.01 err3^2)), each a scaled sum of squares.
            let skip = sys.unmeasured();
            let n = measured(N, skip);
            let err5 = scaled_rms(&self.core.tol, &e5, (&y0, &y1), skip).powi(2) * n;
            let err3 = scaled_rms(&self.core.tol, &e3, (&y0, &y1), skip).powi(2) * n;
            let mut deno = err5 + ERR3_WEIGHT * err3;
            if deno <= 0.0 {
                deno = 1.0;
            }
            let err = h.abs() * err5 * (1.0 / (n * deno)).sqrt();
            // f(t1, y1): the next step's first stage, and a stage of the dense output.
            let k13 = if err.is_finite() && err <= 1.0 && all_finite(&y1) {
                self.core.stats.rhs_evals += 1;
                Some(sys.rhs(t1, &y1))
            } else {
                None
            };
            let finite = err.is_finite() && all_finite(&y1) && k13.as_ref().is_none_or(all_finite);
            if !finite {
                rejected_before = true;
                last_non_finite = true;
                self.core.reject(h, FAC_SHRINK_MAX);
                continue;
            }
            last_non_finite = false;

            let fac11 = err.powf(EXPO);
            let Some(k13) = k13 else {
                rejected_before = true;
                self.core.reject(h, FAC_SHRINK_MAX.min(fac11 / SAFE));
                continue;
            };
            let fac = (fac11 / SAFE).clamp(FAC_GROW_MAX, FAC_SHRINK_MAX);
            self.core.accept(h, (t1, y1, k13), h / fac, rejected_before);
            k[STAGES] = k13;
            self.core.stats.rhs_evals += DENSE_STAGES - STAGES - 1;
            return Ok(dense_step(sys, (t, t1, h), &y0, y1, &mut k));
        }
    }
}

/// The state of stage `i` of a step of size `h` from `y0`, from the stages `k[..i]` before it.
fn stage_state<const N: usize>(
    y0: &SVector<f64, N>,
    k: &[SVector<f64, N>],
    i: usize,
    h: f64,
) -> SVector<f64, N> {
    let mut sum = SVector::<f64, N>::zeros();
    for &(j, a) in &tableau().a[i] {
        sum += k[j] * a;
    }
    y0 + sum * h
}

/// Stages `2 ..= STAGES` of a step of size `h` from `(t, y0)`, given `k[0] = f(t, y0)`.
fn trial_stages<const N: usize>(
    sys: &impl OdeSystem<N>,
    t: f64,
    y0: &SVector<f64, N>,
    k: &mut [SVector<f64, N>; DENSE_STAGES],
    h: f64,
) {
    let tab = tableau();
    for i in 1..STAGES {
        let yi = stage_state(y0, k, i, h);
        k[i] = sys.rhs(t + tab.c[i] * h, &yi);
    }
}

/// The dense output of an accepted step `(t, t1, h)` from `y0` to `y1`, given its stages `k[..=STAGES]`
/// (`k[STAGES] = f(t1, y1)`): the three extra stages of the 7th-order extension (`contd8` of `dop853`).
fn dense_step<const N: usize>(
    sys: &impl OdeSystem<N>,
    (t, t1, h): (f64, f64, f64),
    y0: &SVector<f64, N>,
    y1: SVector<f64, N>,
    k: &mut [SVector<f64, N>; DENSE_STAGES],
) -> DenseStep<N> {
    let tab = tableau();
    for i in STAGES + 1..DENSE_STAGES {
        let yi = stage_state(y0, k, i, h);
        k[i] = sys.rhs(t + tab.c[i] * h, &yi);
    }
    let delta = y1 - y0;
    let bspl = k[0] * h - delta;
    let mut cont = [
        *y0,
        delta,
        bspl,
        delta - k[STAGES] * h - bspl,
        SVector::zeros(),
        SVector::zeros(),
        SVector::zeros(),
        SVector::zeros(),
    ];
    for (row, c) in tab.d.iter().zip(cont[4..].iter_mut()) {
        for (ki, &d) in k.iter().zip(row) {
            if d != 0.0 {
                *c += ki * d;
            }
        }
        *c *= h;
    }
    DenseStep::from_coefficients((t, t1, h), y1, &cont)
}

/// One DOP853 step of the given size `h` from `(t, y0)` with `f0 = f(t, y0)` to `t1` (`t + h`, or the `t_stop`
/// it landed on), with no error control: the step an adaptive run accepted, taken again on another system (the
/// variational equations, see `crate::variational`). The same arithmetic as [`Dop853::step`], so a system whose
/// first components are the original one's reproduces its states bit for bit. Returns `y1`, `f(t1, y1)` and,
/// if `dense`, the dense output (three more stages).
pub(crate) fn fixed_step<const N: usize>(
    sys: &impl OdeSystem<N>,
    (t, y0, f0): (f64, &SVector<f64, N>, &SVector<f64, N>),
    h: f64,
    t1: f64,
    dense: bool,
) -> FixedStep<N> {
    let tab = tableau();
    let mut k = [SVector::<f64, N>::zeros(); DENSE_STAGES];
    k[0] = *f0;
    trial_stages(sys, t, y0, &mut k, h);
    let mut yseg = SVector::<f64, N>::zeros();
    for (i, ki) in k.iter().take(STAGES).enumerate() {
        yseg += ki * tab.b[i];
    }
    let y1 = y0 + yseg * h;
    k[STAGES] = sys.rhs(t1, &y1);
    let f1 = k[STAGES];
    FixedStep {
        y1,
        f1,
        dense: dense.then(|| dense_step(sys, (t, t1, h), y0, y1, &mut k)),
    }
}

#[cfg(test)]
mod tests {
    use crate::integrate::testing::steps_of;
    use crate::integrate::Method;

    /// Largest distance of the observed convergence order from the method's order.
    const ORDER_TOL: f64 = 0.5;

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
}
