//! The compass gait with the paper's telescopic viscoelastic legs (docs/model.md section 13): the compass-gait
//! biped of Goswami, Thuilot and Espiau ([`super::compass`]) whose legs are the rimless wheel's (docs/model.md
//! section 2). Each leg is a sleeve, hinged at the hip and carrying the compass gait's leg mass `leg_mass` at
//! `leg_mass_offset` from the tip of a leg of full length (`stopper_length`), in which the leg's lower part
//! slides: that part carries `foot_mass` at the tip, a linear spring of stiffness `stiffness` and natural length
//! `spring_natural_length` and a linear damper `viscosity` push it outward, and a stopper holds the leg at
//! `stopper_length` at most. (The wheel's legs carry their whole mass on the sliding part; a biped's swing
//! leg needs its mass on the part that swings with it, and a light foot is what the stopper's impacts
//! jerk.) With the spring's preload `k (Lstar - L0)` above the load a leg carries, the legs
//! never leave their stoppers and the walker is the rigid compass gait; softer, both feet can stay on the ground
//! together after a heel strike (double support), and the paper's DLS indicators decide whether they do.
//!
//! Coordinates `q = (x, z, theta1, theta2, L1, L2)`: the hip in the slope frame, each leg's angle from the
//! downward normal of the slope (positive toward `+x`, as the compass gait's) and its length from hip to tip.
//! Leg 1 is the fore (stance) leg and Leg 2 the rear one (the swing leg in single support), contact points 0
//! and 1; at a heel strike the legs exchange their roles ([`super::legged::Legged::relabel`]).

use nalgebra::{DVector, SVector};

use super::assembly::{
    along_leg, along_telescopic_leg, point_mass_equations, point_mass_potential, up, PointMass,
};
use super::legged::derivative::{
    replayed_step_map, LeggedDerivative, LeggedDerivativeError, LeggedDerivatives,
};
use super::legged::walk::LeggedOptions;
use super::legged::{Legged, Stroke};
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
/// Index of Leg 1's length in `q`.
pub const LENGTH1: usize = 4;
/// Index of Leg 2's length in `q`.
pub const LENGTH2: usize = 5;

/// The telescopic-legged compass gait's parameters. The masses and the leg's geometry default to Goswami,
/// Thuilot and Espiau's compass gait; the leg's spring is stiffer than the wheel's (a biped's stance leg
/// carries the whole walker) and preloaded above a leg's weight, so that a swinging leg rests on its stopper.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Telescopic {
    /// Hip mass `mH` \[kg\]. Default 10.
    pub hip_mass: f64,
    /// Mass of each leg's sleeve, a point at `stopper_length - leg_mass_offset` from the hip \[kg\]. Default 5.
    pub leg_mass: f64,
    /// Distance `a` of the sleeve's mass from the tip of a leg at full length \[m\]. Default 0.5.
    pub leg_mass_offset: f64,
    /// Mass of each leg's sliding part, a point at its tip \[kg\]. Default 0.5.
    pub foot_mass: f64,
    /// The stopper's length `L0`: a leg is at most this long \[m\]. Default 1.
    pub stopper_length: f64,
    /// The spring's natural length `Lstar` (above `L0`: preloaded) \[m\]. Default 1.005: a preload of 100 N,
    /// above a leg's weight (a swinging leg rests on its stopper) and below the walker's (a stance leg is
    /// compressed).
    pub spring_natural_length: f64,
    /// The spring's stiffness `k` \[N/m\]. Default 20000.
    pub stiffness: f64,
    /// The damper's coefficient `c` \[N s/m\]. Default 1000 (a softer damper lets a stance leg reach its
    /// stopper fast enough to jerk its foot off the ground).
    pub viscosity: f64,
    /// Gravitational acceleration \[m/s^2\]. Default 9.81.
    pub gravity: f64,
    /// Slope `phi` of the ground \[rad\] (downhill toward `+x`). Default 3 degrees.
    pub slope: f64,
}

impl Default for Telescopic {
    fn default() -> Telescopic {
        Telescopic {
            hip_mass: 10.0,
            leg_mass: 5.0,
            leg_mass_offset: 0.5,
            foot_mass: 0.5,
            stopper_length: 1.0,
            spring_natural_length: 1.005,
            stiffness: 20000.0,
            viscosity: 1000.0,
            gravity: 9.81,
            slope: 3f64.to_radians(),
        }
    }
}

