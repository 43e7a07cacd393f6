//! Parameters and configuration: the first stage of the pipeline.
//!
//! [`Params`] holds the physical model of the viscoelastic-legged rimless wheel (`docs/model.md` sections 1, 2
//! and 7, defaults from the paper's Table 1), [`SolverOptions`] the numerical settings, including every
//! tolerance that guards grazing and chatter (`docs/model.md` section 4), and [`Config`] both of them together.
//!
//! A configuration file is a *flat* TOML file whose keys are the field names of both structs; keys that
//! are absent keep their defaults:
//!
//! ```toml
//! viscosity = 50          # integers are accepted for real-valued keys
//! impact = "traditional"
//! rigid_legs = false
//! inconsistent_contact = "slide"
//! rtol = 1e-11
//! ```
//!
//! Loading ([`Config::from_toml_str`], [`Config::from_file`]) validates the result. Single assignments
//! ([`Config::set`], [`Config::apply_override`] for the command line's `--set key=value`,
//! [`Config::set_numeric`] for sweeps) do not, because the rules couple keys (for instance
//! `spring_natural_length >= stopper_length`): apply all of them, then call [`Config::validate`].

use std::f64::consts::{FRAC_PI_2, PI};
use std::fmt;
use std::path::Path;

use crate::fmt::short;
use crate::integrate::Method;

/// Impact law at touchdown (`docs/model.md` section 5).
///
/// In TOML and on the command line the values are the strings `"dlsi"` (default) and `"traditional"`;
/// [`Display`](fmt::Display) gives the same strings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ImpactModel {
    /// The paper's DLS-indicator procedure, algorithm (A1)-(A4), (B1)-(B3): the impact is first solved
    /// with both tips constrained (`J_DLS`), and the rear leg leaves only if the indicators say so.
    Dlsi,
    /// The traditional exchange: the impact is always solved with the fore tip alone constrained
    /// (`J_SLS`), so the rear leg leaves the ground at once.
    Traditional,
}

impl Choice for ImpactModel {
    const ALL: &'static [ImpactModel] = &[ImpactModel::Dlsi, ImpactModel::Traditional];
    const EXPECTED: &'static str = "the string \"dlsi\" or \"traditional\"";

    fn name(self) -> &'static str {
        match self {
            ImpactModel::Dlsi => "dlsi",
            ImpactModel::Traditional => "traditional",
        }
    }
}

impl fmt::Display for ImpactModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What happens when no no-slip contact state is consistent (`docs/model.md` sections 3-4).
///
/// At a lift-off where the tangential force of the no-slip contact is not zero (the paper's "scuffing" /
/// open case), holding the tip needs a pulling normal force and releasing it drives the tip into the ground.
///
/// In TOML and on the command line the values are the strings `"slide"` (default) and `"rebound"`;
/// [`Display`](fmt::Display) gives the same strings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ContactInconsistency {
    /// The tip slides frictionlessly along the ground (normal constraint only) until its normal force
    /// vanishes: the limit of any friction cone as the normal force goes to zero. Default.
    Slide,
    /// `docs/model.md` section 4 literally: the tip is released, re-contacts at once (plastic impact), and the
    /// force check (B1)-(B3) releases it again; the resulting chatter is bounded by `max_events_per_step`.
    Rebound,
}

impl Choice for ContactInconsistency {
    const ALL: &'static [ContactInconsistency] =
        &[ContactInconsistency::Slide, ContactInconsistency::Rebound];
    const EXPECTED: &'static str = "the string \"slide\" or \"rebound\"";

    fn name(self) -> &'static str {
        match self {
            ContactInconsistency::Slide => "slide",
            ContactInconsistency::Rebound => "rebound",
        }
    }
}

impl Choice for Method {
    const ALL: &'static [Method] = &[Method::Dop853, Method::Dopri5];
    const EXPECTED: &'static str = "the string \"dop853\" or \"dopri5\"";

    fn name(self) -> &'static str {
        // The inherent `Method::name`, which the integrator module uses too.
        Method::name(self)
    }
}

/// A key whose value is one of a few names (`impact`, `inconsistent_contact`, `integrator`).
trait Choice: Copy + 'static {
    /// Every value.
    const ALL: &'static [Self];
    /// What the key accepts, as shown in errors.
    const EXPECTED: &'static str;

    /// The name of this value, as in TOML and on the command line.
    fn name(self) -> &'static str;

    /// The value called `name`, if there is one.
    fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|c| c.name() == name)
    }
}

impl fmt::Display for ContactInconsistency {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Physical parameters of the wheel and the slope (`docs/model.md` sections 1, 2 and 7).
///
/// Defaults are the paper's Table 1; the viscosity `c` is the parameter the paper sweeps. Check a value
/// built by hand with [`Params::validate`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Params {
    /// Number of legs `N` \[-\]. Default 8, i.e. the inter-leg angle `alpha = 2 pi / N = pi/4` of Table 1
    /// (see [`Params::alpha`]). From 3 to [`MAX_LEGS`]. `docs/model.md` section 1.
    pub legs: usize,
    /// Hub mass `mH` \[kg\]. Default 10 (Table 1). Positive. `docs/model.md` section 2.
    pub hub_mass: f64,
    /// Rotational inertia `IH` of the hub about its centre \[kg m^2\]. Default 0: the paper gives none, so
    /// this is an **assumption** (`docs/model.md` section 2). Non-negative.
    pub hub_inertia: f64,
    /// Leg mass `m` \[kg\], a point mass on the sliding part of each leg. Default 1 (Table 1). Positive.
    /// `docs/model.md` section 2.
    pub leg_mass: f64,
    /// Distance `a` of the leg mass from the leg's tip \[m\]. Default 0.3 (Table 1). In
    /// `[0, stopper_length)`. `docs/model.md` section 2.
    pub leg_mass_offset: f64,
    /// Stopper length `L0` \[m\]: the longest a leg can be (hub to tip); legs other than Leg 1 and Leg 2
    /// are locked at it. Default 1.0 (Table 1). Positive. `docs/model.md` section 2.
    pub stopper_length: f64,
    /// Natural length `Lstar` of the leg spring \[m\]. Default 1.02 (Table 1). At least `stopper_length`:
    /// the spring is preloaded by `k (Lstar - L0)` (10 N by default) so that an unloaded leg rests on its
    /// stopper. `docs/model.md` section 2.
    pub spring_natural_length: f64,
    /// Spring stiffness `k` of Legs 1 and 2 \[N/m\]. Default 500 (Table 1). Positive. `docs/model.md` section 2.
    pub stiffness: f64,
    /// Damper viscosity `c` of Legs 1 and 2 \[N s/m\]: the force along a leg is
    /// `k (Lstar - L) - c dL/dt`. Default 50; the paper sweeps it (thresholds near 4.0 and 220).
    /// Non-negative. `docs/model.md` sections 2 and 6.
    pub viscosity: f64,
    /// Slope angle `phi` \[rad\]; the wheel walks down a slope with `phi > 0`. Default 0.10 (Table 1).
    /// `|phi| < pi/2`. `docs/model.md` section 1.
    pub slope: f64,
    /// Gravitational acceleration `g` \[m/s^2\]. Default 9.81. Positive. `docs/model.md` section 1.
    pub gravity: f64,
    /// Impact law at touchdown. Default [`ImpactModel::Dlsi`]. `docs/model.md` section 5.
    pub impact: ImpactModel,
    /// Rigid special case: when `true`, every leg stays locked at `stopper_length` (the stopper acts both
    /// ways, through impacts too) and the exchange is the traditional one, which makes the model the
    /// classical rigid rimless wheel with a closed-form step map. Default `false`. `docs/model.md` section 7.
    pub rigid_legs: bool,
    /// What happens when no no-slip contact state is consistent (a lift-off with a non-zero tangential
    /// contact force). Default [`ContactInconsistency::Slide`]. `docs/model.md` sections 3-4.
    pub inconsistent_contact: ContactInconsistency,
}

