//! The corrector of the continuation (docs/model.md section 11) and what it works on: the options, a family's
//! point, the scaled unknowns `z = (x, p / sigma)`, the Jacobian `J = [DP - I, sigma dP/dp]`, the tangent,
//! and Newton's method on `P(x) = x` with one linear condition (a hyperplane) added.

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

use super::{FamilyMap, MapFailure};

/// How a family is followed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ContinuationOptions {
    /// The parameter range `[from, to]` the family is followed in.
    pub from: f64,
    /// See `from`.
    pub to: f64,
    /// First step length, in the scaled unknowns `z`.
    pub initial_step: f64,
    /// Smallest step: a family whose step falls below it ends there.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Most points in each direction from the start.
    pub max_points: usize,
    /// The corrector converges when `max |P(x) - x|` is below this.
    pub tolerance: f64,
    /// Corrector iterations allowed.
    pub max_corrector_iterations: usize,
    /// `sigma`: the parameter is followed as `p / sigma`.
    pub param_scale: f64,
    /// Special points are located to this in the parameter.
    pub param_tolerance: f64,
    /// Detect and locate special points (folds, period doublings, Neimark-Sacker points, border collisions).
    pub detect: bool,
}

impl ContinuationOptions {
    /// The defaults for the range `[from, to]`: `sigma` the power of two nearest a tenth of its
    /// width, steps from `1e-7` to `0.1`
    /// (first `0.01`), 300 points each way, `tolerance = 1e-10` (as the gait search), eight corrector iterations, special points
    /// to `1e-10` in the parameter.
    pub fn for_range(from: f64, to: f64) -> ContinuationOptions {
        let width = (to - from).abs();
        ContinuationOptions {
            from: from.min(to),
            to: from.max(to),
            initial_step: 0.01,
            min_step: 1e-7,
            max_step: 0.1,
            max_points: 300,
            tolerance: 1e-10,
            max_corrector_iterations: 8,
            // A power of two, so that `p / sigma * sigma` is `p` exactly (a family's last point lies exactly
            // on the bound).
            param_scale: if width > 0.0 {
                (width / 10.0).log2().round().exp2()
            } else {
                1.0
            },
            param_tolerance: 1e-10,
            detect: true,
        }
    }

    /// Checks the settings; the message names the first one that is wrong.
    pub fn validate(&self) -> Result<(), String> {
        let finite = [
            ("from", self.from),
            ("to", self.to),
            ("initial_step", self.initial_step),
            ("min_step", self.min_step),
            ("max_step", self.max_step),
            ("tolerance", self.tolerance),
            ("param_scale", self.param_scale),
            ("param_tolerance", self.param_tolerance),
        ];
        if let Some((name, v)) = finite.iter().find(|(_, v)| !v.is_finite()) {
            return Err(format!("{name} must be a finite number, got {v}"));
        }
        if self.from >= self.to {
            return Err(format!(
                "the range must have from < to, got [{}, {}]",
                self.from, self.to
            ));
        }
        for (name, v) in &finite[2..] {
            if *v <= 0.0 {
                return Err(format!("{name} must be positive, got {v}"));
            }
        }
        if !(self.min_step <= self.initial_step && self.initial_step <= self.max_step) {
            return Err(format!(
                "the steps must satisfy min_step <= initial_step <= max_step, got {} <= {} <= {}",
                self.min_step, self.initial_step, self.max_step
            ));
        }
        if self.max_points == 0 || self.max_corrector_iterations == 0 {
            return Err("max_points and max_corrector_iterations must be at least 1".to_string());
        }
        Ok(())
    }
}

