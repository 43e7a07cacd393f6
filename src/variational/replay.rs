//! The variational equations of each phase and the saltation matrix of each event, replayed over a walked step
//! ([`StepTape`]): docs/model.md section 10.
//!
//! **Phases.** The sensitivity `S = d(q, q')/d(s, p)` (10 rows: `q`, `q'` without the swinging leg's `L3`,
//! which no step of the map has; `D` columns: the three section coordinates, and the parameter's if one is
//! asked for) obeys `S' = F_y S + F_p`, with `F` the phase's vector field
//! `(q', q'')`, `q''` from the KKT system with the active set fixed. Both products come from one evaluation of
//! the KKT residual on dual numbers whose derivative parts are the rows of `S` (and the parameter's unit
//! direction), forward-mode automatic differentiation, and one solve with the KKT matrix (`kkt.rs`). The
//! augmented state `[y, S]` is integrated with the very steps the walk accepted (`Integrator::fixed_step`, the
//! same stages and dense output): internal numerical differentiation (Bock), so the state part reproduces the
//! walk bit for bit and its error control is the walk's, untouched; `S` is the exact derivative of that
//! discretization. At each stage the state's vector field, accelerations, multipliers and factored KKT matrix
//! are the walk's own, found in the step's log of its evaluations (`StageLog`) rather than computed again.
//!
//! **Events.** An event with guard `g(y, p) = 0`, reset `R` and vector fields `f-`, `f+` before and after moves
//! the time of the event by `dt = -(g_y S + g_p) / (g_y f-)`; the sensitivity after it is
//! `S+ = R_y (S- + f- dt) + R_p - f+ dt`, which for `p = 0` is the saltation matrix
//! `S+ = [R_y + (f+ - R_y f-) g_y^T / (g_y f-)] S-`. `g_y S` and `g_y f-` come from one evaluation of `g` on
//! duals carrying `S` and `f-` (`Dual<D + 1>`): so the force guards (a normal force, a stopper reaction
//! or a compression stop's reaching zero, from the KKT solution) are differentiated through the KKT solve
//! like the rest. `R` is the identity for a change of active set (lift-off, unlock, slide, and with Coulomb
//! friction a slip's start at the edge of the cone and its stop, whose guard is the tip's velocity along the
//! slope) and the collision equation (5) with the recorded units for an impact (touchdown, landing, stopper or
//! compression-stop hit, Zeno locks; a slipping contact's impulse is its Coulomb impulse `-s mu Lambda_n`),
//! differentiated in duals. Where the stance tip slips at the section, its slip velocity is a fourth
//! direction of `S`, and the next section's slip (Leg 2's tip velocity after re-indexing) a fourth row.

use std::cell::Cell;

use nalgebra::{SMatrix, SVector};

use crate::contact::{cone_distance, impulse, ActiveSet, Role, NROWS};
use crate::dynamics::{
    swinging, Coords, CoordsOf, LegIndex, Mechanics, Model, Real, L1, NQ, THETA,
};
use crate::integrate::{Integrator, OdeSystem};
use crate::params::SolverOptions;
use crate::walk::impact::touchdown_leg;
use crate::walk::tape::{Segment, StepTape};
use crate::walk::{unpack, EventKind, PhaseSystem, StageLog, WalkVector};

use super::dual::{dual, eps, seeded, Dual};
use super::kkt::{dynamics_derivative, impulse_derivative};
use super::{NotDifferentiable, BORDER_TOL};

/// The coordinates a sensitivity covers: all but the swinging leg's `L3` (a step of the step map has no
/// swinging leg: [`replay_step`] refuses one), so that the replay costs what it did before `L3` existed.
pub(crate) const NC: usize = NQ - 1;
/// Rows of a sensitivity: `q` and `q'` without `L3`, `dL3/dt` (the velocities from row [`NC`]).
pub(crate) const NS: usize = 2 * NC;
/// `d(q, q')/d(L2, dtheta/dt, dL2/dt)` (`D = 3` directions), with the slip velocity's column where the stance
/// tip slips at the section (Coulomb friction), and the parameter's column last where one is asked for (`D` up
/// to 5): without a parameter the replay carries a direction less, a fifth less work per stage.
pub(crate) type Sensitivity<const D: usize> = SMatrix<f64, NS, D>;

