//! Studies over parameters (docs/model.md section 6): the grid runner every study shares (`grid`: rows continued
//! point to point, bitwise identical for any thread count), the sweep of one parameter and its thresholds, the
//! map over two parameters and its curves (`map`, `map_curves`), the orbit diagram and the basin of
//! attraction, and the measured parallelism of their phases (`parallelism`: work and span). They are built on the step map and its fixed points ([`crate::gait`]) and the families of
//! [`crate::continuation`].

pub mod basin;
pub(crate) mod grid;
pub mod map;
pub mod map_curves;
pub mod orbit;
pub mod parallelism;
pub(crate) mod sweep;
pub(crate) mod thresholds;

pub use map::{
    check_part, map_curves, map_gaits, map_gaits_measured, ContinuedCurve, CurveMethod, GaitMap,
    MapCurves, MapSpec, ThresholdCurve, LINE_CHECK_TOL,
};
pub use sweep::{
    check_values, sweep, sweep_values, FollowAttempt, PointStatus, RangeNames, SweepPoint,
    SweepSpec, MAX_SWEEP_POINTS, SWEEP_RANGE,
};
pub use thresholds::{find_thresholds, SecondRoute, Threshold, SECOND_ROUTE_TOL};
