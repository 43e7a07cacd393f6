//! One step of a legged walker (docs/model.md section 13): from a state on the section (a heel strike after
//! the relabeling, before its impact) through the heel strike's DLS-indicator procedure, the phases it chooses
//! and their events, to the next heel strike.
//!
//! A phase integrates `(q, q', W)` (`W` the dampers' work, a quadrature for the energy audit) with DOP853. After
//! every accepted step the event functions are evaluated at the ends of [`EVENT_SAMPLES`] equal parts of it on
//! the dense output; the earliest function that goes from `> 0` to `<= 0` over a part is located by Brent's
//! method (`crate::integrate::locate_root`) and handled: a lift-off (a tip's normal force
//! [`FORCE_EVENT_MARGIN`] below zero) or a stopper's unlock (its holding force the same) chooses the next phase
//! ([`super::forces::choose`]); a leg reaching its stopper or a bounced fore tip landing is an impact
//! ([`super::impact::impact`]); the swing tip reaching the ground ahead of the fore tip ends the step. A stopper
//! and a landing tip are guarded as the wheel's (docs/model.md section 4): a function that starts within
//! [`GUARD_GAP`] of its zero is disarmed until it has cleared the gap, and fires only past `-GUARD_GAP` before.

use nalgebra::SVector;

use super::forces::{solve, Solved};
use super::impact::{heel_strike, impact, next_phase, Branch, Closing};
use super::{Legged, LeggedError, Modes, Tip};
use crate::integrate::{locate_root, DenseStep, Dop853, Method, OdeSystem, Tolerances};
use crate::mechanism::rigid::{MIN_STRIDE, STOP_CHECK_STEPS};
use crate::mechanism::sensitivity::Tape;

/// Equal parts of an accepted step at whose ends the event functions are evaluated.
pub const EVENT_SAMPLES: usize = 4;

/// A force event fires this far below zero \[N\], as the wheel's (`FORCE_EVENT_MARGIN`).
pub const FORCE_EVENT_MARGIN: f64 = 1e-10;

/// The grazing guard of a stopper and of a landing tip \[m\].
pub const GUARD_GAP: f64 = 1e-9;

/// How a legged walker's step is integrated.
#[derive(Debug, Clone, Copy)]
pub struct LeggedOptions {
    /// The integrator's tolerances.
    pub tolerances: Tolerances,
    /// The longest a step may last \[s\].
    pub max_step_time: f64,
    /// Events are located to this time \[s\].
    pub event_time_tol: f64,
    /// Most events in one step before it is called chatter.
    pub max_events: usize,
    /// Asked every [`STOP_CHECK_STEPS`] integrator steps whether to stop (Ctrl-C); `None`: never.
    pub stop: Option<fn() -> bool>,
}

impl Default for LeggedOptions {
    fn default() -> LeggedOptions {
        LeggedOptions {
            tolerances: Tolerances {
                rtol: 1e-11,
                atol: 1e-12,
                h_max: 0.01,
                h_min: 1e-14,
            },
            max_step_time: 20.0,
            event_time_tol: 1e-13,
            max_events: 200,
            stop: None,
        }
    }
}

/// The energy a step's impacts took, by kind \[J\].
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Losses {
    /// The heel strike at the step's start.
    pub heel_strike: f64,
    /// Legs reaching their stoppers.
    pub stoppers: f64,
    /// A bounced fore tip landing again.
    pub landings: f64,
}

/// What a step's heel strike decided and what its audits found (`gait.json` writes it as it is).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct StepAccount {
    /// DLS indicator 1 of the step's heel strike \[N s\].
    pub lambda_i4: f64,
    /// DLS indicator 2, the fore tip's normal force after (A1) \[N\] (`None` where (A3) was taken).
    pub lambda_2_plus: Option<f64>,
    /// DLS indicator 3, the rear tip's \[N\].
    pub lambda_4_plus: Option<f64>,
    /// The heel strike's branch.
    pub branch: Branch,
    /// Time with both tips on the ground without slipping \[s\].
    pub dls_duration: f64,
    /// Time with the rear tip on the ground, stuck or sliding \[s\].
    pub rear_contact_duration: f64,
    /// The impacts' losses.
    pub losses: Losses,
    /// The dampers' work \[J\].
    pub damper_work: f64,
    /// The energy audit: `T + V` at the start less at the end, less the losses and the dampers' work \[J\].
    pub energy_residual: f64,
    /// The deepest an active tip went into the ground (constraint drift) \[m\].
    pub penetration: f64,
    /// Crossings of the ground by the swing tip that were not heel strikes (scuffing).
    pub scuffs: usize,
    /// Events in the step.
    pub events: usize,
}

