//! The physical model's parameters: [`Params`], the wheel and the slope (`docs/model.md` sections 1, 2
//! and 7, defaults from the paper's Table 1), with the rules a valid model obeys.

use std::f64::consts::{FRAC_PI_2, PI};

use super::solver::{ContactInconsistency, ImpactModel, RearExit};
use super::{finite, invalid, non_negative, ordered, positive, ConfigError, Order::*, Rules};
use crate::fmt::short;

/// Physical parameters of the wheel and the slope (`docs/model.md` sections 1, 2 and 7).
///
/// Defaults are the paper's Table 1; the viscosity `c` is the parameter the paper sweeps. Check a value
/// built by hand with [`Params::validate`].
///
/// Each field is a key of a configuration file, read by serde (`load`); absent keys keep their
/// defaults and unknown keys are refused.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
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
    /// stopper; shorter (the tension reading) only with `rear_exit = "reset"`. `docs/model.md` sections 2 and 5.
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
    /// What becomes of the old rear leg when it leaves Legs 1 and 2 at a touchdown. Default
    /// [`RearExit::Relock`] (it must be locked on its stopper by then); [`RearExit::Continue`] lets it swing on
    /// as the coordinate `L3`; [`RearExit::Reset`] discards its state. `docs/model.md` section 5.
    #[serde(skip_serializing_if = "RearExit::is_relock")]
    pub rear_exit: RearExit,
    /// Whether Leg 2 (the rear leg) has its extension stopper. Default `true`. `false`: it has no extension
    /// limit, as in a third-party MATLAB VRW code (Leg 1, the fore leg, keeps its stopper, and a leg loses it
    /// when it becomes Leg 2 at a touchdown). Needs `rear_exit = "reset"` (the rear leg is then never relocked)
    /// and `rigid_legs = false`. `docs/model.md` section 5.
    #[serde(skip_serializing_if = "is_true")]
    pub rear_stopper: bool,
    /// Length of the compression stop \[m\]: a rigid limit `L >= min_length` on Legs 1 and 2 (the stroke-limited
    /// leg of the paper's readings), treated like the stopper in every force- and impulse-level
    /// complementarity problem, with its own lock and unlock events; its reaction may only push the leg
    /// outward. Default 0: no compression stop. Otherwise in `(0, stopper_length)`, with soft legs.
    /// `docs/model.md` sections 2 and 4.
    #[serde(skip_serializing_if = "is_zero")]
    pub min_length: f64,
    /// Length at which a leg touches down, and of every leg other than Legs 1 and 2 (rigid spokes) \[m\].
    /// Default 0: the stopper length. Otherwise within the stroke, `[min_length, stopper_length]`; shorter than
    /// the stopper only with `rear_exit = "reset"` (a leg that leaves the coordinates is set to it) and soft
    /// legs. A leg that lands shorter than its stopper is free at once. `docs/model.md` sections 2 and 5.
    #[serde(skip_serializing_if = "is_zero")]
    pub touchdown_length: f64,
    /// Coulomb friction coefficient `mu` of the ground at the leg tips \[-\]. Default infinity (`inf`): the paper's
    /// no-slip contacts, with the frictionless slide of `inconsistent_contact` where no-slip is inconsistent.
    /// Finite: a contact sticks while `|lambda_t| <= mu lambda_n`, slips with `lambda_t = -mu lambda_n
    /// sign(slip velocity)` or is off, and impacts keep their impulses in the cone. Non-negative.
    /// `docs/model.md` section 12.
    #[serde(skip_serializing_if = "is_infinite")]
    pub friction: f64,
}

fn is_infinite(x: &f64) -> bool {
    *x == f64::INFINITY
}

fn is_true(b: &bool) -> bool {
    *b
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
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
            rear_exit: RearExit::Relock,
            rear_stopper: true,
            min_length: 0.0,
            touchdown_length: 0.0,
            friction: f64::INFINITY,
        }
    }
}

