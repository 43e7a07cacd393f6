//! A walker with compliant legs as a [`super::WalkerModel`] (docs/model.md section 13): [`LeggedModel`], the legged
//! walk ([`crate::mechanism::legged`]) on the section at a heel strike before its impact, for every job of a
//! walker (`simulate`, `sweep`, `orbit`, `plot`/`animate` of its runs). Its steps carry the legged walk's account
//! ([`WalkerStep::legged`]: the heel strike's branch and DLS indicators, the double support, the audits), its
//! samples the spring's energy in the potential, and its gaits the multipliers of the exact `DP`, checked
//! against Richardson-extrapolated central differences (their largest difference is the error stated).

use nalgebra::{DVector, SVector};

use super::walker_model::{
    along, split, Body, FoundGait, Grid, Sampling, Walk, WalkerError, WalkerGaitError, WalkerStep,
    Walking,
};
use crate::mechanism::legged::derivative::LeggedDerivatives;
use crate::mechanism::legged::gait::{
    legged_gait_exact, legged_step_map, LeggedGait, LeggedGaitError,
};
use crate::mechanism::legged::walk::{legged_step_observed, LeggedOptions, LeggedStep};
use crate::mechanism::legged::{Legged, LeggedError};
use crate::mechanism::telescopic::{Telescopic, LENGTH1, LENGTH2, THETA1, THETA2, X, Z};
use crate::mechanism::Mechanism;
use crate::output::walker_run::StickFigure;

/// The legged walk's options with the library's interrupt flag (Ctrl-C) asked whether to stop.
pub(crate) fn legged_interruptible() -> LeggedOptions {
    LeggedOptions {
        stop: Some(crate::walk::interrupted),
        ..LeggedOptions::default()
    }
}

/// The gait of `walker` searched from the section state `start`: `transient` steps walked, then Newton's
/// method with the exact derivatives ([`legged_gait_exact`]), each walk answering the interrupt flag.
pub(crate) fn search_legged_gait<W: LeggedDerivatives<N>, const N: usize, const Y: usize>(
    walker: &W,
    start: &DVector<f64>,
    transient: usize,
) -> Result<LeggedGait<N>, LeggedGaitError> {
    let options = legged_interruptible();
    let mut s = start.clone();
    for _ in 0..transient {
        s = legged_step_map::<W, N, Y>(walker, &s, &options)
            .map_err(|source| LeggedGaitError::Step {
                iteration: 0,
                source,
            })?
            .0;
    }
    legged_gait_exact::<W, N, Y>(walker, &s, &options)
}

impl Body<6> for Telescopic {
    fn coordinate_names(&self) -> [&'static str; 6] {
        self.coordinates()
    }

    fn kinetic(&self, q: &SVector<f64, 6>, qd: &SVector<f64, 6>) -> f64 {
        self.kinetic_energy(q, qd)
    }

    fn slope_angle(&self) -> f64 {
        self.slope
    }

    fn stick_figure(&self) -> StickFigure {
        StickFigure::telescopic_legs()
    }

    /// The feet at each leg's length from the hip, the sleeves' ends at their masses (`stopper_length -
    /// leg_mass_offset` from the hip), the rods' tops `leg_mass_offset / 2` above the feet (a drawing's choice:
    /// the spring between sleeve and rod shortens as the leg does).
    fn points(&self, q: &SVector<f64, 6>) -> Vec<[f64; 2]> {
        let hip = [q[X], q[Z]];
        let sleeve = self.stopper_length - self.leg_mass_offset;
        let rod = 0.5 * self.leg_mass_offset;
        vec![
            along(hip, q[THETA1], q[LENGTH1]),
            hip,
            along(hip, q[THETA2], q[LENGTH2]),
            along(hip, q[THETA1], sleeve),
            along(hip, q[THETA2], sleeve),
            along(hip, q[THETA1], q[LENGTH1] - rod),
            along(hip, q[THETA2], q[LENGTH2] - rod),
        ]
    }
}

/// A walker with compliant legs as a [`super::WalkerModel`].
pub type LeggedModel<'w, W, const N: usize, const Y: usize> = Walking<'w, W, Compliant, N, Y>;

/// The compliant-leg walk ([`crate::mechanism::legged`]), for [`Walking`].
#[derive(Debug, Clone, Copy)]
pub struct Compliant;