/// Size of the walk's state `[q, q', E_damper]`.
const NY: usize = 2 * NQ + 1;
/// Size of the augmented state `[y, S]` (`S` column by column) with `D` directions: the third const
/// parameter `A` of the replay's functions, which must equal it (checked at compile time, since a const
/// generic cannot be computed from another on stable Rust).
pub(crate) const fn augmented(d: usize) -> usize {
    NY + NS * d
}
type Augmented<const A: usize> = SVector<f64, A>;

/// A grazing event: the guard's rate along the flow `g_y f-` is at most this times its largest derivative
/// `|g_y S + g_p|` (the event time would move by more than `1 / GRAZING_RATE` seconds per unit of the section
/// state or parameter): the flow touches the guard tangentially and the event time is not a smooth function.
pub const GRAZING_RATE: f64 = 1e-7;

/// Two events less than this apart \[s\] are taken as coincident (e.g. a lift-off at a stopper lock): the
/// step map has a corner there and no derivative.
pub const COINCIDENT_EVENTS: f64 = 1e-9;

/// The index in the walk's state `y` of coordinate `i` of `q` (`velocity = false`) or `q'`, and its row in a
/// sensitivity (`None` for `L3`, `dL3/dt`, whose derivatives are 0).
fn rows_of(i: usize, velocity: bool) -> (usize, Option<usize>) {
    let row = (i < NC).then_some(if velocity { NC + i } else { i });
    (if velocity { NQ + i } else { i }, row)
}

/// `(q, q')` as duals: real parts from `y`, derivative parts from the rows of `s`.
fn duals<const D: usize>(
    y: &WalkVector,
    s: &Sensitivity<D>,
) -> (CoordsOf<Dual<D>>, CoordsOf<Dual<D>>) {
    let at = |i: usize, velocity: bool| {
        let (k, row) = rows_of(i, velocity);
        dual(y[k], row.map_or(SVector::zeros(), |r| s.row(r).transpose()))
    };
    (
        CoordsOf::from_fn(|i, _| at(i, false)),
        CoordsOf::from_fn(|i, _| at(i, true)),
    )
}

/// `(q, q')` as duals whose first `D` directions are the rows of `s` and whose last one (`E = D + 1`) is the
/// rate `f`.
fn with_rate<const D: usize, const E: usize>(
    y: &WalkVector,
    s: &Sensitivity<D>,
    f: &WalkVector,
) -> (CoordsOf<Dual<E>>, CoordsOf<Dual<E>>) {
    const { assert!(E == D + 1) };
    let at = |i: usize, velocity: bool| {
        let (k, row) = rows_of(i, velocity);
        let mut e = SVector::<f64, E>::zeros();
        if let Some(r) = row {
            e.fixed_rows_mut::<D>(0).copy_from(&s.row(r).transpose());
        }
        e[D] = f[k];
        dual(y[k], e)
    };
    (
        CoordsOf::from_fn(|i, _| at(i, false)),
        CoordsOf::from_fn(|i, _| at(i, true)),
    )
}

/// The sensitivity carried by duals `(q, q')`.
pub(crate) fn sensitivity<const D: usize>(
    q: &CoordsOf<Dual<D>>,
    qd: &CoordsOf<Dual<D>>,
) -> Sensitivity<D> {
    Sensitivity::from_fn(|i, c| {
        let x = if i < NC { &q[i] } else { &qd[i - NC] };
        eps(x)[c]
    })
}

/// The derivative of the velocity of Leg 2's tip along the slope (a section state's `slip`) at `(q, q')` with
/// sensitivity `s`, the constants `mech` carrying the parameter's direction.
pub(crate) fn slip_derivative<const D: usize>(
    model: &Model,
    mech: &Mechanics<Dual<D>>,
    (q, qd): (&Coords, &Coords),
    s: &Sensitivity<D>,
) -> SVector<f64, D> {
    let (q, qd) = duals(&crate::walk::pack(q, qd, 0.0), s);
    eps(&model
        .tip_with(mech, &q, &qd, Role::Rear.index())
        .velocity(&qd)
        .x)
}

/// The phase's vector field with its variational equation, on the augmented state `[y, S]`.
struct Variational<'a, const D: usize, const A: usize> {
    model: &'a Model,
    mech: &'a Mechanics<Dual<D>>,
    active: ActiveSet,
    /// The walk's evaluations of the vector field, and how far the replay has come through them.
    log: (Option<&'a StageLog>, &'a Cell<usize>),
}

