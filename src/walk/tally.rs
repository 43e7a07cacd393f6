//! The bookkeeping of a step in progress ([`StepTally`]): durations, the contact audit, flags and the energy
//! lost in impacts, which the step's report is made of.

use crate::contact::ActiveSet;

use super::impact::SwingLock;
use super::report::ContactAudit;
use super::zeno::ZenoLock;

/// Bookkeeping of the step in progress.
#[derive(Debug, Default, Clone, Copy)]
pub(super) struct StepTally {
    /// Time in double-limb support so far \[s\].
    pub(super) dls_duration: f64,
    /// Time Leg 2's tip touched the ground so far \[s\].
    pub(super) rear_contact_duration: f64,
    /// The contact audit so far.
    pub(super) audit: ContactAudit,
    /// Leg 2 scuffed (re-contact or slide).
    pub(super) scuffing: bool,
    /// Leg 1 bounced.
    pub(super) bounce: bool,
    /// Kinetic energy lost in ground impacts \[J\].
    pub(super) impact_loss: f64,
    /// Kinetic energy lost in stopper impacts \[J\].
    pub(super) stopper_loss: f64,
    /// Events handled so far.
    pub(super) events: usize,
}

impl StepTally {
    /// Account for a Zeno lock (docs/model.md section 5): its kinetic energy loss is a stopper loss, its impulse
    /// goes to the contact audit as `zeno_impulse` (the other units' pulls as `pull_impulse`).
    pub(super) fn see_zeno(&mut self, lock: &ZenoLock) {
        self.stopper_loss += lock.loss;
        self.audit.zeno_impulse = self.audit.zeno_impulse.max(lock.impulse);
        self.audit.pull_impulse = self.audit.pull_impulse.max(lock.pull_impulse);
        self.scuffing |= lock.active.slide2;
    }

    /// Account for the swinging leg's stopper lock from `before` (rear_exit = continue): a stopper loss, its
    /// pulls to the contact audit, and Leg 1 leaving or Leg 2 sliding through it.
    pub(super) fn see_swing_lock(&mut self, lock: &SwingLock, before: &ActiveSet) {
        self.stopper_loss += lock.loss;
        self.audit.pull_impulse = self.audit.pull_impulse.max(lock.pull_impulse);
        self.bounce |= before.contact1 && !lock.active.contact1;
        self.scuffing |= lock.active.slide2;
    }
}
