//! The viscoelastic-legged rimless wheel ([`Model`]) as a [`Mechanism`]: its equations of motion, the tips of
//! Legs 1 and 2 as its contact points, its energies (docs/model.md sections 1-3). Its own reduced solver
//! (`crate::contact`) is checked here against the general one ([`super::constrained`]).

use nalgebra::SVector;

use super::{Equations, Mechanism, PointKinematics, Real, Role};
use crate::dynamics::{Mechanics, Model, L1, L2, L3, NQ};

impl Mechanism<NQ> for Model {
    type Constants<T: Real> = Mechanics<T>;

    fn name(&self) -> &'static str {
        "vrw"
    }

    fn coordinates(&self) -> [&'static str; NQ] {
        ["x", "z", "theta", "L1", "L2", "L3"]
    }

    fn constants<T: Real>(&self, value: &dyn Fn(&'static str, f64) -> T) -> Mechanics<T> {
        Mechanics::seeded(self.params(), value)
    }

    fn equations<T: Real>(
        &self,
        c: &Mechanics<T>,
        q: &SVector<T, NQ>,
        qd: &SVector<T, NQ>,
    ) -> Equations<T, NQ> {
        let eom = self.equations_of_motion_with(c, q, qd);
        Equations {
            mass: eom.mass,
            bias: eom.bias,
        }
    }

    /// The tips of Leg 1 (contact point 0) and Leg 2 (contact point 1).
    fn contact_points(&self) -> usize {
        2
    }

    fn contact<T: Real>(
        &self,
        c: &Mechanics<T>,
        q: &SVector<T, NQ>,
        qd: &SVector<T, NQ>,
        i: usize,
    ) -> PointKinematics<T, NQ> {
        self.tip_with(c, q, qd, i)
    }

    fn potential_energy(&self, q: &SVector<f64, NQ>) -> f64 {
        Model::potential_energy(self, q)
    }

    /// `c (L1'^2 + L2'^2 + L3'^2)`, as the walk integrates it (`L3' = 0` without a swinging leg).
    fn damper_power(&self, _q: &SVector<f64, NQ>, qd: &SVector<f64, NQ>) -> f64 {
        self.params().viscosity * (qd[L1] * qd[L1] + qd[L2] * qd[L2] + qd[L3] * qd[L3])
    }

    fn kinetic_energy(&self, q: &SVector<f64, NQ>, qd: &SVector<f64, NQ>) -> f64 {
        Model::kinetic_energy(self, q, qd)
    }
}

