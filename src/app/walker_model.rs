//! What a walker offers the jobs of `--model` (`simulate`, `sweep`, `orbit`, and `plot`/`animate` of their
//! runs; docs/model.md section 13): [`WalkerModel`], an object-safe interface on section states, so that a job
//! is written once for every walker. Every walker gives it as [`Walking`]: the walker with what a drawing and
//! the energy split need ([`Body`], written once for every walk) and its walk ([`Walk`]): the rigid-leg walk
//! ([`Rigid`], [`crate::mechanism::rigid`]: the simplest walker, the compass gait, [`RigidModel`]) or the
//! compliant-leg walk ([`super::Compliant`], in `super::legged`: [`super::LeggedModel`]); another kind of walk
//! slots in by implementing [`Walk`], another kind of walker by implementing [`WalkerModel`] and being returned
//! by [`super::Walker::model`]. A step's or a search's failure is one [`WalkerError`] or [`WalkerGaitError`]
//! whatever the walk, with the kinds of the walk's own errors (`fell`, `rolled_back`, `no_convergence`, ...).

use std::marker::PhantomData;

use nalgebra::{DVector, SVector};

use crate::integrate::{Dop853, OdeSystem};
use crate::mechanism::compass::{Compass, THETA1, THETA2, X, Z};
use crate::mechanism::legged::gait::LeggedGaitError;
use crate::mechanism::legged::walk::StepAccount;
use crate::mechanism::legged::LeggedError;
use crate::mechanism::rigid::{rigid_step, RigidError, RigidOptions, RigidStep, RigidWalker};
use crate::mechanism::rigid_gait::{rigid_gait, RigidGait, RigidGaitError};
use crate::mechanism::simplest::{Simplest, INTER_LEG_ANGLE, STANCE_ANGLE};
use crate::mechanism::Mechanism;
use crate::output::walker_run::StickFigure;

/// One step of a walker, from just after a heel strike to just after the next.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkerStep {
    /// The section state just after the next heel strike.
    pub section: DVector<f64>,
    /// The step's duration (in the model's time unit).
    pub period: f64,
    /// How far the stance foot moves along the slope (the next stance foot's distance ahead of this one).
    pub stride: f64,
    /// The heel strike's DLS indicator `lambda_I4`.
    pub lambda_i4: f64,
    /// The energy the heel strike takes.
    pub impact_loss: f64,
    /// `T + V` at the step's start.
    pub energy_start: f64,
    /// The largest change of `T + V` over the step's single support (conserved there): its energy audit.
    pub energy_drift: f64,
    /// Crossings of the ground by the swing foot ignored as scuffing.
    pub scuffs: usize,
    /// What a step of a walker with compliant legs has besides (its heel strike's branch and `lambda_2+`,
    /// `lambda_4+`, the double support's duration, the impacts' losses, the dampers' work, the signed energy
    /// audit, the penetration); `None` for a rigid-legged walker.
    pub legged: Option<StepAccount>,
}

/// Why a walker's step failed: the rigid or the legged walk's error, with its kind.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WalkerError {
    /// A rigid-legged walker's step.
    #[error(transparent)]
    Rigid(#[from] RigidError),
    /// A step of a walker with compliant legs.
    #[error(transparent)]
    Legged(#[from] LeggedError),
}

impl WalkerError {
    /// Short machine-readable name: the walk's own (`fell`, `rolled_back`, `stalled`, ...).
    pub fn kind(&self) -> &'static str {
        match self {
            WalkerError::Rigid(e) => e.kind(),
            WalkerError::Legged(e) => e.kind(),
        }
    }

    /// Did the caller ask the walk to stop (Ctrl-C)?
    pub fn is_interrupted(&self) -> bool {
        matches!(
            self,
            WalkerError::Rigid(RigidError::Interrupted)
                | WalkerError::Legged(LeggedError::Interrupted)
        )
    }
}

