//! A described biped with two telescopic legs walks by the compliant walk (docs/model.md section 13,
//! [`crate::mechanism::legged`]): the paper's procedure, phases chosen by force-level complementarity, every
//! impact an impulse-level complementarity problem, the DLS indicators at a heel strike, the legs' strokes held
//! at their stoppers as the wheel's legs are.
//!
//! From its `[gait]` table: contact point 0 is the stance (fore) leg's tip and 1 the landing (rear) leg's (the
//! check puts them first), the strokes are the legs' lengths with their upper stoppers, the hip's body gives
//! the hip's height and the walker's progress (its velocity down the slope), and a heel strike relabels the
//! coordinates and slides the walker so that the new fore tip is at `x = 0`, as a rigid biped's
//! ([`crate::mechanism::turns::exchanged`]). The section is the heel strike after the relabeling and before its
//! impact: the fore leg at its stopper with its tip at the origin, the rear tip at rest on the ground
//! ([`Described::section_state`]). The springs' energy and the dampers' power, which the walk's audit closes,
//! are the description's ([`Mechanism::potential_energy`], [`Mechanism::damper_power`]).

use nalgebra::{DVector, SVector};

use super::super::legged::{Legged, Stroke};
use super::super::turns;
use super::super::Mechanism;
use super::Described;

impl<const N: usize> Legged<N> for Described<N> {
    fn strokes(&self) -> [Option<Stroke>; 2] {
        match &self.gait().strokes {
            Some(strokes) => strokes.each_ref().map(|s| {
                Some(Stroke {
                    coordinate: s.coordinate,
                    stopper: s.stopper.eval(&self.values),
                })
            }),
            None => [None, None],
        }
    }

    /// The height of the hip's body's frame.
    fn hip_height(&self, q: &SVector<f64, N>) -> f64 {
        self.hip(q, &SVector::zeros()).position.y
    }

    /// The velocity of the hip's body's frame down the slope.
    fn progress(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64 {
        (self.hip(q, qd).jacobian * qd).x
    }

    fn relabel(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
    ) -> (SVector<f64, N>, SVector<f64, N>) {
        let t = self.turns();
        let q_after = turns::exchanged(self, &t, &self.constants_f64(), (q, qd));
        (q_after, t.relabeled(qd))
    }

    fn section_names(&self) -> Vec<&'static str> {
        self.gait().section_names.clone()
    }

    fn section_of(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> DVector<f64> {
        DVector::from_vec(self.section_values(q, qd))
    }

    /// [`Described::section_state`]; `None` where the contact conditions have no solution.
    fn state_at_section(&self, s: &DVector<f64>) -> Option<(SVector<f64, N>, SVector<f64, N>)> {
        self.section_state(s).ok()
    }
}

/// Calls `$body` with `$w` bound to the [`Described`] inside an [`super::AnyDescribed`] that can walk by the
/// compliant walk (`4..=MAX_COORDINATES` coordinates: the section's conditions fix four positions), with the
/// constants `$n`, its number of coordinates, and `$y = 2 $n + 1`, the walk's state (`q`, `q'` and the dampers'
/// work); else `$other`.
#[macro_export]
macro_rules! with_legged_described {
    ($any:expr, $w:ident, $n:ident, $y:ident => $body:expr, _ => $other:expr) => {{
        use $crate::mechanism::described::AnyDescribed as A;
        match $any {
            A::N4($w) => {
                const $n: usize = 4;
                const $y: usize = 9;
                $body
            }
            A::N5($w) => {
                const $n: usize = 5;
                const $y: usize = 11;
                $body
            }
            A::N6($w) => {
                const $n: usize = 6;
                const $y: usize = 13;
                $body
            }
            A::N7($w) => {
                const $n: usize = 7;
                const $y: usize = 15;
                $body
            }
            A::N8($w) => {
                const $n: usize = 8;
                const $y: usize = 17;
                $body
            }
            A::N1(_) | A::N2(_) | A::N3(_) => $other,
        }
    }};
}
