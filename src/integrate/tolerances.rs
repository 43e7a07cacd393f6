//! Error tolerances and step-size bounds ([`Tolerances`]), and the scaled RMS norm in which both Runge–Kutta
//! pairs measure their local error and their starting step (HNW I, Eq. II.4.11).

use nalgebra::SVector;

/// Error tolerances and step-size bounds of [`Dopri5`](super::Dopri5).
///
/// The local error estimate `e` of a step from `y0` to `y1` is accepted when
/// `sqrt(mean_i (e_i / (atol + rtol * max(|y0_i|, |y1_i|)))^2) <= 1` (HNW I, Eq. II.4.11).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Relative tolerance \[-\], default 1e-10.
    pub rtol: f64,
    /// Absolute tolerance \[state units\], default 1e-12.
    pub atol: f64,
    /// Largest step \[s\], default 0.02 (a step may be stretched by up to 1% to land exactly
    /// on `t_stop`, see [`Dopri5::step`](super::Dopri5::step)).
    pub h_max: f64,
    /// Smallest step \[s\]: a controller proposal below it ends the integration with
    /// [`IntegrationError::StepSizeTooSmall`](super::IntegrationError::StepSizeTooSmall) (or [`IntegrationError::NonFinite`](super::IntegrationError::NonFinite) if the last
    /// trial produced non-finite values), default 1e-14. Steps shortened to land on `t_stop`
    /// are not subject to it.
    pub h_min: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            rtol: 1e-10,
            atol: 1e-12,
            h_max: 0.02,
            h_min: 1e-14,
        }
    }
}

/// Weighted RMS norm of `v` with scale `atol + rtol * max(|a_i|, |b_i|)` (HNW I, Eq. II.4.11), over the
/// components not in `unmeasured` ([`OdeSystem::unmeasured`](super::OdeSystem::unmeasured)).
pub(super) fn scaled_rms<const N: usize>(
    tol: &Tolerances,
    v: &SVector<f64, N>,
    (a, b): (&SVector<f64, N>, &SVector<f64, N>),
    unmeasured: &[usize],
) -> f64 {
    let sum: f64 = v
        .iter()
        .zip(a.iter().zip(b.iter()))
        .enumerate()
        .filter(|(i, _)| !unmeasured.contains(i))
        .map(|(_, (vi, (ai, bi)))| {
            let r = vi / (tol.atol + tol.rtol * ai.abs().max(bi.abs()));
            r * r
        })
        .sum();
    (sum / measured(N, unmeasured)).sqrt()
}

/// How many of `N` components the norm measures.
pub(super) fn measured(n: usize, unmeasured: &[usize]) -> f64 {
    (n - unmeasured.len()) as f64
}