/// Why a walker's gait search failed: the rigid or the legged search's error, with its kind.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WalkerGaitError {
    /// A rigid-legged walker's search.
    #[error(transparent)]
    Rigid(#[from] RigidGaitError),
    /// The search of a walker with compliant legs.
    #[error(transparent)]
    Legged(#[from] LeggedGaitError),
}

impl WalkerGaitError {
    /// Short machine-readable name: a failed step's kind, `singular_jacobian`, `no_convergence` or
    /// `not_differentiable`.
    pub fn kind(&self) -> &'static str {
        match self {
            WalkerGaitError::Rigid(RigidGaitError::Step { source, .. }) => source.kind(),
            WalkerGaitError::Legged(LeggedGaitError::Step { source, .. }) => source.kind(),
            WalkerGaitError::Rigid(RigidGaitError::Singular { .. })
            | WalkerGaitError::Legged(LeggedGaitError::Singular { .. }) => "singular_jacobian",
            WalkerGaitError::Rigid(RigidGaitError::NoConvergence { .. })
            | WalkerGaitError::Legged(LeggedGaitError::NoConvergence { .. }) => "no_convergence",
            WalkerGaitError::Rigid(RigidGaitError::NotDifferentiable { .. }) => {
                "not_differentiable"
            }
        }
    }
}

/// A walker's state at one instant of a step, for `trajectory.csv` and the drawings.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkerSample {
    /// The walk's time.
    pub time: f64,
    /// The coordinates ([`WalkerModel::coordinates`]).
    pub q: Vec<f64>,
    /// Their rates.
    pub qd: Vec<f64>,
    /// Kinetic energy.
    pub kinetic: f64,
    /// Potential energy (gravity, from the stance foot's height, and the legs' springs where they have some).
    pub potential: f64,
    /// The points of the drawing ([`StickFigure::points`]) in the slope frame, the stance foot at the origin.
    pub points: Vec<[f64; 2]>,
}

/// A gait found from a start.
#[derive(Debug, Clone, PartialEq)]
pub struct FoundGait {
    /// The fixed point on the section.
    pub section: DVector<f64>,
    /// `max |P(s) - s|` there.
    pub residual: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// The Floquet multipliers `[re, im]`, largest modulus first.
    pub multipliers: Vec<[f64; 2]>,
    /// How `DP` was taken, in words (`gait.json`'s `derivative`).
    pub derivative: String,
    /// The error estimate of `DP`, where it was taken by Richardson-extrapolated differences.
    pub jacobian_error: Option<f64>,
    /// The step from the fixed point.
    pub step: WalkerStep,
}

impl FoundGait {
    /// The largest modulus of the multipliers.
    pub fn largest_multiplier(&self) -> f64 {
        self.multipliers
            .first()
            .map_or(f64::NAN, |[re, im]| re.hypot(*im))
    }
}

/// What a walker offers the jobs, on its Poincare section at a heel strike. Every walk answers the library's
/// interrupt flag (Ctrl-C) with an interrupted [`WalkerError`] ([`WalkerError::is_interrupted`]).
pub trait WalkerModel {
    /// The model's name.
    fn name(&self) -> &str;
    /// The names of the generalized coordinates (`trajectory.csv`'s columns).
    fn coordinates(&self) -> Vec<String>;
    /// The names of the section's coordinates.
    fn section_names(&self) -> Vec<String>;
    /// Where a walk or a gait search starts by default.
    fn default_start(&self) -> DVector<f64>;
    /// The slope \[rad\].
    fn slope(&self) -> f64;
    /// What a drawing of the walker shows.
    fn figure(&self) -> StickFigure;
    /// One step from the section state `s`; with `sampling`, its states at its start, at the multiples of the
    /// sampling interval inside it and just before the heel strike are passed to the sink.
    fn step(
        &self,
        s: &DVector<f64>,
        sampling: Option<Sampling<'_>>,
    ) -> Result<WalkerStep, WalkerError>;
    /// The gait near `start` (a section state), after `transient` steps.
    fn gait(&self, start: &DVector<f64>, transient: usize) -> Result<FoundGait, WalkerGaitError>;
    /// Do its steps carry [`WalkerStep::legged`] (`steps.csv`'s extra columns)?
    fn legged(&self) -> bool {
        false
    }
}

