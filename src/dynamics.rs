//! Equations of motion of the viscoelastic-legged rimless wheel (docs/model.md sections 1-2, paper Eq. (1)).
//!
//! The wheel is described by `q = [x, z, theta, L1, L2, L3]` in the slope frame (`x` down the slope, `z` normal
//! to it). `(x, z)` is the tip of Leg 1, `theta` the angle of Leg 1 from the slope normal, `L1`, `L2` the lengths
//! of Leg 1 and Leg 2, and `L3` the length of the swinging leg (the old Leg 2 after it left Legs 1 and 2 unlocked,
//! under `rear_exit = "continue"`; 0 when no leg swings, see [`L3`]). Every body is a point mass (the hub, and
//! one sliding mass per leg at distance `a` from the tip) plus the hub's rotational inertia, so the equations
//! are assembled from point kinematics:
//!
//! ```text
//! M(q)    = sum_i m_i J_i^T J_i + IH e_theta e_theta^T
//! h(q,q') = sum_i m_i J_i^T (dJ_i/dt q' + g_n) + dV_spring/dq + damping
//! ```
//!
//! with `J_i = dp_i/dq` and `g_n = g (-sin phi, cos phi)` (minus the gravity vector). This is exactly Lagrange's
//! equations for the energies of docs/model.md section 2 (the tests check it against finite differences of `T` and
//! `V`).

use std::ops::Neg;

use nalgebra::{
    ClosedAddAssign, ClosedDivAssign, ClosedMulAssign, ClosedSubAssign, SMatrix, SVector, Vector2,
};
use num_traits::{One, Zero};

use crate::params::{ConfigError, Params};

mod dual;
mod force;

pub(crate) use dual::Dual;

/// A real scalar the kinematics and the equations of motion are written for: `f64` for the walk, and the dual
/// numbers (`Dual`, of the wheel's [`crate::variational`] and the rigid walkers' derivatives) that carry
/// derivatives through the very same code (forward-mode automatic differentiation, docs/model.md section 10).
/// STYLE.md asks for concrete `f64`; this is the one exception, so that the exact derivatives differentiate the
/// equations the walk integrates rather than a copy of them.
///
/// The trait asks only for what the kinematics use (field arithmetic, the sine, cosine and arctangent, and the
/// value for a solver's pivot), so that a plain dual number (`Dual`) can implement it.
pub trait Real:
    nalgebra::Scalar
    + Copy
    + Zero
    + One
    + ClosedAddAssign
    + ClosedSubAssign
    + ClosedMulAssign
    + ClosedDivAssign
    + Neg<Output = Self>
{
    /// The constant `x` (exact: every `Real` holds an `f64`).
    fn lit(x: f64) -> Self;
    /// `sin(self)`.
    fn sin(self) -> Self;
    /// `cos(self)`.
    fn cos(self) -> Self;
    /// `(sin(self), cos(self))`.
    fn sin_cos(self) -> (Self, Self);
    /// `atan(self)`.
    fn atan(self) -> Self;
    /// The value without its derivatives (itself for `f64`): for the decisions a computation makes (a pivot's
    /// sign), never for its arithmetic.
    fn value(self) -> f64;
}

impl Real for f64 {
    fn lit(x: f64) -> f64 {
        x
    }
    fn sin(self) -> f64 {
        f64::sin(self)
    }
    fn cos(self) -> f64 {
        f64::cos(self)
    }
    fn sin_cos(self) -> (f64, f64) {
        f64::sin_cos(self)
    }
    fn atan(self) -> f64 {
        f64::atan(self)
    }
    fn value(self) -> f64 {
        self
    }
}

/// The constant `x` as a [`Real`].
pub(crate) fn lit<T: Real>(x: f64) -> T {
    T::lit(x)
}

/// Number of generalized coordinates.
pub(crate) const NQ: usize = 6;
/// Generalized coordinates or velocities `[x, z, theta, L1, L2, L3]`.
pub type Coords = SVector<f64, NQ>;
/// Generalized coordinates or velocities over any [`Real`].
pub(crate) type CoordsOf<T> = SVector<T, NQ>;
/// A matrix over the generalized coordinates (`M`).
pub(crate) type MatQ = SMatrix<f64, NQ, NQ>;
/// Jacobian of a planar point with respect to `q`.
pub(crate) type PointJacobian<T = f64> = SMatrix<T, 2, NQ>;

/// Index of `x` in `q`.
pub const X: usize = 0;
/// Index of `z` in `q`.
pub const Z: usize = 1;
/// Index of `theta` in `q`.
pub const THETA: usize = 2;
/// Index of `L1` (length of Leg 1) in `q`.
pub const L1: usize = 3;
/// Index of `L2` (length of Leg 2) in `q`.
pub const L2: usize = 4;
/// Index of `L3` in `q`: the length of the swinging leg, the old Leg 2 that left Legs 1 and 2 at the last
/// touchdown before its stopper locked it (`rear_exit = "continue"`, docs/model.md section 5). It is leg `j = 2`
/// until its stopper locks it, then a spoke again. `L3 = 0` (and `dL3/dt = 0`) when no leg swings: a leg's length
/// is positive, so 0 cannot be one, and the coordinate is then left out of the dynamics (its row of `M` is the
/// identity's, with no force) and of the integrator's error norm ([`PhaseSystem`](crate::walk::PhaseSystem)).
pub const L3: usize = 5;

/// Does `q` hold a swinging leg ([`L3`] nonzero)?
pub fn swinging<T: Real>(q: &CoordsOf<T>) -> bool {
    q[L3] != T::zero()
}

/// Position, Jacobian and velocity-product acceleration of one point of a mechanism with `N` coordinates (the
/// wheel's by default).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointKinematics<T: Real = f64, const N: usize = NQ> {
    /// Position in the slope frame \[m\].
    pub position: Vector2<T>,
    /// `J = dp/dq`.
    pub jacobian: SMatrix<T, 2, N>,
    /// `dJ/dt q'`: the acceleration of the point when `q'' = 0` \[m/s^2\].
    pub velocity_product: Vector2<T>,
}

impl<T: Real, const N: usize> PointKinematics<T, N> {
    /// Velocity `J q'` of the point \[m/s\].
    pub fn velocity(&self, qd: &SVector<T, N>) -> Vector2<T> {
        self.jacobian * qd
    }
}

