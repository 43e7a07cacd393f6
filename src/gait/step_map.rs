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
//! **Jacobian.** `DP` (and `dP/dp`) is exact: [`StepMap::eval_with_derivatives`] walks the step with a record of
//! it and replays that record with the variational equations and the saltation matrix of every event
//! ([`crate::variational`], docs/model.md section 10). The finite-difference route stays as its independent
//! check and as Newton's matrix where the map is not differentiable: [`StepMap::central_jacobian`],
//! `D(h) = (P(s + h e_i) - P(s - h e_i)) / 2h`, with an error `c2 h^2 + c4 h^4 + noise/h`, and its Richardson
//! extrapolation `(4 D(h/2) - D(h)) / 3`, whose difference to the plain `D(h/2)` estimates its error.

use std::ops::{Deref, DerefMut};
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::meter::carried;

use crate::dynamics::{Model, DIFFERENTIABLE_KEYS, L2, THETA};
use crate::params::ImpactModel;
use crate::params::SolverOptions;
use crate::variational::{
    augmented, replay_step, seeded, sensitivity, slip_derivative, Dual, NotDifferentiable,
    Sensitivity, BORDER_TOL, NC,
};
use crate::walk::section::section_coords;
use crate::walk::tape::StepTape;
use crate::walk::WalkError;
use crate::walk::{Branch, SectionState, StepReport, Walker, WorkCounts, SECTION_COORDINATES};

/// Indices (into [`SECTION_COORDINATES`]) of a step map's free coordinates: `dtheta/dt` alone with rigid legs
/// or Leg 2 held at its compression stop (`theta_dot_only`), else `(L2, dtheta/dt, dL2/dt)`; and the slip
/// velocity where Leg 2's tip slips at the section (`slipping`, Coulomb friction).
pub(crate) fn free_coordinates(theta_dot_only: bool, slipping: bool) -> &'static [usize] {
    match (theta_dot_only, slipping) {
        (true, false) => &[1],
        (true, true) => &[1, 3],
        (false, false) => &[0, 1, 2],
        (false, true) => &[0, 1, 2, 3],
    }
}

/// The coordinates `free` of `s` as a vector.
pub(crate) fn reduce(free: &[usize], s: &SectionState) -> DVector<f64> {
    DVector::from_iterator(free.len(), free.iter().map(|&i| s.coordinate(i)))
}

/// `base` with its coordinates `free` replaced by `v`.
pub(crate) fn expand(free: &[usize], base: &SectionState, v: &DVector<f64>) -> SectionState {
    free.iter()
        .enumerate()
        .fold(*base, |s, (k, &i)| s.with_coordinate(i, v[k]))
}

/// One evaluation of the step map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOutcome {
    /// `P(s)` (`P^k(s)` for an iterated map).
    pub next: SectionState,
    /// The (first) step's report (DLS indicators, period, energy audit, ...).
    pub report: StepReport,
}

/// One evaluation of the step map with its exact derivatives ([`StepMap::eval_with_derivatives`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StepDerivatives {
    /// `P(s)` and the (first) step's report, exactly as [`StepMap::eval`] gives them.
    pub outcome: StepOutcome,
    /// `DP`: the Jacobian of the map over its free coordinates ([`StepMap::reduce`]; `D(P^k)` for an iterated
    /// map).
    pub jacobian: DMatrix<f64>,
    /// `dP/dp` over the free coordinates for the chosen parameter, if one was chosen.
    pub dparam: Option<DVector<f64>>,
    /// The event sequence of the walk (see [`StepMap::eval_signature`]).
    pub signature: String,
    /// The report of every step walked (`k` of them for `P^k`; the first is `outcome.report`).
    pub cycle: Vec<StepReport>,
}

/// One evaluation of the step map with the event sequence of its walk ([`StepMap::eval_signature`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SignedOutcome {
    /// `P(s)` and the (first) step's report.
    pub outcome: StepOutcome,
    /// The event sequence.
    pub signature: String,
    /// The report of every step walked.
    pub cycle: Vec<StepReport>,
}

