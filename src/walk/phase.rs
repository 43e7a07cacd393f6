//! The phase ODE (docs/model.md section 4): the integrated state `[q, q', E_damper]` ([`WalkVector`]), its
//! packing, the vector field of one phase of constrained motion ([`PhaseSystem`]), the wheel's state between
//! events ([`WalkState`]), and the log of a taped step's evaluations of the field that the exact derivatives
//! replay ([`StageLog`]).

use std::cell::{Cell, Ref, RefCell};

use nalgebra::SVector;

use crate::contact::{
    constrained_dynamics, constrained_dynamics_solved, solve_into, ActiveSet, ConstrainedDynamics,
    ContactError, Solved,
};
use crate::dynamics::{swinging, Coords, Model, L3, NQ};
use crate::integrate::OdeSystem;
use crate::mechanism::Mechanism;

/// Size of the integrated state `[q, q', E_damper]`.
pub(crate) const NY: usize = 2 * NQ + 1;
/// The integrated state: coordinates, velocities and the energy dissipated by the dampers so far in the step.
pub type WalkVector = SVector<f64, NY>;

pub(crate) fn pack(q: &Coords, qd: &Coords, dissipated: f64) -> WalkVector {
    let mut y = WalkVector::zeros();
    y.fixed_rows_mut::<NQ>(0).copy_from(q);
    y.fixed_rows_mut::<NQ>(NQ).copy_from(qd);
    y[2 * NQ] = dissipated;
    y
}

pub(crate) fn unpack(y: &WalkVector) -> (Coords, Coords) {
    (
        y.fixed_rows::<NQ>(0).into_owned(),
        y.fixed_rows::<NQ>(NQ).into_owned(),
    )
}

/// The vector field of one phase: Eq. (1) with the constraints of `active`, plus the damper power
/// `c (dL1^2 + dL2^2 + dL3^2)` as a quadrature (`dL3/dt = 0` when no leg swings).
#[derive(Debug, Clone, Copy)]
pub struct PhaseSystem<'a> {
    /// The model.
    pub model: &'a Model,
    /// Active contacts and stoppers.
    pub active: ActiveSet,
    /// Does a leg swing ([`L3`](crate::dynamics::L3) a coordinate) in this phase? (It swings, or not, through
    /// the whole phase: its stopper's lock is an event.)
    pub swing: bool,
    /// Where the evaluations go for the replay of a taped step ([`PhaseSystem::logging`]).
    log: Option<&'a StageLog>,
}

impl<'a> PhaseSystem<'a> {
    /// The phase that starts at `y` with `active`.
    pub fn at(model: &'a Model, active: ActiveSet, y: &WalkVector) -> PhaseSystem<'a> {
        PhaseSystem {
            model,
            active,
            swing: swinging(&unpack(y).0),
            log: None,
        }
    }

    /// This phase, keeping each evaluation of its vector field in `log` (none if `None`).
    pub(crate) fn logging(self, log: Option<&'a StageLog>) -> PhaseSystem<'a> {
        PhaseSystem { log, ..self }
    }

    /// The vector field at `y` and the constrained dynamics it came from (`None` where the KKT system is
    /// singular; the field is then `NaN`).
    pub(crate) fn rhs_and_dynamics(
        &self,
        y: &WalkVector,
    ) -> (WalkVector, Option<ConstrainedDynamics>) {
        let (q, qd) = unpack(y);
        self.field(
            (&q, &qd),
            constrained_dynamics(self.model, &q, &qd, &self.active),
        )
    }

    /// [`PhaseSystem::rhs_and_dynamics`] with what the solve computed on the way (the same numbers; the
    /// derivatives of the dynamics solve the same KKT system again).
    pub(crate) fn rhs_dynamics_solved(
        &self,
        y: &WalkVector,
    ) -> (WalkVector, Option<ConstrainedDynamics>, Solved) {
        let (q, qd) = unpack(y);
        let (dynamics, solved) = constrained_dynamics_solved(self.model, &q, &qd, &self.active);
        let (f, dynamics) = self.field((&q, &qd), dynamics);
        (f, dynamics, solved)
    }

    /// The vector field from the constrained dynamics at `(q, q')`, with the dampers' power
    /// ([`Mechanism::damper_power`]).
    pub(crate) fn field(
        &self,
        (q, qd): (&Coords, &Coords),
        dynamics: Result<ConstrainedDynamics, ContactError>,
    ) -> (WalkVector, Option<ConstrainedDynamics>) {
        match dynamics {
            Ok(d) => {
                let f = pack(qd, &d.qdd, self.model.damper_power(q, qd));
                (f, Some(d))
            }
            // The integrator reports a non-finite derivative as an error with its time.
            Err(_) => (WalkVector::repeat(f64::NAN), None),
        }
    }
}

impl OdeSystem<NY> for PhaseSystem<'_> {
    fn rhs(&self, _t: f64, y: &WalkVector) -> WalkVector {
        match self.log {
            Some(log) => log.evaluate(self, y),
            None => self.rhs_and_dynamics(y).0,
        }
    }

    /// `L3` and `dL3/dt` when no leg swings (both stay 0).
    fn unmeasured(&self) -> &[usize] {
        if self.swing {
            &[]
        } else {
            &[L3, NQ + L3]
        }
    }
}

/// The wheel between events, in the frame of its current Leg 1.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkState {
    /// Time \[s\].
    pub time: f64,
    /// `q` (with `x` relative to `x_origin`).
    pub q: Coords,
    /// `q'`.
    pub qd: Coords,
    /// Active contacts and stoppers (before the touchdown impact, when at the section).
    pub active: ActiveSet,
    /// Position along the slope of this frame's origin (the touchdown point of Leg 1) \[m\].
    pub x_origin: f64,
    /// Which physical leg (0..N) is Leg 1.
    pub leg1: usize,
}