/// Which leg of the wheel, counted from Leg 1 (`j = 0`) in the direction of Leg 2 (`j = 1`); the next leg to
/// touch down is `j = N - 1` (docs/model.md section 1: `psi_j = theta + j alpha`).
pub(crate) type LegIndex = usize;

/// `M`, `h` and the tip of Leg 2 at one state, from [`Model::equations_of_motion`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct EquationsOfMotion<T: Real = f64> {
    /// Mass matrix `M(q)`.
    pub mass: SMatrix<T, NQ, NQ>,
    /// Bias vector `h(q, q')`: Coriolis/centrifugal terms, gravity, springs and dampers.
    pub bias: CoordsOf<T>,
    /// Kinematics of the tip of Leg 2 (the rows of (C2)), as [`Model::tip`] gives them.
    pub rear_tip: PointKinematics<T>,
    /// Does a leg swing ([`L3`] a coordinate)? If not, `L3`'s row of `mass` is the identity's and of `bias` 0.
    pub swing: bool,
}

/// The physical constants the equations of motion use, as [`Real`]s: the [`Params`] values (as `f64` for the
/// walk, or with one of them carrying a derivative, see `Mechanics::seeded`) and the gravity vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mechanics<T: Real = f64> {
    /// `mH` \[kg\].
    pub hub_mass: T,
    /// `IH` \[kg m^2\].
    pub hub_inertia: T,
    /// `m` \[kg\].
    pub leg_mass: T,
    /// `a` \[m\].
    pub leg_mass_offset: T,
    /// `L0` \[m\].
    pub stopper_length: T,
    /// The length of the legs other than Legs 1 and 2, at which a leg touches down
    /// ([`Params::spoke_length`]: `touchdown_length`, or `L0`) \[m\].
    pub spoke_length: T,
    /// `Lstar` \[m\].
    pub spring_natural_length: T,
    /// `k` \[N/m\].
    pub stiffness: T,
    /// `c` \[N s/m\].
    pub viscosity: T,
    /// `mu`, the Coulomb friction coefficient at the tips (infinite: no slip; only a slipping contact reads it).
    pub friction: T,
    /// `g (-sin phi, cos phi)`: the negative of the gravity vector in the slope frame \[m/s^2\].
    pub up: Vector2<T>,
}

/// The numeric keys of [`Params`] the equations of motion depend on smoothly: the parameters `dP/dp` can be
/// taken for (`gait::StepMap::eval_with_derivatives`, `vrw gait --parameter`).
pub const DIFFERENTIABLE_KEYS: [&str; 11] = [
    "hub_mass",
    "hub_inertia",
    "leg_mass",
    "leg_mass_offset",
    "stopper_length",
    "spring_natural_length",
    "stiffness",
    "viscosity",
    "slope",
    "gravity",
    // Only a slipping tip's force depends on it: `dP/dfriction` is 0 where no tip slips (friction infinite).
    "friction",
];

impl<T: Real> Mechanics<T> {
    /// The constants of `params`, each made a `T` by `value(key, value)` (the key as in a configuration file).
    pub(crate) fn seeded(params: &Params, value: impl Fn(&'static str, f64) -> T) -> Mechanics<T> {
        let (slope, gravity) = (
            value("slope", params.slope),
            value("gravity", params.gravity),
        );
        Mechanics {
            hub_mass: value("hub_mass", params.hub_mass),
            hub_inertia: value("hub_inertia", params.hub_inertia),
            leg_mass: value("leg_mass", params.leg_mass),
            leg_mass_offset: value("leg_mass_offset", params.leg_mass_offset),
            stopper_length: value("stopper_length", params.stopper_length),
            // At its default the touchdown length is the stopper length, and its derivative is that key's.
            spoke_length: if params.touchdown_length == 0.0 {
                value("stopper_length", params.stopper_length)
            } else {
                value("touchdown_length", params.touchdown_length)
            },
            spring_natural_length: value("spring_natural_length", params.spring_natural_length),
            stiffness: value("stiffness", params.stiffness),
            viscosity: value("viscosity", params.viscosity),
            friction: value("friction", params.friction),
            up: Vector2::new(-slope.sin(), slope.cos()) * gravity,
        }
    }
}

/// Sums over point masses `m_i` with Jacobian columns `b_i = [b_theta, b_L1, b_L2(, b_L3)]` (the `x`, `z`
/// columns being the identity) and forces `f_i = m_i (dJ_i/dt q' + g_n)`, from which `M` and `h` are assembled:
/// `C = 3` columns when no leg swings, `C = 4` (with `L3`) when one does. A constant, so that the loops over the
/// columns unroll (the right-hand side spends much of its time here).
#[derive(Debug)]
struct PointSums<T: Real, const C: usize> {
    /// `sum m_i`.
    mass: T,
    /// `sum m_i b_ik`.
    b: [Vector2<T>; C],
    /// `sum m_i b_ik . b_il` for `k <= l`.
    bb: [[T; C]; C],
    /// `sum f_i`.
    f: Vector2<T>,
    /// `sum b_ik . f_i`.
    bf: [T; C],
}

impl<T: Real, const C: usize> PointSums<T, C> {
    fn zero() -> Self {
        let (z, v) = (T::zero(), Vector2::zeros());
        PointSums {
            mass: z,
            b: [v; C],
            bb: [[z; C]; C],
            f: v,
            bf: [z; C],
        }
    }

