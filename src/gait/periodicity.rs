//! When two section states are the same gait, and with which period a walk's returns repeat: the tolerances
//! and the least-period test shared by the period-k search ([`super::period_k`]), continuation
//! ([`super::continuation`]), the orbit diagram ([`super::orbit`]) and the basin ([`super::basin`]) (docs/model.md
//! section 6). Distances are [`SectionState::distance`], the largest coordinate difference of
//! `(L2, thetadot, L2dot)`.

use crate::walk::SectionState;

/// Two fixed points closer than this (largest coordinate difference of `(L2, thetadot, L2dot)`) are the same
/// gait. Newton converges to `1e-10` in the residual, so one gait found twice agrees to far better than this;
/// distinct families differ by `1e-3` or more.
pub(crate) const SAME_GAIT_TOL: f64 = 1e-6;

/// The longest period searched by default (`vrw gait` and sweeps).
pub const MAX_PERIOD: usize = 8;

/// Number of recent returns over which a period must hold.
pub(crate) const RETURN_WINDOW: usize = 4;

/// A period `k` is tried when the returns repeat with period `k` to within this (largest coordinate
/// difference of `(L2, thetadot, L2dot)`; Newton's method then converges from there).
pub(crate) const RETURN_TOL: f64 = 1e-3;

/// `d_k` for `k = 1 ..= max_period`: the largest coordinate difference between `returns[n]` and
/// `returns[n - k]` over the last [`RETURN_WINDOW`] returns `n` (`INFINITY` where there are too few returns).
pub(crate) fn return_distances(returns: &[SectionState], max_period: usize) -> Vec<f64> {
    (1..=max_period)
        .map(|k| {
            if returns.len() < k + RETURN_WINDOW {
                return f64::INFINITY;
            }
            (returns.len() - RETURN_WINDOW..returns.len())
                .map(|n| returns[n].distance(&returns[n - k]))
                .fold(0.0, f64::max)
        })
        .collect()
}

/// The least period of the returns: the smallest `k` whose return distance is below `tol`.
pub fn least_period(returns: &[SectionState], max_period: usize, tol: f64) -> Option<usize> {
    return_distances(returns, max_period)
        .iter()
        .position(|&d| d < tol)
        .map(|i| i + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(l2: f64) -> SectionState {
        SectionState {
            l2,
            theta_dot: 1.0,
            l2_dot: 0.0,
            slip: 0.0,
        }
    }

    #[test]
    fn least_period_of_alternating_returns_is_two() {
        let returns: Vec<SectionState> = (0..20)
            .map(|i| s(if i % 2 == 0 { 0.7 } else { 0.8 }))
            .collect();
        assert_eq!(least_period(&returns, MAX_PERIOD, 1e-9), Some(2));
        let d = return_distances(&returns, 4);
        assert!((d[0] - 0.1).abs() < 1e-12 && d[1] == 0.0 && d[3] == 0.0);
    }

    #[test]
    fn too_few_returns_have_no_period() {
        let returns: Vec<SectionState> = (0..3).map(|_| s(0.7)).collect();
        assert_eq!(least_period(&returns, MAX_PERIOD, 1e-9), None);
    }

    #[test]
    fn period_three_is_found_before_six() {
        let returns: Vec<SectionState> = (0..30).map(|i| s(0.7 + 0.01 * (i % 3) as f64)).collect();
        assert_eq!(least_period(&returns, MAX_PERIOD, 1e-9), Some(3));
    }

    #[test]
    fn distance_is_the_largest_coordinate_difference() {
        let a = SectionState {
            l2: 0.7,
            theta_dot: 1.0,
            l2_dot: 0.0,
            slip: 0.0,
        };
        let b = SectionState {
            l2: 0.71,
            theta_dot: 0.9,
            l2_dot: 0.05,
            slip: 0.0,
        };
        assert_eq!(a.distance(&b), (1.0f64 - 0.9).abs());
        assert_eq!(a.distance(&b), b.distance(&a));
    }
}
