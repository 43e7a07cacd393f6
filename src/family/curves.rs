//! The curves of the families' special points in a second parameter (docs/model.md section 11, "Two-parameter
//! curves"; `vrw continue --two-param`), and their records in `special_points.json`.

use serde::Serialize;

use crate::continuation::curve::{
    border_curve_seed, CurveTest, BORDER_OFFSET, FOLLOW_OFFSET_FACTOR,
};
use crate::continuation::special::{test_function, test_name};
use crate::continuation::{
    continue_curve, Curve, CurveEnd, CurveOptions, CurveProblem, Family, SpecialKind,
};
use crate::family::{GaitFamily, GaitInfo};

/// One two-parameter curve in `special_points.json`.
#[derive(Debug, Clone, Serialize)]
pub struct CurveRecord {
    /// Its number (`curve` in `curves.csv`), from 1.
    pub curve: usize,
    /// The family and the index of the special point (in `special_points`) it starts from.
    pub family: usize,
    /// Index into `special_points`.
    pub special_point: usize,
    /// The special point's kind.
    pub kind: SpecialKind,
    /// The function that is zero along the curve: a DLS indicator for a `BC`, a test function of `DP` for the
    /// others (`det(DP - I)`, `det(DP + I)`, `bialternate product`).
    pub condition: String,
    /// The second parameter.
    pub param2: String,
    /// Points in `curves.csv`.
    pub points: usize,
    /// How it ends at its first point and at its last.
    pub ends: [CurveEnd; 2],
    /// How it was computed.
    pub method: String,
}

/// The followed parameter and its range (`vrw continue`'s `--param`, `--from`, `--to`).
pub struct FollowedParam<'s> {
    /// The parameter the families were followed in.
    pub param: &'s str,
    /// The lower end of its range.
    pub from: f64,
    /// The upper end.
    pub to: f64,
}

/// The curves of every located special point of `families` (each with its map) in the second parameter
/// (`name`, from, to; its value in the configuration `q0`, checked to lie in the range), a border collision's
/// followed on its family's side of the border (docs/model.md section 11, "Two-parameter curves"). A curve that
/// cannot be followed is a warning.
pub fn two_param_curves(
    job: &FollowedParam,
    (name, from, to): &(String, f64, f64),
    q0: f64,
    families: &[(&Family<GaitInfo>, GaitFamily)],
    warnings: &mut Vec<String>,
) -> (Vec<CurveRecord>, Vec<Curve<GaitInfo>>) {
    let options = CurveOptions::for_ranges((job.from, job.to), (*from, *to));
    let mut records = Vec::new();
    let mut curves = Vec::new();
    let mut index = 0;
    for (k, (family, family_map)) in families.iter().enumerate() {
        for sp in &family.special {
            let this = index;
            index += 1;
            if !sp.located {
                continue;
            }
            let map = *family_map;
            let at = format!(
                "family {} {} at {} = {}",
                k + 1,
                sp.kind,
                job.param,
                sp.param
            );
            // What is followed, from where: an indicator border on the family's side of it, from the family's
            // point nearest the collision clearly on that side; a fold, period doubling or Neimark-Sacker point
            // by its test function of `DP`, from the located point.
            let (jacobian_test, offset, start, border) = match sp.kind {
                SpecialKind::BorderCollision => {
                    let Some(border) = sp.border.clone().filter(|b| b != "event sequence") else {
                        continue;
                    };
                    let Some((before, side)) =
                        border_curve_seed(family_map, family, sp.arclength, &border)
                    else {
                        warnings.push(format!(
                            "{at} ({border}): no point of the family lies clearly on one side of the \
                             border; no curve followed"
                        ));
                        continue;
                    };
                    (
                        None,
                        BORDER_OFFSET.copysign(side),
                        (before.x.clone(), before.param),
                        border,
                    )
                }
                kind => {
                    let Some(test) = test_function(kind) else {
                        continue;
                    };
                    (
                        Some(test),
                        0.0,
                        (sp.x.clone(), sp.param),
                        test_name(kind).to_string(),
                    )
                }
            };
            let eval = |x: &nalgebra::DVector<f64>, p: f64, q: f64| map.eval_with(name, x, p, q);
            let observe =
                |x: &nalgebra::DVector<f64>, p: f64, q: f64| map.observe_with(name, x, p, q);
            let condition = jacobian_test.map_or(CurveTest::Border(&border), CurveTest::Jacobian);
            let test =
                |ev: &crate::continuation::Evaluation<GaitInfo>| condition.of(family_map, ev);
            let problem = CurveProblem {
                eval: &eval,
                observe: (!condition.needs_derivatives()).then_some(&observe),
                test: &test,
                offset,
            };
            match continue_curve(&problem, &start.0, (start.1, q0), &options) {
                Ok(curve) => {
                    let aim = if offset == 0.0 {
                        String::new()
                    } else {
                        format!(
                            " (the family's side), steps at {:e}, polished",
                            offset * FOLLOW_OFFSET_FACTOR
                        )
                    };
                    records.push(CurveRecord {
                        curve: records.len() + 1,
                        family: k + 1,
                        special_point: this,
                        kind: sp.kind,
                        condition: border.clone(),
                        param2: name.clone(),
                        points: curve.points.len(),
                        ends: curve.ends.clone(),
                        method: format!("pseudo-arclength on P(x) = x, {border} = {offset:e}{aim}"),
                    });
                    curves.push(curve);
                }
                Err(e) => warnings.push(format!("{at}: no curve in {name}: {}", e.message)),
            }
        }
    }
    (records, curves)
}
