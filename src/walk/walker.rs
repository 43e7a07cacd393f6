//! The walker (docs/model.md sections 4-5): [`Walker`] takes the wheel from one touchdown to the next
//! ([`Walker::step`]) in named stages: the touchdown impact, integration to the next event, the event's
//! handling (release of a contact, an impact, a stopper), and at the next touchdown the step's report and the
//! re-indexing of the legs.

use std::cell::Cell;
use std::sync::atomic::AtomicBool;

use crate::contact::{ActiveSet, Phase, Role, Stop};
use crate::dynamics::{swinging, Model, L3, NQ, THETA, X};
use crate::integrate::{locate_root, DenseStep, Integrator, Tolerances};
use crate::params::SolverOptions;

use super::contact_event::contact_event;
use super::error::WalkError;
use super::events::{sample_count, EventKind, EventSet, Forces, Hit, StepSearch};
use super::impact::{
    close_unit, consistent_active_set, lock_swinging_leg, post_impact_candidates, touchdown_impact,
    touchdown_leg, TouchdownImpact, Unit,
};
use super::phase::{pack, unpack, PhaseSystem, WalkState, WalkVector, NY};
use super::reindex::reindex;
use super::report::{EnergyAudit, StepReport};
use super::section::SectionState;
use super::tally::StepTally;
use super::tape::{log_of, StepTape};
use super::trajectory::Trajectory;
use super::work::WorkCounts;
use super::zeno::lock_zeno_stoppers;

/// Largest speed of Leg 2's tip at a touchdown for the wheel to count as on the Poincare section \[m/s\]: the
/// no-slip constraint holds it at rest up to the integration error (~1e-12 m/s).
pub(crate) const SECTION_TIP_SPEED_TOL: f64 = 1e-8;

/// Walks the wheel from touchdown to touchdown.
#[derive(Debug, Clone)]
pub struct Walker<'m> {
    model: &'m Model,
    opts: SolverOptions,
    /// At the section: just before the touchdown impact, after re-indexing.
    state: WalkState,
    steps_done: usize,
    /// Why the next step cannot start (the re-indexing at the last touchdown failed).
    blocked: Option<WalkError>,
    /// The work of every step taken so far.
    work: WorkCounts,
    /// Stops a step in progress when set ([`Walker::with_interrupt`]).
    interrupt: Option<&'m AtomicBool>,
}

/// A walker reads its interrupt flags (its own and the library's) every this many accepted integrator steps
/// (and before the first): stiff legs take millions of integrator steps per walking step, so touchdowns alone are too rare.
pub const INTERRUPT_CHECK_STEPS: usize = 1000;

/// Where the phases of a step end: the touchdown event, with what the step's report needs.
struct Touchdown {
    /// The impact that started the step.
    td: TouchdownImpact,
    tally: StepTally,
    /// `T + V` at the start of the step \[J\].
    e_start: f64,
    /// Time of the touchdown event \[s\].
    t: f64,
    /// The state then.
    y: WalkVector,
    /// The active set then.
    active: ActiveSet,
}