impl<const D: usize, const A: usize> Variational<'_, D, A> {
    fn split(a: &Augmented<A>) -> (WalkVector, Sensitivity<D>) {
        const { assert!(A == augmented(D)) };
        let y = a.fixed_rows::<NY>(0).into_owned();
        let s = Sensitivity::<D>::from_column_slice(&a.as_slice()[NY..]);
        (y, s)
    }

    fn join(y: &WalkVector, s: &Sensitivity<D>) -> Augmented<A> {
        const { assert!(A == augmented(D)) };
        let mut a = Augmented::<A>::zeros();
        a.fixed_rows_mut::<NY>(0).copy_from(y);
        a.as_mut_slice()[NY..].copy_from_slice(s.as_slice());
        a
    }
}

impl<const D: usize, const A: usize> OdeSystem<A> for Variational<'_, D, A> {
    fn rhs(&self, _t: f64, a: &Augmented<A>) -> Augmented<A> {
        let (y, s) = Self::split(a);
        // The state's derivative as the walk computed it at this very state (from its log, else by the walk's
        // own code), so the state part is the walk's bit for bit.
        let (log, cursor) = self.log;
        let logged = log.and_then(|log| log.find(cursor, &self.active, &y));
        let computed;
        let (fy, dynamics, solved) = match &logged {
            Some(stage) => (stage.f, stage.dynamics, &stage.solved),
            None => {
                let phase = PhaseSystem::at(self.model, self.active, &y);
                computed = phase.rhs_dynamics_solved(&y);
                (computed.0, computed.1, &computed.2)
            }
        };
        let (q, qd) = duals(&y, &s);
        let derivative = dynamics.and_then(|d| {
            let duals = (q, qd, *self.mech);
            let solution = (&d.qdd, &d.multipliers);
            dynamics_derivative(self.model, &duals, (solved, &self.active), solution)
        });
        let Some((dqdd, _)) = derivative else {
            return Augmented::<A>::repeat(f64::NAN);
        };
        let mut ds = Sensitivity::<D>::zeros();
        ds.fixed_rows_mut::<NC>(0)
            .copy_from(&s.fixed_rows::<NC>(NC));
        ds.fixed_rows_mut::<NC>(NC)
            .copy_from(&dqdd.fixed_rows::<NC>(0));
        Self::join(&fy, &ds)
    }
}

/// The impacts `sets` applied in order at `q` to `q'` with sensitivity rows `s` (the collision equation (5)
/// with the recorded units, differentiated): the velocity after them and the sensitivity.
fn apply_impacts<const D: usize>(
    model: &Model,
    mech: &Mechanics<Dual<D>>,
    y: &WalkVector,
    s: &Sensitivity<D>,
    sets: &[ActiveSet],
    time: f64,
) -> Result<(Coords, Sensitivity<D>), NotDifferentiable> {
    let (q, mut qd) = crate::walk::unpack(y);
    let mut s = *s;
    for set in sets {
        let singular = NotDifferentiable::Singular { time };
        let sol = impulse(model, &q, &qd, set).map_err(|_| singular.clone())?;
        impulse_border(model, (&q, &sol.qd_plus), set, &sol.impulses, time)?;
        let (q_d, qd_d) = duals(&crate::walk::pack(&q, &qd, 0.0), &s);
        let dqd_plus = impulse_derivative(
            model,
            &(q_d, qd_d, *mech),
            set,
            (&(sol.qd_plus - qd), &sol.impulses),
        )
        .ok_or(singular)?;
        s.fixed_rows_mut::<NC>(NC)
            .copy_from(&dqd_plus.fixed_rows::<NC>(0));
        qd = sol.qd_plus;
    }
    Ok((qd, s))
}

