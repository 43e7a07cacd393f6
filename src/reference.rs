//! Reference problems with known closed-form answers, shared by tests and benchmarks.
//!
//! Like diffsol's and russell's test models, each problem is an [`OdeSystem`] together with its
//! exact solution and exact event times, so the integrator and the event location can be
//! checked against numbers that do not come from the integrator itself.

use nalgebra::SVector;

use crate::integrate::OdeSystem;
use crate::params::{Config, ImpactModel, Params};
use crate::walk::SectionState;

/// Point mass falling from height h0 with upward velocity v0 under gravity g: y=[z, vz], exact impact time
/// of z = 0.
///
/// Dynamics z' = vz, vz' = -g, so z(t) = h0 + v0 t - g t²/2 and vz(t) = v0 - g t.
/// Requires `h0 > 0` and `g > 0` for an impact to exist.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FallingPoint {
    /// Initial height z(0) \[m\].
    pub h0: f64,
    /// Initial upward velocity vz(0) \[m/s\].
    pub v0: f64,
    /// Gravitational acceleration, positive downward \[m/s²\].
    pub g: f64,
}

impl FallingPoint {
    /// The positive root of h0 + v0 t - g t²/2 = 0, `t = (v0 + s)/g = 2 h0/(s - v0)` with
    /// `s = sqrt(v0² + 2 g h0)`; the form without cancellation is used for the sign of v0.
    pub fn exact_impact_time(&self) -> f64 {
        let s = (self.v0 * self.v0 + 2.0 * self.g * self.h0).sqrt();
        if self.v0 >= 0.0 {
            (self.v0 + s) / self.g
        } else {
            2.0 * self.h0 / (s - self.v0)
        }
    }

    /// Exact state [z, vz] at time t.
    pub fn exact(&self, t: f64) -> SVector<f64, 2> {
        SVector::<f64, 2>::new(
            self.h0 + self.v0 * t - 0.5 * self.g * t * t,
            self.v0 - self.g * t,
        )
    }
}

impl OdeSystem<2> for FallingPoint {
    fn rhs(&self, _t: f64, y: &SVector<f64, 2>) -> SVector<f64, 2> {
        SVector::<f64, 2>::new(y[1], -self.g)
    }
}

/// Harmonic oscillator x'' = -w^2 x, exact zero crossings t_k = (k*pi + pi/2 - phase)/w of
/// x(t) = A cos(w t + phase).
///
/// State y = [x, v] with v = x'. For `-pi/2 < phase < pi/2`, `t_0` is the first crossing after
/// t = 0. The energy `(v² + w² x²)/2 = w² A²/2` is conserved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicOscillator {
    /// Angular frequency w \[rad/s\].
    pub omega: f64,
    /// Amplitude A of x \[m\].
    pub amplitude: f64,
    /// Phase of x(t) = A cos(w t + phase) at t = 0 \[rad\].
    pub phase: f64,
}

impl HarmonicOscillator {
    /// Exact state [x, v] = [A cos(w t + phase), -A w sin(w t + phase)] at time t.
    pub fn exact(&self, t: f64) -> SVector<f64, 2> {
        let (s, c) = (self.omega * t + self.phase).sin_cos();
        SVector::<f64, 2>::new(self.amplitude * c, -self.amplitude * self.omega * s)
    }

    /// Time of the k-th zero of x (k = 0, 1, ...): t_k = (k pi + pi/2 - phase)/w.
    pub fn zero_crossing(&self, k: usize) -> f64 {
        use std::f64::consts::{FRAC_PI_2, PI};
        (k as f64 * PI + FRAC_PI_2 - self.phase) / self.omega
    }
}

impl OdeSystem<2> for HarmonicOscillator {
    fn rhs(&self, _t: f64, y: &SVector<f64, 2>) -> SVector<f64, 2> {
        SVector::<f64, 2>::new(y[1], -self.omega * self.omega * y[0])
    }
}

