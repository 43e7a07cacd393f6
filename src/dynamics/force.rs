//! `M(q) z + h(q, q')` without forming `M`: what the derivatives of the constrained dynamics differentiate
//! (`crate::variational`, docs/model.md section 10).

use super::{
    add_leg_forces, lit, swinging, Coords, CoordsOf, Locked, Mechanics, Model, PointKinematics,
    Real,
};
use super::{L1, L3, THETA, X, Z};
use nalgebra::Vector2;

impl Model {
    /// `M(q) z + h(q, q')` for a vector `z` of accelerations held fixed (the left side of Eq. (1)), with the
    /// kinematics of Leg 2's tip, over any [`Real`] with the constants `mech`: what the derivative of the
    /// constrained dynamics differentiates (`crate::variational`), without forming `M`. Each point adds
    /// `m b^T u` with its acceleration `u = b z + dJ/dt q' + g_n` (`O(C)` products where `M` takes `O(C^2)`),
    /// and the locked legs, whose `u_j = U + d (e_psi,j z_theta - e_j w^2)` differ from the hub's `U` only
    /// along their directions, add in closed form `sum_j m u_j = m (n U + d (S_psi z_theta - S_e w^2))` and
    /// `sum_j m b_theta,j . u_j = m (b_theta,H . sum_j u_j + d S_psi . U + n d^2 z_theta)`
    /// (`S_e = sum_j e_j`, `S_psi = sum_j e_psi,j`).
    pub(crate) fn generalized_force_with<T: Real>(
        &self,
        mech: &Mechanics<T>,
        q: &CoordsOf<T>,
        qd: &CoordsOf<T>,
        z: &Coords,
    ) -> (CoordsOf<T>, PointKinematics<T>) {
        if swinging(q) {
            self.generalized_force::<T, 4>(mech, q, qd, z)
        } else {
            self.generalized_force::<T, 3>(mech, q, qd, z)
        }
    }

    /// [`Model::generalized_force_with`] with `C` length columns.
    fn generalized_force<T: Real, const C: usize>(
        &self,
        p: &Mechanics<T>,
        q: &CoordsOf<T>,
        qd: &CoordsOf<T>,
        z: &Coords,
    ) -> (CoordsOf<T>, PointKinematics<T>) {
        let swing = C == 4;
        let wheel = self.wheel::<T, C>(q, qd);
        let zc: [T; C] = std::array::from_fn(|k| lit::<T>(z[THETA + k]));
        let z_xz = Vector2::new(lit::<T>(z[X]), lit::<T>(z[Z]));
        let mut force = CoordsOf::<T>::zeros();
        // A point of mass m: u = (z_x, z_z) + sum_k b_k z_k + a; it adds m u to (x, z) and m b_k . u to column k.
        let mut add = |m: T, b: &[Vector2<T>; C], a: Vector2<T>| -> Vector2<T> {
            let mut u = z_xz + a;
            for (b_k, z_k) in b.iter().zip(&zc) {
                u += b_k * *z_k;
            }
            let mu = u * m;
            force[X] += mu.x;
            force[Z] += mu.y;
            for (k, b_k) in b.iter().enumerate() {
                force[THETA + k] += b_k.dot(&mu);
            }
            u
        };
        let hub_u = add(p.hub_mass, &wheel.hub_b, wheel.hub_vp + p.up);
        wheel.each_leg_point(p, (q, qd), self.swinging_offset::<C>(), |m, b, a| {
            add(m, b, a);
        });
        let Locked {
            n,
            d,
            sum_e,
            sum_e_psi,
        } = self.locked(&wheel, p, swing);
        let (w, m, z_theta) = (wheel.w, p.leg_mass, zc[0]);
        let sum_u = hub_u * n + (sum_e_psi * z_theta - sum_e * (w * w)) * d;
        force[X] += m * sum_u.x;
        force[Z] += m * sum_u.y;
        force[THETA] +=
            m * (wheel.hub_b[0].dot(&sum_u) + d * sum_e_psi.dot(&hub_u) + n * d * d * z_theta);
        force[L1] += m * wheel.hub_b[1].dot(&sum_u);
        force[THETA] += p.hub_inertia * z_theta;
        add_leg_forces(p, (q, qd), swing, &mut force);
        if !swing {
            force[L3] += lit::<T>(z[L3]);
        }
        (force, self.rear_tip(&wheel, q, qd))
    }
}