/// With Coulomb friction, is an impulse of `set` (`impulses`, the velocity after it `q'+`) on the border between
/// sticking and slipping: a sticking contact's impulse within [`BORDER_TOL`] of the edge of its cone, or a
/// slipping tip's velocity after the impact within it of 0? There the impact law switches, and the step map
/// has no derivative ([`NotDifferentiable::ImpulseBorder`]).
fn impulse_border(
    model: &Model,
    (q, qd_plus): (&Coords, &Coords),
    set: &ActiveSet,
    impulses: &SVector<f64, NROWS>,
    time: f64,
) -> Result<(), NotDifferentiable> {
    let mu = model.params().friction;
    if !model.params().has_friction() {
        return Ok(());
    }
    for leg in Role::BOTH.into_iter().filter(|&leg| set.contact(leg)) {
        let (what, value) = if set.slip(leg) != 0 {
            let v = model.tip(q, qd_plus, leg.index()).velocity(qd_plus).x;
            ("slip_after", f64::from(set.slip(leg)) * v)
        } else if !set.slide(leg) {
            let (t, n) = (impulses[leg.tangential_row()], impulses[leg.normal_row()]);
            ("cone_distance", cone_distance(mu, t, n))
        } else {
            continue;
        };
        if value.abs() < BORDER_TOL {
            return Err(NotDifferentiable::ImpulseBorder { time, what, value });
        }
    }
    Ok(())
}

/// The derivatives of one step: the sensitivity of the state after the re-indexing at the next touchdown (the
/// next section).
pub(crate) struct StepDerivative<const D: usize> {
    /// `d(q, q')/d(s, p)` just after re-indexing.
    pub(crate) sensitivity: Sensitivity<D>,
}

/// Replays `tape`, a step walked from the state `(q, q')` (at the section, before the touchdown impact) with
/// sensitivity `s0`: the sensitivity after the re-indexing at the next touchdown. `opts` are the walk's. `D`
/// directions (the parameter `param`'s, if any, the last), `E = D + 1` (the guard's rate rides along) and
/// `A =` [`augmented`]`(D)`.
pub(crate) fn replay_step<const D: usize, const E: usize, const A: usize>(
    model: &Model,
    opts: &SolverOptions,
    param: Option<&str>,
    (q0, qd0): (&CoordsOf<f64>, &CoordsOf<f64>),
    s0: &Sensitivity<D>,
    tape: &StepTape,
) -> Result<StepDerivative<D>, NotDifferentiable> {
    let mech = seeded::<D>(model, param, D - 1);
    let mech5 = seeded::<E>(model, param, D - 1);
    // The touchdown impact at the section: the recorded collision, then any Zeno locks (no time shift: the
    // section is the touchdown instant).
    let (Some(first), Some(t0)) = (tape.segments.first(), tape.segments.first().map(|s| s.t0))
    else {
        return Err(NotDifferentiable::Incomplete);
    };
    let y_section = crate::walk::pack(q0, qd0, 0.0);
    let (_, mut s) = apply_impacts(model, &mech, &y_section, s0, &tape.impacts, t0)?;
    let mut y0 = first.y0;
    let mut last_event: Option<f64> = None;
    let log = (tape.stages.as_ref(), &Cell::new(0));
    for (k, segment) in tape.segments.iter().enumerate() {
        if swinging(&unpack(&segment.y0).0) {
            return Err(NotDifferentiable::Swinging { time: segment.t0 });
        }
        let (y_minus, s_minus) =
            integrate_segment::<D, A>((model, opts, &mech), segment, (&y0, &s), log)?;
        let end = segment.end.as_ref().ok_or(NotDifferentiable::Incomplete)?;
        if last_event.is_some_and(|t| (end.time - t).abs() < COINCIDENT_EVENTS) {
            return Err(NotDifferentiable::CoincidentEvents { time: end.time });
        }
        last_event = Some(end.time);
        let (s_event, dt) = cross_guard(model, &mech5, segment, &y_minus, &s_minus)?;
        if end.kind == EventKind::Touchdown {
            let (q, qd) = duals(&y_minus, &s_event);
            let (q, qd) = reindex_duals(model, &mech, &q, &qd);
            return Ok(StepDerivative {
                sensitivity: sensitivity(&q, &qd),
            });
        }
        let next = tape
            .segments
            .get(k + 1)
            .ok_or(NotDifferentiable::Incomplete)?;
        // The reset: the recorded impacts, differentiated.
        let (_, s_reset) = apply_impacts(model, &mech, &y_minus, &s_event, &end.impacts, end.time)?;
        let f_plus = PhaseSystem::at(model, next.active, &next.y0).rhs(end.time, &next.y0);
        s = s_reset - rate_outer(&f_plus, &dt);
        y0 = next.y0;
    }
    Err(NotDifferentiable::Incomplete)
}

/// `f dt^T` over the rows `(q, q')` of the state's rate `f`.
fn rate_outer<const D: usize>(f: &WalkVector, dt: &SVector<f64, D>) -> Sensitivity<D> {
    Sensitivity::from_fn(|i, c| {
        let k = if i < NC { i } else { NQ + i - NC };
        f[k] * dt[c]
    })
}