/// Why [`StepMap::eval_with_derivatives`] gave no derivatives.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DerivativeError {
    /// The step could not be walked.
    #[error(transparent)]
    Walk(#[from] WalkError),
    /// The map is not differentiable there (or the replay failed).
    #[error(transparent)]
    NotDifferentiable(#[from] NotDifferentiable),
    /// The parameter is not a key the equations of motion depend on smoothly.
    #[error("no derivative with respect to {key:?}: the parameter must be one of {keys}", keys = DIFFERENTIABLE_KEYS.join(", "))]
    UnknownParameter {
        /// The key given.
        key: String,
    },
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
    /// Stops its walks inside a step when set ([`StepMap::with_interrupt`]).
    interrupt: Option<&'m AtomicBool>,
    /// The map acts on states whose Leg 2 is held at its compression stop ([`StepMap::on_section_of`]).
    rear_held: bool,
    /// The map acts on states whose Leg 2's tip slips (Coulomb friction): `slip` is one of its coordinates
    /// ([`StepMap::on_section_of`]).
    slipping: bool,
}

impl<'m> StepMap<'m> {
    /// The step map of `model` integrated with `opts`.
    pub fn new(model: &'m Model, opts: &SolverOptions) -> StepMap<'m> {
        StepMap {
            model,
            opts: opts.clone(),
            iterate: 1,
            work: Arc::default(),
            interrupt: None,
            rear_held: false,
            slipping: false,
        }
    }

    /// The map whose coordinates fit the section state `s`: where Leg 2 is held at its compression stop there
    /// ([`SectionState::rear_held`]: `L2 = min_length`, `dL2/dt = 0`, as at every touchdown of a walk whose
    /// stance leg is held then), the map acts on `dtheta/dt` alone, as with rigid legs, and an evaluation whose
    /// next touchdown has Leg 2 free fails ([`WalkError::HoldChanged`]); otherwise on all three coordinates.
    /// Where Leg 2's tip slips at `s` (Coulomb friction, [`SectionState::slips`]), its slip velocity is a
    /// coordinate too; a map on states whose tip is at rest fails where the next touchdown's slips
    /// ([`WalkError::SlipAtSection`]).
    pub fn on_section_of(&self, s: &SectionState) -> StepMap<'m> {
        self.clone()
            .with_rear_held(s.rear_held(self.model))
            .with_slip(s.slips())
    }

    /// The map on states whose Leg 2's tip slips (`slipping`: `slip` is a coordinate) or is at rest.
    pub(crate) fn with_slip(self, slipping: bool) -> StepMap<'m> {
        StepMap { slipping, ..self }
    }

    /// The map on the states whose Leg 2 is held at its compression stop (`held`, see
    /// [`StepMap::on_section_of`]) or on all three coordinates.
    pub(crate) fn with_rear_held(self, held: bool) -> StepMap<'m> {
        StepMap {
            rear_held: held,
            ..self
        }
    }

    /// Does the map act on states whose Leg 2 is held at its compression stop ([`StepMap::on_section_of`])?
    pub(crate) fn rear_held(&self) -> bool {
        self.rear_held
    }

    /// `next`, or [`WalkError::HoldChanged`] where this map holds Leg 2 at its compression stop and `next`
    /// does not.
    /// The same for a map on states whose stance tip is at rest and a `next` whose tip slips
    /// ([`WalkError::SlipAtSection`]).
    fn check_hold(&self, next: SectionState) -> Result<SectionState, WalkError> {
        if self.rear_held && !next.rear_held(self.model) {
            return Err(WalkError::HoldChanged {
                length: next.l2,
                rate: next.l2_dot,
            });
        }
        if !self.slipping && next.slips() {
            return Err(WalkError::SlipAtSection { slip: next.slip });
        }
        Ok(next)
    }

    /// The same map, whose walks stop with [`WalkError::Interrupted`] when `flag` is set (read every
    /// [`crate::walk::INTERRUPT_CHECK_STEPS`] integrator steps): what makes a gait search interruptible.
    pub fn with_interrupt(self, flag: Option<&'m AtomicBool>) -> StepMap<'m> {
        StepMap {
            interrupt: flag,
            ..self
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

    /// The model the map walks.
    pub(crate) fn model(&self) -> &'m Model {
        self.model
    }

    /// The solver options the map integrates with.
    pub(crate) fn options(&self) -> &SolverOptions {
        &self.opts
    }

    /// The same map integrated with `rtol` and `atol` multiplied by `factor` (the error estimate of the exact
    /// derivatives, [`super::derivative`]); its work joins this map's.
    pub(crate) fn with_tolerances_scaled(&self, factor: f64) -> StepMap<'m> {
        let mut opts = self.opts.clone();
        opts.rtol *= factor;
        opts.atol *= factor;
        StepMap {
            opts,
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
            walker: Walker::new(self.model, &self.opts, s)?.with_interrupt(self.interrupt),
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
        let next = self.check_hold(walker.section()?)?;
        Ok(StepOutcome { next, report })
    }

    /// Evaluate `P(s)` (`P^k(s)`) with its exact derivatives (docs/model.md section 10): `DP` over the free
    /// coordinates and, if `param` names one of [`DIFFERENTIABLE_KEYS`], `dP/dp`. The walk is the one
    /// [`StepMap::eval`] takes (same outcome, bit for bit); the derivatives come from the variational equations
    /// over its steps and the saltation matrix of each of its events ([`crate::variational`]). `D(P^k)` is the
    /// chain of the `k` steps' derivatives.
    pub fn eval_with_derivatives(
        &self,
        s: &SectionState,
        param: Option<&str>,
    ) -> Result<StepDerivatives, DerivativeError> {
        if let Some(key) = param.filter(|key| !DIFFERENTIABLE_KEYS.contains(key)) {
            return Err(DerivativeError::UnknownParameter {
                key: key.to_string(),
            });
        }
        // The section state's directions (three, four where the stance tip slips), and the parameter's last.
        match (self.slipping, param) {
            (false, None) => self.derivatives::<3, 4, { augmented(3) }>(s, None),
            (false, Some(_)) | (true, None) => self.derivatives::<4, 5, { augmented(4) }>(s, param),
            (true, Some(_)) => self.derivatives::<5, 6, { augmented(5) }>(s, param),
        }
    }

    /// [`StepMap::eval_with_derivatives`] along `D` directions (`E = D + 1`, `A =` [`augmented`]`(D)`, see
    /// [`replay_step`]).
    fn derivatives<const D: usize, const E: usize, const A: usize>(
        &self,
        s: &SectionState,
        param: Option<&str>,
    ) -> Result<StepDerivatives, DerivativeError> {
        let model = self.model;
        if self.slipping && !s.slips() {
            return Err(NotDifferentiable::SectionAtRest.into());
        }
        let mut walker = self.walker(s)?;
        // The section's own constraint, differentiated: (q, q') as functions of (s, p).
        let mech = seeded::<D>(model, param, D - 1);
        let unit = |i: usize, value: f64| {
            let mut e = nalgebra::SVector::<f64, D>::zeros();
            e[i] = 1.0;
            crate::variational::dual_of(value, e)
        };
        let s = s.pinned(model);
        // The slip's own direction where it is a coordinate of the map, a constant where it is not.
        let slip = s.slips().then(|| match self.slipping {
            true => unit(3, s.slip),
            false => crate::dynamics::lit::<Dual<D>>(s.slip),
        });
        let (q, qd) = section_coords::<Dual<D>>(
            model,
            &mech,
            (unit(0, s.l2), unit(1, s.theta_dot), unit(2, s.l2_dot)),
            slip,
        );
        let mut sens: Sensitivity<D> = sensitivity(&q, &qd);
        let mut cycle = Vec::with_capacity(self.iterate);
        let mut words = Vec::with_capacity(self.iterate);
        for _ in 0..self.iterate {
            let start = walker.state().clone();
            let mut tape = StepTape::logging();
            let step = walker.step_taped(&mut tape)?;
            words.push(tape.signature(step.branch));
            on_border(model, &step)?;
            cycle.push(step);
            sens = replay_step::<D, E, A>(
                model,
                &self.opts,
                param,
                (&start.q, &start.qd),
                &sens,
                &tape,
            )?
            .sensitivity;
        }
        let next = self.check_hold(walker.section()?)?;
        let report = cycle[0];
        // The derivatives of the next section state (L2, dtheta/dt, dL2/dt, slip): the sensitivity's rows of
        // L2, dtheta/dt and dL2/dt, and the slipping tip's velocity (0 where the tip sticks: the slip stays 0).
        let end = walker.state();
        let slip_row = match end.active.contact2 && end.active.slip2 != 0 {
            true => slip_derivative(model, &mech, (&end.q, &end.qd), &sens),
            false => nalgebra::SVector::zeros(),
        };
        let row = |i: usize, j: usize| match i {
            3 => slip_row[j],
            _ => sens[([L2, NC + THETA, NC + L2][i], j)],
        };
        let free = self.free_coordinates();
        let jacobian = DMatrix::from_fn(free.len(), free.len(), |i, j| row(free[i], free[j]));
        let dparam = param.map(|_| DVector::from_fn(free.len(), |i, _| row(free[i], D - 1)));
        Ok(StepDerivatives {
            outcome: StepOutcome { next, report },
            jacobian,
            dparam,
            signature: words.join(" / "),
            cycle,
        })
    }

    /// Evaluate `P(s)` (`P^k(s)`) as [`StepMap::eval`] does, with the event sequence of its walk: the words of
    /// each step's record (`TD DLS UNLOCK1 LIFT2 LOCK2`: the touchdown's branch, then the changes of contacts
    /// and stoppers between its phases), the steps of an iterated map joined by ` / `.
    pub fn eval_signature(&self, s: &SectionState) -> Result<SignedOutcome, WalkError> {
        let mut walker = self.walker(s)?;
        let mut cycle = Vec::with_capacity(self.iterate);
        let mut words = Vec::with_capacity(self.iterate);
        for _ in 0..self.iterate {
            let mut tape = StepTape::default();
            let step = walker.step_taped(&mut tape)?;
            words.push(tape.signature(step.branch));
            cycle.push(step);
        }
        let next = self.check_hold(walker.section()?)?;
        Ok(SignedOutcome {
            outcome: StepOutcome {
                next,
                report: cycle[0],
            },
            signature: words.join(" / "),
            cycle,
        })
    }

    /// Indices (into [`SECTION_COORDINATES`], `[L2, dtheta/dt, dL2/dt, slip]`) of the coordinates the map acts
    /// on.
    pub(crate) fn free_coordinates(&self) -> &'static [usize] {
        free_coordinates(
            self.model.params().rigid_legs || self.rear_held,
            self.slipping,
        )
    }

    /// The names of the free coordinates (in [`SECTION_COORDINATES`]).
    pub fn free_coordinate_names(&self) -> Vec<&'static str> {
        self.free_coordinates()
            .iter()
            .map(|&i| SECTION_COORDINATES[i])
            .collect()
    }

    /// The free coordinates of `s` as a vector.
    pub fn reduce(&self, s: &SectionState) -> DVector<f64> {
        reduce(self.free_coordinates(), s)
    }

    /// `base` with its free coordinates replaced by `v`.
    pub fn expand(&self, base: &SectionState, v: &DVector<f64>) -> SectionState {
        expand(self.free_coordinates(), base, v)
    }

    /// Central-difference Jacobian `D(h)` of the reduced map at `s`, with relative step `h`.
    pub fn central_jacobian(&self, s: &SectionState, h: f64) -> Result<DMatrix<f64>, WalkError> {
        let x = self.reduce(s);
        let n = x.len();
        let steps: Vec<f64> = x.iter().map(|v| h * v.abs().max(1.0)).collect();
        // The 2n evaluations are independent: run them in parallel (the result does not depend on the
        // number of threads, since each evaluation is the same computation wherever it runs). All of them
        // run, a failure or not, and the first failure in order is the error: the work is the same for any
        // number of threads too.
        let images: Vec<Result<DVector<f64>, WalkError>> = (0..2 * n)
            .into_par_iter()
            .map(carried(|k| {
                let (j, sign) = (k / 2, if k % 2 == 0 { 1.0 } else { -1.0 });
                let mut shifted = x.clone();
                shifted[j] += sign * steps[j];
                Ok(self.reduce(&self.eval(&self.expand(s, &shifted))?.next))
            }))
            .collect();
        let images = images.into_iter().collect::<Result<Vec<_>, _>>()?;
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

/// An error if the step's touchdown impact is on a border between two of its branches: the indicator that decides
/// the branch (`lambda_I4` between (A1) and (A3), `lambda_2+` and `lambda_4+` between (B2), (B3) and the bounce)
/// within [`BORDER_TOL`] of zero. Only the paper's procedure decides by the indicators (not `rigid_legs`, not the
/// traditional exchange, not a landing with the rear leg in the air).
fn on_border(model: &Model, step: &StepReport) -> Result<(), NotDifferentiable> {
    let p = model.params();
    if p.rigid_legs || p.impact != ImpactModel::Dlsi || step.branch == Branch::RearAirborne {
        return Ok(());
    }
    let i = &step.indicators;
    for (indicator, value) in [
        ("lambda_I4", i.lambda_i4),
        ("lambda_2_plus", i.lambda_2_plus),
        ("lambda_4_plus", i.lambda_4_plus),
    ] {
        if value.abs() < BORDER_TOL {
            return Err(NotDifferentiable::Border {
                time: step.time,
                indicator,
                value,
            });
        }
    }
    Ok(())
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
