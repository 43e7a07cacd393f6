//! Impacts of a legged walker (docs/model.md section 5): every impact is an impulse-level complementarity
//! problem over the units present ([`impact`]), and a heel strike follows the paper's DLS-indicator procedure
//! ([`heel_strike`]).
//!
//! **Rule.** The closing unit (the landing tip, the leg reaching its stopper) is forced: a tip takes a no-slip
//! impulse if its normal part pushes, else a frictionless one (`inconsistent_contact = "slide"`); a stopper
//! stops its leg. Every other unit present (a tip on the ground, a leg held at its stopper) either takes an
//! impulse that pushes (`>= 0`) and ends at rest, or takes none and separates (a tip not moving into the
//! ground, a leg not moving past its stopper). The walk takes the choice in which the most units take an
//! impulse, the first in a fixed order among equals: no unit is held through an impact merely because it was
//! active before, and none is released while holding it pushes.

use nalgebra::SVector;

use super::forces::{choose, Solved, FORCE_TOL};
use super::{Legged, LeggedError, Modes, Tip, UnitForces};
use crate::mechanism::constrained::{impulse, ConstrainedError};

/// An impulse within this of 0 is 0 (the impulse-level complementarity's tolerance) \[N s\].
pub const IMPULSE_TOL: f64 = 1e-12;

/// A unit that takes no impulse separates if it approaches no faster than this \[m/s\].
pub const SEPARATION_TOL: f64 = 1e-9;

/// The outcome of an impact.
#[derive(Debug, Clone, PartialEq)]
pub struct Impact<const N: usize> {
    /// `q'+`.
    pub qd_plus: SVector<f64, N>,
    /// The units that took an impulse.
    pub took: Modes,
    /// Their impulses by unit.
    pub impulses: UnitForces,
    /// The energy the impact took (`T + V` before less after) \[J\].
    pub loss: f64,
}

/// Which unit closes an impact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Closing {
    /// Tip `i` lands.
    Tip(usize),
    /// Leg `i` reaches its stopper.
    Stopper(usize),
    /// Both tips are held (the paper's (A1)); none other is forced.
    BothTips,
}

/// Does `choice` (the units taking an impulse) satisfy the rule at `q`, its solve giving `result`?
fn valid<W: Legged<N>, const N: usize>(
    walker: &W,
    q: &SVector<f64, N>,
    (present, choice, closing): (&Modes, &Modes, Closing),
    result: &(SVector<f64, N>, UnitForces),
) -> bool {
    let (qd_plus, impulses) = result;
    let c = walker.constants_f64();
    let strokes = walker.strokes();
    // (A1) holds both tips whatever their impulses: its `lambda_I4` is the indicator.
    let tips = closing == Closing::BothTips
        || (0..2).all(|i| match (present.tips[i], choice.tips[i]) {
            (_, Tip::Stuck | Tip::Sliding) => impulses.normal[i].is_some_and(|p| p >= -IMPULSE_TOL),
            (Tip::Free, Tip::Free) => true,
            (_, Tip::Free) => {
                walker.contact(&c, q, qd_plus, i).velocity(qd_plus).y >= -SEPARATION_TOL
            }
        });
    let legs = (0..2).all(|i| match (present.held[i], choice.held[i], strokes[i]) {
        // The closing stopper is forced (a Zeno lock stops a leg moving inward: its impulse is outward).
        (_, true, _) if closing == Closing::Stopper(i) => true,
        (_, true, _) => impulses.holding[i].is_some_and(|p| p >= -IMPULSE_TOL),
        (true, false, Some(s)) => qd_plus[s.coordinate] <= SEPARATION_TOL,
        _ => true,
    });
    tips && legs
}

/// `q'+` and the impulses with the units of `choice` taking an impulse.
fn solve_choice<W: Legged<N>, const N: usize>(
    walker: &W,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    choice: &Modes,
) -> Result<(SVector<f64, N>, UnitForces), ConstrainedError> {
    let i = impulse(walker, q, qd, &choice.rows(&walker.strokes()))?;
    Ok((i.qd_plus, UnitForces::of(choice, &i.impulses)))
}

/// The options of each unit in an impact, preferred first: a closing tip sticks or slides, (A1)'s tips
/// stick; a tip on the ground sticks, slides or leaves; a sliding tip slides or leaves; a held leg stays held
/// or leaves its stopper; the closing stopper holds.
fn unit_options(present: &Modes, closing: Closing) -> ([Vec<Tip>; 2], [Vec<bool>; 2]) {
    let tips = [0, 1].map(|i| match (closing, present.tips[i]) {
        (Closing::BothTips, _) => vec![Tip::Stuck],
        (Closing::Tip(j), _) if j == i => vec![Tip::Stuck, Tip::Sliding],
        (_, Tip::Stuck) => vec![Tip::Stuck, Tip::Sliding, Tip::Free],
        (_, Tip::Sliding) => vec![Tip::Sliding, Tip::Free],
        (_, Tip::Free) => vec![Tip::Free],
    });
    let held = [0, 1].map(|i| match (closing, present.held[i]) {
        (Closing::Stopper(j), _) if j == i => vec![true],
        (_, true) => vec![true, false],
        (_, false) => vec![false],
    });
    (tips, held)
}