impl<W: LeggedDerivatives<N> + Body<N>, const N: usize, const Y: usize> LeggedModel<'_, W, N, Y> {
    /// The record of `step`, started at `(q, q')` on the section: the stride is the new stance tip's distance
    /// ahead of the old one (behind the new one just after the relabeling), the energy audit the step's
    /// residual's size.
    fn record(
        &self,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        step: &LeggedStep<N>,
    ) -> WalkerStep {
        let w = self.walker;
        let rear = w.contact(&w.constants_f64(), &step.q, &step.qd, 1).position;
        let account = step.account;
        WalkerStep {
            section: w.section_of(&step.q, &step.qd),
            period: step.period,
            stride: -rear.x,
            lambda_i4: account.lambda_i4,
            impact_loss: account.losses.heel_strike,
            energy_start: w.energy(q, qd),
            energy_drift: account.energy_residual.abs(),
            scuffs: account.scuffs,
            legged: Some(account),
        }
    }

    /// The step from `(q, q')` on the section, its states passed to `sampling`'s sink: at its start (the
    /// section's state, before the heel strike's impact), at the multiples of the sampling interval inside it
    /// and just before the next heel strike, on the walk's own integrator steps.
    fn sampled(
        &self,
        (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
        options: &LeggedOptions,
        sampling: Sampling<'_>,
    ) -> Result<LeggedStep<N>, LeggedError> {
        let Sampling { start, dt, sink } = sampling;
        sink(self.sample(start, (q, qd)));
        let mut grid = Grid::new(start, dt);
        let mut last = None;
        let step =
            legged_step_observed::<W, N, Y>(self.walker, (q, qd), options, &mut |s, end| {
                grid.through(end, |t| {
                    let (q, qd) = split::<N, Y>(&s.eval(t));
                    sink(self.sample(start + t, (&q, &qd)));
                });
                last = Some(if end >= s.t1() { *s.y1() } else { s.eval(end) });
            })?;
        if let Some(y) = last {
            let (q, qd) = split::<N, Y>(&y);
            sink(self.sample(start + step.period, (&q, &qd)));
        }
        Ok(step)
    }
}

impl<W, const N: usize, const Y: usize> Walk<W, N, Y> for Compliant
where
    W: LeggedDerivatives<N> + Body<N>,
{
    const LEGGED: bool = true;

    fn name(walker: &W) -> &'static str {
        Mechanism::name(walker)
    }

    fn section_names(walker: &W) -> Vec<&'static str> {
        Legged::section_names(walker)
    }

    /// Gravity's and the springs' potential energy.
    fn potential(walker: &W, q: &SVector<f64, N>, _qd: &SVector<f64, N>) -> f64 {
        walker.potential_energy(q)
    }

    fn step(
        model: &LeggedModel<'_, W, N, Y>,
        s: &DVector<f64>,
        sampling: Option<Sampling<'_>>,
    ) -> Result<WalkerStep, WalkerError> {
        let options = legged_interruptible();
        if options.stop.is_some_and(|stop| stop()) {
            return Err(LeggedError::Interrupted.into());
        }
        let (q, qd) = model
            .walker
            .state_at_section(s)
            .ok_or(LeggedError::OffSection)?;
        let step = match sampling {
            Some(sampling) => model.sampled((&q, &qd), &options, sampling)?,
            None => {
                legged_step_observed::<W, N, Y>(model.walker, (&q, &qd), &options, &mut |_, _| {})?
            }
        };
        Ok(model.record(&q, &qd, &step))
    }

    fn gait(
        model: &LeggedModel<'_, W, N, Y>,
        start: &DVector<f64>,
        transient: usize,
    ) -> Result<FoundGait, WalkerGaitError> {
        let g = search_legged_gait::<W, N, Y>(model.walker, start, transient)?;
        let (q, qd) = model
            .walker
            .state_at_section(&g.section)
            .ok_or(LeggedGaitError::Step {
                iteration: g.iterations,
                source: LeggedError::OffSection,
            })?;
        Ok(FoundGait {
            step: model.record(&q, &qd, &g.step),
            derivative: g.derivative.to_string(),
            jacobian_error: Some(g.jacobian_error),
            section: g.section,
            residual: g.residual,
            iterations: g.iterations,
            multipliers: g.multipliers,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::WalkerModel;

    /// A step of `vrw simulate --model telescopic` is the gait search's step map bit for bit, with its samples
    /// or without (the observer changes nothing of the walk); its first sample holds the step's starting
    /// energy, its last is at the heel strike, where the swing foot is one stride ahead.
    #[test]
    fn a_simulated_step_is_the_gait_searchs_step_map() {
        let w = Telescopic::default();
        let model = LeggedModel::<_, 6, 13>::new(&w, Telescopic::default_start);
        let s = w.default_start();
        let (p, walked) = legged_step_map::<_, 6, 13>(&w, &s, &LeggedOptions::default()).unwrap();
        let mut samples = Vec::new();
        let mut sink = |x| samples.push(x);
        let sampling = Sampling {
            start: 0.0,
            dt: 0.01,
            sink: &mut sink,
        };
        let step = model.step(&s, Some(sampling)).unwrap();
        assert_eq!(step.section, p);
        assert_eq!(model.step(&s, None).unwrap().section, p);
        assert_eq!(step.period, walked.period);
        assert_eq!(step.legged, Some(walked.account));
        let first = &samples[0];
        assert!((first.kinetic + first.potential - step.energy_start).abs() < 1e-12);
        let last = samples.last().unwrap();
        assert_eq!(last.time, step.period);
        // The figure's swing foot (point 2) at the heel strike: on the ground, one stride ahead of the stance
        // foot (point 0, within the contact's drift of the origin).
        let [stance, swing] = [last.points[0], last.points[2]];
        assert!(
            (swing[0] - stance[0] - step.stride).abs() < 1e-12,
            "{last:?}"
        );
        assert!(stance[0].abs() < 1e-8, "{last:?}");
        assert!(last.points[2][1].abs() < 1e-9, "{last:?}");
        assert!(samples.len() > 80, "{}", samples.len());
    }
}
