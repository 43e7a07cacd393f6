//! The ends of gait families along a sweep: each family followed from its last sweep point toward the next to
//! its end (to [`PARAM_TOL`]), the end named by what happens just past it (`gait_lost`, `gait_found`,
//! `branch_switch`, `fold`, `unconfirmed`; see the parent module), with the DLS indicators that vanish there.

use super::{sorted, unconfirmed, Quantity, Threshold, PARAM_TOL};
use crate::family::natural::{EndCause, FollowOutcome, GaitPoint, NaturalContinuation};
use crate::family::Parameter;
use crate::gait::limit_cycle::{Gait, GaitOptions};
use crate::gait::periodicity::SAME_GAIT_TOL;
use crate::study::sweep::{family_tangent, SweepPoint};

/// The DLS indicators that vanish where a gait family ends: the family's end is then the indicator's zero (a
/// border collision, e.g. the period-1 DLS gait that ends at `lambda_2+ = 0` where a period-2 BOUNCE gait takes
/// over). An indicator counts as vanishing when, extrapolated linearly from the grid point `from` to the last
/// gait of the family, it reaches zero within [`PARAM_TOL`] of the end. Each is reported as its own threshold at
/// the end's value, with the indicator's value at the last gait as its residual.
fn vanishing_at_end(
    parameter: Parameter,
    from: &SweepPoint,
    last: &GaitPoint,
    end: &Threshold,
) -> Vec<Threshold> {
    let Some(g) = from.gait.as_ref() else {
        return Vec::new();
    };
    // Within the family's range, the parameter is valid and the walk worked in the continuation: no reason to
    // report is lost where either fails.
    let Ok(at) = parameter.at(last.value) else {
        return Vec::new();
    };
    let map = at
        .step_map()
        .iterated(g.period_k)
        .with_slip(last.section.slips());
    let Ok(out) = map.eval(&last.section) else {
        return Vec::new();
    };
    let run = last.value - from.value;
    // Stability has no value from the indicators (NaN), so only the three DLS indicators can vanish here.
    Quantity::ALL
        .into_iter()
        .filter_map(|q| {
            let (at_from, at_last) = (q.of(g), q.of_indicators(&out.report.indicators));
            let slope = (at_last - at_from) / run;
            let to_zero = (at_last / slope).abs();
            (at_last.is_finite() && slope.is_finite() && to_zero <= PARAM_TOL).then(|| Threshold {
                name: q.name().to_string(),
                value: end.value,
                bracket: end.bracket,
                grid_bracket: end.grid_bracket,
                residual: at_last,
                detail: Some(format!(
                    "where the gait family ends ({}): {} of its last gait, at {p} = {}, is {at_last:.3e} and \
                     extrapolates to zero within {to_zero:.1e} of the end; the family ends where it vanishes",
                    end.name,
                    q.name().trim_end_matches(" = 0"),
                    last.value,
                    p = parameter.key(),
                )),
                second_route: None,
            })
        })
        .collect()
}

/// Follow the family of `from`'s gait toward `toward` to its end, and name the end by what happens just past
/// it (see the module documentation), followed by the DLS indicators that vanish there
/// ([`vanishing_at_end`]). Nothing if the family reaches `toward` after all and is `toward`'s gait.
pub(super) fn refine_end(
    parameter: Parameter,
    from: &SweepPoint,
    toward: &SweepPoint,
    options: &GaitOptions,
    gait_before: bool,
) -> Vec<Threshold> {
    let g = from.gait.as_ref().expect("an end starts at a gait");
    let cont = NaturalContinuation::new(parameter, options).with_period(g.period_k);
    let grid_bracket = sorted([from.value, toward.value]);
    let (last, beyond) = match followed_to_end(parameter, &cont, from, toward) {
        Ok(end) => end,
        Err(reported) => return reported,
    };
    let upward = toward.value > from.value;
    let ended = EndOf {
        parameter,
        cont: &cont,
        gait: g,
        last,
        beyond,
    };
    let (name, detail) = ended.named(upward, gait_before);
    let end = Threshold {
        name: name.to_string(),
        value: 0.5 * (last.value + beyond),
        bracket: sorted([last.value, beyond]),
        grid_bracket,
        residual: f64::NAN,
        detail: Some(detail),
        second_route: None,
    };
    let vanishing = vanishing_at_end(parameter, from, &last, &end);
    std::iter::once(end).chain(vanishing).collect()
}

