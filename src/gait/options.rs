//! The valid range of every gait-search setting ([`GaitOptions`]), checked in one place: the command line's
//! flags and the Python binding's keywords are read into a [`GaitOptions`] and checked by
//! [`GaitOptions::validate`], so both report the same rule (`docs/model.md` section 6).

use super::limit_cycle::GaitOptions;
use crate::fmt::short;
use crate::params::ConfigError;

/// The most transient steps a search walks before Newton's method (`transient_steps`): a step takes about a
/// millisecond to compute, so this is minutes; a walk that has not settled by then will not.
pub const MAX_TRANSIENT_STEPS: usize = 100_000;

/// The most Newton iterations allowed (`max_iterations`): Newton's method converges in a handful or not at
/// all.
pub const MAX_NEWTON_ITERATIONS: usize = 1000;

/// Accepted range of the Newton tolerance `max |P(s) - s|` (`tolerance`). Below: the step map is computed to
/// about 1e-13 (integration and event-location tolerances, rounding over a step of thousands of solves), so
/// a smaller residual cannot be reached reliably. Above: a residual of 1e-6 in the section coordinates (m,
/// rad/s, m/s) is no longer a fixed point, and with no transient a loose tolerance returns the start itself.
pub const TOLERANCE_RANGE: [f64; 2] = [1e-13, 1e-6];

/// Accepted range of the relative finite-difference step of `DP` (`fd_step`). Below: the difference of two
/// step maps accurate to about 1e-12 divided by the step is noise (1e-16 gives a multiplier of 1430 where
/// the true one is 0.044, and 1e-18 does not move the state at all). Above: the truncation error of the
/// difference exceeds the multipliers' resolution.
pub const FD_STEP_RANGE: [f64; 2] = [1e-6, 1e-2];

impl GaitOptions {
    /// Checks every setting against its range: `transient_steps <=` [`MAX_TRANSIENT_STEPS`],
    /// `1 <= max_iterations <=` [`MAX_NEWTON_ITERATIONS`], `tolerance` in [`TOLERANCE_RANGE`], `fd_step` in
    /// [`FD_STEP_RANGE`]. Each error names the field (the Python keyword; the command line renames it to its
    /// flag); several are [`ConfigError::Several`].
    pub fn validate(&self) -> Result<(), ConfigError> {
        let mut errors = Vec::new();
        let mut count = |key: &str, value: usize, range: [usize; 2]| {
            if !(range[0]..=range[1]).contains(&value) {
                errors.push(invalid(
                    key,
                    value.to_string(),
                    format!("must be between {} and {}", range[0], range[1]),
                ));
            }
        };
        count(
            "transient_steps",
            self.transient_steps,
            [0, MAX_TRANSIENT_STEPS],
        );
        count(
            "max_iterations",
            self.max_iterations,
            [1, MAX_NEWTON_ITERATIONS],
        );
        for (key, value, [lo, hi], why) in [
            (
                "tolerance",
                self.tolerance,
                TOLERANCE_RANGE,
                "the step map is computed to about 1e-13; a looser residual is not a fixed point",
            ),
            (
                "fd_step",
                self.fd_step,
                FD_STEP_RANGE,
                "a relative finite-difference step outside it gives a Jacobian of noise or of truncation \
                 error",
            ),
        ] {
            if !(value.is_finite() && (lo..=hi).contains(&value)) {
                errors.push(invalid(
                    key,
                    short(value),
                    format!("must be between {} and {} ({why})", short(lo), short(hi)),
                ));
            }
        }
        match errors.len() {
            0 => Ok(()),
            1 => Err(errors.remove(0)),
            _ => Err(ConfigError::Several { errors }),
        }
    }
}

/// A [`ConfigError::InvalidValue`] for the setting `key`.
fn invalid(key: &str, value: String, reason: String) -> ConfigError {
    ConfigError::InvalidValue {
        key: key.to_string(),
        value,
        reason,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_sweep_settings_are_valid() {
        GaitOptions::default().validate().unwrap();
        GaitOptions::for_sweeps().validate().unwrap();
    }

    /// `find_gait(p, fd_step=1e-16)` called a gait unstable with a multiplier of 1430, `fd_step <= 1e-18`
    /// hung, `--transient 0 --tolerance 1` returned the start, `--transient 100000000` ran on: each is
    /// refused naming the setting and its range.
    #[test]
    fn fd_step_tolerance_and_transient_out_of_range_are_refused() {
        let cases = [
            (
                GaitOptions {
                    fd_step: 1e-16,
                    ..GaitOptions::default()
                },
                "fd_step",
            ),
            (
                GaitOptions {
                    fd_step: f64::NAN,
                    ..GaitOptions::default()
                },
                "fd_step",
            ),
            (
                GaitOptions {
                    tolerance: 1.0,
                    transient_steps: 0,
                    ..GaitOptions::default()
                },
                "tolerance",
            ),
            (
                GaitOptions {
                    tolerance: 1e-14,
                    ..GaitOptions::default()
                },
                "tolerance",
            ),
            (
                GaitOptions {
                    transient_steps: 100_000_000,
                    ..GaitOptions::default()
                },
                "transient_steps",
            ),
            (
                GaitOptions {
                    max_iterations: 0,
                    ..GaitOptions::default()
                },
                "max_iterations",
            ),
        ];
        for (options, key) in cases {
            let error = options.validate().unwrap_err();
            assert_eq!(error.key(), Some(key), "{error}");
            assert!(error.to_string().contains("must be between"), "{error}");
        }
        let error = GaitOptions {
            fd_step: 0.0,
            tolerance: 1.0,
            ..GaitOptions::default()
        }
        .validate()
        .unwrap_err();
        let keys: Vec<_> = error.problems().iter().map(|e| e.key()).collect();
        assert_eq!(keys, [Some("tolerance"), Some("fd_step")], "{error}");
    }
}
