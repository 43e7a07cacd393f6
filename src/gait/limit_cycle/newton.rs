//! Newton's method on `P(s) - s` for [`solve_fixed_point_asking`](super::solve_fixed_point_asking): its
//! iterate and its state from one iteration to the next (the damped step, the matrix held with Broyden's
//! update, the count of poor iterations).

use nalgebra::{DMatrix, DVector};

use super::{norm, FixedPoint, GaitError, GaitOptions, MAX_POOR_ITERATIONS};
use crate::gait::derivative::newton_jacobian;
use crate::gait::step_map::{StepMap, StepOutcome};
use crate::walk::SectionState;

/// An iterate of Newton's method: the section state, the step from it and the residual `P(s) - s` in the
/// map's free coordinates.
pub(super) struct Trial {
    pub(super) section: SectionState,
    pub(super) outcome: StepOutcome,
    pub(super) r: DVector<f64>,
}

impl Trial {
    /// The iterate at `s`, the map evaluated in Newton iteration `iteration`.
    pub(super) fn at(map: &StepMap, s: SectionState, iteration: usize) -> Result<Trial, GaitError> {
        let out = map
            .eval(&s)
            .map_err(|source| GaitError::Newton { iteration, source })?;
        let r = map.reduce(&out.next) - map.reduce(&s);
        Ok(Trial {
            section: s,
            outcome: out,
            r,
        })
    }
}

/// The state of Newton's method on `P(s) - s` from one iteration to the next (see
/// [`solve_fixed_point_asking`](super::solve_fixed_point_asking)).
pub(super) struct Newton<'a, 'm> {
    /// The map on the section of the start.
    map: &'a StepMap<'m>,
    options: &'a GaitOptions,
    /// Fail where a step with `DP` at its iterate must be damped.
    undamped: bool,
    /// The number of free coordinates.
    n: usize,
    /// The current iterate.
    at: Trial,
    /// `DP - I` (or a guess of it) for the next step; `None`: computed at the iterate.
    newton_matrix: Option<DMatrix<f64>>,
    /// Newton iterations so far.
    iterations: usize,
    /// Was the current Newton matrix computed at the current iterate (so recomputing it cannot help)?
    fresh: bool,
    /// Consecutive iterations with a fresh DP that did not even halve the residual: Newton is not converging
    /// (e.g. the iterate hops across a discontinuity of the map), so stop early.
    poor: usize,
}

impl<'a, 'm> Newton<'a, 'm> {
    /// Newton's method from the iterate `at` of `map`, with the Newton matrix `newton_matrix` if given (else
    /// `DP - I` computed at the iterate).
    pub(super) fn new(
        map: &'a StepMap<'m>,
        options: &'a GaitOptions,
        undamped: bool,
        at: Trial,
        newton_matrix: Option<DMatrix<f64>>,
    ) -> Self {
        Newton {
            map,
            options,
            undamped,
            n: map.free_coordinates().len(),
            at,
            newton_matrix,
            iterations: 0,
            fresh: false,
            poor: 0,
        }
    }

    /// `max |P(s) - s|` at the iterate.
    pub(super) fn residual(&self) -> f64 {
        norm(&self.at.r)
    }

    /// One iteration: the Newton step, damped, then the matrix kept with Broyden's update or dropped.
    pub(super) fn iterate(&mut self) -> Result<(), GaitError> {
        self.iterations += 1;
        if self.iterations > self.options.max_iterations {
            return Err(GaitError::NoConvergence {
                iterations: self.options.max_iterations,
                residual: norm(&self.at.r),
            });
        }
        let a = self.matrix()?;
        let delta = a
            .lu()
            .solve(&(-&self.at.r))
            .ok_or(GaitError::SingularJacobian {
                residual: norm(&self.at.r),
            })?;
        let x = self.map.reduce(&self.at.section);
        let Some(trial) = self.damped(&x, &delta) else {
            if !self.fresh {
                // A stale matrix (the guess, or DP from an earlier iterate): recompute DP here and retry.
                self.newton_matrix = None;
                return Ok(());
            }
            return Err(GaitError::NoConvergence {
                iterations: self.iterations,
                residual: norm(&self.at.r),
            });
        };
        let (r, r_trial) = (&self.at.r, &trial.r);
        if self.fresh && norm(r_trial) > 0.5 * norm(r) {
            self.poor += 1;
            if self.poor >= MAX_POOR_ITERATIONS {
                return Err(GaitError::NoConvergence {
                    iterations: self.iterations,
                    residual: norm(r_trial),
                });
            }
        } else {
            self.poor = 0;
        }
        self.fresh = false;
        self.update_matrix(&x, &trial);
        self.at = trial;
        Ok(())
    }

    /// The Newton matrix `DP - I`: the one held, or `DP` computed at the iterate.
    fn matrix(&mut self) -> Result<DMatrix<f64>, GaitError> {
        if let Some(a) = &self.newton_matrix {
            return Ok(a.clone());
        }
        let dp = newton_jacobian(self.map, &self.at.section, self.options.fd_step).map_err(
            |source| GaitError::Newton {
                iteration: self.iterations,
                source,
            },
        )?;
        let a = dp - DMatrix::identity(self.n, self.n);
        self.newton_matrix = Some(a.clone());
        self.fresh = true;
        Ok(a)
    }

    /// The damped step from the iterate's coordinates `x` along `delta`: halved until the residual decreases
    /// (the map may fail far from the gait); `None` where none does, or where `undamped` and the full step
    /// does not.
    fn damped(&self, x: &DVector<f64>, delta: &DVector<f64>) -> Option<Trial> {
        let mut lambda = 1.0;
        let mut accepted = None;
        for _ in 0..6 {
            let trial = self.map.expand(&self.at.section, &(x + lambda * delta));
            if let Ok(trial) = Trial::at(self.map, trial, self.iterations) {
                if norm(&trial.r) < norm(&self.at.r) {
                    accepted = Some(trial);
                    break;
                }
            }
            lambda /= 2.0;
        }
        accepted.filter(|_| !(self.undamped && lambda < 1.0))
    }

    /// The matrix after the accepted step from `x` to `trial`: dropped where the residual did not fall
    /// tenfold, else Broyden's ("good") rank-one update (Broyden 1965).
    fn update_matrix(&mut self, x: &DVector<f64>, trial: &Trial) {
        let (r, r_trial) = (&self.at.r, &trial.r);
        if norm(r_trial) > 0.1 * norm(r) {
            self.newton_matrix = None;
        } else if let Some(a) = &mut self.newton_matrix {
            // Broyden's update makes the matrix map this step to the change of the residual it made, which
            // turns the linear convergence of a stale matrix (the neighbour's DP in a continuation: 10-15x per
            // iteration, seven or eight iterations to 1e-10) into superlinear convergence (three to five) at no
            // extra evaluation. Three lines, so no crate.
            let dx = self.map.reduce(&trial.section) - x;
            let dr = r_trial - r;
            let denom = dx.dot(&dx);
            if denom > 0.0 {
                *a += (dr - &*a * &dx) * dx.transpose() / denom;
            }
        }
    }

    /// The fixed point Newton's method converged to.
    pub(super) fn fixed_point(self) -> FixedPoint {
        FixedPoint {
            // Held: `L2 = min_length`, `dL2/dt = 0` exactly (the walk's rounding left out, as the map does).
            section: self.at.section.pinned(self.map.model()),
            outcome: self.at.outcome,
            residual: norm(&self.at.r),
            iterations: self.iterations,
            rear_held: self.map.rear_held(),
        }
    }
}