impl<'m> Walker<'m> {
    /// Start at a Poincare-section state (docs/model.md section 6), at time 0 and position 0.
    pub fn new(
        model: &'m Model,
        opts: &SolverOptions,
        section: &SectionState,
    ) -> Result<Walker<'m>, WalkError> {
        section.validate(model)?;
        let (q, qd) = section.to_coords(model);
        let state = WalkState {
            time: 0.0,
            q,
            qd,
            active: section.active_before(model),
            x_origin: 0.0,
            leg1: 0,
        };
        Ok(Walker {
            model,
            opts: opts.clone(),
            state,
            steps_done: 0,
            interrupt: None,
            blocked: None,
            work: WorkCounts::ZERO,
        })
    }

    /// The current state (at the section).
    pub fn state(&self) -> &WalkState {
        &self.state
    }

    /// The section coordinates `(L2, thetadot, L2dot, slip)` at the current touchdown, without the check of
    /// [`Walker::section`]: what a return map or an orbit diagram records. Where the stance tip slides without
    /// friction they do not hold the whole state, so they must not be used to start a walk there.
    pub(crate) fn touchdown_coordinates(&self) -> SectionState {
        SectionState::at_touchdown(
            self.model,
            &self.state.q,
            &self.state.qd,
            &self.state.active,
        )
    }

    /// The current Poincare-section state, or why the walk cannot continue, or why the wheel is not on the
    /// section ([`WalkError::OffSection`]: Leg 2's tip, which the section assumes at rest (or slipping along the
    /// ground with Coulomb friction), slides frictionlessly or leaves the ground; [`WalkError::SwingAtSection`]:
    /// the old rear leg still swings).
    pub fn section(&self) -> Result<SectionState, WalkError> {
        if let Some(e) = &self.blocked {
            return Err(e.clone());
        }
        let (q, qd) = (&self.state.q, &self.state.qd);
        if swinging(q) {
            return Err(WalkError::SwingAtSection {
                time: self.state.time,
                length: q[L3],
                rate: qd[L3],
            });
        }
        let v = self.model.tip(q, qd, Role::Rear.index()).velocity(qd);
        // A tip slipping with Coulomb friction is on the section with its slip velocity: only its normal
        // velocity must vanish.
        let slips = self.state.active.slip2 != 0;
        let speed = if slips { v.y.abs() } else { v.norm() };
        if speed > SECTION_TIP_SPEED_TOL {
            return Err(WalkError::OffSection {
                time: self.state.time,
                speed,
            });
        }
        Ok(self.touchdown_coordinates())
    }

    fn tolerances(&self) -> Tolerances {
        Tolerances {
            rtol: self.opts.rtol,
            atol: self.opts.atol,
            h_max: self.opts.max_step,
            ..Tolerances::default()
        }
    }

    /// Advance from this touchdown to the next one: the impact procedure, then the continuous phases and their
    /// events. Returns the step's report; the walker is then at the next section. Samples go to `trajectory`.
    ///
    /// The stages: `walk_to_touchdown` (the touchdown impact, then `integrate_to_event` and `handle_event`
    /// until the next touchdown), then `finish_step` (the report and the re-indexing). The step's work, failed
    /// or not, is added to [`Walker::work`].
    pub fn step(&mut self, trajectory: Option<&mut Trajectory>) -> Result<StepReport, WalkError> {
        self.step_recorded(trajectory, None)
    }

    /// [`Walker::step`], recording the step in `tape` (which must be empty) for the exact derivatives.
    pub(crate) fn step_taped(&mut self, tape: &mut StepTape) -> Result<StepReport, WalkError> {
        self.step_recorded(None, Some(tape))
    }

    fn step_recorded(
        &mut self,
        trajectory: Option<&mut Trajectory>,
        tape: Option<&mut StepTape>,
    ) -> Result<StepReport, WalkError> {
        if let Some(e) = &self.blocked {
            return Err(e.clone());
        }
        let start = self.state.clone();
        crate::meter::count_step();
        let mut work = WorkCounts {
            steps: 1,
            ..WorkCounts::ZERO
        };
        let reached = self.walk_to_touchdown(&start, trajectory, tape, &mut work);
        self.work += work;
        reached.map(|touchdown| self.finish_step(&start, touchdown))
    }

    /// Stops a step in progress when `flag` is set (e.g. by Ctrl-C), as the library's own flag
    /// ([`super::interrupt`]) always does: the flags are read every [`INTERRUPT_CHECK_STEPS`] integrator
    /// steps, and the step then fails with [`WalkError::Interrupted`].
    pub fn with_interrupt(mut self, flag: Option<&'m AtomicBool>) -> Walker<'m> {
        self.interrupt = flag;
        self
    }

    /// The work of every step this walker took, failed ones included.
    pub fn work(&self) -> WorkCounts {
        self.work
    }

    /// From the section state `start` to the next touchdown event: the touchdown impact and the active set
    /// that follows it, then the phases up to the touchdown. Counts its work in `work`.
    fn walk_to_touchdown(
        &self,
        start: &WalkState,
        trajectory: Option<&mut Trajectory>,
        mut tape: Option<&mut StepTape>,
        work: &mut WorkCounts,
    ) -> Result<Touchdown, WalkError> {
        let model = self.model;
        let t_start = start.time;

        let e_start = model.energy(&start.q, &start.qd);
        let td = touchdown_impact(model, &start.q, &start.qd, start.active)
            .map_err(WalkError::contact_at(t_start, Phase::SingleSupport))?;
        work.impacts += 1;
        if let Some(tape) = tape.as_deref_mut() {
            tape.impact(td.impulse_set);
        }
        let mut tally = StepTally::after_touchdown(model, &td);
        let mut present = start.active;
        present.set_contact(Role::Fore, true);
        let (forced, candidates) = post_impact_candidates(
            model,
            &start.q,
            &td.qd_plus,
            &td.impulse_set,
            &present,
            &td.preferred,
        );
        let (mut active, _) =
            consistent_active_set(model, &start.q, &td.qd_plus, forced, &candidates)
                .map_err(WalkError::contact_at(t_start, td.preferred.phase()))?
                .ok_or(WalkError::InconsistentContacts {
                    time: t_start,
                    phase: td.preferred.phase(),
                })?;
        tally.scuffing |= active.slide2;
        let mut qd_plus = td.qd_plus;
        let zeno = lock_zeno_stoppers(
            model,
            &start.q,
            &qd_plus,
            active,
            (self.opts.stopper_gap, self.opts.recontact_gap),
            t_start,
        )?;
        if let Some(lock) = zeno {
            work.impacts += 1;
            tally.see_zeno(&lock);
            if let Some(tape) = tape.as_deref_mut() {
                lock.impulse_sets.iter().for_each(|set| tape.impact(*set));
            }
            (qd_plus, active) = (lock.qd_plus, lock.active);
        }

        let y = pack(&start.q, &qd_plus, 0.0);
        let mut phases = Phases::start(self, start, (trajectory, tape), tally, active, y);
        let reached = phases.run();
        *work += phases.work();
        let (t, y) = reached?;
        Ok(Touchdown {
            td,
            tally: phases.tally,
            e_start,
            t,
            y,
            active: phases.active,
        })
    }

    /// Stage 3, at the touchdown event: the step's report, then re-indexing for the next step.
    fn finish_step(&mut self, start: &WalkState, touchdown: Touchdown) -> StepReport {
        let Touchdown {
            td,
            tally,
            e_start,
            t,
            y,
            active,
        } = touchdown;
        let model = self.model;
        let (q, qd) = unpack(&y);
        let e_end = model.energy(&q, &qd);
        let damper = y[2 * NQ];
        let loss = e_start - e_end;
        let touching = touchdown_leg(model, &q);
        let front = model.tip(&q, &qd, touching);
        let step_length = front.position.x - start.q[X];
        let period = t - start.time;
        self.steps_done += 1;
        let reindexed = reindex(model, t, &q, &qd, active, touching);
        let report = StepReport {
            step: self.steps_done,
            time: start.time,
            section: SectionState::at_touchdown(model, &start.q, &start.qd, &start.active),
            theta: start.q[THETA],
            indicators: td.indicators,
            branch: td.branch,
            dls_duration: tally.dls_duration,
            rear_contact_duration: tally.rear_contact_duration,
            period,
            step_length,
            speed: step_length / period,
            scuffing: tally.scuffing,
            bounce: tally.bounce,
            events: tally.events,
            energy: EnergyAudit {
                start: e_start,
                end: e_end,
                loss,
                damper,
                impact: tally.impact_loss,
                stopper: tally.stopper_loss,
                friction: model.params().has_friction().then_some(tally.friction_loss),
                residual: loss
                    - (damper + tally.impact_loss + tally.stopper_loss + tally.friction_loss),
                reset: reindexed.as_ref().map_or(0.0, |r| r.3),
            },
            contact: tally.audit,
            slowest: tally.slowest.value,
        };
        match reindexed {
            Ok((q_new, qd_new, before, _)) => {
                self.state = WalkState {
                    time: t,
                    q: q_new,
                    qd: qd_new,
                    active: before,
                    x_origin: start.x_origin + front.position.x,
                    leg1: (start.leg1 + touching) % model.legs(),
                };
            }
            Err(e) => self.blocked = Some(e),
        }
        report
    }
}