impl Params {
    /// The keys that written configurations leave out at their defaults (so that files stay as they were before
    /// these keys existed), with their values here: what a front listing every key adds to the serialization.
    pub fn keys_left_out_at_defaults(&self) -> [(&'static str, toml::Value); 5] {
        [
            (
                "rear_exit",
                toml::Value::String(self.rear_exit.name().to_string()),
            ),
            ("rear_stopper", toml::Value::Boolean(self.rear_stopper)),
            ("min_length", toml::Value::Float(self.min_length)),
            (
                "touchdown_length",
                toml::Value::Float(self.touchdown_length),
            ),
            ("friction", toml::Value::Float(self.friction)),
        ]
    }

    /// Does a leg land on its stopper (locked), the touchdown length being the stopper length?
    pub fn lands_on_stopper(&self) -> bool {
        self.spoke_length() == self.stopper_length
    }

    /// The length at which a leg touches down, and of every leg other than Legs 1 and 2: `touchdown_length`,
    /// or `stopper_length` where that is 0 (its default).
    pub fn spoke_length(&self) -> f64 {
        if self.touchdown_length == 0.0 {
            self.stopper_length
        } else {
            self.touchdown_length
        }
    }

    /// Inter-leg angle `alpha = 2 pi / legs` \[rad\] (`docs/model.md` section 1); `pi/4` by default.
    pub fn alpha(&self) -> f64 {
        2.0 * PI / self.legs as f64
    }

    /// Checks every rule on the physical parameters; every broken rule is reported (one error names its key,
    /// several are [`ConfigError::Several`]).
    ///
    /// Rules: `3 <= legs <=` [`MAX_LEGS`]; every real value finite; `hub_mass`, `leg_mass`, `gravity`, `stopper_length`,
    /// `stiffness > 0`; `hub_inertia`, `viscosity >= 0`; `|slope| < pi/2`;
    /// `0 <= leg_mass_offset < stopper_length`; `spring_natural_length >= stopper_length` (unless
    /// `rear_exit = "reset"`); `rear_stopper = false` only with `rear_exit = "reset"` and soft legs;
    /// `min_length` 0 or in `(0, stopper_length)` with soft legs, and not with `rear_exit = "continue"`;
    /// `leg_mass / hub_mass` within [`MASS_RATIO_LIMIT`] of 1; legs not too stiff to integrate (the time scale
    /// of [`Params::leg_time_scale`] at least [`MIN_LEG_TIME_SCALE`]).
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.check(&|_| true)
    }

    /// [`Params::validate`], where a rule between two keys names the one the user gave (`given(key)`): a file
    /// that sets only `stopper_length = 2` is told that `stopper_length` must be `<= spring_natural_length`,
    /// not that the default `spring_natural_length` is wrong. When both or neither were given, the rule
    /// names the key [`Params::validate`] names.
    pub(crate) fn check(&self, given: &dyn Fn(&str) -> bool) -> Result<(), ConfigError> {
        let mut rules = Rules::new(given);
        self.collect(&mut rules);
        rules.finish()
    }

    /// Checks every rule into `rules` (see [`Params::check`]).
    pub(crate) fn collect(&self, rules: &mut Rules<'_>) {
        self.single_key_rules(rules);
        self.mass_ratio_rule(rules);
        self.stopper_length_rules(rules);
        if !self.rear_stopper {
            self.without_rear_stopper_rules(rules);
        }
        rules.single(non_negative("min_length", self.min_length));
        if self.min_length > 0.0 {
            self.min_length_rules(rules);
        }
        rules.single(non_negative("touchdown_length", self.touchdown_length));
        if self.touchdown_length > 0.0 {
            self.touchdown_length_rules(rules);
        }
        self.friction_rules(rules);
        // The time scale needs sound masses: not when the mass ratio is already refused.
        let ratio = self.leg_mass / self.hub_mass;
        if (1.0 / MASS_RATIO_LIMIT..=MASS_RATIO_LIMIT).contains(&ratio)
            && !["leg_mass", "hub_mass", "viscosity", "stiffness"]
                .iter()
                .any(|key| rules.failed(key))
        {
            let result = self.stiff_legs_rule(&|key| rules.given(key));
            rules.between(["viscosity", "stiffness"], |_| result);
        }
    }

