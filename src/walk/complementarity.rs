//! The complementarity problems of contacts and stops (docs/model.md sections 4 and 12): the unilateral units,
//! their modes (off, on, a frictionless slide, a Coulomb slip), and the enumeration of active sets at force and
//! impulse level.
//!
//! Unilateral units (contacts that may only push, stoppers that may only pull a leg inward, compression stops
//! that may only push it outward) are resolved by enumerating the few possible active sets and keeping a set
//! that satisfies complementarity: included units push the right way, excluded units do not penetrate. Where
//! several sets qualify, the one that best matches the stated preference (keep what was active, add no stopper
//! that is not needed, follow the paper's branch) wins, so in the regular case the result is exactly the
//! paper's procedure. With Coulomb friction a contact is off, sticking (its force inside the cone) or slipping
//! one way or the other (the friction force on the cone's edge, against the slip).

use crate::contact::{
    cone_distance, constrained_dynamics, dynamics_through_painleve, impulse, ActiveSet,
    ConstrainedDynamics, ContactError, ImpulseSolution, Role, Stop,
};
use crate::dynamics::{Coords, Model};
use crate::params::ContactInconsistency;

/// Tolerance of the complementarity checks (forces \[N\], impulses \[N s\], velocities \[m/s\], accelerations
/// \[m/s^2\]): a value within this of zero counts as zero, so that an event located at a force or velocity
/// zero is not undone by rounding.
pub(crate) const COMPLEMENTARITY_TOL: f64 = 1e-9;

/// Largest tangential speed of a tip that a no-slip contact may hold at force level \[m/s\]: a tip at rest up to
/// the integration error (~1e-12 m/s, as `SECTION_TIP_SPEED_TOL` of the walk); a tip that slides faster (after a
/// frictionless impulse) is not stuck by the force-level problem, which has no impulse to stop it.
pub(crate) const STICK_SPEED_TOL: f64 = 1e-8;

/// A unilateral unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// Ground contact of a leg tip.
    Contact(Role),
    /// One of a leg's stroke limits: its stopper or its compression stop.
    Stop(Role, Stop),
}

/// State of a unit in an active set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Mode {
    /// Inactive: the tip is free / the leg is free of its stopper.
    Off,
    /// Active: a no-slip contact, or a locked stopper.
    On,
    /// A contact that slides without friction (normal row only); used only when neither `On` nor `Off` is
    /// consistent and [`ContactInconsistency::Slide`] is selected.
    Slide,
    /// A contact that slips with Coulomb friction (a finite `friction`) in the direction `+1` (down the slope)
    /// or `-1`: its normal row, and the friction force on the edge of the cone against the slip.
    Slip(i8),
}

impl Unit {
    /// The units of `leg`: its ground contact, its stopper and its compression stop.
    pub(crate) fn of(leg: Role) -> [Unit; 3] {
        [
            Unit::Contact(leg),
            Unit::Stop(leg, Stop::Extension),
            Unit::Stop(leg, Stop::Compression),
        ]
    }

    /// Put the unit in `mode` in `active`.
    pub(crate) fn apply(self, active: &mut ActiveSet, mode: Mode) {
        match (self, mode) {
            (Unit::Contact(leg), Mode::Slide) => active.set_sliding(leg),
            (Unit::Contact(leg), Mode::Slip(s)) => active.set_slipping(leg, s),
            (Unit::Contact(leg), m) => active.set_contact(leg, m == Mode::On),
            (Unit::Stop(leg, stop), m) => active.set_held(leg, stop, m != Mode::Off),
        }
    }

    /// The unit's mode in `active`.
    pub(crate) fn mode(self, active: &ActiveSet) -> Mode {
        match self {
            Unit::Contact(leg) if active.slip(leg) != 0 => Mode::Slip(active.slip(leg)),
            Unit::Contact(leg) if active.slide(leg) => Mode::Slide,
            Unit::Contact(leg) if active.contact(leg) => Mode::On,
            Unit::Stop(leg, stop) if active.held(leg, stop) => Mode::On,
            _ => Mode::Off,
        }
    }
}

