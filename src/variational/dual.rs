//! The dual numbers of the wheel's exact derivatives: [`Dual`] (`crate::dynamics::Dual`, shared with the rigid
//! walkers' derivatives), with the wheel's physical constants with one parameter seeded.

use nalgebra::SVector;

pub(crate) use crate::dynamics::Dual;
use crate::dynamics::{Mechanics, Model};

/// The dual number `re + eps . e`.
pub(crate) fn dual<const D: usize>(re: f64, eps: SVector<f64, D>) -> Dual<D> {
    Dual::new(re, eps)
}

/// The derivative part of a dual number.
pub(crate) fn eps<const D: usize>(x: &Dual<D>) -> SVector<f64, D> {
    x.derivative()
}

/// The constants of `model` with the parameter `param` (if any) carrying the unit derivative in direction
/// `index` of `D`.
pub(crate) fn seeded<const D: usize>(
    model: &Model,
    param: Option<&str>,
    index: usize,
) -> Mechanics<Dual<D>> {
    Mechanics::seeded(model.params(), |key, value| {
        let mut e = SVector::<f64, D>::zeros();
        if param == Some(key) {
            e[index] = 1.0;
        }
        dual(value, e)
    })
}
