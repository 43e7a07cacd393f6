//! The continuation and the location of special points on the reference families with closed-form answers
//! ([`QuadraticFamily`], [`DelayedLogisticFamily`]).

use nalgebra::{DMatrix, DVector};

use super::*;
use crate::reference::{DelayedLogisticFamily, QuadraticFamily};

/// Special points of the reference families are located to this in the parameter (the 1e-8, with
/// margin).
const LOCATE_TOL: f64 = 1e-9;

/// A closed form: `P(x; p)`, `DP` (row-major) and `dP/dp` of a map of the plane.
type ClosedForm = fn([f64; 2], f64) -> ([f64; 2], [[f64; 2]; 2], [f64; 2]);

/// A two-dimensional reference family given by its closed form, iterated `period` times.
#[derive(Debug, Clone, Copy)]
struct Closed {
    eval: ClosedForm,
    period: usize,
}

impl FamilyMap for Closed {
    type Info = ();

    fn dim(&self) -> usize {
        2
    }

    fn eval(&self, x: &DVector<f64>, p: f64) -> Result<Evaluation<()>, MapFailure> {
        let mut v = [x[0], x[1]];
        let mut jac = DMatrix::identity(2, 2);
        let mut dp = DVector::zeros(2);
        for _ in 0..self.period {
            let (next, j, d) = (self.eval)(v, p);
            let j = DMatrix::from_fn(2, 2, |r, c| j[r][c]);
            dp = &j * dp + DVector::from_column_slice(&d);
            jac = &j * jac;
            v = next;
        }
        Ok(Evaluation {
            value: DVector::from_column_slice(&v),
            jacobian: jac,
            dparam: dp,
            exact: true,
            info: (),
        })
    }

    fn value(&self, x: &DVector<f64>, p: f64) -> Result<DVector<f64>, MapFailure> {
        Ok(self.eval(x, p)?.value)
    }

    fn iterated(&self, k: usize) -> Self {
        Closed {
            period: self.period * k,
            ..*self
        }
    }

    fn period(&self) -> usize {
        self.period
    }
}

fn quadratic() -> Closed {
    Closed {
        eval: |x, p| QuadraticFamily.eval(x, p),
        period: 1,
    }
}

fn of_kind<I>(family: &Family<I>, kind: SpecialKind) -> Vec<&SpecialPoint<I>> {
    family.special.iter().filter(|s| s.kind == kind).collect()
}

/// The quadratic family from its upper fixed point at `p = 0.3`, followed over `[-0.5, 1]`.
fn quadratic_through_fold() -> Family<()> {
    let start = DVector::from_column_slice(&QuadraticFamily.upper_fixed_point(0.3));
    let options = ContinuationOptions {
        max_points: 1000,
        ..ContinuationOptions::for_range(-0.5, 1.0)
    };
    continue_family(&quadratic(), &start, 0.3, &options).unwrap()
}

#[test]
fn quadratic_family_through_its_fold_and_period_doubling() {
    let family = quadratic_through_fold();
    // Through the fold at p = -1/4 onto the lower branch, then out of the range at p = 1 on both ends.
    assert_eq!(family.ends[0], FamilyEnd::LeftRange { bound: 1.0 });
    assert_eq!(family.ends[1], FamilyEnd::LeftRange { bound: 1.0 });
    let folds = of_kind(&family, SpecialKind::Fold);
    assert_eq!(folds.len(), 1, "{:?}", family.special);
    let (p_lp, x_lp) = QuadraticFamily::FOLD;
    assert!(folds[0].located);
    assert!(
        (folds[0].param - p_lp).abs() < LOCATE_TOL,
        "{}",
        folds[0].param
    );
    assert!((folds[0].x[0] - x_lp).abs() < 1e-6);
    let flips = of_kind(&family, SpecialKind::PeriodDoubling);
    // The upper branch's multiplier -2x is -1 at x = 1/2; the lower branch's (x < -1/2) is above +1.
    assert_eq!(flips.len(), 1, "{:?}", family.special);
    let (p_pd, x_pd) = QuadraticFamily::PERIOD_DOUBLING;
    assert!(
        (flips[0].param - p_pd).abs() < LOCATE_TOL,
        "{}",
        flips[0].param
    );
    assert!((flips[0].x[0] - x_pd).abs() < 1e-6);
    // Every point is a fixed point, and the parameter is monotone on either side of the fold.
    for point in &family.points {
        assert!(point.residual < 1e-10);
        let exact = point.param - point.x[0] * point.x[0];
        assert!((exact - point.x[0]).abs() < 1e-10);
    }
    assert!(family
        .points
        .windows(2)
        .all(|w| w[1].arclength > w[0].arclength));
}

