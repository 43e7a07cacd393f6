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
use crate::params::{Config, ConfigError, SolverOptions};
use crate::walk::SectionState;

/// What to sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepSpec {
    /// A numeric key of the configuration ([`Config::numeric_keys`]), e.g. `viscosity`.
    pub param: String,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values, evenly spaced, ends included (at least 2).
    pub points: usize,
}

impl SweepSpec {
    /// Check the specification against a configuration.
    pub fn validate(&self, config: &Config) -> Result<(), ConfigError> {
        config.get_numeric(&self.param)?;
        let invalid = |value: String, reason: &str| ConfigError::InvalidValue {
            key: format!("sweep {}", self.param),
            value,
            reason: reason.to_string(),
        };
        if !(self.from.is_finite() && self.to.is_finite()) || self.from == self.to {
            return Err(invalid(
                format!("{}..{}", self.from, self.to),
                "the range must have two different finite ends",
            ));
        }
        if self.points < 2 {
            return Err(invalid(
                self.points.to_string(),
                "at least 2 points are needed",
            ));
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
    sweep_values(
        config,
        &spec.param,
        &spec.values(),
        initial,
        options,
        progress,
    )
}

/// Sweep the real-valued key `param` over the given `values` (in the order given) with continuation, as
/// [`sweep`] does over a [`SweepSpec`]'s evenly spaced values.
pub fn sweep_values(
    config: &Config,
    param: &str,
    values: &[f64],
    initial: &SectionState,
    options: &GaitOptions,
    progress: &(dyn Fn(&SweepPoint) + Sync),
) -> Result<Vec<SweepPoint>, ConfigError> {
    config.get_numeric(param)?;
    let coarse_values: Vec<f64> = values.iter().copied().step_by(COARSE_STRIDE).collect();
    let coarse = continue_along(
        config,
        param,
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
                param,
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
