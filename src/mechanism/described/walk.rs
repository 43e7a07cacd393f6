//! A described biped with rigid legs walks as the built-in compass gait does (docs/model.md section 13): single
//! support, heel strike and the legs' exchange by [`super::super::turns`] with the stance and landing contacts
//! and the relabeling of its `[gait]` table, and a section of its own. (One with two telescopic legs walks by
//! the compliant walk, `compliant.rs`, on the section made here too.)
//!
//! The section holds the coordinates and velocities the table names; the others follow from the contact
//! conditions: the stance contact at the origin (`x = z = 0`), the landing contact on the ground behind it
//! (`z = 0`), and at rest (`J q' = 0`) the stance contact just after a rigid biped's heel strike, or the landing
//! (rear) contact before a compliant walker's impact, whose fore leg is then at its stopper and not extending.
//! The positions are solved by Newton's method on the contacts' positions from the table's guesses, the
//! velocities by the linear solve of the resting contact's rows. A description that cannot walk (no `[gait]`
//! table; joints with springs, dampers or stoppers and no legs' strokes; more than two telescopic legs) says
//! what it lacks ([`NotWalkable`]).

use nalgebra::{DVector, Matrix2, Matrix3, SVector, Vector2, Vector3};

use super::super::constrained::ConstrainedError;
use super::super::rigid::{HeelStrike, RigidOptions, RigidWalker, Transition};
use super::super::rigid_derivative::{step_map_derivative, DerivativeError, StepMapDerivative};
use super::super::turns::{self, Turns};
use super::super::{Mechanism, PointKinematics, Real};
use super::kinematics::Values;
use super::model::{Description, Gait, Motion, State};
use super::{AnyDescribed, Described};

/// Newton's method on the section's contact conditions stops when its step is below this (relative to the
/// coordinates' size, at least 1).
pub const SECTION_STEP_TOL: f64 = 1e-15;

/// The contact conditions on the section must hold to this (relative to the coordinates' size, at least 1).
pub const SECTION_RESIDUAL_TOL: f64 = 1e-12;

/// Most Newton iterations on the section's contact conditions.
const SECTION_ITERATIONS: usize = 50;

/// Why a description cannot walk (yet), or not the walk asked for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NotWalkable {
    /// Joints with springs, dampers or stoppers, and a `[gait]` table that names no legs' strokes.
    #[error(
        "`{name}` ({file}) cannot walk: its joints {joints} have springs, dampers or stoppers, and its [gait] \
         table names no legs' strokes; a described walker walks with rigid legs and point feet, or with two \
         telescopic legs named in its [gait] table (`strokes = {{ fore = ..., rear = ... }}`: prismatic joints with \
         an upper stopper) by the compliant walk (docs/model.md section 13)"
    )]
    Compliant {
        /// The walker's name.
        name: String,
        /// Its file.
        file: String,
        /// The compliant joints.
        joints: String,
    },
    /// More than two joints with stoppers (telescopic legs) and no `[gait]` table naming two of them: the
    /// compliant walk takes two legs that take turns.
    #[error(
        "`{name}` ({file}) cannot walk: its joints {joints} have stoppers ({count} telescopic legs), and the \
         compliant walk of a described walker takes two legs that take turns (the fore and the rear leg's strokes \
         in a [gait] table); the rimless wheel walks built in, as `--model vrw`"
    )]
    ManyLegs {
        /// The walker's name.
        name: String,
        /// Its file.
        file: String,
        /// The joints with stoppers.
        joints: String,
        /// How many.
        count: usize,
    },
    /// Telescopic legs: the walker walks by the compliant walk, not the rigid walk asked for.
    #[error(
        "`{name}` ({file}) has telescopic legs (its [gait] table names their strokes): it walks by the compliant \
         walk (docs/model.md section 13), not as a biped with rigid legs, and only `vrw gait` takes it so far"
    )]
    Telescopic {
        /// The walker's name.
        name: String,
        /// Its file.
        file: String,
    },
    /// No `[gait]` table.
    #[error(
        "`{name}` ({file}) cannot walk: it has no [gait] table (which contact stands, which lands, the \
         relabeling of its coordinates, its section, and for telescopic legs their strokes)"
    )]
    NoGait {
        /// The walker's name.
        name: String,
        /// Its file.
        file: String,
    },
}

/// How a description walks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Walk {
    /// As a biped with rigid legs and point feet (`crate::mechanism::rigid`).
    Rigid,
    /// By the compliant walk of a walker with two telescopic legs (`crate::mechanism::legged`).
    Compliant,
}