/// The constants of the equations over a [`Real`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TelescopicConstants<T: Real> {
    /// `mH` \[kg\].
    pub hip_mass: T,
    /// `m` \[kg\].
    pub leg_mass: T,
    /// The stoppers' length `L0` \[m\].
    pub stopper_length: T,
    /// The sleeve mass's distance from the hip, `L0 - a` \[m\].
    pub sleeve_radius: T,
    /// The foot's mass \[kg\].
    pub foot_mass: T,
    /// `Lstar` \[m\].
    pub spring_natural_length: T,
    /// `k` \[N/m\].
    pub stiffness: T,
    /// `c` \[N s/m\].
    pub viscosity: T,
    /// `g (-sin phi, cos phi)` \[m/s^2\].
    pub up: nalgebra::Vector2<T>,
}

/// The parameter keys, in the order of [`Telescopic`]'s fields.
pub const KEYS: [&str; 10] = [
    "hip_mass",
    "leg_mass",
    "leg_mass_offset",
    "foot_mass",
    "stopper_length",
    "spring_natural_length",
    "stiffness",
    "viscosity",
    "gravity",
    "slope",
];

impl Telescopic {
    /// Checks every rule: positive masses, lengths, stiffness and gravity, a damper of at least 0, the leg's
    /// mass on its sliding part (`0 <= leg_mass_offset < stopper_length`), `leg_mass / hip_mass` within
    /// [`MASS_RATIO_LIMIT`] of 1, a slope between -90 and 90 degrees. Every broken rule is reported.
    pub fn validate(&self) -> Result<(), ConfigError> {
        use crate::params::{finite, positive};
        let mut errors: Vec<ConfigError> = [
            positive("hip_mass", self.hip_mass),
            positive("leg_mass", self.leg_mass),
            positive("foot_mass", self.foot_mass),
            positive("stopper_length", self.stopper_length),
            positive("spring_natural_length", self.spring_natural_length),
            positive("stiffness", self.stiffness),
            positive("gravity", self.gravity),
            finite("viscosity", self.viscosity),
            finite("leg_mass_offset", self.leg_mass_offset),
            finite("slope", self.slope),
        ]
        .into_iter()
        .filter_map(Result::err)
        .collect();
        let mut refuse = |key: &str, value: f64, reason: String| {
            errors.push(ConfigError::InvalidValue {
                key: key.to_string(),
                value: crate::fmt::short(value),
                reason,
            })
        };
        if self.viscosity < 0.0 {
            refuse("viscosity", self.viscosity, "must be >= 0".to_string());
        }
        if self.leg_mass_offset.is_finite()
            && !(0.0..self.stopper_length).contains(&self.leg_mass_offset)
        {
            refuse(
                "leg_mass_offset",
                self.leg_mass_offset,
                format!(
                    "the sleeve's mass must lie on the leg below the hip: from 0 to less than \
                     stopper_length = {} from the tip",
                    crate::fmt::short(self.stopper_length)
                ),
            );
        }
        for (key, mass) in [("leg_mass", self.leg_mass), ("foot_mass", self.foot_mass)] {
            let ratio = mass / self.hip_mass;
            if ratio.is_finite() && !(1.0 / MASS_RATIO_LIMIT..=MASS_RATIO_LIMIT).contains(&ratio) {
                refuse(
                    key,
                    mass,
                    format!(
                        "{key} / hip_mass = {} is outside [{}, {}]: the mass matrix would be singular to \
                         rounding",
                        crate::fmt::short(ratio),
                        crate::fmt::short(1.0 / MASS_RATIO_LIMIT),
                        crate::fmt::short(MASS_RATIO_LIMIT)
                    ),
                );
            }
        }
        if self.slope.abs() >= std::f64::consts::FRAC_PI_2 {
            refuse(
                "slope",
                self.slope,
                "the slope must be between -pi/2 and pi/2 rad".to_string(),
            );
        }
        ConfigError::all(errors)
    }

    /// Where a gait search starts (the section of [`Legged::section_of`]): the gait with the default
    /// parameters (`theta1 = 0.28196`, `L2 = 0.99728` m, `theta1' = -1.65060`, `theta2' = -1.47117` rad/s,
    /// `L2' = 0.00937` m/s).
    pub fn default_start(&self) -> DVector<f64> {
        DVector::from_column_slice(&[0.28196, 0.99728, -1.65060, -1.47117, 0.00937])
    }

    /// The hip mass, the two sleeves' masses and the two feet.
    fn masses<T: Real>(
        c: &TelescopicConstants<T>,
        q: &SVector<T, 6>,
        qd: &SVector<T, 6>,
    ) -> [PointMass<T, 6>; 5] {
        let sleeve = |angle| PointMass {
            mass: c.leg_mass,
            point: along_leg(q, qd, [X, Z, angle], c.sleeve_radius),
        };
        let foot = |angle, length| PointMass {
            mass: c.foot_mass,
            point: along_telescopic_leg(q, qd, [X, Z, angle, length], T::zero()),
        };
        [
            PointMass {
                mass: c.hip_mass,
                point: along_leg(q, qd, [X, Z, THETA1], T::zero()),
            },
            sleeve(THETA1),
            sleeve(THETA2),
            foot(THETA1, LENGTH1),
            foot(THETA2, LENGTH2),
        ]
    }
}