impl Default for Params {
    /// The paper's Table 1, with `c = 50 N s/m`, `g = 9.81 m/s^2`, `IH = 0`, the DLS-indicator impact and
    /// frictionless sliding at an inconsistent contact.
    fn default() -> Self {
        Params {
            legs: 8,
            hub_mass: 10.0,
            hub_inertia: 0.0,
            leg_mass: 1.0,
            leg_mass_offset: 0.3,
            stopper_length: 1.0,
            spring_natural_length: 1.02,
            stiffness: 500.0,
            viscosity: 50.0,
            slope: 0.10,
            gravity: 9.81,
            impact: ImpactModel::Dlsi,
            rigid_legs: false,
            inconsistent_contact: ContactInconsistency::Slide,
        }
    }
}

impl Params {
    /// Inter-leg angle `alpha = 2 pi / legs` \[rad\] (`docs/model.md` section 1); `pi/4` by default.
    pub fn alpha(&self) -> f64 {
        2.0 * PI / self.legs as f64
    }

    /// Checks every rule on the physical parameters; the error names the first offending key.
    ///
    /// Rules: `3 <= legs <=` [`MAX_LEGS`]; every real value finite; `hub_mass`, `leg_mass`, `gravity`, `stopper_length`,
    /// `stiffness > 0`; `hub_inertia`, `viscosity >= 0`; `|slope| < pi/2`;
    /// `0 <= leg_mass_offset < stopper_length`; `spring_natural_length >= stopper_length`;
    /// `leg_mass / hub_mass` within [`MASS_RATIO_LIMIT`] of 1.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !(3..=MAX_LEGS).contains(&self.legs) {
            return Err(invalid(
                "legs",
                self.legs,
                format!("must be between 3 and {MAX_LEGS}"),
            ));
        }
        positive("hub_mass", self.hub_mass)?;
        non_negative("hub_inertia", self.hub_inertia)?;
        positive("leg_mass", self.leg_mass)?;
        non_negative("leg_mass_offset", self.leg_mass_offset)?;
        positive("stopper_length", self.stopper_length)?;
        finite("spring_natural_length", self.spring_natural_length)?;
        positive("stiffness", self.stiffness)?;
        non_negative("viscosity", self.viscosity)?;
        finite("slope", self.slope)?;
        if self.slope.abs() >= FRAC_PI_2 {
            return Err(invalid(
                "slope",
                short(self.slope),
                "must satisfy |slope| < pi/2 (a slope angle in radians)",
            ));
        }
        positive("gravity", self.gravity)?;
        let ratio = self.leg_mass / self.hub_mass;
        if !(1.0 / MASS_RATIO_LIMIT..=MASS_RATIO_LIMIT).contains(&ratio) {
            return Err(invalid(
                "leg_mass",
                short(self.leg_mass),
                format!(
                    "leg_mass / hub_mass = {} is outside [{}, {}]: the mass matrix would be singular to rounding",
                    short(ratio),
                    short(1.0 / MASS_RATIO_LIMIT),
                    short(MASS_RATIO_LIMIT)
                ),
            ));
        }
        below_stopper("leg_mass_offset", self.leg_mass_offset, self.stopper_length)?;
        if self.spring_natural_length < self.stopper_length {
            return Err(invalid(
                "spring_natural_length",
                short(self.spring_natural_length),
                format!("must be >= stopper_length ({})", short(self.stopper_length)),
            ));
        }
        Ok(())
    }
}

/// `leg_mass / hub_mass` must lie in `[1 / MASS_RATIO_LIMIT, MASS_RATIO_LIMIT]`: beyond it `M(q)` is singular
/// to rounding and the constraint solves fail.
pub const MASS_RATIO_LIMIT: f64 = 1e6;

/// The largest accepted number of legs.
pub const MAX_LEGS: usize = 1000;

/// Numerical settings of the integration and of the walk's event handling (`docs/model.md` section 4).
///
/// Every tolerance that guards grazing or chatter is a named field here. Check a value built by hand
/// with [`SolverOptions::validate`] (and [`Config::validate`] for the rule that involves [`Params`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SolverOptions {
    /// The Runge-Kutta pair that integrates the continuous phases: `"dop853"` (default; order 8, the fastest at
    /// the default tolerances) or `"dopri5"` (order 5). Both locate events on their dense output; running a
    /// result again with the other one is a check that it does not depend on the integrator.
    pub integrator: Method,
    /// Relative integration tolerance \[-\]. Default 1e-10. In [`RTOL_RANGE`] (1e-14 to 1e-3).
    pub rtol: f64,
    /// Absolute integration tolerance \[state units: m, rad, m/s, rad/s\]. Default 1e-12. In [`ATOL_RANGE`]
    /// (1e-16 to 1e-3).
    pub atol: f64,
    /// Largest integrator step \[s\]. Default 0.04 (events are still resolved to a quarter of a step, see
    /// `walk::EVENT_SAMPLES`). In [`MAX_STEP_RANGE`] (1e-6 to 1).
    pub max_step: f64,
    /// Tolerance on located event times (root finding on the dense output) \[s\]. Default 1e-13. In
    /// [`EVENT_TIME_TOL_RANGE`] (1e-15 to 1e-9). `docs/model.md`, events.
    pub event_time_tol: f64,
    /// Grazing guard for re-contact \[m\]. Default 1e-11. In [`GAP_RANGE`] (1e-12 to 1e-6). After a lift-off
    /// the tip leaves the ground with zero velocity and acceleration, so a lifted tip's re-contact event is
    /// armed only once its height exceeds this gap; before that it fires only if the tip sinks `recontact_gap`
    /// below where it started (this bounds the audit's `penetration` there).
    /// `docs/model.md` section 4 (grazing).
    pub recontact_gap: f64,
    /// The same grazing guard for an unlocked leg re-reaching its stopper \[m\]. Default 1e-9. In
    /// [`GAP_RANGE`].
    /// The stopper-lock event is armed only once `stopper_length - L > stopper_gap`. `docs/model.md` section 4.
    pub stopper_gap: f64,
    /// The run ends with the status `Fell` when the hub height above the slope drops below this \[m\].
    /// Default 0.3. In `[0, stopper_length)`. `docs/model.md` section 4 (fall / stall).
    pub fall_hub_height: f64,
    /// The run ends with the status `Stalled` when no touchdown happens within this time of the previous
    /// one \[s\]. Default 60 (heavily damped gaits creep through long double support). In
    /// [`MAX_STEP_TIME_RANGE`] (1e-3 to 1e4).
    /// `docs/model.md` section 4 (fall / stall).
    pub max_step_time: f64,
    /// More events than this within one step ends the run with the status `Chatter` (a Zeno sequence of
    /// contacts) \[-\]. Default 200. From 1 to [`MAX_EVENTS_PER_STEP_LIMIT`]. `docs/model.md` section 4.
    pub max_events_per_step: usize,
}

