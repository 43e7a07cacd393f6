//! Branch switching for `vrw continue` (docs/model.md section 11): the families born from a followed family
//! (the period-2 family of a period doubling, the other piece's family at a border collision, the family of
//! the gait a walk past an end settles on), and whether a family was followed already.

use super::family_records::EndRecord;
use crate::continuation::corrector::solve_on_hyperplane;
use crate::continuation::special::JUMP_TOL;
use crate::continuation::{
    continue_family, switch_at_border, switch_at_period_doubling, ContinuationOptions, Family,
    FamilyEnd, FamilyMap, SpecialKind,
};
use crate::family::natural::EndCause;
use crate::family::{GaitFamily, GaitInfo};

/// A family being followed: where it came from, its map and its ends with their causes.
pub(super) struct Followed<'a> {
    pub family: Family<GaitInfo>,
    pub origin: String,
    pub map: GaitFamily<'a>,
    pub ends: Option<[EndRecord; 2]>,
}

/// The families born from family `k` (branch switching): the period-2 family of each of its located period
/// doublings, the other piece's family at each border collision where it ends, and the family of each gait that a walk past one of its `ends` settles on (unless a family
/// already followed passes through that gait). A family that cannot be started is a warning.
pub(super) fn switched_families<'a>(
    param: &str,
    k: usize,
    families: &[Followed<'a>],
    base_map: GaitFamily<'a>,
    ends: &[EndRecord; 2],
    options: &ContinuationOptions,
) -> Vec<Result<Followed<'a>, String>> {
    let parent = &families[k];
    let mut born = Vec::new();
    for (i, pd) in parent.family.special.iter().enumerate() {
        if pd.kind != SpecialKind::PeriodDoubling || !pd.located {
            continue;
        }
        born.push(
            switch_at_period_doubling(&parent.map, pd, options)
                .map(|family| Followed {
                    family,
                    origin: format!("family {} special point {i} (PD)", k + 1),
                    map: parent.map.iterated(2),
                    ends: None,
                })
                .map_err(|e| {
                    format!(
                        "family {} PD at {} = {}: no period-2 family followed: {e}",
                        k + 1,
                        param,
                        pd.param
                    )
                }),
        );
    }
    for (i, bc) in parent.family.special.iter().enumerate() {
        // Where the map jumps across the border, no fixed point of the other piece is near: the walk past
        // the end (below) looks for what takes over.
        if bc.kind != SpecialKind::BorderCollision
            || !bc.ends_family
            || !bc.located
            || bc.jump.is_nan()
            || bc.jump > JUMP_TOL
        {
            continue;
        }
        born.push(
            switch_at_border(&parent.map, bc, options)
                .map(|family| Followed {
                    family,
                    origin: format!(
                        "family {} special point {i} (BC: the other piece's fixed points)",
                        k + 1
                    ),
                    map: parent.map,
                    ends: None,
                })
                .map_err(|e| {
                    format!(
                        "family {} BC at {} = {}: no family of the other piece followed: {e}",
                        k + 1,
                        param,
                        bc.param
                    )
                }),
        );
    }
    for end in ends {
        let (
            Some(EndCause::OtherGait {
                section, period_k, ..
            }),
            FamilyEnd::Ended { beyond, .. },
        ) = (&end.cause, &end.end)
        else {
            continue;
        };
        // The walk's period may be a multiple of the gait's least period (its detection compares states
        // within the walk's tolerance): the family is followed as P^j for the least period j of its fixed
        // point at the walk's parameter.
        let walked = base_map.iterated(*period_k);
        let x = walked.reduce(section);
        let least = solve_on_parameter(&walked, &x, *beyond, options)
            .and_then(|fixed| walked.value_with_info(&fixed, *beyond).ok())
            .map_or(*period_k, |info| info.least_period());
        let period_k = &least;
        let map = base_map.iterated(*period_k);
        if known_gait(families, base_map, *period_k, &x, *beyond) {
            continue;
        }
        if !(options.from..=options.to).contains(beyond) {
            continue;
        }
        born.push(
            continue_family(&map, &x, *beyond, options)
                .map(|family| Followed {
                    family,
                    origin: format!(
                        "family {} end at {} = {} (the gait a walk past it settles on)",
                        k + 1,
                        param,
                        beyond
                    ),
                    map,
                    ends: None,
                })
                .map_err(|e| {
                    format!(
                        "family {} end at {} = {}: the period-{period_k} gait past it could not be followed: {e}",
                        k + 1,
                        param,
                        beyond
                    )
                }),
        );
    }
    born
}

/// The fixed point of `map` at `p` by Newton's method from `x` (`None` if it does not converge).
fn solve_on_parameter(
    map: &GaitFamily,
    x: &nalgebra::DVector<f64>,
    p: f64,
    options: &ContinuationOptions,
) -> Option<nalgebra::DVector<f64>> {
    let sigma = options.param_scale;
    let n = x.len();
    let mut z = x.clone().insert_row(n, p / sigma);
    let mut row = nalgebra::DVector::zeros(n + 1);
    row[n] = 1.0;
    z = solve_on_hyperplane(map, &z, &row, options).ok()?;
    Some(z.rows(0, n).into_owned())
}

/// Does a family already followed pass through the period-`k` gait `x` at `p` (any of its `k` phases)? Each
/// family of period `k` is interpolated linearly at `p` between its successive points that bracket `p`, and
/// compared with the phases within [`KNOWN_GAIT_TOL`] (the interpolation's error over a continuation step).
fn known_gait(
    families: &[Followed],
    base_map: GaitFamily,
    k: usize,
    x: &nalgebra::DVector<f64>,
    p: f64,
) -> bool {
    let mut phases = vec![x.clone()];
    for _ in 1..k {
        match phases.last().map(|y| base_map.value(y, p)) {
            Some(Ok(y)) => phases.push(y),
            _ => break,
        }
    }
    families
        .iter()
        .filter(|f| f.map.period() == k)
        .flat_map(|f| f.family.points.windows(2))
        .filter(|w| (w[0].param - p) * (w[1].param - p) <= 0.0 && w[0].param != w[1].param)
        .any(|w| {
            let t = (p - w[0].param) / (w[1].param - w[0].param);
            let at = &w[0].x + t * (&w[1].x - &w[0].x);
            phases.iter().any(|y| (&at - y).amax() < KNOWN_GAIT_TOL)
        })
}

/// Is `new` a family already followed: the same period, and both its ends within [`SAME_END_TOL`] times
/// `max(1, |p|)` in the parameter of that family's ends (a walk past an end can settle on another phase of a
/// known orbit, where [`known_gait`]'s interpolation misses it)?
pub(super) fn same_as_followed(families: &[Followed], new: &Followed) -> bool {
    let ends = |f: &Family<GaitInfo>| -> Option<[f64; 2]> {
        Some([f.points.first()?.param, f.points.last()?.param])
    };
    let Some(mut a) = ends(&new.family) else {
        return false;
    };
    a.sort_by(f64::total_cmp);
    families.iter().any(|f| {
        f.family.period == new.family.period
            && ends(&f.family).is_some_and(|mut b| {
                b.sort_by(f64::total_cmp);
                a.iter()
                    .zip(b)
                    .all(|(x, y)| (x - y).abs() <= SAME_END_TOL * y.abs().max(1.0))
            })
    })
}

/// Two families whose ends lie this close (relative to the parameter) are taken as one: ends are bracketed to
/// far less.
pub const SAME_END_TOL: f64 = 1e-6;

/// Two gaits closer than this on the section (interpolated) are taken as one (`known_gait`).
pub const KNOWN_GAIT_TOL: f64 = 1e-3;