/// The classical rigid rimless wheel (docs/model.md section 7): the VRW with `rigid_legs`, whose step map is known
/// in closed form. Angular momentum about the new contact point is conserved through the impact, so
/// `omega+ = eta omega-` with `eta = 1 - M L0^2 (1 - cos alpha) / I_P`; between impacts the wheel rotates
/// rigidly about its stance tip from `theta = -alpha/2` to `alpha/2`, gaining
/// `Delta E = 2 M g L0 sin(phi) sin(alpha/2)`. `M` is the total mass and `I_P = IH + N m (L0 - a)^2 + M L0^2`
/// the inertia about a tip (the centre of mass is at the hub by symmetry).
#[derive(Debug, Clone, PartialEq)]
pub struct RigidRimlessWheel {
    /// The parameters (only `rigid_legs`-relevant ones are used).
    pub params: Params,
}

impl RigidRimlessWheel {
    fn total_mass(&self) -> f64 {
        self.params.hub_mass + self.params.legs as f64 * self.params.leg_mass
    }

    /// Inertia about a leg tip, `I_P` \[kg m^2\].
    pub(crate) fn inertia_about_tip(&self) -> f64 {
        let p = &self.params;
        let r = p.stopper_length - p.leg_mass_offset;
        p.hub_inertia
            + p.legs as f64 * p.leg_mass * r * r
            + self.total_mass() * p.stopper_length.powi(2)
    }

    /// Velocity ratio of the impact, `eta = omega+ / omega-`.
    pub fn eta(&self) -> f64 {
        let p = &self.params;
        1.0 - self.total_mass() * p.stopper_length.powi(2) * (1.0 - p.alpha().cos())
            / self.inertia_about_tip()
    }

    /// `omega^2` gained between impacts: `2 Delta E / I_P`.
    fn omega_sq_gain(&self) -> f64 {
        let p = &self.params;
        4.0 * self.total_mass()
            * p.gravity
            * p.stopper_length
            * p.slope.sin()
            * (p.alpha() / 2.0).sin()
            / self.inertia_about_tip()
    }

    /// The step map on `omega = dtheta/dt` just before touchdown: `sqrt(eta^2 omega^2 + 2 Delta E / I_P)`, valid
    /// when the wheel passes over its top, which the walk checks for itself.
    pub fn step_map(&self, omega: f64) -> f64 {
        (self.eta().powi(2) * omega * omega + self.omega_sq_gain()).sqrt()
    }

    /// Its derivative, the Floquet multiplier of the gait at the fixed point: `eta^2 omega / P(omega)`.
    pub fn step_map_derivative(&self, omega: f64) -> f64 {
        self.eta().powi(2) * omega / self.step_map(omega)
    }

    /// The fixed point `omega* = sqrt(2 Delta E / (I_P (1 - eta^2)))`.
    pub fn fixed_point(&self) -> f64 {
        (self.omega_sq_gain() / (1.0 - self.eta().powi(2))).sqrt()
    }
}

/// The least default start length of Leg 2 as a fraction of `L0` (0.72 m with Table 1's `L0 = 1 m`): the start
/// tuned for the paper's parameters (`k = 500 N/m`), where the static compression of [`default_initial`] would
/// put Leg 2 lower (0.669 m). A softer leg is not started more compressed than this.
pub(crate) const DEFAULT_START_LENGTH_FRACTION: f64 = 0.72;

/// How far above `L0 cos(alpha)` (as a factor) the default start keeps Leg 2: at `L2 = L0 cos(alpha)` the section
/// has `theta = -alpha`, and the tip of the leg behind Leg 2 touches the ground too (below, it starts in it).
pub(crate) const VALID_START_MARGIN: f64 = 1.01;