#[test]
fn family_followed_back_through_a_fold_returns_to_the_same_points() {
    let map = quadratic();
    let options = ContinuationOptions {
        max_points: 1000,
        ..ContinuationOptions::for_range(-0.5, 1.0)
    };
    let start = DVector::from_column_slice(&QuadraticFamily.upper_fixed_point(0.3));
    let there = continue_family(&map, &start, 0.3, &options).unwrap();
    // Start again on the lower branch, from the family's first point (p = 1), and follow it back.
    let first = &there.points[0];
    assert!(first.x[0] < -0.5);
    let back = continue_family(&map, &first.x, first.param, &options).unwrap();
    // The same family: through the same fold to the same period doubling, out of the range at both ends, and
    // through the start's gait.
    for kind in [SpecialKind::Fold, SpecialKind::PeriodDoubling] {
        let (a, b) = (of_kind(&there, kind), of_kind(&back, kind));
        assert_eq!((a.len(), b.len()), (1, 1), "{kind:?}");
        assert!((a[0].param - b[0].param).abs() < LOCATE_TOL);
    }
    assert_eq!(back.ends, there.ends);
    let near = back
        .points
        .iter()
        .filter(|p| p.x[0] > -0.5)
        .min_by(|a, b| (a.param - 0.3).abs().total_cmp(&(b.param - 0.3).abs()))
        .unwrap();
    let exact = QuadraticFamily.upper_fixed_point(near.param);
    assert!((near.x[0] - exact[0]).abs() < 1e-10 && (near.x[1] - exact[1]).abs() < 1e-10);
}

#[test]
fn period_two_family_from_the_period_doubling_and_its_own_doubling() {
    let map = quadratic();
    let options = ContinuationOptions::for_range(0.0, 1.4);
    let start = DVector::from_column_slice(&QuadraticFamily.upper_fixed_point(0.3));
    let family = continue_family(&map, &start, 0.3, &options).unwrap();
    let pd = of_kind(&family, SpecialKind::PeriodDoubling)[0];
    let doubled = switch_at_period_doubling(&map, pd, &options).unwrap();
    assert_eq!(doubled.period, 2);
    // Its points are period-2 orbits, x = (1 ± sqrt(4p - 3)) / 2 (to the corrector's tolerance over
    // |1 - mu|, mu = 4 (1 - p) the multiplier of P^2), not fixed points of P.
    for point in doubled.points.iter().filter(|p| p.param > 0.76) {
        let root = (4.0 * point.param - 3.0).sqrt();
        let phase = [0.5 * (1.0 + root), 0.5 * (1.0 - root)];
        let tol = 1e-9 / (1.0 - 4.0 * (1.0 - point.param)).abs();
        assert!(
            phase.iter().any(|x| (point.x[0] - x).abs() < tol),
            "{} {}",
            point.param,
            point.x[0]
        );
        assert!((point.param - point.x[0] * point.x[0] - point.x[0]).abs() > 1e-3);
    }
    let second: Vec<_> = of_kind(&doubled, SpecialKind::PeriodDoubling)
        .into_iter()
        .filter(|s| s.param > 1.0)
        .collect();
    assert!(!second.is_empty(), "{:?}", doubled.special);
    for sp in second {
        assert!(
            (sp.param - QuadraticFamily::SECOND_PERIOD_DOUBLING).abs() < LOCATE_TOL,
            "{}",
            sp.param
        );
    }
}

#[test]
fn delayed_logistic_neimark_sacker_point() {
    let map = Closed {
        eval: |x, p| DelayedLogisticFamily.eval(x, p),
        period: 1,
    };
    let p0 = 1.5;
    let start = DVector::from_column_slice(&DelayedLogisticFamily.fixed_point(p0));
    let options = ContinuationOptions::for_range(1.3, 2.5);
    let family = continue_family(&map, &start, p0, &options).unwrap();
    let ns = of_kind(&family, SpecialKind::NeimarkSacker);
    assert_eq!(ns.len(), 1, "{:?}", family.special);
    assert!(
        (ns[0].param - DelayedLogisticFamily::NEIMARK_SACKER).abs() < LOCATE_TOL,
        "{}",
        ns[0].param
    );
    assert!(ns[0]
        .multipliers
        .iter()
        .all(|m| (m.norm() - 1.0).abs() < 1e-8));
}

#[test]
fn invalid_options_and_starts_are_refused() {
    let map = quadratic();
    let start = DVector::from_column_slice(&QuadraticFamily.upper_fixed_point(0.3));
    let mut options = ContinuationOptions::for_range(-0.5, 1.0);
    assert!(matches!(
        continue_family(&map, &start, 2.0, &options),
        Err(arclength::ContinuationError::StartOutsideRange { .. })
    ));
    options.min_step = 0.0;
    assert!(matches!(
        continue_family(&map, &start, 0.3, &options),
        Err(arclength::ContinuationError::Options(_))
    ));
    // No fixed point at p < -1/4.
    let options = ContinuationOptions::for_range(-1.0, 1.0);
    assert!(matches!(
        continue_family(&map, &start, -0.9, &options),
        Err(arclength::ContinuationError::NoStart { .. })
    ));
}

