//! The exact derivatives of a legged walker's step map checked by a second route (`vrw gait --model telescopic
//! --check-jacobian`, docs/model.md section 13): the walker's map as a
//! [`CheckedMap`](crate::mechanism::derivative_check::CheckedMap), so that the rigid walkers' check
//! (Richardson-extrapolated central differences against the replay's `DP` and `dP/dp`) and their `dP/dp` at a
//! gait serve it too.

use nalgebra::DVector;

use super::derivative::{constant_value, LeggedDerivativeError, LeggedDerivatives};
use super::gait::{legged_step_map, EXACT_ROUTE};
use super::walk::LeggedOptions;
use crate::integrate::Tolerances;
use crate::mechanism::derivative_check::{joined, DerivativeFailure, Exact, Walk, WalkerMap};
use crate::mechanism::sensitivity::NotDifferentiable;

/// A legged walker's step map.
pub type LeggedMap<'w, W, const N: usize, const Y: usize> = WalkerMap<'w, W, LeggedOptions, N, Y>;

/// The legged walk ([`super::walk`]) and its exact derivatives ([`super::derivative`]).
impl<W: LeggedDerivatives<N>, const N: usize, const Y: usize> Walk<W, N, Y> for LeggedOptions {
    type Failure = LeggedDerivativeError;

    const EXACT: &'static str = EXACT_ROUTE;

    fn tolerances(&mut self) -> &mut Tolerances {
        &mut self.tolerances
    }

    fn step_map(&self, walker: &W, s: &DVector<f64>) -> Result<DVector<f64>, Self::Failure> {
        Ok(legged_step_map::<W, N, Y>(walker, s, self)?.0)
    }

    fn exact(&self, walker: &W, s: &DVector<f64>, param: Option<&str>) -> Exact<Self::Failure> {
        let d = walker.exact_step_map(s, param, self)?;
        Ok(joined(&d.jacobian, d.dparam.as_ref()))
    }

    fn constant(walker: &W, key: &str) -> Option<f64> {
        constant_value(walker, key)
    }
}

impl DerivativeFailure for LeggedDerivativeError {
    fn not_differentiable(&self) -> Option<&NotDifferentiable> {
        match self {
            LeggedDerivativeError::NotDifferentiable(reason) => Some(reason),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanism::derivative_check::{check_derivatives, parameter_derivative};
    use crate::mechanism::legged::gait::legged_gait_exact;
    use crate::mechanism::telescopic::Telescopic;

    /// At the telescopic walker's default gait, its exact `DP` and `dP/dp` in the damper's coefficient and in
    /// the stoppers' length (which moves the section's held leg and every stopper event) agree with
    /// Richardson-extrapolated central differences within the differences' own error estimate (plus the exact
    /// ones' change at looser tolerances); the `dP/dp` at the gait is the check's exact column, said exact.
    #[test]
    fn the_telescopic_walkers_derivatives_agree_with_differences() {
        let w = Telescopic::default();
        let options = LeggedOptions::default();
        let gait = legged_gait_exact::<_, 6, 13>(&w, &w.default_start(), &options).unwrap();
        let map = LeggedMap::<_, 6, 13>::new(&w, options);
        for key in ["viscosity", "stopper_length"] {
            let check = check_derivatives(&map, &gait.section, Some(key)).unwrap();
            println!(
                "{key}: difference {:e}, exact error {:e}, differences' error {:e}",
                check.difference, check.exact_error, check.finite_difference_error
            );
            assert!(check.agree, "{check:?}");
            assert!(check.difference < 2e-8, "{check:?}");
            assert_eq!(check.exact.len(), 5);
            assert_eq!(check.exact[0].len(), 6);
            let d = parameter_derivative(&map, &gait.section, key).unwrap();
            assert_eq!(d.derivative, EXACT_ROUTE);
            assert_eq!(d.error, None);
            for (i, row) in check.exact.iter().enumerate() {
                assert_eq!(d.values[i], row[5]);
            }
            // A second route for the column: the differences' own, within their estimate.
            for (i, row) in check.finite_difference.iter().enumerate() {
                let gap = (d.values[i] - row[5]).abs();
                assert!(
                    gap <= check.finite_difference_error + check.exact_error,
                    "{key} row {i}: {gap:e}"
                );
            }
        }
    }
}