/// A point of a family: a fixed point of `P` (or `P^k`) and its derivatives there.
#[derive(Debug, Clone, PartialEq)]
pub struct FamilyPoint<I> {
    /// The parameter.
    pub param: f64,
    /// The fixed point.
    pub x: DVector<f64>,
    /// Arclength along the family in the scaled unknowns, from its first point.
    pub arclength: f64,
    /// `DP` there (`D(P^k)`).
    pub jacobian: DMatrix<f64>,
    /// `dP/dp` there.
    pub dparam: DVector<f64>,
    /// The derivatives are exact (see [`super::Evaluation::exact`]).
    pub exact: bool,
    /// The eigenvalues of `DP` (the Floquet multipliers), largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// `max |P(x) - x|` by direct evaluation.
    pub residual: f64,
    /// The unit tangent in the scaled unknowns, oriented along the direction followed.
    pub tangent: DVector<f64>,
    /// Corrector iterations it took (0 for the start).
    pub iterations: usize,
    /// The residual's contraction per corrector iteration (`NaN` if fewer than two residuals).
    pub corrector_rate: f64,
    /// What the map records of it.
    pub info: I,
}

impl<I> FamilyPoint<I> {
    /// Largest modulus of the multipliers.
    pub fn max_multiplier(&self) -> f64 {
        self.multipliers.first().map_or(f64::NAN, |z| z.norm())
    }

    /// Were `DP` and `dP/dp` computed here (exactly or by differences)?
    pub fn has_derivatives(&self) -> bool {
        self.jacobian
            .iter()
            .chain(self.dparam.iter())
            .all(|v| v.is_finite())
    }

    /// The scaled unknowns `(x, p / sigma)`.
    pub(crate) fn z(&self, sigma: f64) -> DVector<f64> {
        let n = self.x.len();
        DVector::from_fn(
            n + 1,
            |i, _| if i < n { self.x[i] } else { self.param / sigma },
        )
    }
}

/// `J = [DP - I, sigma dP/dp]`.
pub(crate) fn augmented(
    jacobian: &DMatrix<f64>,
    dparam: &DVector<f64>,
    sigma: f64,
) -> DMatrix<f64> {
    let n = dparam.len();
    DMatrix::from_fn(n, n + 1, |i, j| {
        if j < n {
            jacobian[(i, j)] - if i == j { 1.0 } else { 0.0 }
        } else {
            sigma * dparam[i]
        }
    })
}

/// `[j; row^T]`.
pub(crate) fn bordered(j: &DMatrix<f64>, row: &DVector<f64>) -> DMatrix<f64> {
    let n = j.nrows();
    let mut m = j.clone().insert_row(n, 0.0);
    m.row_mut(n).copy_from(&row.transpose());
    m
}

/// The unit null vector of `j` (`n x (n + 1)`) with a positive component along `orient`; `None` where `j`
/// has no one-dimensional null space.
pub(crate) fn tangent(j: &DMatrix<f64>, orient: &DVector<f64>) -> Option<DVector<f64>> {
    let n = j.nrows();
    let mut rhs = DVector::zeros(n + 1);
    rhs[n] = 1.0;
    let t = bordered(j, orient).lu().solve(&rhs)?;
    let norm = t.norm();
    (norm.is_finite() && norm > 0.0).then(|| t / norm)
}

/// `x` and `p` of the scaled unknowns.
pub(crate) fn split(z: &DVector<f64>, sigma: f64) -> (DVector<f64>, f64) {
    let n = z.len() - 1;
    (z.rows(0, n).into_owned(), z[n] * sigma)
}

/// The eigenvalues of `dp`, largest modulus first (empty if `dp` is not finite).
pub(crate) fn multipliers(dp: &DMatrix<f64>) -> Vec<Complex<f64>> {
    if !dp.iter().all(|v| v.is_finite()) {
        return Vec::new();
    }
    let mut m: Vec<Complex<f64>> = dp.complex_eigenvalues().iter().copied().collect();
    m.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
    m
}

/// Newton's method from `z_pred` on `H(z) = 0` and `row . (z - z_pred) = 0` with the matrix `m` held (see
/// the module documentation); the converged `z` and the iterations.
pub(crate) fn correct<M: FamilyMap>(
    map: &M,
    z_pred: &DVector<f64>,
    row: &DVector<f64>,
    m: &DMatrix<f64>,
    options: &ContinuationOptions,
) -> Result<(DVector<f64>, usize), MapFailure> {
    chord(map, (z_pred, row), m, None, options).map(|c| (c.z, c.iterations))
}

