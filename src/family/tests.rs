//! The VRW's gait families followed by the continuation engine: their ends against natural continuation, the
//! slope fold, the border collision `lambda_2+ = 0` and the curves of both in two parameters.

use nalgebra::DVector;

use super::{GaitFamily, GaitInfo, Parameter};
use crate::continuation::curve::border_curve_seed;
use crate::continuation::*;

fn of_kind<I>(family: &Family<I>, kind: SpecialKind) -> Vec<&SpecialPoint<I>> {
    family.special.iter().filter(|s| s.kind == kind).collect()
}

use crate::dynamics::Model;
use crate::family::natural::{FollowOutcome, GaitPoint, NaturalContinuation};
use crate::gait::{find_gait, GaitOptions, StepMap};
use crate::params::Config;
use crate::reference::default_initial;

/// The configuration of Table 1 with `key` at `value`, and its gait found from the default start.
fn vrw_gait(changes: &[(&str, f64)]) -> (Config, crate::walk::SectionState) {
    let mut config = Config::default();
    for (key, value) in changes {
        config.set_numeric(key, *value).unwrap();
    }
    config.validate().unwrap();
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let gait = find_gait(
        &map,
        &default_initial(&config),
        &GaitOptions::default(),
        None,
    )
    .unwrap();
    (config, gait.section)
}

/// `max |P(s) - s|` of the VRW at the family point, by a direct evaluation of the step map.
fn direct_residual(
    config: &Config,
    key: &str,
    point: &FamilyPoint<GaitInfo>,
    family: &GaitFamily,
) -> f64 {
    let c = config.with(key, point.param).unwrap();
    let model = Model::new(&c.params).unwrap();
    let map = StepMap::new(&model, &c.solver).iterated(family.period());
    let s = family.expand(&point.x);
    map.eval(&s).unwrap().next.distance(&s)
}

/// The end of the default family (the wheel stalls in double support, c = 135.489237) is where natural
/// continuation (the sweep's route, bracketing to 1e-6) ends too; and its gaits are far from a fold there.
#[test]
fn default_family_ends_where_the_sweep_ends() {
    let (config, section) = vrw_gait(&[("viscosity", 130.0)]);
    let family_map = GaitFamily::new(Parameter::named(&config, "viscosity").unwrap(), section);
    let options = ContinuationOptions::for_range(120.0, 140.0);
    let family =
        continue_family(&family_map, &family_map.reduce(&section), 130.0, &options).unwrap();
    let FamilyEnd::Ended { param, beyond, .. } = family.ends[1].clone() else {
        panic!("{:?}", family.ends);
    };
    let natural = NaturalContinuation::new(
        Parameter::named(&config, "viscosity").unwrap(),
        &GaitOptions::default(),
    )
    .follow(
        GaitPoint {
            value: 130.0,
            section,
        },
        140.0,
        (None, None),
    );
    let FollowOutcome::Ended { last, .. } = natural else {
        panic!("{natural:?}");
    };
    assert!((param - last.value).abs() < 1e-6, "{param} {}", last.value);
    assert!(beyond > param && beyond - param < 1e-6);
    // Not a fold: the multipliers stay far from +1 to the end (where the step map still has derivatives: at
    // the very end an event's time depends on the state too steeply, and the last points have none).
    let with = family.points.iter().filter(|p| p.has_derivatives());
    assert!(with.clone().count() > family.points.len() / 2);
    assert!(with.into_iter().all(|p| p.max_multiplier() < 0.1));
    assert!(family.special.is_empty(), "{:?}", family.special);
}

