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

use super::super::legged::derivative::{
    replayed_step_map, LeggedDerivative, LeggedDerivativeError, LeggedDerivatives,
};
use super::super::legged::walk::LeggedOptions;
use super::super::legged::{Legged, Stroke};
use super::super::turns;
use super::super::{Mechanism, Real};
use super::kinematics::Values;
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

/// The exact derivatives of a described compliant walker's step map, for each number of coordinates `$n` it can
/// have: the walk's state `$y = 2 $n + 1`, the replay's `$z = 2 $n`, the section's `2 $n - 7` values (`$n - 4`
/// coordinates, `$n - 3` rates) and the parameter's direction `$d = 2 $n - 6`, `$e = $d + 1`, `$a = $z + $z $d`
/// ([`replayed_step_map`]).
macro_rules! legged_derivatives {
    ($($n:literal => $y:literal, $z:literal, $d:literal, $e:literal, $a:literal);*) => {$(
        impl LeggedDerivatives<$n> for Described<$n> {
            /// The stopper's expression over the constants.
            fn stopper_with<T: Real>(&self, c: &Values<T>, leg: usize) -> T {
                match &self.gait().strokes {
                    Some(strokes) => c.of(&strokes[leg].stopper),
                    None => T::lit(f64::NAN),
                }
            }

            fn relabel_with<T: Real>(
                &self,
                c: &Values<T>,
                q: &SVector<T, $n>,
                qd: &SVector<T, $n>,
            ) -> (SVector<T, $n>, SVector<T, $n>) {
                let t = self.turns_with(c);
                (turns::exchanged(self, &t, c, (q, qd)), t.relabeled(qd))
            }

            fn section_with<T: Real>(&self, q: &SVector<T, $n>, qd: &SVector<T, $n>) -> Vec<T> {
                self.section_values(q, qd)
            }

            /// [`Described::section_state_with`]: the contact conditions differentiated implicitly; `None`
            /// where they have no solution.
            fn state_at_section_with<T: Real>(
                &self,
                c: &Values<T>,
                s: &[T],
            ) -> Option<(SVector<T, $n>, SVector<T, $n>)> {
                let (q, qd) = self.section_state_with(c, s);
                q.iter().chain(qd.iter()).all(|v| !v.value().is_nan()).then_some((q, qd))
            }

            fn exact_step_map(
                &self,
                x: &DVector<f64>,
                param: Option<&str>,
                options: &LeggedOptions,
            ) -> Result<LeggedDerivative<$n>, LeggedDerivativeError> {
                replayed_step_map::<_, $n, $y, $z, $d, $e, $a>(self, x, param, options)
            }
        }
    )*};
}

legged_derivatives!(
    4 => 9, 8, 2, 3, 24;
    5 => 11, 10, 4, 5, 50;
    6 => 13, 12, 6, 7, 84;
    7 => 15, 14, 8, 9, 126;
    8 => 17, 16, 10, 11, 176
);