/// What a candidate unit is doing at the moment its mode is resolved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Part {
    /// Present before (or touching after an impact): any mode its kind allows.
    Keep,
    /// Its normal force has just fallen through zero (a lift-off event), or, with Coulomb friction, its
    /// tangential force has just reached the edge of the cone: it may leave the ground or slide (slip), but not
    /// stay a no-slip contact.
    Releasing,
    /// The unit an impact closes (a landing tip, a leg hitting its stopper): it takes the impulse, no-slip if
    /// that impulse pushes, else (under [`ContactInconsistency::Slide`]) as a frictionless sliding contact.
    Closing {
        /// Sliding is allowed (the model's `inconsistent_contact = slide`).
        allow_slide: bool,
    },
}

/// An optional unit and the mode the caller prefers for it when several are consistent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Candidate {
    /// The unit.
    pub unit: Unit,
    /// Preferred mode.
    pub preferred: Mode,
    /// What the unit is doing.
    pub role: Part,
}

impl Candidate {
    /// The candidate `unit` preferring the mode it has in `active`.
    pub(crate) fn keep(unit: Unit, active: &ActiveSet) -> Candidate {
        Candidate::new(unit, unit.mode(active))
    }

    /// The candidate `unit` preferring `preferred`.
    pub(crate) fn new(unit: Unit, preferred: Mode) -> Candidate {
        Candidate {
            unit,
            preferred,
            role: Part::Keep,
        }
    }

    /// A contact whose normal force has just reached zero: preferably it leaves; it may slide (under
    /// [`ContactInconsistency::Slide`], or slip with Coulomb friction), but it cannot stay a no-slip contact.
    pub(crate) fn releasing(leg: Role) -> Candidate {
        Candidate::released(leg, Mode::Off)
    }

    /// A sticking contact whose tangential force has just reached the edge of the friction cone: preferably
    /// it slips in `direction` (against the force that reached the edge); it may leave, but not stick.
    pub(crate) fn cone_reached(leg: Role, direction: i8) -> Candidate {
        Candidate::released(leg, Mode::Slip(direction))
    }

    fn released(leg: Role, preferred: Mode) -> Candidate {
        Candidate {
            unit: Unit::Contact(leg),
            preferred,
            role: Part::Releasing,
        }
    }

    /// The unit an impact closes, preferably no-slip (see [`Part::Closing`]).
    pub(crate) fn closing(unit: Unit, model: &Model) -> Candidate {
        Candidate {
            unit,
            preferred: Mode::On,
            role: Part::Closing {
                allow_slide: model.params().inconsistent_contact == ContactInconsistency::Slide,
            },
        }
    }

    /// The modes tried for this candidate. At impulse level a contact keeps its kind: a no-slip contact may
    /// take a full (tangential and normal) impulse or none, a sliding one a frictionless normal impulse or none;
    /// a closing unit always takes an impulse. At force level a contact may also start to slide when
    /// `allow_slide`.
    ///
    /// With Coulomb friction a contact's modes are: closing, stick or slip either way (it takes the impulse);
    /// released, off or slip; otherwise off, stick or slip, at both levels (an impulse may stop a slipping tip,
    /// or make a sticking one slip).
    fn modes(&self, level: Level) -> &'static [Mode] {
        let contact = matches!(self.unit, Unit::Contact(_));
        if contact && level.friction() {
            return match self.role {
                Part::Closing { .. } => &[Mode::On, Mode::Slip(1), Mode::Slip(-1)],
                Part::Releasing => &[Mode::Off, Mode::Slip(1), Mode::Slip(-1)],
                Part::Keep => &[Mode::Off, Mode::On, Mode::Slip(1), Mode::Slip(-1)],
            };
        }
        match (self.role, level) {
            (Part::Closing { allow_slide: true }, _) if contact => &[Mode::On, Mode::Slide],
            (Part::Closing { .. }, _) => &[Mode::On],
            (
                Part::Releasing,
                Level::Force {
                    allow_slide: true, ..
                },
            ) => &[Mode::Off, Mode::Slide],
            (Part::Releasing, _) => &[Mode::Off],
            (Part::Keep, Level::Impulse { .. }) if contact && self.preferred == Mode::Slide => {
                &[Mode::Off, Mode::Slide]
            }
            (
                Part::Keep,
                Level::Force {
                    allow_slide: true, ..
                },
            ) if contact => &[Mode::Off, Mode::On, Mode::Slide],
            _ => &[Mode::Off, Mode::On],
        }
    }

    /// Preference score: the preferred mode 2, another regular mode 1, sliding (the last resort) 0.
    fn score(&self, mode: Mode) -> usize {
        if mode == self.preferred {
            2
        } else if mode == Mode::Slide {
            0
        } else {
            1
        }
    }
}

