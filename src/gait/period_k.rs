//! Period-k gaits: fixed points of the iterated step map `P^k` (docs/model.md section 6).
//!
//! Where Newton's method on `P(s) - s` fails but the walk settles, the wheel may walk a gait that repeats every
//! `k` steps (a period-doubled gait, `k = 2`, for example). The search:
//!
//! 1. walks the transient, then `SETTLE_STEPS` more steps, keeping their section states (the returns);
//! 2. for each `k = 1 ..= max_period` measures how far the returns are from repeating with period `k`
//!    (the largest coordinate difference of `s_n` and `s_{n-k}` over the last `RETURN_WINDOW` returns);
//! 3. for the smallest `k` whose distance is below `RETURN_TOL` (the walk's period), runs Newton's method
//!    on `P^k(s) - s` from the last return (`solve_fixed_point` on
//!    [`StepMap::iterated`]);
//! 4. walks two periods from the fixed point: a periodic walk is back at it after `2k` steps too, otherwise
//!    the fixed point is an artefact of the section ([`GaitError::SectionIncomplete`], below);
//! 5. checks its least period (`P^j(s*) = s*` for a divisor `j < k` would make it a period-`j` gait) and
//!    reports it with every step of its period and the eigenvalues of `D(P^k)`, the Floquet multipliers of
//!    the period-k gait.
//!
//! `P^k` walks `k` steps with one walker from the state built from `s` (not `k` fresh starts): the section
//! `s = (L2, dtheta/dt, dL2/dt)` assumes the stance tip at rest at touchdown, but when it slides without
//! friction (`inconsistent_contact = "slide"`) its velocity is a state the section does not hold. In the
//! period-2 reference gait ([`crate::reference::period_two_config`]) this happens before every second
//! touchdown, so `P(P(s))` with a fresh start at the middle touchdown differs from the walk, while the walk
//! itself repeats every two steps to 1e-11. Where the tip slides at every touchdown (the same parameters
//! with `c` from 4.5 to 8.6 N s/m), the walk settles on period 1 but `P` started from the section has no
//! fixed point, and a multiple `k` would give a fixed point of `P^k` that the walk does not repeat: step 4
//! refuses it.

use super::limit_cycle::{
    find_gait, friction_admits_gaits, gait_with_jacobian, solve_fixed_point, FixedPoint, Gait,
    GaitError, GaitOptions,
};
use super::periodicity::SAME_GAIT_TOL;
pub use super::periodicity::{least_period, MAX_PERIOD};
pub(crate) use super::periodicity::{return_distances, RETURN_TOL, RETURN_WINDOW};
use super::step_map::StepMap;
use crate::walk::SectionState;

/// Steps walked after the transient before the period is looked for.
pub(crate) const SETTLE_STEPS: usize = 64;

/// The section states of `k` steps from `s` (`s` first), and the reports of those steps.
fn walk_period(
    map: &StepMap,
    s: &SectionState,
    k: usize,
) -> Result<(Vec<SectionState>, Vec<crate::walk::StepReport>), crate::walk::WalkError> {
    let mut walker = map.walker(s)?;
    let mut states = vec![*s];
    let mut reports = Vec::with_capacity(k);
    for i in 0..k {
        reports.push(walker.step(None)?);
        // Touchdowns inside the cycle may be off the section; its end must be on it.
        states.push(if i + 1 == k {
            walker.section()?
        } else {
            walker.touchdown_coordinates()
        });
    }
    Ok((states, reports))
}

