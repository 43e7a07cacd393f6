//! Where a family ends because the wheel is about to roll back, or at a border where a DLS indicator vanishes,
//! the end extrapolated from the family's own gaits instead of bisected (docs/model.md section 6, "Sweeps").
//!
//! Such ends are zeros of a quantity every verified gait carries (its [`Gauges`]): the smallest `dtheta/dt` of
//! the gait's step ([`crate::walk::StepReport::slowest`]) falls to zero where the wheel is about to roll back
//! (past it the walk rolls back), a DLS indicator where the map changes branch and the family with it (the
//! period-1 DLS gait ends at `lambda_2+ = 0`, where Leg 1 starts to bounce). Near the end each behaves as a
//! power of the distance, `g ~ A |v_end - v|^p`, with an exponent that depends on how the quantity meets zero
//! (1 for an indicator or a smooth minimum, about 0.6 was seen for the smallest `dtheta/dt` on the default
//! map's ends), so the power law through the last three verified gaits (the secant through the last two where
//! that fails) estimates `v_end`; the nearest estimate inside the bracket is taken, and the next continuation
//! step aims just short of it, by half the estimate's last change. Steps still verify everything: the reported
//! end remains the last verified gait and the first value not reached, at most the tolerance apart. Where no
//! estimate falls inside that bracket (the family ends for another reason: a fold, a grazing event), or after
//! [`MAX_EXTRAPOLATED`] extrapolated steps, the continuation bisects as before. An estimate at the zero of an
//! indicator that does not end the family costs a few steps: the gait past it has the indicator's other sign,
//! and the indicator no longer counts.

use crate::walk::StepReport;

/// Most continuation steps one [`EndSearch`] aims by extrapolation. Near a roll-back end of the default map
/// the bracket closes in four to eight of them; an end that has not closed by then is bisected.
pub(crate) const MAX_EXTRAPOLATED: usize = 12;

/// How many quantities a gait carries whose zero may end its family.
const GAUGE_COUNT: usize = 4;

/// The quantities of a gait whose zero may end its family: the smallest `dtheta/dt` of its step \[rad/s\]
/// and its DLS indicators `lambda_I4`, `lambda_2+`, `lambda_4+` \[N s\].
pub(crate) type Gauges = [f64; GAUGE_COUNT];

/// The [`Gauges`] of the gait whose step `report` describes.
pub(crate) fn gauges(report: &StepReport) -> Gauges {
    let i = &report.indicators;
    [
        report.slowest,
        i.lambda_i4,
        i.lambda_2_plus,
        i.lambda_4_plus,
    ]
}

/// Where a followed family ends: its last verified gaits with their [`Gauges`], the nearest value past them not
/// reached, and the last estimate of the end (see the module documentation).
#[derive(Debug, Clone, Default)]
pub(crate) struct EndSearch {
    /// The last verified gait's value.
    last: Option<f64>,
    /// The last verified gaits whose gauges are known, oldest first: `(value, gauges)`, at most three, none
    /// before a gait where they are not known.
    points: Vec<(f64, Gauges)>,
    /// The nearest value past the last verified gait that a step did not reach.
    beyond: Option<f64>,
    /// The last estimate of the end.
    previous: Option<f64>,
    /// Steps aimed by extrapolation so far.
    extrapolated: usize,
}

impl EndSearch {
    /// A step reached the gait at `value`, whose gauges are `gauges` (`None` where they are not known: a step
    /// by walking, a period-k family; the gaits before it are then forgotten).
    pub(crate) fn verified(&mut self, value: f64, gauges: Option<Gauges>) {
        if let (Some(a), Some(b)) = (self.last, self.beyond) {
            // A step past a value not reached before (a Newton failure, not an end): the bracket is gone.
            if (value - a) * (b - value) <= 0.0 {
                self.beyond = None;
            }
        }
        self.last = Some(value);
        match gauges {
            Some(g) => {
                if self.points.len() == 3 {
                    self.points.remove(0);
                }
                self.points.push((value, g));
            }
            None => {
                self.points.clear();
                self.previous = None;
            }
        }
    }