    /// Add a point of mass `m`, Jacobian columns `b` and acceleration `a = dJ/dt q' + g_n`.
    fn add(&mut self, m: T, b: &[Vector2<T>; C], a: Vector2<T>) {
        let f = a * m;
        self.mass += m;
        self.f += f;
        for k in 0..C {
            self.b[k] += b[k] * m;
            self.bf[k] += b[k].dot(&f);
            for l in k..C {
                self.bb[k][l] += m * b[k].dot(&b[l]);
            }
        }
    }
}

/// The hub's kinematics at one state, which every point of the wheel shares ([`Model::equations_of_motion_with`],
/// [`Model::generalized_force_with`]): `C` length columns as for [`PointSums`].
struct Wheel<T: Real, const C: usize> {
    /// `sin theta`, `cos theta`.
    st: T,
    ct: T,
    /// `dtheta/dt`.
    w: T,
    /// The hub's Jacobian columns: `b_theta = (L1 c, -L1 s)`, `b_L1 = (s, c)`, the others 0.
    hub_b: [Vector2<T>; C],
    /// The hub's `dJ/dt q'`.
    hub_vp: Vector2<T>,
    /// The hub's position.
    hub_position: Vector2<T>,
    /// `e` and `e_psi` of Legs 1 and 2 ([`Wheel::directions`]).
    legs: [(Vector2<T>, Vector2<T>); 2],
}

impl<T: Real, const C: usize> Wheel<T, C> {
    /// The kinematics at `(q, q')`, with Legs 1 and 2 at the angular offsets `(sin j alpha, cos j alpha)` of
    /// `legs`.
    fn new(q: &CoordsOf<T>, qd: &CoordsOf<T>, legs: [(f64, f64); 2]) -> Self {
        let two = lit::<T>(2.0);
        let (st, ct) = q[THETA].sin_cos();
        let (l1, dl1, w) = (q[L1], qd[L1], qd[THETA]);
        let mut hub_b = [Vector2::zeros(); C];
        hub_b[0] = Vector2::new(l1 * ct, -l1 * st);
        hub_b[1] = Vector2::new(st, ct);
        let hub_vp = Vector2::new(
            two * dl1 * ct * w - l1 * st * w * w,
            -two * dl1 * st * w - l1 * ct * w * w,
        );
        Wheel {
            st,
            ct,
            w,
            hub_b,
            hub_vp,
            hub_position: Vector2::new(q[X] + l1 * st, q[Z] + l1 * ct),
            legs: legs.map(|offset| directions(st, ct, offset)),
        }
    }

    /// A point of a leg with directions `(e, e_psi)`, length and rate `(L, dL/dt)` and its length column `slot`
    /// of `b`, at distance `from_tip` from its tip: its Jacobian columns `b`, `dJ/dt q'` and position.
    fn point(
        &self,
        (e, e_psi): (Vector2<T>, Vector2<T>),
        (length, dlength): (T, T),
        slot: usize,
        from_tip: T,
    ) -> ([Vector2<T>; C], Vector2<T>, Vector2<T>) {
        let two = lit::<T>(2.0);
        let w = self.w;
        let d = length - from_tip;
        let mut b = self.hub_b;
        b[0] += e_psi * d;
        b[slot] += e;
        let vp = self.hub_vp + e_psi * (two * dlength * w) - e * (d * w * w);
        (b, vp, self.hub_position + e * d)
    }

    /// [`directions`] of the leg at the offset `(sin j alpha, cos j alpha)`.
    fn directions(&self, offset: (f64, f64)) -> (Vector2<T>, Vector2<T>) {
        directions(self.st, self.ct, offset)
    }

    /// Legs 1 and 2 and, while one swings, the swinging leg (`C = 4`), point by point with the constants `p`:
    /// `add(m, b, dJ/dt q' + g_n)` for each leg's point mass.
    #[inline(always)]
    fn each_leg_point(
        &self,
        p: &Mechanics<T>,
        (q, qd): (&CoordsOf<T>, &CoordsOf<T>),
        swinging: Option<(f64, f64)>,
        mut add: impl FnMut(T, &[Vector2<T>; C], Vector2<T>),
    ) {
        for (k, slot) in [(0, 1), (1, 2)] {
            let length = (q[THETA + slot], qd[THETA + slot]);
            let (b, vp, _) = self.point(self.legs[k], length, slot, p.leg_mass_offset);
            add(p.leg_mass, &b, vp + p.up);
        }
        if let Some(offset) = swinging {
            let directions = self.directions(offset);
            let (b, vp, _) = self.point(directions, (q[L3], qd[L3]), 3, p.leg_mass_offset);
            add(p.leg_mass, &b, vp + p.up);
        }
    }
}

/// `e(psi)` and `e_psi = de/dpsi` for `psi = theta + j alpha` given `(sin theta, cos theta)` and
/// `(sin j alpha, cos j alpha)`: `e = (-sin psi, -cos psi)`, `e_psi = (-cos psi, sin psi)`.
fn directions<T: Real>(st: T, ct: T, (sj, cj): (f64, f64)) -> (Vector2<T>, Vector2<T>) {
    let (sj, cj) = (lit::<T>(sj), lit::<T>(cj));
    let (sp, cp) = (st * cj + ct * sj, ct * cj - st * sj);
    (Vector2::new(-sp, -cp), Vector2::new(-cp, sp))
}

/// The springs and dampers of the legs' lengths, `-k (L0 - L) + c dL/dt`, added to the rows of `L1`, `L2` and,
/// while a leg swings, `L3` of `force`.
#[inline(always)]
fn add_leg_forces<T: Real>(
    p: &Mechanics<T>,
    (q, qd): (&CoordsOf<T>, &CoordsOf<T>),
    swing: bool,
    force: &mut CoordsOf<T>,
) {
    let lengths: &[usize] = if swing { &[L1, L2, L3] } else { &[L1, L2] };
    for &l in lengths {
        force[l] += -p.stiffness * (p.spring_natural_length - q[l]) + p.viscosity * qd[l];
    }
}

/// The locked legs' sums of [`Model::equations_of_motion_with`]: their number `n`, the distance `d = L0 - a`
/// of their masses from the hub, `sum_j e(psi_j)` and `sum_j e_psi(psi_j)`.
struct Locked<T: Real> {
    n: T,
    d: T,
    sum_e: Vector2<T>,
    sum_e_psi: Vector2<T>,
}

/// The validated model: parameters plus precomputed leg-angle offsets.
#[derive(Debug, Clone)]
pub struct Model {
    params: Params,
    alpha: f64,
    /// `(sin j alpha, cos j alpha)` for `j = 0..N`.
    offsets: Vec<(f64, f64)>,
    /// `sum_j (sin j alpha, cos j alpha)` over the locked legs `j = 2..N`.
    locked_offsets: (f64, f64),
    /// The physical constants as `f64`.
    mech: Mechanics,
}

impl Model {
    /// Validate the parameters and build the model.
    pub fn new(params: &Params) -> Result<Model, ConfigError> {
        params.validate()?;
        let alpha = params.alpha();
        let offsets: Vec<(f64, f64)> = (0..params.legs)
            .map(|j| {
                let a = j as f64 * alpha;
                (a.sin(), a.cos())
            })
            .collect();
        // The N-th roots of unity sum to zero, so the locked legs' sum is minus that of legs 0 and 1 (exact,
        // without the rounding of a sum over up to `MAX_LEGS` terms).
        let locked_offsets = (-alpha.sin(), -1.0 - alpha.cos());
        Ok(Model {
            params: params.clone(),
            alpha,
            offsets,
            locked_offsets,
            mech: Mechanics::seeded(params, |_, value| value),
        })
    }