/// A quantity of the quadratic family's points, monitored along it.
struct Quantity {
    name: &'static str,
    value: fn(&DVector<f64>, f64) -> f64,
    /// Its smooth pieces (none: one formula everywhere).
    shape: Option<fn(&DVector<f64>) -> &'static str>,
}

impl monitor::Monitor<()> for Quantity {
    fn name(&self) -> &str {
        self.name
    }

    fn value(&self, at: &monitor::At<'_, ()>) -> f64 {
        (self.value)(at.x, at.p)
    }

    fn shape(&self, at: &monitor::At<'_, ()>) -> String {
        self.shape.map_or(String::new(), |f| f(at.x).to_string())
    }
}

/// The extrema of `q` along the quadratic family from `p = 1` on the upper branch through the fold to `p = 1`
/// on the lower one.
fn quadratic_extrema(q: &Quantity) -> (Family<()>, Vec<monitor::Extremum<()>>) {
    let map = quadratic();
    let family = quadratic_through_fold();
    let monitored: Vec<monitor::Monitored> = monitor::monitor_family(&map, &family, &[q])
        .into_iter()
        .map(|m| m[0])
        .collect();
    let found = monitor::extrema(&map, &family, q, &monitored);
    (family, found)
}

/// The parameter along the family is least at the fold, `p = -1/4`, and `(x - 0.2)^2` at `x = 0.2`, `p = 0.24`:
/// smooth minima, located to `1e-8`; the derivatives along the family agree with the closed form's
/// `dp/ds = sigma t_p` and `dq/ds = 2 (x - 0.2) t_x`.
#[test]
fn smooth_extrema_of_monitored_quantities_on_the_quadratic_family() {
    let p = Quantity {
        name: "p",
        value: |_, p| p,
        shape: None,
    };
    let (family, found) = quadratic_extrema(&p);
    assert_eq!(found.len(), 1, "{found:?}");
    let e = &found[0];
    assert_eq!(e.kind, monitor::ExtremumKind::Min);
    assert!(e.corner.is_none() && e.special.located, "{e:?}");
    assert!(
        (e.special.param - QuadraticFamily::FOLD.0).abs() < 1e-8,
        "{}",
        e.special.param
    );
    assert!((e.located_bracket[1] - e.located_bracket[0]).abs() <= monitor::EXTREMUM_TOL);
    assert_eq!(e.special.kind, SpecialKind::Extremum);
    // The derivative along the family, against the tangent's own component (oriented along the arclength).
    let sigma = family.options.param_scale;
    let monitored = monitor::monitor_family(&quadratic(), &family, &[&p]);
    for (i, m) in monitored
        .iter()
        .enumerate()
        .skip(1)
        .take(family.points.len() - 2)
    {
        let chord = family.points[i + 1].param - family.points[i - 1].param;
        let t_p = family.points[i].tangent[2] * sigma;
        let along = if chord == 0.0 {
            t_p
        } else {
            t_p.abs() * chord.signum()
        };
        assert!(
            (m[0].derivative - along).abs() < 1e-9,
            "{} {along}",
            m[0].derivative
        );
    }
    let bowl = Quantity {
        name: "bowl",
        value: |x, _| (x[0] - 0.2).powi(2),
        shape: None,
    };
    let (_, found) = quadratic_extrema(&bowl);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].kind, monitor::ExtremumKind::Min);
    assert!(found[0].corner.is_none());
    assert!(
        (found[0].special.param - 0.24).abs() < 1e-8,
        "{}",
        found[0].special.param
    );
    assert!(found[0].value.abs() < 1e-12, "{}", found[0].value);
}

/// `|x - 0.3|` has a corner at `x = 0.3` (`p = 0.39`): with its two pieces named it is bracketed by bisection
/// on the change of piece; without, the one-sided differences at the zero of the smoothed derivative show it.
/// Either way a corner minimum, never a smooth one.
#[test]
fn a_corner_of_a_monitored_quantity_is_reported_as_a_corner() {
    for shape in [
        None,
        Some((|x| if x[0] < 0.3 { "left" } else { "right" }) as fn(&DVector<f64>) -> &'static str),
    ] {
        let q = Quantity {
            name: "kink",
            value: |x, _| (x[0] - 0.3).abs(),
            shape,
        };
        let (_, found) = quadratic_extrema(&q);
        assert_eq!(found.len(), 1, "{found:?}");
        let e = &found[0];
        assert!(e.special.located, "{e:?}");
        assert_eq!(e.kind, monitor::ExtremumKind::Min);
        assert!(e.corner.is_some(), "{e:?}");
        let [a, b] = e.located_bracket;
        assert!((b - a).abs() <= monitor::EXTREMUM_TOL, "{a} {b}");
        assert!((e.special.param - 0.39).abs() < 1e-8, "{}", e.special.param);
    }
}
