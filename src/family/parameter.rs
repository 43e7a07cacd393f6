//! A configuration with one numeric key free: the parameter of a gait family, of a sweep's or a map's row, of
//! an orbit diagram. The key is checked once ([`NumericKey`]); [`Parameter::at`] is the one place where it is
//! set to a value and the model there built, with a typed error where the value leaves the valid domain.

use crate::dynamics::Model;
use crate::gait::StepMap;
use crate::params::{Config, ConfigError, NumericKey};

/// One numeric key of a configuration, free to take values.
#[derive(Debug, Clone, Copy)]
pub struct Parameter<'a> {
    config: &'a Config,
    key: NumericKey,
}

/// The configuration and the model at one value of a [`Parameter`].
#[derive(Debug, Clone)]
pub struct ParamPoint {
    /// The parameter's value.
    pub value: f64,
    /// The configuration with the key at `value`, validated.
    pub config: Config,
    /// Its model.
    pub model: Model,
}

impl<'a> Parameter<'a> {
    /// The key `key` of `config`.
    pub fn new(config: &'a Config, key: NumericKey) -> Parameter<'a> {
        Parameter { config, key }
    }

    /// The key named `key` of `config`: one of [`Config::numeric_keys`], else the error names the key and the
    /// keys there are.
    pub fn named(config: &'a Config, key: &str) -> Result<Parameter<'a>, ConfigError> {
        Ok(Parameter::new(config, NumericKey::new(key)?))
    }

    /// The key's name.
    pub fn key(&self) -> &'static str {
        self.key.name()
    }

    /// The configuration the key is free in (its own value of the key is not used).
    pub fn config(&self) -> &'a Config {
        self.config
    }

    /// The configuration with the key at `value`, validated, and its model; the broken rule where `value`
    /// leaves the valid domain (alone, or with the other keys).
    pub fn at(&self, value: f64) -> Result<ParamPoint, ConfigError> {
        let config = self.config.with(self.key.name(), value)?;
        let model = Model::new(&config.params)?;
        Ok(ParamPoint {
            value,
            config,
            model,
        })
    }

    /// The configuration with another key, `other`, at `value` (one point of a two-parameter curve: this
    /// parameter is then set by [`Parameter::at`] of the configuration returned).
    pub fn fixing(&self, other: &str, value: f64) -> Result<Config, ConfigError> {
        self.config.with(other, value)
    }

    /// The same key in `config`.
    pub fn of<'b>(&self, config: &'b Config) -> Parameter<'b> {
        Parameter {
            config,
            key: self.key,
        }
    }
}

impl ParamPoint {
    /// The step map at this point, with the configuration's solver options.
    pub fn step_map(&self) -> StepMap<'_> {
        StepMap::new(&self.model, &self.config.solver)
    }
}
