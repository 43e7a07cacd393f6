//! Parameters and configuration: the first stage of the pipeline.
//!
//! [`Params`] holds the physical model of the viscoelastic-legged rimless wheel (`docs/model.md` sections 1, 2
//! and 7, defaults from the paper's Table 1; in `model`), [`SolverOptions`] the numerical settings, including
//! every tolerance that guards grazing and chatter (`docs/model.md` section 4; in `solver`, with the named
//! choices [`ImpactModel`] and [`ContactInconsistency`]), and [`Config`] both of them together. Reading a
//! configuration (a TOML file, `--set key=value` overrides, typed values from the Python binding) is in
//! `load`.
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
//! Loading ([`Config::from_toml_str`], [`Config::from_file`], [`Config::load`] with overrides) validates the
//! result once, after every key is read. Single assignments ([`Config::set`], [`Config::apply_override`] for the
//! command line's `--set key=value`, [`Config::set_numeric`] for sweeps) do not, because the rules couple keys
//! (for instance `spring_natural_length >= stopper_length`): apply all of them, then call
//! [`Config::validate`].

use std::fmt;

use crate::fmt::{clip, clip_lines, short};

mod de;
pub(crate) mod load;
pub(crate) mod model;
pub(crate) mod solver;

pub use load::{read_named_parameters, read_walker_parameters, NumericKey};
pub use model::{
    LegTimeScale, Params, MASS_RATIO_LIMIT, MAX_LEGS, MIN_LEG_TIME_SCALE, SLOW_LEG_TIME_SCALE,
};
pub use solver::{ContactInconsistency, ImpactModel, RearExit, SolverOptions};
pub use solver::{
    ATOL_RANGE, EVENT_SPACING_RANGE, EVENT_TIME_TOL_RANGE, GAP_RANGE, MAX_EVENTS_PER_STEP_LIMIT,
    MAX_STEP_RANGE, MAX_STEP_TIME_RANGE, RTOL_RANGE,
};

/// Everything a run needs: physics ([`Params`]) and numerics ([`SolverOptions`]).
///
/// It reads from, and serializes to, a flat TOML table whose keys are the field names of both structs
/// (e.g. `viscosity = 50.0`, `impact = "traditional"`, `rigid_legs = true`,
/// `inconsistent_contact = "rebound"`, `rtol = 1e-11`).
///
/// It is read by serde, one struct at a time (`load` says why not through `#[serde(flatten)]`).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct Config {
    /// Physical parameters (`docs/model.md` sections 1, 2 and 7). Default: the paper's Table 1.
    #[serde(flatten)]
    pub params: Params,
    /// Numerical settings (`docs/model.md` section 4). Default: [`SolverOptions::default`].
    #[serde(flatten)]
    pub solver: SolverOptions,
}

impl Config {
    /// Checks every rule: [`Params::validate`], [`SolverOptions::validate`] and
    /// `fall_hub_height < stopper_length`. Every broken rule is reported: one error names its key, several
    /// are [`ConfigError::Several`].
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.check(&|_| true)
    }

    /// A copy with the real-valued key `key` set to `value` and validated: the configuration at one point of a
    /// sweep, a map or a continuation.
    pub(crate) fn with(&self, key: &str, value: f64) -> Result<Config, ConfigError> {
        let mut c = self.clone();
        c.set_numeric(key, value)?;
        c.validate()?;
        Ok(c)
    }

    /// [`Config::validate`], where a rule between two keys names the one the user gave (`given(key)`, see
    /// [`Params::check`]).
    pub(crate) fn check(&self, given: &dyn Fn(&str) -> bool) -> Result<(), ConfigError> {
        let mut rules = Rules::new(given);
        self.params.collect(&mut rules);
        self.solver.collect(&mut rules);
        rules.between(["fall_hub_height", "stopper_length"], |given| {
            ordered(
                ("fall_hub_height", self.solver.fall_hub_height),
                Order::Below,
                ("stopper_length", self.params.stopper_length),
                given,
            )
        });
        rules.finish()
    }
}

/// The rules of one input checked together: every broken rule is kept, so that the user sees all of them at
/// once. A rule between two keys is checked only when both keys passed their own rules (a NaN
/// `stopper_length` is reported once, not again by every rule that compares with it).
pub(crate) struct Rules<'a> {
    /// Whether the user gave a key (see [`ordered`]).
    given: &'a dyn Fn(&str) -> bool,
    /// The broken rules so far.
    errors: Vec<ConfigError>,
    /// The keys that broke a rule of their own (not a rule between two keys).
    failed: Vec<String>,
}