    /// The rules of one key each: `legs` from 3 to [`MAX_LEGS`]; the masses, the stopper length, the stiffness
    /// and gravity positive; the inertia, the mass offset and the viscosity non-negative; the spring's natural
    /// length finite; `|slope| < pi/2`.
    fn single_key_rules(&self, rules: &mut Rules<'_>) {
        if !(3..=MAX_LEGS).contains(&self.legs) {
            rules.single(Err(invalid(
                "legs",
                self.legs,
                format!("must be between 3 and {MAX_LEGS}"),
            )));
        }
        rules.single(positive("hub_mass", self.hub_mass));
        rules.single(non_negative("hub_inertia", self.hub_inertia));
        rules.single(positive("leg_mass", self.leg_mass));
        rules.single(non_negative("leg_mass_offset", self.leg_mass_offset));
        rules.single(positive("stopper_length", self.stopper_length));
        rules.single(finite("spring_natural_length", self.spring_natural_length));
        rules.single(positive("stiffness", self.stiffness));
        rules.single(non_negative("viscosity", self.viscosity));
        rules.single(finite("slope", self.slope).and_then(|()| {
            if self.slope.abs() < FRAC_PI_2 {
                Ok(())
            } else {
                Err(invalid(
                    "slope",
                    short(self.slope),
                    "must satisfy |slope| < pi/2 (a slope angle in radians)",
                ))
            }
        }));
        rules.single(positive("gravity", self.gravity));
    }

    /// The rule of the mass ratio: `leg_mass / hub_mass` within [`MASS_RATIO_LIMIT`] of 1.
    fn mass_ratio_rule(&self, rules: &mut Rules<'_>) {
        rules.between(["leg_mass", "hub_mass"], |given| {
            let ratio = self.leg_mass / self.hub_mass;
            if (1.0 / MASS_RATIO_LIMIT..=MASS_RATIO_LIMIT).contains(&ratio) {
                return Ok(());
            }
            let (key, value) = if !given("leg_mass") && given("hub_mass") {
                ("hub_mass", self.hub_mass)
            } else {
                ("leg_mass", self.leg_mass)
            };
            Err(invalid(
                key,
                short(value),
                format!(
                    "leg_mass / hub_mass = {} is outside [{}, {}]: the mass matrix would be singular to rounding",
                    short(ratio),
                    short(1.0 / MASS_RATIO_LIMIT),
                    short(MASS_RATIO_LIMIT)
                ),
            ))
        });
    }

    /// The rules against the stopper length: the leg mass below it, and the spring's natural length at least
    /// as long unless a leaving leg is reset.
    fn stopper_length_rules(&self, rules: &mut Rules<'_>) {
        let stopper = ("stopper_length", self.stopper_length);
        rules.between(["leg_mass_offset", "stopper_length"], |given| {
            ordered(
                ("leg_mass_offset", self.leg_mass_offset),
                Below,
                stopper,
                given,
            )
        });
        // A spring shorter than the stopper (the tension reading) pulls a free leg off its stopper, so a rear leg
        // is never relocked: allowed only where its state is discarded at the next touchdown.
        if self.rear_exit != RearExit::Reset {
            rules.between(["spring_natural_length", "stopper_length"], |given| {
                ordered(
                    ("spring_natural_length", self.spring_natural_length),
                    AtLeast,
                    stopper,
                    given,
                )
                .map_err(|e| match e {
                    ConfigError::InvalidValue { key, value, reason } => ConfigError::InvalidValue {
                        key,
                        value,
                        reason: format!(
                            "{reason} (a shorter spring pulls a free leg off its stopper, so the rear leg is \
                             never relocked: it needs rear_exit = \"reset\")"
                        ),
                    },
                    other => other,
                })
            });
        }
    }

    /// The rules of a rear leg without a stopper: only with `rear_exit = "reset"`, and not with rigid legs.
    fn without_rear_stopper_rules(&self, rules: &mut Rules<'_>) {
        rules.between(["rear_stopper", "rear_exit"], |_| {
            if self.rear_exit != RearExit::Reset {
                return Err(invalid(
                    "rear_stopper",
                    self.rear_stopper,
                    format!(
                        "a rear leg without a stopper is never relocked: it needs rear_exit = \"reset\", not \"{}\"",
                        self.rear_exit
                    ),
                ));
            }
            Ok(())
        });
        rules.between(["rear_stopper", "rigid_legs"], |_| {
            if self.rigid_legs {
                return Err(invalid(
                    "rear_stopper",
                    self.rear_stopper,
                    "rigid legs are held by their stoppers both ways: they need rear_stopper = true",
                ));
            }
            Ok(())
        });
    }

