//! How a biped with rigid legs and point feet takes turns (docs/model.md section 13), for any [`Mechanism`]:
//! single support with the stance contact held ([`super::constrained::accelerations_with`]), the swing foot's place,
//! and the heel strike — the impact with both feet held for the DLS indicator `lambda_I4`, the traditional
//! impact with the landing foot held ([`super::constrained::impulse_with`]), then the relabeling of the coordinates
//! that exchanges the legs' roles and the slide that puts the new stance foot at `x = 0`. The built-in compass
//! gait and the described bipeds walk through these functions alike; they are written over any [`Real`] with the
//! walker's constants, so that the walk runs them on `f64` and its exact derivatives
//! (`super::rigid_derivative`) on dual numbers.

use nalgebra::SVector;

use super::constrained::{accelerations_with, impulse_with, ConstrainedError, Row};
use super::rigid::{HeelStrike, Transition};
use super::{Mechanism, Real};

/// Which contact stands, which lands, and how the coordinates are relabeled at a heel strike; `T` the scalar of
/// the slide's rate (a dual number where it depends on a parameter being differentiated in).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turns<const N: usize, T = f64> {
    /// The stance contact (held in single support).
    pub stance: usize,
    /// The contact that strikes the ground ahead.
    pub lands: usize,
    /// After a heel strike, coordinate `i` takes the value coordinate `relabel[i]` had (a permutation).
    pub relabel: [usize; N],
    /// The coordinate that slides the walker along the slope, and the `x` it moves per unit: after the
    /// relabeling it is moved so that the new stance contact is at `x = 0`.
    pub shift: Option<(usize, T)>,
}

impl<const N: usize, T: Real> Turns<N, T> {
    /// `v` relabeled: `out[i] = v[relabel[i]]`.
    pub fn relabeled<S: Real>(&self, v: &SVector<S, N>) -> SVector<S, N> {
        SVector::from_fn(|i, _| v[self.relabel[i]])
    }

    /// `v` in the old roles: the inverse of [`Turns::relabeled`], `out[relabel[i]] = v[i]`.
    pub fn unrelabeled<S: Real>(&self, v: &SVector<S, N>) -> SVector<S, N> {
        let mut out = *v;
        for (i, &k) in self.relabel.iter().enumerate() {
            out[k] = v[i];
        }
        out
    }
}

impl<const N: usize> Turns<N> {
    /// The same turns with the slide's rate a `T` (a constant: no derivative).
    pub fn lit<T: Real>(&self) -> Turns<N, T> {
        Turns {
            stance: self.stance,
            lands: self.lands,
            relabel: self.relabel,
            shift: self.shift.map(|(k, per_unit)| (k, T::lit(per_unit))),
        }
    }
}

/// `q''` in single support (the stance contact's two rows held) and the stance contact's normal force, with the
/// constants `c`.
pub fn single_support<T: Real, M: Mechanism<N>, const N: usize>(
    walker: &M,
    turns: &Turns<N, T>,
    c: &M::Constants<T>,
    (q, qd): (&SVector<T, N>, &SVector<T, N>),
) -> Result<(SVector<T, N>, T), ConstrainedError> {
    let a = accelerations_with(walker, c, (q, qd), &Row::contact(turns.stance))?;
    Ok((a.qdd, a.multipliers[1]))
}

/// The landing contact's height above the ground and its distance ahead of the stance contact along the slope,
/// with the constants `c`.
pub fn swing_foot<T: Real, M: Mechanism<N>, const N: usize>(
    walker: &M,
    turns: &Turns<N, T>,
    c: &M::Constants<T>,
    q: &SVector<T, N>,
) -> (T, T) {
    let zero = SVector::zeros();
    let (stance, swing) = (
        walker.contact(c, q, &zero, turns.stance).position,
        walker.contact(c, q, &zero, turns.lands).position,
    );
    (swing.y, swing.x - stance.x)
}

/// The heel strike's transition at `(q, q'-)` with the constants `c`: `lambda_I4`, the stance contact's normal
/// impulse with both contacts held, and the traditional impact (the landing contact held), in the new roles
/// (relabeled, slid so that the new stance contact is at `x = 0`), whatever the sign of `lambda_I4`.
pub fn transition<T: Real, M: Mechanism<N>, const N: usize>(
    walker: &M,
    turns: &Turns<N, T>,
    c: &M::Constants<T>,
    (q, qd): (&SVector<T, N>, &SVector<T, N>),
) -> Result<Transition<N, T>, ConstrainedError> {
    let both = [Row::contact(turns.stance), Row::contact(turns.lands)].concat();
    let lambda_i4 = impulse_with(walker, c, (q, qd), &both)?.impulses[1];
    let traditional = impulse_with(walker, c, (q, qd), &Row::contact(turns.lands))?.qd_plus;
    Ok(Transition {
        lambda_i4,
        q: exchanged(walker, turns, c, (q, qd)),
        qd: turns.relabeled(&traditional),
    })
}

/// The positions at a heel strike `(q, q')` in the new roles, with the constants `c`: relabeled, and slid so
/// that the landing contact, the new stance contact, is at `x = 0`.
pub fn exchanged<T: Real, M: Mechanism<N>, const N: usize>(
    walker: &M,
    turns: &Turns<N, T>,
    c: &M::Constants<T>,
    (q, qd): (&SVector<T, N>, &SVector<T, N>),
) -> SVector<T, N> {
    let mut after = turns.relabeled(q);
    if let Some((k, per_unit)) = turns.shift {
        let new_foot = walker.contact(c, q, qd, turns.lands).position.x;
        after[k] -= new_foot / per_unit;
    }
    after
}

/// The heel strike at `(q, q'-)` (see the module documentation): the [`transition`] on `f64`, the walker
/// stopping in double support where `lambda_I4 >= 0`, and the energy the traditional impact takes.
pub fn heel_strike<M: Mechanism<N>, const N: usize>(
    walker: &M,
    turns: &Turns<N>,
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
) -> Result<HeelStrike<N>, ConstrainedError> {
    let t = transition(walker, turns, &walker.constants_f64(), (q, qd))?;
    // The velocities after the impact in the old roles, where the energy before is measured.
    let loss = walker.energy(q, qd) - walker.energy(q, &turns.unrelabeled(&t.qd));
    Ok(HeelStrike {
        lambda_i4: t.lambda_i4,
        q: t.q,
        qd: (t.lambda_i4 < 0.0).then_some(t.qd),
        loss,
    })
}