impl<'a> Rules<'a> {
    /// No rule checked yet.
    pub(crate) fn new(given: &'a dyn Fn(&str) -> bool) -> Rules<'a> {
        Rules {
            given,
            errors: Vec::new(),
            failed: Vec::new(),
        }
    }

    /// Keeps the error of a rule on one key.
    pub(crate) fn single(&mut self, result: Result<(), ConfigError>) {
        if let Err(error) = result {
            self.failed.extend(error.key().map(str::to_string));
            self.errors.push(error);
        }
    }

    /// Checks a rule between `keys`, unless one of them already broke a rule of its own.
    pub(crate) fn between(
        &mut self,
        keys: [&str; 2],
        rule: impl FnOnce(&dyn Fn(&str) -> bool) -> Result<(), ConfigError>,
    ) {
        if !keys.iter().any(|key| self.failed(key)) {
            if let Err(error) = rule(self.given) {
                self.errors.push(error);
            }
        }
    }

    /// Whether `key` broke a rule of its own so far.
    pub(crate) fn failed(&self, key: &str) -> bool {
        self.failed.iter().any(|k| k == key)
    }

    /// Whether the user gave `key`.
    pub(crate) fn given(&self, key: &str) -> bool {
        (self.given)(key)
    }

    /// Nothing broken, the one error, or [`ConfigError::Several`].
    pub(crate) fn finish(self) -> Result<(), ConfigError> {
        ConfigError::all(self.errors)
    }
}

/// What a configuration can go wrong with. Every variant names the key or the source it concerns.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// A key that is not a field of [`Params`] or [`SolverOptions`].
    #[error("unknown key `{}` (known keys: {known})", clip(.key))]
    UnknownKey {
        /// The key as given.
        key: String,
        /// The keys that would have been accepted, comma-separated.
        known: String,
    },
    /// A value of the right type that breaks a rule.
    #[error("invalid value {} for `{}`: {reason}", clip(.value), clip(.key))]
    InvalidValue {
        /// The offending key.
        key: String,
        /// The value as given or stored.
        value: String,
        /// The rule it breaks, e.g. "must be positive" or "must be >= stopper_length (1)".
        reason: String,
    },
    /// A value whose type does not fit the key (a string for a number, a float for an integer, ...).
    #[error("wrong type for `{}`: expected {expected}, found {}", clip(.key), clip(.found))]
    WrongType {
        /// The offending key.
        key: String,
        /// The type the key holds, e.g. "a real number" or "the string \"dlsi\" or \"traditional\"".
        expected: String,
        /// What was given instead.
        found: String,
    },
    /// A `--set` override that is not of the form `key=value`.
    #[error("malformed override `{}`: expected key=value", clip(.assignment))]
    MalformedOverride {
        /// The override as given.
        assignment: String,
    },
    /// A TOML document that does not parse.
    #[error("malformed TOML in {path}: {}", clip_lines(.message))]
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
    /// A configuration file that is not one: larger than [`MAX_CONFIG_BYTES`], or not a regular file (a
    /// device such as `/dev/zero`, a directory).
    #[error("cannot read configuration file {path}: {reason}")]
    NotAConfigFile {
        /// The file.
        path: String,
        /// Why, e.g. "it is larger than 1048576 bytes".
        reason: String,
    },
    /// Several problems with one input (a file, the `--set` overrides, keyword arguments), each naming its
    /// key, in the order of the keys' declaration.
    #[error("{} problems: {}", errors.len(), numbered(errors))]
    Several {
        /// The problems, each a single error (never `Several`).
        errors: Vec<ConfigError>,
    },
}

/// The largest configuration file read \[bytes\]: a flat file of every key is about 600 bytes; a larger one
/// is not a configuration (and a device like `/dev/zero` would be read forever).
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// "1) first; 2) second".
fn numbered(errors: &[ConfigError]) -> String {
    errors
        .iter()
        .enumerate()
        .map(|(i, e)| format!("{}) {e}", i + 1))
        .collect::<Vec<_>>()
        .join("; ")
}

impl ConfigError {
    /// The key the error names, for the errors that name one (not for [`ConfigError::Several`], which names
    /// one per problem: see [`ConfigError::problems`]).
    pub fn key(&self) -> Option<&str> {
        match self {
            ConfigError::UnknownKey { key, .. }
            | ConfigError::InvalidValue { key, .. }
            | ConfigError::WrongType { key, .. } => Some(key),
            _ => None,
        }
    }