impl Default for SolverOptions {
    /// Tolerances tight enough to locate the paper's thresholds by root finding in `c`.
    fn default() -> Self {
        SolverOptions {
            integrator: Method::Dop853,
            rtol: 1e-10,
            atol: 1e-12,
            max_step: 0.04,
            event_time_tol: 1e-13,
            recontact_gap: 1e-11,
            stopper_gap: 1e-9,
            fall_hub_height: 0.3,
            max_step_time: 60.0,
            max_events_per_step: 200,
        }
    }
}

impl SolverOptions {
    /// Checks the numerical settings on their own; the error names the first offending key.
    ///
    /// Rules: every real value finite; `rtol` in [`RTOL_RANGE`], `atol` in [`ATOL_RANGE`], `max_step` in
    /// [`MAX_STEP_RANGE`], `event_time_tol` in [`EVENT_TIME_TOL_RANGE`], `recontact_gap` and `stopper_gap`
    /// in [`GAP_RANGE`], `max_step_time` in [`MAX_STEP_TIME_RANGE`]; `fall_hub_height >= 0`;
    /// `1 <= max_events_per_step <=` [`MAX_EVENTS_PER_STEP_LIMIT`]. The upper bound
    /// `fall_hub_height < stopper_length` needs the [`Params`] and is checked by [`Config::validate`].
    pub fn validate(&self) -> Result<(), ConfigError> {
        within("rtol", self.rtol, RTOL_RANGE)?;
        within("atol", self.atol, ATOL_RANGE)?;
        within("max_step", self.max_step, MAX_STEP_RANGE)?;
        within("event_time_tol", self.event_time_tol, EVENT_TIME_TOL_RANGE)?;
        within("recontact_gap", self.recontact_gap, GAP_RANGE)?;
        within("stopper_gap", self.stopper_gap, GAP_RANGE)?;
        non_negative("fall_hub_height", self.fall_hub_height)?;
        within("max_step_time", self.max_step_time, MAX_STEP_TIME_RANGE)?;
        if !(1..=MAX_EVENTS_PER_STEP_LIMIT).contains(&self.max_events_per_step) {
            return Err(invalid(
                "max_events_per_step",
                self.max_events_per_step,
                format!("must be between 1 and {MAX_EVENTS_PER_STEP_LIMIT}"),
            ));
        }
        Ok(())
    }
}

/// Accepted range of `rtol` \[-\]: below 1e-14 the Dormand-Prince error estimate is rounding noise (machine
/// epsilon is 2.2e-16); above 1e-3 the DLS indicators and thresholds are no longer meaningful.
pub const RTOL_RANGE: [f64; 2] = [1e-14, 1e-3];
/// Accepted range of `atol` \[state units\]: the same reasoning as [`RTOL_RANGE`], on states of order 1.
pub const ATOL_RANGE: [f64; 2] = [1e-16, 1e-3];
/// Accepted range of `max_step` \[s\]: a step is ~2.7 s of motion; below 1e-6 s a walk takes millions of
/// integrator steps per touchdown.
pub const MAX_STEP_RANGE: [f64; 2] = [1e-6, 1.0];
/// Accepted range of `event_time_tol` \[s\]: events are located on the dense output to this; at tip speeds of
/// order 1 m/s, 1e-9 s is already a position error of the size of the grazing guards ([`GAP_RANGE`]), so a
/// looser tolerance would change results silently; below 1e-15 s is below the rounding of the time itself.
pub const EVENT_TIME_TOL_RANGE: [f64; 2] = [1e-15, 1e-9];
/// Accepted range of the grazing guards `recontact_gap` and `stopper_gap` \[m\]: they must exceed the
/// position error of the integration and of event location (about 1e-12 m with the defaults) and stay far below
/// the leg's scales (a guard of a millimetre would let a tip sink into the ground unseen).
pub const GAP_RANGE: [f64; 2] = [1e-12, 1e-6];
/// Accepted range of `max_step_time` \[s\]: a step of the paper's gait takes 2.7 s; the heavily damped gaits
/// creep for tens of seconds.
pub const MAX_STEP_TIME_RANGE: [f64; 2] = [1e-3, 1e4];
/// The largest accepted `max_events_per_step`.
pub const MAX_EVENTS_PER_STEP_LIMIT: usize = 1_000_000;

/// Everything a run needs: physics ([`Params`]) and numerics ([`SolverOptions`]).
///
/// It reads from, and serializes to, a flat TOML table whose keys are the field names of both structs
/// (e.g. `viscosity = 50.0`, `impact = "traditional"`, `rigid_legs = true`,
/// `inconsistent_contact = "rebound"`, `rtol = 1e-11`).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct Config {
    /// Physical parameters (`docs/model.md` sections 1, 2 and 7). Default: the paper's Table 1.
    #[serde(flatten)]
    pub params: Params,
    /// Numerical settings (`docs/model.md` section 4). Default: [`SolverOptions::default`].
    #[serde(flatten)]
    pub solver: SolverOptions,
}

/// Every key of a configuration, in declaration order: the fields of [`Params`], then of
/// [`SolverOptions`].
const ALL_KEYS: [&str; 24] = [
    "legs",
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
    "impact",
    "rigid_legs",
    "inconsistent_contact",
    "integrator",
    "rtol",
    "atol",
    "max_step",
    "event_time_tol",
    "recontact_gap",
    "stopper_gap",
    "fall_hub_height",
    "max_step_time",
    "max_events_per_step",
];

/// Declares the real-valued (sweepable) keys once and generates, from that single list, the key list
/// returned by [`Config::numeric_keys`] and the accessors behind [`Config::get_numeric`] and
/// [`Config::set_numeric`].
macro_rules! real_keys {
    ($($key:literal => $part:ident . $field:ident),* $(,)?) => {
        /// Keys of every `f64` field, in declaration order.
        const NUMERIC_KEYS: &[&str] = &[$($key),*];

        impl Config {
            /// The `f64` field called `key`, if there is one.
            fn real_ref(&self, key: &str) -> Option<&f64> {
                match key {
                    $($key => Some(&self.$part.$field),)*
                    _ => None,
                }
            }

            /// The `f64` field called `key`, mutably, if there is one.
            fn real_mut(&mut self, key: &str) -> Option<&mut f64> {
                match key {
                    $($key => Some(&mut self.$part.$field),)*
                    _ => None,
                }
            }
        }
    };
}