/// What the jobs need of a rigid-legged walker besides its walk: the names of its coordinates, its kinetic
/// energy, and the points of its drawing.
pub trait Body<const N: usize> {
    /// The names of `q`.
    fn coordinate_names(&self) -> [&'static str; N];
    /// Kinetic energy.
    fn kinetic(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64;
    /// The slope \[rad\].
    fn slope_angle(&self) -> f64;
    /// What the drawing shows.
    fn stick_figure(&self) -> StickFigure;
    /// The drawing's points at `q`, the stance foot at the origin of the slope frame.
    fn points(&self, q: &SVector<f64, N>) -> Vec<[f64; 2]>;
}

/// A point at `length` along a leg of angle `angle` (from the slope's downward normal, positive down the slope)
/// from `from`.
pub(super) fn along(from: [f64; 2], angle: f64, length: f64) -> [f64; 2] {
    [
        from[0] + length * angle.sin(),
        from[1] - length * angle.cos(),
    ]
}

impl Body<2> for Simplest {
    fn coordinate_names(&self) -> [&'static str; 2] {
        ["theta", "phi"]
    }

    /// The hip's `theta'^2 / 2` (the feet's masses tend to 0).
    fn kinetic(&self, _q: &SVector<f64, 2>, qd: &SVector<f64, 2>) -> f64 {
        0.5 * qd[STANCE_ANGLE] * qd[STANCE_ANGLE]
    }

    fn slope_angle(&self) -> f64 {
        self.slope
    }

    fn stick_figure(&self) -> StickFigure {
        StickFigure::legs_from_hip(&[])
    }

    /// The stance foot, the hip at `(-sin theta, cos theta)`, the swing foot along the swing leg's angle
    /// `theta - phi`.
    fn points(&self, q: &SVector<f64, 2>) -> Vec<[f64; 2]> {
        let theta = q[STANCE_ANGLE];
        let hip = [-theta.sin(), theta.cos()];
        vec![[0.0, 0.0], hip, along(hip, theta - q[INTER_LEG_ANGLE], 1.0)]
    }
}

impl Body<4> for Compass {
    fn coordinate_names(&self) -> [&'static str; 4] {
        self.coordinates()
    }

    fn kinetic(&self, q: &SVector<f64, 4>, qd: &SVector<f64, 4>) -> f64 {
        self.kinetic_energy(q, qd)
    }

    fn slope_angle(&self) -> f64 {
        self.slope
    }

    fn stick_figure(&self) -> StickFigure {
        StickFigure::legs_from_hip(&["stance_leg_mass", "swing_leg_mass"])
    }

    /// The feet at `leg_length` from the hip, the legs' masses at `leg_mass_offset` from the feet.
    fn points(&self, q: &SVector<f64, 4>) -> Vec<[f64; 2]> {
        let hip = [q[X], q[Z]];
        let (l, b) = (self.leg_length, self.leg_length - self.leg_mass_offset);
        vec![
            along(hip, q[THETA1], l),
            hip,
            along(hip, q[THETA2], l),
            along(hip, q[THETA1], b),
            along(hip, q[THETA2], b),
        ]
    }
}

/// A walker as a [`WalkerModel`]: the walker, where its walks start by default, and how it walks (`K`: the
/// rigid-leg walk, [`Rigid`], or the compliant-leg walk, [`super::Compliant`]). What describes the
/// walker to the jobs (its names, slope, drawing and samples) is written here once, for every walk; its steps
/// and gaits are its walk's ([`Walk`]).
#[derive(Debug, Clone, Copy)]
pub struct Walking<'w, W, K, const N: usize, const Y: usize> {
    pub(super) walker: &'w W,
    start: fn(&W) -> DVector<f64>,
    walk: PhantomData<K>,
}

impl<'w, W, K, const N: usize, const Y: usize> Walking<'w, W, K, N, Y> {
    /// `walker`, its searches and walks starting at `start(walker)` by default.
    pub fn new(walker: &'w W, start: fn(&W) -> DVector<f64>) -> Walking<'w, W, K, N, Y> {
        Walking {
            walker,
            start,
            walk: PhantomData,
        }
    }
}

/// A rigid-legged walker as a [`WalkerModel`].
pub type RigidModel<'w, W, const N: usize, const Y: usize> = Walking<'w, W, Rigid, N, Y>;

/// How a kind of walker walks, for [`Walking`]: what differs between the rigid-leg and the compliant-leg walk.
pub trait Walk<W, const N: usize, const Y: usize>: Sized {
    /// Do its steps carry [`WalkerStep::legged`] ([`WalkerModel::legged`])?
    const LEGGED: bool;
    /// The model's name.
    fn name(walker: &W) -> &'static str;
    /// The names of the section's coordinates.
    fn section_names(walker: &W) -> Vec<&'static str>;
    /// The potential energy at `(q, q')` (gravity, and the legs' springs where they have some).
    fn potential(walker: &W, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64;
    /// [`WalkerModel::step`].
    fn step(
        model: &Walking<'_, W, Self, N, Y>,
        s: &DVector<f64>,
        sampling: Option<Sampling<'_>>,
    ) -> Result<WalkerStep, WalkerError>;
    /// [`WalkerModel::gait`].
    fn gait(
        model: &Walking<'_, W, Self, N, Y>,
        start: &DVector<f64>,
        transient: usize,
    ) -> Result<FoundGait, WalkerGaitError>;
}

/// The rigid-leg walk ([`crate::mechanism::rigid`]), for [`Walking`].
#[derive(Debug, Clone, Copy)]
pub struct Rigid;

/// The single-support field of a rigid walker, as the walk integrates it (the jobs' sampling integrates it
/// again, with the same integrator, tolerances and stop, so its steps are the walk's).
struct Field<'w, W, const N: usize>(&'w W);

impl<W: RigidWalker<N, Y>, const N: usize, const Y: usize> OdeSystem<Y> for Field<'_, W, N> {
    fn rhs(&self, _t: f64, y: &SVector<f64, Y>) -> SVector<f64, Y> {
        let (q, qd) = split::<N, Y>(y);
        match self.0.single_support(&q, &qd) {
            Ok((qdd, _)) => SVector::from_iterator(qd.iter().chain(qdd.iter()).copied()),
            Err(_) => SVector::repeat(f64::NAN),
        }
    }
}

/// `(q, q')` of an integrated state.
pub(super) fn split<const N: usize, const Y: usize>(
    y: &SVector<f64, Y>,
) -> (SVector<f64, N>, SVector<f64, N>) {
    (
        SVector::from_iterator(y.rows(0, N).iter().copied()),
        SVector::from_iterator(y.rows(N, N).iter().copied()),
    )
}

impl<W: Body<N>, K: Walk<W, N, Y>, const N: usize, const Y: usize> Walking<'_, W, K, N, Y> {
    /// The sample of the state `(q, q')` at the walk's time `time`.
    pub(super) fn sample(
        &self,
        time: f64,
        (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    ) -> WalkerSample {
        WalkerSample {
            time,
            q: q.iter().copied().collect(),
            qd: qd.iter().copied().collect(),
            kinetic: self.walker.kinetic(q, qd),
            potential: K::potential(self.walker, q, qd),
            points: self.walker.points(q),
        }
    }
}

impl<W, const N: usize, const Y: usize> RigidModel<'_, W, N, Y>
where
    W: RigidWalker<N, Y> + Body<N>,
{
    /// The sample of the integrated state `y` at the walk's time `time`.
    fn sample_of(&self, time: f64, y: &SVector<f64, Y>) -> WalkerSample {
        let (q, qd) = split::<N, Y>(y);
        self.sample(time, (&q, &qd))
    }

    /// The states of the step from `(q, q')` lasting `period`, started at the walk's time `sampling.start`:
    /// at its start, at the multiples of `sampling.dt` inside it, and just before the heel strike, integrated
    /// as [`rigid_step`] integrates it (the same integrator, tolerances and stop, so the same steps).
    fn sampled(
        &self,
        (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
        period: f64,
        sampling: Sampling<'_>,
    ) -> Result<(), RigidError> {
        let options = interruptible();
        let field = Field::<W, N>(self.walker);
        let y0 = SVector::from_iterator(q.iter().chain(qd.iter()).copied());
        let mut integrator = Dop853::new(&field, 0.0, y0, options.tolerances);
        let Sampling { start, dt, sink } = sampling;
        sink(self.sample_of(start, &y0));
        let mut grid = Grid::new(start, dt);
        loop {
            if options.stop.is_some_and(|stop| stop()) {
                return Err(RigidError::Interrupted);
            }
            let step = integrator.step(&field, options.max_step_time)?;
            grid.through(step.t1().min(period), |t| {
                sink(self.sample_of(start + t, &step.eval(t)))
            });
            if step.t1() >= period {
                sink(self.sample_of(start + period, &step.eval(period)));
                return Ok(());
            }
        }
    }
}

/// The walk's grid times `k dt` inside a step started at the walk's time `start`, met in order.
pub(super) struct Grid {
    start: f64,
    dt: f64,
    next: u64,
}

impl Grid {
    /// The grid of the sampling interval `dt`, from the step started at `start`.
    pub(super) fn new(start: f64, dt: f64) -> Grid {
        Grid {
            start,
            dt,
            next: (start / dt).floor() as u64 + 1,
        }
    }

    /// Passes each grid time not yet met before `end` (the step's own time, after its start) to `at`.
    pub(super) fn through(&mut self, end: f64, mut at: impl FnMut(f64)) {
        while (self.next as f64) * self.dt - self.start < end {
            let t = (self.next as f64) * self.dt - self.start;
            if t > 0.0 {
                at(t);
            }
            self.next += 1;
        }
    }
}

/// Where a step's samples go ([`WalkerModel::step`]): the walk's time at the step's start, the sampling
/// interval, and what takes each sample.
pub struct Sampling<'a> {
    /// The walk's time at the step's start.
    pub start: f64,
    /// The sampling interval.
    pub dt: f64,
    /// What takes each sample (its `time` is the walk's).
    pub sink: &'a mut dyn FnMut(WalkerSample),
}

impl<W, K, const N: usize, const Y: usize> WalkerModel for Walking<'_, W, K, N, Y>
where
    W: Body<N>,
    K: Walk<W, N, Y>,
{
    fn name(&self) -> &str {
        K::name(self.walker)
    }

    fn coordinates(&self) -> Vec<String> {
        self.walker
            .coordinate_names()
            .iter()
            .map(|n| n.to_string())
            .collect()
    }

    fn section_names(&self) -> Vec<String> {
        K::section_names(self.walker)
            .iter()
            .map(|n| n.to_string())
            .collect()
    }

    fn default_start(&self) -> DVector<f64> {
        (self.start)(self.walker)
    }

    fn slope(&self) -> f64 {
        self.walker.slope_angle()
    }

    fn figure(&self) -> StickFigure {
        self.walker.stick_figure()
    }

    fn step(
        &self,
        s: &DVector<f64>,
        sampling: Option<Sampling<'_>>,
    ) -> Result<WalkerStep, WalkerError> {
        K::step(self, s, sampling)
    }

    fn gait(&self, start: &DVector<f64>, transient: usize) -> Result<FoundGait, WalkerGaitError> {
        K::gait(self, start, transient)
    }

    fn legged(&self) -> bool {
        K::LEGGED
    }
}

impl<W, const N: usize, const Y: usize> Walk<W, N, Y> for Rigid
where
    W: RigidWalker<N, Y> + Body<N>,
{
    const LEGGED: bool = false;

    fn name(walker: &W) -> &'static str {
        RigidWalker::name(walker)
    }

