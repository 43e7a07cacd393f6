//! The phase ODE (docs/model.md section 4): the integrated state `[q, q', E_damper]` ([`WalkVector`]), its
//! packing, the vector field of one phase of constrained motion ([`PhaseSystem`]), and the wheel's state
//! between events ([`WalkState`]).

use nalgebra::SVector;

use crate::contact::{
    constrained_dynamics, constrained_dynamics_solved, ActiveSet, ConstrainedDynamics,
    ContactError, Solved,
};
use crate::dynamics::{swinging, Coords, Model, L1, L2, L3, NQ};
use crate::integrate::OdeSystem;

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
}

impl<'a> PhaseSystem<'a> {
    /// The phase that starts at `y` with `active`.
    pub fn at(model: &'a Model, active: ActiveSet, y: &WalkVector) -> PhaseSystem<'a> {
        PhaseSystem {
            model,
            active,
            swing: swinging(&unpack(y).0),
        }
    }

    /// The vector field at `y` and the constrained dynamics it came from (`None` where the KKT system is
    /// singular; the field is then `NaN`).
    pub(crate) fn rhs_and_dynamics(
        &self,
        y: &WalkVector,
    ) -> (WalkVector, Option<ConstrainedDynamics>) {
        let (q, qd) = unpack(y);
        self.field(&qd, constrained_dynamics(self.model, &q, &qd, &self.active))
    }

    /// [`PhaseSystem::rhs_and_dynamics`] with what the solve computed on the way (the same numbers; the
    /// derivatives of the dynamics solve the same KKT system again).
    pub(crate) fn rhs_dynamics_solved(
        &self,
        y: &WalkVector,
    ) -> (WalkVector, Option<ConstrainedDynamics>, Solved) {
        let (q, qd) = unpack(y);
        let (dynamics, solved) = constrained_dynamics_solved(self.model, &q, &qd, &self.active);
        let (f, dynamics) = self.field(&qd, dynamics);
        (f, dynamics, solved)
    }

    /// The vector field from the constrained dynamics at a state with velocities `qd`.
    fn field(
        &self,
        qd: &Coords,
        dynamics: Result<ConstrainedDynamics, ContactError>,
    ) -> (WalkVector, Option<ConstrainedDynamics>) {
        match dynamics {
            Ok(d) => {
                let c = self.model.params().viscosity;
                let power = qd[L1] * qd[L1] + qd[L2] * qd[L2] + qd[L3] * qd[L3];
                let f = pack(qd, &d.qdd, c * power);
                (f, Some(d))
            }
            // The integrator reports a non-finite derivative as an error with its time.
            Err(_) => (WalkVector::repeat(f64::NAN), None),
        }
    }
}

impl OdeSystem<NY> for PhaseSystem<'_> {
    fn rhs(&self, _t: f64, y: &WalkVector) -> WalkVector {
        self.rhs_and_dynamics(y).0
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