    /// A step from the last verified gait did not reach `value`.
    pub(crate) fn failed(&mut self, value: f64) {
        let Some(a) = self.last else {
            return;
        };
        let nearer = self
            .beyond
            .is_none_or(|b| (value - a).abs() < (b - a).abs());
        if nearer && (value - a) != 0.0 {
            self.beyond = Some(value);
        }
    }

    /// The value the next step from the last verified gait should aim at, where an estimate of the end falls
    /// strictly between it and the nearest value not reached, and that bracket is wider than `tol`: just
    /// short of the estimate by half its last change (by a quarter of the distance to it for a first estimate, by
    /// at least `tol / 2`), or `tol` past the last gait where the estimate is within `tol` of it (a step
    /// expected to fail, which closes the bracket). `None` otherwise: the caller bisects.
    pub(crate) fn aim(&mut self, tol: f64) -> Option<f64> {
        if self.extrapolated >= MAX_EXTRAPOLATED {
            return None;
        }
        let (&(a, _), b) = (self.points.last()?, self.beyond?);
        if self.last != Some(a) || (b - a).abs() <= tol {
            return None;
        }
        let inside = |v: f64| v.is_finite() && (v - a) * (b - v) > 0.0;
        let e = (0..GAUGE_COUNT)
            .filter_map(|k| {
                let series = self.falling(k)?;
                [power_law(&series, b), secant(&series)]
                    .into_iter()
                    .flatten()
                    .find(|&v| inside(v))
            })
            .min_by(|x, y| (x - a).abs().total_cmp(&(y - a).abs()))?;
        let toward = (b - a).signum();
        // Half the last change: on the default map's 81 ends 1 475 steps in all, against 1 515 with the whole
        // change (too cautious) and 1 559 with a quarter (too many steps past the end, each failing).
        let guard = self
            .previous
            .map_or(0.25 * (e - a).abs(), |p| 0.5 * (e - p).abs());
        self.previous = Some(e);
        self.extrapolated += 1;
        // Just inside the tolerance, so that the step counts as the finest one whatever the rounding of `a + tol`.
        let finest = 0.99 * tol;
        if (e - a).abs() <= finest {
            return Some(a + toward * finest).filter(|&v| inside(v));
        }
        let short = guard.max(0.5 * tol).min(0.5 * (e - a).abs());
        Some(e - toward * short)
    }

    /// The last gaits' `(value, |g|)` for gauge `k`, as many as have the sign it has now and a magnitude that
    /// falls from gait to gait (toward a zero): two at least, else `None`.
    fn falling(&self, k: usize) -> Option<Vec<(f64, f64)>> {
        let sign = self.points.last()?.1[k].signum();
        let mut series: Vec<(f64, f64)> = Vec::with_capacity(self.points.len());
        for &(v, g) in self.points.iter().rev() {
            let g = sign * g[k];
            if !(g.is_finite() && g > 0.0) || series.last().is_some_and(|&(_, later)| later >= g) {
                break;
            }
            series.push((v, g));
        }
        series.reverse();
        (series.len() >= 2).then_some(series)
    }
}