/// Its parameters by key ([`KEYS`]), each settable for `vrw sweep`, `orbit` and `continue --param`.
impl super::rigid_family::Parametrized for Telescopic {
    fn parameter_keys(&self) -> Vec<&'static str> {
        KEYS.to_vec()
    }

    /// The walker with the parameter `key` set to `value`, checked (its domain: [`Telescopic::validate`]).
    fn with_parameter(&self, key: &str, value: f64) -> Result<Telescopic, ConfigError> {
        let mut walker = *self;
        let field = match key {
            "hip_mass" => &mut walker.hip_mass,
            "leg_mass" => &mut walker.leg_mass,
            "leg_mass_offset" => &mut walker.leg_mass_offset,
            "foot_mass" => &mut walker.foot_mass,
            "stopper_length" => &mut walker.stopper_length,
            "spring_natural_length" => &mut walker.spring_natural_length,
            "stiffness" => &mut walker.stiffness,
            "viscosity" => &mut walker.viscosity,
            "gravity" => &mut walker.gravity,
            "slope" => &mut walker.slope,
            _ => {
                return Err(ConfigError::UnknownKey {
                    key: key.to_string(),
                    known: KEYS.join(", "),
                })
            }
        };
        *field = value;
        walker.validate()?;
        Ok(walker)
    }
}

impl Mechanism<6> for Telescopic {
    type Constants<T: Real> = TelescopicConstants<T>;

    fn name(&self) -> &'static str {
        "telescopic"
    }

    fn coordinates(&self) -> [&'static str; 6] {
        ["x", "z", "theta1", "theta2", "L1", "L2"]
    }

    fn constants<T: Real>(&self, value: &dyn Fn(&'static str, f64) -> T) -> TelescopicConstants<T> {
        TelescopicConstants {
            hip_mass: value("hip_mass", self.hip_mass),
            leg_mass: value("leg_mass", self.leg_mass),
            stopper_length: value("stopper_length", self.stopper_length),
            sleeve_radius: value("stopper_length", self.stopper_length)
                - value("leg_mass_offset", self.leg_mass_offset),
            foot_mass: value("foot_mass", self.foot_mass),
            spring_natural_length: value("spring_natural_length", self.spring_natural_length),
            stiffness: value("stiffness", self.stiffness),
            viscosity: value("viscosity", self.viscosity),
            up: up(value("gravity", self.gravity), value("slope", self.slope)),
        }
    }

    /// The point masses' equations ([`point_mass_equations`]) and the legs' springs and dampers: each pushes
    /// its leg outward with `k (Lstar - L) - c L'`.
    fn equations<T: Real>(
        &self,
        c: &TelescopicConstants<T>,
        q: &SVector<T, 6>,
        qd: &SVector<T, 6>,
    ) -> Equations<T, 6> {
        let mut e = point_mass_equations(&Telescopic::masses(c, q, qd), c.up);
        for l in [LENGTH1, LENGTH2] {
            e.bias[l] += c.stiffness * (q[l] - c.spring_natural_length) + c.viscosity * qd[l];
        }
        e
    }

    fn contact_points(&self) -> usize {
        2
    }

    fn contact<T: Real>(
        &self,
        _c: &TelescopicConstants<T>,
        q: &SVector<T, 6>,
        qd: &SVector<T, 6>,
        i: usize,
    ) -> PointKinematics<T, 6> {
        let (angle, length) = if i == 0 {
            (THETA1, LENGTH1)
        } else {
            (THETA2, LENGTH2)
        };
        along_telescopic_leg(q, qd, [X, Z, angle, length], T::zero())
    }

    fn potential_energy(&self, q: &SVector<f64, 6>) -> f64 {
        let c = self.constants_f64();
        let springs: f64 = [LENGTH1, LENGTH2]
            .iter()
            .map(|&l| 0.5 * self.stiffness * (self.spring_natural_length - q[l]).powi(2))
            .sum();
        point_mass_potential(&Telescopic::masses(&c, q, &SVector::zeros()), c.up) + springs
    }

    fn damper_power(&self, _q: &SVector<f64, 6>, qd: &SVector<f64, 6>) -> f64 {
        self.viscosity * (qd[LENGTH1].powi(2) + qd[LENGTH2].powi(2))
    }
}

