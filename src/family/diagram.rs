//! The bifurcation diagram of the wheel's gaits in one parameter (docs/model.md section 11; `vrw continue`):
//! the family of a gait followed by the continuation engine, then breadth first the families born from each
//! family followed (the period-2 family of a period doubling, the other piece's family at a border collision,
//! the family of the gait a walk past an end settles on), each end explained by a walk past it, and whether a
//! family was followed already.

use std::sync::atomic::AtomicBool;

use serde::Serialize;

use crate::continuation::corrector::solve_on_hyperplane;
use crate::continuation::special::JUMP_TOL;
use crate::continuation::{
    continue_family, switch_at_border, switch_at_period_doubling, ContinuationError,
    ContinuationOptions, Family, FamilyEnd, FamilyMap, SpecialKind, SpecialPoint,
};
use crate::family::natural::{EndCause, GaitPoint, NaturalContinuation};
use crate::family::{GaitFamily, GaitInfo};
use crate::gait::GaitOptions;
use crate::walk::interrupt::stop_requested;

/// How a family ends at one side, with the physical cause found by walking just past it.
#[derive(Debug, Clone, Serialize)]
pub struct EndRecord {
    /// How following it stopped.
    #[serde(flatten)]
    pub end: FamilyEnd,
    /// What the walk from the last gait does just past the end (where the map failed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cause: Option<EndCause>,
}

/// A family of the diagram: where it came from, its map and its ends with their causes.
pub struct FollowedFamily<'a> {
    /// The family followed.
    pub family: Family<GaitInfo>,
    /// Where it came from: `start`, or the special point or end it was switched to from.
    pub origin: String,
    /// Its map (`P^k` for a family of period k).
    pub map: GaitFamily<'a>,
    /// Its ends with their causes (`None` until explained; an interrupted diagram may leave it so).
    pub ends: Option<[EndRecord; 2]>,
}

/// The families born from family `k` (branch switching): the period-2 family of each of its located period
/// doublings, the other piece's family at each border collision where it ends, and the family of each gait that
/// a walk past one of its `ends` settles on (unless a family already followed passes through that gait). A
/// family that cannot be started is a warning.
fn switched_families<'a>(
    k: usize,
    families: &[FollowedFamily<'a>],
    base_map: GaitFamily<'a>,
    ends: &[EndRecord; 2],
    options: &ContinuationOptions,
) -> Vec<Result<FollowedFamily<'a>, String>> {
    let mut born = period_doubling_families(k, &families[k], options);
    born.extend(border_families(k, &families[k], options));
    born.extend(end_families(k, families, base_map, ends, options));
    born
}

/// The period-2 family of each located period doubling of `parent` (family `k`).
fn period_doubling_families<'a>(
    k: usize,
    parent: &FollowedFamily<'a>,
    options: &ContinuationOptions,
) -> Vec<Result<FollowedFamily<'a>, String>> {
    let param = parent.map.param();
    let doublings = parent.family.special.iter().enumerate();
    doublings
        .filter(|(_, pd)| pd.kind == SpecialKind::PeriodDoubling && pd.located)
        .map(|(i, pd)| {
            switch_at_period_doubling(&parent.map, pd, options)
                .map(|family| FollowedFamily {
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
                })
        })
        .collect()
}

/// The other piece's family at each located border collision that ends `parent` (family `k`) without a jump of
/// the map across the border.
fn border_families<'a>(
    k: usize,
    parent: &FollowedFamily<'a>,
    options: &ContinuationOptions,
) -> Vec<Result<FollowedFamily<'a>, String>> {
    let param = parent.map.param();
    // Where the map jumps across the border, no fixed point of the other piece is near: the walk past the end
    // ([`end_families`]) looks for what takes over.
    let continuous_ends = |bc: &&SpecialPoint<GaitInfo>| {
        bc.kind == SpecialKind::BorderCollision
            && bc.ends_family
            && bc.located
            && !bc.jump.is_nan()
            && bc.jump <= JUMP_TOL
    };
    let collisions = parent.family.special.iter().enumerate();
    collisions
        .filter(|(_, bc)| continuous_ends(bc))
        .map(|(i, bc)| {
            switch_at_border(&parent.map, bc, options)
                .map(|family| FollowedFamily {
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
                })
        })
        .collect()
}