/// Which complementarity problem an active set is resolved for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Level {
    /// An impact (impulses and velocities just after it).
    Impulse {
        /// Contacts have Coulomb friction (a finite `friction`).
        friction: bool,
    },
    /// Continuous motion (forces and accelerations).
    Force {
        /// Contacts may slide without friction when neither sticking nor leaving is consistent.
        allow_slide: bool,
        /// Contacts have Coulomb friction (a finite `friction`).
        friction: bool,
    },
}

impl Level {
    fn friction(self) -> bool {
        match self {
            Level::Impulse { friction } | Level::Force { friction, .. } => friction,
        }
    }
}

/// A solve of a set through the Painleve case ([`crate::contact::dynamics_through_painleve`]).
type SolveThrough<'a, T> = dyn FnMut(&ActiveSet) -> Result<T, ContactError> + 'a;

/// Among `forced` plus every combination of modes of the `candidates`, the consistent set with the best
/// preference score, or `None` if no combination is consistent. When none is and some combination with a
/// slipping contact was the Painleve case, that is the error ([`ContactError::Painleve`]): the problem has no
/// solution because friction made a slip inconsistent, not because the units were chosen wrong.
///
/// With `through_painleve` (the force-level problem with friction), every set with a slipping contact is
/// solved, whatever its score, and a Painleve set is solved again through its non-positive pivot: if its
/// forces are consistent, the problem has that solution too (or only it), and that is the error
/// ([`ContactError::PainleveSlip`]) rather than a silent pick of the preferred one.
fn best_subset<T>(
    forced: ActiveSet,
    candidates: &[Candidate],
    level: Level,
    mut solve: impl FnMut(&ActiveSet) -> Result<T, ContactError>,
    mut consistent: impl FnMut(&ActiveSet, &T) -> bool,
    mut through_painleve: Option<&mut SolveThrough<T>>,
) -> Result<Option<(ActiveSet, T)>, ContactError> {
    let radix: Vec<usize> = candidates.iter().map(|c| c.modes(level).len()).collect();
    let combinations: usize = radix.iter().product();
    let mut best: Option<(usize, ActiveSet, T)> = None;
    let mut painleve = None;
    let mut painleve_solution = None;
    for mut code in 0..combinations {
        let mut set = forced;
        let mut score = 0;
        for (c, r) in candidates.iter().zip(&radix) {
            let mode = c.modes(level)[code % r];
            code /= r;
            c.unit.apply(&mut set, mode);
            score += c.score(mode);
        }
        let outscored = best.as_ref().is_some_and(|(s, _, _)| *s >= score);
        if outscored && !(through_painleve.is_some() && set.any_slip()) {
            continue;
        }
        match solve(&set) {
            Ok(value) if !outscored && consistent(&set, &value) => best = Some((score, set, value)),
            Ok(_) => {}
            // A redundant set is simply not a candidate; other failures are real.
            Err(ContactError::RedundantConstraints(_)) => {}
            Err(ContactError::Painleve(set)) => {
                painleve = painleve.or(Some(set));
                if let Some(again) = through_painleve.as_deref_mut() {
                    if again(&set).is_ok_and(|value| consistent(&set, &value)) {
                        painleve_solution = painleve_solution.or(Some(set));
                    }
                }
            }
            Err(e) => return Err(e),
        }
    }
    match (best, painleve, painleve_solution) {
        (best, _, Some(slip)) => Err(ContactError::PainleveSlip {
            slip,
            other: best.map(|(_, set, _)| set),
        }),
        (Some((_, set, value)), _, None) => Ok(Some((set, value))),
        (None, Some(set), None) => Err(ContactError::Painleve(set)),
        (None, None, None) => Ok(None),
    }
}

