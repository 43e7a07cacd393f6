//! The compass-gait biped of Goswami, Thuilot and Espiau ("A study of the passive gait of a compass-like
//! biped robot: symmetry and chaos", IJRR 17(12):1282-1301, 1998; docs/model.md section 13): two rigid legs of
//! length `leg_length = a + b` hinged at the hip, a point mass `leg_mass` on each at `a = leg_mass_offset` from
//! its foot, `hip_mass` at the hip, point feet.
//!
//! Coordinates `q = (x, z, theta1, theta2)`: the hip in the slope frame (`x` down the slope, `z` normal to it)
//! and each leg's angle from the downward normal of the slope, positive toward `+x` (a leg ahead of the hip has
//! a positive angle). The feet are the contact points 0 and 1; a stance foot is held by its contact's two rows,
//! as the wheel's tips are (docs/model.md section 3), so that the force-level and impulse problems of the paper
//! apply unchanged ([`super::constrained`]).

use nalgebra::{DVector, SVector};

use super::assembly::{along_leg, point_mass_equations, point_mass_potential, up, PointMass};
use super::constrained::ConstrainedError;
use super::rigid::{HeelStrike, RigidOptions, RigidWalker, Transition};
use super::rigid_derivative::{step_map_derivative, DerivativeError, StepMapDerivative};
use super::turns::{self, Turns};
use super::{Equations, Mechanism, PointKinematics, Real};
use crate::params::{ConfigError, MASS_RATIO_LIMIT};

/// Index of the hip's `x` in `q`.
pub const X: usize = 0;
/// Index of the hip's `z` in `q`.
pub const Z: usize = 1;
/// Index of Leg 1's angle in `q`.
pub const THETA1: usize = 2;
/// Index of Leg 2's angle in `q`.
pub const THETA2: usize = 3;

/// How the compass gait takes turns: Leg 1's foot (contact 0) stands, Leg 2's (contact 1) lands, the legs'
/// angles are exchanged and the hip slides along the slope (`x`) to put the new stance foot at the origin.
pub const TURNS: Turns<4> = Turns {
    stance: 0,
    lands: 1,
    relabel: [X, Z, THETA2, THETA1],
    shift: Some((X, 1.0)),
};

/// The compass gait's parameters; the defaults are Goswami, Thuilot and Espiau's (their Table 1).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Compass {
    /// Hip mass `mH` \[kg\]. Default 10.
    pub hip_mass: f64,
    /// Mass of each leg, a point at `leg_mass_offset` from its foot \[kg\]. Default 5.
    pub leg_mass: f64,
    /// Leg length `l = a + b` \[m\]. Default 1.
    pub leg_length: f64,
    /// Distance `a` of a leg's mass from its foot \[m\]. Default 0.5.
    pub leg_mass_offset: f64,
    /// Gravitational acceleration \[m/s^2\]. Default 9.81.
    pub gravity: f64,
    /// Slope `phi` of the ground \[rad\] (downhill toward `+x`). Default 3 degrees.
    pub slope: f64,
}

impl Default for Compass {
    fn default() -> Compass {
        Compass {
            hip_mass: 10.0,
            leg_mass: 5.0,
            leg_length: 1.0,
            leg_mass_offset: 0.5,
            gravity: 9.81,
            slope: 3f64.to_radians(),
        }
    }
}

/// The compass gait's constants over a [`Real`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompassConstants<T: Real> {
    /// `mH` \[kg\].
    pub hip_mass: T,
    /// `m` \[kg\].
    pub leg_mass: T,
    /// `l` \[m\].
    pub leg_length: T,
    /// `a` \[m\].
    pub leg_mass_offset: T,
    /// `g (-sin phi, cos phi)` \[m/s^2\].
    pub up: nalgebra::Vector2<T>,
}

