//! The curves of the families' special points in a second parameter (docs/model.md section 11, "Two-parameter
//! curves"; `vrw continue --two-param`), and their records in `special_points.json`.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::continuation::curve::{
    border_curve_seed, CurveTest, BORDER_OFFSET, FOLLOW_OFFSET_FACTOR,
};
use crate::continuation::special::{test_function, test_name, SpecialPoint};
use crate::continuation::{
    continue_curve, Curve, CurveEnd, CurveOptions, CurveProblem, Evaluation, Family, MapFailure,
    SpecialKind,
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
    let located = families
        .iter()
        .enumerate()
        .flat_map(|(k, (family, map))| family.special.iter().map(move |sp| (k, *family, *map, sp)));
    for (index, (k, family, map, sp)) in located.enumerate() {
        if !sp.located {
            continue;
        }
        let at = format!(
            "family {} {} at {} = {}",
            k + 1,
            sp.kind,
            job.param,
            sp.param
        );
        let Some(seed) = CurveSeed::of(sp, family, map, &at, warnings) else {
            continue;
        };
        let followed = seed.with_problem(map, name, |problem| {
            seed.follow(problem, (seed.p, q0), &options)
        });
        match followed {
            Ok(curve) => {
                records.push(CurveRecord {
                    curve: records.len() + 1,
                    family: k + 1,
                    special_point: index,
                    kind: sp.kind,
                    condition: seed.condition.clone(),
                    param2: name.clone(),
                    points: curve.points.len(),
                    ends: curve.ends.clone(),
                    method: seed.method(),
                });
                curves.push(curve);
            }
            Err(e) => warnings.push(format!("{at}: no curve in {name}: {}", e.message)),
        }
    }
    (records, curves)
}

/// What a special point's curve follows, and from where: an indicator border on the family's side of it, from
/// the family's point nearest the collision clearly on that side; a fold, period doubling or Neimark-Sacker
/// point by its test function of `DP`, from the located point.
pub(crate) struct CurveSeed {
    /// The test function of `DP` (`None` for a border).
    jacobian_test: Option<fn(&DMatrix<f64>) -> f64>,
    /// The offset from the border that is followed (0 for a test function).
    pub offset: f64,
    /// The start's free coordinates.
    x: DVector<f64>,
    /// The start's value of the family's parameter.
    pub p: f64,
    /// The function that is zero along the curve ([`CurveRecord::condition`]).
    pub condition: String,
}

impl CurveSeed {
    /// The seed of the curve of `sp`, a special point of `family` (with its map), named `at` in warnings; `None`
    /// where no curve is followed (a border collision of the event sequence, or without a point clearly on
    /// one side of the border: a warning).
    fn of(
        sp: &SpecialPoint<GaitInfo>,
        family: &Family<GaitInfo>,
        map: GaitFamily,
        at: &str,
        warnings: &mut Vec<String>,
    ) -> Option<CurveSeed> {
        if sp.kind != SpecialKind::BorderCollision {
            return CurveSeed::at_special(sp);
        }
        let border = sp.border.as_deref().filter(|b| *b != "event sequence")?;
        let seed = CurveSeed::at_border(&map, family, sp.arclength, border);
        if seed.is_none() {
            warnings.push(format!(
                "{at} ({border}): no point of the family lies clearly on one side of the border; no curve \
                 followed"
            ));
        }
        seed
    }

    /// The curve of the special point `sp` (a fold, period doubling or Neimark-Sacker point) by its test
    /// function, from the located point (`None` for a border collision).
    pub(crate) fn at_special(sp: &SpecialPoint<GaitInfo>) -> Option<CurveSeed> {
        Some(CurveSeed {
            jacobian_test: Some(test_function(sp.kind)?),
            offset: 0.0,
            x: sp.x.clone(),
            p: sp.param,
            condition: test_name(sp.kind).to_string(),
        })
    }

    /// The curve of `border` on the side of `family` (of `map`) where its points near the arclength `s` lie,
    /// from the one nearest `s` clearly on that side ([`border_curve_seed`]); `None` without such a point.
    pub(crate) fn at_border(
        map: &GaitFamily,
        family: &Family<GaitInfo>,
        s: f64,
        border: &str,
    ) -> Option<CurveSeed> {
        let (before, side) = border_curve_seed(map, family, s, border)?;
        Some(CurveSeed {
            jacobian_test: None,
            offset: BORDER_OFFSET.copysign(side),
            x: before.x.clone(),
            p: before.param,
            condition: border.to_string(),
        })
    }

    /// `f` of the curve problem of this seed in the configuration of `map`, with the second parameter `second`:
    /// the fixed point of `P(x; p, q)` and the seed's condition.
    pub(crate) fn with_problem<R>(
        &self,
        map: GaitFamily,
        second: &str,
        f: impl FnOnce(&CurveProblem<'_, GaitInfo>) -> R,
    ) -> R {
        let eval = |x: &DVector<f64>, p: f64, q: f64| map.eval_with(second, x, p, q);
        let observe = |x: &DVector<f64>, p: f64, q: f64| map.observe_with(second, x, p, q);
        let condition = self
            .jacobian_test
            .map_or(CurveTest::Border(&self.condition), CurveTest::Jacobian);
        let test = |ev: &Evaluation<GaitInfo>| condition.of(&map, ev);
        f(&CurveProblem {
            eval: &eval,
            observe: (!condition.needs_derivatives()).then_some(&observe),
            test: &test,
            offset: self.offset,
        })
    }

    /// The curve of `problem` (this seed's, [`CurveSeed::with_problem`]) from the seed's point with the
    /// parameters at `at`.
    pub(crate) fn follow(
        &self,
        problem: &CurveProblem<'_, GaitInfo>,
        at: (f64, f64),
        options: &CurveOptions,
    ) -> Result<Curve<GaitInfo>, MapFailure> {
        continue_curve(problem, &self.x, at, options)
    }

    /// How the curve is computed, in words ([`CurveRecord::method`]).
    fn method(&self) -> String {
        let (border, offset) = (&self.condition, self.offset);
        let aim = if offset == 0.0 {
            String::new()
        } else {
            format!(
                " (the family's side), steps at {:e}, polished",
                offset * FOLLOW_OFFSET_FACTOR
            )
        };
        format!("pseudo-arclength on P(x) = x, {border} = {offset:e}{aim}")
    }
}