/// One step from a heel strike (on the section) to the next.
#[derive(Debug, Clone, PartialEq)]
pub struct LeggedStep<const N: usize> {
    /// The state at the next heel strike, relabeled, before its impact (on the section).
    pub q: SVector<f64, N>,
    /// Its velocities.
    pub qd: SVector<f64, N>,
    /// The legs held at their stoppers there (the new fore leg first).
    pub held: [bool; 2],
    /// The step's duration \[s\].
    pub period: f64,
    /// Its heel strike and audits.
    pub account: StepAccount,
}

/// The vector field of a phase: `(q', q'', damper power)` with the rows of `modes`.
struct Phase<'w, W, const N: usize> {
    walker: &'w W,
    modes: Modes,
}

impl<W: Legged<N>, const N: usize, const Y: usize> OdeSystem<Y> for Phase<'_, W, N> {
    fn rhs(&self, _t: f64, y: &SVector<f64, Y>) -> SVector<f64, Y> {
        let (q, qd) = unpack::<N, Y>(y);
        match solve(self.walker, (&q, &qd), &self.modes) {
            Ok(s) => pack(&qd, &s.qdd, self.walker.damper_power(&q, &qd)),
            Err(_) => SVector::repeat(f64::NAN),
        }
    }
}

/// `(q, q', w)` as one state.
fn pack<const N: usize, const Y: usize>(
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
    w: f64,
) -> SVector<f64, Y> {
    assert_eq!(Y, 2 * N + 1, "a legged walker integrates (q, q', W)");
    let mut y = SVector::<f64, Y>::zeros();
    y.rows_mut(0, N).copy_from(q);
    y.rows_mut(N, N).copy_from(qd);
    y[2 * N] = w;
    y
}

/// `(q, q')` of a state.
fn unpack<const N: usize, const Y: usize>(
    y: &SVector<f64, Y>,
) -> (SVector<f64, N>, SVector<f64, N>) {
    (
        SVector::from_iterator(y.rows(0, N).iter().copied()),
        SVector::from_iterator(y.rows(N, N).iter().copied()),
    )
}

/// A grazing guard (see the module documentation): `Some(floor)` while disarmed.
#[derive(Debug, Clone, Copy)]
struct Guard(Option<f64>);

impl Guard {
    /// The guard of a function starting at `g0`.
    fn new(g0: f64) -> Guard {
        Guard((g0 <= GUARD_GAP).then(|| g0.min(0.0) - GUARD_GAP))
    }

    /// The guarded value of `g`.
    fn value(&self, g: f64) -> f64 {
        g - self.0.unwrap_or(0.0)
    }

    /// Arm once `g` has cleared the gap at an accepted step.
    fn update(&mut self, g: f64) {
        if g > GUARD_GAP {
            self.0 = None;
        }
    }
}

/// The events a phase watches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    /// Tip `i`'s normal force vanishes.
    LiftOff(usize),
    /// Leg `i`'s stopper lets go.
    Unlock(usize),
    /// Leg `i` reaches its stopper.
    Stopper(usize),
    /// The fore tip lands (after a bounce).
    Landing,
    /// The swing tip reaches the ground ahead of the fore tip.
    Strike,
    /// The hip reaches the ground.
    Fall,
    /// The walker stops vaulting forward.
    RollBack,
}

/// The raw event functions of a phase at `(q, q')`, unguarded: `(event, value)`; the strike's is `None` where
/// the swing tip is not ahead of the fore tip.
fn event_values<W: Legged<N>, const N: usize>(
    walker: &W,
    modes: &Modes,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
) -> Vec<(Event, Option<f64>)> {
    let mut out = Vec::with_capacity(8);
    let solved: Option<Solved<N>> = solve(walker, (q, qd), modes).ok();
    let strokes = walker.strokes();
    let c = walker.constants_f64();
    let tip = |i| walker.contact(&c, q, qd, i).position;
    for (i, stroke) in strokes.iter().enumerate() {
        if modes.tips[i] != Tip::Free {
            let f = solved.as_ref().and_then(|s| s.forces.normal[i]);
            out.push((Event::LiftOff(i), f.map(|f| f + FORCE_EVENT_MARGIN)));
        }
        if modes.held[i] {
            let f = solved.as_ref().and_then(|s| s.forces.holding[i]);
            out.push((Event::Unlock(i), f.map(|f| f + FORCE_EVENT_MARGIN)));
        } else if let Some(s) = stroke {
            out.push((Event::Stopper(i), Some(s.stopper - q[s.coordinate])));
        }
    }
    if modes.tips[0] == Tip::Free {
        out.push((Event::Landing, Some(tip(0).y)));
    }
    if modes.tips[1] == Tip::Free {
        let (fore, swing) = (tip(0), tip(1));
        let ahead = swing.x - fore.x > MIN_STRIDE * walker.hip_height(q).abs();
        out.push((Event::Strike, ahead.then_some(swing.y)));
    }
    out.push((Event::Fall, Some(walker.hip_height(q))));
    out.push((Event::RollBack, Some(walker.progress(q, qd))));
    out
}