    fn section_names(walker: &W) -> Vec<&'static str> {
        RigidWalker::section_names(walker)
    }

    /// `T + V` less `T`: the walk's energy less the drawing's kinetic energy.
    fn potential(walker: &W, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64 {
        walker.mechanical_energy(q, qd) - walker.kinetic(q, qd)
    }

    fn step(
        model: &RigidModel<'_, W, N, Y>,
        s: &DVector<f64>,
        sampling: Option<Sampling<'_>>,
    ) -> Result<WalkerStep, WalkerError> {
        let options = interruptible();
        // Asked at every step too: a step takes fewer integrator steps than the walk's own check waits for.
        if options.stop.is_some_and(|stop| stop()) {
            return Err(RigidError::Interrupted.into());
        }
        let (q, qd) = model.walker.state_at_section(s);
        let step = rigid_step(model.walker, &q, &qd, &options)?;
        if let Some(sampling) = sampling {
            model.sampled((&q, &qd), step.period, sampling)?;
        }
        Ok(rigid_record(model.walker, &q, &qd, &step))
    }

    fn gait(
        model: &RigidModel<'_, W, N, Y>,
        start: &DVector<f64>,
        transient: usize,
    ) -> Result<FoundGait, WalkerGaitError> {
        Ok(found_rigid(
            model.walker,
            search_gait(model.walker, start, transient)?,
        ))
    }
}