impl Compass {
    /// Checks every rule: positive masses, length and gravity, `leg_mass / hip_mass` within
    /// [`MASS_RATIO_LIMIT`] of 1 (as the wheel's), the leg's mass on the leg below the hip
    /// (`0 <= leg_mass_offset < leg_length`), a slope between -90 and 90 degrees. Every broken rule is
    /// reported.
    pub fn validate(&self) -> Result<(), ConfigError> {
        use crate::params::{finite, positive};
        let mut errors: Vec<ConfigError> = [
            positive("hip_mass", self.hip_mass),
            positive("leg_mass", self.leg_mass),
            positive("leg_length", self.leg_length),
            positive("gravity", self.gravity),
            finite("leg_mass_offset", self.leg_mass_offset),
            finite("slope", self.slope),
        ]
        .into_iter()
        .filter_map(Result::err)
        .collect();
        if self.leg_mass_offset.is_finite()
            && !(0.0..self.leg_length).contains(&self.leg_mass_offset)
        {
            errors.push(ConfigError::InvalidValue {
                key: "leg_mass_offset".to_string(),
                value: crate::fmt::short(self.leg_mass_offset),
                reason: format!(
                    "the leg's mass must lie on the leg below the hip: from 0 to less than leg_length = {} (a \
                     leg with its mass at the hip has no inertia and the mass matrix is singular; the simplest \
                     walking model is that limit)",
                    crate::fmt::short(self.leg_length)
                ),
            });
        }
        let ratio = self.leg_mass / self.hip_mass;
        if ratio.is_finite() && !(1.0 / MASS_RATIO_LIMIT..=MASS_RATIO_LIMIT).contains(&ratio) {
            errors.push(ConfigError::InvalidValue {
                key: "leg_mass".to_string(),
                value: crate::fmt::short(self.leg_mass),
                reason: format!(
                    "leg_mass / hip_mass = {} is outside [{}, {}]: the mass matrix would be singular to \
                     rounding",
                    crate::fmt::short(ratio),
                    crate::fmt::short(1.0 / MASS_RATIO_LIMIT),
                    crate::fmt::short(MASS_RATIO_LIMIT)
                ),
            });
        }
        if self.slope.abs() >= std::f64::consts::FRAC_PI_2 {
            errors.push(ConfigError::InvalidValue {
                key: "slope".to_string(),
                value: crate::fmt::short(self.slope),
                reason: "the slope must be between -pi/2 and pi/2 rad".to_string(),
            });
        }
        ConfigError::all(errors)
    }

    /// Where a gait search starts: the symmetric gait down 3 degrees with the paper's masses and lengths
    /// (`theta1 = 0.2710` rad, `theta1' = -1.0924`, `theta2' = -0.3774` rad/s).
    pub fn default_start(&self) -> DVector<f64> {
        DVector::from_column_slice(&[0.2710, -1.0924, -0.3774])
    }

    /// The hip mass and the two leg masses.
    fn masses<T: Real>(
        c: &CompassConstants<T>,
        q: &SVector<T, 4>,
        qd: &SVector<T, 4>,
    ) -> [PointMass<T, 4>; 3] {
        let from_hip = c.leg_length - c.leg_mass_offset;
        [
            PointMass {
                mass: c.hip_mass,
                point: along_leg(q, qd, [X, Z, THETA1], T::zero()),
            },
            PointMass {
                mass: c.leg_mass,
                point: along_leg(q, qd, [X, Z, THETA1], from_hip),
            },
            PointMass {
                mass: c.leg_mass,
                point: along_leg(q, qd, [X, Z, THETA2], from_hip),
            },
        ]
    }
}

impl Mechanism<4> for Compass {
    type Constants<T: Real> = CompassConstants<T>;

    fn name(&self) -> &'static str {
        "compass"
    }

    fn coordinates(&self) -> [&'static str; 4] {
        ["x", "z", "theta1", "theta2"]
    }

    fn constants<T: Real>(&self, value: &dyn Fn(&'static str, f64) -> T) -> CompassConstants<T> {
        CompassConstants {
            hip_mass: value("hip_mass", self.hip_mass),
            leg_mass: value("leg_mass", self.leg_mass),
            leg_length: value("leg_length", self.leg_length),
            leg_mass_offset: value("leg_mass_offset", self.leg_mass_offset),
            up: up(value("gravity", self.gravity), value("slope", self.slope)),
        }
    }

    fn equations<T: Real>(
        &self,
        c: &CompassConstants<T>,
        q: &SVector<T, 4>,
        qd: &SVector<T, 4>,
    ) -> Equations<T, 4> {
        point_mass_equations(&Compass::masses(c, q, qd), c.up)
    }

    fn contact_points(&self) -> usize {
        2
    }

    fn contact<T: Real>(
        &self,
        c: &CompassConstants<T>,
        q: &SVector<T, 4>,
        qd: &SVector<T, 4>,
        i: usize,
    ) -> PointKinematics<T, 4> {
        let leg = if i == 0 { THETA1 } else { THETA2 };
        along_leg(q, qd, [X, Z, leg], c.leg_length)
    }

    fn potential_energy(&self, q: &SVector<f64, 4>) -> f64 {
        let c = self.constants_f64();
        point_mass_potential(&Compass::masses(&c, q, &SVector::zeros()), c.up)
    }

    fn damper_power(&self, _q: &SVector<f64, 4>, _qd: &SVector<f64, 4>) -> f64 {
        0.0
    }
}

impl RigidWalker<4, 8> for Compass {
    type Constants<T: Real> = CompassConstants<T>;

