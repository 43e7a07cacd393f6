//! The interface a planar walker gives the engine (docs/model.md section 13): named generalized coordinates, the
//! equations of motion `M(q) q'' + h(q, q') = J^T lambda` of Eq. (1) over any [`Real`] (so that the exact
//! derivatives differentiate the very equations a walk integrates), the ground-contact points with their
//! Jacobians, and the energies the audit closes.
//!
//! The paper's procedure (Eqs. (1)-(9)) needs nothing else of a walker: the force-level problem of a phase and
//! the impulse problem of a touchdown are solved for any [`Mechanism`] by [`constrained`]. The wheel
//! ([`crate::dynamics::Model`]) is one mechanism (`wheel.rs`, where its own reduced solver is checked against the
//! general one); the compass-gait biped of Goswami, Thuilot and Espiau ([`compass`]) is another, assembled from
//! point masses by [`assembly`].
//!
//! Walkers with rigid legs and point feet walk by [`rigid`] (single support between heel strikes) and have their
//! gaits by [`rigid_gait`]: the compass gait and the simplest walking model of Garcia et al. ([`simplest`]),
//! whose massless legs leave it only reduced equations. Their step maps have exact derivatives
//! ([`rigid_derivative`], checked against differences by [`derivative_check`]) from a replay of the walk's own steps
//! that knows only phases, guards and resets ([`sensitivity`]), and their families are followed by
//! [`rigid_family`]. Walkers with compliant legs walk by [`legged`]: the paper's whole procedure (phases chosen
//! by force-level complementarity, every impact an impulse-level complementarity problem, the DLS indicators at
//! a heel strike, stoppers with their Zeno rule) for any mechanism whose two legs take turns, as the compass
//! gait with the paper's telescopic legs ([`telescopic`]) does. The wheel still walks through `walk/`; the walks
//! are to become one on this interface
//! (docs/model.md section 13).

pub mod assembly;
pub mod compass;
pub mod constrained;
pub mod derivative_check;
pub mod described;
pub mod legged;
pub mod rigid;
pub mod rigid_derivative;
pub mod rigid_family;
pub mod rigid_gait;
pub mod sensitivity;
pub mod simplest;
pub mod telescopic;
pub mod turns;
mod wheel;

use nalgebra::{SMatrix, SVector};

pub use crate::dynamics::{PointKinematics, Real};

/// `M(q)` and `h(q, q')` at one state: Eq. (1) reads `M q'' + h = J^T lambda`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Equations<T: Real, const N: usize> {
    /// The mass matrix (symmetric, positive definite for an assembled mechanism).
    pub mass: SMatrix<T, N, N>,
    /// The bias: Coriolis and centrifugal terms, gravity, springs and dampers.
    pub bias: SVector<T, N>,
}

/// A leg's role in a step of a walker whose legs take turns (docs/model.md section 13): the fore (stance) leg,
/// whose tip is contact point 0, and the rear leg (contact point 1), which lands ahead as the next fore leg
/// once it has left the ground and swung. The contact layer, the walk and its derivatives name a leg by its
/// role; which coordinates are its stroke and its tip is the walker's (the wheel's Leg 1 and Leg 2 of
/// docs/model.md section 1 are the fore and rear roles).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Role {
    /// The fore (stance) leg: contact point 0.
    Fore,
    /// The rear leg: contact point 1.
    Rear,
}

impl Role {
    /// Both roles, the fore leg first.
    pub const BOTH: [Role; 2] = [Role::Fore, Role::Rear];

    /// The role's contact point (`0` fore, `1` rear), and its place in per-role arrays.
    pub fn index(self) -> usize {
        match self {
            Role::Fore => 0,
            Role::Rear => 1,
        }
    }
}

/// A planar walker with `N` generalized coordinates, as the engine sees it.
///
/// The constants of its equations (masses, lengths, stiffnesses, the slope and gravity) are a
/// [`Mechanism::Constants`] over any [`Real`]: `f64` for a walk, or with one of them a dual number carrying
/// `d/dp` for the exact `dP/dp` (docs/model.md section 10).
pub trait Mechanism<const N: usize> {
    /// The constants the equations use, over a [`Real`].
    type Constants<T: Real>: Copy;

    /// The walker's name, as a configuration names it (`model = "compass"`).
    fn name(&self) -> &'static str;

    /// The names of the generalized coordinates, in the order of `q` (the columns of the outputs).
    fn coordinates(&self) -> [&'static str; N];

    /// The constants, each made a `T` by `value(key, value)` (the key as in a configuration file).
    fn constants<T: Real>(&self, value: &dyn Fn(&'static str, f64) -> T) -> Self::Constants<T>;

    /// The constants as `f64`.
    fn constants_f64(&self) -> Self::Constants<f64> {
        self.constants(&|_, v| v)
    }

    /// `M(q)` and `h(q, q')` (Eq. (1)) with the constants `c`.
    fn equations<T: Real>(
        &self,
        c: &Self::Constants<T>,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
    ) -> Equations<T, N>;

    /// Number of ground-contact points (feet, or tips of legs).
    fn contact_points(&self) -> usize;

    /// Position, Jacobian and `dJ/dt q'` of contact point `i` (`0..contact_points()`), in the slope frame
    /// (`x` down the slope, `z` normal to it: a contact's tangential row is `x`, its normal row `z`).
    fn contact<T: Real>(
        &self,
        c: &Self::Constants<T>,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        i: usize,
    ) -> PointKinematics<T, N>;

    /// Potential energy \[J\]: gravity and springs.
    fn potential_energy(&self, q: &SVector<f64, N>) -> f64;

    /// The power the dampers take out of the motion (at least 0) \[W\]: with the impacts' losses, what the energy
    /// audit of a step adds to the change of `T + V`.
    fn damper_power(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64;

    /// Kinetic energy `1/2 q'^T M q'` \[J\].
    fn kinetic_energy(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64 {
        let e = self.equations(&self.constants_f64(), q, qd);
        0.5 * qd.dot(&(e.mass * qd))
    }

    /// Total mechanical energy `T + V` \[J\].
    fn energy(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64 {
        self.kinetic_energy(q, qd) + self.potential_energy(q)
    }
}

#[cfg(test)]
mod derivative_tests;
#[cfg(test)]
mod tests;