/// The choices of units taking an impulse (see [`unit_options`]): the most units taking first, then the
/// fewest sliding, the first in a fixed order among equals.
fn choices(present: &Modes, closing: Closing) -> Vec<Modes> {
    let (tips, held) = unit_options(present, closing);
    let mut all = Vec::new();
    for &t0 in &tips[0] {
        for &t1 in &tips[1] {
            for &h0 in &held[0] {
                for &h1 in &held[1] {
                    let choice = Modes {
                        tips: [t0, t1],
                        held: [h0, h1],
                    };
                    let idle = [t0, t1].iter().filter(|t| **t == Tip::Free).count()
                        + [h0, h1].iter().filter(|h| !**h).count();
                    let sliding = [t0, t1].iter().filter(|t| **t == Tip::Sliding).count();
                    all.push(((idle, sliding), choice));
                }
            }
        }
    }
    all.sort_by_key(|(rank, _)| *rank);
    all.into_iter().map(|(_, choice)| choice).collect()
}

/// The impact at `q` arriving with `q'-`, closed by `closing`, over the units `present` (see the module
/// documentation).
pub fn impact<W: Legged<N>, const N: usize>(
    walker: &W,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    present: &Modes,
    closing: Closing,
    time: f64,
) -> Result<Impact<N>, LeggedError> {
    for choice in choices(present, closing) {
        let result = match solve_choice(walker, (q, qd), &choice) {
            Ok(result) => result,
            Err(ConstrainedError::RedundantRows) => continue,
            Err(e) => return Err(e.into()),
        };
        if valid(walker, q, (present, &choice, closing), &result) {
            let loss = walker.energy(q, qd) - walker.energy(q, &result.0);
            return Ok(Impact {
                qd_plus: result.0,
                took: choice,
                impulses: result.1,
                loss,
            });
        }
    }
    Err(LeggedError::Inconsistent { time })
}

/// Which branch of the DLS-indicator procedure a heel strike took (docs/model.md section 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum Branch {
    /// (B2): double support follows.
    #[default]
    Dls,
    /// (A3): `lambda_I4 < 0`, the rear tip leaves at once.
    Sls,
    /// (B3): `lambda_4+ < 0`, single support from the (A1) velocities.
    SlsB3,
    /// `lambda_2+ < 0`: the new fore tip bounces.
    Bounce,
}

/// A heel strike: the DLS indicators, the branch, the impact and the phase that follows.
#[derive(Debug, Clone, PartialEq)]
pub struct HeelStrike<const N: usize> {
    /// DLS indicator 1: the rear tip's normal impulse with both tips held \[N s\].
    pub lambda_i4: f64,
    /// DLS indicators 2 and 3: the fore and rear tips' normal forces with both held after (A1) \[N\]; `None`
    /// where (A3) was taken.
    pub lambda_plus: Option<[f64; 2]>,
    /// The branch.
    pub branch: Branch,
    /// The impact taken.
    pub impact: Impact<N>,
    /// The phase that follows, and its solve.
    pub next: (Modes, Solved<N>),
}

/// The heel strike at `q` (after the relabeling: the landing tip is tip 0, the old stance tip tip 1, stuck)
/// arriving with `q'-`, the legs held as `held` (docs/model.md section 5, (A1)-(A4), (B1)-(B3)).
pub fn heel_strike<W: Legged<N>, const N: usize>(
    walker: &W,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    held: [bool; 2],
    time: f64,
) -> Result<HeelStrike<N>, LeggedError> {
    let present = Modes {
        tips: [Tip::Free, Tip::Stuck],
        held,
    };
    // (A1): both tips held, the stoppers candidates.
    let both = impact(walker, (q, qd), &present, Closing::BothTips, time)?;
    let lambda_i4 = both.impulses.normal[1].unwrap_or(f64::NAN);
    if lambda_i4 < 0.0 {
        // (A3): the new tip alone; the rear tip leaves.
        let alone = Modes {
            tips: [Tip::Free, Tip::Free],
            held,
        };
        let sls = impact(walker, (q, qd), &alone, Closing::Tip(0), time)?;
        let start = Modes {
            tips: [sls.took.tips[0], Tip::Free],
            held: sls.took.held,
        };
        let next = next_phase(walker, (q, &sls.qd_plus), &start, time)?;
        return Ok(HeelStrike {
            lambda_i4,
            lambda_plus: None,
            branch: Branch::Sls,
            impact: sls,
            next,
        });
    }
    // (A4)/(B1): the force-level problem with both tips held at (q, q'+).
    let dls = both.took;
    let solved = super::forces::solve(walker, (q, &both.qd_plus), &dls)?;
    let plus = [0, 1].map(|i| solved.forces.normal[i].unwrap_or(f64::NAN));
    let branch = if plus[1] < -FORCE_TOL {
        Branch::SlsB3
    } else if plus[0] < -FORCE_TOL {
        Branch::Bounce
    } else {
        Branch::Dls
    };
    let next = next_phase(walker, (q, &both.qd_plus), &dls, time)?;
    Ok(HeelStrike {
        lambda_i4,
        lambda_plus: Some(plus),
        branch,
        impact: both,
        next,
    })
}

/// The phase after an impact: the consistent modes nearest to `start` ([`choose`]).
pub fn next_phase<W: Legged<N>, const N: usize>(
    walker: &W,
    state: (&SVector<f64, N>, &SVector<f64, N>),
    start: &Modes,
    time: f64,
) -> Result<(Modes, Solved<N>), LeggedError> {
    choose(walker, state, start)?.ok_or(LeggedError::Inconsistent { time })
}