/// The most impulses one event applies: its impact, then a Zeno lock of each leg (the Zeno rule of
/// docs/model.md section 5).
pub const MOST_IMPULSES: usize = 3;

/// An event as the step's exact derivatives replay it (`super::derivative`): which event, and the impulses its
/// reset applied in order (the units that took each: the impact's, then the Zeno locks'), the legs exchanged
/// after the heel strike that ends the step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// The event.
    pub event: Event,
    /// The impulses, in order.
    pub impulses: [Option<Modes>; MOST_IMPULSES],
}

/// The record of a legged walker's step: the heel strike's impulse at its start (the units that took it), and
/// its phases with their accepted integrator steps and the events that ended them, on the walk's state
/// `(q, q', W)`.
#[derive(Debug, Clone, PartialEq)]
pub struct LeggedTape<const Y: usize> {
    /// The units that took the heel strike's impulse at the step's start.
    pub strike: Modes,
    /// The phases.
    pub phases: Tape<Modes, Crossing, Y>,
}

impl<const Y: usize> LeggedTape<Y> {
    /// An empty record.
    pub fn new() -> LeggedTape<Y> {
        LeggedTape {
            strike: Modes {
                tips: [Tip::Free; 2],
                held: [false; 2],
            },
            phases: Tape::new(Method::Dop853),
        }
    }
}

impl<const Y: usize> Default for LeggedTape<Y> {
    fn default() -> LeggedTape<Y> {
        LeggedTape::new()
    }
}

/// What a phase keeps between accepted steps.
struct Watch {
    /// The guards of the stoppers and of the landing, by event.
    guards: Vec<(Event, Guard)>,
    /// Whether the swing tip is below the ground (for the scuff count).
    below: bool,
}

impl Watch {
    /// The guards of a phase starting at `(q, q')`.
    fn new<W: Legged<N>, const N: usize>(
        walker: &W,
        modes: &Modes,
        state: (&SVector<f64, N>, &SVector<f64, N>),
        below: bool,
    ) -> Watch {
        let guards = event_values(walker, modes, state)
            .into_iter()
            .filter(|(e, _)| matches!(e, Event::Stopper(_) | Event::Landing))
            .filter_map(|(e, g)| g.map(|g| (e, Guard::new(g))))
            .collect();
        Watch { guards, below }
    }

    /// The guarded value of `event`'s raw value `g`.
    fn value(&self, event: Event, g: f64) -> f64 {
        self.guards
            .iter()
            .find(|(e, _)| *e == event)
            .map_or(g, |(_, guard)| guard.value(g))
    }
}

/// The earliest event in `step` (at its sample points `samples`), located: `(event, time)`.
fn earliest_event<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    modes: &Modes,
    watch: &Watch,
    step: &DenseStep<Y>,
    options: &LeggedOptions,
) -> Option<(Event, f64)> {
    let (t0, t1) = (step.t0(), step.t1());
    let value = |event: Event, t: f64| -> Option<f64> {
        let y = if t >= t1 { *step.y1() } else { step.eval(t) };
        let (q, qd) = unpack::<N, Y>(&y);
        event_values(walker, modes, (&q, &qd))
            .into_iter()
            .find(|(e, _)| *e == event)
            .and_then(|(_, g)| g)
            .map(|g| watch.value(event, g))
    };
    let times: Vec<f64> = (0..=EVENT_SAMPLES)
        .map(|k| t0 + (t1 - t0) * k as f64 / EVENT_SAMPLES as f64)
        .collect();
    let events: Vec<Event> = event_values(walker, modes, unpack_pair::<N, Y>(step.y0()).as_refs())
        .into_iter()
        .map(|(e, _)| e)
        .collect();
    for part in times.windows(2) {
        let mut first: Option<(Event, f64)> = None;
        for &event in &events {
            let (Some(ga), Some(gb)) = (value(event, part[0]), value(event, part[1])) else {
                continue;
            };
            if ga > 0.0 && gb <= 0.0 {
                let t = locate_root(
                    step,
                    |t, _| value(event, t).unwrap_or(gb),
                    part[0],
                    ga,
                    part[1],
                    gb,
                    options.event_time_tol,
                );
                if first.is_none_or(|(_, tf)| t < tf) {
                    first = Some((event, t));
                }
            }
        }
        if first.is_some() {
            return first;
        }
    }
    None
}

