//! The equations of motion of a mechanism made of point masses (docs/model.md section 13): for masses `m_k` at
//! points `p_k(q)` with Jacobians `J_k = dp_k/dq`, d'Alembert's principle gives Eq. (1) with
//!
//! ```text
//! M = sum_k m_k J_k^T J_k,        h = sum_k m_k J_k^T (dJ_k/dt q' + u),        V = sum_k m_k u . p_k,
//! ```
//!
//! `u = g (-sin phi, cos phi)` the negative of gravity in the slope frame (`x` down the slope). Rigid bodies
//! with an inertia and springs at joints add to these; a point-mass walker (the compass gait) needs only them.

use nalgebra::{SMatrix, SVector, Vector2};

use super::{Equations, PointKinematics, Real};

/// One point mass of a mechanism.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointMass<T: Real, const N: usize> {
    /// Its mass \[kg\].
    pub mass: T,
    /// Where it is, its Jacobian and `dJ/dt q'`.
    pub point: PointKinematics<T, N>,
}

/// `u = g (-sin phi, cos phi)`: the negative of the gravity vector in the slope frame of slope `phi` \[m/s^2\].
pub fn up<T: Real>(gravity: T, slope: T) -> Vector2<T> {
    let (s, c) = slope.sin_cos();
    Vector2::new(-(gravity * s), gravity * c)
}

/// `M` and `h` of the point masses `masses` under gravity `-up` (see the module documentation).
pub fn point_mass_equations<T: Real, const N: usize>(
    masses: &[PointMass<T, N>],
    up: Vector2<T>,
) -> Equations<T, N> {
    let mut mass = SMatrix::<T, N, N>::zeros();
    let mut bias = SVector::<T, N>::zeros();
    for m in masses {
        let j = &m.point.jacobian;
        mass += j.transpose() * j * m.mass;
        bias += j.transpose() * ((m.point.velocity_product + up) * m.mass);
    }
    Equations { mass, bias }
}

/// Potential energy `sum m_k u . p_k` of the point masses `masses` \[J\].
pub fn point_mass_potential<const N: usize>(masses: &[PointMass<f64, N>], up: Vector2<f64>) -> f64 {
    masses
        .iter()
        .map(|m| m.mass * m.point.position.dot(&up))
        .sum()
}

/// The point at distance `r` from `base` along the unit vector `(sin a, -cos a)` (a leg at angle `a` from the
/// downward normal of the slope, positive toward `+x`), where `base` is the point `(x, z)` of coordinates
/// `ix`, `iz` and `a` the coordinate `ia`: its position, Jacobian and `dJ/dt q'`.
pub fn along_leg<T: Real, const N: usize>(
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    [ix, iz, ia]: [usize; 3],
    r: T,
) -> PointKinematics<T, N> {
    let (s, c) = q[ia].sin_cos();
    let w = qd[ia];
    let mut jacobian = SMatrix::<T, 2, N>::zeros();
    jacobian[(0, ix)] = T::one();
    jacobian[(1, iz)] = T::one();
    jacobian[(0, ia)] = r * c;
    jacobian[(1, ia)] = r * s;
    PointKinematics {
        position: Vector2::new(q[ix] + r * s, q[iz] - r * c),
        jacobian,
        velocity_product: Vector2::new(-(r * s * w * w), r * c * w * w),
    }
}

/// The point at distance `q[il] - offset` from `base` along the leg at angle `q[ia]` (as [`along_leg`]): a point
/// of a telescopic leg of length `q[il]`, `offset` from its tip (its tip where `offset = 0`, the leg's sliding
/// mass at the paper's `a` from the tip): position, Jacobian and `dJ/dt q'`.
pub fn along_telescopic_leg<T: Real, const N: usize>(
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    [ix, iz, ia, il]: [usize; 4],
    offset: T,
) -> PointKinematics<T, N> {
    let r = q[il] - offset;
    let (s, c) = q[ia].sin_cos();
    let (w, rate) = (qd[ia], qd[il]);
    let mut jacobian = SMatrix::<T, 2, N>::zeros();
    jacobian[(0, ix)] = T::one();
    jacobian[(1, iz)] = T::one();
    jacobian[(0, ia)] = r * c;
    jacobian[(1, ia)] = r * s;
    jacobian[(0, il)] = s;
    jacobian[(1, il)] = -c;
    // d/dt of the angle's column times w, and of the length's column times its rate: 2 L' w (cos, sin) +
    // r w^2 (-sin, cos).
    let two = T::one() + T::one();
    PointKinematics {
        position: Vector2::new(q[ix] + r * s, q[iz] - r * c),
        jacobian,
        velocity_product: Vector2::new(
            two * rate * w * c - r * s * w * w,
            two * rate * w * s + r * c * w * w,
        ),
    }
}