/// The record of a rigid walker's `step`, started at `(q, q')`.
fn rigid_record<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
    step: &RigidStep<N>,
) -> WalkerStep {
    WalkerStep {
        section: walker.section_of(&step.q, &step.qd),
        period: step.period,
        // Just after the strike the old stance foot is the swing foot, behind the new one.
        stride: -walker.swing_foot(&step.q).1,
        lambda_i4: step.lambda_i4,
        impact_loss: step.impact_loss,
        energy_start: walker.mechanical_energy(q, qd),
        energy_drift: step.energy_drift,
        scuffs: step.scuffs,
        legged: None,
    }
}

/// The rigid walker's gait `g` as the jobs hold a gait.
pub(super) fn found_rigid<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    g: RigidGait<N>,
) -> FoundGait {
    let (q, qd) = walker.state_at_section(&g.section);
    FoundGait {
        step: rigid_record(walker, &q, &qd, &g.step),
        derivative: g.derivative.to_string(),
        jacobian_error: None,
        section: g.section,
        residual: g.residual,
        iterations: g.iterations,
        multipliers: g.multipliers,
    }
}

/// The gait of `walker` searched from the section state `start`: `steps` steps walked, then Newton's method,
/// each walk answering the interrupt flag ([`interruptible`]).
pub(crate) fn search_gait<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    start: &DVector<f64>,
    steps: usize,
) -> Result<RigidGait<N>, RigidGaitError> {
    let options = interruptible();
    let transient = |source| RigidGaitError::Step {
        iteration: 0,
        source,
    };
    let (mut q, mut qd) = walker.state_at_section(start);
    for _ in 0..steps {
        if options.stop.is_some_and(|stop| stop()) {
            return Err(transient(RigidError::Interrupted));
        }
        let step = rigid_step(walker, &q, &qd, &options).map_err(transient)?;
        (q, qd) = (step.q, step.qd);
    }
    rigid_gait(walker, &walker.section_of(&q, &qd), &options)
}

/// The walk's options with the library's interrupt flag (Ctrl-C) asked whether to stop, and `DP` by central
/// differences where the step map has no exact derivative (the outputs say where: `derivative`).
pub(crate) fn interruptible() -> RigidOptions {
    RigidOptions {
        stop: Some(crate::walk::interrupted),
        difference_fallback: true,
        ..RigidOptions::default()
    }
}