    /// The rules of a compression stop that is set: below the stopper, with soft legs, and not with
    /// `rear_exit = "continue"`.
    fn min_length_rules(&self, rules: &mut Rules<'_>) {
        rules.between(["min_length", "stopper_length"], |given| {
            ordered(
                ("min_length", self.min_length),
                Below,
                ("stopper_length", self.stopper_length),
                given,
            )
        });
        rules.between(["min_length", "rigid_legs"], |_| {
            if self.rigid_legs {
                return Err(invalid(
                    "min_length",
                    short(self.min_length),
                    "rigid legs never shorten: a compression stop needs rigid_legs = false (or min_length = 0, \
                     none)",
                ));
            }
            Ok(())
        });
        rules.between(["min_length", "rear_exit"], |_| {
            if self.rear_exit == RearExit::Continue {
                return Err(invalid(
                    "min_length",
                    short(self.min_length),
                    "the swinging leg of rear_exit = \"continue\" has no compression stop yet: use \
                     rear_exit = \"relock\" or \"reset\" with min_length (or min_length = 0, none)",
                ));
            }
            Ok(())
        });
    }

    /// The rules of the friction coefficient: non-negative, infinity allowed (no slip, the default); a finite
    /// one replaces the treatment of an inconsistent no-slip contact, so not with `inconsistent_contact =
    /// "rebound"`, and not with `rear_exit = "continue"`.
    fn friction_rules(&self, rules: &mut Rules<'_>) {
        if self.friction.is_nan() || self.friction < 0.0 {
            rules.single(Err(invalid(
                "friction",
                short(self.friction),
                "must be non-negative (or inf: no slip)",
            )));
        } else if self.has_friction() {
            rules.between(["friction", "inconsistent_contact"], |_| {
                if self.inconsistent_contact == ContactInconsistency::Rebound {
                    return Err(invalid(
                        "friction",
                        short(self.friction),
                        "a finite friction coefficient decides what a contact that cannot stick does (it slips): \
                         inconsistent_contact = \"rebound\" is a resolution of friction = inf only",
                    ));
                }
                Ok(())
            });
            rules.between(["friction", "rear_exit"], |_| {
                if self.rear_exit == RearExit::Continue {
                    return Err(invalid(
                        "friction",
                        short(self.friction),
                        "the swinging leg's stopper impact of rear_exit = \"continue\" has no Coulomb impulse yet: \
                         use rear_exit = \"relock\" or \"reset\" with a finite friction (or friction = inf)",
                    ));
                }
                Ok(())
            });
        }
    }

    /// Is the friction coefficient finite (Coulomb friction at the tips rather than no slip)?
    pub fn has_friction(&self) -> bool {
        self.friction.is_finite()
    }

    /// The rules of a touchdown length that is set: within the stroke (`[min_length, stopper_length]`, above
    /// `leg_mass_offset`), and shorter than the stopper only where a leaving leg is reset to it.
    fn touchdown_length_rules(&self, rules: &mut Rules<'_>) {
        let td = ("touchdown_length", self.touchdown_length);
        rules.between(["touchdown_length", "stopper_length"], |given| {
            ordered(("stopper_length", self.stopper_length), AtLeast, td, given)
        });
        rules.between(["touchdown_length", "leg_mass_offset"], |given| {
            ordered(("leg_mass_offset", self.leg_mass_offset), Below, td, given)
        });
        if self.min_length > 0.0 {
            rules.between(["touchdown_length", "min_length"], |given| {
                ordered(td, AtLeast, ("min_length", self.min_length), given)
            });
        }
        if self.touchdown_length < self.stopper_length {
            rules.between(["touchdown_length", "rear_exit"], |_| {
                if self.rear_exit != RearExit::Reset || self.rigid_legs {
                    return Err(invalid(
                        "touchdown_length",
                        short(self.touchdown_length),
                        "a touchdown length shorter than the stopper makes the legs in the air spokes of that \
                         length, which a leg relocked at stopper_length is not: it needs rear_exit = \"reset\" \
                         (and soft legs)",
                    ));
                }
                Ok(())
            });
        }
    }