/// The continuous part of a step in progress: the phases between the touchdown impact and the next touchdown,
/// integrated one accepted step at a time ([`Phases::integrate_to_event`]) with the events handled as they
/// come ([`Phases::handle_event`]).
struct Phases<'a> {
    model: &'a Model,
    opts: &'a SolverOptions,
    /// The section state the step started from (its frame and time).
    start: &'a WalkState,
    trajectory: Option<&'a mut Trajectory>,
    /// The record of the step for the exact derivatives, if asked for.
    tape: Option<&'a mut StepTape>,
    tally: StepTally,
    /// Time of the integrator's current point \[s\].
    t: f64,
    /// The state at the last event (or the start of the step).
    y: WalkVector,
    active: ActiveSet,
    /// A step that has not reached its touchdown by then stalls.
    t_limit: f64,
    /// The walker's interrupt flag ([`Walker::with_interrupt`]).
    interrupt: Option<&'a AtomicBool>,
    solver: Integrator<NY>,
    events: EventSet<'a>,
    /// Event values at the integrator's current point.
    g_prev: Vec<f64>,
    /// The states at the event search's points of the last integrator step (all of them when no event cut the
    /// step short), for the penetration audit: one buffer for every step.
    sampled: Vec<WalkVector>,
    /// Crossings, root evaluations, events and impacts so far (the integrator counts its own work).
    work: WorkCounts,
}