/// Where the chord method converged.
struct Converged<I> {
    /// The converged unknowns.
    z: DVector<f64>,
    /// Iterations.
    iterations: usize,
    /// The residual's contraction per iteration (`NaN` if unknown).
    rate: f64,
    /// The evaluation at `z` with derivatives, if the last iteration made one.
    ev: Option<super::Evaluation<I>>,
}

/// The chord method of [`correct`]. With `rate_hint` (the last corrector's contraction rate, until this one
/// has its own), the iteration whose residual the contraction predicts below the tolerance evaluates the map
/// with its derivatives (see [`correct_to_point`]); without, only `P` is evaluated.
fn chord<M: FamilyMap>(
    map: &M,
    (z_pred, row): (&DVector<f64>, &DVector<f64>),
    m: &DMatrix<f64>,
    rate_hint: Option<f64>,
    options: &ContinuationOptions,
) -> Result<Converged<M::Info>, MapFailure> {
    let sigma = options.param_scale;
    let mut lu = m.clone().lu();
    let mut z = z_pred.clone();
    let mut previous = f64::INFINITY;
    let mut rate = rate_hint.unwrap_or(f64::NAN);
    for iteration in 0..=options.max_corrector_iterations {
        let (x, p) = split(&z, sigma);
        let expect_converged = rate_hint.is_some() && previous * rate < options.tolerance;
        let (h, ev) = if expect_converged {
            let ev = map.eval(&x, p)?;
            (&ev.value - &x, Some(ev))
        } else {
            (map.value(&x, p)? - &x, None)
        };
        let residual = h.amax();
        if residual < options.tolerance {
            return Ok(Converged {
                z,
                iterations: iteration,
                rate,
                ev,
            });
        }
        if residual.is_nan()
            || residual >= 0.5 * previous
            || iteration == options.max_corrector_iterations
        {
            return Err(corrector_failure(iteration, residual));
        }
        if previous.is_finite() {
            rate = residual / previous;
        }
        previous = residual;
        if let Some(ev) = ev.filter(|ev| ev.jacobian.iter().all(|v| v.is_finite())) {
            lu = bordered(&augmented(&ev.jacobian, &ev.dparam, sigma), row).lu();
        }
        let n = h.len();
        let mut r = h.insert_row(n, row.dot(&(&z - z_pred)));
        r.neg_mut();
        let dz = lu
            .solve(&r)
            .ok_or_else(|| corrector_failure(iteration, residual))?;
        z += dz;
    }
    unreachable!("the loop returns at its last iteration")
}

/// The corrector did not converge.
pub(crate) fn corrector_failure(iteration: usize, residual: f64) -> MapFailure {
    MapFailure {
        kind: "corrector".to_string(),
        message: format!(
            "the corrector did not converge (residual {residual:.2e} after {iteration} iterations)"
        ),
    }
}

/// The family point at the converged `z`, with its tangent oriented along `orient`.
pub(crate) fn point_at<M: FamilyMap>(
    map: &M,
    z: &DVector<f64>,
    orient: &DVector<f64>,
    options: &ContinuationOptions,
) -> Result<FamilyPoint<M::Info>, MapFailure> {
    let (x, p) = split(z, options.param_scale);
    let ev = map.eval(&x, p)?;
    point_from(ev, z, orient, options.param_scale)
}

/// The family point at `z` from the map's evaluation there, with its tangent oriented along `orient`.
fn point_from<I>(
    ev: super::Evaluation<I>,
    z: &DVector<f64>,
    orient: &DVector<f64>,
    sigma: f64,
) -> Result<FamilyPoint<I>, MapFailure> {
    let (x, p) = split(z, sigma);
    let j = augmented(&ev.jacobian, &ev.dparam, sigma);
    // Without derivatives (the map is not differentiable there) the tangent is the previous one.
    let t = if j.iter().all(|v| v.is_finite()) {
        tangent(&j, orient).ok_or_else(|| MapFailure {
            kind: "singular".to_string(),
            message: format!("the family has no unique tangent at p = {p}"),
        })?
    } else {
        orient.normalize()
    };
    Ok(FamilyPoint {
        param: p,
        residual: (&ev.value - &x).amax(),
        multipliers: multipliers(&ev.jacobian),
        x,
        arclength: 0.0,
        jacobian: ev.jacobian,
        dparam: ev.dparam,
        exact: ev.exact,
        tangent: t,
        iterations: 0,
        corrector_rate: f64::NAN,
        info: ev.info,
    })
}

