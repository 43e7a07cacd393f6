//! The simplest walking model of Garcia, Chatterjee, Ruina and Coleman ("The simplest walking model: stability,
//! complexity, and scaling", J. Biomech. Eng. 120:281-288, 1998; docs/model.md section 13): a point mass at the
//! hip, two rigid massless legs of length 1 with point feet whose mass over the hip's tends to 0, `g = 1` (time
//! in units of `sqrt(l/g)`); one parameter, the slope `gamma`.
//!
//! Its legs are massless, so a mass matrix assembled from its bodies is singular: it gives the walk its reduced
//! equations and its transition instead (the paper's Eqs. (2)-(4)). Coordinates `(theta, phi)`: the stance
//! leg's angle from the slope normal (the hip at `(-sin theta, cos theta)` from the stance foot, `x` down the
//! slope) and the angle between the legs (the swing foot at `(sin(theta - phi), -cos(theta - phi))` from the
//! hip):
//!
//! ```text
//! theta'' = sin(theta - gamma)
//! phi''   = theta'' + theta'^2 sin(phi) - cos(theta - gamma) sin(phi)
//! ```
//!
//! Heel strike at `phi - 2 theta = 0` with the swing foot ahead; the legs exchange roles:
//! `theta+ = -theta-`, `theta'+ = cos(2 theta-) theta'-`, `phi+ = -2 theta-`,
//! `phi'+ = cos(2 theta-) (1 - cos(2 theta-)) theta'-`.
//!
//! **DLS indicator.** With both feet held at heel strike the hip stops, the two massless legs carrying its
//! impulse along themselves: `-v = P1 e1 + P2 e2` with `e1 = (-sin theta, cos theta)`, `e2 = (sin theta,
//! cos theta)` the legs from foot to hip and `v = theta' (-cos theta, -sin theta)` the hip's velocity, so
//! `P1 = -theta' cos(2 theta) / sin(2 theta)`, and the rear foot's normal impulse is `lambda_I4 = P1 cos theta`
//! (in units of the hip mass times `sqrt(g l)`). It is negative on every gait (`theta- < 0`, `theta'- < 0`):
//! the rear foot leaves, as the paper's transition assumes.

use nalgebra::{DVector, SVector};

use super::constrained::ConstrainedError;
use super::rigid::{HeelStrike, RigidOptions, RigidWalker, Transition};
use super::rigid_derivative::{step_map_derivative, DerivativeError, StepMapDerivative};
use super::Real;
use crate::params::ConfigError;

/// Index of `theta`, the stance leg's angle, in `q`.
pub const STANCE_ANGLE: usize = 0;
/// Index of `phi`, the angle between the legs, in `q`.
pub const INTER_LEG_ANGLE: usize = 1;

/// The simplest walking model on the slope `slope` \[rad\] (the paper's `gamma`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Simplest {
    /// The slope `gamma` \[rad\]. Default 0.009, the paper's example.
    pub slope: f64,
}

impl Default for Simplest {
    fn default() -> Simplest {
        Simplest { slope: 0.009 }
    }
}

impl Simplest {
    /// Checks the slope: finite, between -pi/2 and pi/2 rad.
    pub fn validate(&self) -> Result<(), ConfigError> {
        crate::params::finite("slope", self.slope)?;
        if self.slope.abs() >= std::f64::consts::FRAC_PI_2 {
            return Err(ConfigError::InvalidValue {
                key: "slope".to_string(),
                value: crate::fmt::short(self.slope),
                reason: "the slope must be between -pi/2 and pi/2 rad".to_string(),
            });
        }
        Ok(())
    }

    /// Where a gait search starts: the paper's gait at `gamma = 0.009` scaled by its law
    /// `theta ~ gamma^(1/3)` (the paper's section 5), `theta' = -theta`.
    pub fn default_start(&self) -> DVector<f64> {
        let theta = 0.2003 * (self.slope.abs() / 0.009).cbrt();
        DVector::from_column_slice(&[theta, -theta])
    }
}

/// The simplest walker's one constant over a [`Real`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimplestConstants<T: Real> {
    /// The slope `gamma` \[rad\].
    pub slope: T,
}

impl RigidWalker<2, 4> for Simplest {
    type Constants<T: Real> = SimplestConstants<T>;