/// The wheel's strokes as the walk asks for them.
impl Model {
    /// The coordinate that is the length of the leg in `role` (its stroke: the row of its stopper and of its
    /// compression stop): `L1` for the fore leg, `L2` for the rear one.
    pub fn stroke_coordinate(role: Role) -> usize {
        match role {
            Role::Fore => L1,
            Role::Rear => L2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::constrained::{accelerations, impulse, Row};
    use super::*;
    use crate::contact::{constrained_dynamics, ActiveSet, Role, Stop};
    use crate::dynamics::{Coords, THETA, X, Z};
    use crate::params::Params;

    /// A state of the wheel with both tips near the ground and every velocity nonzero.
    fn state(model: &Model) -> (Coords, Coords) {
        let p = model.params();
        let alpha = model.alpha();
        let (l1, l2) = (0.98 * p.stopper_length, 0.97 * p.stopper_length);
        let theta = 0.4 * alpha;
        let q = Coords::from([0.0, l1 * theta.cos(), theta, l1, l2, 0.0]);
        let qd = Coords::from([0.01, -0.02, -0.8, -0.05, 0.07, 0.0]);
        (q, qd)
    }

    /// The largest difference between two vectors, relative to the larger of their largest entries.
    fn relative(a: &[f64], b: &[f64]) -> f64 {
        let scale = a.iter().chain(b).fold(1.0f64, |m, x| m.max(x.abs()));
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / scale
    }

    /// The wheel's reduced solver (`crate::contact`) and the general Schur-complement solve of any mechanism
    /// give the same accelerations and multipliers: single support, double support, a leg at its stopper.
    #[test]
    fn the_wheels_solver_is_the_general_one() {
        let model = Model::new(&Params::default()).unwrap();
        let (q, qd) = state(&model);
        let mut single = ActiveSet::default();
        single.set_contact(Role::Fore, true);
        let mut double = single;
        double.set_contact(Role::Rear, true);
        let mut locked = double;
        locked.set_held(Role::Rear, Stop::Extension, true);
        let cases: [(ActiveSet, Vec<Row>); 3] = [
            (single, Row::contact(0).to_vec()),
            (double, [Row::contact(0), Row::contact(1)].concat()),
            (
                locked,
                [&Row::contact(0)[..], &Row::contact(1), &[Row::Held(L2)]].concat(),
            ),
        ];
        for (active, rows) in cases {
            let own = constrained_dynamics(&model, &q, &qd, &active).unwrap();
            let general = accelerations(&model, &q, &qd, &rows).unwrap();
            let d = relative(own.qdd.as_slice(), general.qdd.as_slice());
            assert!(d < 1e-12, "{rows:?}: q'' differs by {d:e}");
            // The wheel stacks [lambda_1..lambda_4, mu_1, mu_2]; the general solve in the order of `rows`. A
            // held coordinate's reaction is the stopper's generalized force on the leg, as the wheel's `mu_2`.
            let own_rows: Vec<f64> = rows
                .iter()
                .map(|r| match *r {
                    Row::Tangential(i) => own.multipliers[2 * i],
                    Row::Normal(i) => own.multipliers[2 * i + 1],
                    Row::Held(_) => own.multipliers[5],
                })
                .collect();
            let d = relative(&own_rows, general.multipliers.as_slice());
            assert!(
                d < 1e-11,
                "{rows:?}: multipliers differ by {d:e}: {own_rows:?} {general:?}"
            );
        }
    }

    /// The touchdown impulse of Eq. (5) with both tips held: the wheel's and the general solve agree.
    #[test]
    fn the_wheels_impulse_is_the_general_one() {
        let model = Model::new(&Params::default()).unwrap();
        let (q, qd) = state(&model);
        let mut double = ActiveSet::default();
        double.set_contact(Role::Fore, true);
        double.set_contact(Role::Rear, true);
        let own = crate::contact::impulse(&model, &q, &qd, &double).unwrap();
        let rows = [Row::contact(0), Row::contact(1)].concat();
        let general = impulse(&model, &q, &qd, &rows).unwrap();
        let d = relative(own.qd_plus.as_slice(), general.qd_plus.as_slice());
        assert!(d < 1e-12, "q'+ differs by {d:e}");
        let d = relative(&own.impulses.as_slice()[..4], general.impulses.as_slice());
        assert!(d < 1e-12, "impulses differ by {d:e}");
        // The held tips do not move after the impulse.
        for i in 0..2 {
            let v = model
                .tip(&q, &general.qd_plus, i)
                .velocity(&general.qd_plus);
            assert!(v.amax() < 1e-12, "tip {i} moves at {v:?}");
        }
    }

    /// The interface gives the wheel's own energies and coordinates.
    #[test]
    fn the_wheel_behind_the_interface_is_the_wheel() {
        let model = Model::new(&Params::default()).unwrap();
        let (q, qd) = state(&model);
        assert_eq!(Mechanism::energy(&model, &q, &qd), model.energy(&q, &qd));
        let names = model.coordinates();
        assert_eq!((names[X], names[Z], names[THETA]), ("x", "z", "theta"));
        let power = model.damper_power(&q, &qd);
        let c = model.params().viscosity;
        assert_eq!(power, c * (qd[L1] * qd[L1] + qd[L2] * qd[L2]));
    }
}