real_keys! {
    "hub_mass" => params.hub_mass,
    "hub_inertia" => params.hub_inertia,
    "leg_mass" => params.leg_mass,
    "leg_mass_offset" => params.leg_mass_offset,
    "stopper_length" => params.stopper_length,
    "spring_natural_length" => params.spring_natural_length,
    "stiffness" => params.stiffness,
    "viscosity" => params.viscosity,
    "slope" => params.slope,
    "gravity" => params.gravity,
    "rtol" => solver.rtol,
    "atol" => solver.atol,
    "max_step" => solver.max_step,
    "event_time_tol" => solver.event_time_tol,
    "recontact_gap" => solver.recontact_gap,
    "stopper_gap" => solver.stopper_gap,
    "fall_hub_height" => solver.fall_hub_height,
    "max_step_time" => solver.max_step_time,
}

impl Config {
    /// Parses a flat TOML document: starts from the defaults, applies every key, then validates.
    ///
    /// Integers are accepted for real-valued keys (`viscosity = 50`); a float for an integer key
    /// (`legs = 8.0`) or a string for a number is [`ConfigError::WrongType`]. Syntax errors are
    /// [`ConfigError::Toml`] with `path` `"<string>"` and toml's line/column message.
    pub fn from_toml_str(text: &str) -> Result<Config, ConfigError> {
        Self::parse_toml(text, "<string>")
    }

    /// Reads and parses a flat TOML file, as [`Config::from_toml_str`] does; errors carry the path.
    pub fn from_file(path: &Path) -> Result<Config, ConfigError> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
            path: shown.clone(),
            source,
        })?;
        Self::parse_toml(&text, &shown)
    }

    /// Applies one `key=value` override (the command line's repeatable `--set key=value`); spaces
    /// around the key and the value are ignored, and the value is parsed as by [`Config::set`].
    ///
    /// A missing `=` or an empty key is [`ConfigError::MalformedOverride`]. Does not validate: call
    /// [`Config::validate`] after the last override.
    pub fn apply_override(&mut self, assignment: &str) -> Result<(), ConfigError> {
        match assignment.split_once('=') {
            Some((key, value)) if !key.trim().is_empty() => self.set(key.trim(), value.trim()),
            _ => Err(ConfigError::MalformedOverride {
                assignment: assignment.to_string(),
            }),
        }
    }

    /// Sets `key` from its textual `value`, parsed by the key's type: a real number for `f64` keys
    /// (`"50"`, `"5e1"`, `"0.1"`), a non-negative integer for `legs` and `max_events_per_step`, `true` or
    /// `false` for `rigid_legs`, `dlsi` or `traditional` for `impact`, `slide` or `rebound` for
    /// `inconsistent_contact`.
    ///
    /// Does not validate, because the rules couple keys: call [`Config::validate`] after the last change.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), ConfigError> {
        self.assign(key, value)
    }

    /// Sets `key` from a TOML value, converted exactly as a configuration file's value is (for fronts that
    /// receive typed values, e.g. the Python binding's keyword arguments).
    ///
    /// Does not validate: call [`Config::validate`] after the last change.
    pub fn set_value(&mut self, key: &str, value: &toml::Value) -> Result<(), ConfigError> {
        self.assign(key, value)
    }

    /// Names of the keys holding a real number (sweepable): every `f64` field of [`Params`] and
    /// [`SolverOptions`], in declaration order.
    pub fn numeric_keys() -> &'static [&'static str] {
        NUMERIC_KEYS
    }

    /// The value of the real-valued key `key` (one of [`Config::numeric_keys`]).
    pub fn get_numeric(&self, key: &str) -> Result<f64, ConfigError> {
        self.real_ref(key)
            .copied()
            .ok_or_else(|| unknown_numeric_key(key))
    }

    /// A copy with the real-valued key `key` set to `value` and validated: the configuration at one point of a
    /// sweep, a map or a continuation.
    pub fn with(&self, key: &str, value: f64) -> Result<Config, ConfigError> {
        let mut c = self.clone();
        c.set_numeric(key, value)?;
        c.validate()?;
        Ok(c)
    }

    /// Sets the real-valued key `key` (one of [`Config::numeric_keys`]) to `value`, as a sweep does.
    ///
    /// Does not validate: call [`Config::validate`] afterwards.
    pub fn set_numeric(&mut self, key: &str, value: f64) -> Result<(), ConfigError> {
        let slot = self.real_mut(key).ok_or_else(|| unknown_numeric_key(key))?;
        *slot = value;
        Ok(())
    }

    /// Checks every rule: [`Params::validate`], [`SolverOptions::validate`] and
    /// `fall_hub_height < stopper_length`. The error names the first offending key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.params.validate()?;
        self.solver.validate()?;
        below_stopper(
            "fall_hub_height",
            self.solver.fall_hub_height,
            self.params.stopper_length,
        )
    }

    /// Parses a flat TOML document read from `origin` (a path, or `"<string>"`), applies it over the
    /// defaults and validates the result.
    fn parse_toml(text: &str, origin: &str) -> Result<Config, ConfigError> {
        let table: toml::Table =
            text.parse()
                .map_err(|error: toml::de::Error| ConfigError::Toml {
                    path: origin.to_string(),
                    message: error.to_string().trim_end().to_string(),
                })?;
        let mut config = Config::default();
        for (key, value) in &table {
            config.assign(key, value)?;
        }
        config.validate()?;
        Ok(config)
    }

    /// Stores `value` in the field called `key`, converted by that field's type.
    fn assign<V: RawValue + ?Sized>(&mut self, key: &str, value: &V) -> Result<(), ConfigError> {
        if let Some(slot) = self.real_mut(key) {
            *slot = value.real(key)?;
            return Ok(());
        }
        match key {
            "legs" => self.params.legs = value.count(key)?,
            "max_events_per_step" => self.solver.max_events_per_step = value.count(key)?,
            "rigid_legs" => self.params.rigid_legs = value.flag(key)?,
            "impact" => self.params.impact = value.choice(key)?,
            "inconsistent_contact" => self.params.inconsistent_contact = value.choice(key)?,
            "integrator" => self.solver.integrator = value.choice(key)?,
            _ => {
                return Err(ConfigError::UnknownKey {
                    key: key.to_string(),
                    known: ALL_KEYS.join(", "),
                })
            }
        }
        Ok(())
    }
}

/// What a configuration can go wrong with. Every variant names the key or the source it concerns.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// A key that is not a field of [`Params`] or [`SolverOptions`].
    #[error("unknown key `{key}` (known keys: {known})")]
    UnknownKey {
        /// The key as given.
        key: String,
        /// The keys that would have been accepted, comma-separated.
        known: String,
    },
    /// A value of the right type that breaks a rule.
    #[error("invalid value {value} for `{key}`: {reason}")]
    InvalidValue {
        /// The offending key.
        key: String,
        /// The value as given or stored.
        value: String,
        /// The rule it breaks, e.g. "must be positive" or "must be >= stopper_length (1)".
        reason: String,
    },
    /// A value whose type does not fit the key (a string for a number, a float for an integer, ...).
    #[error("wrong type for `{key}`: expected {expected}, found {found}")]
    WrongType {
        /// The offending key.
        key: String,
        /// The type the key holds.
        expected: &'static str,
        /// What was given instead.
        found: String,
    },
    /// A `--set` override that is not of the form `key=value`.
    #[error("malformed override `{assignment}`: expected key=value")]
    MalformedOverride {
        /// The override as given.
        assignment: String,
    },
    /// A TOML document that does not parse.
    #[error("malformed TOML in {path}: {message}")]
    Toml {
        /// The file, or `"<string>"` for [`Config::from_toml_str`].
        path: String,
        /// toml's message, with line and column.
        message: String,
    },
    /// A configuration file that cannot be read.
    #[error("cannot read configuration file {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// A value for one key, from a TOML document or from the text of a `--set key=value` override,
