//! Test support shared by the integrator's unit tests: tolerances, the two methods, stepping to a located crossing
//! and the exact flow of the harmonic oscillator (the reference problems themselves are in `crate::reference`).

use nalgebra::SVector;

use super::{locate_root, DenseStep, Integrator, Method, OdeSystem, Tolerances};
use crate::reference::HarmonicOscillator;

/// Time tolerance handed to `locate_root` \[s\] (the contract's default).
pub(super) const ROOT_T_TOL: f64 = 1e-13;
/// Required accuracy of the falling point's impact time at rtol 1e-10 \[s\].
pub(super) const IMPACT_TIME_TOL: f64 = 1e-12;
/// Required accuracy of the oscillator's zero crossings at rtol 1e-10, atol 1e-12 \[s\].
pub(super) const CROSSING_TIME_TOL: f64 = 1e-9;
/// Required accuracy of the oscillator state after 10 periods \[m, m/s\].
pub(super) const FINAL_STATE_TOL: f64 = 1e-8;
/// Both methods, for the tests that hold for each.
pub(super) const METHODS: [Method; 2] = [Method::Dop853, Method::Dopri5];
/// Roundoff allowance for times built from sums of floating-point steps \[s\].
pub(super) const TIME_ROUNDOFF: f64 = 1e-14;
/// Safety cap on steps in test loops, so a broken solver fails instead of hanging.
pub(super) const MAX_STEPS: usize = 1_000_000;

pub(super) fn tight() -> Tolerances {
    Tolerances::default()
}

/// Step until `g` goes from > 0 to <= 0; returns the located time and the step holding it.
pub(super) fn first_downward_crossing<const N: usize>(
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
pub(super) fn oscillator_flow(omega: f64, y: &SVector<f64, 2>, s: f64) -> SVector<f64, 2> {
    let (sn, cs) = (omega * s).sin_cos();
    SVector::<f64, 2>::new(
        y[0] * cs + y[1] / omega * sn,
        -y[0] * omega * sn + y[1] * cs,
    )
}

/// The oscillator x'' = -4 x from x = 1 and `method` on it with largest step `h_max` and tolerances `tol`
/// (loose, so that `h_max` sets the step).
pub(super) fn steps_of(
    method: Method,
    h_max: f64,
    tol: f64,
) -> (HarmonicOscillator, Integrator<2>) {
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