    /// The parameters this model was built from.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The physical constants as `f64`.
    pub(crate) fn mechanics(&self) -> &Mechanics {
        &self.mech
    }

    /// Inter-leg angle `alpha = 2 pi / N` \[rad\].
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// Number of legs `N`.
    pub(crate) fn legs(&self) -> usize {
        self.offsets.len()
    }

    /// Index of the next leg to touch down (`j = -1`, i.e. `N - 1`).
    pub(crate) fn front_leg(&self) -> LegIndex {
        self.legs() - 1
    }

    /// Total mass `mH + N m` \[kg\].
    pub fn total_mass(&self) -> f64 {
        self.params.hub_mass + self.legs() as f64 * self.params.leg_mass
    }

    /// Length of leg `j`: `L1`, `L2` (and `L3` for `j = 2` while a leg swings) from `q`, the spoke length
    /// (`touchdown_length`, by default the stopper length `L0`) for the locked legs (docs/model.md section 2).
    fn leg_length<T: Real>(
        mech: &Mechanics<T>,
        q: &CoordsOf<T>,
        j: LegIndex,
    ) -> (T, Option<usize>) {
        match j {
            0 => (q[L1], Some(L1)),
            1 => (q[L2], Some(L2)),
            2 if swinging(q) => (q[L3], Some(L3)),
            _ => (mech.spoke_length, None),
        }
    }

    /// Hub kinematics: `p_H = (x + L1 sin theta, z + L1 cos theta)` (docs/model.md section 1).
    pub(crate) fn hub<T: Real>(&self, q: &CoordsOf<T>, qd: &CoordsOf<T>) -> PointKinematics<T> {
        let (s, c) = q[THETA].sin_cos();
        let (l1, dl1, w) = (q[L1], qd[L1], qd[THETA]);
        let two = lit::<T>(2.0);
        let mut jac = PointJacobian::<T>::zeros();
        jac[(0, X)] = T::one();
        jac[(1, Z)] = T::one();
        jac[(0, THETA)] = l1 * c;
        jac[(1, THETA)] = -l1 * s;
        jac[(0, L1)] = s;
        jac[(1, L1)] = c;
        PointKinematics {
            position: Vector2::new(q[X] + l1 * s, q[Z] + l1 * c),
            jacobian: jac,
            velocity_product: Vector2::new(
                two * dl1 * c * w - l1 * s * w * w,
                -two * dl1 * s * w - l1 * c * w * w,
            ),
        }
    }

    /// A point on leg `j` at distance `from_tip` from its tip, `p = p_H + (L_j - from_tip) e(psi_j)` with
    /// `e(psi) = (-sin psi, -cos psi)`, given the hub kinematics `hub` and the constants `mech`.
    pub(crate) fn leg_point_from_hub<T: Real>(
        &self,
        mech: &Mechanics<T>,
        hub: &PointKinematics<T>,
        (q, qd): (&CoordsOf<T>, &CoordsOf<T>),
        j: LegIndex,
        from_tip: T,
    ) -> PointKinematics<T> {
        let (sj, cj) = self.offsets[j];
        let (sj, cj) = (lit::<T>(sj), lit::<T>(cj));
        let (st, ct) = q[THETA].sin_cos();
        // psi = theta + j alpha
        let (sp, cp) = (st * cj + ct * sj, ct * cj - st * sj);
        let e = Vector2::new(-sp, -cp);
        let e_psi = Vector2::new(-cp, sp);
        let (length, length_index) = Self::leg_length(mech, q, j);
        let d = length - from_tip;
        let dd = length_index.map_or(T::zero(), |i| qd[i]);
        let w = qd[THETA];
        let mut jac = hub.jacobian;
        if let Some(i) = length_index {
            jac[(0, i)] += e.x;
            jac[(1, i)] += e.y;
        }
        jac[(0, THETA)] += d * e_psi.x;
        jac[(1, THETA)] += d * e_psi.y;
        PointKinematics {
            position: hub.position + e * d,
            jacobian: jac,
            velocity_product: hub.velocity_product + e_psi * (lit::<T>(2.0) * dd * w)
                - e * (d * w * w),
        }
    }

    /// The tip of leg `j`.
    pub fn tip(&self, q: &Coords, qd: &Coords, j: LegIndex) -> PointKinematics {
        self.tip_with(&self.mech, q, qd, j)
    }

    /// The tip of leg `j` over any [`Real`], with the constants `mech`.
    pub(crate) fn tip_with<T: Real>(
        &self,
        mech: &Mechanics<T>,
        q: &CoordsOf<T>,
        qd: &CoordsOf<T>,
        j: LegIndex,
    ) -> PointKinematics<T> {
        let hub = self.hub(q, qd);
        self.leg_point_from_hub(mech, &hub, (q, qd), j, T::zero())
    }

    /// Height of the hub above the slope, `z + L1 cos(theta)` \[m\].
    pub(crate) fn hub_height(&self, q: &Coords) -> f64 {
        q[Z] + q[L1] * q[THETA].cos()
    }

    /// Height of the tip of leg `j` above the slope \[m\] (no Jacobian; cheap, for event functions).
    pub fn tip_height(&self, q: &Coords, j: LegIndex) -> f64 {
        self.tip_height_with(&self.mech, q, j)
    }

