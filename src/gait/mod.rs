//! Gait analysis (docs/model.md section 6): the step map and its exact derivatives, and its fixed points
//! (limit cycles, period-k gaits) with their stability. A gait as a function of one parameter (the natural and
//! the pseudo-arclength continuation) is in [`crate::family`], the studies built on them (sweeps, thresholds,
//! maps, orbit diagrams, basins) in [`crate::study`].

pub(crate) mod derivative;
pub(crate) mod limit_cycle;
pub mod options;
pub mod period_k;
pub(crate) mod periodicity;
pub(crate) mod step_map;

pub use crate::walk::interrupt::{clear_interrupt, interrupt_flag, interrupted};
pub use derivative::{check_jacobian, JacobianCheck, ParamDerivative, DERIVATIVE_CHECK_TIGHTENING};
pub use limit_cycle::{find_gait, Gait, GaitError, GaitOptions, Stability};
pub use options::{FD_STEP_RANGE, MAX_NEWTON_ITERATIONS, MAX_TRANSIENT_STEPS, TOLERANCE_RANGE};
pub use period_k::{find_gait_any_period, find_periodic_gait, MAX_PERIOD};
pub use step_map::{DerivativeError, SignedOutcome, StepDerivatives, StepMap, StepOutcome};