/// converted by the type of the key it is meant for.
trait RawValue {
    /// A real number (integers are accepted).
    fn real(&self, key: &str) -> Result<f64, ConfigError>;
    /// A non-negative integer.
    fn count(&self, key: &str) -> Result<usize, ConfigError>;
    /// A boolean.
    fn flag(&self, key: &str) -> Result<bool, ConfigError>;
    /// One of a few names (an impact law, an integrator, ...).
    fn choice<T: Choice>(&self, key: &str) -> Result<T, ConfigError>;
}

/// Text of a `--set` override.
impl RawValue for str {
    fn real(&self, key: &str) -> Result<f64, ConfigError> {
        self.parse()
            .map_err(|_| wrong_type(key, EXPECTED_REAL, format!("{self:?}")))
    }

    fn count(&self, key: &str) -> Result<usize, ConfigError> {
        match self.parse::<i64>() {
            Ok(n) => count_from_integer(key, n),
            Err(error)
                if matches!(
                    error.kind(),
                    std::num::IntErrorKind::PosOverflow | std::num::IntErrorKind::NegOverflow
                ) =>
            {
                Err(invalid(key, self, "is out of range"))
            }
            Err(_) => Err(wrong_type(key, EXPECTED_COUNT, format!("{self:?}"))),
        }
    }

    fn flag(&self, key: &str) -> Result<bool, ConfigError> {
        self.parse()
            .map_err(|_| wrong_type(key, EXPECTED_FLAG, format!("{self:?}")))
    }

    fn choice<T: Choice>(&self, key: &str) -> Result<T, ConfigError> {
        choice_from_name(key, self)
    }
}

/// A value of a TOML document.
impl RawValue for toml::Value {
    fn real(&self, key: &str) -> Result<f64, ConfigError> {
        match self {
            toml::Value::Float(x) => Ok(*x),
            toml::Value::Integer(n) => Ok(*n as f64),
            other => Err(wrong_type(key, EXPECTED_REAL, describe(other))),
        }
    }

    fn count(&self, key: &str) -> Result<usize, ConfigError> {
        match self {
            toml::Value::Integer(n) => count_from_integer(key, *n),
            other => Err(wrong_type(key, EXPECTED_COUNT, describe(other))),
        }
    }

    fn flag(&self, key: &str) -> Result<bool, ConfigError> {
        match self {
            toml::Value::Boolean(b) => Ok(*b),
            other => Err(wrong_type(key, EXPECTED_FLAG, describe(other))),
        }
    }

    fn choice<T: Choice>(&self, key: &str) -> Result<T, ConfigError> {
        match self {
            toml::Value::String(name) => choice_from_name(key, name),
            other => Err(wrong_type(key, T::EXPECTED, describe(other))),
        }
    }
}

/// Expected type of a real-valued key, as shown in [`ConfigError::WrongType`].
const EXPECTED_REAL: &str = "a real number";
/// Expected type of an integer key, as shown in [`ConfigError::WrongType`].
const EXPECTED_COUNT: &str = "a non-negative integer";
/// Expected type of a boolean key, as shown in [`ConfigError::WrongType`].
const EXPECTED_FLAG: &str = "true or false";

/// A TOML value's type and value, for [`ConfigError::WrongType`].
fn describe(value: &toml::Value) -> String {
    match value {
        toml::Value::String(s) => format!("the string {s:?}"),
        toml::Value::Integer(n) => format!("the integer {n}"),
        toml::Value::Float(x) => format!("the float {x}"),
        toml::Value::Boolean(b) => format!("the boolean {b}"),
        toml::Value::Datetime(d) => format!("the datetime {d}"),
        toml::Value::Array(_) => "an array".to_string(),
        toml::Value::Table(_) => "a table (the file must be flat: no [sections])".to_string(),
    }
}

/// An integer for an integer key: negative values are rejected.
fn count_from_integer(key: &str, n: i64) -> Result<usize, ConfigError> {
    usize::try_from(n).map_err(|_| invalid(key, n, "must be a non-negative integer"))
}

/// The value called `name` of a [`Choice`] key, or an [`ConfigError::InvalidValue`] listing the known names.
fn choice_from_name<T: Choice>(key: &str, name: &str) -> Result<T, ConfigError> {
    T::from_name(name)
        .ok_or_else(|| invalid(key, format!("{name:?}"), format!("must be {}", T::EXPECTED)))
}

/// The error for a key that is not one of [`Config::numeric_keys`].
fn unknown_numeric_key(key: &str) -> ConfigError {
    ConfigError::UnknownKey {
        key: key.to_string(),
        known: NUMERIC_KEYS.join(", "),
    }
}

/// A [`ConfigError::WrongType`] for `key`.
fn wrong_type(key: &str, expected: &'static str, found: String) -> ConfigError {
    ConfigError::WrongType {
        key: key.to_string(),
        expected,
        found,
    }
}

/// A [`ConfigError::InvalidValue`] for `key`.
fn invalid(key: &str, value: impl fmt::Display, reason: impl Into<String>) -> ConfigError {
    ConfigError::InvalidValue {
        key: key.to_string(),
        value: value.to_string(),
        reason: reason.into(),
    }
}

/// Rejects NaN and infinities.
fn finite(key: &str, value: f64) -> Result<(), ConfigError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(invalid(key, short(value), "must be finite"))
    }
}

/// Requires a finite value `> 0`.
fn positive(key: &str, value: f64) -> Result<(), ConfigError> {
    finite(key, value)?;
    if value > 0.0 {
        Ok(())
    } else {
        Err(invalid(key, short(value), "must be positive"))
    }
}

/// Requires a finite value `>= 0`.
fn non_negative(key: &str, value: f64) -> Result<(), ConfigError> {
    finite(key, value)?;
    if value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(key, short(value), "must be non-negative"))
    }
}

/// Requires a finite value in `[lo, hi]`.
fn within(key: &str, value: f64, [lo, hi]: [f64; 2]) -> Result<(), ConfigError> {
    finite(key, value)?;
    if (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(invalid(
            key,
            short(value),
            format!("must be between {} and {}", short(lo), short(hi)),
        ))
    }
}