/// Integrate the variational equations over the recorded steps of `segment` from `(y0, s0)`: the state and
/// sensitivity at the event that ends it.
fn integrate_segment<'a, const D: usize, const A: usize>(
    (model, opts, mech): (&'a Model, &SolverOptions, &'a Mechanics<Dual<D>>),
    segment: &Segment,
    (y0, s0): (&WalkVector, &Sensitivity<D>),
    log: (Option<&'a StageLog>, &'a Cell<usize>),
) -> Result<(WalkVector, Sensitivity<D>), NotDifferentiable> {
    let sys = Variational::<D, A> {
        model,
        mech,
        active: segment.active,
        log,
    };
    let end = segment.end.as_ref().ok_or(NotDifferentiable::Incomplete)?;
    let mut t = segment.t0;
    let mut a = Variational::<D, A>::join(y0, s0);
    let mut f = sys.rhs(t, &a);
    let mut at_event = None;
    for &(h, t1) in &segment.steps {
        let last = end.time <= t1;
        let step = Integrator::fixed_step(opts.integrator, &sys, (t, &a, &f), (h, t1), last);
        if let Some(dense) = step.dense {
            at_event = Some(dense.eval(end.time));
            break;
        }
        (a, f, t) = (step.y1, step.f1, t1);
    }
    let (y, s) = Variational::<D, A>::split(&at_event.ok_or(NotDifferentiable::Incomplete)?);
    // The replay takes the walk's steps with the walk's arithmetic: its state is the walk's, bit for bit.
    if y != end.y || !s.iter().all(|v| v.is_finite()) {
        return Err(NotDifferentiable::Diverged { time: end.time });
    }
    Ok((y, s))
}

/// The event that ends `segment`, crossed: its time's derivative `dt = -(g_y S + g_p) / (g_y f-)` and the
/// sensitivity at the event `S- + f- dt` (before its reset).
fn cross_guard<const D: usize, const E: usize>(
    model: &Model,
    mech: &Mechanics<Dual<E>>,
    segment: &Segment,
    y: &WalkVector,
    s: &Sensitivity<D>,
) -> Result<(Sensitivity<D>, SVector<f64, D>), NotDifferentiable> {
    let end = segment.end.as_ref().ok_or(NotDifferentiable::Incomplete)?;
    let (f, dynamics, solved) = PhaseSystem::at(model, segment.active, y).rhs_dynamics_solved(y);
    let (q, qd) = with_rate(y, s, &f);
    let touching = touchdown_leg(model, &y.fixed_rows::<NQ>(0).into_owned());
    let singular = NotDifferentiable::Singular { time: end.time };
    // The multipliers as duals, for a force guard: their derivatives through the KKT solve.
    let forces = || -> Result<[Dual<E>; NROWS], NotDifferentiable> {
        let d = dynamics.as_ref().ok_or(singular.clone())?;
        let duals = (q, qd, *mech);
        let (_, dlam) = dynamics_derivative(
            model,
            &duals,
            (&solved, &segment.active),
            (&d.qdd, &d.multipliers),
        )
        .ok_or(singular.clone())?;
        Ok(std::array::from_fn(|row| {
            dual(d.multipliers[row], dlam.row(row).transpose())
        }))
    };
    let guard = match end.kind {
        EventKind::LiftOff(_) | EventKind::Unlock(_) | EventKind::CompressionUnlock(_) => {
            // The guard is the unit's reaction in its admissible direction: `lambda` for a contact, `-mu` for a
            // stopper, `mu` for a compression stop.
            let (row, sign) = match (end.kind, end.kind.stop_unlock()) {
                (EventKind::LiftOff(leg), _) => (leg.normal_row(), 1.0),
                (_, Some((leg, stop))) => (leg.stopper_row(), -stop.sign()),
                _ => unreachable!("a force guard"),
            };
            Dual::<E>::lit(sign) * forces()?[row]
        }
        EventKind::ConeLimit(leg) => {
            // With Coulomb friction: `mu lambda_n - |lambda_t|`, the sticking tip's force reaching the edge of
            // the cone (the walk's event function divided by `sqrt(1 + mu^2)`, which moves neither its zero nor,
            // there, the zero's derivatives). The sticking force there is the slipping one, so `f+ = f-` and the
            // saltation is the identity whatever `dt` (as at a lift-off): the guard's derivative serves the
            // grazing check.
            let lam = forces()?;
            let (t, n) = (lam[leg.tangential_row()], lam[leg.normal_row()]);
            mech.friction * n - Dual::<E>::lit(t.re.signum()) * t
        }
        EventKind::SlipStop(leg) => {
            // The slipping tip comes to rest: its velocity along the slope, signed by the slip.
            let slip = Dual::<E>::lit(f64::from(segment.active.slip(leg)));
            slip * model.tip_with(mech, &q, &qd, leg.index()).velocity(&qd).x
        }
        kind => guard(model, mech, (kind, touching), &q).ok_or(singular)?,
    };
    let d = eps(&guard);
    let rate = d[D];
    let grazing = rate.abs() <= GRAZING_RATE * d.fixed_rows::<D>(0).amax();
    if grazing || !rate.is_finite() || rate == 0.0 {
        return Err(NotDifferentiable::Grazing {
            time: end.time,
            event: format!("{:?}", end.kind),
        });
    }
    let dt: SVector<f64, D> = -d.fixed_rows::<D>(0) / rate;
    Ok((s + rate_outer(&f, &dt), dt))
}

