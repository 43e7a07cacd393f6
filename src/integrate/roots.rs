//! Root location on the dense output ([`locate_root`]): Brent's method from the `roots` crate, finished by
//! bisection so that the returned time is never before the crossing (R. P. Brent, 1973, Ch. 4).

use nalgebra::SVector;

use super::DenseStep;

/// Largest number of Brent iterations in [`locate_root`] before falling back to bisection.
const BRENT_MAX_ITER: usize = 100;

/// Brent stopping rule in time only: bracket narrower than `t_tol`, or g exactly zero.
struct BracketWidth {
    t_tol: f64,
}

impl ::roots::Convergency<f64> for BracketWidth {
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
pub(crate) fn locate_root<const N: usize>(
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
    let brent = ::roots::find_root_brent(
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

#[cfg(test)]
mod tests {
    use crate::integrate::testing::{
        first_downward_crossing, tight, IMPACT_TIME_TOL, METHODS, ROOT_T_TOL, TIME_ROUNDOFF,
    };
    use crate::integrate::Integrator;
    use crate::reference::FallingPoint;
    use approx::assert_abs_diff_eq;

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
}