/// The default starting point on the Poincare section (docs/model.md section 6), derived from the parameters:
///
/// - `L2 = min(L0, max(0.72 L0, 1.01 L0 cos(alpha), min_length, Lstar - M g cos(phi) / k))`, with `M = mH + N m` the
///   wheel's mass: Leg 2 at the length at which its spring alone carries the wheel's weight normal to the slope
///   (its static compression), but no shorter than `DEFAULT_START_LENGTH_FRACTION` of `L0` (the start tuned
///   for the paper's `k = 500 N/m`, where the static length is 0.669 m, so Table 1 starts at `(0.72, 1.0, 0.0)`
///   as before), no shorter than `VALID_START_MARGIN` times `L0 cos(alpha)` (with many legs a shorter Leg 2
///   would put the next leg's tip in the ground), no shorter than the compression stop, and no longer than the
///   stopper. A stiff leg (`k = 3000 N/m`,
///   `Lstar = L0`: 0.941 m) thus starts near its stopper, where its gait is, instead of far inside the spring's
///   range;
/// - `dtheta/dt = sqrt(L2 / (0.72 L0))` rad/s: 1.0 rad/s where `L2` is at its floor (Table 1), faster for a
///   leg that starts nearer its stopper. This is an empirical **choice**: a stiff wheel loses more energy per
///   step (it tends to the rigid wheel, whose gait is faster), and started at 1 rad/s from its static length it
///   rolls back within three steps (`k = 3000 N/m`, `Lstar = L0`: 1.14 rad/s walks to the gait, 1.0 does not);
/// - `dL2/dt = 0`;
///
/// with `rigid_legs`, `(L0, omega*, 0.0)` with `omega*` the closed-form gait of the rigid rimless wheel
/// ([`RigidRimlessWheel::fixed_point`]), since rigid legs stay at `L0` and a rigid wheel started much slower
/// than its gait rolls back.
pub fn default_initial(config: &Config) -> SectionState {
    let p = &config.params;
    if p.rigid_legs {
        let omega = RigidRimlessWheel { params: p.clone() }.fixed_point();
        SectionState {
            l2: p.stopper_length,
            theta_dot: if omega.is_finite() && omega > 0.0 {
                omega
            } else {
                1.0
            },
            l2_dot: 0.0,
            slip: 0.0,
        }
    } else {
        let mass = p.hub_mass + p.legs as f64 * p.leg_mass;
        let static_length =
            p.spring_natural_length - mass * p.gravity * p.slope.cos() / p.stiffness;
        let tuned = DEFAULT_START_LENGTH_FRACTION * p.stopper_length;
        // Below L0 cos(alpha) the leg behind Leg 2 would start below the ground.
        let floor = tuned.max(VALID_START_MARGIN * p.spoke_length() * p.alpha().cos());
        // A compression stop (`min_length`) holds a loaded leg at it.
        let l2 = static_length
            .max(floor)
            .max(p.min_length)
            .min(p.stopper_length);
        SectionState {
            l2,
            theta_dot: (l2 / tuned).sqrt(),
            l2_dot: 0.0,
            slip: 0.0,
        }
    }
}

/// A VRW with a period-2 gait (a fixed point of `P^2` that is not one of `P`, found by a parameter search;
/// docs/model.md section 6, period-k gaits): a light hub (`mH = 2 kg`), weak damping (`c = 3 N s/m`), a soft spring (`k = 300 N/m`),
/// slope 0.15 rad and the traditional impact; the other parameters are Table 1's. Its two steps alternate
/// between `dtheta/dt` of about 1.09 and 1.66 rad/s just before touchdown; the period-1 search fails there. The
/// walk settles on it from the default start. With `viscosity` from 1 to 10 N s/m it is the middle of a
/// period-doubling bubble (README, "Orbit diagram").
pub fn period_two_config() -> Config {
    let mut config = Config::default();
    let p = &mut config.params;
    p.hub_mass = 2.0;
    p.viscosity = 3.0;
    p.stiffness = 300.0;
    p.slope = 0.15;
    p.impact = ImpactModel::Traditional;
    config
}

/// A one-parameter family of maps of the plane with a fold and a period-doubling cascade in closed form: the
/// quadratic map `x -> p - x^2` with a contracting companion coordinate,
///
/// `P(x, y; p) = (p - x^2, y / 2 + x / 10)`.
///
/// Its fixed points are `x = (-1 ± sqrt(1 + 4p)) / 2`, `y = x / 5`, with multipliers `-2x` and `1/2`: the two
/// meet at the fold `p = -1/4` (`x = -1/2`, multiplier +1); the upper one loses stability by period doubling at
/// `p = 3/4` (`x = 1/2`, multiplier -1), where the period-2 orbit `x = (1 ± sqrt(4p - 3)) / 2` is born, which
/// doubles again at `p = 5/4` (the multiplier of `P^2` there is `4 x1 x2 = 4 (1 - p) = -1`). The reference
/// of the continuation tests (`crate::continuation`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct QuadraticFamily;

impl QuadraticFamily {
    /// The fold: `(p, x)`.
    pub const FOLD: (f64, f64) = (-0.25, -0.5);
    /// The period doubling of the fixed points: `(p, x)`.
    pub const PERIOD_DOUBLING: (f64, f64) = (0.75, 0.5);
    /// The period doubling of the period-2 orbit: `p`.
    pub const SECOND_PERIOD_DOUBLING: f64 = 1.25;

