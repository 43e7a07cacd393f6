//! The dual numbers that carry derivatives (forward-mode automatic differentiation): a number with its
//! derivatives along `N` directions ([`Dual`]), a [`Real`] so that the equations of motion, the constrained
//! solves and the transitions written over [`Real`] run on it unchanged (the wheel's `crate::variational`, and
//! the rigid walkers' `crate::mechanism::sensitivity`).
//!
//! Hand-written rather than `num-dual`'s `DualVec`: the variational equations evaluate the equations of motion
//! on duals at every stage of every integrator step (about a thousand times per walking step), and `DualVec`
//! keeps its derivative as an optional nalgebra vector, so that every operation branches and copies; a plain
//! array of `N` derivatives is several times faster, and the few operations the kinematics need
//! ([`Real`]) are a page of code.

use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

use nalgebra::SVector;
use num_traits::{One, Zero};

use super::Real;

/// `re + sum_i eps_i e_i` with `e_i e_j = 0`: a number and its derivatives along `N` directions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Dual<const N: usize> {
    /// The value.
    pub(crate) re: f64,
    /// Its derivatives.
    pub(crate) eps: [f64; N],
}

impl<const N: usize> Dual<N> {
    /// `re` with the derivatives `eps`.
    pub(crate) fn new(re: f64, eps: SVector<f64, N>) -> Self {
        Dual {
            re,
            eps: eps.into(),
        }
    }

    /// The derivatives as a vector.
    pub(crate) fn derivative(&self) -> SVector<f64, N> {
        SVector::from(self.eps)
    }

    /// The chain rule for `f(self)` with `f(re) = value`, `f'(re) = slope`.
    fn chain(self, value: f64, slope: f64) -> Self {
        Dual {
            re: value,
            eps: self.eps.map(|e| slope * e),
        }
    }
}

impl<const N: usize> Add for Dual<N> {
    type Output = Self;
    fn add(self, b: Self) -> Self {
        Dual {
            re: self.re + b.re,
            eps: std::array::from_fn(|i| self.eps[i] + b.eps[i]),
        }
    }
}

impl<const N: usize> Sub for Dual<N> {
    type Output = Self;
    fn sub(self, b: Self) -> Self {
        Dual {
            re: self.re - b.re,
            eps: std::array::from_fn(|i| self.eps[i] - b.eps[i]),
        }
    }
}

impl<const N: usize> Mul for Dual<N> {
    type Output = Self;
    // The product rule: (a + a' e)(b + b' e) = ab + (a b' + b a') e.
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn mul(self, b: Self) -> Self {
        Dual {
            re: self.re * b.re,
            eps: std::array::from_fn(|i| self.re * b.eps[i] + b.re * self.eps[i]),
        }
    }
}

impl<const N: usize> Div for Dual<N> {
    type Output = Self;
    fn div(self, b: Self) -> Self {
        let inv = 1.0 / b.re;
        let re = self.re * inv;
        Dual {
            re,
            eps: std::array::from_fn(|i| (self.eps[i] - re * b.eps[i]) * inv),
        }
    }
}

impl<const N: usize> Neg for Dual<N> {
    type Output = Self;
    fn neg(self) -> Self {
        Dual {
            re: -self.re,
            eps: self.eps.map(|e| -e),
        }
    }
}

impl<const N: usize> AddAssign for Dual<N> {
    fn add_assign(&mut self, b: Self) {
        *self = *self + b;
    }
}

impl<const N: usize> SubAssign for Dual<N> {
    fn sub_assign(&mut self, b: Self) {
        *self = *self - b;
    }
}

impl<const N: usize> MulAssign for Dual<N> {
    fn mul_assign(&mut self, b: Self) {
        *self = *self * b;
    }
}

impl<const N: usize> DivAssign for Dual<N> {
    fn div_assign(&mut self, b: Self) {
        *self = *self / b;
    }
}

impl<const N: usize> Zero for Dual<N> {
    fn zero() -> Self {
        Dual {
            re: 0.0,
            eps: [0.0; N],
        }
    }
    fn is_zero(&self) -> bool {
        self.re == 0.0 && self.eps.iter().all(|e| *e == 0.0)
    }
}

impl<const N: usize> One for Dual<N> {
    fn one() -> Self {
        Dual {
            re: 1.0,
            eps: [0.0; N],
        }
    }
}

impl<const N: usize> Real for Dual<N> {
    fn lit(x: f64) -> Self {
        Dual {
            re: x,
            eps: [0.0; N],
        }
    }
    fn sin(self) -> Self {
        self.chain(self.re.sin(), self.re.cos())
    }
    fn cos(self) -> Self {
        self.chain(self.re.cos(), -self.re.sin())
    }
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.re.sin_cos();
        (self.chain(s, c), self.chain(c, -s))
    }
    fn atan(self) -> Self {
        self.chain(self.re.atan(), 1.0 / (1.0 + self.re * self.re))
    }
    fn value(self) -> f64 {
        self.re
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each operation's derivative against a central difference of the same operation on `f64`.
    #[test]
    fn operations_differentiate_like_finite_differences() {
        let h = 1e-6;
        let x = 0.7;
        let at = |x: f64| Dual::<1>::new(x, SVector::<f64, 1>::new(1.0));
        type Case = (&'static str, fn(Dual<1>) -> Dual<1>, fn(f64) -> f64);
        let ops: [Case; 6] = [
            ("sin", |d| d.sin(), f64::sin),
            ("cos", |d| d.cos(), f64::cos),
            ("atan", |d| d.atan(), f64::atan),
            (
                "x / (1 + x^2)",
                |d| d / (Dual::one() + d * d),
                |x| x / (1.0 + x * x),
            ),
            (
                "-x^3 + 2",
                |d| -(d * d * d) + Dual::lit(2.0),
                |x| -(x * x * x) + 2.0,
            ),
            (
                "sin cos",
                |d| d.sin_cos().0 * d.sin_cos().1,
                |x| x.sin() * x.cos(),
            ),
        ];
        for (name, f, g) in ops {
            let d = f(at(x));
            let fd = (g(x + h) - g(x - h)) / (2.0 * h);
            assert!((d.re - g(x)).abs() < 1e-15, "{name}");
            assert!((d.eps[0] - fd).abs() < 1e-9, "{name}: {} vs {fd}", d.eps[0]);
        }
    }
}