/// A state's `(q, q')` kept together.
struct Pair<const N: usize>(SVector<f64, N>, SVector<f64, N>);

impl<const N: usize> Pair<N> {
    /// Borrowed.
    fn as_refs(&self) -> (&SVector<f64, N>, &SVector<f64, N>) {
        (&self.0, &self.1)
    }
}

/// `(q, q')` of a state, kept together.
fn unpack_pair<const N: usize, const Y: usize>(y: &SVector<f64, Y>) -> Pair<N> {
    let (q, qd) = unpack::<N, Y>(y);
    Pair(q, qd)
}

impl StepAccount {
    /// Count `dt` of a phase with `modes`, ending at `(q, q')`.
    fn phase<W: Legged<N>, const N: usize>(
        &mut self,
        walker: &W,
        modes: &Modes,
        dt: f64,
        q: &SVector<f64, N>,
    ) {
        if modes.tips == [Tip::Stuck; 2] {
            self.dls_duration += dt;
        }
        if modes.tips[1] != Tip::Free {
            self.rear_contact_duration += dt;
        }
        let c = walker.constants_f64();
        for i in 0..2 {
            if modes.tips[i] != Tip::Free {
                let height = walker.contact(&c, q, &SVector::zeros(), i).position.y;
                self.penetration = self.penetration.max(-height);
            }
        }
    }
}

/// Is the swing tip (free) below the ground at `q`?
fn swing_below<W: Legged<N>, const N: usize>(
    walker: &W,
    modes: &Modes,
    q: &SVector<f64, N>,
) -> bool {
    let c = walker.constants_f64();
    modes.tips[1] == Tip::Free && walker.contact(&c, q, &SVector::zeros(), 1).position.y < 0.0
}

/// What watches a step's integration ([`legged_step_observed`]): each accepted integrator step with the time it
/// is taken to (its end, or the event that ends the phase within it).
pub type Observer<'a, const Y: usize> = &'a mut dyn FnMut(&DenseStep<Y>, f64);

/// Integrate the phase `modes` from `(t, y)` to its first event and handle it; `Ok(true)` at the heel strike
/// that ends the step (`t`, `y` there).
fn run_phase<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    (modes, t, y): (&mut Modes, &mut f64, &mut SVector<f64, Y>),
    (acc, tape): (&mut StepAccount, &mut Tape<Modes, Crossing, Y>),
    options: &LeggedOptions,
    observe: Observer<'_, Y>,
) -> Result<bool, LeggedError> {
    let system = Phase {
        walker,
        modes: *modes,
    };
    tape.begin(*modes, *t, *y);
    let mut integrator = Dop853::new(&system, *t, *y, options.tolerances);
    let start = unpack_pair::<N, Y>(y);
    let mut watch = Watch::new(
        walker,
        modes,
        start.as_refs(),
        swing_below(walker, modes, &start.0),
    );
    // The stop is asked at every phase's start (a phase is often shorter than STOP_CHECK_STEPS steps) and every
    // STOP_CHECK_STEPS steps within one.
    let mut taken = 0usize;
    loop {
        if taken.is_multiple_of(STOP_CHECK_STEPS) && options.stop.is_some_and(|stop| stop()) {
            return Err(LeggedError::Interrupted);
        }
        taken += 1;
        let step = integrator.step(&system, options.max_step_time)?;
        let (t0, t1) = (step.t0(), step.t1());
        tape.step(step.h(), t1);
        if let Some((event, te)) = earliest_event(walker, modes, &watch, &step, options) {
            observe(&step, te);
            *y = step.eval(te);
            *t = te;
            acc.phase(walker, modes, te - t0, &unpack::<N, Y>(y).0);
            let before = *y;
            let (ends, impulses) = handle_event(walker, event, (modes, *t, y), acc, options)?;
            tape.end(te, Crossing { event, impulses }, before);
            return Ok(ends);
        }
        observe(&step, t1);
        let end = unpack_pair::<N, Y>(step.y1());
        acc.phase(walker, modes, t1 - t0, &end.0);
        for (event, g) in event_values(walker, modes, end.as_refs()) {
            if let (Some(g), Some((_, guard))) =
                (g, watch.guards.iter_mut().find(|(e, _)| *e == event))
            {
                guard.update(g);
            }
        }
        let below = swing_below(walker, modes, &end.0);
        if watch.below && !below {
            acc.scuffs += 1;
        }
        watch.below = below;
        if walker.hip_height(&end.0) <= 0.0 {
            return Err(LeggedError::Fell { time: t1 });
        }
        if t1 >= options.max_step_time {
            return Err(LeggedError::Stalled { time: t1 });
        }
    }
}