/// The guard of a kinematic event at `q` over any [`Real`]: the function whose zero is the event (the unshifted
/// event function of `crate::walk`'s event table; its guards' numerical offsets are constants). Force guards
/// are differentiated through the KKT solve in [`cross_guard`].
fn guard<T: Real>(
    model: &Model,
    mech: &Mechanics<T>,
    (kind, touching): (EventKind, LegIndex),
    q: &CoordsOf<T>,
) -> Option<T> {
    match kind {
        EventKind::Touchdown => Some(model.tip_height_with(mech, q, touching)),
        EventKind::Landing(leg) => Some(model.tip_height_with(mech, q, leg.index())),
        EventKind::StopperHit(leg) => Some(mech.stopper_length - q[Model::stroke_coordinate(leg)]),
        // `min_length` is not a differentiable key: a constant here.
        EventKind::CompressionHit(leg) => {
            Some(q[Model::stroke_coordinate(leg)] - T::lit(model.params().min_length))
        }
        EventKind::LiftOff(_)
        | EventKind::Unlock(_)
        | EventKind::CompressionUnlock(_)
        | EventKind::Fall
        | EventKind::RollBack
        // Not in a step without a swinging leg (refused in `step_derivative`).
        | EventKind::SwingLock
        | EventKind::SwingLanding
        // Crossed in `cross_guard`: a force guard and a velocity guard.
        | EventKind::ConeLimit(_)
        | EventKind::SlipStop(_) => None,
    }
}

/// Re-indexing at touchdown in duals (as `crate::walk`'s `reindex`): the touching leg becomes Leg 1 (at the
/// touchdown length), the old Leg 1 Leg 2 (or, after a long flight, a spoke at the touchdown length), the
/// origin moves to the new tip.
fn reindex_duals<const D: usize>(
    model: &Model,
    mech: &Mechanics<Dual<D>>,
    q: &CoordsOf<Dual<D>>,
    qd: &CoordsOf<Dual<D>>,
) -> (CoordsOf<Dual<D>>, CoordsOf<Dual<D>>) {
    let real_q = q.map(|x| x.re);
    let touching = touchdown_leg(model, &real_q);
    let shift = model.legs() - touching;
    let front = model.tip_with(mech, q, qd, touching);
    let v = front.velocity(qd);
    let l0 = mech.spoke_length;
    let zero = Dual::<D>::lit(0.0);
    let (l2, l2_dot) = if shift == 1 {
        (q[L1], qd[L1])
    } else {
        (l0, zero)
    };
    let alpha = model.alpha();
    let theta = if shift == 1 {
        q[THETA] - Dual::<D>::lit(alpha)
    } else {
        let psi = q[THETA] + Dual::<D>::lit(touching as f64 * alpha);
        let turns = (psi.re / std::f64::consts::TAU).round();
        psi - Dual::<D>::lit(std::f64::consts::TAU * turns)
    };
    let q_new = CoordsOf::<Dual<D>>::new(zero, front.position.y, theta, l0, l2, zero);
    let qd_new = CoordsOf::<Dual<D>>::new(v.x, v.y, qd[THETA], zero, l2_dot, zero);
    (q_new, qd_new)
}