/// How `d` walks, or what it lacks.
pub fn walk(d: &Description) -> Result<Walk, NotWalkable> {
    let (name, file) = (d.name.to_string(), d.file.clone());
    let strokes = d.gait.as_ref().is_some_and(|g| g.strokes.is_some());
    let stopped: Vec<&str> = d
        .free_joints()
        .filter(|(_, f)| f.stoppers.iter().any(Option::is_some))
        .map(|(j, _)| j.name.as_str())
        .collect();
    if stopped.len() > 2 && !strokes {
        return Err(NotWalkable::ManyLegs {
            name,
            file,
            joints: stopped.join(", "),
            count: stopped.len(),
        });
    }
    let Some(gait) = &d.gait else {
        return Err(NotWalkable::NoGait { name, file });
    };
    if gait.strokes.is_some() {
        return Ok(Walk::Compliant);
    }
    let compliant = d.compliant_joints();
    if !compliant.is_empty() {
        return Err(NotWalkable::Compliant {
            name,
            file,
            joints: compliant.join(", "),
        });
    }
    Ok(Walk::Rigid)
}

/// Whether `d` can walk as a rigid biped (its `[gait]` table), or what it lacks.
pub fn walkable(d: &Description) -> Result<&Gait, NotWalkable> {
    match walk(d)? {
        Walk::Compliant => Err(NotWalkable::Telescopic {
            name: d.name.to_string(),
            file: d.file.clone(),
        }),
        Walk::Rigid => d.gait.as_ref().ok_or_else(|| NotWalkable::NoGait {
            name: d.name.to_string(),
            file: d.file.clone(),
        }),
    }
}

impl AnyDescribed {
    /// Whether it can walk as a rigid biped, or what it lacks.
    pub fn walkable(&self) -> Result<(), NotWalkable> {
        walkable(self.description()).map(|_| ())
    }

    /// Whether it walks by the compliant walk (two telescopic legs named in its `[gait]` table).
    pub fn walks_compliant(&self) -> bool {
        walk(self.description()) == Ok(Walk::Compliant)
    }

    /// Whether the section values `s` complete to a state on its section ([`Described::section_state`]); a
    /// walker that cannot walk has no section.
    pub fn check_section(&self, s: &DVector<f64>) -> Result<(), SectionError> {
        if walk(self.description()).is_err() {
            return Err(SectionError::Singular);
        }
        crate::with_described!(self, w => w.section_state(s).map(|_| ()))
    }
}

impl<const N: usize> Described<N> {
    /// Its `[gait]` table; a walker is checked [`walkable`] before it walks, and one without a table walks as
    /// one whose stance contact is its first (it cannot be asked to: the jobs check first).
    pub(super) fn gait(&self) -> &Gait {
        self.description
            .gait
            .as_ref()
            .expect("a described walker walks only once checked walkable")
    }

    /// How it takes turns, at its parameter values.
    pub fn turns(&self) -> Turns<N> {
        self.turns_with(&self.constants_f64())
    }

    /// How it takes turns, with the constants `c` (the slide's rate may depend on the parameters).
    pub fn turns_with<T: Real>(&self, c: &Values<T>) -> Turns<N, T> {
        let g = self.gait();
        let shift = g.shift.map(|k| (k, self.slide_per_unit(c, k)));
        Turns {
            stance: g.stance,
            lands: g.lands,
            relabel: std::array::from_fn(|i| g.relabel[i]),
            shift,
        }
    }

    /// The `x` a unit of the sliding coordinate `k` moves the walker (its direction's `x`), with the constants
    /// `c`.
    fn slide_per_unit<T: Real>(&self, c: &Values<T>, k: usize) -> T {
        self.description
            .joints
            .iter()
            .find_map(|j| match (&j.motion, &j.state) {
                (Motion::Prismatic { direction }, State::Free(f)) if f.coordinate == k => {
                    Some(c.of(&direction[0]))
                }
                _ => None,
            })
            .unwrap_or(T::one())
    }