/// One evaluation of a phase's vector field by the walk, with what its solve computed on the way.
#[derive(Debug)]
pub(crate) struct Stage {
    /// The active set of the phase.
    pub(crate) active: ActiveSet,
    /// The state.
    pub(crate) y: WalkVector,
    /// The vector field there.
    pub(crate) f: WalkVector,
    /// The accelerations and multipliers (`None` where the KKT system is singular).
    pub(crate) dynamics: Option<ConstrainedDynamics>,
    /// The equations of motion and the factored KKT system.
    pub(crate) solved: Solved,
}

/// The walk's evaluations of the vector field during a taped step, in order, rejected integrator steps and the
/// dense output's stages included: the replay integrates the state with the very stages the walk accepted, so
/// it finds each of its states here instead of solving the constrained dynamics there again (about a fifth of a
/// replay's work). A replay state not found (or past the log's [`MAX_STAGES`]) is computed.
#[derive(Debug, Default)]
pub(crate) struct StageLog {
    stages: RefCell<Vec<Stage>>,
    /// States the replay found here, and states it did not.
    found: Cell<usize>,
    missed: Cell<usize>,
}

/// The most evaluations a log keeps (about 1.5 kB each, 6 MB in all): a step of a few seconds takes about a
/// thousand, one of 10 s about four; of a longer step (near a family's end, up to a minute) the replay computes
/// the rest. (With 10 000, the default map's peak memory was 54 MB instead of 38 MB, 25 MB without a log.)
const MAX_STAGES: usize = 4_000;

/// The evaluations a log has room for from the start.
const STAGES_RESERVED: usize = 1024;

/// How far past the replay's last match a log looks for its next state: the rejected trial steps and dense
/// stages the replay does not take lie in between.
const LOOKAHEAD: usize = 256;

impl StageLog {
    /// An empty log with room for a step of a few seconds, so that it is not moved as it grows.
    pub(super) fn reserved() -> StageLog {
        StageLog {
            stages: RefCell::new(Vec::with_capacity(STAGES_RESERVED)),
            ..StageLog::default()
        }
    }

    /// The vector field of `phase` at `y`, as [`PhaseSystem::rhs_and_dynamics`] gives it, the evaluation kept
    /// (written in place, so that its kilobyte and a half is not moved around).
    pub(crate) fn evaluate(&self, phase: &PhaseSystem, y: &WalkVector) -> WalkVector {
        let mut stages = self.stages.borrow_mut();
        if stages.len() >= MAX_STAGES {
            return phase.rhs_and_dynamics(y).0;
        }
        let (q, qd) = unpack(y);
        let stage = stages.push_mut(Stage {
            active: phase.active,
            y: *y,
            f: WalkVector::zeros(),
            dynamics: None,
            solved: Solved {
                eom: phase.model.equations_of_motion(&q, &qd),
                kkt: None,
            },
        });
        let dynamics = solve_into(phase.model, (&q, &qd), &phase.active, &mut stage.solved);
        (stage.f, stage.dynamics) = phase.field((&q, &qd), dynamics);
        stage.f
    }

    /// The first evaluation at or after `cursor` (within [`LOOKAHEAD`]) of the state `y` (bit for bit) with
    /// `active`; the cursor moves past it.
    pub(crate) fn find(
        &self,
        cursor: &Cell<usize>,
        active: &ActiveSet,
        y: &WalkVector,
    ) -> Option<Ref<'_, Stage>> {
        let stages = self.stages.borrow();
        let from = cursor.get();
        let same = |s: &Stage| {
            s.active == *active
                && s.y
                    .iter()
                    .zip(y.iter())
                    .all(|(a, b)| a.to_bits() == b.to_bits())
        };
        let Some(at) = stages.iter().skip(from).take(LOOKAHEAD).position(same) else {
            self.missed.set(self.missed.get() + 1);
            return None;
        };
        self.found.set(self.found.get() + 1);
        cursor.set(from + at + 1);
        Some(Ref::map(stages, |s| &s[from + at]))
    }

    /// How many states the replay found here, and how many it did not.
    #[cfg(test)]
    pub(crate) fn lookups(&self) -> (usize, usize) {
        (self.found.get(), self.missed.get())
    }
}