    fn name(&self) -> &'static str {
        "compass"
    }

    fn section_names(&self) -> Vec<&'static str> {
        vec!["theta1", "theta1_dot", "theta2_dot"]
    }

    fn rigid_constants<T: Real>(
        &self,
        value: &dyn Fn(&'static str, f64) -> T,
    ) -> CompassConstants<T> {
        Mechanism::constants(self, value)
    }

    /// Eq. (1) with Leg 1's foot held ([`super::turns::single_support`]); its normal force.
    fn single_support_with<T: Real>(
        &self,
        c: &CompassConstants<T>,
        q: &SVector<T, 4>,
        qd: &SVector<T, 4>,
    ) -> Result<(SVector<T, 4>, T), ConstrainedError> {
        turns::single_support(self, &TURNS.lit(), c, (q, qd))
    }

    fn swing_foot_with<T: Real>(&self, c: &CompassConstants<T>, q: &SVector<T, 4>) -> (T, T) {
        turns::swing_foot(self, &TURNS.lit(), c, q)
    }

    fn hip_height(&self, q: &SVector<f64, 4>) -> f64 {
        q[Z]
    }

    /// The impact with both feet held gives `lambda_I4` (Leg 1's normal impulse); the traditional impact with
    /// Leg 2's foot held, then Leg 2 is the stance leg (the angles exchanged, the hip moved along the slope so
    /// that the new stance foot is at `x = 0`): [`super::turns::transition`].
    fn transition_with<T: Real>(
        &self,
        c: &CompassConstants<T>,
        q: &SVector<T, 4>,
        qd: &SVector<T, 4>,
    ) -> Result<Transition<4, T>, ConstrainedError> {
        turns::transition(self, &TURNS.lit(), c, (q, qd))
    }

    /// [`RigidWalker::transition_with`]; where `lambda_I4 < 0` the rear foot leaves (the traditional impact):
    /// [`super::turns::heel_strike`].
    fn heel_strike(
        &self,
        q: &SVector<f64, 4>,
        qd: &SVector<f64, 4>,
    ) -> Result<HeelStrike<4>, ConstrainedError> {
        turns::heel_strike(self, &TURNS, q, qd)
    }

    fn mechanical_energy(&self, q: &SVector<f64, 4>, qd: &SVector<f64, 4>) -> f64 {
        self.energy(q, qd)
    }

    fn section_with<T: Real>(
        &self,
        _: &CompassConstants<T>,
        q: &SVector<T, 4>,
        qd: &SVector<T, 4>,
    ) -> Vec<T> {
        vec![q[THETA1], qd[THETA1], qd[THETA2]]
    }

    /// `(theta1, theta1', theta2')` just after a heel strike: Leg 1's foot at the origin, Leg 2's on the ground
    /// behind it (`theta2 = -theta1`), the hip moving about Leg 1's foot.
    fn state_at_section_with<T: Real>(
        &self,
        c: &CompassConstants<T>,
        s: &[T],
    ) -> (SVector<T, 4>, SVector<T, 4>) {
        let (theta, w, w2) = (s[0], s[1], s[2]);
        let l = c.leg_length;
        let (sn, cs) = theta.sin_cos();
        (
            SVector::from([-(l * sn), l * cs, theta, -theta]),
            SVector::from([-(l * cs * w), -(l * sn * w), w, w2]),
        )
    }

    fn step_map_derivative(
        &self,
        x: &DVector<f64>,
        param: Option<&str>,
        period: usize,
        options: &RigidOptions,
    ) -> Result<StepMapDerivative<4>, DerivativeError> {
        step_map_derivative::<Compass, 4, 8, 4, 5, 40>(self, x, param, period, options)
    }
}

impl super::rigid_family::Parametrized for Compass {
    fn parameter_keys(&self) -> Vec<&'static str> {
        vec![
            "hip_mass",
            "leg_mass",
            "leg_length",
            "leg_mass_offset",
            "gravity",
            "slope",
        ]
    }

    fn with_parameter(&self, key: &str, value: f64) -> Result<Compass, ConfigError> {
        let mut walker = *self;
        let field = match key {
            "hip_mass" => &mut walker.hip_mass,
            "leg_mass" => &mut walker.leg_mass,
            "leg_length" => &mut walker.leg_length,
            "leg_mass_offset" => &mut walker.leg_mass_offset,
            "gravity" => &mut walker.gravity,
            "slope" => &mut walker.slope,
            _ => {
                return Err(ConfigError::UnknownKey {
                    key: key.to_string(),
                    known: self.parameter_keys().join(", "),
                })
            }
        };
        *field = value;
        walker.validate()?;
        Ok(walker)
    }
}