    /// The single problems: the list of [`ConfigError::Several`], or this error alone.
    pub fn problems(&self) -> Vec<&ConfigError> {
        match self {
            ConfigError::Several { errors } => errors.iter().collect(),
            other => vec![other],
        }
    }

    /// `Ok` without errors, the error alone, or [`ConfigError::Several`].
    pub(crate) fn all(mut errors: Vec<ConfigError>) -> Result<(), ConfigError> {
        match errors.len() {
            0 => Ok(()),
            1 => Err(errors.remove(0)),
            _ => Err(ConfigError::Several { errors }),
        }
    }
}

/// A [`ConfigError::InvalidValue`] for `key`.
pub(crate) fn invalid(
    key: &str,
    value: impl fmt::Display,
    reason: impl Into<String>,
) -> ConfigError {
    ConfigError::InvalidValue {
        key: key.to_string(),
        value: value.to_string(),
        reason: reason.into(),
    }
}

/// Rejects NaN and infinities.
pub(crate) fn finite(key: &str, value: f64) -> Result<(), ConfigError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(invalid(key, short(value), "must be finite"))
    }
}

/// Requires a finite value `> 0`.
pub(crate) fn positive(key: &str, value: f64) -> Result<(), ConfigError> {
    finite(key, value)?;
    if value > 0.0 {
        Ok(())
    } else {
        Err(invalid(key, short(value), "must be positive"))
    }
}

/// Requires a finite value `>= 0`.
pub(crate) fn non_negative(key: &str, value: f64) -> Result<(), ConfigError> {
    finite(key, value)?;
    if value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(key, short(value), "must be non-negative"))
    }
}

/// Requires a finite value in `[lo, hi]`.
pub(crate) fn within(key: &str, value: f64, [lo, hi]: [f64; 2]) -> Result<(), ConfigError> {
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

/// How a key's value must compare with another key's, in a rule between two keys.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Order {
    /// `value < other`.
    Below,
    /// `value >= other`.
    AtLeast,
}

/// Requires `value < other` or `value >= other` (`order`) for the rule between `key` and `other_key`.
///
/// The error names `key` ("must be < stopper_length (1)"), unless the user gave `other_key` and not `key`
/// (`given`): then it names `other_key` with the relation turned round ("must be > leg_mass_offset (0.3)").
pub(crate) fn ordered(
    (key, value): (&str, f64),
    order: Order,
    (other_key, other): (&str, f64),
    given: &dyn Fn(&str) -> bool,
) -> Result<(), ConfigError> {
    let (holds, relation, turned) = match order {
        Order::Below => (value < other, "<", ">"),
        Order::AtLeast => (value >= other, ">=", "<="),
    };
    if holds {
        Ok(())
    } else if given(other_key) && !given(key) {
        Err(invalid(
            other_key,
            short(other),
            format!("must be {turned} {key} ({})", short(value)),
        ))
    } else {
        Err(invalid(
            key,
            short(value),
            format!("must be {relation} {other_key} ({})", short(other)),
        ))
    }
}

/// What the tests of this module and its children share.
#[cfg(test)]
pub(crate) mod test_support {
    use super::ConfigError;

    /// The key named by an error, for the errors that name one.
    pub(crate) fn key_of(error: &ConfigError) -> Option<&str> {
        error.key()
    }

    /// A temporary file path unique to this test process and `name`.
    pub(crate) fn temp_path(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("vrw-params-{}-{name}", std::process::id()))
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::key_of;
    use super::*;

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
                if key == "friction" && bad == f64::INFINITY {
                    // No slip: the default.
                    continue;
                }
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

    /// `friction` is a non-negative number or `inf` (no slip, the default); a finite one is refused with the
    /// `rebound` treatment of an inconsistent no-slip contact, which it replaces.
    #[test]
    fn friction_is_non_negative_or_infinite() {
        let config = Config::from_toml_str("friction = inf").unwrap();
        assert_eq!(config.params.friction, f64::INFINITY);
        let mut config = Config::default();
        config.apply_override("friction=0.6").unwrap();
        config.validate().unwrap();
        assert!(config.params.has_friction());
        config.apply_override("friction=0").unwrap();
        config.validate().unwrap();
        for bad in ["-0.1", "nan", "-inf"] {
            let mut config = Config::default();
            config.apply_override(&format!("friction={bad}")).unwrap();
            let error = config.validate().unwrap_err();
            assert_eq!(key_of(&error), Some("friction"), "{bad}: {error}");
        }
        let error = Config::from_toml_str("friction = 0.5\ninconsistent_contact = \"rebound\"")
            .unwrap_err();
        assert!(error.to_string().contains("rebound"), "{error}");
    }
}