/// The end `e` of the power law `g = A |e - v|^p` through three gaits `(v, g)` (`g > 0` falling toward the
/// end), where it lies between the last gait and `b`: `A`, `p` and `e` are all fitted (the exponent depends on
/// how the quantity meets zero). `e` is the root of `ln(g0/g1) ln((e-v1)/(e-v2)) = ln(g1/g2) ln((e-v0)/(e-v1))`,
/// found by bisection (the left side minus the right is `+inf` just past `v2`).
fn power_law(series: &[(f64, f64)], b: f64) -> Option<f64> {
    let [(v0, g0), (v1, g1), (v2, g2)] = series[..] else {
        return None;
    };
    let toward = (b - v2).signum();
    let (x0, x1, x2, xb) = (toward * v0, toward * v1, toward * v2, toward * b);
    if !(x0 < x1 && x1 < x2 && x2 < xb) {
        return None;
    }
    let (l01, l12) = ((g0 / g1).ln(), (g1 / g2).ln());
    let r = |x: f64| l01 * ((x - x1) / (x - x2)).ln() - l12 * ((x - x0) / (x - x1)).ln();
    if r(xb).is_nan() || r(xb) >= 0.0 {
        return None;
    }
    let (mut lo, mut hi) = (x2, xb);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if r(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(toward * 0.5 * (lo + hi))
}

/// The zero of the secant through the last two gaits `(v, g)` of `series` (`g > 0` falling toward it).
fn secant(series: &[(f64, f64)]) -> Option<f64> {
    let [.., (v0, g0), (v1, g1)] = series[..] else {
        return None;
    };
    Some(v1 - g1 * (v1 - v0) / (g1 - g0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gauges with `g` as the smallest `dtheta/dt` and indicators that do not change.
    fn slowest(g: f64) -> Option<Gauges> {
        Some([g, 1.0, -2.0, 3.0])
    }

    /// Follow a family toward `end` the way a continuation does, from gaits at `end - 3` and `end - 2` and a
    /// failure at `end + 1.5`: every aimed value below `end` is a verified gait with gauges `gauges(v)`, every
    /// one above it a failure. The bracket reached and the steps it took.
    fn bracket(gauges: &dyn Fn(f64) -> Option<Gauges>, end: f64, tol: f64) -> (f64, f64, usize) {
        let mut search = EndSearch::default();
        for v in [end - 3.0, end - 2.0] {
            search.verified(v, gauges(v));
        }
        search.failed(end + 1.5);
        let (mut a, mut b, mut steps) = (end - 2.0, end + 1.5, 0);
        while (b - a) > tol {
            let v = search.aim(tol).unwrap_or(0.5 * (a + b));
            steps += 1;
            if v < end {
                search.verified(v, gauges(v));
                a = v;
            } else {
                search.failed(v);
                b = v;
            }
            assert!(steps < 60, "no bracket after 60 steps");
        }
        (a, b, steps)
    }

    /// A simple zero (a smooth minimum of `dtheta/dt`), a square-root zero (a minimum over the top) and an
    /// indicator that rises to zero from below (`lambda_2+` of a DLS gait about to bounce) are all bracketed to
    /// the tolerance in a few steps, where bisection from a bracket of 3.5 takes 22.
    #[test]
    fn ends_at_a_zero_are_bracketed_in_a_few_steps() {
        let end = 54.061_868_59;
        let smooth = |v: f64| slowest(0.3 * (end - v) + 0.02 * (end - v).powi(2));
        let root = |v: f64| slowest((end - v).max(0.0).sqrt());
        let indicator = |v: f64| Some([2.0, 1.0, -40.0 * (end - v), 3.0]);
        for gauges in [&smooth as &dyn Fn(f64) -> Option<Gauges>, &root, &indicator] {
            let (a, b, steps) = bracket(gauges, end, 1e-6);
            assert!(a < end && end <= b && b - a <= 1e-6, "[{a}, {b}]");
            assert!(steps <= 10, "{steps} steps");
        }
        assert_eq!(bracket(&|_| slowest(1.0), end, 1e-6).2, 22);
    }

    /// Without a gauge falling toward zero (another kind of end) there is no estimate, and a step past the value
    /// not reached forgets it. Of two gauges falling toward zero, the nearer zero is aimed at.
    #[test]
    fn other_ends_are_bisected() {
        let mut search = EndSearch::default();
        search.verified(1.0, slowest(1.0));
        search.verified(2.0, slowest(1.1));
        search.failed(3.0);
        assert_eq!(search.aim(1e-6), None);
        search.verified(2.5, Some([0.3, 0.5, -2.0, 3.0]));
        assert!(search.aim(1e-6).is_some_and(|v| v > 2.5 && v < 2.6875));
        search.verified(3.5, slowest(0.8));
        assert_eq!(search.beyond, None);
        assert_eq!(search.aim(1e-6), None);
        search.verified(4.0, None);
        search.failed(5.0);
        assert_eq!(search.aim(1e-6), None);
    }
}