    /// The state on the section with the section values `s` (see the module documentation), or why the contact
    /// conditions have no solution from the guesses.
    pub fn section_state(
        &self,
        s: &DVector<f64>,
    ) -> Result<(SVector<f64, N>, SVector<f64, N>), SectionError> {
        let g = self.gait();
        let (mut q, mut qd) = (SVector::<f64, N>::zeros(), SVector::<f64, N>::zeros());
        let mut names = self.values.clone();
        for (&(k, velocity), &v) in g.section.iter().zip(s.iter()) {
            if velocity {
                qd[k] = v;
            } else {
                q[k] = v;
                names.push(v);
            }
        }
        for (k, e) in &g.guess {
            q[*k] = e.eval(&names);
        }
        let held = self.held_on_section();
        if let Some((k, stopper)) = held {
            q[k] = stopper;
        }
        let solved = |velocity: bool| -> Vec<usize> {
            (0..N)
                .filter(|k| {
                    !g.section.contains(&(*k, velocity)) && held.map(|(h, _)| h) != Some(*k)
                })
                .collect()
        };
        self.solve_positions(g, &mut q, &solved(false))?;
        let unknown = solved(true);
        let c = self.constants_f64();
        let resting = self.contact(&c, &q, &qd, self.resting_contact()).jacobian;
        let a = Matrix2::from_fn(|r, i| resting[(r, unknown[i])]);
        let rhs: Vector2<f64> = -(resting * qd);
        let v = a.lu().solve(&rhs).ok_or(SectionError::Singular)?;
        for (i, k) in unknown.iter().enumerate() {
            qd[*k] = v[i];
        }
        Ok((q, qd))
    }

    /// With telescopic legs, the fore leg's stroke held at its stopper on the section: its coordinate and the
    /// stopper's value (its rate is 0).
    fn held_on_section(&self) -> Option<(usize, f64)> {
        let [fore, _] = self.gait().strokes.as_ref()?;
        Some((fore.coordinate, fore.stopper.eval(&self.values)))
    }

    /// The contact at rest on the section: the stance contact just after a rigid biped's heel strike, the rear
    /// (landing) contact before a compliant walker's impact.
    fn resting_contact(&self) -> usize {
        let g = self.gait();
        if g.strokes.is_some() {
            g.lands
        } else {
            g.stance
        }
    }

