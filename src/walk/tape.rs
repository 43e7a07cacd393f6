//! The record of one walked step that the exact derivatives replay (docs/model.md section 10): the impulse sets
//! of its impacts, the active set, start and accepted integrator steps of each phase, and the event that ended
//! each phase. With it, `crate::variational` integrates the variational equations over the very steps the walk
//! took and composes the saltation matrix of every event, without deciding anything again.

use crate::contact::{ActiveSet, Role, Stop};

use super::events::EventKind;
use super::phase::{StageLog, WalkVector};

/// One step as the walker took it ([`super::Walker::step_taped`]).
#[derive(Debug, Default)]
pub(crate) struct StepTape {
    /// The units that took an impulse at the touchdown impact: the collision the procedure applied, then the
    /// Zeno locks that followed it, in order.
    pub(crate) impacts: Vec<ActiveSet>,
    /// The phases of the step, in order; the last ends at the next touchdown.
    pub(crate) segments: Vec<Segment>,
    /// The walk's evaluations of the vector field, kept for the replay where asked for ([`StepTape::logging`]).
    pub(crate) stages: Option<StageLog>,
}

/// The log of `tape`, if it keeps one.
pub(crate) fn log_of<'t>(tape: &'t Option<&mut StepTape>) -> Option<&'t StageLog> {
    tape.as_deref().and_then(|t| t.stages.as_ref())
}

/// One phase of constrained motion.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Segment {
    /// Its active contacts and stoppers.
    pub(crate) active: ActiveSet,
    /// Start time \[s\].
    pub(crate) t0: f64,
    /// The state at the start (after the event's reset).
    pub(crate) y0: WalkVector,
    /// The accepted integrator steps, `(h, t1)` each, every one starting where the one before ended.
    pub(crate) steps: Vec<(f64, f64)>,
    /// The event that ended it (located inside the last step).
    pub(crate) end: Option<SegmentEnd>,
}

/// The event that ended a phase.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SegmentEnd {
    /// When \[s\].
    pub(crate) time: f64,
    /// Which event.
    pub(crate) kind: EventKind,
    /// The state then, on the last step's dense output (before any reset).
    pub(crate) y: WalkVector,
    /// The units that took an impulse at the event's impacts (a landing or stopper hit, then its Zeno locks),
    /// in order; empty when the event only changes the active set.
    pub(crate) impacts: Vec<ActiveSet>,
}

impl StepTape {
    /// An empty tape that also keeps the walk's evaluations of the vector field ([`StageLog`]).
    pub(crate) fn logging() -> StepTape {
        StepTape {
            stages: Some(StageLog::reserved()),
            ..StepTape::default()
        }
    }

    /// Start a phase at `(t0, y0)` with `active`.
    pub(crate) fn begin(&mut self, active: ActiveSet, t0: f64, y0: WalkVector) {
        self.segments.push(Segment {
            active,
            t0,
            y0,
            steps: Vec::new(),
            end: None,
        });
    }

    /// The phase in progress.
    fn current(&mut self) -> Option<&mut Segment> {
        self.segments.last_mut()
    }

    /// An accepted integrator step of size `h` ending at `t1`.
    pub(crate) fn step(&mut self, h: f64, t1: f64) {
        if let Some(segment) = self.current() {
            segment.steps.push((h, t1));
        }
    }

    /// The phase in progress ends with `kind` at `(time, y)`.
    pub(crate) fn end(&mut self, time: f64, kind: EventKind, y: WalkVector) {
        if let Some(segment) = self.current() {
            segment.end = Some(SegmentEnd {
                time,
                kind,
                y,
                impacts: Vec::new(),
            });
        }
    }

    /// The units of an impact at the end of the phase in progress (or, before any phase, at the touchdown).
    pub(crate) fn impact(&mut self, set: ActiveSet) {
        match self.segments.last_mut().and_then(|s| s.end.as_mut()) {
            Some(end) => end.impacts.push(set),
            None => self.impacts.push(set),
        }
    }
}

impl StepTape {
    /// The step's event sequence in words (`branch.csv`'s `signature`, docs/model.md section 11): the touchdown
    /// and its branch (`TD DLS`), then one word per change of a unit between successive phases, in the order
    /// the phases follow and, within one change, Leg 1 before Leg 2: `LIFT`/`LAND` (ground contact off/on),
    /// `SLIDE`/`STICK` (a contact starts/stops sliding), `UNLOCK`/`LOCK` (stopper), `UNLOCKMIN`/`LOCKMIN`
    /// (compression stop, `min_length`), each with the leg's number,
    /// as `TD DLS UNLOCK1 LIFT2 LOCK2`. With Coulomb friction (docs/model.md section 12) a tip that slips through
    /// the touchdown impact adds `SLIP1`/`SLIP2` right after the branch, and a slip that reverses (a slip stop
    /// followed by a slip the other way) `REVERSE1`/`REVERSE2`; a frictionless slide has neither, so the
    /// signatures of `friction = inf` are unchanged. Two steps with the same signature took the same smooth piece
    /// of the step map; a family whose signature changes crossed a border between pieces.
    pub(crate) fn signature(&self, branch: impl std::fmt::Display) -> String {
        let mut words = vec!["TD".to_string(), branch.to_string()];
        let number = |leg: Role| match leg {
            Role::Fore => 1,
            Role::Rear => 2,
        };
        if let Some(first) = self.segments.first() {
            for leg in Role::BOTH {
                if first.active.slip(leg) != 0 {
                    words.push(format!("SLIP{}", number(leg)));
                }
            }
        }
        for pair in self.segments.windows(2) {
            let (a, b) = (pair[0].active, pair[1].active);
            for leg in Role::BOTH {
                let n = number(leg);
                if a.slip(leg) * b.slip(leg) < 0 {
                    words.push(format!("REVERSE{n}"));
                }
                let slide = |s: &ActiveSet| match leg {
                    Role::Fore => s.slide1,
                    Role::Rear => s.slide2,
                };
                let changes = [
                    (a.contact(leg), b.contact(leg), "LAND", "LIFT"),
                    (
                        a.contact(leg) && slide(&a),
                        b.contact(leg) && slide(&b),
                        "SLIDE",
                        "STICK",
                    ),
                    (a.lock(leg), b.lock(leg), "LOCK", "UNLOCK"),
                    (
                        a.held(leg, Stop::Compression),
                        b.held(leg, Stop::Compression),
                        "LOCKMIN",
                        "UNLOCKMIN",
                    ),
                ];
                for (before, after, on, off) in changes {
                    if before != after {
                        let word = if after { on } else { off };
                        // A sliding contact that leaves is a lift-off, not a stick.
                        if word == "STICK" && !b.contact(leg) {
                            continue;
                        }
                        words.push(format!("{word}{n}"));
                    }
                }
            }
        }
        words.join(" ")
    }
}