/// [`correct`] and [`point_at`] in one: the iteration whose residual the contraction so far (or, before this
/// corrector has two residuals, `rate_hint`, the last corrector's) predicts below the tolerance evaluates
/// the map with its derivatives, which is the converged point's own evaluation (one evaluation of `P` fewer
/// per point) or, if it is not yet converged, gives the remaining iterations a fresh matrix.
pub(crate) fn correct_to_point<M: FamilyMap>(
    map: &M,
    z_pred: &DVector<f64>,
    row: &DVector<f64>,
    m: &DMatrix<f64>,
    (orient, rate_hint): (&DVector<f64>, f64),
    options: &ContinuationOptions,
) -> Result<FamilyPoint<M::Info>, MapFailure> {
    let c = chord(map, (z_pred, row), m, Some(rate_hint), options)?;
    let ev = match c.ev {
        Some(ev) => ev,
        None => {
            let (x, p) = split(&c.z, options.param_scale);
            map.eval(&x, p)?
        }
    };
    let mut point = point_from(ev, &c.z, orient, options.param_scale)?;
    point.iterations = c.iterations;
    point.corrector_rate = c.rate;
    Ok(point)
}

/// The fixed point near `x0` at `p0`, with its tangent pointing to increasing `p` (or, at a fold, along the
/// first coordinate).
pub(crate) fn start_point<M: FamilyMap>(
    map: &M,
    x0: &DVector<f64>,
    p0: f64,
    options: &ContinuationOptions,
) -> Result<FamilyPoint<M::Info>, MapFailure> {
    let sigma = options.param_scale;
    let n = x0.len();
    let z0 = DVector::from_fn(n + 1, |i, _| if i < n { x0[i] } else { p0 / sigma });
    let mut e_p = DVector::zeros(n + 1);
    e_p[n] = 1.0;
    let z = solve_on_hyperplane(map, &z0, &e_p, options)?;
    point_at(map, &z, &e_p, options)
}

/// The fixed point on the hyperplane `row . (z - z0) = 0` by Newton's method from `z0`, with `DP` recomputed
/// at every iterate (the start may be far from the fixed point).
pub(crate) fn solve_on_hyperplane<M: FamilyMap>(
    map: &M,
    z0: &DVector<f64>,
    row: &DVector<f64>,
    options: &ContinuationOptions,
) -> Result<DVector<f64>, MapFailure> {
    let sigma = options.param_scale;
    let n = z0.len() - 1;
    let mut z = z0.clone();
    for _ in 0..options.max_corrector_iterations.max(MIN_START_ITERATIONS) {
        let (x, p) = split(&z, sigma);
        let ev = map.eval(&x, p)?;
        let h = &ev.value - &x;
        if h.amax() < options.tolerance {
            return Ok(z);
        }
        let m = bordered(&augmented(&ev.jacobian, &ev.dparam, sigma), row);
        let mut r = h.insert_row(n, row.dot(&(&z - z0)));
        r.neg_mut();
        let dz = m.lu().solve(&r).ok_or_else(|| MapFailure {
            kind: "singular".to_string(),
            message: format!("singular Newton matrix at p = {p}"),
        })?;
        z += dz;
    }
    let (_, p) = split(z0, sigma);
    Err(MapFailure {
        kind: "corrector".to_string(),
        message: format!("Newton's method did not converge near p = {p}"),
    })
}

/// Newton iterations allowed to find the first point of a family.
const MIN_START_ITERATIONS: usize = 20;