/// Find a gait of period `k <= max_period` from `initial` (see the module documentation). `options` are
/// those of the period-1 search (transient, tolerance, Jacobian). Fails with the walk's failure if the wheel
/// does not keep walking, and with [`GaitError::Unsettled`] if no period up to `max_period` is found.
pub fn find_periodic_gait(
    map: &StepMap,
    initial: &SectionState,
    options: &GaitOptions,
    max_period: usize,
) -> Result<Gait, GaitError> {
    options.validate().map_err(|e| GaitError::InvalidOptions {
        message: e.to_string(),
    })?;
    friction_admits_gaits(map.model().params())?;
    let max_period = max_period.max(1);
    let single = map.iterated(1);
    let walked = options.transient_steps + SETTLE_STEPS.max(max_period + RETURN_WINDOW);
    let mut walker = single
        .walker(initial)
        .map_err(|source| GaitError::Transient { step: 1, source })?;
    // The returns' coordinates, and the last return on the section (where Newton's method on P^k may start:
    // touchdowns off the section, where the stance tip slides, can be inside the cycle but not start it).
    let mut returns = Vec::with_capacity(walked);
    let mut last_on_section = None;
    for step in 1..=walked {
        let transient = |source| GaitError::Transient { step, source };
        walker.step(None).map_err(transient)?;
        returns.push(walker.touchdown_coordinates());
        match walker.section() {
            Ok(s) => last_on_section = Some(s),
            Err(e) if e.leaves_section() => {}
            Err(source) => return Err(transient(source)),
        }
    }
    let distances = return_distances(&returns, max_period);
    let Some(start) = last_on_section else {
        let source = walker
            .section()
            .expect_err("no touchdown of the walk was on the section");
        return Err(GaitError::Transient {
            step: walked,
            source,
        });
    };
    let newton = GaitOptions {
        transient_steps: 0,
        ..*options
    };
    // Only the least period the walk shows: a multiple of it would let Newton's method find a spurious fixed
    // point of P^k where the section does not hold the whole state (see the module documentation).
    let Some(k) = distances
        .iter()
        .position(|d| *d < RETURN_TOL)
        .map(|i| i + 1)
    else {
        return Err(GaitError::Unsettled {
            max_period,
            steps: walked,
            distance: distances.iter().copied().fold(f64::INFINITY, f64::min),
        });
    };
    let fp = solve_fixed_point(&single.iterated(k), &start, &newton, None)?;
    periodic_gait_at(&single, &fp, k, options)
}

/// The period-`k` gait at `fp`, a fixed point of `P^k` (`single` is `P`): steps 4 and 5 of the module
/// documentation (two periods walked, the least period, `D(P^k)` with the settings of `options`). Also what a
/// continuation of a period-k family completes its gaits with.
pub(crate) fn periodic_gait_at(
    single: &StepMap,
    fp: &FixedPoint,
    k: usize,
    options: &GaitOptions,
) -> Result<Gait, GaitError> {
    let newton_error = |source| GaitError::Newton {
        iteration: fp.iterations + 1,
        source,
    };
    // Two periods walked on: a periodic walk returns to s* after k and after 2k steps.
    let (states, reports) = walk_period(single, &fp.section, 2 * k).map_err(newton_error)?;
    let distance = states[2 * k].distance(&fp.section);
    if distance > SAME_GAIT_TOL {
        return Err(GaitError::SectionIncomplete {
            period_k: k,
            distance,
        });
    }
    // The least period: P^j(s*) = s* for a divisor j of k.
    let least = (1..=k)
        .find(|&j| k.is_multiple_of(j) && states[j].distance(&fp.section) <= SAME_GAIT_TOL)
        .unwrap_or(k);
    let map_least = single.iterated(least);
    let mut gait = gait_with_jacobian(&map_least, fp, options);
    gait.period_k = least;
    gait.cycle = reports[..least].to_vec();
    if least < k {
        // The residual of the least period's map at the point.
        gait.residual = states[least].distance(&fp.section);
    }
    Ok(gait)
}

/// The gait of any period up to `max_period`: the period-1 search ([`find_gait`]) first; if the walk keeps
/// going but Newton's method fails there, the period-k search ([`find_periodic_gait`]).
pub fn find_gait_any_period(
    map: &StepMap,
    initial: &SectionState,
    options: &GaitOptions,
    max_period: usize,
) -> Result<Gait, GaitError> {
    match find_gait(map, initial, options, None) {
        // A transient that ends off the section (the walk's cycle has touchdowns where the stance tip slides, or
        // where the old rear leg still swings) is not a failure of the walk: look for a longer period.
        Err(e)
            if (!matches!(
                e,
                GaitError::Transient { .. } | GaitError::InvalidOptions { .. }
            ) || e.leaves_section())
                && max_period > 1 =>
        {
            find_periodic_gait(map, initial, options, max_period)
        }
        result => result,
    }
}
