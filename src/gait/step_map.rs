//! The step map `P` on the Poincare section (docs/model.md section 6) and its Jacobian.
//!
//! `P(s)` walks one step from the section state `s = (L2, dtheta/dt, dL2/dt)` to the next touchdown. With
//! `rigid_legs` only `dtheta/dt` is free (`L2 = L0`, `dL2/dt = 0` always), so the map acts on that coordinate
//! alone.
//!
//! **Iterated map.** [`StepMap::iterated`] gives `P^k`, `k` steps walked in one evaluation, whose fixed points
//! are the period-k gaits ([`super::period_k`]); everything below (Jacobian, Newton's method) works on it
//! unchanged.
//!
//! **Jacobian.** `DP` is computed by central differences of the whole map with Richardson extrapolation:
//! `D(h) = (P(s + h e_i) - P(s - h e_i)) / 2h` has an error `c2 h^2 + c4 h^4 + noise/h`, and
//! `(4 D(h/2) - D(h)) / 3` removes the `h^2` term. The difference between the extrapolated and the plain
//! `D(h/2)` estimates the error, which is reported with every gait. Forward sensitivities through the events
//! (variational equations with saltation matrices) would avoid the `noise/h` term; the finite differences are
//! checked against the closed-form Floquet multiplier of the rigid rimless wheel instead (tests), where they
//! agree to about 1e-9.

use std::ops::{Deref, DerefMut};
use std::sync::{Arc, Mutex};

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::dynamics::Model;
use crate::params::SolverOptions;
use crate::walk::WalkError;
use crate::walk::{SectionState, StepReport, Walker, WorkCounts};

/// One evaluation of the step map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOutcome {
    /// `P(s)` (`P^k(s)` for an iterated map).
    pub next: SectionState,
    /// The (first) step's report (DLS indicators, period, energy audit, ...).
    pub report: StepReport,
}

/// The step map of one parameter set.
#[derive(Debug, Clone)]
pub struct StepMap<'m> {
    model: &'m Model,
    opts: SolverOptions,
    /// Steps per evaluation: 1 for `P`, `k` for `P^k`.
    iterate: usize,
    /// The work of every walker this map (and its iterates) made, added once per walker when it is dropped.
    work: Arc<Mutex<WorkCounts>>,
}

impl<'m> StepMap<'m> {
    /// The step map of `model` integrated with `opts`.
    pub fn new(model: &'m Model, opts: &SolverOptions) -> StepMap<'m> {
        StepMap {
            model,
            opts: opts.clone(),
            iterate: 1,
            work: Arc::default(),
        }
    }

    /// The iterated map `P^k` (`k >= 1`; `k = 0` is taken as 1): each evaluation walks `k` steps, and its
    /// report is that of the first step.
    pub fn iterated(&self, k: usize) -> StepMap<'m> {
        StepMap {
            iterate: k.max(1),
            ..self.clone()
        }
    }

    /// Steps walked per evaluation (`k` of `P^k`).
    pub fn steps_per_eval(&self) -> usize {
        self.iterate
    }

    /// The work of every walker this map and its iterates ([`StepMap::iterated`]) have made so far: the
    /// evaluations, and the walks of a gait search (transient, settling, orbit checks), failed steps included.
    pub fn work(&self) -> WorkCounts {
        *self
            .work
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// A walker of this map's model and options from `s`, whose work is added to [`StepMap::work`] when it is
    /// dropped (once per walker, not per step: evaluations run in parallel).
    pub(crate) fn walker(&self, s: &SectionState) -> Result<CountedWalker<'_, 'm>, WalkError> {
        Ok(CountedWalker {
            walker: Walker::new(self.model, &self.opts, s)?,
            tally: &self.work,
        })
    }

    /// Evaluate `P(s)` (`P^k(s)` for an iterated map). Fails with the reason the step could not be walked
    /// (fell, stalled, old rear leg not relocked at the next touchdown, ...).
    pub fn eval(&self, s: &SectionState) -> Result<StepOutcome, WalkError> {
        let mut walker = self.walker(s)?;
        let report = walker.step(None)?;
        for _ in 1..self.iterate {
            walker.step(None)?;
        }
        let next = walker.section()?;
        Ok(StepOutcome { next, report })
    }

    /// Indices (into `[L2, dtheta/dt, dL2/dt]`) of the coordinates the map acts on.
    pub(crate) fn free_coordinates(&self) -> &'static [usize] {
        if self.model.params().rigid_legs {
            &[1]
        } else {
            &[0, 1, 2]
        }
    }

