//! How a biped with rigid legs and point feet takes turns (docs/model.md section 13), for any [`Mechanism`]:
//! single support with the stance contact held ([`super::constrained::accelerations`]), the swing foot's place,
//! and the heel strike — the impact with both feet held for the DLS indicator `lambda_I4`, the traditional
//! impact with the landing foot held ([`super::constrained::impulse`]), then the relabeling of the coordinates
//! that exchanges the legs' roles and the slide that puts the new stance foot at `x = 0`. The built-in compass
//! gait and the described bipeds walk through these functions alike.

use nalgebra::SVector;

use super::constrained::{accelerations, impulse, ConstrainedError, Row};
use super::rigid::HeelStrike;
use super::Mechanism;

/// Which contact stands, which lands, and how the coordinates are relabeled at a heel strike.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turns<const N: usize> {
    /// The stance contact (held in single support).
    pub stance: usize,
    /// The contact that strikes the ground ahead.
    pub lands: usize,
    /// After a heel strike, coordinate `i` takes the value coordinate `relabel[i]` had (a permutation).
    pub relabel: [usize; N],
    /// The coordinate that slides the walker along the slope, and the `x` it moves per unit: after the
    /// relabeling it is moved so that the new stance contact is at `x = 0`.
    pub shift: Option<(usize, f64)>,
}

impl<const N: usize> Turns<N> {
    /// `v` relabeled: `out[i] = v[relabel[i]]`.
    pub fn relabeled(&self, v: &SVector<f64, N>) -> SVector<f64, N> {
        SVector::from_fn(|i, _| v[self.relabel[i]])
    }
}

/// `q''` in single support (the stance contact's two rows held) and the stance contact's normal force.
pub fn single_support<M: Mechanism<N>, const N: usize>(
    walker: &M,
    turns: &Turns<N>,
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
) -> Result<(SVector<f64, N>, f64), ConstrainedError> {
    let a = accelerations(walker, q, qd, &Row::contact(turns.stance))?;
    Ok((a.qdd, a.multipliers[1]))
}

/// The landing contact's height above the ground and its distance ahead of the stance contact along the slope.
pub fn swing_foot<M: Mechanism<N>, const N: usize>(
    walker: &M,
    turns: &Turns<N>,
    q: &SVector<f64, N>,
) -> (f64, f64) {
    let c = walker.constants_f64();
    let zero = SVector::zeros();
    let (stance, swing) = (
        walker.contact(&c, q, &zero, turns.stance).position,
        walker.contact(&c, q, &zero, turns.lands).position,
    );
    (swing.y, swing.x - stance.x)
}

/// The heel strike at `(q, q'-)` (see the module documentation): `lambda_I4` is the stance contact's normal
/// impulse with both contacts held; where it is negative, the traditional impact, in the new roles.
pub fn heel_strike<M: Mechanism<N>, const N: usize>(
    walker: &M,
    turns: &Turns<N>,
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
) -> Result<HeelStrike<N>, ConstrainedError> {
    let both = [Row::contact(turns.stance), Row::contact(turns.lands)].concat();
    let lambda_i4 = impulse(walker, q, qd, &both)?.impulses[1];
    let traditional = impulse(walker, q, qd, &Row::contact(turns.lands))?.qd_plus;
    let loss = walker.energy(q, qd) - walker.energy(q, &traditional);
    let mut after = turns.relabeled(q);
    if let Some((k, per_unit)) = turns.shift {
        let new_foot = walker
            .contact(&walker.constants_f64(), q, qd, turns.lands)
            .position
            .x;
        after[k] -= new_foot / per_unit;
    }
    Ok(HeelStrike {
        lambda_i4,
        q: after,
        qd: (lambda_i4 < 0.0).then(|| turns.relabeled(&traditional)),
        loss,
    })
}