/// `forced` plus every candidate in its preferred mode.
fn preferred_set(forced: ActiveSet, candidates: &[Candidate]) -> ActiveSet {
    let mut set = forced;
    for c in candidates {
        c.unit.apply(&mut set, c.preferred);
    }
    set
}

/// Plastic impact with the units of `forced` closing and the `candidates` taking an impulse only where they
/// must: paper Eq. (5) with the active set resolved as an impulse-level complementarity problem (docs/model.md
/// section 4). Every candidate either takes a non-negative impulse and ends at zero relative normal velocity,
/// or takes none and separates (normal velocity after the impact `>= 0`, a free leg not moving past its
/// stopper). A no-slip contact's impulse has a tangential part; a sliding contact's is normal only. If no
/// combination is consistent the preferred one is used, and the step's contact audit
/// ([`largest_pull`]) shows the pulling impulse; with Coulomb friction (a sticking impulse in the cone, a
/// slipping one leaving the tip moving its way) that is [`ContactError::InconsistentImpact`] instead.
pub(crate) fn plastic_impact(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    forced: ActiveSet,
    candidates: &[Candidate],
) -> Result<(ActiveSet, ImpulseSolution), ContactError> {
    plastic_impact_by(model, (q, qd), forced, candidates, |set| {
        impulse(model, q, qd, set)
    })
}

/// [`plastic_impact`] with the collision equation solved by `solve` for each combination of units (which may
/// add a row of its own, as the swinging leg's stopper, [`lock_swinging_leg`]).
pub(crate) fn plastic_impact_by(
    model: &Model,
    (q, qd): (&Coords, &Coords),
    forced: ActiveSet,
    candidates: &[Candidate],
    solve: impl Fn(&ActiveSet) -> Result<ImpulseSolution, ContactError>,
) -> Result<(ActiveSet, ImpulseSolution), ContactError> {
    let friction = model.params().friction;
    let level = Level::Impulse {
        friction: friction.is_finite(),
    };
    let found = best_subset(
        forced,
        candidates,
        level,
        &solve,
        |set, sol| {
            candidates.iter().all(|c| match (c.unit, c.unit.mode(set)) {
                (Unit::Contact(leg), Mode::Off) => {
                    model.tip(q, qd, leg.index()).velocity(&sol.qd_plus).y >= -COMPLEMENTARITY_TOL
                }
                (Unit::Contact(leg), Mode::On) => within_cone(
                    friction,
                    sol.impulses[leg.tangential_row()],
                    sol.normal_impulse(leg),
                ),
                // A Coulomb impulse leaves the tip moving the way it slips (or at rest).
                (Unit::Contact(leg), Mode::Slip(s)) => {
                    let v = model.tip(q, qd, leg.index()).velocity(&sol.qd_plus).x;
                    sol.normal_impulse(leg) >= -COMPLEMENTARITY_TOL
                        && f64::from(s) * v >= -COMPLEMENTARITY_TOL
                }
                (Unit::Contact(leg), _) => sol.normal_impulse(leg) >= -COMPLEMENTARITY_TOL,
                (Unit::Stop(leg, stop), Mode::Off) => {
                    stop.sign() * sol.qd_plus[Model::stroke_coordinate(leg)] <= COMPLEMENTARITY_TOL
                }
                (Unit::Stop(leg, stop), _) => sol.stop_impulse(leg, stop) >= -COMPLEMENTARITY_TOL,
            })
        },
        None,
    )?;
    match found {
        Some(found) => Ok(found),
        // With friction an arbitrary pick would hide that the frictional impact has no solution: say so.
        None if level.friction() => Err(ContactError::InconsistentImpact(preferred_set(
            forced, candidates,
        ))),
        None => {
            let set = preferred_set(forced, candidates);
            Ok((set, solve(&set)?))
        }
    }
}

