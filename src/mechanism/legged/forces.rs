//! The force-level problem of a legged walker's phase (docs/model.md section 3): the accelerations and
//! multipliers of a set of active constraints ([`solve`]), and the choice of that set among the units that
//! touch ([`choose`]).
//!
//! **Rule.** A tip on the ground is stuck, sliding (frictionless) or free; a leg at its stopper is held or free.
//! A choice is consistent when every stuck or sliding tip's normal force pushes (`>= 0`), every free tip at the
//! ground does not accelerate into it, every held stopper pushes inward, and every free leg at its stopper does
//! not accelerate past it. Among the consistent choices the walk takes the one that changes the fewest units,
//! each unit's changes ranked (a stuck tip is released before it slides: slipping is the answer only where a
//! released tip would fall into the ground, the lift-off inconsistency of docs/model.md section 4), the first
//! of equal rank in a fixed order. This is the complementarity problem solved by enumeration: at most 36
//! candidates, each one solve of Eq. (1).

use nalgebra::SVector;

use super::{Legged, Modes, Stroke, Tip, UnitForces};
use crate::mechanism::constrained::{accelerations, ConstrainedError};

/// An acceleration or force within this of 0 is 0 (the force-level complementarity's tolerance) \[m/s^2, N\].
pub const FORCE_TOL: f64 = 1e-9;

/// A tip this close to the ground, or a leg this close to its stopper, touches it \[m\].
pub const TOUCH_GAP: f64 = 1e-9;

/// A normal velocity this small is at rest (a tip or a leg that neither approaches nor leaves) \[m/s\].
pub const REST_SPEED: f64 = 1e-9;

/// The accelerations of a phase and its multipliers by unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Solved<const N: usize> {
    /// `q''`.
    pub qdd: SVector<f64, N>,
    /// The multipliers by unit.
    pub forces: UnitForces,
}

/// Eq. (1) at `(q, q')` with the constraints of `modes` active.
pub fn solve<W: Legged<N>, const N: usize>(
    walker: &W,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    modes: &Modes,
) -> Result<Solved<N>, ConstrainedError> {
    let a = accelerations(walker, q, qd, &modes.rows(&walker.strokes()))?;
    Ok(Solved {
        qdd: a.qdd,
        forces: UnitForces::of(modes, &a.multipliers),
    })
}

/// Which units touch at `(q, q')`: the tips on the ground (active, or free at the ground and not rising) and
/// the legs at their stoppers (held, or free at the stopper and not retracting).
pub fn touching<W: Legged<N>, const N: usize>(
    walker: &W,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    modes: &Modes,
) -> ([bool; 2], [bool; 2]) {
    let c = walker.constants_f64();
    let tips = [0, 1].map(|i| {
        let p = walker.contact(&c, q, qd, i);
        modes.tips[i] != Tip::Free || (p.position.y <= TOUCH_GAP && p.velocity(qd).y <= REST_SPEED)
    });
    let strokes = walker.strokes();
    let legs = [0, 1].map(|i| {
        strokes[i].is_some_and(|s| {
            modes.held[i]
                || (q[s.coordinate] >= s.stopper - TOUCH_GAP && qd[s.coordinate] >= -REST_SPEED)
        })
    });
    (tips, legs)
}

/// The options of a tip, in rank order: what it is, then its changes.
fn tip_options(now: Tip, touches: bool) -> Vec<Tip> {
    match (now, touches) {
        (Tip::Stuck, _) => vec![Tip::Stuck, Tip::Free, Tip::Sliding],
        (Tip::Sliding, _) => vec![Tip::Sliding, Tip::Free],
        (Tip::Free, true) => vec![Tip::Free, Tip::Stuck, Tip::Sliding],
        (Tip::Free, false) => vec![Tip::Free],
    }
}

/// The options of a leg's stopper, in rank order.
fn stopper_options(held: bool, touches: bool) -> Vec<bool> {
    match (held, touches) {
        (true, _) => vec![true, false],
        (false, true) => vec![false, true],
        (false, false) => vec![false],
    }
}

/// Every choice of modes with the sum of its units' ranks, fewest changes first.
fn candidates(modes: &Modes, (tips, legs): ([bool; 2], [bool; 2])) -> Vec<(usize, Modes)> {
    let t = [0, 1].map(|i| tip_options(modes.tips[i], tips[i]));
    let s = [0, 1].map(|i| stopper_options(modes.held[i], legs[i]));
    let mut all = Vec::new();
    for (r0, &t0) in t[0].iter().enumerate() {
        for (r1, &t1) in t[1].iter().enumerate() {
            for (r2, &h0) in s[0].iter().enumerate() {
                for (r3, &h1) in s[1].iter().enumerate() {
                    let choice = Modes {
                        tips: [t0, t1],
                        held: [h0, h1],
                    };
                    all.push((r0 + r1 + r2 + r3, choice));
                }
            }
        }
    }
    // Stable: equal ranks keep the enumeration's order.
    all.sort_by_key(|(rank, _)| *rank);
    all
}

/// Is `solved` (the modes `modes`) consistent at `(q, q')`, for the units that touch (see the module
/// documentation)?
fn consistent<W: Legged<N>, const N: usize>(
    walker: &W,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    modes: &Modes,
    solved: &Solved<N>,
) -> bool {
    let c = walker.constants_f64();
    let strokes: [Option<Stroke>; 2] = walker.strokes();
    let tips_ok = (0..2).all(|i| match modes.tips[i] {
        Tip::Stuck | Tip::Sliding => solved.forces.normal[i].is_some_and(|f| f >= 0.0),
        Tip::Free => {
            let p = walker.contact(&c, q, qd, i);
            let at_ground = p.position.y <= TOUCH_GAP && p.velocity(qd).y <= REST_SPEED;
            let accel = (p.jacobian * solved.qdd + p.velocity_product).y;
            !at_ground || accel >= -FORCE_TOL
        }
    });
    let legs_ok = (0..2).all(|i| match (modes.held[i], strokes[i]) {
        (true, _) => solved.forces.holding[i].is_some_and(|f| f >= 0.0),
        (false, Some(s)) => {
            let at_stopper =
                q[s.coordinate] >= s.stopper - TOUCH_GAP && qd[s.coordinate] >= -REST_SPEED;
            !at_stopper || solved.qdd[s.coordinate] <= FORCE_TOL
        }
        (false, None) => true,
    });
    tips_ok && legs_ok
}

/// The consistent modes nearest to `modes` at `(q, q')` (see the module documentation), with their solve;
/// `None` where no choice is consistent.
pub fn choose<W: Legged<N>, const N: usize>(
    walker: &W,
    state: (&SVector<f64, N>, &SVector<f64, N>),
    modes: &Modes,
) -> Result<Option<(Modes, Solved<N>)>, ConstrainedError> {
    let touch = touching(walker, state, modes);
    for (_, choice) in candidates(modes, touch) {
        let solved = match solve(walker, state, &choice) {
            Ok(solved) => solved,
            // Redundant rows (both tips stuck with both legs held on a rigid mechanism): not this choice.
            Err(ConstrainedError::RedundantRows) => continue,
            Err(e) => return Err(e),
        };
        if consistent(walker, state, &choice, &solved) {
            return Ok(Some((choice, solved)));
        }
    }
    Ok(None)
}