/// The impulses an event's reset applied, in order ([`Crossing::impulses`]).
type Impulses = [Option<Modes>; MOST_IMPULSES];

/// Handle `event` at `(t, y)`: the next phase's modes (and the impact's velocities in `y`); `true` at the heel
/// strike; with the impulses applied.
fn handle_event<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    event: Event,
    (modes, t, y): (&mut Modes, f64, &mut SVector<f64, Y>),
    acc: &mut StepAccount,
    options: &LeggedOptions,
) -> Result<(bool, Impulses), LeggedError> {
    acc.events += 1;
    if acc.events > options.max_events {
        return Err(LeggedError::Chatter {
            events: options.max_events,
            time: t,
        });
    }
    let (q, qd) = unpack::<N, Y>(y);
    let mut impulses: Impulses = [None; MOST_IMPULSES];
    let closing = match event {
        Event::Strike => return Ok((true, impulses)),
        Event::Fall => return Err(LeggedError::Fell { time: t }),
        Event::RollBack => return Err(LeggedError::RolledBack { time: t }),
        Event::LiftOff(_) | Event::Unlock(_) => None,
        Event::Stopper(i) => Some(Closing::Stopper(i)),
        Event::Landing => Some(Closing::Tip(0)),
    };
    let (start, qd_plus) = match closing {
        None => (*modes, qd),
        Some(closing) => {
            let hit = impact(walker, (&q, &qd), modes, closing, t)?;
            match closing {
                Closing::Tip(_) => acc.losses.landings += hit.loss,
                _ => acc.losses.stoppers += hit.loss,
            }
            impulses[0] = Some(hit.took);
            (hit.took, hit.qd_plus)
        }
    };
    let (next, qd_plus, locks) = settle_zeno(walker, (&q, qd_plus), start, t, acc)?;
    for (slot, lock) in impulses.iter_mut().filter(|m| m.is_none()).zip(locks) {
        *slot = Some(lock);
    }
    *modes = next;
    *y = pack(&q, &qd_plus, y[2 * N]);
    Ok((false, impulses))
}

/// The phase after an impact, with the Zeno rule of docs/model.md section 5: a free leg at its stopper (within
/// [`GUARD_GAP`]) that moves inward at `v` with `v^2 < 2 a GUARD_GAP`, `a` its outward acceleration in the phase
/// that would follow, would come back within the guard: it is locked at once by a plastic stopper impact (each
/// leg at most once), the other units candidates; the kinetic energy taken is a stopper loss. With the units
/// that took each lock's impulse, in order.
fn settle_zeno<W: Legged<N>, const N: usize>(
    walker: &W,
    (q, mut qd): (&SVector<f64, N>, SVector<f64, N>),
    start: Modes,
    t: f64,
    acc: &mut StepAccount,
) -> Result<(Modes, SVector<f64, N>, Vec<Modes>), LeggedError> {
    let (mut modes, mut solved) = next_phase(walker, (q, &qd), &start, t)?;
    let strokes = walker.strokes();
    let mut locked = [false; 2];
    let mut locks = Vec::new();
    while let Some(i) = (0..2).find(|&i| {
        let Some(s) = strokes[i] else { return false };
        let (v, a) = (-qd[s.coordinate], solved.qdd[s.coordinate]);
        !modes.held[i]
            && !locked[i]
            && q[s.coordinate] >= s.stopper - GUARD_GAP
            && v >= 0.0
            && a > 0.0
            && v * v < 2.0 * a * GUARD_GAP
    }) {
        locked[i] = true;
        let hit = impact(walker, (q, &qd), &modes, Closing::Stopper(i), t)?;
        acc.losses.stoppers += hit.loss;
        qd = hit.qd_plus;
        locks.push(hit.took);
        (modes, solved) = next_phase(walker, (q, &qd), &hit.took, t)?;
    }
    Ok((modes, qd, locks))
}

