//! Reading a configuration: a flat TOML file or string, the command line's `--set key=value` overrides, typed
//! values from other fronts (the Python binding's keywords), and the key lists that follow from the structs.
//!
//! Every source is first merged into one flat table (the defaults or a configuration's current values, then the
//! file, then the overrides, a later value replacing an earlier one); serde then reads the merged table into
//! [`Params`] and [`SolverOptions`] (the value reader is in `de.rs`), and the result is validated once. So a file
//! with `stopper_length = 2` and `--set spring_natural_length=2.5` is accepted, and a rule between two keys
//! names the key the user gave.
//!
//! A key is declared once, as a field of [`Params`] or [`SolverOptions`]. The structs are not read through a
//! `#[serde(flatten)]` [`Config`]: serde does not support `deny_unknown_fields` together with `flatten`, and
//! it hands flattened fields a buffered copy of the values instead of our reader, which would lose the
//! configuration's error messages. Instead the table is split by the field names serde reports for
//! [`SolverOptions`] ([`Config::numeric_keys`] and the list of known keys come from the same names), the rest
//! goes to [`Params`], and each struct is read with `deny_unknown_fields`, which refuses any other key.

use std::path::Path;
use std::sync::OnceLock;

use super::de::{self, Entry, Raw, Table};
use super::{Config, ConfigError, Params, SolverOptions, MAX_CONFIG_BYTES};

/// The keys of a configuration, found once from the structs.
struct Keys {
    /// The fields of [`SolverOptions`].
    solver: &'static [&'static str],
    /// Every key, in declaration order: the fields of [`Params`], then of [`SolverOptions`].
    all: Vec<&'static str>,
    /// The keys holding a real number, in declaration order.
    numeric: Vec<&'static str>,
}

/// The keys of a configuration.
fn keys() -> &'static Keys {
    static KEYS: OnceLock<Keys> = OnceLock::new();
    KEYS.get_or_init(|| {
        let solver = de::field_names::<SolverOptions>();
        let all: Vec<&'static str> = de::field_names::<Params>()
            .iter()
            .chain(solver)
            .copied()
            .collect();
        let config = Config::default();
        let mut defaults = config.stored().unwrap_or_default();
        // Keys files leave out at their defaults (`min_length = 0`) are still keys of their type.
        for (key, value) in config.params.keys_left_out_at_defaults() {
            defaults.insert(key.to_string(), Raw::Stored(value));
        }
        let numeric = all
            .iter()
            .copied()
            .filter(|key| matches!(defaults.get(*key), Some(Raw::Stored(toml::Value::Float(_)))))
            .collect();
        Keys {
            solver,
            all,
            numeric,
        }
    })
}

/// Every key of a configuration, in declaration order: the fields of [`Params`], then of [`SolverOptions`].
pub(crate) fn all_keys() -> &'static [&'static str] {
    &keys().all
}

impl Config {
    /// Parses a flat TOML document: starts from the defaults, applies every key, then validates.
    ///
    /// Integers are accepted for real-valued keys (`viscosity = 50`); a float for an integer key
    /// (`legs = 8.0`) or a string for a number is [`ConfigError::WrongType`]. Syntax errors are
    /// [`ConfigError::Toml`] with `path` `"<string>"` and toml's line/column message.
    pub fn from_toml_str(text: &str) -> Result<Config, ConfigError> {
        Config::read_validated(&document(text, "<string>")?)
    }

    /// Reads and parses a flat TOML file, as [`Config::from_toml_str`] does; errors carry the path.
    pub fn from_file(path: &Path) -> Result<Config, ConfigError> {
        Config::read_validated(&file_table(path)?)
    }