/// The family of `from`'s gait followed toward `toward` (or the sweep's attempt that did so already): its last
/// gait and the first value it does not reach; else what is reported instead of an end (nothing where it
/// reaches `toward`'s gait, an `unconfirmed` entry where it is given up or reaches another gait there).
fn followed_to_end(
    parameter: Parameter,
    cont: &NaturalContinuation,
    from: &SweepPoint,
    toward: &SweepPoint,
) -> Result<(GaitPoint, f64), Vec<Threshold>> {
    let g = from.gait.as_ref().expect("an end starts at a gait");
    let p = parameter.key();
    let start = GaitPoint {
        value: from.value,
        section: g.section,
    };
    let grid_bracket = sorted([from.value, toward.value]);
    // The sweep may have followed this family from this gait toward this point already (and failed): take
    // that result rather than follow it again (the same computation, see `SweepPoint::attempts`).
    let followed = match toward.attempt_from(&start) {
        Some(f) => f.clone(),
        // With the sweep's predictor (the tangent of `from`'s gait), so as to follow it as the sweep did.
        None => {
            let guess = g.jacobian_guess();
            let tangent = family_tangent(&parameter, from.value, g);
            cont.follow(start, toward.value, (guess.as_ref(), tangent))
        }
    };
    match followed {
        FollowOutcome::Ended { last, beyond } => Ok((last, beyond)),
        FollowOutcome::GaveUp { last, .. } => Err(vec![unconfirmed(
            grid_bracket,
            format!(
                "the family of {p} = {} was followed only to {p} = {} toward {p} = {} (given up after {} \
                 continuation steps or {} steps by walking)",
                from.value,
                last.value,
                toward.value,
                crate::family::natural::MAX_FOLLOW_STEPS,
                crate::family::natural::MAX_FOLLOW_WALKS,
            ),
        )]),
        FollowOutcome::Reached(reached) => {
            let same = toward
                .gait
                .as_ref()
                .is_some_and(|gt| gt.section.distance(&reached.section) <= SAME_GAIT_TOL);
            if same {
                return Err(Vec::new());
            }
            let what = if toward.gait.is_some() {
                "the sweep found another gait there (two gaits coexist)"
            } else {
                "the sweep found no gait there"
            };
            Err(vec![unconfirmed(
                grid_bracket,
                format!(
                    "the family of {p} = {} reaches {p} = {}, but {what}",
                    from.value, toward.value
                ),
            )])
        }
    }
}

/// The end of a family: its last gait, the first value it does not reach, and how it was followed.
struct EndOf<'a> {
    parameter: Parameter<'a>,
    cont: &'a NaturalContinuation<'a>,
    /// The sweep's gait the family was followed from.
    gait: &'a Gait,
    last: GaitPoint,
    beyond: f64,
}

impl EndOf<'_> {
    /// The end's name and detail, by what happens just past it ([`NaturalContinuation::end_cause`]); `upward`:
    /// the family was followed up the parameter; `gait_before`: the sweep has a gait below it.
    fn named(&self, upward: bool, gait_before: bool) -> (&'static str, String) {
        let (p, last, beyond, g) = (self.parameter.key(), &self.last, self.beyond, self.gait);
        match self.cont.end_cause(last, beyond) {
            EndCause::WalkFails { failure, message } => (
                if upward { "gait_lost" } else { "gait_found" },
                format!(
                    "{}; walking from its last gait at {p} = {beyond}: {failure} ({message}){}",
                    self.existence(),
                    if !upward && gait_before {
                        "; the gait is found again"
                    } else {
                        ""
                    },
                ) + &cut_by_step_limit(self.parameter, self.cont, (last, beyond), &failure),
            ),
            EndCause::OtherGait {
                steps,
                lambda_i4,
                period_k,
                ..
            } => (
                "branch_switch",
                format!(
                    "the gait family of lambda_I4 = {:.6} N s (period {}) ends at {p} = {} (not reached at \
                     {beyond}); walking {steps} steps from its last gait there settles on another gait, of period \
                     {period_k}, lambda_I4 = {lambda_i4:.6} N s",
                    g.lambda_i4, g.period_k, last.value,
                ),
            ),
            EndCause::Fold { multiplier } => (
                "fold",
                format!(
                    "the gait family ends at {p} = {} (not reached at {beyond}) with a Floquet multiplier {multiplier:.4} \
                     near +1: a fold (saddle-node)",
                    last.value,
                ),
            ),
            EndCause::Unconfirmed { reason } => (
                "unconfirmed",
                format!(
                    "the gait family is not followed past {p} = {} (to {beyond}), but no physical cause was found: \
                     {reason}",
                    last.value,
                ),
            ),
        }
    }

    /// Where the family exists and where not, in words, for an end where the walk past it fails. A walk from an
    /// unstable gait fails whether or not the family goes on: then the evidence is Newton's method's alone.
    fn existence(&self) -> String {
        let (p, last, beyond) = (self.parameter.key(), &self.last, self.beyond);
        if self.cont.largest_multiplier(last).is_some_and(|m| m > 1.0) {
            format!(
                "the gait family is followed to {p} = {}, where its gait is unstable, and Newton's \
                 method finds none of its gaits at {p} = {beyond} (the walk from an unstable gait fails \
                 either way: that no gait of the family exists there is not shown)",
                last.value,
            )
        } else {
            format!(
                "the gait family exists at {p} = {} and not at {p} = {beyond}",
                last.value,
            )
        }
    }
}

/// Where the walk past a family's end stalls (no touchdown within `max_step_time`) and the family's last gait
/// has a step within [`STEP_LIMIT_SHARE`] of that limit, the family is cut by the limit rather than ended by the
/// physics (the wheel creeps ever more slowly over the top of its step): that, in words, for the end's detail;
/// an empty string otherwise.
fn cut_by_step_limit(
    parameter: Parameter,
    cont: &NaturalContinuation,
    (last, beyond): (&GaitPoint, f64),
    failure: &str,
) -> String {
    // Only a stalled walk asks for the last gait's step (a walk of up to max_step_time of motion).
    if failure != "stalled" {
        return String::new();
    }
    let Ok(at) = parameter.at(beyond) else {
        return String::new();
    };
    let limit = at.config.solver.max_step_time;
    match cont.longest_step(last) {
        Some(step) if step >= STEP_LIMIT_SHARE * limit => format!(
            "; the last gait's step lasts {step:.6} s of the max_step_time = {limit} s a step may last: the \
             family is cut by that limit, not ended by the dynamics (a larger max_step_time follows it further)"
        ),
        _ => String::new(),
    }
}

/// A family whose last gait's step lasts at least this share of `max_step_time` and whose walk past the end
/// stalls is cut by that limit ([`cut_by_step_limit`]).
const STEP_LIMIT_SHARE: f64 = 0.9;
