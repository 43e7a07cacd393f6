//! The dual numbers that carry the derivatives (forward-mode automatic differentiation, `num-dual`): a number
//! with its derivatives along the [`NDIR`] directions of a sensitivity, and the physical constants with one
//! parameter seeded.

use nalgebra::{Const, SVector};
use num_dual::{Derivative, DualSVec64};

use crate::dynamics::{Mechanics, Model};

/// Directions of the derivatives: the three section coordinates `(L2, dtheta/dt, dL2/dt)` and one parameter.
pub(crate) const NDIR: usize = 4;

/// A number with its derivatives along the [`NDIR`] directions.
pub(crate) type Dual = DualSVec64<NDIR>;
/// A number with its derivatives along the [`NDIR`] directions and along the flow (the event's rate).
pub(crate) type Dual5 = DualSVec64<{ NDIR + 1 }>;

/// The dual number `re + eps . e`.
pub(crate) fn dual<const D: usize>(re: f64, eps: SVector<f64, D>) -> DualSVec64<D> {
    DualSVec64::new(re, Derivative::some(eps))
}

/// The derivative part of a dual number.
pub(crate) fn eps<const D: usize>(x: &DualSVec64<D>) -> SVector<f64, D> {
    x.eps.unwrap_generic(Const::<D>, Const::<1>)
}

/// The constants of `model` with the parameter `param` (if any) carrying the unit derivative in direction
/// `index` of `D`.
pub(crate) fn seeded<const D: usize>(
    model: &Model,
    param: Option<&str>,
    index: usize,
) -> Mechanics<DualSVec64<D>> {
    Mechanics::seeded(model.params(), |key, value| {
        let mut e = SVector::<f64, D>::zeros();
        if param == Some(key) {
            e[index] = 1.0;
        }
        dual(value, e)
    })
}