impl<'a> Phases<'a> {
    /// Start the first phase at `(start.time, y)` with `active`, right after the touchdown impact.
    fn start(
        walker: &'a Walker<'_>,
        start: &'a WalkState,
        (mut trajectory, mut tape): (Option<&'a mut Trajectory>, Option<&'a mut StepTape>),
        mut tally: StepTally,
        active: ActiveSet,
        y: WalkVector,
    ) -> Phases<'a> {
        let (model, opts) = (walker.model, &walker.opts);
        let t = start.time;
        if let Some(tr) = trajectory.as_deref_mut() {
            tr.push(model, t, &y, active, start);
        }
        if let Some(tape) = tape.as_deref_mut() {
            tape.begin(active, t, y);
        }
        let t_limit = start.time + opts.max_step_time;
        let solver = Integrator::new(
            opts.integrator,
            &PhaseSystem::at(model, active, &y).logging(log_of(&tape)),
            t,
            y,
            walker.tolerances(),
        );
        let events = EventSet::new(model, opts, active, &y);
        let (g_prev, pull) = events.values(&y);
        tally.audit.see_force(pull);
        tally.audit.see_tips(model, &y);
        tally.slowest.begin_phase(t, y[NQ + THETA]);
        Phases {
            model,
            opts,
            start,
            trajectory,
            tape,
            tally,
            t,
            y,
            active,
            t_limit,
            interrupt: walker.interrupt,
            solver,
            events,
            g_prev,
            sampled: Vec::new(),
            work: WorkCounts::ZERO,
        }
    }

    /// Integrate until the touchdown event: its time and state.
    fn run(&mut self) -> Result<(f64, WalkVector), WalkError> {
        loop {
            let Some(hit) = self.integrate_to_event()? else {
                continue;
            };
            if let Some(touchdown) = self.handle_event(hit)? {
                return Ok(touchdown);
            }
        }
    }

    /// The work so far, the integrator's included.
    fn work(&self) -> WorkCounts {
        let stats = self.solver.stats();
        WorkCounts {
            accepted: stats.accepted,
            rejected: stats.rejected,
            rhs_evals: stats.rhs_evals,
            ..self.work
        }
    }

    /// Stage 1: one accepted integrator step, searched for events on its dense output, with the step's share
    /// of the durations, the contact audit and the trajectory. Returns the earliest event in the step, or
    /// `None` when there is none (the integrator's point is then the step's end, with the guards armed).
    fn integrate_to_event(&mut self) -> Result<Option<Hit>, WalkError> {
        let (model, active) = (self.model, self.active);
        let phase = active.phase();
        if self.t >= self.t_limit {
            return Err(WalkError::Stalled {
                time: self.t,
                phase,
                limit: self.opts.max_step_time,
            });
        }
        if self
            .solver
            .stats()
            .accepted
            .is_multiple_of(INTERRUPT_CHECK_STEPS)
            && super::interrupt::stop_requested(self.interrupt)
        {
            return Err(WalkError::Interrupted {
                time: self.t,
                phase,
            });
        }
        let sys = PhaseSystem::at(model, active, &self.y).logging(log_of(&self.tape));
        let step = self
            .solver
            .step(&sys, self.t_limit)
            .map_err(|source| WalkError::Integration { phase, source })?;
        if let Some(tape) = self.tape.as_deref_mut() {
            tape.step(step.h(), step.t1());
        }
        let StepSearch {
            hit,
            mut g_next,
            pull_next,
        } = self.search_step(&step);
        let t_end = hit.map_or(step.t1(), |(t_hit, _)| t_hit);
        if active.double_support() {
            self.tally.dls_duration += t_end - step.t0();
        }
        if active.contact2 {
            self.tally.rear_contact_duration += t_end - step.t0();
        }
        if active.any_slip() {
            self.tally.see_slip(model, active, &step, t_end);
        }
        match hit {
            // The same points see_dense would take, evaluated once.
            None => self
                .sampled
                .iter()
                .for_each(|y| self.tally.audit.see_tips(model, y)),
            Some(_) => self.tally.audit.see_dense(model, &step, t_end, self.opts),
        }
        if let Some(tr) = self.trajectory.as_deref_mut() {
            tr.record(model, &step, t_end, active, self.start);
        }
        let Some((t_hit, k)) = hit else {
            self.tally.audit.see_force(pull_next);
            self.events.arm(&mut g_next);
            self.g_prev = g_next;
            self.t = step.t1();
            return Ok(None);
        };
        Ok(Some(Hit {
            time: t_hit,
            index: k,
            y: step.eval(t_hit),
        }))
    }

    /// The event search of stage 1. Events are looked for on [`sample_count`] equal sub-intervals of the
    /// step's dense output (at least four, none longer than `event_spacing`), the first one with a crossing
    /// first: an event function that dips below its floor and back within a step is still caught if the dip is
    /// longer than a sub-interval. The pulling force at the sample points before the last one goes to the
    /// contact audit.
    fn search_step(&mut self, step: &DenseStep<NY>) -> StepSearch {
        let opts = self.opts;
        let mut hit: Option<(f64, usize)> = None;
        let (mut t_a, mut pull_next, mut g_next) = (step.t0(), Forces::NONE, Vec::new());
        let n = sample_count(step.t0(), step.t1(), opts.event_spacing);
        self.sampled.clear();
        for i in 1..=n {
            let t_b = if i == n {
                step.t1()
            } else {
                step.t0() + (step.t1() - step.t0()) * i as f64 / n as f64
            };
            self.sampled.push(step.eval(t_b));
            (g_next, pull_next) = self.events.values(&self.sampled[i - 1]);
            for (k, (&g_a, &g_b)) in self.g_prev.iter().zip(&g_next).enumerate() {
                if g_a > 0.0 && g_b <= 0.0 {
                    let root_evals = Cell::new(0);
                    let tk = locate_root(
                        step,
                        |_, y| {
                            root_evals.set(root_evals.get() + 1);
                            self.events.value(k, y)
                        },
                        t_a,
                        g_a,
                        t_b,
                        g_b,
                        opts.event_time_tol,
                    );
                    self.work.crossings += 1;
                    self.work.root_evals += root_evals.get();
                    if hit.is_none_or(|(t_hit, _)| tk < t_hit) {
                        hit = Some((tk, k));
                    }
                }
            }
            if hit.is_some() {
                break;
            }
            self.tally.slowest.see(t_b, self.sampled[i - 1][NQ + THETA]);
            if i < n {
                self.tally.audit.see_force(pull_next);
                self.g_prev = std::mem::take(&mut g_next);
            }
            t_a = t_b;
        }
        StepSearch {
            hit,
            g_next,
            pull_next,
        }
    }

    /// Stage 2: the event `hit`. A touchdown ends the phases (its time and state are returned), a fall or a
    /// roll-back fails the step; any other event changes the active set (through an impact for a landing or a
    /// stopper hit) and the next phase starts there.
    fn handle_event(&mut self, hit: Hit) -> Result<Option<(f64, WalkVector)>, WalkError> {
        let model = self.model;
        let phase = self.active.phase();
        let t = hit.time;
        self.t = t;
        self.y = hit.y;
        let (q, qd) = unpack(&self.y);
        self.tally.slowest.see(t, qd[THETA]);
        self.tally.audit.see_force(self.events.values(&self.y).1);
        let kind = self.events.events[hit.index].kind;
        self.work.events.count(kind);
        if let Some(tape) = self.tape.as_deref_mut() {
            tape.end(t, kind, self.y);
        }
        match kind {
            EventKind::Touchdown => return Ok(Some((t, self.y))),
            EventKind::Fall => {
                return Err(WalkError::Fell {
                    time: t,
                    phase,
                    hub_height: model.hub_height(&q),
                })
            }
            EventKind::RollBack => return Err(WalkError::RolledBack { time: t, phase }),
            EventKind::SwingLanding => {
                return Err(WalkError::SwingingLegLanded {
                    time: t,
                    phase,
                    length: q[L3],
                })
            }
            EventKind::SwingLock => {
                let lock = lock_swinging_leg(model, &q, &qd, self.active)
                    .map_err(WalkError::contact_at(t, phase))?
                    .ok_or(WalkError::InconsistentContacts { time: t, phase })?;
                self.work.impacts += 1;
                self.tally.see_swing_lock(&lock, &self.active);
                self.active = lock.active;
                self.y = pack(&lock.q, &lock.qd_plus, self.y[2 * NQ]);
            }
            EventKind::LiftOff(leg) | EventKind::ConeLimit(leg) | EventKind::SlipStop(leg) => {
                self.active = contact_event(model, t, (&q, &qd), self.active, kind)?;
                self.tally.bounce |= leg == Role::Fore && !self.active.contact(Role::Fore);
                self.tally.scuffing |= self.active.slide2;
            }
            EventKind::Unlock(leg) => self.active.set_held(leg, Stop::Extension, false),
            EventKind::CompressionUnlock(leg) => {
                self.active.set_held(leg, Stop::Compression, false)
            }
            EventKind::Landing(leg)
            | EventKind::StopperHit(leg)
            | EventKind::CompressionHit(leg) => self.close_at_event(leg, kind, phase)?,
        }
        self.tally.events += 1;
        if self.tally.events > self.opts.max_events_per_step {
            return Err(WalkError::Chatter {
                time: t,
                phase: self.active.phase(),
                events: self.tally.events,
            });
        }
        self.restart_phase();
        Ok(None)
    }

    /// A landing or a stopper hit of `leg` (the event `kind`, in `phase`) at the current point: the unit closes
    /// by a plastic impact ([`close_unit`], docs/model.md section 5), then the Zeno rule may lock the legs and
    /// tips the impact kicked off ([`lock_zeno_stoppers`]).
    fn close_at_event(
        &mut self,
        leg: Role,
        kind: EventKind,
        phase: Phase,
    ) -> Result<(), WalkError> {
        let (model, t) = (self.model, self.t);
        let (q, qd) = unpack(&self.y);
        let unit = match kind.stop_hit() {
            Some((_, stop)) => Unit::Stop(leg, stop),
            None => Unit::Contact(leg),
        };
        let closed = close_unit(model, &q, &qd, self.active, unit)
            .map_err(WalkError::contact_at(t, phase))?
            .ok_or(WalkError::InconsistentContacts { time: t, phase })?;
        self.work.impacts += 1;
        if let Some(tape) = self.tape.as_deref_mut() {
            tape.impact(closed.impulse_set);
        }
        self.tally.see_closed_unit(&closed, unit, leg);
        let (mut qd_plus, mut active) = (closed.qd_plus, closed.active);
        let gaps = (self.opts.stopper_gap, self.opts.recontact_gap);
        if let Some(lock) = lock_zeno_stoppers(model, &q, &qd_plus, active, gaps, t)? {
            self.work.impacts += 1;
            self.tally.see_zeno(&lock);
            if let Some(tape) = self.tape.as_deref_mut() {
                lock.impulse_sets.iter().for_each(|set| tape.impact(*set));
            }
            (qd_plus, active) = (lock.qd_plus, lock.active);
        }
        // Leg 1's tip may leave the ground at an impact (a stopper lock that lifts the wheel).
        self.tally.bounce |= self.active.contact1 && !active.contact1;
        self.active = active;
        self.y = pack(&q, &qd_plus, self.y[2 * NQ]);
        Ok(())
    }

    /// Start the next phase at the event just handled: the integrator and the event functions restart with the
    /// new active set, and the trajectory takes a sample there.
    fn restart_phase(&mut self) {
        let (model, active) = (self.model, self.active);
        let sys = PhaseSystem::at(model, active, &self.y).logging(log_of(&self.tape));
        self.solver.restart(&sys, self.t, self.y);
        self.events = EventSet::new(model, self.opts, active, &self.y);
        let pull;
        (self.g_prev, pull) = self.events.values(&self.y);
        self.tally.audit.see_force(pull);
        self.tally.slowest.begin_phase(self.t, self.y[NQ + THETA]);
        if let Some(tr) = self.trajectory.as_deref_mut() {
            tr.push(model, self.t, &self.y, active, self.start);
        }
        if let Some(tape) = self.tape.as_deref_mut() {
            tape.begin(active, self.t, self.y);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{Coords, Z};
    use crate::params::{Config, Params};

    /// The rigid wheel standing on two legs (`theta = -alpha/2`) is a block on the incline: with both tips
    /// slipping, its rows fix `z` and `theta`, the normal forces sum to `W cos phi` whatever their split, and
    /// `x'' = g (sin phi - s mu cos phi)` exactly. Walks the block from `(x, x') = (0, v0)` until `t_end` (the
    /// step then stalls, as a step without touchdown must) and returns its samples.
    fn slide_block(mu: f64, slope: f64, v0: f64, t_end: f64) -> Vec<crate::walk::Sample> {
        let params = Params {
            rigid_legs: true,
            friction: mu,
            slope,
            ..Params::default()
        };
        let model = Model::new(&params).unwrap();
        let mut opts = Config::default().solver;
        opts.max_step_time = t_end;
        let section = SectionState {
            l2: 1.0,
            theta_dot: 1.0,
            l2_dot: 0.0,
            slip: 0.0,
        };
        let mut walker = Walker::new(&model, &opts, &section).unwrap();
        let q = Coords::new(0.0, 0.0, -model.alpha() / 2.0, 1.0, 1.0, 0.0);
        let qd = Coords::new(v0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let mut active = ActiveSet {
            contact1: true,
            contact2: true,
            lock1: true,
            lock2: true,
            ..Default::default()
        };
        let direction = if v0 > 0.0 || (v0 == 0.0 && slope.tan() > mu) {
            1
        } else {
            -1
        };
        active.set_slipping(Role::Fore, direction);
        active.set_slipping(Role::Rear, direction);
        walker.state = WalkState {
            q,
            qd,
            active,
            ..walker.state.clone()
        };
        let mut trajectory = Trajectory::new(0.01);
        let start = walker.state.clone();
        let y = pack(&q, &qd, 0.0);
        let tally = StepTally::default();
        let mut phases = Phases::start(
            &walker,
            &start,
            (Some(&mut trajectory), None),
            tally,
            active,
            y,
        );
        let end = phases.run();
        assert!(matches!(end, Err(WalkError::Stalled { .. })), "{end:?}");
        trajectory.samples
    }

    /// A block on an incline with Coulomb friction: it slips with the exact acceleration `g (sin phi - mu cos
    /// phi)` above `tan phi = mu`; below, a block sliding down decelerates at `g (mu cos phi - sin phi)`, stops
    /// at `t* = v0 / (g (mu cos phi - sin phi))` (a slip-stop event) and stays at rest.
    #[test]
    fn a_block_on_an_incline_slips_and_stops_exactly() {
        let g = 9.81;
        let slope: f64 = 0.3;
        // Above tan phi = mu: from rest, down the slope.
        let mu = 0.2;
        let a = g * (slope.sin() - mu * slope.cos());
        let samples = slide_block(mu, slope, 0.0, 1.0);
        assert!(samples.len() > 90, "{}", samples.len());
        for s in &samples {
            assert!((s.q[X] - 0.5 * a * s.time * s.time).abs() < 1e-9, "{s:?}");
            assert!(s.q[Z].abs() < 1e-12 && s.qd[THETA].abs() < 1e-9);
        }
        // Below: sliding down at 1 m/s, it stops at t*.
        let (mu, v0) = (0.5, 1.0);
        let decel = g * (mu * slope.cos() - slope.sin());
        let t_stop = v0 / decel;
        let x_stop = 0.5 * v0 * t_stop;
        let samples = slide_block(mu, slope, v0, 1.5 * t_stop + 0.2);
        assert!(samples.last().unwrap().time > 1.2 * t_stop);
        assert!(samples.iter().filter(|s| s.time > t_stop).count() > 10);
        for s in &samples {
            let x = if s.time < t_stop {
                v0 * s.time - 0.5 * decel * s.time * s.time
            } else {
                x_stop
            };
            assert!((s.q[X] - x).abs() < 1e-9, "t {}: {} vs {x}", s.time, s.q[X]);
        }
    }
}