    fn name(&self) -> &'static str {
        "simplest"
    }

    fn section_names(&self) -> Vec<&'static str> {
        vec!["theta", "theta_dot"]
    }

    fn rigid_constants<T: Real>(
        &self,
        value: &dyn Fn(&'static str, f64) -> T,
    ) -> SimplestConstants<T> {
        SimplestConstants {
            slope: value("slope", self.slope),
        }
    }

    /// The paper's Eqs. (2)-(3), and the stance leg's push along itself projected on the slope normal:
    /// `(cos(theta - gamma) - theta'^2) cos(theta)`.
    fn single_support_with<T: Real>(
        &self,
        c: &SimplestConstants<T>,
        q: &SVector<T, 2>,
        qd: &SVector<T, 2>,
    ) -> Result<(SVector<T, 2>, T), ConstrainedError> {
        let (theta, phi, w) = (q[STANCE_ANGLE], q[INTER_LEG_ANGLE], qd[STANCE_ANGLE]);
        let (s, cs) = (theta - c.slope).sin_cos();
        let theta_dd = s;
        let phi_dd = theta_dd + w * w * phi.sin() - cs * phi.sin();
        let push = (cs - w * w) * theta.cos();
        Ok((SVector::from([theta_dd, phi_dd]), push))
    }

    fn swing_foot_with<T: Real>(&self, _: &SimplestConstants<T>, q: &SVector<T, 2>) -> (T, T) {
        let (theta, phi) = (q[STANCE_ANGLE], q[INTER_LEG_ANGLE]);
        let height = theta.cos() - (theta - phi).cos();
        let ahead = -theta.sin() + (theta - phi).sin();
        (height, ahead)
    }

    fn hip_height(&self, q: &SVector<f64, 2>) -> f64 {
        q[STANCE_ANGLE].cos()
    }

    /// The paper's Eq. (4) and the DLS indicator of the module documentation.
    fn transition_with<T: Real>(
        &self,
        _: &SimplestConstants<T>,
        q: &SVector<T, 2>,
        qd: &SVector<T, 2>,
    ) -> Result<Transition<2, T>, ConstrainedError> {
        let (theta, w) = (q[STANCE_ANGLE], qd[STANCE_ANGLE]);
        let two = T::lit(2.0);
        let (s2, c2) = (two * theta).sin_cos();
        Ok(Transition {
            lambda_i4: -w * c2 / s2 * theta.cos(),
            q: SVector::from([-theta, -(two * theta)]),
            qd: SVector::from([c2 * w, c2 * (T::one() - c2) * w]),
        })
    }

    fn heel_strike(
        &self,
        q: &SVector<f64, 2>,
        qd: &SVector<f64, 2>,
    ) -> Result<HeelStrike<2>, ConstrainedError> {
        let t = self.transition_with(&self.rigid_constants_f64(), q, qd)?;
        let loss = self.mechanical_energy(q, qd) - self.mechanical_energy(q, &t.qd);
        Ok(HeelStrike {
            lambda_i4: t.lambda_i4,
            q: t.q,
            qd: (t.lambda_i4 < 0.0).then_some(t.qd),
            loss,
        })
    }

    /// `theta'^2 / 2 + cos(theta - gamma)`: the hip's energy (the feet's masses tend to 0), with the stance
    /// foot as the origin of height.
    fn mechanical_energy(&self, q: &SVector<f64, 2>, qd: &SVector<f64, 2>) -> f64 {
        0.5 * qd[STANCE_ANGLE] * qd[STANCE_ANGLE] + (q[STANCE_ANGLE] - self.slope).cos()
    }

    fn section_with<T: Real>(
        &self,
        _: &SimplestConstants<T>,
        q: &SVector<T, 2>,
        qd: &SVector<T, 2>,
    ) -> Vec<T> {
        vec![q[STANCE_ANGLE], qd[STANCE_ANGLE]]
    }

    /// `(theta, theta')` just after a heel strike: `phi = 2 theta`, `phi' = (1 - cos(2 theta)) theta'`.
    fn state_at_section_with<T: Real>(
        &self,
        _: &SimplestConstants<T>,
        s: &[T],
    ) -> (SVector<T, 2>, SVector<T, 2>) {
        let (theta, w) = (s[0], s[1]);
        let two = T::lit(2.0);
        (
            SVector::from([theta, two * theta]),
            SVector::from([w, (T::one() - (two * theta).cos()) * w]),
        )
    }

    fn step_map_derivative(
        &self,
        x: &DVector<f64>,
        param: Option<&str>,
        period: usize,
        options: &RigidOptions,
    ) -> Result<StepMapDerivative<2>, DerivativeError> {
        step_map_derivative::<Simplest, 2, 4, 3, 4, 16>(self, x, param, period, options)
    }
}

impl super::rigid_family::Parametrized for Simplest {
    fn parameter_keys(&self) -> Vec<&'static str> {
        vec!["slope"]
    }

    fn with_parameter(&self, key: &str, value: f64) -> Result<Simplest, ConfigError> {
        let walker = match key {
            "slope" => Simplest { slope: value },
            _ => {
                return Err(ConfigError::UnknownKey {
                    key: key.to_string(),
                    known: "slope".to_string(),
                })
            }
        };
        walker.validate()?;
        Ok(walker)
    }
}
