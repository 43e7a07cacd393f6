//! Gait analysis (docs/model.md section 6): the step map, limit cycles and their stability, the grid runner
//! (`grid`) behind parameter sweeps and maps with continuation, and the parameter values where the DLS
//! indicators change sign or the gait is lost.

pub mod basin;
pub mod continuation;
pub(crate) mod derivative;
pub(crate) mod end_search;
pub(crate) mod grid;
pub(crate) mod limit_cycle;
pub mod map;
pub mod options;
pub mod orbit;
pub mod period_k;
pub(crate) mod periodicity;
pub(crate) mod step_map;
pub(crate) mod sweep;
pub(crate) mod thresholds;

pub use derivative::{check_jacobian, JacobianCheck, ParamDerivative, DERIVATIVE_CHECK_TIGHTENING};
pub use grid::{clear_interrupt, interrupt_flag, interrupted};
pub use limit_cycle::{find_gait, Gait, GaitError, GaitOptions, Stability};
pub use map::{
    check_part, map_curves, map_gaits, map_gaits_part, ContinuedCurve, CurveMethod, GaitMap,
    MapCurves, MapSpec, ThresholdCurve, LINE_CHECK_TOL,
};
pub use options::{FD_STEP_RANGE, MAX_NEWTON_ITERATIONS, MAX_TRANSIENT_STEPS, TOLERANCE_RANGE};
pub use period_k::{find_gait_any_period, find_periodic_gait, MAX_PERIOD};
pub use step_map::{DerivativeError, SignedOutcome, StepDerivatives, StepMap, StepOutcome};
pub use sweep::{
    check_values, sweep, sweep_values, FollowAttempt, RangeNames, SweepPoint, SweepSpec,
    MAX_SWEEP_POINTS, SWEEP_RANGE,
};
pub use thresholds::{find_thresholds, SecondRoute, Threshold, SECOND_ROUTE_TOL};