    /// Reads the command line's configuration: the defaults, then the flat TOML `file` if there is one, then
    /// each `key=value` of `overrides` (as [`Config::apply_override`] reads them), validated once at the end.
    ///
    /// Validating after the overrides lets them repair a file (`stopper_length = 2` in the file,
    /// `--set spring_natural_length=2.5`), and a rule between two keys names the key the user gave.
    pub fn load<S: AsRef<str>>(
        file: Option<&Path>,
        overrides: &[S],
    ) -> Result<Config, ConfigError> {
        let mut table = match file {
            Some(path) => file_table(path)?,
            None => Table::new(),
        };
        for assignment in overrides {
            let (key, value) = split_override(assignment.as_ref())?;
            table.insert(key.to_string(), Raw::Text(value.to_string()));
        }
        Config::read_validated(&table)
    }

    /// Applies one `key=value` override (the command line's repeatable `--set key=value`); spaces
    /// around the key and the value are ignored, and the value is parsed as by [`Config::set`].
    ///
    /// A missing `=` or an empty key is [`ConfigError::MalformedOverride`]. Does not validate: call
    /// [`Config::validate`] after the last override.
    pub fn apply_override(&mut self, assignment: &str) -> Result<(), ConfigError> {
        let (key, value) = split_override(assignment)?;
        self.set(key, value)
    }