    /// `P(x, y; p)`, its Jacobian `DP` (row-major) and `dP/dp`.
    pub fn eval(&self, x: [f64; 2], p: f64) -> ([f64; 2], [[f64; 2]; 2], [f64; 2]) {
        (
            [p - x[0] * x[0], 0.5 * x[1] + 0.1 * x[0]],
            [[-2.0 * x[0], 0.0], [0.1, 0.5]],
            [1.0, 0.0],
        )
    }

    /// The upper fixed point at `p >= -1/4`: `(x, y)`.
    pub fn upper_fixed_point(&self, p: f64) -> [f64; 2] {
        let x = 0.5 * (-1.0 + (1.0 + 4.0 * p).sqrt());
        [x, 0.2 * x]
    }
}

/// The delayed logistic map, a one-parameter family of maps of the plane with a Neimark-Sacker bifurcation in
/// closed form: `P(x, y; p) = (p x (1 - y), x)`. Its fixed point `x = y = 1 - 1/p` has the Jacobian
/// `[[1, 1 - p], [1, 0]]`, whose determinant `p - 1` is the squared modulus of its complex pair (for
/// `5/4 < p < 5`): the pair crosses the unit circle at `p = 2`, with angle `pi / 3`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DelayedLogisticFamily;

impl DelayedLogisticFamily {
    /// The Neimark-Sacker point: `p`.
    pub const NEIMARK_SACKER: f64 = 2.0;

    /// `P(x, y; p)`, its Jacobian `DP` (row-major) and `dP/dp`.
    pub fn eval(&self, x: [f64; 2], p: f64) -> ([f64; 2], [[f64; 2]; 2], [f64; 2]) {
        (
            [p * x[0] * (1.0 - x[1]), x[0]],
            [[p * (1.0 - x[1]), -p * x[0]], [1.0, 0.0]],
            [x[0] * (1.0 - x[1]), 0.0],
        )
    }

    /// The fixed point `x = y = 1 - 1/p`.
    pub fn fixed_point(&self, p: f64) -> [f64; 2] {
        [1.0 - 1.0 / p, 1.0 - 1.0 / p]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    /// Central-difference step for checking exact solutions against the right-hand side \[s\].
    const FD_STEP: f64 = 1e-5;
    /// Tolerance of the central-difference derivative check (O(FD_STEP²) plus roundoff).
    const FD_TOL: f64 = 1e-8;
    /// Roundoff tolerance on closed-form identities.
    const ROUNDOFF_TOL: f64 = 1e-14;

    fn check_exact_solves_ode(
        sys: &impl OdeSystem<2>,
        exact: impl Fn(f64) -> SVector<f64, 2>,
        t: f64,
    ) {
        let fd = (exact(t + FD_STEP) - exact(t - FD_STEP)) / (2.0 * FD_STEP);
        let f = sys.rhs(t, &exact(t));
        assert_abs_diff_eq!(fd, f, epsilon = FD_TOL);
    }

    #[test]
    fn falling_point_exact_solution_and_impact_time() {
        for v0 in [0.5, 0.0, -0.3] {
            let p = FallingPoint {
                h0: 1.0,
                v0,
                g: 9.81,
            };
            for t in [0.0, 0.2, 0.4] {
                check_exact_solves_ode(&p, |t| p.exact(t), t);
            }
            let t_impact = p.exact_impact_time();
            assert!(t_impact > 0.0);
            assert_abs_diff_eq!(p.exact(t_impact)[0], 0.0, epsilon = ROUNDOFF_TOL);
        }
    }

    #[test]
    fn harmonic_oscillator_exact_solution_and_crossings() {
        let osc = HarmonicOscillator {
            omega: 3.0,
            amplitude: 0.7,
            phase: 0.3,
        };
        for t in [0.0, 0.5, 2.0] {
            check_exact_solves_ode(&osc, |t| osc.exact(t), t);
        }
        assert!(osc.zero_crossing(0) > 0.0);
        for k in 0..10 {
            assert_abs_diff_eq!(
                osc.exact(osc.zero_crossing(k))[0],
                0.0,
                epsilon = ROUNDOFF_TOL
            );
        }
    }
}
