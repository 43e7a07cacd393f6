//! Where a family ends because the wheel is about to roll back, the end extrapolated from the family's own
//! gaits instead of bisected (docs/model.md section 6, "Sweeps").
//!
//! Along such a family the smallest `dtheta/dt` of the gait's step, `g` ([`crate::walk::StepReport::slowest`]),
//! falls to zero at the end: past it the walk rolls back. Near the end it behaves as a power of the distance,
//! `g ~ A |v_end - v|^p`, with an exponent that depends on how the minimum meets zero (1 for a smooth minimum,
//! about 0.6 on the default map's ends), so the power law through the last three verified gaits (the secant
//! through the last two where that fails) estimates `v_end`, and the next continuation step aims just short of
//! the estimate, by the estimate's own last change. Steps still verify everything: the reported end remains
//! the last verified gait and the first value not reached, at most the tolerance apart. Where no estimate
//! falls inside that bracket (the family ends for another reason: a fold, a border where the map jumps), or
//! after [`MAX_EXTRAPOLATED`] extrapolated steps, the continuation bisects as before.

/// Most continuation steps one [`EndSearch`] aims by extrapolation. Near a roll-back end of the default map
/// the bracket closes in four to eight of them; an end that has not closed by then is bisected.
pub(crate) const MAX_EXTRAPOLATED: usize = 12;

/// Where a followed family ends: its last verified gaits with their smallest `dtheta/dt`, the nearest value
/// past them not reached, and the last estimate of the end (see the module documentation).
#[derive(Debug, Clone, Default)]
pub(crate) struct EndSearch {
    /// The last verified gait's value.
    last: Option<f64>,
    /// The last verified gaits whose smallest `dtheta/dt` is known, oldest first: `(value, smallest
    /// dtheta/dt)`, at most three, none before a gait where it is not known.
    points: Vec<(f64, f64)>,
    /// The nearest value past the last verified gait that a step did not reach.
    beyond: Option<f64>,
    /// The last estimate of the end.
    previous: Option<f64>,
    /// Steps aimed by extrapolation so far.
    extrapolated: usize,
}

impl EndSearch {
    /// A step reached the gait at `value`, whose smallest `dtheta/dt` is `slowest` (`None` where it is not known:
    /// a step by walking, a period-k family; the gaits before it are then forgotten).
    pub(crate) fn verified(&mut self, value: f64, slowest: Option<f64>) {
        if let (Some(a), Some(b)) = (self.last, self.beyond) {
            // A step past a value not reached before (a Newton failure, not an end): the bracket is gone.
            if (value - a) * (b - value) <= 0.0 {
                self.beyond = None;
            }
        }
        self.last = Some(value);
        match slowest.filter(|g| g.is_finite()) {
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
    /// short of the estimate by its last change (by a quarter of the distance to it for a first estimate, by
    /// at least `tol / 2`), or `tol` past the last gait where the estimate is within `tol` of it (a step
    /// expected to fail, which closes the bracket). `None` otherwise: the caller bisects.
    pub(crate) fn aim(&mut self, tol: f64) -> Option<f64> {
        if self.extrapolated >= MAX_EXTRAPOLATED {
            return None;
        }
        let (&(a, _), b) = (self.points.last()?, self.beyond?);
        if self.last != Some(a) {
            return None;
        }
        let inside = |v: f64| v.is_finite() && (v - a) * (b - v) > 0.0;
        let e = [self.power_law(b), self.secant()]
            .into_iter()
            .flatten()
            .find(|&v| inside(v))?;
        if (b - a).abs() <= tol {
            return None;
        }
        let toward = (b - a).signum();
        let guard = self
            .previous
            .map_or(0.25 * (e - a).abs(), |p| (e - p).abs());
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

    /// The end `e` of the power law `g = A |e - v|^p` through the last three gaits (`g` the smallest
    /// `dtheta/dt`, falling toward the end), where it lies between the last gait and `b`. Near a roll-back end
    /// that law holds with an exponent that depends on how the minimum meets zero, so `A`, `p` and `e` are all
    /// fitted: `e` is the root of `ln(g0/g1) ln((e-v1)/(e-v2)) = ln(g1/g2) ln((e-v0)/(e-v1))`, found by
    /// bisection (the left side minus the right is `+inf` just past `v2`).
    fn power_law(&self, b: f64) -> Option<f64> {
        let [(v0, g0), (v1, g1), (v2, g2)] = self.points[..] else {
            return None;
        };
        let toward = (b - v2).signum();
        let (x0, x1, x2, xb) = (toward * v0, toward * v1, toward * v2, toward * b);
        if !(g0 > g1 && g1 > g2 && g2 > 0.0 && x0 < x1 && x1 < x2 && x2 < xb) {
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

    /// The zero of the secant through the last two gaits, where their smallest `dtheta/dt` falls toward it.
    fn secant(&self) -> Option<f64> {
        let [.., (v0, g0), (v1, g1)] = self.points[..] else {
            return None;
        };
        (g0 > g1 && g1 > 0.0).then(|| v1 - g1 * (v1 - v0) / (g1 - g0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Follow `g(v) = end - v` (scaled) toward `end` the way a continuation does: every aimed value below `end`
    /// is a verified gait, every one above it a failure.
    fn bracket(g: impl Fn(f64) -> f64, end: f64, tol: f64) -> (f64, f64, usize) {
        let mut search = EndSearch::default();
        for v in [end - 3.0, end - 2.0] {
            search.verified(v, Some(g(v)));
        }
        search.failed(end + 1.5);
        let (mut a, mut b, mut steps) = (end - 2.0, end + 1.5, 0);
        while (b - a) > tol {
            let v = search.aim(tol).unwrap_or(0.5 * (a + b));
            steps += 1;
            if v < end {
                search.verified(v, Some(g(v)));
                a = v;
            } else {
                search.failed(v);
                b = v;
            }
            assert!(steps < 60, "no bracket after 60 steps");
        }
        (a, b, steps)
    }

    /// A simple zero (the smallest `dtheta/dt` of a double-support minimum) and a square-root zero (a minimum
    /// over the top) are both bracketed to the tolerance in a few steps where bisection from a bracket of 3.5
    /// takes 22.
    #[test]
    fn roll_back_ends_are_bracketed_in_a_few_steps() {
        let end = 54.061_868_59;
        for g in [
            &(|v: f64| 0.3 * (end - v) + 0.02 * (end - v).powi(2)) as &dyn Fn(f64) -> f64,
            &|v: f64| (end - v).max(0.0).sqrt(),
        ] {
            let (a, b, steps) = bracket(g, end, 1e-6);
            assert!(a < end && end <= b && b - a <= 1e-6, "[{a}, {b}]");
            assert!(steps <= 10, "{steps} steps");
        }
    }

    /// Without a falling `dtheta/dt` (another kind of end) there is no estimate, and a step past the value not
    /// reached forgets it.
    #[test]
    fn other_ends_are_bisected() {
        let mut search = EndSearch::default();
        search.verified(1.0, Some(1.0));
        search.verified(2.0, Some(1.1));
        search.failed(3.0);
        assert_eq!(search.aim(1e-6), None);
        search.verified(2.5, Some(0.3));
        assert!(search.aim(1e-6).is_some_and(|v| v > 2.5 && v < 3.0));
        search.verified(3.5, Some(0.8));
        assert_eq!(search.beyond, None);
        assert_eq!(search.aim(1e-6), None);
        search.verified(4.0, None);
        search.failed(5.0);
        assert_eq!(search.aim(1e-6), None);
    }
}