/// The slope family turns back at a fold (phi = 0.33116), located with a multiplier +1; the unstable gaits
/// past it are fixed points of the step map by direct evaluation, and the family followed back from one of
/// them meets the same fold.
#[test]
fn slope_family_through_its_fold() {
    let (config, section) = vrw_gait(&[("slope", 0.3)]);
    let family_map = GaitFamily::new(Parameter::named(&config, "slope").unwrap(), section);
    let options = ContinuationOptions::for_range(0.29, 0.34);
    let family = continue_family(&family_map, &family_map.reduce(&section), 0.3, &options).unwrap();
    let folds = of_kind(&family, SpecialKind::Fold);
    assert_eq!(folds.len(), 1, "{:?}", family.special);
    let fold = folds[0];
    assert!(
        fold.located && (fold.param - 0.331163).abs() < 1e-5,
        "{}",
        fold.param
    );
    assert!((fold.multipliers[0].re - 1.0).abs() < 1e-8 && fold.multipliers[0].im == 0.0);
    let unstable: Vec<_> = family
        .points
        .iter()
        .filter(|p| p.max_multiplier() > 1.0 + 1e-6)
        .collect();
    assert!(unstable.len() > 3);
    for p in &unstable {
        assert!(direct_residual(&config, "slope", p, &family_map) < 1e-10);
    }
    let back_from = unstable[unstable.len() / 2];
    let back = continue_family(&family_map, &back_from.x, back_from.param, &options).unwrap();
    let again = of_kind(&back, SpecialKind::Fold);
    assert_eq!(again.len(), 1, "{:?}", back.special);
    assert!((again[0].param - fold.param).abs() < 1e-8);
}

/// At c = 20 the DLS family ends where lambda_2+ reaches zero (k = 593.866724): a border collision located
/// on the border, at the end natural continuation finds, with the BOUNCE piece on the other side.
#[test]
fn dls_family_ends_at_a_border_collision() {
    let (config, section) = vrw_gait(&[("viscosity", 20.0), ("stiffness", 590.0)]);
    let family_map = GaitFamily::new(Parameter::named(&config, "stiffness").unwrap(), section);
    let options = ContinuationOptions::for_range(585.0, 600.0);
    let family =
        continue_family(&family_map, &family_map.reduce(&section), 590.0, &options).unwrap();
    let bc = of_kind(&family, SpecialKind::BorderCollision);
    assert_eq!(bc.len(), 1, "{:?}", family.special);
    let bc = bc[0];
    assert_eq!(bc.border.as_deref(), Some("lambda_2_plus"));
    assert!(bc.located && bc.test_value.abs() < 1e-6);
    let natural = NaturalContinuation::new(
        Parameter::named(&config, "stiffness").unwrap(),
        &GaitOptions::default(),
    )
    .follow(
        GaitPoint {
            value: 590.0,
            section,
        },
        600.0,
        (None, None),
    );
    let FollowOutcome::Ended { last, beyond } = natural else {
        panic!("{natural:?}");
    };
    assert!(
        bc.param >= last.value - 1e-6 && bc.param <= beyond + 1e-6,
        "{} {}",
        bc.param,
        last.value
    );
    let sides = bc.sides.as_ref().unwrap();
    assert!(sides[0].piece.starts_with("TD DLS") && sides[1].piece.starts_with("TD BOUNCE"));
}