/// The active set for continuous motion (the force-level complementarity problem): `forced` units plus the
/// `candidates` that must push (positive normal force, inward stopper reaction) so that no excluded unit
/// penetrates (tip accelerating into the ground, leg accelerating past its stopper). Sliding contacts are
/// tried only under [`ContactInconsistency::Slide`]; under [`ContactInconsistency::Rebound`], when no set is
/// consistent, the paper's (B2)/(B3) rule decides: contacts with a pulling normal force are released.
pub(crate) fn consistent_active_set(
    model: &Model,
    q: &Coords,
    qd: &Coords,
    forced: ActiveSet,
    candidates: &[Candidate],
) -> Result<Option<(ActiveSet, ConstrainedDynamics)>, ContactError> {
    let allow_slide = model.params().inconsistent_contact == ContactInconsistency::Slide;
    let friction = model.params().friction;
    let solve = |set: &ActiveSet| constrained_dynamics(model, q, qd, set);
    let level = Level::Force {
        allow_slide,
        friction: friction.is_finite(),
    };
    // With friction, a slip in the Painleve case is solved through it: if its forces are consistent, the
    // problem is ambiguous (or has only that solution), which is reported, not picked.
    let mut again = |set: &ActiveSet| dynamics_through_painleve(model, q, qd, set);
    let through_painleve: Option<&mut SolveThrough<_>> = friction.is_finite().then_some(&mut again);
    let found = best_subset(
        forced,
        candidates,
        level,
        solve,
        |set, dynamics| {
            candidates.iter().all(|c| match (c.unit, c.unit.mode(set)) {
                (Unit::Contact(leg), Mode::Off) => {
                    let tip = model.tip(q, qd, leg.index());
                    (tip.jacobian * dynamics.qdd + tip.velocity_product).y >= -COMPLEMENTARITY_TOL
                }
                // A no-slip contact needs its tip at rest: one that slides (after a frictionless impulse) stays
                // sliding or leaves; holding it would make the tangential force do work.
                (Unit::Contact(leg), Mode::On) => {
                    let (lambda_t, lambda_n) = (
                        dynamics.multipliers[leg.tangential_row()],
                        dynamics.normal_force(leg),
                    );
                    within_cone(friction, lambda_t, lambda_n)
                        && model.tip(q, qd, leg.index()).velocity(qd).x.abs() <= STICK_SPEED_TOL
                }
                // A slipping tip keeps the direction it moves in; one at rest starts to slip the way it accelerates.
                (Unit::Contact(leg), Mode::Slip(s)) => {
                    let tip = model.tip(q, qd, leg.index());
                    let v = tip.velocity(qd).x;
                    let along = if v.abs() > STICK_SPEED_TOL {
                        v.signum() == f64::from(s)
                    } else {
                        let a = (tip.jacobian * dynamics.qdd + tip.velocity_product).x;
                        f64::from(s) * a >= -COMPLEMENTARITY_TOL
                    };
                    dynamics.normal_force(leg) >= -COMPLEMENTARITY_TOL && along
                }
                (Unit::Contact(leg), _) => dynamics.normal_force(leg) >= -COMPLEMENTARITY_TOL,
                (Unit::Stop(leg, stop), Mode::Off) => {
                    stop.sign() * dynamics.qdd[Model::stroke_coordinate(leg)] <= COMPLEMENTARITY_TOL
                }
                (Unit::Stop(leg, stop), _) => {
                    dynamics.stop_reaction(leg, stop) >= -COMPLEMENTARITY_TOL
                }
            })
        },
        through_painleve,
    )?;
    if found.is_some() || allow_slide {
        return Ok(found);
    }
    // ContactInconsistency::Rebound: the paper's rule (B2)/(B3) applied literally. Start from the preferred set
    // and release every contact whose normal force pulls, even if the released tip then falls back at once.
    let mut set = preferred_set(forced, candidates);
    let dynamics = solve(&set)?;
    for c in candidates {
        if let Unit::Contact(leg) = c.unit {
            if set.contact(leg) && dynamics.normal_force(leg) < 0.0 {
                set.set_contact(leg, false);
            }
        }
    }
    Ok(Some((set, solve(&set)?)))
}