/// The legs at their stoppers in `q`.
pub fn legs_held<W: Legged<N>, const N: usize>(walker: &W, q: &SVector<f64, N>) -> [bool; 2] {
    walker
        .strokes()
        .map(|s| s.is_some_and(|s| q[s.coordinate] >= s.stopper - super::forces::TOUCH_GAP))
}

/// One step of `walker` from `(q, q')` on the section (see the module documentation).
pub fn legged_step<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    state: (&SVector<f64, N>, &SVector<f64, N>),
    options: &LeggedOptions,
) -> Result<LeggedStep<N>, LeggedError> {
    legged_step_recorded::<W, N, Y>(
        walker,
        state,
        options,
        (&mut LeggedTape::new(), &mut |_, _| {}),
    )
}

/// [`legged_step`], recorded on `tape` for its exact derivatives (`super::derivative`).
pub fn legged_step_taped<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    state: (&SVector<f64, N>, &SVector<f64, N>),
    options: &LeggedOptions,
    tape: &mut LeggedTape<Y>,
) -> Result<LeggedStep<N>, LeggedError> {
    legged_step_recorded::<W, N, Y>(walker, state, options, (tape, &mut |_, _| {}))
}

/// [`legged_step`], each accepted integrator step passed to `observe` as it is taken (a drawing's samples are
/// taken on the walk's own steps).
pub fn legged_step_observed<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    state: (&SVector<f64, N>, &SVector<f64, N>),
    options: &LeggedOptions,
    observe: Observer<'_, Y>,
) -> Result<LeggedStep<N>, LeggedError> {
    legged_step_recorded::<W, N, Y>(walker, state, options, (&mut LeggedTape::new(), observe))
}

/// [`legged_step`], recorded on `tape`, each accepted integrator step passed to `observe`.
fn legged_step_recorded<W: Legged<N>, const N: usize, const Y: usize>(
    walker: &W,
    (q, qd): (&SVector<f64, N>, &SVector<f64, N>),
    options: &LeggedOptions,
    (tape, observe): (&mut LeggedTape<Y>, Observer<'_, Y>),
) -> Result<LeggedStep<N>, LeggedError> {
    let e0 = walker.energy(q, qd);
    let strike = heel_strike(walker, (q, qd), legs_held(walker, q), 0.0)?;
    let mut acc = StepAccount {
        lambda_i4: strike.lambda_i4,
        lambda_2_plus: strike.lambda_plus.map(|[fore, _]| fore),
        lambda_4_plus: strike.lambda_plus.map(|[_, rear]| rear),
        branch: strike.branch,
        losses: Losses {
            heel_strike: strike.impact.loss,
            ..Losses::default()
        },
        ..StepAccount::default()
    };
    let mut modes = strike.next.0;
    let mut y = pack::<N, Y>(q, &strike.impact.qd_plus, 0.0);
    let mut t = 0.0;
    *tape = LeggedTape {
        strike: strike.impact.took,
        phases: Tape::new(Method::Dop853),
    };
    while !run_phase(
        walker,
        (&mut modes, &mut t, &mut y),
        (&mut acc, &mut tape.phases),
        options,
        &mut *observe,
    )? {}
    let (q1, qd1) = unpack::<N, Y>(&y);
    if modes.tips[0] != Tip::Stuck {
        return Err(LeggedError::StanceNotStuck {
            state: modes.tips[0],
            time: t,
        });
    }
    if walker.strokes()[1].is_some() && !modes.held[1] {
        return Err(LeggedError::SwingLegNotLocked { time: t });
    }
    acc.damper_work = y[2 * N];
    let lost = acc.losses.heel_strike + acc.losses.stoppers + acc.losses.landings;
    acc.energy_residual = e0 - walker.energy(&q1, &qd1) - lost - acc.damper_work;
    let (q_next, qd_next) = walker.relabel(&q1, &qd1);
    Ok(LeggedStep {
        q: q_next,
        qd: qd_next,
        held: [modes.held[1], modes.held[0]],
        period: t,
        account: acc,
    })
}