    /// Sets `key` from its textual `value`, parsed by the key's type: a real number for `f64` keys
    /// (`"50"`, `"5e1"`, `"0.1"`; a finite literal that overflows or underflows to 0 is refused), a
    /// non-negative integer for `legs` and `max_events_per_step`, `true` or `false` for `rigid_legs`, `dlsi` or
    /// `traditional` for `impact`, `slide` or `rebound` for `inconsistent_contact`, `dop853` or `dopri5` for
    /// `integrator`. On error the configuration is unchanged.
    ///
    /// Does not validate, because the rules couple keys: call [`Config::validate`] after the last change.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), ConfigError> {
        self.merge(key, Raw::Text(value.to_string()))
    }

    /// Sets `key` from a TOML value, converted exactly as a configuration file's value is (for fronts that
    /// receive typed values, e.g. the Python binding's keyword arguments). On error the configuration is
    /// unchanged.
    ///
    /// Does not validate: call [`Config::validate`] after the last change.
    pub fn set_value(&mut self, key: &str, value: &toml::Value) -> Result<(), ConfigError> {
        self.merge(key, Raw::Given(value.clone(), None))
    }

    /// A copy with every key of `values` set from its TOML value (as [`Config::set_value`] does), validated once
    /// after the last: the Python binding's keywords. A rule between two keys names the key given here.
    pub fn with_values<I>(&self, values: I) -> Result<Config, ConfigError>
    where
        I: IntoIterator<Item = (String, toml::Value)>,
    {
        let mut table = self.stored()?;
        for (key, value) in values {
            table.insert(key, Raw::Given(value, None));
        }
        Config::read_validated(&table)
    }

    /// Names of the keys holding a real number (sweepable): every `f64` field of [`Params`] and
    /// [`SolverOptions`], in declaration order.
    pub fn numeric_keys() -> &'static [&'static str] {
        &keys().numeric
    }

    /// The value of the real-valued key `key` (one of [`Config::numeric_keys`]).
    pub(crate) fn get_numeric(&self, key: &str) -> Result<f64, ConfigError> {
        self.clone()
            .numeric_field(key)
            .map(|v| *v)
            .ok_or_else(|| unknown_numeric_key(key))
    }

    /// Sets the real-valued key `key` (one of [`Config::numeric_keys`]) to `value`, as a sweep does.
    ///
    /// Does not validate: call [`Config::validate`] afterwards.
    pub fn set_numeric(&mut self, key: &str, value: f64) -> Result<(), ConfigError> {
        *self
            .numeric_field(key)
            .ok_or_else(|| unknown_numeric_key(key))? = value;
        Ok(())
    }

    /// The field of the real-valued key `key`, set and read in place: a sweep's or a continuation's change of
    /// one key costs an assignment, not a round trip of the whole configuration through TOML. The match is
    /// kept equal to [`Config::numeric_keys`] (derived from serde) by the test
    /// `numeric_fields_are_the_numeric_keys`.
    fn numeric_field(&mut self, key: &str) -> Option<&mut f64> {
        let (p, s) = (&mut self.params, &mut self.solver);
        Some(match key {
            "hub_mass" => &mut p.hub_mass,
            "hub_inertia" => &mut p.hub_inertia,
            "leg_mass" => &mut p.leg_mass,
            "leg_mass_offset" => &mut p.leg_mass_offset,
            "stopper_length" => &mut p.stopper_length,
            "spring_natural_length" => &mut p.spring_natural_length,
            "stiffness" => &mut p.stiffness,
            "viscosity" => &mut p.viscosity,
            "slope" => &mut p.slope,
            "gravity" => &mut p.gravity,
            "min_length" => &mut p.min_length,
            "touchdown_length" => &mut p.touchdown_length,
            "friction" => &mut p.friction,
            "rtol" => &mut s.rtol,
            "atol" => &mut s.atol,
            "max_step" => &mut s.max_step,
            "event_spacing" => &mut s.event_spacing,
            "event_time_tol" => &mut s.event_time_tol,
            "recontact_gap" => &mut s.recontact_gap,
            "stopper_gap" => &mut s.stopper_gap,
            "fall_hub_height" => &mut s.fall_hub_height,
            "max_step_time" => &mut s.max_step_time,
            _ => return None,
        })
    }

    /// Sets `key` to `value`, read by serde with every other key as it is now; on error nothing changes.
    fn merge(&mut self, key: &str, value: Raw) -> Result<(), ConfigError> {
        let mut table = self.stored()?;
        table.insert(key.to_string(), value);
        *self = Config::read(&table)?;
        Ok(())
    }

    /// Every key and its value, as a TOML file would hold them.
    fn stored(&self) -> Result<Table, ConfigError> {
        match toml::Value::try_from(self) {
            Ok(toml::Value::Table(table)) => Ok(table
                .into_iter()
                .map(|(key, value)| (key, Raw::Stored(value)))
                .collect()),
            // toml holds integers as i64: only a count set by hand beyond i64::MAX gets here, and validation
            // refuses it naming its key.
            other => Err(self.validate().err().unwrap_or_else(|| ConfigError::Toml {
                path: "<configuration>".to_string(),
                message: match other {
                    Err(error) => error.to_string(),
                    Ok(_) => "not a table".to_string(),
                },
            })),
        }
    }

    /// Reads `table` over the defaults and validates the result; a rule between two keys names the key whose
    /// value the user gave.
    ///
    /// Every problem is reported at once: the values that cannot be read (each given key read alone over the
    /// defaults, so that one bad value does not hide the next), or else every broken rule.
    fn read_validated(table: &Table) -> Result<Config, ConfigError> {
        let config = match Config::read(table) {
            Ok(config) => config,
            Err(first) => {
                let errors: Vec<ConfigError> = table
                    .iter()
                    .filter(|(_, value)| value.is_given())
                    .filter_map(|(key, value)| {
                        let alone = Table::from([(key.clone(), value.clone())]);
                        Config::read(&alone).err()
                    })
                    .collect();
                return Err(match ConfigError::all(errors) {
                    Err(all) => all,
                    Ok(()) => first,
                });
            }
        };
        config.check(&|key| table.get(key).is_some_and(Raw::is_given))?;
        Ok(config)
    }

    /// Reads `table` over the defaults, without validating.
    fn read(table: &Table) -> Result<Config, ConfigError> {
        let solver_keys = keys().solver;
        let (solver, params): (Vec<Entry>, Vec<Entry>) = table
            .iter()
            .map(|(key, value)| (key.as_str(), value))
            .partition(|(key, _)| solver_keys.contains(key));
        // An unknown key is refused by the struct that reads it; the message lists every key.
        let listing_keys = |error| match error {
            ConfigError::UnknownKey { key, .. } => ConfigError::UnknownKey {
                key,
                known: all_keys().join(", "),
            },
            other => other,
        };
        Ok(Config {
            params: de::read(&params).map_err(listing_keys)?,
            solver: de::read(&solver).map_err(listing_keys)?,
        })
    }
}