    /// [`Model::tip_height`] over any [`Real`], with the constants `mech`.
    pub(crate) fn tip_height_with<T: Real>(
        &self,
        mech: &Mechanics<T>,
        q: &CoordsOf<T>,
        j: LegIndex,
    ) -> T {
        let (sj, cj) = self.offsets[j];
        let (st, ct) = q[THETA].sin_cos();
        let cp = ct * lit::<T>(cj) - st * lit::<T>(sj);
        let (length, _) = Self::leg_length(mech, q, j);
        q[Z] + q[L1] * ct - length * cp
    }

    /// Height of the lowest tip above the slope, over every leg \[m\]: the least [`Model::tip_height`], with one
    /// sine and cosine of `theta` for all legs (the penetration audit runs it several times per integrator step).
    pub(crate) fn lowest_tip_height(&self, q: &Coords) -> f64 {
        let (st, ct) = q[THETA].sin_cos();
        let hub_height = q[Z] + q[L1] * ct;
        self.offsets
            .iter()
            .enumerate()
            .map(|(j, &(sj, cj))| {
                hub_height - Self::leg_length(&self.mech, q, j).0 * (ct * cj - st * sj)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The locked legs' sums (every leg but Legs 1 and 2, and but the swinging leg while one `swing`s).
    fn locked<T: Real, const C: usize>(
        &self,
        wheel: &Wheel<T, C>,
        p: &Mechanics<T>,
        swing: bool,
    ) -> Locked<T> {
        let (mut locked, (mut ss, mut sc)) = (self.legs() - 2, self.locked_offsets);
        if swing {
            locked -= 1;
            (ss, sc) = (ss - self.offsets[2].0, sc - self.offsets[2].1);
        }
        let (st, ct) = (wheel.st, wheel.ct);
        let (ss, sc) = (lit::<T>(ss), lit::<T>(sc));
        let (sum_sin, sum_cos) = (st * sc + ct * ss, ct * sc - st * ss);
        Locked {
            n: lit::<T>(locked as f64),
            d: p.spoke_length - p.leg_mass_offset,
            sum_e: Vector2::new(-sum_sin, -sum_cos),
            sum_e_psi: Vector2::new(-sum_cos, sum_sin),
        }
    }

    /// The hub's kinematics at `(q, q')` with the directions of Legs 1 and 2.
    fn wheel<T: Real, const C: usize>(&self, q: &CoordsOf<T>, qd: &CoordsOf<T>) -> Wheel<T, C> {
        Wheel::new(q, qd, [self.offsets[0], self.offsets[1]])
    }

    /// The angular offset of the swinging leg while one swings (`C = 4`), for [`Wheel::each_leg_point`].
    fn swinging_offset<const C: usize>(&self) -> Option<(f64, f64)> {
        (C == 4).then(|| self.offsets[2])
    }

    /// The kinematics of Leg 2's tip (the rows of (C2)).
    fn rear_tip<T: Real, const C: usize>(
        &self,
        wheel: &Wheel<T, C>,
        q: &CoordsOf<T>,
        qd: &CoordsOf<T>,
    ) -> PointKinematics<T> {
        let (b, velocity_product, position) =
            wheel.point(wheel.legs[1], (q[L2], qd[L2]), 2, T::zero());
        let mut jacobian = PointJacobian::<T>::zeros();
        jacobian[(0, X)] = T::one();
        jacobian[(1, Z)] = T::one();
        for (k, column) in b.iter().enumerate() {
            jacobian.set_column(THETA + k, column);
        }
        PointKinematics {
            position,
            jacobian,
            velocity_product,
        }
    }

    /// Mass matrix `M(q)` and bias vector `h(q, q')` of Eq. (1): Coriolis/centrifugal terms, gravity, the leg
    /// springs `k (Lstar - L)` and dampers `c dL/dt` of Legs 1 and 2 (docs/model.md section 2).
    ///
    /// See [`Model::equations_of_motion`] for how they are assembled; [`Model::mass_and_bias_reference`] is the
    /// plain formula the tests compare against.
    pub(crate) fn mass_and_bias(&self, q: &Coords, qd: &Coords) -> (MatQ, Coords) {
        let eom = self.equations_of_motion(q, qd);
        (eom.mass, eom.bias)
    }

    /// `M(q)` and `h(q, q')` of Eq. (1) (as [`Model::mass_and_bias`]) together with the kinematics of Leg 2's tip,
    /// which share the sine and cosine of `theta` and the hub terms (docs/model.md sections 2-3).
    pub(crate) fn equations_of_motion(&self, q: &Coords, qd: &Coords) -> EquationsOfMotion {
        self.equations_of_motion_with(&self.mech, q, qd)
    }

    /// [`Model::equations_of_motion`] over any [`Real`], with the constants `mech`.
    ///
    /// Every point Jacobian has the form `J_i = [I_2 | b_theta | b_L1 | b_L2]` (the `x`, `z` columns are the
    /// identity), so `M = sum m_i J_i^T J_i` and `h = sum m_i J_i^T f_i` are accumulated from the three
    /// columns `b` only. The hub, Leg 1 and Leg 2 are added point by point. The `N - 2` locked legs are added in
    /// closed form: leg `j` has `b_theta = b_H + d e(psi_j)'`, `b_L1 = b_L1,H`, `b_L2 = 0` and
    /// `f = m (a_H + g_n - d w^2 e(psi_j))` with the same `d = L0 - a` for all, and `|e'|^2 = 1`,
    /// `e . e' = 0`, so their sums need only `sum_j e(psi_j)` (and `sum_j e(psi_j)' `), a rotation by `theta` of
    /// the constant `sum_j (sin j alpha, cos j alpha)`. The cost is independent of `N`.
    pub(crate) fn equations_of_motion_with<T: Real>(
        &self,
        mech: &Mechanics<T>,
        q: &CoordsOf<T>,
        qd: &CoordsOf<T>,
    ) -> EquationsOfMotion<T> {
        if swinging(q) {
            self.assemble::<T, 4>(mech, q, qd)
        } else {
            self.assemble::<T, 3>(mech, q, qd)
        }
    }

    /// [`Model::equations_of_motion_with`] with `C` length columns: 3 without a swinging leg, 4 with one.
    fn assemble<T: Real, const C: usize>(
        &self,
        mech: &Mechanics<T>,
        q: &CoordsOf<T>,
        qd: &CoordsOf<T>,
    ) -> EquationsOfMotion<T> {
        let swing = C == 4;
        let p = mech;
        let two = lit::<T>(2.0);
        let wheel = self.wheel::<T, C>(q, qd);
        let (hub_b, hub_vp, w) = (wheel.hub_b, wheel.hub_vp, wheel.w);
        let mut sums = PointSums::<T, C>::zero();
        sums.add(p.hub_mass, &hub_b, hub_vp + p.up);
        // Legs 1 and 2 and the swinging leg j = 2, point by point, and the locked legs: j = 2..N, or j = 3..N
        // while a leg swings, all of the spoke length (see above).
        wheel.each_leg_point(p, (q, qd), self.swinging_offset::<C>(), |m, b, a| {
            sums.add(m, b, a)
        });
        let Locked {
            n,
            d,
            sum_e,
            sum_e_psi,
        } = self.locked(&wheel, p, swing);
        let a = hub_vp + p.up;
        let m = p.leg_mass;
        sums.mass += n * m;
        sums.f += (a * n - sum_e * (d * w * w)) * m;
        sums.b[0] += (hub_b[0] * n + sum_e_psi * d) * m;
        sums.b[1] += hub_b[1] * (m * n);
        sums.bb[0][0] +=
            m * (n * hub_b[0].dot(&hub_b[0]) + two * d * hub_b[0].dot(&sum_e_psi) + n * d * d);
        sums.bb[0][1] += m * (n * hub_b[0].dot(&hub_b[1]) + d * hub_b[1].dot(&sum_e_psi));
        sums.bb[1][1] += m * n * hub_b[1].dot(&hub_b[1]);
        sums.bf[0] +=
            m * (n * hub_b[0].dot(&a) - d * w * w * hub_b[0].dot(&sum_e) + d * sum_e_psi.dot(&a));
        sums.bf[1] += m * (n * hub_b[1].dot(&a) - d * w * w * hub_b[1].dot(&sum_e));

        let mut mass = SMatrix::<T, NQ, NQ>::zeros();
        let mut bias = CoordsOf::<T>::zeros();
        mass[(X, X)] = sums.mass;
        mass[(Z, Z)] = sums.mass;
        bias[X] = sums.f.x;
        bias[Z] = sums.f.y;
        for k in 0..C {
            let c = THETA + k;
            mass[(X, c)] = sums.b[k].x;
            mass[(c, X)] = sums.b[k].x;
            mass[(Z, c)] = sums.b[k].y;
            mass[(c, Z)] = sums.b[k].y;
            bias[c] = sums.bf[k];
            for l in k..C {
                mass[(c, THETA + l)] = sums.bb[k][l];
                mass[(THETA + l, c)] = sums.bb[k][l];
            }
        }
        mass[(THETA, THETA)] += p.hub_inertia;
        add_leg_forces(p, (q, qd), swing, &mut bias);
        if !swing {
            // No leg swings: `L3` is left out, with the identity's row so that M stays regular and `L3'' = 0`.
            mass[(L3, L3)] = T::one();
        }

        EquationsOfMotion {
            mass,
            bias,
            rear_tip: self.rear_tip(&wheel, q, qd),
            swing,
        }
    }

    /// `M` and `h` by the plain point-mass formula `sum m_i J_i^T J_i`, `sum m_i J_i^T (dJ_i/dt q' + g_n)`:
    /// slower than [`Model::mass_and_bias`], kept as its reference.
    #[cfg(test)]
    pub(crate) fn mass_and_bias_reference(&self, q: &Coords, qd: &Coords) -> (MatQ, Coords) {
        let p = &self.params;
        let up = self.mech.up;
        let hub = self.hub(q, qd);
        let mut m = p.hub_mass * hub.jacobian.transpose() * hub.jacobian;
        let mut h = p.hub_mass * hub.jacobian.transpose() * (hub.velocity_product + up);
        m[(THETA, THETA)] += p.hub_inertia;
        for j in 0..self.legs() {
            let leg = self.leg_point_from_hub(&self.mech, &hub, (q, qd), j, p.leg_mass_offset);
            let jt = leg.jacobian.transpose();
            m += p.leg_mass * jt * leg.jacobian;
            h += p.leg_mass * jt * (leg.velocity_product + up);
        }
        h[L1] += -p.stiffness * (p.spring_natural_length - q[L1]) + p.viscosity * qd[L1];
        h[L2] += -p.stiffness * (p.spring_natural_length - q[L2]) + p.viscosity * qd[L2];
        if swinging(q) {
            h[L3] += -p.stiffness * (p.spring_natural_length - q[L3]) + p.viscosity * qd[L3];
        } else {
            m[(L3, L3)] = 1.0;
        }
        (m, h)
    }

    /// Mass matrix `M(q)` alone.
    pub(crate) fn mass_matrix(&self, q: &Coords) -> MatQ {
        self.mass_and_bias(q, &Coords::zeros()).0
    }

    /// Kinetic energy `T = 1/2 q'^T M q'` \[J\].
    pub(crate) fn kinetic_energy(&self, q: &Coords, qd: &Coords) -> f64 {
        0.5 * qd.dot(&(self.mass_matrix(q) * qd))
    }

    /// Potential energy `V`: gravity of every body, `mass g (-p_x sin phi + p_z cos phi)`, plus the springs of
    /// Legs 1 and 2, `1/2 k (Lstar - L)^2`, and that of a swinging leg less its value at the spoke length (so that
    /// `V` is continuous where its stopper locks it and it becomes a spoke again, whose spring `V` leaves out)
    /// \[J\] (docs/model.md section 2).
    pub(crate) fn potential_energy(&self, q: &Coords) -> f64 {
        let p = &self.params;
        let zero = Coords::zeros();
        let up = self.mech.up;
        let hub = self.hub(q, &zero);
        let mut v = p.hub_mass * hub.position.dot(&up);
        for j in 0..self.legs() {
            let leg = self.leg_point_from_hub(&self.mech, &hub, (q, &zero), j, p.leg_mass_offset);
            v += p.leg_mass * leg.position.dot(&up);
        }
        let spring = |l: f64| 0.5 * p.stiffness * (p.spring_natural_length - l).powi(2);
        let v = v + spring(q[L1]) + spring(q[L2]);
        if swinging(q) {
            v + spring(q[L3]) - spring(p.spoke_length())
        } else {
            v
        }
    }

    /// Total mechanical energy `T + V` \[J\].
    pub fn energy(&self, q: &Coords, qd: &Coords) -> f64 {
        self.kinetic_energy(q, qd) + self.potential_energy(q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Relative tolerance of central finite differences with step `FD_STEP`.
    const FD_TOL: f64 = 1e-6;
    const FD_STEP: f64 = 1e-5;

    fn model() -> Model {
        let params = Params {
            hub_inertia: 0.3,
            ..Params::default()
        };
        Model::new(&params).unwrap()
    }

    fn sample_state() -> (Coords, Coords) {
        (
            Coords::new(0.1, 0.02, -0.2, 0.93, 0.81, 0.0),
            Coords::new(0.4, -0.3, 1.1, -0.25, 0.6, 0.0),
        )
    }

    /// [`sample_state`] with a swinging leg ([`L3`]).
    fn swinging_state() -> (Coords, Coords) {
        let (mut q, mut qd) = sample_state();
        (q[L3], qd[L3]) = (0.87, -0.45);
        (q, qd)
    }

    /// Both sample states: without and with a swinging leg.
    fn sample_states() -> [(Coords, Coords); 2] {
        [sample_state(), swinging_state()]
    }

    fn unit(i: usize) -> Coords {
        let mut e = Coords::zeros();
        e[i] = 1.0;
        e
    }

    #[test]
    fn structured_assembly_equals_the_point_mass_formula() {
        let model = model();
        for (q, qd) in sample_states() {
            let (m, h) = model.mass_and_bias(&q, &qd);
            let (m_ref, h_ref) = model.mass_and_bias_reference(&q, &qd);
            assert_relative_eq!(m, m_ref, epsilon = 1e-12, max_relative = 1e-13);
            assert_relative_eq!(h, h_ref, epsilon = 1e-11, max_relative = 1e-13);
        }
    }

    /// `M z + h` without forming `M` (what the derivatives of the dynamics differentiate) equals the assembled
    /// `M z + h` for any number of legs, with and without a swinging leg, in `f64` and along a direction of
    /// every coordinate and of a parameter on dual numbers; Leg 2's tip is the assembled one.
    #[test]
    fn generalized_force_equals_the_assembled_equations_of_motion() {
        use crate::variational::{dual_of as dual, seeded, Dual};
        for legs in [3, 6, 11] {
            let params = Params {
                legs,
                hub_inertia: 0.3,
                ..Params::default()
            };
            let model = Model::new(&params).unwrap();
            for (k, (q, qd)) in random_states(12).into_iter().enumerate() {
                let z = Coords::from_fn(|i, _| {
                    if i == L3 && !swinging(&q) {
                        0.0
                    } else {
                        (i as f64 + 1.3 * k as f64).sin()
                    }
                });
                let eom = model.equations_of_motion(&q, &qd);
                let (force, tip) = model.generalized_force_with(model.mechanics(), &q, &qd, &z);
                assert_relative_eq!(force, eom.mass * z + eom.bias, epsilon = 1e-11);
                assert_eq!(tip, eom.rear_tip);
                // Along one direction in (q, q') and the stiffness: the derivative parts agree too.
                let mech = seeded::<1>(&model, Some("stiffness"), 0);
                // `L3` carries no direction where no leg swings (it is not a coordinate there).
                let along = |x: f64, i: usize| {
                    let e = if x == 0.0 { 0.0 } else { 0.1 + 0.07 * i as f64 };
                    dual(x, nalgebra::SVector::<f64, 1>::new(e))
                };
                let qs = CoordsOf::<Dual<1>>::from_fn(|i, _| along(q[i], i));
                let qds = CoordsOf::<Dual<1>>::from_fn(|i, _| along(qd[i], 7 + i));
                let eom = model.equations_of_motion_with(&mech, &qs, &qds);
                let assembled = CoordsOf::<Dual<1>>::from_fn(|i, _| {
                    (0..NQ).fold(eom.bias[i], |sum, j| sum + eom.mass[(i, j)] * lit(z[j]))
                });
                let (force, _) = model.generalized_force_with(&mech, &qs, &qds, &z);
                for i in 0..NQ {
                    assert_relative_eq!(force[i].re, assembled[i].re, epsilon = 1e-11);
                    assert_relative_eq!(force[i].eps[0], assembled[i].eps[0], epsilon = 1e-10);
                }
            }
        }
    }

    /// A small deterministic generator of states (xorshift), uniform in `[-1, 1)` per component.
    fn random_states(count: usize) -> Vec<(Coords, Coords)> {
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut uniform = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        };
        (0..count)
            .map(|_| {
                // Every other state has a swinging leg.
                let swing = uniform() > 0.0;
                let q = Coords::new(
                    uniform(),
                    uniform(),
                    3.0 * uniform(),
                    0.9 + 0.1 * uniform(),
                    0.9 + 0.1 * uniform(),
                    if swing { 0.9 + 0.1 * uniform() } else { 0.0 },
                );
                let mut qd = Coords::from_fn(|_, _| 2.0 * uniform());
                if !swing {
                    qd[L3] = 0.0;
                }
                (q, qd)
            })
            .collect()
    }

    /// The closed-form sums over the locked legs equal the leg-by-leg point-mass formula for any number of
    /// legs, hub inertia and mass offset.
    #[test]
    fn locked_legs_in_closed_form_equal_the_point_mass_formula() {
        for legs in [3, 4, 5, 8, 12, 1000] {
            for (hub_inertia, leg_mass_offset) in [(0.0, 0.3), (0.3, 0.0), (1.2, 0.9)] {
                let params = Params {
                    legs,
                    hub_inertia,
                    leg_mass_offset,
                    ..Params::default()
                };
                let model = Model::new(&params).unwrap();
                // The reference sums N terms: its rounding grows with N and with the size of the entries.
                let scale = model.total_mass() * (1.0 + params.gravity);
                for (q, qd) in random_states(20) {
                    let (m, h) = model.mass_and_bias(&q, &qd);
                    let (m_ref, h_ref) = model.mass_and_bias_reference(&q, &qd);
                    let context = format!("N = {legs}, IH = {hub_inertia}, a = {leg_mass_offset}");
                    assert_relative_eq!(m, m_ref, epsilon = 1e-13 * scale, max_relative = 1e-13);
                    assert!(
                        (h - h_ref).amax() <= 1e-13 * scale * (1.0 + qd.amax().powi(2)),
                        "{context}: h = {h}, reference {h_ref}"
                    );
                }
            }
        }
    }

    #[test]
    fn lowest_tip_height_is_the_least_tip_height() {
        for legs in [3, 8, 13] {
            let model = Model::new(&Params {
                legs,
                ..Params::default()
            })
            .unwrap();
            for (q, _) in random_states(10) {
                let least = (0..legs)
                    .map(|j| model.tip_height(&q, j))
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(model.lowest_tip_height(&q), least);
            }
        }
    }

    #[test]
    fn rear_tip_of_the_equations_of_motion_is_the_tip_of_leg_two() {
        let model = model();
        for (q, qd) in random_states(10) {
            let tip = model.tip(&q, &qd, 1);
            let eom = model.equations_of_motion(&q, &qd);
            assert_relative_eq!(eom.rear_tip.position, tip.position, epsilon = 1e-14);
            assert_relative_eq!(eom.rear_tip.jacobian, tip.jacobian, epsilon = 1e-14);
            assert_relative_eq!(
                eom.rear_tip.velocity_product,
                tip.velocity_product,
                epsilon = 1e-13
            );
        }
    }

    #[test]
    fn locked_leg_offsets_are_the_sum_over_the_locked_legs() {
        for legs in [3, 8, 1000] {
            let model = Model::new(&Params {
                legs,
                ..Params::default()
            })
            .unwrap();
            let (ss, sc) = model.offsets[2..]
                .iter()
                .fold((0.0, 0.0), |(ss, sc), &(s, c)| (ss + s, sc + c));
            assert_relative_eq!(model.locked_offsets.0, ss, epsilon = 1e-12);
            assert_relative_eq!(model.locked_offsets.1, sc, epsilon = 1e-12);
        }
    }

    #[test]
    fn mass_matrix_is_symmetric_positive_definite() {
        for (q, _) in sample_states() {
            let m = model().mass_matrix(&q);
            assert_relative_eq!(m, m.transpose(), epsilon = 1e-14);
            assert!(m.cholesky().is_some());
        }
    }

    #[test]
    fn mass_matrix_is_the_hessian_of_kinetic_energy() {
        let model = model();
        let (q, _) = swinging_state();
        let m = model.mass_matrix(&q);
        for i in 0..NQ {
            for j in 0..NQ {
                // T is quadratic in q', so the second difference is exact up to rounding.
                let t = |a: f64, b: f64| model.kinetic_energy(&q, &(a * unit(i) + b * unit(j)));
                let fd = (t(1.0, 1.0) - t(1.0, -1.0) - t(-1.0, 1.0) + t(-1.0, -1.0)) / 4.0;
                assert_relative_eq!(m[(i, j)], fd, epsilon = 1e-10, max_relative = 1e-10);
            }
        }
    }

    /// `h = dM/dt q' - dT/dq + dV/dq + damping`, Lagrange's equations built from the energies only.
    #[test]
    fn bias_matches_lagrange_equations_from_energies() {
        let model = model();
        let p = model.params().clone();
        let (q, qd) = swinging_state();
        let (_, h) = model.mass_and_bias(&q, &qd);
        // dM/dt q' = sum_k dM/dq_k qd_k q', by central differences along q'
        let m_at = |s: f64| model.mass_matrix(&(q + s * qd));
        let dm_dt = (m_at(FD_STEP) - m_at(-FD_STEP)) / (2.0 * FD_STEP);
        let mut expected = dm_dt * qd;
        for k in 0..NQ {
            let e = unit(k) * FD_STEP;
            let dt_dq = (model.kinetic_energy(&(q + e), &qd) - model.kinetic_energy(&(q - e), &qd))
                / (2.0 * FD_STEP);
            let dv_dq = (model.potential_energy(&(q + e)) - model.potential_energy(&(q - e)))
                / (2.0 * FD_STEP);
            expected[k] += -dt_dq + dv_dq;
        }
        expected[L1] += p.viscosity * qd[L1];
        expected[L2] += p.viscosity * qd[L2];
        expected[L3] += p.viscosity * qd[L3];
        assert_relative_eq!(h, expected, epsilon = 1e-6, max_relative = FD_TOL);
    }

    #[test]
    fn point_jacobians_and_velocity_products_match_finite_differences() {
        let model = model();
        let (q, qd) = swinging_state();
        for j in 0..model.legs() {
            let tip = model.tip(&q, &qd, j);
            let pos = |q: &Coords| model.tip(q, &qd, j).position;
            for k in 0..NQ {
                let e = unit(k) * FD_STEP;
                let fd = (pos(&(q + e)) - pos(&(q - e))) / (2.0 * FD_STEP);
                assert_relative_eq!(tip.jacobian.column(k).into_owned(), fd, epsilon = 1e-8);
            }
            // dJ/dt q' = d/ds [J(q + s q') q'] at s = 0
            let jq = |s: f64| model.tip(&(q + s * qd), &qd, j).jacobian * qd;
            let fd = (jq(FD_STEP) - jq(-FD_STEP)) / (2.0 * FD_STEP);
            assert_relative_eq!(tip.velocity_product, fd, epsilon = 1e-7);
        }
    }

    #[test]
    fn leg_one_tip_is_the_origin_of_q_with_constant_jacobian() {
        let model = model();
        let (q, qd) = sample_state();
        let tip = model.tip(&q, &qd, 0);
        assert_relative_eq!(tip.position, Vector2::new(q[X], q[Z]), epsilon = 1e-14);
        let mut expected = PointJacobian::zeros();
        expected[(0, X)] = 1.0;
        expected[(1, Z)] = 1.0;
        assert_relative_eq!(tip.jacobian, expected, epsilon = 1e-14);
        assert_relative_eq!(tip.velocity_product.norm(), 0.0, epsilon = 1e-13);
        assert_relative_eq!(
            model.tip_height(&q, 3),
            model.tip(&q, &qd, 3).position.y,
            epsilon = 1e-14
        );
    }
}