    /// The free coordinates of `s` as a vector.
    pub fn reduce(&self, s: &SectionState) -> DVector<f64> {
        let a = s.to_array();
        DVector::from_iterator(
            self.free_coordinates().len(),
            self.free_coordinates().iter().map(|&i| a[i]),
        )
    }

    /// `base` with its free coordinates replaced by `v`.
    pub fn expand(&self, base: &SectionState, v: &DVector<f64>) -> SectionState {
        let mut a = base.to_array();
        for (k, &i) in self.free_coordinates().iter().enumerate() {
            a[i] = v[k];
        }
        SectionState::from_array(a)
    }

    /// Central-difference Jacobian `D(h)` of the reduced map at `s`, with relative step `h`.
    pub fn central_jacobian(&self, s: &SectionState, h: f64) -> Result<DMatrix<f64>, WalkError> {
        let x = self.reduce(s);
        let n = x.len();
        let steps: Vec<f64> = x.iter().map(|v| h * v.abs().max(1.0)).collect();
        // The 2n evaluations are independent: run them in parallel (the result does not depend on the
        // number of threads, since each evaluation is the same computation wherever it runs).
        let images: Vec<DVector<f64>> = (0..2 * n)
            .into_par_iter()
            .map(|k| {
                let (j, sign) = (k / 2, if k % 2 == 0 { 1.0 } else { -1.0 });
                let mut shifted = x.clone();
                shifted[j] += sign * steps[j];
                Ok(self.reduce(&self.eval(&self.expand(s, &shifted))?.next))
            })
            .collect::<Result<_, WalkError>>()?;
        let mut jac = DMatrix::zeros(n, n);
        for j in 0..n {
            jac.set_column(
                j,
                &((&images[2 * j] - &images[2 * j + 1]) / (2.0 * steps[j])),
            );
        }
        Ok(jac)
    }

    /// Richardson-extrapolated Jacobian `(4 D(h/2) - D(h)) / 3` and an estimate of its error (the largest
    /// entry of `|extrapolated - D(h/2)|`).
    pub(crate) fn jacobian(
        &self,
        s: &SectionState,
        h: f64,
    ) -> Result<(DMatrix<f64>, f64), WalkError> {
        let coarse = self.central_jacobian(s, h)?;
        let fine = self.central_jacobian(s, h / 2.0)?;
        let extrapolated = (4.0 * &fine - coarse) / 3.0;
        let error = (&extrapolated - fine).abs().max();
        Ok((extrapolated, error))
    }
}

/// A walker made by a [`StepMap`], which adds its work to the map's tally when it is dropped (on every path,
/// failures included). Not `Clone`, so no work is counted twice.
pub(crate) struct CountedWalker<'a, 'm> {
    walker: Walker<'m>,
    tally: &'a Mutex<WorkCounts>,
}

impl<'m> Deref for CountedWalker<'_, 'm> {
    type Target = Walker<'m>;

    fn deref(&self) -> &Walker<'m> {
        &self.walker
    }
}

impl DerefMut for CountedWalker<'_, '_> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.walker
    }
}

impl Drop for CountedWalker<'_, '_> {
    fn drop(&mut self) {
        *self
            .tally
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner()) += self.walker.work();
    }
}