/// The key and the value of a `key=value` override, trimmed.
fn split_override(assignment: &str) -> Result<(&str, &str), ConfigError> {
    match assignment.split_once('=') {
        Some((key, value)) if !key.trim().is_empty() => Ok((key.trim(), value.trim())),
        _ => Err(ConfigError::MalformedOverride {
            assignment: assignment.to_string(),
        }),
    }
}

/// The keys and values of the flat TOML file at `path`; errors carry the path.
///
/// Only a regular file (or a link to one) is read, and at most [`MAX_CONFIG_BYTES`] of it: a device such as
/// `/dev/zero` or a pipe would be read forever.
pub(crate) fn file_table(path: &Path) -> Result<Table, ConfigError> {
    use std::io::Read;

    let shown = path.display().to_string();
    let io = |source| ConfigError::Io {
        path: shown.clone(),
        source,
    };
    let refused = |reason: String| ConfigError::NotAConfigFile {
        path: shown.clone(),
        reason,
    };
    // The kind is read before the file is opened: opening a FIFO waits for a writer, for ever.
    let kind = std::fs::metadata(path).map_err(io)?.file_type();
    if !kind.is_file() {
        return Err(refused(format!(
            "it is not a regular file (it is {})",
            if kind.is_dir() {
                "a directory"
            } else {
                "a device, a pipe or a socket"
            }
        )));
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(MAX_CONFIG_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_CONFIG_BYTES {
        return Err(refused(format!(
            "it is larger than {MAX_CONFIG_BYTES} bytes (a configuration is a flat file of a few dozen keys)"
        )));
    }
    let text =
        String::from_utf8(bytes).map_err(|e| refused(format!("it is not UTF-8 text ({e})")))?;
    document(&text, &shown)
}

/// The keys and values of a flat TOML document read from `origin` (a path, or `"<string>"`), each value with
/// the text it was written as.
fn document(text: &str, origin: &str) -> Result<Table, ConfigError> {
    let parsed: std::collections::BTreeMap<String, toml::Spanned<toml::Value>> =
        toml::from_str(text).map_err(|error: toml::de::Error| ConfigError::Toml {
            path: origin.to_string(),
            message: error.to_string().trim_end().to_string(),
        })?;
    Ok(parsed
        .into_iter()
        .map(|(key, value)| {
            let written = text.get(value.span()).map(str::to_string);
            (key, Raw::Given(value.into_inner(), written))
        })
        .collect())
}

/// The parameters `T` of a walker other than the wheel (docs/model.md section 13), read as a configuration is:
/// `T`'s defaults, then the flat TOML `file` if there is one, then each real-valued `key=value` of `overrides`.
/// The keys are `T`'s fields (read off its serialization, never listed by hand); an unknown key, a value that
/// is not a number or a malformed override is an error that names it.
pub fn read_walker_parameters<T, S>(file: Option<&Path>, overrides: &[S]) -> Result<T, ConfigError>
where
    T: serde::Serialize + serde::de::DeserializeOwned + Default,
    S: AsRef<str>,
{
    let defaults = toml::Table::try_from(T::default()).map_err(|e| ConfigError::Toml {
        path: "<defaults>".to_string(),
        message: e.to_string(),
    })?;
    parameter_table(defaults, file, overrides)?
        .try_into()
        .map_err(|e: toml::de::Error| ConfigError::Toml {
            path: file.map_or_else(|| "--set".to_string(), |p| p.display().to_string()),
            message: e.message().to_string(),
        })
}

/// The real-valued parameters named in `defaults` (a described walker's, docs/model.md section 13), read as
/// [`read_walker_parameters`] reads a walker's: the defaults, then the flat TOML `file`, then `overrides`; their
/// values in the order of `defaults`.
pub fn read_named_parameters<S: AsRef<str>>(
    defaults: &[(&str, f64)],
    file: Option<&Path>,
    overrides: &[S],
) -> Result<Vec<f64>, ConfigError> {
    let table: toml::Table = defaults
        .iter()
        .map(|(k, v)| (k.to_string(), toml::Value::Float(*v)))
        .collect();
    let read = parameter_table(table, file, overrides)?;
    defaults
        .iter()
        .map(|(key, _)| match read.get(*key) {
            Some(toml::Value::Float(x)) => Ok(*x),
            Some(toml::Value::Integer(i)) => Ok(*i as f64),
            other => Err(ConfigError::WrongType {
                key: key.to_string(),
                expected: "a number".to_string(),
                found: other.map_or_else(String::new, ToString::to_string),
            }),
        })
        .collect()
}

/// `defaults` with the keys of the flat TOML `file` and then of `overrides` (`key=value`, a number) replaced:
/// an unknown key, a value that is not a number or a malformed override is an error that names it.
fn parameter_table<S: AsRef<str>>(
    defaults: toml::Table,
    file: Option<&Path>,
    overrides: &[S],
) -> Result<toml::Table, ConfigError> {
    let known = || defaults.keys().cloned().collect::<Vec<_>>().join(", ");
    let mut table = defaults.clone();
    if let Some(path) = file {
        for (key, raw) in file_table(path)? {
            if !defaults.contains_key(&key) {
                return Err(ConfigError::UnknownKey {
                    key,
                    known: known(),
                });
            }
            let value = match raw {
                Raw::Given(toml::Value::Float(x), Some(text)) => {
                    toml::Value::Float(de::literal(&key, &text, x)?)
                }
                Raw::Stored(value) | Raw::Given(value, _) => value,
                Raw::Text(text) => toml::Value::String(text),
            };
            table.insert(key, value);
        }
    }
    for assignment in overrides {
        let assignment = assignment.as_ref();
        let Some((key, value)) = assignment.split_once('=') else {
            return Err(ConfigError::MalformedOverride {
                assignment: assignment.to_string(),
            });
        };
        let key = key.trim();
        if !defaults.contains_key(key) {
            return Err(ConfigError::UnknownKey {
                key: key.to_string(),
                known: known(),
            });
        }
        let text = value.trim();
        let number: f64 = text.parse().map_err(|_| ConfigError::WrongType {
            key: key.to_string(),
            expected: "a number".to_string(),
            found: value.to_string(),
        })?;
        table.insert(
            key.to_string(),
            toml::Value::Float(de::literal(key, text, number)?),
        );
    }
    Ok(table)
}

/// A key of [`Config::numeric_keys`], checked once: the parameter of a sweep, a map's axis, a continuation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NumericKey(&'static str);

impl NumericKey {
    /// The key `key`, or the error that names it and the keys there are.
    pub fn new(key: &str) -> Result<NumericKey, ConfigError> {
        Config::numeric_keys()
            .iter()
            .find(|k| **k == key)
            .map(|k| NumericKey(k))
            .ok_or_else(|| unknown_numeric_key(key))
    }

    /// Its name, as in the configuration.
    pub fn name(self) -> &'static str {
        self.0
    }
}

impl std::fmt::Display for NumericKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0)
    }
}