/// The border collision lambda_2+ = 0 followed as a curve in (stiffness, viscosity) from c = 20 crosses c = 4
/// where natural continuation along the stiffness at c = 4 ends (k = 564.367191, the README's sweep), to 1e-6.
#[test]
fn border_curve_agrees_with_the_one_parameter_end() {
    let (config, section) = vrw_gait(&[("viscosity", 20.0), ("stiffness", 590.0)]);
    let family_map = GaitFamily::new(Parameter::named(&config, "stiffness").unwrap(), section);
    let options = ContinuationOptions::for_range(585.0, 600.0);
    let family =
        continue_family(&family_map, &family_map.reduce(&section), 590.0, &options).unwrap();
    let bc = of_kind(&family, SpecialKind::BorderCollision)[0].clone();
    let eval = |x: &DVector<f64>, k: f64, c: f64| family_map.eval_with("viscosity", x, k, c);
    let test = |ev: &Evaluation<GaitInfo>| family_map.border(&ev.info, "lambda_2_plus");
    let observe = |x: &DVector<f64>, p: f64, q: f64| family_map.observe_with("viscosity", x, p, q);
    let problem = CurveProblem {
        eval: &eval,
        observe: Some(&observe),
        test: &test,
        offset: crate::continuation::curve::BORDER_OFFSET,
    };
    let (seed, side) =
        border_curve_seed(&family_map, &family, bc.arclength, "lambda_2_plus").unwrap();
    assert_eq!(side, 1.0, "lambda_2+ > 0 on the DLS side");
    let curve_options = CurveOptions {
        steps: (0.05, 1e-6, 0.5),
        ..CurveOptions::for_ranges((500.0, 700.0), (3.0, 21.0))
    };
    let curve = continue_curve(&problem, &seed.x, (seed.param, 20.0), &curve_options).unwrap();
    assert!(curve
        .points
        .iter()
        .all(|p| p.test_value.abs() < 1e-6 && p.residual < 1e-9));
    assert_eq!(curve.ends, [CurveEnd::LeftRange, CurveEnd::LeftRange]);
    let at4 = curve_at_p2(&problem, &curve, 4.0, &curve_options).expect("the curve crosses c = 4");
    // Natural continuation along the stiffness at c = 4, as a sweep does.
    let (config4, section4) = vrw_gait(&[("viscosity", 4.0), ("stiffness", 560.0)]);
    let natural = NaturalContinuation::new(
        Parameter::named(&config4, "stiffness").unwrap(),
        &GaitOptions::default(),
    )
    .follow(
        GaitPoint {
            value: 560.0,
            section: section4,
        },
        570.0,
        (None, None),
    );
    let FollowOutcome::Ended { last, beyond } = natural else {
        panic!("{natural:?}");
    };
    assert!(
        at4.p1 >= last.value - 1e-6 && at4.p1 <= beyond + 1e-6,
        "curve {} sweep [{}, {beyond}]",
        at4.p1,
        last.value
    );
}

/// The slope fold followed as a curve in (slope, viscosity) from c = 50 (`det(DP - I) = 0`, every evaluation
/// with its derivatives): at c = 60 it lies where the family followed in the slope alone at c = 60 folds, to
/// 1e-7 (the fold is located to 1e-8; the curve solves the same condition).
#[test]
fn fold_curve_agrees_with_the_fold_of_another_line() {
    let fold_at = |c: f64| {
        let (config, section) = vrw_gait(&[("slope", 0.3), ("viscosity", c)]);
        let family_map = GaitFamily::new(Parameter::named(&config, "slope").unwrap(), section);
        let options = ContinuationOptions::for_range(0.29, 0.34);
        let family =
            continue_family(&family_map, &family_map.reduce(&section), 0.3, &options).unwrap();
        let fold = of_kind(&family, SpecialKind::Fold)[0].clone();
        (config, fold)
    };
    let (config, fold) = fold_at(50.0);
    let (_, fold60) = fold_at(60.0);
    let family_map = GaitFamily::new(
        Parameter::named(&config, "slope").unwrap(),
        crate::reference::default_initial(&config),
    );
    let eval = |x: &DVector<f64>, p: f64, c: f64| family_map.eval_with("viscosity", x, p, c);
    let test = |ev: &Evaluation<GaitInfo>| {
        special::test_function(SpecialKind::Fold).unwrap()(&ev.jacobian)
    };
    let problem = CurveProblem {
        eval: &eval,
        observe: None,
        test: &test,
        offset: 0.0,
    };
    let curve_options = CurveOptions::for_ranges((0.29, 0.34), (45.0, 65.0));
    let curve = continue_curve(&problem, &fold.x, (fold.param, 50.0), &curve_options).unwrap();
    assert!(curve
        .points
        .iter()
        .all(|p| p.test_value.abs() < 1e-8 && p.residual < 1e-9));
    let at60 =
        curve_at_p2(&problem, &curve, 60.0, &curve_options).expect("the curve crosses c = 60");
    assert!(
        (at60.p1 - fold60.param).abs() < 1e-7,
        "curve {} family {}",
        at60.p1,
        fold60.param
    );
}