    /// The hip's point (its body's frame's origin) at `(q, q')`.
    pub fn hip(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> PointKinematics<f64, N> {
        let c = self.constants_f64();
        super::kinematics::frames(&self.description, &c, q, qd)[self.gait().hip].origin
    }

    /// The section's values at `(q, q')`, over any [`Real`].
    pub fn section_values<T: Real>(&self, q: &SVector<T, N>, qd: &SVector<T, N>) -> Vec<T> {
        let g = self.gait();
        g.section
            .iter()
            .map(|&(k, velocity)| if velocity { qd[k] } else { q[k] })
            .collect()
    }

    /// Newton's method for the coordinates `unknown` of `q`: the stance contact at the origin, the landing
    /// contact on the ground, behind it.
    fn solve_positions(
        &self,
        g: &Gait,
        q: &mut SVector<f64, N>,
        unknown: &[usize],
    ) -> Result<(), SectionError> {
        let c = self.constants_f64();
        let zero = SVector::zeros();
        let conditions = |q: &SVector<f64, N>| {
            let (stance, lands) = (
                self.contact(&c, q, &zero, g.stance),
                self.contact(&c, q, &zero, g.lands),
            );
            let r = Vector3::new(stance.position.x, stance.position.y, lands.position.y);
            let rows = [
                stance.jacobian.row(0),
                stance.jacobian.row(1),
                lands.jacobian.row(1),
            ];
            let j = Matrix3::from_fn(|r, i| rows[r][unknown[i]]);
            (r, j, lands.position.x - stance.position.x)
        };
        for _ in 0..SECTION_ITERATIONS {
            let (r, j, _) = conditions(q);
            if r.amax() == 0.0 {
                break;
            }
            let step = j.lu().solve(&-r).ok_or(SectionError::Singular)?;
            for (i, k) in unknown.iter().enumerate() {
                q[*k] += step[i];
            }
            if step.amax() <= SECTION_STEP_TOL * q.amax().max(1.0) {
                break;
            }
        }
        let (r, _, behind) = conditions(q);
        // A NaN residual is no solution either.
        let met = r.amax() <= SECTION_RESIDUAL_TOL * q.amax().max(1.0);
        if !met {
            return Err(SectionError::NoSolution { residual: r.amax() });
        }
        let is_behind = behind < 0.0;
        if !is_behind {
            return Err(SectionError::NotBehind { ahead: behind });
        }
        Ok(())
    }
}

impl<const N: usize> Described<N> {
    /// [`Described::section_state`] over a [`Real`] with the constants `c`, differentiated implicitly: the
    /// positions solved on `f64`, then one Newton correction on `T` from that solution, which moves the values
    /// by the residual only and gives the derivative parts exactly (`dq_u = -J_u^-1 (J_s dq_s + dr/dp)`, the
    /// implicit function theorem on the contact conditions `r`), and the velocities by the resting contact's rows
    /// solved on `T` (Cramer's rule); with telescopic legs, the fore leg held at its stopper. A state of NaN
    /// where the conditions have no solution.
    pub fn section_state_with<T: Real>(
        &self,
        c: &Values<T>,
        s: &[T],
    ) -> (SVector<T, N>, SVector<T, N>) {
        let nan = || {
            (
                SVector::repeat(T::lit(f64::NAN)),
                SVector::repeat(T::lit(f64::NAN)),
            )
        };
        let values = DVector::from_iterator(s.len(), s.iter().map(|v| v.value()));
        let Ok((q0, _)) = self.section_state(&values) else {
            return nan();
        };
        let g = self.gait();
        let (mut q, mut qd) = (q0.map(T::lit), SVector::<T, N>::zeros());
        for (&(k, velocity), &v) in g.section.iter().zip(s) {
            if velocity {
                qd[k] = v;
            } else {
                q[k] = v;
            }
        }
        // With telescopic legs, the fore leg's stroke at its stopper (which may carry `d/dp`), its rate 0.
        let held = g.strokes.as_ref().map(|[fore, _]| fore.coordinate);
        if let Some([fore, _]) = &g.strokes {
            q[fore.coordinate] = c.of(&fore.stopper);
        }
        let unknown: Vec<usize> = (0..N)
            .filter(|k| !g.section.contains(&(*k, false)) && held != Some(*k))
            .collect();
        let Some(inverse) = self.conditions_jacobian(g, &q0, &unknown).try_inverse() else {
            return nan();
        };
        let zero = SVector::zeros();
        let (stance, lands) = (
            self.contact(c, &q, &zero, g.stance).position,
            self.contact(c, &q, &zero, g.lands).position,
        );
        let r = [stance.x, stance.y, lands.y];
        for (i, k) in unknown.iter().enumerate() {
            q[*k] -= (0..3).fold(T::zero(), |sum, j| sum + T::lit(inverse[(i, j)]) * r[j]);
        }
        let unknown: Vec<usize> = (0..N)
            .filter(|k| !g.section.contains(&(*k, true)) && held != Some(*k))
            .collect();
        let j = self.contact(c, &q, &qd, self.resting_contact()).jacobian;
        let rhs = -(j * qd);
        let a = |r: usize, i: usize| j[(r, unknown[i])];
        let det = a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0);
        qd[unknown[0]] = (rhs[0] * a(1, 1) - a(0, 1) * rhs[1]) / det;
        qd[unknown[1]] = (a(0, 0) * rhs[1] - rhs[0] * a(1, 0)) / det;
        (q, qd)
    }

    /// The contact conditions' Jacobian at `q` (on `f64`) in the coordinates `unknown`: the rows of the stance
    /// contact's `x` and `z` and the landing contact's `z`.
    fn conditions_jacobian(
        &self,
        g: &Gait,
        q: &SVector<f64, N>,
        unknown: &[usize],
    ) -> Matrix3<f64> {
        let (c, zero) = (self.constants_f64(), SVector::zeros());
        let (stance, lands) = (
            self.contact(&c, q, &zero, g.stance).jacobian,
            self.contact(&c, q, &zero, g.lands).jacobian,
        );
        let rows = [stance.row(0), stance.row(1), lands.row(1)];
        Matrix3::from_fn(|r, i| rows[r][unknown[i]])
    }
}

/// Why a section's state has no solution.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum SectionError {
    /// The contact conditions' Jacobian is singular.
    #[error("the contact conditions on the section are singular")]
    Singular,
    /// Newton's method did not meet the conditions.
    #[error("the contact conditions on the section are not met (residual {residual:e})")]
    NoSolution {
        /// `max |residual|`.
        residual: f64,
    },
    /// The solution found puts the landing contact ahead of the stance contact.
    #[error("the landing contact is {ahead:e} ahead of the stance contact, not behind it (change the guesses)")]
    NotBehind {
        /// Its distance ahead.
        ahead: f64,
    },
}