/// Requires `value < stopper_length` (a point on a leg, or a hub height, below the leg's full length).
fn below_stopper(key: &str, value: f64, stopper_length: f64) -> Result<(), ConfigError> {
    if value < stopper_length {
        Ok(())
    } else {
        Err(invalid(
            key,
            short(value),
            format!("must be < stopper_length ({})", short(stopper_length)),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The key named by an error, for the errors that name one.
    fn key_of(error: &ConfigError) -> Option<&str> {
        match error {
            ConfigError::UnknownKey { key, .. }
            | ConfigError::InvalidValue { key, .. }
            | ConfigError::WrongType { key, .. } => Some(key),
            _ => None,
        }
    }

    /// A temporary file path unique to this test process and `name`.
    fn temp_path(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("vrw-params-{}-{name}", std::process::id()))
    }

    #[test]
    fn defaults_equal_table_1() {
        let p = Params::default();
        assert_eq!(p.legs, 8);
        assert_eq!(p.alpha(), PI / 4.0);
        assert_eq!(p.hub_mass, 10.0);
        assert_eq!(p.hub_inertia, 0.0);
        assert_eq!(p.leg_mass, 1.0);
        assert_eq!(p.leg_mass_offset, 0.3);
        assert_eq!(p.stopper_length, 1.0);
        assert_eq!(p.spring_natural_length, 1.02);
        assert_eq!(p.stiffness, 500.0);
        assert_eq!(p.viscosity, 50.0);
        assert_eq!(p.slope, 0.10);
        assert_eq!(p.gravity, 9.81);
        assert_eq!(p.impact, ImpactModel::Dlsi);
        assert!(!p.rigid_legs);
        assert_eq!(p.inconsistent_contact, ContactInconsistency::Slide);
        // The preload k (Lstar - L0) = 10 N exceeds the leg weight m g (docs/model.md section 2).
        let preload = p.stiffness * (p.spring_natural_length - p.stopper_length);
        assert!(preload > p.leg_mass * p.gravity);

        let s = SolverOptions::default();
        assert_eq!(s.rtol, 1e-10);
        assert_eq!(s.atol, 1e-12);
        assert_eq!(s.max_step, 0.04);
        assert_eq!(s.event_time_tol, 1e-13);
        assert_eq!(s.recontact_gap, 1e-11);
        assert_eq!(s.stopper_gap, 1e-9);
        assert_eq!(s.fall_hub_height, 0.3);
        assert_eq!(s.max_step_time, 60.0);
        assert_eq!(s.max_events_per_step, 200);

        Config::default().validate().unwrap();
        assert_eq!(Config::from_toml_str("").unwrap(), Config::default());
    }

    #[test]
    fn impact_names_match_serde_and_display() {
        for &model in ImpactModel::ALL {
            let via_serde = toml::Value::try_from(model).unwrap();
            assert_eq!(via_serde.as_str(), Some(model.to_string().as_str()));
            let back: ImpactModel = via_serde.try_into().unwrap();
            assert_eq!(back, model);
        }
        assert_eq!(ImpactModel::Dlsi.to_string(), "dlsi");
        assert_eq!(ImpactModel::Traditional.to_string(), "traditional");
    }

    #[test]
    fn inconsistency_names_match_serde_and_display() {
        for &treatment in ContactInconsistency::ALL {
            let via_serde = toml::Value::try_from(treatment).unwrap();
            assert_eq!(via_serde.as_str(), Some(treatment.to_string().as_str()));
            let back: ContactInconsistency = via_serde.try_into().unwrap();
            assert_eq!(back, treatment);
        }
        assert_eq!(ContactInconsistency::Slide.to_string(), "slide");
        assert_eq!(ContactInconsistency::Rebound.to_string(), "rebound");
    }

    #[test]
    fn inconsistent_contact_parses_both_values() {
        for &treatment in ContactInconsistency::ALL {
            let name = treatment.name();
            let config =
                Config::from_toml_str(&format!("inconsistent_contact = \"{name}\"")).unwrap();
            assert_eq!(config.params.inconsistent_contact, treatment, "TOML {name}");

            let mut config = Config::default();
            config
                .apply_override(&format!("inconsistent_contact={name}"))
                .unwrap();
            assert_eq!(
                config.params.inconsistent_contact, treatment,
                "--set {name}"
            );
            config.validate().unwrap();
        }
        // The default comes back after a change.
        let mut config = Config::from_toml_str("inconsistent_contact = \"rebound\"").unwrap();
        config
            .apply_override("inconsistent_contact = slide")
            .unwrap();
        assert_eq!(config, Config::default());
    }

    #[test]
    fn inconsistent_contact_rejects_unknown_names() {
        let error = Config::from_toml_str("inconsistent_contact = \"stick\"").unwrap_err();
        assert!(matches!(error, ConfigError::InvalidValue { .. }), "{error}");
        assert_eq!(key_of(&error), Some("inconsistent_contact"));
        let message = error.to_string();
        assert!(
            message.contains("slide") && message.contains("rebound") && message.contains("stick"),
            "{message}"
        );

        let mut config = Config::default();
        let error = config
            .apply_override("inconsistent_contact=Slide")
            .unwrap_err();
        assert!(matches!(error, ConfigError::InvalidValue { .. }), "{error}");
        assert_eq!(key_of(&error), Some("inconsistent_contact"));
        assert!(error.to_string().contains("rebound"), "{error}");
        assert_eq!(
            config,
            Config::default(),
            "a failed override changes nothing"
        );

        let error = Config::from_toml_str("inconsistent_contact = true").unwrap_err();
        assert!(matches!(error, ConfigError::WrongType { .. }), "{error}");
        assert_eq!(key_of(&error), Some("inconsistent_contact"));
        assert!(
            error.to_string().contains("\"slide\" or \"rebound\""),
            "{error}"
        );
    }

    #[test]
    fn toml_file_round_trip() {
        let mut config = Config::default();
        config.params.legs = 6;
        config.params.viscosity = 123.456;
        config.params.slope = -0.05;
        config.params.impact = ImpactModel::Traditional;
        config.params.rigid_legs = true;
        config.params.inconsistent_contact = ContactInconsistency::Rebound;
        config.solver.rtol = 3e-11;
        config.solver.max_events_per_step = 17;
        config.solver.integrator = Method::Dopri5;

        let text = toml::to_string(&config).unwrap();
        // The file is flat and holds exactly the documented keys.
        let table: toml::Table = text.parse().unwrap();
        let mut written: Vec<&str> = table.keys().map(String::as_str).collect();
        let mut expected = ALL_KEYS.to_vec();
        written.sort_unstable();
        expected.sort_unstable();
        assert_eq!(written.len(), 24);
        assert_eq!(written, expected);
        assert_eq!(table["inconsistent_contact"].as_str(), Some("rebound"));
        assert_eq!(table["integrator"].as_str(), Some("dopri5"));

        let path = temp_path("round-trip.toml");
        std::fs::write(&path, &text).unwrap();
        let loaded = Config::from_file(&path);
        std::fs::remove_file(&path).unwrap();
        assert_eq!(loaded.unwrap(), config);
    }

    #[test]
    fn flat_toml_accepts_integers_for_reals() {
        let config = Config::from_toml_str(
            "viscosity = 50\nimpact = \"traditional\"\nrigid_legs = true\nrtol = 1e-11\nlegs = 10\n",
        )
        .unwrap();
        assert_eq!(config.params.viscosity, 50.0);
        assert_eq!(config.params.impact, ImpactModel::Traditional);
        assert!(config.params.rigid_legs);
        assert_eq!(config.solver.rtol, 1e-11);
        assert_eq!(config.params.legs, 10);
        assert_eq!(config.params.alpha(), 2.0 * PI / 10.0);
        assert_eq!(
            config.params.hub_mass, 10.0,
            "absent keys keep their defaults"
        );
    }

    #[test]
    fn each_rule_rejects_with_invalid_value_naming_the_key() {
        let cases = [
            ("legs=2", "legs"),
            ("hub_mass=0", "hub_mass"),
            ("hub_inertia=-0.1", "hub_inertia"),
            ("leg_mass=-1", "leg_mass"),
            ("leg_mass_offset=-0.1", "leg_mass_offset"),
            ("leg_mass_offset=1.0", "leg_mass_offset"),
            ("stopper_length=0", "stopper_length"),
            ("spring_natural_length=0.99", "spring_natural_length"),
            ("stiffness=0", "stiffness"),
            ("viscosity=-1", "viscosity"),
            ("slope=1.5708", "slope"),
            ("slope=-1.6", "slope"),
            ("gravity=0", "gravity"),
            ("rtol=0", "rtol"),
            ("atol=-1e-12", "atol"),
            ("max_step=0", "max_step"),
            ("event_time_tol=0", "event_time_tol"),
            ("recontact_gap=0", "recontact_gap"),
            ("stopper_gap=-1e-9", "stopper_gap"),
            ("fall_hub_height=-0.1", "fall_hub_height"),
            ("fall_hub_height=1.0", "fall_hub_height"),
            ("max_step_time=0", "max_step_time"),
            ("max_events_per_step=0", "max_events_per_step"),
        ];
        for (assignment, key) in cases {
            let mut config = Config::default();
            config.apply_override(assignment).unwrap();
            let error = config.validate().unwrap_err();
            assert!(
                matches!(error, ConfigError::InvalidValue { .. }),
                "{assignment}: {error}"
            );
            assert_eq!(key_of(&error), Some(key), "{assignment}: {error}");
            assert!(error.to_string().contains(key), "{assignment}: {error}");

            // The same value from a TOML document is rejected at load time.
            let (_, value) = assignment.split_once('=').unwrap();
            let error = Config::from_toml_str(&format!("{key} = {value}")).unwrap_err();
            assert_eq!(key_of(&error), Some(key), "TOML {assignment}: {error}");
        }
    }

    /// Every tolerance has a documented range; a value outside it (e.g. `event_time_tol = 0.01`, which would
    /// silently change every event time) is refused with the range in the message.
    #[test]
    fn huge_or_tiny_tolerances_are_refused() {
        let cases = [
            ("rtol", RTOL_RANGE),
            ("atol", ATOL_RANGE),
            ("max_step", MAX_STEP_RANGE),
            ("event_time_tol", EVENT_TIME_TOL_RANGE),
            ("recontact_gap", GAP_RANGE),
            ("stopper_gap", GAP_RANGE),
            ("max_step_time", MAX_STEP_TIME_RANGE),
        ];
        let defaults = Config::default();
        for (key, [lo, hi]) in cases {
            let default = defaults.get_numeric(key).unwrap();
            assert!(
                (lo..=hi).contains(&default),
                "{key}: default outside its range"
            );
            for bad in [lo / 10.0, hi * 10.0, 1e308] {
                let mut config = Config::default();
                config.set_numeric(key, bad).unwrap();
                let error = config.validate().unwrap_err();
                assert_eq!(key_of(&error), Some(key), "{key} = {bad}: {error}");
                let message = error.to_string();
                assert!(message.contains("between"), "{message}");
                assert!(!message.contains("0000000"), "not in short form: {message}");
            }
        }
        let mut config = Config::default();
        config.solver.max_events_per_step = MAX_EVENTS_PER_STEP_LIMIT + 1;
        assert_eq!(
            key_of(&config.validate().unwrap_err()),
            Some("max_events_per_step")
        );
        let mut config = Config::default();
        config.params.legs = MAX_LEGS + 1;
        assert_eq!(key_of(&config.validate().unwrap_err()), Some("legs"));
        let mut config = Config::default();
        config.params.leg_mass = 1e-300;
        let error = config.validate().unwrap_err();
        assert_eq!(key_of(&error), Some("leg_mass"));
        assert!(error.to_string().contains("1e-300"), "{error}");
    }

    #[test]
    fn cross_key_rules_name_stopper_length() {
        let mut config = Config::default();
        config.set("spring_natural_length", "0.5").unwrap();
        let message = config.validate().unwrap_err().to_string();
        assert!(message.contains("spring_natural_length"), "{message}");
        assert!(
            message.contains("must be >= stopper_length (1)"),
            "{message}"
        );

        // Rules couple keys, so overrides are validated together, not one by one.
        let mut config = Config::default();
        config.apply_override("stopper_length=2").unwrap();
        config.apply_override("spring_natural_length=2.1").unwrap();
        config.validate().unwrap();
    }

    #[test]
    fn every_real_key_rejects_nan_and_infinity() {
        for &key in Config::numeric_keys() {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let mut config = Config::default();
                config.set_numeric(key, bad).unwrap();
                let error = config.validate().unwrap_err();
                assert!(
                    matches!(error, ConfigError::InvalidValue { .. }),
                    "{key}: {error}"
                );
                assert_eq!(key_of(&error), Some(key), "{key} = {bad}: {error}");
            }
        }
        // TOML spells them `nan` and `inf`; the command line as Rust parses them.
        let error = Config::from_toml_str("viscosity = nan").unwrap_err();
        assert_eq!(key_of(&error), Some("viscosity"));
        let mut config = Config::default();
        config.apply_override("stiffness=inf").unwrap();
        assert!(config
            .validate()
            .unwrap_err()
            .to_string()
            .contains("stiffness"));
    }

    #[test]
    fn wrong_types_in_toml() {
        let cases = [
            ("legs = 8.0", "legs"),
            ("max_events_per_step = 1.5", "max_events_per_step"),
            ("viscosity = \"50\"", "viscosity"),
            ("rigid_legs = 1", "rigid_legs"),
            ("impact = 3", "impact"),
            ("inconsistent_contact = 0", "inconsistent_contact"),
            ("slope = [0.1]", "slope"),
            ("gravity = 1979-05-27", "gravity"),
        ];
        for (text, key) in cases {
            let error = Config::from_toml_str(text).unwrap_err();
            assert!(
                matches!(error, ConfigError::WrongType { .. }),
                "{text}: {error}"
            );
            assert_eq!(key_of(&error), Some(key), "{text}: {error}");
            assert!(error.to_string().contains(key), "{text}: {error}");
        }
        let error = Config::from_toml_str("impact = \"rigid\"").unwrap_err();
        assert!(matches!(error, ConfigError::InvalidValue { .. }), "{error}");
        assert!(error.to_string().contains("traditional"), "{error}");
        let error = Config::from_toml_str("legs = -3").unwrap_err();
        assert!(matches!(error, ConfigError::InvalidValue { .. }), "{error}");
        assert_eq!(key_of(&error), Some("legs"));
    }

    #[test]
    fn unknown_key_lists_the_known_ones() {
        for text in ["foo = 1", "[params]\nviscosity = 50"] {
            let error = Config::from_toml_str(text).unwrap_err();
            assert!(matches!(error, ConfigError::UnknownKey { .. }), "{error}");
            let message = error.to_string();
            assert!(message.contains("viscosity") && message.contains("max_events_per_step"));
        }
        let error = Config::from_toml_str("foo = 1").unwrap_err();
        assert_eq!(key_of(&error), Some("foo"));

        let error = Config::default().set("foo", "1").unwrap_err();
        assert!(matches!(error, ConfigError::UnknownKey { .. }), "{error}");
        assert!(error.to_string().contains("`foo`"), "{error}");
    }

    #[test]
    fn malformed_toml_keeps_line_and_column() {
        let error = Config::from_toml_str("viscosity = 50\nslope = \n").unwrap_err();
        match &error {
            ConfigError::Toml { path, message } => {
                assert_eq!(path, "<string>");
                assert!(message.contains("line 2"), "{message}");
            }
            other => panic!("expected a Toml error, got {other:?}"),
        }

        let path = temp_path("malformed.toml");
        std::fs::write(&path, "viscosity = = 3").unwrap();
        let error = Config::from_file(&path).unwrap_err();
        std::fs::remove_file(&path).unwrap();
        assert!(matches!(error, ConfigError::Toml { .. }), "{error}");
        assert!(error.to_string().contains("malformed.toml"), "{error}");
    }

    #[test]
    fn missing_file_is_an_io_error_with_its_path() {
        let path = temp_path("does-not-exist.toml");
        let error = Config::from_file(&path).unwrap_err();
        assert!(matches!(error, ConfigError::Io { .. }), "{error}");
        assert!(error.to_string().contains("does-not-exist.toml"), "{error}");
    }

    #[test]
    fn set_viscosity_abc_is_a_wrong_type() {
        let mut config = Config::default();
        let error = config.apply_override("viscosity=abc").unwrap_err();
        assert!(matches!(error, ConfigError::WrongType { .. }), "{error}");
        let message = error.to_string();
        assert!(
            message.contains("viscosity") && message.contains("abc"),
            "{message}"
        );
        assert_eq!(
            config,
            Config::default(),
            "a failed override changes nothing"
        );
    }

    #[test]
    fn set_without_equals_is_malformed() {
        for assignment in ["foo", "", "=5", "  = 5"] {
            let error = Config::default().apply_override(assignment).unwrap_err();
            assert!(
                matches!(error, ConfigError::MalformedOverride { .. }),
                "{assignment:?}: {error}"
            );
            assert!(error.to_string().contains(assignment), "{error}");
        }
    }

    #[test]
    fn override_values_are_parsed_by_the_key_type() {
        let mut config = Config::default();
        for assignment in [
            "viscosity=5e1",
            " slope = 0.05 ",
            "stiffness=600",
            "legs=6",
            "max_events_per_step=+50",
            "rigid_legs=true",
            "impact=traditional",
            "inconsistent_contact=rebound",
        ] {
            config.apply_override(assignment).unwrap();
        }
        assert_eq!(config.params.viscosity, 50.0);
        assert_eq!(config.params.slope, 0.05);
        assert_eq!(config.params.stiffness, 600.0);
        assert_eq!(config.params.legs, 6);
        assert_eq!(config.solver.max_events_per_step, 50);
        assert!(config.params.rigid_legs);
        assert_eq!(config.params.impact, ImpactModel::Traditional);
        assert_eq!(
            config.params.inconsistent_contact,
            ContactInconsistency::Rebound
        );
        config.validate().unwrap();

        let cases = [
            ("legs=8.0", "legs"),
            ("legs=eight", "legs"),
            ("rigid_legs=yes", "rigid_legs"),
            ("hub_mass=", "hub_mass"),
        ];
        for (assignment, key) in cases {
            let error = Config::default().apply_override(assignment).unwrap_err();
            assert!(
                matches!(error, ConfigError::WrongType { .. }),
                "{assignment}: {error}"
            );
            assert_eq!(key_of(&error), Some(key));
        }
        for (assignment, key) in [
            ("legs=-1", "legs"),
            ("legs=99999999999999999999999", "legs"),
            ("impact=rigid", "impact"),
            ("inconsistent_contact=stick", "inconsistent_contact"),
        ] {
            let error = Config::default().apply_override(assignment).unwrap_err();
            assert!(
                matches!(error, ConfigError::InvalidValue { .. }),
                "{assignment}: {error}"
            );
            assert_eq!(key_of(&error), Some(key));
        }
    }

    #[test]
    fn override_after_file() {
        let path = temp_path("override.toml");
        std::fs::write(
            &path,
            "viscosity = 30\nslope = 0.08\nimpact = \"traditional\"\n",
        )
        .unwrap();
        let loaded = Config::from_file(&path);
        std::fs::remove_file(&path).unwrap();
        let mut config = loaded.unwrap();
        assert_eq!(config.params.viscosity, 30.0);

        config.apply_override("viscosity=120").unwrap();
        config.apply_override("impact=dlsi").unwrap();
        config.validate().unwrap();
        assert_eq!(config.params.viscosity, 120.0);
        assert_eq!(config.params.impact, ImpactModel::Dlsi);
        assert_eq!(
            config.params.slope, 0.08,
            "keys not overridden keep the file's value"
        );
    }

    #[test]
    fn numeric_keys_get_set_round_trip() {
        let keys = Config::numeric_keys();
        assert_eq!(keys.len(), 18);
        assert!(keys.iter().all(|key| ALL_KEYS.contains(key)));
        for key in [
            "legs",
            "max_events_per_step",
            "impact",
            "rigid_legs",
            "inconsistent_contact",
        ] {
            assert!(!keys.contains(&key), "{key} is not real-valued");
        }

        let mut config = Config::default();
        for (i, &key) in keys.iter().enumerate() {
            config.set_numeric(key, 1000.0 + i as f64).unwrap();
        }
        // Each key reads back its own value, and names the field that serializes under it.
        let table = toml::Value::try_from(&config).unwrap();
        for (i, &key) in keys.iter().enumerate() {
            let value = 1000.0 + i as f64;
            assert_eq!(config.get_numeric(key).unwrap(), value, "{key}");
            assert_eq!(table[key].as_float(), Some(value), "{key}");
        }

        // set_numeric does not validate; the caller does.
        let mut config = Config::default();
        config.set_numeric("viscosity", -1.0).unwrap();
        assert_eq!(config.get_numeric("viscosity").unwrap(), -1.0);
        assert!(config.validate().is_err());

        for key in ["legs", "foo"] {
            let error = config.get_numeric(key).unwrap_err();
            assert!(matches!(error, ConfigError::UnknownKey { .. }), "{error}");
            assert!(config.set_numeric(key, 1.0).is_err());
        }
    }
}