    /// The fastest time scale of the leg dynamics \[s\] (`docs/model.md` section 2, "Stiff legs"), `None`
    /// with rigid legs: the smaller of the damper's time constant `m / c` and the spring's `sqrt(m / k)`
    /// (its period over 2 pi), with `m` the reduced mass `leg_mass hub_mass / (leg_mass + hub_mass)` of the
    /// two bodies a leg's spring and damper push apart. An explicit integrator needs steps of about this
    /// size while a leg is free, whatever `max_step` says: see [`LegTimeScale`].
    pub fn leg_time_scale(&self) -> Option<LegTimeScale> {
        if self.rigid_legs {
            return None;
        }
        let mass = self.leg_mass * self.hub_mass / (self.leg_mass + self.hub_mass);
        let damper = if self.viscosity > 0.0 {
            mass / self.viscosity
        } else {
            f64::INFINITY
        };
        let spring = (mass / self.stiffness).sqrt();
        Some(if damper <= spring {
            LegTimeScale {
                seconds: damper,
                key: "viscosity",
                cause: "the damper's time constant m / c",
            }
        } else {
            LegTimeScale {
                seconds: spring,
                key: "stiffness",
                cause: "the spring's time scale sqrt(m / k)",
            }
        })
    }

    /// Refuses legs so stiff that a walk could not finish in reasonable time ([`MIN_LEG_TIME_SCALE`]).
    fn stiff_legs_rule(&self, given: &dyn Fn(&str) -> bool) -> Result<(), ConfigError> {
        let Some(scale) = self.leg_time_scale() else {
            return Ok(());
        };
        if scale.seconds >= MIN_LEG_TIME_SCALE {
            return Ok(());
        }
        // Name the key the user gave, preferring the one that sets the time scale.
        let key = [scale.key, "leg_mass", "hub_mass"]
            .into_iter()
            .find(|key| given(key))
            .unwrap_or(scale.key);
        let value = match key {
            "viscosity" => self.viscosity,
            "stiffness" => self.stiffness,
            "leg_mass" => self.leg_mass,
            _ => self.hub_mass,
        };
        Err(invalid(
            key,
            short(value),
            format!(
                "makes the legs too stiff to integrate: {} is {} s, below {} s (about {} integrator steps \
                 per simulated second; a step of the gait lasts seconds)",
                scale.cause,
                short(scale.seconds),
                short(MIN_LEG_TIME_SCALE),
                scale.steps_shown()
            ),
        ))
    }
}

/// The fastest time scale of the leg dynamics ([`Params::leg_time_scale`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegTimeScale {
    /// The time scale \[s\].
    pub seconds: f64,
    /// The key that sets it (`viscosity` or `stiffness`).
    pub key: &'static str,
    /// What it is, in words.
    pub cause: &'static str,
}

impl LegTimeScale {
    /// A rough count of integrator steps per simulated second while a leg is free: an explicit
    /// Dormand-Prince method is stable for steps up to about 3 time scales.
    pub fn steps_per_second(&self) -> f64 {
        1.0 / (3.0 * self.seconds)
    }

    /// [`LegTimeScale::steps_per_second`] to one significant digit, for messages (`4e4`).
    fn steps_shown(&self) -> String {
        format!("{:.0e}", self.steps_per_second())
    }

    /// A warning when the legs are stiff enough to slow a walk down ([`SLOW_LEG_TIME_SCALE`]), `None`
    /// otherwise.
    pub fn warning(&self) -> Option<String> {
        (self.seconds < SLOW_LEG_TIME_SCALE).then(|| {
            format!(
                "stiff legs: {} is {} s (set by `{}`), so the integrator needs about {} steps per simulated \
                 second; runs will be slow (they are refused below {} s)",
                self.cause,
                short(self.seconds),
                self.key,
                self.steps_shown(),
                short(MIN_LEG_TIME_SCALE)
            )
        })
    }
}

/// Legs faster than this \[s\] ([`Params::leg_time_scale`]) are refused: about 3e5 integrator steps per
/// simulated second, seconds of computing for each simulated second (measured: `viscosity = 1e7`, a time
/// scale of 9e-8 s, computes about 12 s per simulated second; `1e8`, ten times that), so a gait search of
/// a hundred steps would take many minutes.
pub const MIN_LEG_TIME_SCALE: f64 = 1e-6;

/// Legs faster than this \[s\] ([`Params::leg_time_scale`]) draw a warning before a run: about 3e4
/// integrator steps per simulated second (the defaults' time scale is 0.018 s).
pub const SLOW_LEG_TIME_SCALE: f64 = 1e-5;

/// `leg_mass / hub_mass` must lie in `[1 / MASS_RATIO_LIMIT, MASS_RATIO_LIMIT]`: beyond it `M(q)` is singular
/// to rounding and the constraint solves fail.
pub const MASS_RATIO_LIMIT: f64 = 1e6;

/// The largest accepted number of legs.
pub const MAX_LEGS: usize = 1000;

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use crate::params::*;

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
}
