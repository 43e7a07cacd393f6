//! The numerical side of a configuration: [`SolverOptions`] (integrator, tolerances, and every guard against
//! grazing and chatter, `docs/model.md` section 4) with their accepted ranges, and the named choices a
//! configuration makes between models and methods: the impact law ([`ImpactModel`]), the treatment of an
//! inconsistent contact ([`ContactInconsistency`]), the old rear leg at re-indexing ([`RearExit`]) and the
//! integrator ([`Method`]).
//!
//! In a file and on the command line a choice is written as its lowercase name (`impact = "traditional"`);
//! serde's `rename_all = "lowercase"` is the only place these names are declared for reading, and
//! [`Display`](fmt::Display) writes the same names.

use std::fmt;

use super::{invalid, non_negative, within, ConfigError, Rules};
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

impl ImpactModel {
    /// The name of this law, as in TOML and on the command line (serde's name of the variant).
    pub(crate) fn name(self) -> &'static str {
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

impl ContactInconsistency {
    /// The name of this treatment, as in TOML and on the command line (serde's name of the variant).
    pub(crate) fn name(self) -> &'static str {
        match self {
            ContactInconsistency::Slide => "slide",
            ContactInconsistency::Rebound => "rebound",
        }
    }
}

impl fmt::Display for ContactInconsistency {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What becomes of the old rear leg (Leg 2) when it leaves Legs 1 and 2 at a touchdown (`docs/model.md`
/// section 5, "Re-indexing"): the legs other than Legs 1 and 2 are rigid spokes at `L0`, so the leg that leaves
/// must be one by then, or become one later.
///
/// In TOML and on the command line the values are the strings `"relock"` (default), `"continue"` and
/// `"reset"`; [`Display`](fmt::Display) gives the same strings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RearExit {
    /// The leg must already be locked on its stopper (and in the air) at the touchdown; if it is not, the walk
    /// stops with `rear_leg_not_locked`. Nothing is discarded, so energy is conserved through re-indexing.
    #[default]
    Relock,
    /// A leg that is not locked keeps its free dynamics (spring, damper, its sliding mass coupled with the
    /// wheel) as the sixth coordinate `L3` until its stopper locks it, at an impact counted with the stopper
    /// losses; it is then a spoke again. The walk stops with `swinging_leg_not_locked` if it still swings at the
    /// next touchdown (when another leg would leave), and with `swinging_leg_landed` if its tip reaches the
    /// ground. Nothing is discarded. Not with `min_length` (the swinging leg has no compression stop yet).
    Continue,
    /// The leg's length and rate are discarded at the touchdown and it becomes a spoke at `L0` (as a
    /// third-party MATLAB VRW code does). Not physical: the energy this adds or removes is reported per step
    /// (`reset_energy`). The leg must still be in the air.
    Reset,
}

impl RearExit {
    /// The name of this choice, as in TOML and on the command line (serde's name of the variant).
    pub(crate) fn name(self) -> &'static str {
        match self {
            RearExit::Relock => "relock",
            RearExit::Continue => "continue",
            RearExit::Reset => "reset",
        }
    }

    /// The default, [`RearExit::Relock`] (left out of written configurations, so that they stay as they were
    /// before the key existed).
    pub(crate) fn is_relock(&self) -> bool {
        *self == RearExit::Relock
    }
}

impl fmt::Display for RearExit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Numerical settings of the integration and of the walk's event handling (`docs/model.md` section 4).
///
/// Every tolerance that guards grazing or chatter is a named field here. Check a value built by hand
/// with [`SolverOptions::validate`] (and [`Config::validate`](super::Config::validate) for the rule that involves [`Params`](super::Params)).
///
/// Each field is a key of a configuration file, read by serde (`load`); absent keys keep their
/// defaults and unknown keys are refused.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
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
    /// Largest integrator step \[s\]. Default 0.04. In [`MAX_STEP_RANGE`] (1e-6 to 1). Events do not depend
    /// on it being small: they are looked for at points `event_spacing` apart at most.
    pub max_step: f64,
    /// Largest interval between the points of each integrator step's dense output at which every event
    /// function and the contact audit are evaluated \[s\] (also at least four points per step): an event
    /// function that dips below zero and back for longer than this is caught. Default 0.01. In
    /// [`EVENT_SPACING_RANGE`] (1e-6 to 1). `docs/model.md` section 4.
    pub event_spacing: f64,
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
            event_spacing: 0.01,
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
    /// `fall_hub_height < stopper_length` needs the [`Params`](super::Params) and is checked by
    /// [`Config::validate`](super::Config::validate).
    pub fn validate(&self) -> Result<(), ConfigError> {
        let mut rules = Rules::new(&|_| true);
        self.collect(&mut rules);
        rules.finish()
    }

    /// Checks every rule into `rules` (see [`SolverOptions::validate`]).
    pub(crate) fn collect(&self, rules: &mut Rules<'_>) {
        rules.single(within("rtol", self.rtol, RTOL_RANGE));
        rules.single(within("atol", self.atol, ATOL_RANGE));
        rules.single(within("max_step", self.max_step, MAX_STEP_RANGE));
        rules.single(within(
            "event_spacing",
            self.event_spacing,
            EVENT_SPACING_RANGE,
        ));
        rules.single(within(
            "event_time_tol",
            self.event_time_tol,
            EVENT_TIME_TOL_RANGE,
        ));
        rules.single(within("recontact_gap", self.recontact_gap, GAP_RANGE));
        rules.single(within("stopper_gap", self.stopper_gap, GAP_RANGE));
        rules.single(non_negative("fall_hub_height", self.fall_hub_height));
        rules.single(within(
            "max_step_time",
            self.max_step_time,
            MAX_STEP_TIME_RANGE,
        ));
        if !(1..=MAX_EVENTS_PER_STEP_LIMIT).contains(&self.max_events_per_step) {
            rules.single(Err(invalid(
                "max_events_per_step",
                self.max_events_per_step,
                format!("must be between 1 and {MAX_EVENTS_PER_STEP_LIMIT}"),
            )));
        }
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
/// Accepted range of `event_spacing` \[s\]: the same as [`MAX_STEP_RANGE`]; a spacing longer than a step
/// leaves the four points per step.
pub const EVENT_SPACING_RANGE: [f64; 2] = [1e-6, 1.0];
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

#[cfg(test)]
mod tests {
    use crate::params::test_support::key_of;
    use crate::params::*;

    #[test]
    fn impact_names_match_serde_and_display() {
        for model in [ImpactModel::Dlsi, ImpactModel::Traditional] {
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
        for treatment in [ContactInconsistency::Slide, ContactInconsistency::Rebound] {
            let via_serde = toml::Value::try_from(treatment).unwrap();
            assert_eq!(via_serde.as_str(), Some(treatment.to_string().as_str()));
            let back: ContactInconsistency = via_serde.try_into().unwrap();
            assert_eq!(back, treatment);
        }
        assert_eq!(ContactInconsistency::Slide.to_string(), "slide");
        assert_eq!(ContactInconsistency::Rebound.to_string(), "rebound");
    }

    /// Every tolerance has a documented range; a value outside it (e.g. `event_time_tol = 0.01`, which would
    /// silently change every event time) is refused with the range in the message.
    #[test]
    fn huge_or_tiny_tolerances_are_refused() {
        let cases = [
            ("rtol", RTOL_RANGE),
            ("atol", ATOL_RANGE),
            ("max_step", MAX_STEP_RANGE),
            ("event_spacing", EVENT_SPACING_RANGE),
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
}