/// The rigid walk of a described biped with `N` coordinates and `Y = 2 N` states; its exact derivatives in
/// `D = 2 N - 4` directions (the section's `N - 3` coordinates and `N - 2` velocities, and the parameter), `E =
/// D + 1`, `A = Y + Y D` ([`RigidWalker::step_map_derivative`]).
macro_rules! rigid_walker {
    ($($n:literal => $y:literal, $d:literal, $e:literal, $a:literal);*) => {$(
        impl RigidWalker<$n, $y> for Described<$n> {
            type Constants<T: Real> = Values<T>;

            fn name(&self) -> &'static str {
                self.description.name
            }

            fn section_names(&self) -> Vec<&'static str> {
                self.gait().section_names.clone()
            }

            fn rigid_constants<T: Real>(&self, value: &dyn Fn(&'static str, f64) -> T) -> Values<T> {
                Mechanism::constants(self, value)
            }

            fn single_support_with<T: Real>(
                &self,
                c: &Values<T>,
                q: &SVector<T, $n>,
                qd: &SVector<T, $n>,
            ) -> Result<(SVector<T, $n>, T), ConstrainedError> {
                turns::single_support(self, &self.turns_with(c), c, (q, qd))
            }

            fn swing_foot_with<T: Real>(&self, c: &Values<T>, q: &SVector<T, $n>) -> (T, T) {
                turns::swing_foot(self, &self.turns_with(c), c, q)
            }

            fn hip_height(&self, q: &SVector<f64, $n>) -> f64 {
                self.hip(q, &SVector::zeros()).position.y
            }

            fn transition_with<T: Real>(
                &self,
                c: &Values<T>,
                q: &SVector<T, $n>,
                qd: &SVector<T, $n>,
            ) -> Result<Transition<$n, T>, ConstrainedError> {
                turns::transition(self, &self.turns_with(c), c, (q, qd))
            }

            fn heel_strike(
                &self,
                q: &SVector<f64, $n>,
                qd: &SVector<f64, $n>,
            ) -> Result<HeelStrike<$n>, ConstrainedError> {
                turns::heel_strike(self, &self.turns(), q, qd)
            }

            fn mechanical_energy(&self, q: &SVector<f64, $n>, qd: &SVector<f64, $n>) -> f64 {
                self.energy(q, qd)
            }

            fn section_with<T: Real>(
                &self,
                _: &Values<T>,
                q: &SVector<T, $n>,
                qd: &SVector<T, $n>,
            ) -> Vec<T> {
                self.section_values(q, qd)
            }

            /// [`Described::section_state_with`]: the contact conditions differentiated implicitly.
            fn state_at_section_with<T: Real>(
                &self,
                c: &Values<T>,
                s: &[T],
            ) -> (SVector<T, $n>, SVector<T, $n>) {
                self.section_state_with(c, s)
            }

            fn step_map_derivative(
                &self,
                x: &DVector<f64>,
                param: Option<&str>,
                period: usize,
                options: &RigidOptions,
            ) -> Result<StepMapDerivative<$n>, DerivativeError> {
                step_map_derivative::<Self, $n, $y, $d, $e, $a>(self, x, param, period, options)
            }

            /// [`Described::section_state`]; where it has no solution, a state of NaN, on which the walk's
            /// first step fails (the interface's `state_at_section` has no error).
            fn state_at_section(&self, s: &DVector<f64>) -> (SVector<f64, $n>, SVector<f64, $n>) {
                self.section_state(s).unwrap_or_else(|_| {
                    (SVector::repeat(f64::NAN), SVector::repeat(f64::NAN))
                })
            }
        }
    )*};
}

rigid_walker!(
    3 => 6, 2, 3, 18;
    4 => 8, 4, 5, 40;
    5 => 10, 6, 7, 70;
    6 => 12, 8, 9, 108;
    7 => 14, 10, 11, 154;
    8 => 16, 12, 13, 208
);

/// Calls `$body` with `$w` bound to the [`Described`] inside an [`AnyDescribed`] that can walk as a rigid biped
/// (`3..=MAX_COORDINATES` coordinates: the contact conditions fix three positions), else `$other`.
#[macro_export]
macro_rules! with_rigid_described {
    ($any:expr, $w:ident => $body:expr, _ => $other:expr) => {{
        use $crate::mechanism::described::AnyDescribed as A;
        match $any {
            A::N3($w) => $body,
            A::N4($w) => $body,
            A::N5($w) => $body,
            A::N6($w) => $body,
            A::N7($w) => $body,
            A::N8($w) => $body,
            A::N1(_) | A::N2(_) => $other,
        }
    }};
}