/// Does a no-slip contact's force (impulse) push and lie in the friction cone, `|lambda_t| <= mu lambda_n`
/// (within [`COMPLEMENTARITY_TOL`])? Any pushing force does without friction (`mu` infinite).
fn within_cone(mu: f64, lambda_t: f64, lambda_n: f64) -> bool {
    lambda_n >= -COMPLEMENTARITY_TOL
        && (mu == f64::INFINITY
            || cone_distance(mu, lambda_t, lambda_n.max(0.0)) <= COMPLEMENTARITY_TOL)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{L1, L2, L3, NQ, X};
    use crate::params::Params;
    use nalgebra::{Matrix2, SMatrix, Vector2};

    /// A rigid wheel (its stoppers bilateral) with coefficient `mu` on slope `slope`.
    fn rigid(mu: f64, slope: f64) -> Model {
        Model::new(&Params {
            rigid_legs: true,
            friction: mu,
            slope,
            ..Params::default()
        })
        .unwrap()
    }

    fn bilateral() -> ActiveSet {
        ActiveSet {
            lock1: true,
            lock2: true,
            ..Default::default()
        }
    }

    /// The wheel standing on Leg 1 with its hub straight above the tip along gravity (`theta = -phi`) is in
    /// equilibrium with a contact force along the leg, `|lambda_t| / lambda_n = tan phi`: it sticks where
    /// `mu >= tan phi` and slips down the slope (with the friction force on the cone's edge) where not.
    #[test]
    fn a_wheel_balanced_on_one_leg_sticks_exactly_up_to_mu_equal_tan_phi() {
        let slope: f64 = 0.3;
        for (mu, sticks) in [(slope.tan() * 1.001, true), (slope.tan() * 0.999, false)] {
            let model = rigid(mu, slope);
            let q = Coords::new(0.0, 0.0, -slope, 1.0, 1.0, 0.0);
            let candidates = [Candidate::new(Unit::Contact(Role::Fore), Mode::On)];
            let (set, d) =
                consistent_active_set(&model, &q, &Coords::zeros(), bilateral(), &candidates)
                    .unwrap()
                    .unwrap();
            let (t, n) = (d.multipliers[0], d.multipliers[1]);
            if sticks {
                assert!(set.contact1 && !set.slide1, "{set}");
                assert!((t / n + slope.tan()).abs() < 1e-12, "{t} {n}");
                assert!(d.qdd.amax() < 1e-12);
            } else {
                assert_eq!(set.slip1, 1, "{set}");
                assert!((t + mu * n).abs() < 1e-12 * n, "{t} {n}");
                assert!(d.qdd[X] > 0.0, "the tip slips down the slope: {}", d.qdd[X]);
            }
        }
    }

    /// The plastic impact of one tip with Coulomb friction against its closed form: with `W` the tip's inverse
    /// mass matrix (tangential, normal rows; the wheel's stoppers held), the impulse sticks, `Lambda = -W^-1 v-`,
    /// if that lies in the cone; else it slips in the direction `s` for which `Lambda_n = -v_n / (W_nn - s mu
    /// W_nt)`, `Lambda_t = -s mu Lambda_n` leave the tip moving along `s`. It never adds kinetic energy.
    #[test]
    fn an_oblique_landing_takes_the_closed_form_coulomb_impulse() {
        let q = Coords::new(0.0, 0.0, -0.2, 1.0, 1.0, 0.0);
        let mut regimes = (0, 0);
        for mu in [0.05, 0.2, 0.5, 1.0, 1000.0] {
            for (vx, vz, thetadot) in [(0.3, -0.5, 0.4), (-0.2, -0.7, 1.1), (0.9, -0.2, -0.3)] {
                let model = rigid(mu, 0.1);
                let qd = Coords::new(vx, vz, thetadot, 0.0, 0.0, 0.0);
                let closing = [Candidate::closing(Unit::Contact(Role::Fore), &model)];
                let (set, sol) = plastic_impact(&model, &q, &qd, bilateral(), &closing).unwrap();
                // W = J P J^T with P the inverse mass with the stoppers held (L1, L2, L3 fixed).
                let m = model.mass_matrix(&q);
                let minv = m.try_inverse().unwrap();
                let mut g = SMatrix::<f64, 3, NQ>::zeros();
                for (row, coord) in [L1, L2, L3].into_iter().enumerate() {
                    g[(row, coord)] = 1.0;
                }
                let gmg = (g * minv * g.transpose()).try_inverse().unwrap();
                let p = minv - minv * g.transpose() * gmg * g * minv;
                let j = model.tip(&q, &qd, 0).jacobian;
                let w: Matrix2<f64> = j * p * j.transpose();
                let v: Vector2<f64> = j * qd;
                let stick = -w.try_inverse().unwrap() * v;
                let expected = if stick.x.abs() <= mu * stick.y {
                    regimes.0 += 1;
                    assert!(set.contact1 && !set.slide1, "mu {mu}: {set}");
                    stick
                } else {
                    regimes.1 += 1;
                    let slip = [1.0, -1.0].into_iter().find_map(|s: f64| {
                        let n = -v.y / (w[(1, 1)] - s * mu * w[(1, 0)]);
                        let t = -s * mu * n;
                        let vt = v.x + w[(0, 1)] * n + w[(0, 0)] * t;
                        (n >= 0.0 && s * vt >= 0.0).then_some((s, Vector2::new(t, n)))
                    });
                    let (s, impulse) = slip.expect("a consistent slip");
                    assert_eq!(f64::from(set.slip1), s, "mu {mu}: {set}");
                    impulse
                };
                let got = Vector2::new(sol.impulses[0], sol.impulses[1]);
                assert!(
                    (got - expected).amax() < 1e-10,
                    "mu {mu}: {got} vs {expected}"
                );
                let after = model.tip(&q, &qd, 0).velocity(&sol.qd_plus);
                assert!(after.y.abs() < 1e-12);
                let lost = model.kinetic_energy(&q, &qd) - model.kinetic_energy(&q, &sol.qd_plus);
                assert!(lost >= -1e-12, "mu {mu}: energy gained {lost}");
            }
        }
        // Both regimes were met.
        assert!(regimes.0 > 0 && regimes.1 > 0, "{regimes:?}");
    }

    /// The Painleve case at force level: a tip sliding with a large `mu` whose free motion would take it into
    /// the ground (it cannot leave) and whose slip has a non-positive effective normal inverse mass (it cannot
    /// slip) has no consistent mode: the problem says so by name, and the walk's status is `painleve`.
    #[test]
    fn a_sliding_tip_with_no_consistent_mode_is_the_painleve_case() {
        let model = rigid(5.0, 0.1);
        let mut found = 0;
        for i in -12..=12 {
            let q = Coords::new(0.0, 0.0, 0.1 * f64::from(i), 1.0, 1.0, 0.0);
            // Sliding down the slope, not turning: gravity pulls the tip into the ground.
            let qd = Coords::new(0.5, 0.0, 0.0, 0.0, 0.0, 0.0);
            let mut slipping = bilateral();
            slipping.set_slipping(Role::Fore, 1);
            if !matches!(
                crate::contact::constrained_dynamics(&model, &q, &qd, &slipping),
                Err(ContactError::Painleve(_))
            ) {
                continue;
            }
            let candidates = [Candidate::keep(Unit::Contact(Role::Fore), &slipping)];
            let result = consistent_active_set(&model, &q, &qd, bilateral(), &candidates);
            let Err(error) = result else {
                panic!("theta {i}: {result:?}");
            };
            assert!(matches!(error, ContactError::Painleve(_)), "{error}");
            let walk_error = crate::walk::WalkError::contact_at(1.0, slipping.phase())(error);
            assert_eq!(walk_error.kind(), "painleve");
            assert!(walk_error.to_string().contains("Painleve"), "{walk_error}");
            found += 1;
        }
        assert!(found > 0, "no Painleve configuration in the scan");
    }

    /// The Painleve case with a solution: a tip slipping with a large `mu` whose effective normal inverse mass is
    /// negative, on a wheel spinning fast enough that its free motion lifts the tip, has consistent slip forces
    /// (a pushing normal force that friction turns into a pull toward the ground) besides lift-off: two
    /// solutions, reported by name (status `painleve`) rather than picked.
    #[test]
    fn a_painleve_slip_with_consistent_forces_is_reported_not_picked() {
        let model = rigid(5.0, 0.1);
        let (mut found, mut two) = (0, 0);
        for i in -12..=12 {
            for spin in [-8.0, -4.0, 4.0, 8.0] {
                for v in [-0.5, 0.5] {
                    let q = Coords::new(0.0, 0.0, 0.1 * f64::from(i), 1.0, 1.0, 0.0);
                    let qd = Coords::new(v, 0.0, spin, 0.0, 0.0, 0.0);
                    // The tip's velocity along the ground (the x of the tip, with the hub's turn).
                    let tip_v = model.tip(&q, &qd, 0).velocity(&qd).x;
                    let mut slipping = bilateral();
                    slipping.set_slipping(Role::Fore, if tip_v > 0.0 { 1 } else { -1 });
                    let candidates = [Candidate::keep(Unit::Contact(Role::Fore), &slipping)];
                    let result = consistent_active_set(&model, &q, &qd, bilateral(), &candidates);
                    let Err(error @ ContactError::PainleveSlip { slip, other }) = result else {
                        continue;
                    };
                    assert_eq!(slip.slip1, slipping.slip1);
                    // The slip's forces through the negative pivot push, and the tip slips its way.
                    let dynamics =
                        crate::contact::dynamics_through_painleve(&model, &q, &qd, &slip).unwrap();
                    assert!(dynamics.normal_force(Role::Fore) >= 0.0, "{dynamics:?}");
                    assert!(matches!(
                        crate::contact::constrained_dynamics(&model, &q, &qd, &slip),
                        Err(ContactError::Painleve(_))
                    ));
                    let walk_error = crate::walk::WalkError::contact_at(1.0, slip.phase())(error);
                    assert_eq!(walk_error.kind(), "painleve");
                    if other.is_some() {
                        assert!(
                            walk_error.to_string().contains("two solutions"),
                            "{walk_error}"
                        );
                        two += 1;
                    }
                    found += 1;
                }
            }
        }
        // For one contact the theory says a consistent Painleve slip (w < 0, lambda_n > 0) always has lift-off
        // beside it (the tip's free normal acceleration is then positive): every case met has two solutions.
        assert!(
            found > 0 && two == found,
            "{found} found, {two} with two solutions"
        );
    }

    /// An impact whose closing tip moves away from the ground can only be closed by a pulling impulse: without
    /// friction the preferred units are applied (the audit shows the pull); with Coulomb friction no mode is
    /// consistent and the impact says so by name (walk status `inconsistent_impact`), not an arbitrary pick.
    #[test]
    fn an_impact_with_no_consistent_mode_is_named_with_friction() {
        let q = Coords::new(0.0, 0.0, -0.2, 1.0, 1.0, 0.0);
        let qd = Coords::new(0.1, 0.3, 0.0, 0.0, 0.0, 0.0);
        let frictionless = rigid(f64::INFINITY, 0.1);
        let closing = [Candidate::closing(Unit::Contact(Role::Fore), &frictionless)];
        let (_, sol) = plastic_impact(&frictionless, &q, &qd, bilateral(), &closing).unwrap();
        assert!(
            sol.normal_impulse(Role::Fore) < 0.0,
            "the closing impulse pulls"
        );
        let model = rigid(0.6, 0.1);
        let closing = [Candidate::closing(Unit::Contact(Role::Fore), &model)];
        let error = plastic_impact(&model, &q, &qd, bilateral(), &closing).unwrap_err();
        assert!(
            matches!(error, ContactError::InconsistentImpact(_)),
            "{error}"
        );
        let walk_error =
            crate::walk::WalkError::contact_at(1.0, crate::contact::Phase::Flight)(error);
        assert_eq!(walk_error.kind(), "inconsistent_impact");
    }
}