/// The error for a key that is not one of [`Config::numeric_keys`].
fn unknown_numeric_key(key: &str) -> ConfigError {
    ConfigError::UnknownKey {
        key: key.to_string(),
        known: Config::numeric_keys().join(", "),
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;
    use crate::integrate::Method;
    use crate::params::test_support::{key_of, temp_path};
    use crate::params::{ContactInconsistency, ImpactModel, RearExit};

    #[test]
    fn inconsistent_contact_parses_both_values() {
        for treatment in [ContactInconsistency::Slide, ContactInconsistency::Rebound] {
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
        config.params.rear_exit = RearExit::Reset;
        config.solver.rtol = 3e-11;
        config.solver.max_events_per_step = 17;
        config.solver.integrator = Method::Dopri5;

        let text = toml::to_string(&config).unwrap();
        // The file is flat and holds exactly the documented keys.
        let table: toml::Table = text.parse().unwrap();
        let mut written: Vec<&str> = table.keys().map(String::as_str).collect();
        // `rear_stopper`, `min_length` and `touchdown_length` stay at their defaults here (rigid legs need them),
        // and are left out, as `friction` at its default (infinity, no slip).
        let mut expected: Vec<&str> = all_keys()
            .iter()
            .copied()
            .filter(|k| !["rear_stopper", "min_length", "touchdown_length", "friction"].contains(k))
            .collect();
        written.sort_unstable();
        expected.sort_unstable();
        assert_eq!(written.len(), 26);
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

    /// The typed fields `set_numeric` writes are exactly the numeric keys serde reads, and writing one in place
    /// is writing it through the configuration's TOML (the way every key was set before).
    #[test]
    fn numeric_fields_are_the_numeric_keys() {
        for key in all_keys() {
            let numeric = Config::numeric_keys().contains(key);
            assert_eq!(
                Config::default().numeric_field(key).is_some(),
                numeric,
                "{key}"
            );
            if !numeric {
                continue;
            }
            for value in [0.123456789, 7.0, f64::INFINITY] {
                let mut in_place = Config::default();
                in_place.set_numeric(key, value).unwrap();
                let mut through_toml = Config::default();
                through_toml
                    .merge(key, Raw::Stored(toml::Value::Float(value)))
                    .unwrap();
                assert_eq!(in_place, through_toml, "{key} = {value}");
                assert_eq!(in_place.get_numeric(key).unwrap(), value, "{key}");
            }
        }
    }

    #[test]
    fn numeric_keys_get_set_round_trip() {
        // Every numeric key has a value at the defaults, those written configurations leave out included.
        let defaults = Config::default();
        for key in Config::numeric_keys() {
            defaults.get_numeric(key).unwrap();
        }
        assert_eq!(defaults.get_numeric("friction").unwrap(), f64::INFINITY);
        assert_eq!(defaults.get_numeric("min_length").unwrap(), 0.0);
        let keys = Config::numeric_keys();
        assert_eq!(keys.len(), 22);
        assert!(keys.iter().all(|key| all_keys().contains(key)));
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

    /// Every key of the default configuration is written by the TOML writer and read back to the same value,
    /// alone or all together, and the writer's keys are exactly the keys serde reads.
    #[test]
    fn every_default_key_round_trips_through_toml() {
        let defaults = Config::default();
        let table = toml::Table::try_from(&defaults).unwrap();
        let mut written: Vec<&str> = table.keys().map(String::as_str).collect();
        // `rear_exit`, `rear_stopper`, `min_length`, `touchdown_length` and `friction` are left out at their defaults, so that written
        // configurations stay as they were before them; `keys_left_out_at_defaults` names them (and reads back as
        // the defaults).
        let left_out = defaults.params.keys_left_out_at_defaults();
        let left_out: Vec<&str> = left_out.iter().map(|(key, _)| *key).collect();
        assert_eq!(
            left_out,
            [
                "rear_exit",
                "rear_stopper",
                "min_length",
                "touchdown_length",
                "friction"
            ]
        );
        let mut read: Vec<&str> = all_keys()
            .iter()
            .copied()
            .filter(|k| !left_out.contains(k))
            .collect();
        for (key, value) in defaults.params.keys_left_out_at_defaults() {
            let mut config = Config::default();
            config.set_value(key, &value).unwrap();
            assert_eq!(config, defaults, "{key} = {value}");
        }
        written.sort_unstable();
        read.sort_unstable();
        assert_eq!(written, read);

        let text = toml::to_string(&defaults).unwrap();
        assert_eq!(Config::from_toml_str(&text).unwrap(), defaults);
        for (key, value) in &table {
            let mut one = toml::Table::new();
            one.insert(key.clone(), value.clone());
            let text = toml::to_string(&one).unwrap();
            assert_eq!(Config::from_toml_str(&text).unwrap(), defaults, "{text}");
            let mut config = Config::default();
            config.set(key, &text_of(value)).unwrap();
            assert_eq!(config, defaults, "--set {key}={value}");
        }
    }

    /// The text a `--set` override would give for `value`.
    fn text_of(value: &toml::Value) -> String {
        match value {
            toml::Value::String(s) => s.clone(),
            toml::Value::Float(x) => format!("{x:e}"),
            other => other.to_string(),
        }
    }

    #[test]
    fn unknown_key_is_refused_naming_it_in_a_file_and_in_set() {
        let known = all_keys().join(", ");
        let path = temp_path("unknown.toml");
        std::fs::write(&path, "viscosity = 30\nviscosityy = 5\n").unwrap();
        let from_file = Config::from_file(&path);
        let loaded = Config::load(Some(&path), &["slope=0.05"]);
        std::fs::remove_file(&path).unwrap();
        let errors = [
            from_file.unwrap_err(),
            loaded.unwrap_err(),
            Config::from_toml_str("viscosityy = 5").unwrap_err(),
            Config::load(None, &["viscosityy=5"]).unwrap_err(),
            Config::default()
                .apply_override("viscosityy=5")
                .unwrap_err(),
            Config::default()
                .with_values([("viscosityy".to_string(), toml::Value::Integer(5))])
                .unwrap_err(),
        ];
        for error in errors {
            match &error {
                ConfigError::UnknownKey { key, known: listed } => {
                    assert_eq!(key, "viscosityy");
                    assert_eq!(listed, &known);
                }
                other => panic!("expected UnknownKey, got {other:?}"),
            }
            assert!(error.to_string().contains("`viscosityy`"), "{error}");
        }
    }

    /// A finite literal that an f64 cannot hold is refused naming the key, not read as 0 or infinity.
    #[test]
    fn numbers_out_of_f64_range_are_refused_not_rounded() {
        for assignment in [
            "viscosity=1e-400",
            "viscosity=1e400",
            "viscosity=-1e400",
            "hub_inertia=0.00001e-330",
        ] {
            let error = Config::default().apply_override(assignment).unwrap_err();
            assert!(
                matches!(error, ConfigError::InvalidValue { .. }),
                "{assignment}: {error}"
            );
            let (key, value) = assignment.split_once('=').unwrap();
            assert_eq!(key_of(&error), Some(key), "{assignment}: {error}");
            assert!(error.to_string().contains(value), "{assignment}: {error}");
        }
        for text in [
            "viscosity = 1e-400",
            "viscosity = -1e400",
            "viscosity = 1_0e-400",
        ] {
            let error = Config::from_toml_str(text).unwrap_err();
            assert!(
                matches!(error, ConfigError::InvalidValue { .. }),
                "{text}: {error}"
            );
            assert_eq!(key_of(&error), Some("viscosity"), "{text}: {error}");
        }
        // Zero written as zero, subnormal numbers and the non-finite spellings are read as written (the
        // last are refused by validation, naming the key).
        for (assignment, value) in [
            ("viscosity=0e-400", 0.0),
            ("viscosity=0.000", 0.0),
            ("hub_inertia=1e-310", 1e-310),
        ] {
            let mut config = Config::default();
            config.apply_override(assignment).unwrap();
            let key = assignment.split_once('=').unwrap().0;
            assert_eq!(config.get_numeric(key).unwrap(), value, "{assignment}");
        }
        assert_eq!(
            Config::from_toml_str("viscosity = 0.0e-400")
                .unwrap()
                .params
                .viscosity,
            0.0
        );
        let error = Config::load(None, &["viscosity=-inf"]).unwrap_err();
        assert_eq!(key_of(&error), Some("viscosity"), "{error}");
        assert!(error.to_string().contains("must be finite"), "{error}");
    }

    /// Overrides are merged before validation: they may repair a file, and a rule between two keys names the
    /// key the user gave.
    #[test]
    fn overrides_are_validated_with_the_file() {
        let path = temp_path("stopper.toml");
        std::fs::write(&path, "stopper_length = 2\n").unwrap();
        let alone = Config::from_file(&path);
        let repaired = Config::load(Some(&path), &["spring_natural_length=2.5"]);
        let still_bad = Config::load(Some(&path), &["viscosity=10"]);
        std::fs::remove_file(&path).unwrap();

        let repaired = repaired.unwrap();
        assert_eq!(repaired.params.stopper_length, 2.0);
        assert_eq!(repaired.params.spring_natural_length, 2.5);

        for error in [alone.unwrap_err(), still_bad.unwrap_err()] {
            assert_eq!(key_of(&error), Some("stopper_length"), "{error}");
            assert_eq!(
                error.to_string(),
                concat!(
                "invalid value 2 for `stopper_length`: must be <= spring_natural_length (1.02)",
                " (a shorter spring pulls a free leg off its stopper, so the rear leg is never relocked: it needs rear_exit = \"reset\")"
            )
            );
        }
        // Given both, or only the other key, the rule names the key it always named.
        let error =
            Config::load(None, &["stopper_length=2", "spring_natural_length=1.5"]).unwrap_err();
        assert_eq!(
            error.to_string(),
            concat!(
                "invalid value 1.5 for `spring_natural_length`: must be >= stopper_length (2)",
                " (a shorter spring pulls a free leg off its stopper, so the rear leg is never relocked: it needs rear_exit = \"reset\")"
            )
        );
        // Every rule it breaks is listed, each naming the key given.
        let error = Config::load(None, &["stopper_length=0.2"]).unwrap_err();
        assert_eq!(
            error.to_string(),
            "2 problems: 1) invalid value 0.2 for `stopper_length`: must be > leg_mass_offset (0.3); \
             2) invalid value 0.2 for `stopper_length`: must be > fall_hub_height (0.3)"
        );
        let error = Config::default()
            .with_values([("stopper_length".to_string(), toml::Value::Float(0.25))])
            .unwrap_err();
        for problem in error.problems() {
            assert_eq!(key_of(problem), Some("stopper_length"), "{error}");
        }
        let error = Config::load(None, &["hub_mass=1e-7"]).unwrap_err();
        assert_eq!(key_of(&error), Some("hub_mass"), "{error}");
        assert!(error.to_string().contains("leg_mass / hub_mass"), "{error}");
    }

    /// Keys holding an integer take integers only, from a file, `--set` and typed fronts alike.
    #[test]
    fn integer_keys_take_integers_only() {
        for value in ["8.0", "8e0", "8.5", "true", "\"8\""] {
            let error = Config::from_toml_str(&format!("legs = {value}")).unwrap_err();
            assert!(
                matches!(error, ConfigError::WrongType { .. }),
                "{value}: {error}"
            );
        }
        for value in ["8.0", "8e0", "0x8", "true"] {
            let error = Config::default()
                .apply_override(&format!("legs={value}"))
                .unwrap_err();
            assert!(
                matches!(error, ConfigError::WrongType { .. }),
                "{value}: {error}"
            );
            assert!(
                error.to_string().contains("a non-negative integer"),
                "{error}"
            );
        }
        let error = Config::default()
            .with_values([("legs".to_string(), toml::Value::Float(8.0))])
            .unwrap_err();
        assert_eq!(
            error.to_string(),
            "wrong type for `legs`: expected a non-negative integer, found the float 8"
        );
    }
}