/// The family of each gait that a walk past one of the `ends` of family `k` settles on, unless a family already
/// followed passes through that gait or it lies outside the continuation's range.
fn end_families<'a>(
    k: usize,
    families: &[FollowedFamily<'a>],
    base_map: GaitFamily<'a>,
    ends: &[EndRecord; 2],
    options: &ContinuationOptions,
) -> Vec<Result<FollowedFamily<'a>, String>> {
    let param = base_map.param();
    let mut born = Vec::new();
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
                .map(|family| FollowedFamily {
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
    families: &[FollowedFamily],
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
fn same_as_followed(families: &[FollowedFamily], new: &FollowedFamily) -> bool {
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

/// The families [`follow_families`] followed, the warnings on the way, and where the interrupt flag stopped it
/// (in words; `None` if it did not).
pub struct Diagram<'a> {
    /// The families, in the order they were found (the start's first).
    pub families: Vec<FollowedFamily<'a>>,
    /// Families that could not be followed, or were left out.
    pub warnings: Vec<String>,
    /// Where the interrupt flag stopped the work, in words.
    pub interrupted: Option<String>,
}

/// What [`follow_families`] follows besides the start: whether to switch to the families born at special
/// points and ends, and the job's interrupt flag (the library's is read too).
pub struct DiagramSettings<'s> {
    /// Follow the families born at period doublings, border collisions and ends (up to [`MAX_FAMILIES`]).
    pub switch: bool,
    /// The job's own interrupt flag.
    pub interrupt: Option<&'s AtomicBool>,
}

/// Most families one diagram follows (the start's and those switched to).
pub const MAX_FAMILIES: usize = 8;

/// Follow the family of `gait` from `start`, then breadth first: each family's ends explained by a walk past
/// them, then (with `switch`) the period-2 family of each of its located period doublings and the family of
/// each gait a walk past an end settles on. Once the interrupt flag is set, what the step under way computed
/// is dropped (the causes of a family's ends, the families born from it) and nothing more is followed.
///
/// # Errors
/// The first family could not be started.
pub fn follow_families<'a>(
    settings: &DiagramSettings,
    base_map: GaitFamily<'a>,
    gait: &crate::gait::Gait,
    start: f64,
    options: &ContinuationOptions,
) -> Result<Diagram<'a>, ContinuationError> {
    let flag = settings.interrupt;
    let family_map = base_map.iterated(gait.period_k);
    let first = continue_family(
        &family_map,
        &family_map.reduce(&gait.section),
        start,
        options,
    )?;
    let mut followed = Diagram {
        families: vec![FollowedFamily {
            family: first,
            origin: "start".to_string(),
            map: family_map,
            ends: None,
        }],
        warnings: Vec::new(),
        interrupted: None,
    };
    let families = &mut followed.families;
    let mut next = 0;
    while next < families.len() && !stop_requested(flag) {
        let ends = families[next].family.ends.clone().map(|end| {
            let cause = end_cause(&families[next], &end);
            EndRecord { end, cause }
        });
        if stop_requested(flag) {
            break;
        }
        families[next].ends = Some(ends.clone());
        let born = if settings.switch {
            switched_families(next, families, base_map, &ends, options)
        } else {
            Vec::new()
        };
        if stop_requested(flag) {
            break;
        }
        for outcome in born {
            match outcome {
                Ok(f) if same_as_followed(families, &f) => followed.warnings.push(format!(
                    "the family from {} is one already followed (same period and ends): left out",
                    f.origin
                )),
                Ok(f) if families.len() < MAX_FAMILIES => families.push(f),
                Ok(f) => followed.warnings.push(format!(
                    "more families than the {MAX_FAMILIES} one job follows: the one from {} not followed",
                    f.origin
                )),
                Err(w) => followed.warnings.push(w),
            }
        }
        next += 1;
    }
    if stop_requested(flag) {
        followed.interrupted = Some(format!(
            "while following family {} of {}: the points, ends and special points found before it are \
             kept; families not followed to their ends end as `interrupted`, and no family born after it \
             is followed",
            (next + 1).min(families.len()),
            families.len()
        ));
    }
    Ok(followed)
}

/// In an interrupted job: drop the special points that were not located (their location may have been cut
/// short), with a warning.
pub fn drop_unlocated(families: &mut [FollowedFamily], warnings: &mut Vec<String>) {
    for (k, f) in families.iter_mut().enumerate() {
        let before = f.family.special.len();
        f.family.special.retain(|sp| sp.located);
        let dropped = before - f.family.special.len();
        if dropped > 0 {
            warnings.push(format!(
                "family {}: {dropped} special points detected but not located are left out (the job was \
                 interrupted)",
                k + 1
            ));
        }
    }
}

/// What the walk from the last gait does just past an end where the map failed (`NaturalContinuation::end_cause`).
fn end_cause(followed: &FollowedFamily, end: &FamilyEnd) -> Option<EndCause> {
    let (family, map) = (&followed.family, &followed.map);
    let FamilyEnd::Ended {
        param: at, beyond, ..
    } = end
    else {
        return None;
    };
    if !beyond.is_finite() {
        return None;
    }
    let last = family
        .points
        .iter()
        .find(|p| p.param == *at)
        .or(family.points.last())?;
    let continuation = NaturalContinuation::new(map.parameter(), &GaitOptions::default())
        .with_period(map.period());
    Some(continuation.end_cause(
        &GaitPoint {
            value: last.param,
            section: map.section_at(&last.x, last.param),
        },
        *beyond,
    ))
}
