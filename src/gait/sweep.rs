//! Parameter sweeps with continuation (MODEL.md section 6, the paper's Fig. 2).
//!
//! Every point starts Newton's method from a neighbour's gait, with the neighbour's `DP` as the first Newton
//! matrix. A point whose search fails from the neighbour is retried from the sweep's initial state with a full
//! transient; after a failure the next point starts from the last gait found.
//!
//! Parallelism (rayon) with results bitwise identical for any number of threads: first every
//! [`COARSE_STRIDE`]-th point is continued in order (the coarse pass); then the points between two coarse points
//! are continued from the left one, all intervals in parallel. The chunking is fixed by the sweep, not by the
//! threads, and each point's computation is the same wherever it runs. Inside each point the step-map
//! evaluations of the finite-difference Jacobian run in parallel as well.

use rayon::prelude::*;
use serde::Serialize;

use super::limit_cycle::{find_gait, Gait, GaitOptions};
use super::step_map::StepMap;
use crate::dynamics::Model;
use crate::error::short;
use crate::params::{Config, ConfigError, SolverOptions};
use crate::walk::SectionState;

/// The most points a sweep may have.
pub const MAX_SWEEP_POINTS: usize = 100_000;

/// What to sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepSpec {
    /// A numeric key of the configuration ([`Config::numeric_keys`]), e.g. `viscosity`.
    pub param: String,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values, evenly spaced, ends included (2 to [`MAX_SWEEP_POINTS`]).
    pub points: usize,
}

impl SweepSpec {
    /// Check the specification against a configuration: a known numeric key, two different finite ends, at
    /// least 2 points, and a configuration that is valid with the parameter at either end.
    pub fn validate(&self, config: &Config) -> Result<(), ConfigError> {
        config.get_numeric(&self.param)?;
        let invalid = |value: String, reason: &str| ConfigError::InvalidValue {
            key: format!("sweep {}", self.param),
            value,
            reason: reason.to_string(),
        };
        if !(self.from.is_finite() && self.to.is_finite()) || self.from == self.to {
            return Err(invalid(
                format!("{}..{}", short(self.from), short(self.to)),
                "the range must have two different finite ends",
            ));
        }
        if !(2..=MAX_SWEEP_POINTS).contains(&self.points) {
            return Err(invalid(
                self.points.to_string(),
                &format!("the number of points must be between 2 and {MAX_SWEEP_POINTS}"),
            ));
        }
        // Every rule of the configuration must hold at both ends (the rules on one key are intervals, so the
        // whole range is then valid), before anything is computed.
        for (end, value) in [("from", self.from), ("to", self.to)] {
            let mut at_end = config.clone();
            at_end.set_numeric(&self.param, value)?;
            if let Err(e) = at_end.validate() {
                return Err(invalid(
                    format!("--{end} {}", short(value)),
                    &format!("the range leaves the valid domain: {e}"),
                ));
            }
        }
        Ok(())
    }

    /// The parameter values.
    pub fn values(&self) -> Vec<f64> {
        let n = self.points - 1;
        (0..=n)
            .map(|i| self.from + (self.to - self.from) * (i as f64 / n as f64))
            .collect()
    }
}

/// The result at one parameter value.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepPoint {
    /// The parameter value.
    pub value: f64,
    /// `stable`, `unstable`, or why no gait was found (`invalid_parameter`, `rolled_back`, ...).
    pub status: String,
    /// The failure, in words.
    pub message: Option<String>,
    /// The gait, if found.
    pub gait: Option<Gait>,
}

/// The configuration with the swept parameter set to `value`, validated, and its model.
pub fn configured(
    config: &Config,
    param: &str,
    value: f64,
) -> Result<(Config, Model), ConfigError> {
    let mut c = config.clone();
    c.set_numeric(param, value)?;
    c.validate()?;
    let model = Model::new(&c.params)?;
    Ok((c, model))
}

/// The gait at `value`, continued from `previous` (a neighbouring gait) if given, else from `initial` with the
/// full transient; a failed continuation is retried from `initial`.
pub fn gait_at_value(
    config: &Config,
    param: &str,
    value: f64,
    initial: &SectionState,
    previous: Option<&Gait>,
    options: &GaitOptions,
) -> SweepPoint {
    let (c, model) = match configured(config, param, value) {
        Ok(x) => x,
        Err(e) => {
            return SweepPoint {
                value,
                status: "invalid_parameter".to_string(),
                message: Some(e.to_string()),
                gait: None,
            }
        }
    };
    let solver: &SolverOptions = &c.solver;
    let map = StepMap::new(&model, solver);
    let continued = previous.and_then(|g| {
        let opts = GaitOptions {
            transient_steps: 0,
            ..*options
        };
        find_gait(&map, &g.section, &opts, Some(&g.jacobian_matrix())).ok()
    });
    let result = match continued {
        Some(g) => Ok(g),
        None => find_gait(&map, initial, options, None),
    };
    match result {
        Ok(g) => SweepPoint {
            value,
            status: if g.stable { "stable" } else { "unstable" }.to_string(),
            message: None,
            gait: Some(g),
        },
        Err(e) => SweepPoint {
            value,
            status: e.kind().to_string(),
            message: Some(e.to_string()),
            gait: None,
        },
    }
}

/// Stride of the coarse continuation pass.
pub const COARSE_STRIDE: usize = 10;

/// Continue along `values` from `start` (the gait at the point before them, if any).
fn continue_along(
    config: &Config,
    param: &str,
    values: &[f64],
    initial: &SectionState,
    start: Option<Gait>,
    options: &GaitOptions,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Vec<SweepPoint> {
    let mut last = start;
    values
        .iter()
        .map(|&value| {
            let point = gait_at_value(config, param, value, initial, last.as_ref(), options);
            if let Some(g) = &point.gait {
                last = Some(g.clone());
            }
            progress(&point);
            point
        })
        .collect()
}

/// Sweep `spec.param` over its range with continuation, calling `progress` after each point.
pub fn sweep(
    config: &Config,
    spec: &SweepSpec,
    initial: &SectionState,
    options: &GaitOptions,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<Vec<SweepPoint>, ConfigError> {
    spec.validate(config)?;
    let values = spec.values();
    let coarse_values: Vec<f64> = values.iter().copied().step_by(COARSE_STRIDE).collect();
    let coarse = continue_along(
        config,
        &spec.param,
        &coarse_values,
        initial,
        None,
        options,
        progress,
    );
    let fills: Vec<Vec<SweepPoint>> = coarse
        .par_iter()
        .enumerate()
        .map(|(i, left)| {
            let lo = i * COARSE_STRIDE + 1;
            let hi = ((i + 1) * COARSE_STRIDE).min(values.len());
            let start = left.gait.clone();
            continue_along(
                config,
                &spec.param,
                &values[lo.min(hi)..hi],
                initial,
                start,
                options,
                progress,
            )
        })
        .collect();
    let mut points = Vec::with_capacity(values.len());
    for (left, fill) in coarse.into_iter().zip(fills) {
        points.push(left);
        points.extend(fill);
    }
    Ok(points)
}