impl Legged<6> for Telescopic {
    fn strokes(&self) -> [Option<Stroke>; 2] {
        [LENGTH1, LENGTH2].map(|coordinate| {
            Some(Stroke {
                coordinate,
                stopper: self.stopper_length,
            })
        })
    }

    fn hip_height(&self, q: &SVector<f64, 6>) -> f64 {
        q[Z]
    }

    /// The hip's velocity down the slope.
    fn progress(&self, _q: &SVector<f64, 6>, qd: &SVector<f64, 6>) -> f64 {
        qd[X]
    }

    /// The legs exchange roles (angles and lengths swapped) and the hip moves along the slope so that the new
    /// fore tip is at `x = 0`.
    fn relabel(
        &self,
        q: &SVector<f64, 6>,
        qd: &SVector<f64, 6>,
    ) -> (SVector<f64, 6>, SVector<f64, 6>) {
        self.relabel_with(&self.constants_f64(), q, qd)
    }

    fn section_names(&self) -> Vec<&'static str> {
        vec!["theta1", "L2", "theta1_dot", "theta2_dot", "L2_dot"]
    }

    fn section_of(&self, q: &SVector<f64, 6>, qd: &SVector<f64, 6>) -> DVector<f64> {
        DVector::from_vec(self.section_with(q, qd))
    }

    fn state_at_section(&self, s: &DVector<f64>) -> Option<(SVector<f64, 6>, SVector<f64, 6>)> {
        self.state_at_section_with(&self.constants_f64(), s.as_slice())
    }
}

impl LeggedDerivatives<6> for Telescopic {
    fn stopper_with<T: Real>(&self, c: &TelescopicConstants<T>, _leg: usize) -> T {
        c.stopper_length
    }

    /// Leg 2 becomes the fore leg at the origin: the hip moves back by its tip's `x`.
    fn relabel_with<T: Real>(
        &self,
        _c: &TelescopicConstants<T>,
        q: &SVector<T, 6>,
        qd: &SVector<T, 6>,
    ) -> (SVector<T, 6>, SVector<T, 6>) {
        let swap = |v: &SVector<T, 6>| {
            SVector::from([v[X], v[Z], v[THETA2], v[THETA1], v[LENGTH2], v[LENGTH1]])
        };
        let mut after = swap(q);
        after[X] -= q[X] + q[LENGTH2] * q[THETA2].sin();
        (after, swap(qd))
    }

    fn section_with<T: Real>(&self, q: &SVector<T, 6>, qd: &SVector<T, 6>) -> Vec<T> {
        vec![q[THETA1], q[LENGTH2], qd[THETA1], qd[THETA2], qd[LENGTH2]]
    }

    /// The fore leg at its stopper with its tip at the origin; Leg 2's angle from `cos theta2 = h / L2` (`h` the
    /// hip's height), taken on `f64` and carried to a [`Real`] by one Newton step of that equation from its
    /// root (which leaves the value as it is and gives the derivative the implicit function theorem gives).
    fn state_at_section_with<T: Real>(
        &self,
        c: &TelescopicConstants<T>,
        s: &[T],
    ) -> Option<(SVector<T, 6>, SVector<T, 6>)> {
        let (theta1, l2, w1, w2, l2d) = (s[0], s[1], s[2], s[3], s[4]);
        let l0 = c.stopper_length;
        let height = l0 * theta1.cos();
        if !(l2.value() > 0.0 && height.value() > 0.0 && height.value() <= l2.value()) {
            return None;
        }
        let root = -(height.value() / l2.value()).acos();
        let (sin_root, cos_root) = root.sin_cos();
        let miss = T::lit(cos_root) - height / l2;
        let theta2 = T::lit(root) + (miss - T::lit(miss.value())) / T::lit(sin_root);
        let (s2, c2) = theta2.sin_cos();
        let q = SVector::from([-l0 * theta1.sin(), height, theta1, theta2, l0, l2]);
        // The hip moves about Leg 2's tip at rest: hip = tip - L2 (sin theta2, -cos theta2).
        let qd = SVector::from([
            -l2d * s2 - l2 * c2 * w2,
            l2d * c2 - l2 * s2 * w2,
            w1,
            w2,
            T::zero(),
            l2d,
        ]);
        Some((q, qd))
    }

    fn exact_step_map(
        &self,
        x: &DVector<f64>,
        param: Option<&str>,
        options: &LeggedOptions,
    ) -> Result<LeggedDerivative<6>, LeggedDerivativeError> {
        replayed_step_map::<_, 6, 13, 12, 6, 7, 84>(self, x, param, options)
    }
}
